/* Ramp (CODESYS; docs/models.md, Ramp): rVariation per tTime in both directions,
 * per task cycle when tTime = 0, rVariation 0 holds; eInitial and
 * tInitDelay are the kernel's init modes. REAL pins, TIME in whole
 * milliseconds (rules.md, Arithmetic). */
#include "Ramp_variables.h"

/* A TIME pin set in seconds: whole milliseconds, ties to even (nearbyint,
 * not round: 0.0025 s is 2 ms), used in seconds. */
static double time_ms(double seconds) {
    return nearbyint(seconds * 1000.0) / 1000.0;
}

static int model_configure(const double *v, RlConfig *c) {
    c->rateUp = c->rateDown = rl_value(v[VR_rVariation], VR_rVariation);
    c->ratePeriod = rl_value(time_ms(v[VR_tTime]), VR_tTime);
    c->duration = rl_value(0.0, 0);
    c->cycleTime = rl_value(v[VR_cycleTime], VR_cycleTime);
    c->bypass = false;
    c->bypassValue = NAN;
    c->zeroRate = RL_ZERO_RATE_HOLD;
    c->initMode = (int)v[VR_eInitial];
    c->initValue = v[VR_rInitValue];
    c->initDelay = time_ms(v[VR_tInitDelay]);
    c->passNonFinite = true;
    c->real = true;
    rl_without_section6(c);
    return 0;
}

static void model_publish(const RlState *block, const RlPrepared *prepared, int modelMode, RlPlan *plan, double *v) {
    (void)modelMode;
    v[VR_rOut] = block->y;
    RlOutputs o;
    rl_outputs(block, prepared, plan, &o);
    v[VR_xRampActive] = o.rampActive;
}

FMU_MODEL(VR_rIn, VR_rOut, model_configure, model_publish, NULL);
