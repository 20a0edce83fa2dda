/* LGF_LimRateOfChangeAdvancedCI (Siemens; docs/models.md,
 * LGF_LimRateOfChangeAdvancedCI): rates per quadrant (per second, 0 holds), output limits, and the modes reset,
 * manOp, enDefaultOutValue and track (first match wins), each of which
 * sets the output as a bypass does; the output starts at 0, not limited. */
#include "LGF_LimRateOfChangeAdvancedCI_variables.h"
#include "siemens.h"

enum { MODE_RAMP, MODE_RESET, MODE_MANUAL, MODE_DEFAULT, MODE_TRACK };

static int model_configure(const double *v, RlConfig *c) {
    c->rateUp = rl_value(v[VR_setPosUpRateLim], VR_setPosUpRateLim);
    c->rateDown = rl_value(v[VR_setPosDownRateLim], VR_setPosDownRateLim);
    /* named by the output's magnitude: negUp falls below 0, negDown rises */
    c->rateDownNeg = rl_value(v[VR_setNegUpRateLim], VR_setNegUpRateLim);
    c->rateUpNeg = rl_value(v[VR_setNegDownRateLim], VR_setNegDownRateLim);
    c->ratePeriod = rl_value(1.0, VR_setPosUpRateLim);
    c->yMax = rl_value(v[VR_setHighLim], VR_setHighLim);
    c->yMin = rl_value(v[VR_setLowLim], VR_setLowLim);
    c->hold = false;
    c->duration = rl_value(0.0, 0);
    siemens_cycle(c, v[VR_callOB], VR_callOB, v[VR_cycleTime], VR_cycleTime);
    int mode;
    if (v[VR_reset] != 0) {
        mode = MODE_RESET;
        c->bypassValue = v[VR_enDefaultOutValue] != 0 ? v[VR_defaultOutValue] : 0.0;
    } else if (v[VR_manOp] != 0) {
        mode = MODE_MANUAL;
        c->bypassValue = v[VR_manualValue];
    } else if (v[VR_enDefaultOutValue] != 0) {
        mode = MODE_DEFAULT;
        c->bypassValue = v[VR_defaultOutValue];
    } else if (v[VR_track] != 0) {
        mode = MODE_TRACK;
        c->bypassValue = NAN; /* the output is u itself, autoValue, in every cycle */
    } else {
        mode = MODE_RAMP;
        c->bypassValue = NAN;
    }
    c->bypass = mode != MODE_RAMP;
    c->zeroRate = RL_ZERO_RATE_HOLD;
    c->initMode = RL_INIT_VALUE;
    c->initValue = 0.0;
    c->initDelay = 0.0;
    c->passNonFinite = false;
    c->limitInitialOutput = false;
    c->real = false;
    return mode;
}

static void model_publish(const RlState *block, const RlPrepared *prepared, int modelMode, RlPlan *plan, double *v) {
    RlOutputs o;
    rl_outputs(block, prepared, plan, &o);
    /* the quadrant of the output the rate was picked by */
    const bool negative = isless(block->yPrevious, 0);
    const bool reset = modelMode == MODE_RESET;
    v[VR_outputValue] = block->y;
    v[VR_posUpRateLim] = o.limitingUp && !negative;
    v[VR_posDownRateLim] = o.limitingDown && !negative;
    v[VR_negUpRateLim] = o.limitingDown && negative;
    v[VR_negDownRateLim] = o.limitingUp && negative;
    v[VR_highLim] = o.highLimit && !reset;
    v[VR_lowLim] = o.lowLimit && !reset;
}

static const FmuStatusOutputs statusOutputs = { VR_error, VR_status, VR_subfunctionStatus };

FMU_MODEL(VR_autoValue, VR_outputValue, model_configure, model_publish, &statusOutputs);
