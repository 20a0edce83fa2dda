/* LGF_LimRateOfChangeCI (Siemens; docs/models.md, LGF_LimRateOfChangeCI): one rate per second for
 * both directions (0 holds), enDefaultOutValue as the bypass, output from 0,
 * a NaN value compared rather than passed, callOB validated. */
#include "LGF_LimRateOfChangeCI_variables.h"
#include "siemens.h"

static int model_configure(const double *v, RlConfig *c) {
    c->rateUp = c->rateDown = rl_value(v[VR_setChangeRate], VR_setChangeRate);
    c->ratePeriod = rl_value(1.0, VR_setChangeRate);
    c->duration = rl_value(0.0, 0);
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

static void model_publish(const RlState *block, const RlPrepared *prepared, int modelMode, RlPlan *plan, double *v) {
    (void)prepared;
    (void)modelMode;
    (void)plan;
    v[VR_delayedValue] = block->y;
}

static const FmuStatusOutputs statusOutputs = { VR_error, VR_status, VR_subFunctionStatus };

FMU_MODEL(VR_value, VR_delayedValue, model_configure, model_publish, &statusOutputs);
