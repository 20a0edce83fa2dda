/* LGF_LimRateOfChangeCI (Siemens, SPEC section 4): one rate per second for
 * both directions (0 holds), enDefaultOutValue as the bypass, output from 0,
 * a NaN value compared rather than passed, callOB validated. */
#include "LGF_LimRateOfChangeCI_variables.h"

static void configure(const double *v, RlConfig *c) {
    c->rateUp = c->rateDown = (RlValue){ v[VR_setChangeRate], VR_setChangeRate };
    c->ratePeriod = (RlValue){ 1.0, VR_setChangeRate };
    c->duration = (RlValue){ 0.0, 0 };
    c->cycleTime = fmu_siemens_cycle(v[VR_callOB], VR_callOB, v[VR_cycleTime], VR_cycleTime);
    c->bypass = v[VR_enDefaultOutValue] != 0;
    c->bypassValue = v[VR_defaultOutValue];
    c->zeroRate = RL_ZERO_RATE_HOLD;
    c->initMode = RL_INIT_VALUE;
    c->initValue = 0.0;
    c->initDelay = 0.0;
    c->passNonFinite = false;
    rl_without_section6(c);
}

static void publish(const RlState *block, const RlPrepared *prepared, double *v) {
    (void)prepared;
    v[VR_delayedValue] = block->y;
}

static void publish_status(const RlPrepared *p, double *v) {
    v[VR_error] = p->status >= 0x8000;
    v[VR_status] = p->status;
    v[VR_subFunctionStatus] = p->status >= 0x8000 ? p->statusSource : 0;
}

const ModelDefinition fmuModel = {
    .identifier = MODEL_IDENTIFIER,
    .token = MODEL_TOKEN,
    .variables = modelVariables,
    .count = MODEL_VARIABLE_COUNT,
    .inputVr = VR_value,
    .outputVr = VR_delayedValue,
    .configure = configure,
    .publish = publish,
    .publishStatus = publish_status,
};
