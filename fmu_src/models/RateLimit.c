/* RateLimit (Honeywell IRMN4; docs/models.md, RateLimit): rates per second, 0 = no
 * limit, null (NaN) inputs fall back to their parameters, Duration capped at
 * the block's 259200 s, OutSave/SavedOut restart. REAL: the IRMN4 family's
 * analog pins are 32-bit floats (rules.md, Arithmetic). */
#include "RateLimit_variables.h"

#define DURATION_MAX 259200.0

static int model_configure(const double *v, RlConfig *c) {
    c->rateUp = rl_resolve(v[VR_UpRate], VR_UpRate, v[VR_UpRatePar], VR_UpRatePar);
    c->rateDown = rl_resolve(v[VR_DownRate], VR_DownRate, v[VR_DownRatePar], VR_DownRatePar);
    c->ratePeriod = rl_value(1.0, VR_UpRatePar);
    c->duration = rl_resolve(v[VR_Duration], VR_Duration, v[VR_DurationPar], VR_DurationPar);
    if (isgreater(c->duration.value, DURATION_MAX)) {
        c->duration.value = DURATION_MAX;
    }
    c->cycleTime = rl_value(v[VR_cycleTime], VR_cycleTime);
    c->bypass = v[VR_EnableBypass] != 0;
    c->bypassValue = rl_resolve(v[VR_BypassValue], VR_BypassValue, v[VR_BypassValuePar], VR_BypassValuePar).value;
    c->zeroRate = RL_ZERO_RATE_NO_LIMIT;
    const bool restart = v[VR_OutSave] != 0 && isfinite(v[VR_SavedOut]);
    c->initMode = restart ? RL_INIT_VALUE : RL_INIT_INPUT;
    c->initValue = v[VR_SavedOut];
    c->initDelay = 0.0;
    c->passNonFinite = true;
    c->real = true;
    rl_without_section6(c);
    return 0;
}

static void model_publish(const RlState *block, const RlPrepared *prepared, int modelMode, RlPlan *plan, double *v) {
    (void)prepared;
    (void)modelMode;
    (void)plan;
    v[VR_Out] = block->y;
    v[VR_RunningTime] = rl_running_time(block);
}

FMU_MODEL(VR_In, VR_Out, model_configure, model_publish, NULL);
