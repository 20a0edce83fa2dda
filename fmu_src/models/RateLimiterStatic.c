/* RateLimiterStatic: the unified block set by parameters (docs/models.md),
 * for importers that feed 0 to an unconnected input. Its only inputs are
 * u, bypass and hold; each parameter stands where RateLimiter resolves an
 * "or Par" input, so that with RateLimiter's inputs at NaN both blocks
 * compute the same. */
#include "RateLimiterStatic_variables.h"
#include "unified.h"

/* The parameters stand where RateLimiter's "or Par" inputs fall back. */
static void resolve(const double *v, RlConfig *c) {
    c->rateUp = unified_value(v, VR_rateUpPar);
    c->rateDown = unified_value(v, VR_rateDownPar);
    c->yMax = unified_value(v, VR_yMaxPar);
    c->yMin = unified_value(v, VR_yMinPar);
    c->duration = unified_value(v, VR_durationPar);
    c->bypassValue = v[VR_bypassValuePar];
}

UNIFIED_MAPPING(resolve);
