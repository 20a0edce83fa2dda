/* RateLimiter: the unified block (docs/rules.md), a direct mapping
 * of its variables onto the kernel. */
#include "RateLimiter_variables.h"

static int configure(const double *v, RlConfig *c) {
    c->rateUp = rl_resolve(v[VR_rateUp], VR_rateUp, v[VR_rateUpPar], VR_rateUpPar);
    c->rateDown = rl_resolve(v[VR_rateDown], VR_rateDown, v[VR_rateDownPar], VR_rateDownPar);
    c->rateUpNeg = rl_resolve(v[VR_rateUpNeg], VR_rateUpNeg, c->rateUp.value, c->rateUp.source);
    c->rateDownNeg = rl_resolve(v[VR_rateDownNeg], VR_rateDownNeg, c->rateDown.value, c->rateDown.source);
    c->yMax = rl_resolve(v[VR_yMax], VR_yMax, v[VR_yMaxPar], VR_yMaxPar);
    c->yMin = rl_resolve(v[VR_yMin], VR_yMin, v[VR_yMinPar], VR_yMinPar);
    c->hold = v[VR_hold] != 0;
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
    c->limitInitialOutput = true;
    c->real = (int)v[VR_arithmetic] == RL_ARITHMETIC_REAL;
    return 0;
}

static void publish(const RlState *block, const RlPrepared *prepared, int modelMode, double *v) {
    (void)modelMode;
    RlOutputs o;
    rl_outputs(block, prepared, &o);
    v[VR_y] = block->y;
    v[VR_rampActive] = o.rampActive;
    v[VR_runningTime] = rl_running_time(block);
    v[VR_dydt] = o.dydt;
    v[VR_limitingUp] = o.limitingUp;
    v[VR_limitingDown] = o.limitingDown;
    v[VR_highLimit] = o.highLimit;
    v[VR_lowLimit] = o.lowLimit;
    v[VR_remainingTime] = o.remainingTime;
}

static const FmuStatusOutputs statusOutputs = { VR_error, VR_status, VR_subFunctionStatus };

const ModelDefinition fmuModel = {
    MODEL_TABLE,
    .inputVr = VR_u, .outputVr = VR_y,
    .configure = configure, .publish = publish,
    .statusOutputs = &statusOutputs,
};
