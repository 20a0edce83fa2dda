/* RateLimiterStatic: the unified block set by parameters (docs/models.md),
 * for importers that feed 0 to an unconnected input. Its only inputs are
 * u, bypass and hold; each parameter stands where RateLimiter resolves an
 * "or Par" input, so that with RateLimiter's inputs at NaN both blocks
 * compute the same. */
#include "RateLimiterStatic_variables.h"
#include "unified.h"

static const UnifiedVariables variables = UNIFIED_VARIABLES;

static int configure(const double *v, RlConfig *c) {
    c->rateUp = unified_value(v, VR_rateUpPar);
    c->rateDown = unified_value(v, VR_rateDownPar);
    c->rateUpNeg = rl_resolve(v[VR_rateUpNeg], VR_rateUpNeg, c->rateUp.value, c->rateUp.source);
    c->rateDownNeg = rl_resolve(v[VR_rateDownNeg], VR_rateDownNeg, c->rateDown.value, c->rateDown.source);
    c->yMax = unified_value(v, VR_yMaxPar);
    c->yMin = unified_value(v, VR_yMinPar);
    c->duration = unified_value(v, VR_durationPar);
    c->bypassValue = v[VR_bypassValuePar];
    unified_configure(&variables, v, c);
    return 0;
}

static void publish(const RlState *block, const RlPrepared *prepared, int modelMode, double *v) {
    (void)modelMode;
    unified_publish(&variables, block, prepared, v);
}

static const FmuStatusOutputs statusOutputs = { VR_error, VR_status, VR_subFunctionStatus };

const ModelDefinition fmuModel = {
    MODEL_TABLE,
    .inputVr = VR_u, .outputVr = VR_y,
    .configure = configure, .publish = publish,
    .statusOutputs = &statusOutputs,
};
