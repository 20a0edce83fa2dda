/* RateLimiter: the unified block (docs/rules.md), a direct mapping
 * of its variables onto the kernel. */
#include "RateLimiter_variables.h"
#include "unified.h"

/* Each "or Par" input, NaN when not connected, falls back to its parameter. */
static void resolve(const double *v, RlConfig *c) {
    c->rateUp = rl_resolve(v[VR_rateUp], VR_rateUp, v[VR_rateUpPar], VR_rateUpPar);
    c->rateDown = rl_resolve(v[VR_rateDown], VR_rateDown, v[VR_rateDownPar], VR_rateDownPar);
    c->yMax = rl_resolve(v[VR_yMax], VR_yMax, v[VR_yMaxPar], VR_yMaxPar);
    c->yMin = rl_resolve(v[VR_yMin], VR_yMin, v[VR_yMinPar], VR_yMinPar);
    c->duration = rl_resolve(v[VR_duration], VR_duration, v[VR_durationPar], VR_durationPar);
    c->bypassValue = rl_resolve(v[VR_bypassValue], VR_bypassValue, v[VR_bypassValuePar], VR_bypassValuePar).value;
}

UNIFIED_MAPPING(resolve);
