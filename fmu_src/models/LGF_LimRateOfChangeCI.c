/* LGF_LimRateOfChangeCI (Siemens; docs/models.md, LGF_LimRateOfChangeCI): one rate per second for
 * both directions (0 holds), enDefaultOutValue as the bypass, output from 0,
 * a NaN value compared rather than passed, callOB validated. */
#include "LGF_LimRateOfChangeCI_variables.h"
#include "siemens.h"

static int configure(const double *v, RlConfig *c) {
    c->rateUp = c->rateDown = (RlValue){ v[VR_setChangeRate], VR_setChangeRate };
    c->ratePeriod = (RlValue){ 1.0, VR_setChangeRate };
    c->duration = (RlValue){ 0.0, 0 };
    siemens_cycle(c, v[VR_callOB], VR_callOB, v[VR_cycleTime], VR_cycleTime);
    c->bypass = v[VR_enDefaultOutValue] != 0;
    c->bypassValue = v[VR_defaultOutValue];
    c->zeroRate = RL_ZERO_RATE_HOLD;
    c->initMode = RL_INIT_VALUE;
    c->initValue = 0.0;
    c->initDelay = 0.0;
    c->passNonFinite = false;
    c->real = false;
    rl_without_section6(c);
    return 0;
}

static void publish(const RlState *block, const RlPrepared *prepared, int modelMode, double *v) {
    (void)prepared;
    (void)modelMode;
    v[VR_delayedValue] = block->y;
}

static const FmuStatusOutputs statusOutputs = { VR_error, VR_status, VR_subFunctionStatus };

const ModelDefinition fmuModel = {
    MODEL_TABLE,
    .inputVr = VR_value, .outputVr = VR_delayedValue,
    .configure = configure, .publish = publish,
    .statusOutputs = &statusOutputs,
};
