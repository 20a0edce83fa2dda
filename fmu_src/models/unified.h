/* What the unified blocks share (RateLimiter and RateLimiterStatic): the
 * settings both take from variables of the same names, and their outputs,
 * published from the block's state and its last cycle. */
#ifndef UNIFIED_H
#define UNIFIED_H

#include "model.h"

/* The value references of those variables in the model. */
typedef struct {
    unsigned hold, ratePeriod, cycleTime, bypass, zeroRate, initMode, initValue, initDelay, arithmetic, accelMax,
        decelMax;
    unsigned y, rampActive, runningTime, dydt, limitingUp, limitingDown, highLimit, lowLimit, remainingTime, d2ydt2;
} UnifiedVariables;

static inline RlValue unified_value(const double *v, unsigned vr) {
    return rl_value(v[vr], (int)vr);
}

/* Everything but the rates, limits, duration and bypass value, which each
 * model resolves its own way. */
static inline void unified_configure(const UnifiedVariables *vr, const double *v, RlConfig *c) {
    c->hold = v[vr->hold] != 0;
    c->ratePeriod = unified_value(v, vr->ratePeriod);
    c->cycleTime = unified_value(v, vr->cycleTime);
    c->bypass = v[vr->bypass] != 0;
    c->zeroRate = (int)v[vr->zeroRate];
    c->initMode = (int)v[vr->initMode];
    c->initValue = v[vr->initValue];
    c->initDelay = v[vr->initDelay];
    c->passNonFinite = true;
    c->limitInitialOutput = true;
    c->real = (int)v[vr->arithmetic] == RL_ARITHMETIC_REAL;
    c->accelMax = unified_value(v, vr->accelMax);
    c->decelMax = unified_value(v, vr->decelMax);
}

static inline void unified_publish(const UnifiedVariables *vr, const RlState *block, const RlPrepared *prepared,
                                   RlPlan *plan, double *v) {
    RlOutputs o;
    rl_outputs(block, prepared, plan, &o);
    v[vr->y] = block->y;
    v[vr->rampActive] = o.rampActive;
    v[vr->runningTime] = rl_running_time(block);
    v[vr->dydt] = o.dydt;
    v[vr->limitingUp] = o.limitingUp;
    v[vr->limitingDown] = o.limitingDown;
    v[vr->highLimit] = o.highLimit;
    v[vr->lowLimit] = o.lowLimit;
    v[vr->remainingTime] = o.remainingTime;
    v[vr->d2ydt2] = o.d2ydt2;
}

/* The table of a unified block's variables, from its generated header */
#define UNIFIED_VARIABLES \
    { \
        VR_hold, VR_ratePeriod, VR_cycleTime, VR_bypass, VR_zeroRate, VR_initMode, VR_initValue, VR_initDelay, \
            VR_arithmetic, VR_accelMax, VR_decelMax, VR_y, VR_rampActive, VR_runningTime, VR_dydt, VR_limitingUp, \
            VR_limitingDown, VR_highLimit, VR_lowLimit, VR_remainingTime, VR_d2ydt2 \
    }

/* The mapping of a unified block and its fmuModel (u in, y out):
 * resolve(v, c) sets rateUp, rateDown, yMax, yMin, duration and bypassValue
 * the model's own way; the rates below 0 fall back to the resolved rates,
 * and the rest is shared. */
#define UNIFIED_MAPPING(resolve) \
    static const UnifiedVariables unifiedVariables = UNIFIED_VARIABLES; \
    static int model_configure(const double *v, RlConfig *c) { \
        resolve(v, c); \
        c->rateUpNeg = rl_resolve(v[VR_rateUpNeg], VR_rateUpNeg, c->rateUp.value, c->rateUp.source); \
        c->rateDownNeg = rl_resolve(v[VR_rateDownNeg], VR_rateDownNeg, c->rateDown.value, c->rateDown.source); \
        unified_configure(&unifiedVariables, v, c); \
        return 0; \
    } \
    static void model_publish(const RlState *block, const RlPrepared *prepared, int modelMode, RlPlan *plan, \
                              double *v) { \
        (void)modelMode; \
        unified_publish(&unifiedVariables, block, prepared, plan, v); \
    } \
    static const FmuStatusOutputs statusOutputs = { VR_error, VR_status, VR_subFunctionStatus }; \
    FMU_MODEL(VR_u, VR_y, model_configure, model_publish, &statusOutputs)

#endif
