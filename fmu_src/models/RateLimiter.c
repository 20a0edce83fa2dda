/* RateLimiter: the unified block (SPEC section 3), a direct mapping of its
 * variables onto the kernel. */
#include "RateLimiter_variables.h"

static void configure(const double *v, RlConfig *c) {
    c->rateUp = rl_resolve(v[VR_rateUp], VR_rateUp, v[VR_rateUpPar], VR_rateUpPar);
    c->rateDown = rl_resolve(v[VR_rateDown], VR_rateDown, v[VR_rateDownPar], VR_rateDownPar);
    c->ratePeriod = (RlValue){ v[VR_ratePeriod], VR_ratePeriod };
    c->duration = rl_resolve(v[VR_duration], VR_duration, v[VR_durationPar], VR_durationPar);
    c->cycleTime = (RlValue){ v[VR_cycleTime], VR_cycleTime };
    c->bypass = v[VR_bypass] != 0;
    c->bypassValue = rl_resolve(v[VR_bypassValue], VR_bypassValue, v[VR_bypassValuePar], VR_bypassValuePar).value;
    c->zeroRate = (int)v[VR_zeroRate];
    c->initMode = (int)v[VR_initMode];
    c->initValue = v[VR_initValue];
    c->initDelay = v[VR_initDelay];
    c->passNonFinite = true;
}

static void publish(const RlState *block, double *v) {
    v[VR_y] = block->y;
    v[VR_rampActive] = block->rampActive;
    v[VR_runningTime] = rl_running_time(block);
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
    .inputVr = VR_u,
    .outputVr = VR_y,
    .configure = configure,
    .publish = publish,
    .publishStatus = publish_status,
};
