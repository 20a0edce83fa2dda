#include "rate_limiter.h"

#include <float.h>
#include <math.h>

RlValue rl_resolve(double input, int inputSource, double parameter, int parameterSource) {
    RlValue resolved;
    if (isnan(input)) {
        resolved.value = parameter;
        resolved.source = parameterSource;
    } else {
        resolved.value = input;
        resolved.source = inputSource;
    }
    return resolved;
}

void rl_without_section6(RlConfig *c) {
    c->rateUpNeg = c->rateUp;
    c->rateDownNeg = c->rateDown;
    c->yMax = c->yMin = rl_value(NAN, 0);
    c->hold = false;
    c->limitInitialOutput = false;
    c->accelMax = c->decelMax = rl_value(0.0, 0);
}

int rl_status(const RlConfig *c, int *source) {
    const RlValue *culprit = 0;
    int status = RL_STATUS_OK;

    const RlValue *rates[4] = { &c->rateUp, &c->rateDown, &c->rateUpNeg, &c->rateDownNeg };
    for (int i = 0; i < 4 && !culprit; i++) {
        if (isless(rates[i]->value, 0)) {
            status = RL_STATUS_RATE_NEGATIVE;
            culprit = rates[i];
        }
    }
    for (int i = 0; i < 4 && !culprit; i++) {
        if (isnan(rates[i]->value)) {
            status = RL_STATUS_RATE_NAN;
            culprit = rates[i];
        }
    }
    if (culprit) {
        /* the first match above */
    } else if (!isgreaterequal(c->ratePeriod.value, 0) || !isfinite(c->ratePeriod.value)) {
        status = RL_STATUS_RATE_PERIOD;
        culprit = &c->ratePeriod;
    } else if (!isgreaterequal(c->duration.value, 0)) {
        status = RL_STATUS_DURATION;
        culprit = &c->duration;
    } else if (isgreater(rl_low_limit(c->yMin.value), rl_high_limit(c->yMax.value))) {
        status = RL_STATUS_LIMITS;
        culprit = &c->yMin;
    } else if (!(isgreaterequal(c->accelMax.value, 0) && isfinite(c->accelMax.value))) {
        status = RL_STATUS_ACCELERATION;
        culprit = &c->accelMax;
    } else if (!(isgreaterequal(c->decelMax.value, 0) && isfinite(c->decelMax.value))) {
        status = RL_STATUS_ACCELERATION;
        culprit = &c->decelMax;
    } else if (c->cycleRefused || !isgreaterequal(c->cycleTime.value, 0) || !isfinite(c->cycleTime.value)) {
        status = RL_STATUS_NO_CYCLE;
        culprit = &c->cycleTime;
    }
    *source = culprit ? culprit->source : 0;
    return status;
}

/* Per-cycle limit of one direction; a rate of 0 holds or does not limit. */
static double cycle_limit(double rate, const RlConfig *c, double period) {
    if (rate == 0) {
        return c->zeroRate == RL_ZERO_RATE_NO_LIMIT ? INFINITY : 0.0;
    }
    return c->real ? rl_per_cycle_real(rate, period, c->ratePeriod.value)
                   : rl_per_cycle_lreal(rate, period, c->ratePeriod.value);
}

/* x * T * T, left to right, in the arithmetic */
static double cycle_square(double x, const RlConfig *c, double period) {
    if (c->real) {
        const float t = rl_binary32(period);
        return (double)rl_product_real(rl_product_real((float)x, t), t);
    }
    return rl_product(rl_product(x, period), period);
}

static double binary32(double x) {
    return (double)rl_binary32(x);
}

static RlValue binary32_value(RlValue v) {
    v.value = binary32(v.value);
    return v;
}

/* REAL: the values that enter the signal path, rounded once here (rules.md,
 * Arithmetic); times (duration, cycleTime, initDelay) stay binary64. */
static RlConfig entered(const RlConfig *c) {
    RlConfig r = *c;
    if (c->real) {
        r.rateUp = binary32_value(c->rateUp);
        r.rateDown = binary32_value(c->rateDown);
        r.rateUpNeg = binary32_value(c->rateUpNeg);
        r.rateDownNeg = binary32_value(c->rateDownNeg);
        r.yMax = binary32_value(c->yMax);
        r.yMin = binary32_value(c->yMin);
        r.ratePeriod = binary32_value(c->ratePeriod);
        r.bypassValue = binary32(c->bypassValue);
        r.initValue = binary32(c->initValue);
        r.accelMax = binary32_value(c->accelMax);
        r.decelMax = binary32_value(c->decelMax);
    }
    return r;
}

void rl_prepare(RlPrepared *p, const RlConfig *config, double period) {
    p->config = entered(config);
    const RlConfig *c = &p->config;
    p->period = period;
    p->status = rl_status(c, &p->statusSource);
    p->maxUp = cycle_limit(c->rateUp.value, c, period);
    p->maxDown = cycle_limit(c->rateDown.value, c, period);
    p->maxUpNeg = cycle_limit(c->rateUpNeg.value, c, period);
    p->maxDownNeg = cycle_limit(c->rateDownNeg.value, c, period);
    /* binary32 values in REAL, so exact; LREAL never reads them */
    p->maxUpReal = c->real ? (float)p->maxUp : 0.0f;
    p->maxDownReal = c->real ? (float)p->maxDown : 0.0f;
    p->yLow = rl_low_limit(c->yMin.value);
    p->yHigh = rl_high_limit(c->yMax.value);
    p->durationReached = c->duration.value * (1.0 - RL_TIME_TOLERANCE);
    p->initDelayEnd = c->initDelay + RL_TIME_TOLERANCE * period;
    /* The fast paths (rl_cycle, rl_run, fmu_step_fast) run rule 6 alone
     * while plain, towards u itself at maxUp and maxDown: every rule before
     * 6 that can decide a cycle with a finite u and y (2 bypass, 3 delayed
     * init, 5 error hold, 5b hold, and any new one) and everything that
     * makes rule 6 ramp otherwise (output limits, other limits below 0)
     * must clear it here; so must a per-cycle limit too large for the
     * unchecked sums of the steady paths (RL_STEADY_BELOW). */
    /* the acceleration limit's steps per cycle, accelMax * T * T */
    p->accelLimited = isgreater(c->accelMax.value, 0) && !rl_status_is_error(p->status);
    const double decelMax = isgreater(c->decelMax.value, 0) ? c->decelMax.value : c->accelMax.value;
    p->accelStep = p->accelLimited ? cycle_square(c->accelMax.value, c, period) : 0.0;
    p->decelStep = p->accelLimited ? cycle_square(decelMax, c, period) : 0.0;
    p->plain = !p->accelLimited && !c->bypass && c->initMode != RL_INIT_INPUT_DELAYED &&
               !rl_status_is_error(p->status) && !c->hold && p->yLow == -INFINITY && p->yHigh == INFINITY &&
               p->maxUpNeg == p->maxUp && p->maxDownNeg == p->maxDown && rl_steady_limit(p->maxUp) &&
               rl_steady_limit(p->maxDown);
    p->durationLimited = isgreater(c->duration.value, 0);
}

static void running_reset(RlState *s) {
    s->runCycles = 0;
    s->runBase = 0.0;
}

void rl_init(RlState *s, const RlPrepared *p, double u) {
    const RlConfig *c = &p->config;
    u = rl_input(p, u);
    double y = c->initMode == RL_INIT_VALUE ? c->initValue : u;
    /* within the limits that are set, unless they are inverted */
    const double low = p->yLow, high = p->yHigh;
    if (c->limitInitialOutput && isfinite(y) && !isgreater(low, high)) {
        if (isless(y, low)) y = low;
        if (isgreater(y, high)) y = high;
    }
    s->y = y;
    s->yPrevious = y;
    s->yBefore = y;
    s->periodLast = s->periodBefore = 0.0;
    s->decided = RL_DECIDED_NOTHING;
    s->uPrevious = u;
    s->runCycles = 0;
    s->runPeriod = 0.0;
    s->runBase = 0.0;
}

void rl_cycle_rules(RlState *s, const RlPrepared *p, double u, double elapsed) {
    const RlConfig *c = &p->config;
    double y;

    if (c->passNonFinite && !isfinite(u)) {
        y = u;
        running_reset(s);
    } else if (c->bypass) {
        y = isfinite(c->bypassValue) ? c->bypassValue : u;
        running_reset(s);
    } else if (c->initMode == RL_INIT_INPUT_DELAYED && islessequal(elapsed, p->initDelayEnd)) {
        y = u;
        running_reset(s);
    } else if (!isfinite(s->y) && isfinite(u)) {
        y = u;
        running_reset(s);
    } else if (rl_status_is_error(p->status)) {
        y = s->y;
    } else if (c->hold) {
        /* rule 5b: y and runningTime as they are */
        s->decided = RL_DECIDED_HOLD;
        rl_shift(s, p->period);
        s->yPrevious = s->y;
        s->uPrevious = u;
        return;
    } else {
        rl_ramp(s, p, u);
        return;
    }
    s->decided = RL_DECIDED_OTHER;
    rl_shift(s, p->period);
    s->yPrevious = s->y;
    s->y = y;
    s->uPrevious = u;
}

void rl_run(RlState *s, const RlPrepared *p, double u, uint64_t first, uint64_t last, double cycleTime) {
    if (first > last) {
        return;
    }
    u = rl_input(p, u);
    rl_cycle_entered(s, p, u, (double)first * cycleTime);
    if (!rl_only_ramps(s, p, u)) {
        for (uint64_t n = first + 1; n <= last; n++) {
            rl_cycle_entered(s, p, u, (double)n * cycleTime);
        }
        return;
    }
    /* u held and only rule 6 applies, towards u at maxUp and maxDown
     * (plain): after the first cycle uPrevious is u and runPeriod is T, so
     * each cycle is rl_ramp without its resets; once y reaches u nothing
     * changes any more (and yPrevious is y too). */
    if (p->config.real) {
        rl_run_steady_real(s, p, u, first, last);
    } else {
        rl_run_steady_lreal(s, p, u, first, last);
    }
    if (last > first) {
        s->decided = RL_DECIDED_RAMP; /* cycles first + 1 .. last */
    }
}

const char *rl_status_text(int status) {
    switch (status) {
    case RL_STATUS_OK: return "no error";
    case RL_STATUS_RATE_NEGATIVE: return "a rate is negative";
    case RL_STATUS_RATE_NAN: return "a rate is NaN after falling back to its parameter";
    case RL_STATUS_RATE_PERIOD: return "ratePeriod is negative or not finite";
    case RL_STATUS_DURATION: return "duration is negative, or NaN after falling back to its parameter";
    case RL_STATUS_LIMITS: return "yMin is above yMax";
    case RL_STATUS_ACCELERATION: return "accelMax or decelMax is negative or not finite";
    case RL_STATUS_NO_CYCLE: return "no valid cycle configured";
    default: return "unknown status";
    }
}

/* One leg of the remaining way: length at rate (change per ratePeriod), in
 * seconds; a held direction never arrives, an unlimited one at once. */
static double leg_time(double length, double rate, const RlPrepared *p) {
    const RlConfig *c = &p->config;
    if (length == 0) {
        return 0.0;
    }
    if (rate == 0) {
        return c->zeroRate == RL_ZERO_RATE_NO_LIMIT ? 0.0 : INFINITY;
    }
    const double perSecond = isgreater(c->ratePeriod.value, 0) ? rl_quotient(rate, c->ratePeriod.value)
                                                               : rl_quotient(rate, p->period);
    /* a rate that underflows to 0 per second takes for ever, as IEEE has it */
    return perSecond == 0 ? INFINITY : rl_quotient(length, perSecond);
}

/* The time from y to uc at the current rates (rules.md, Outputs derived
 * from the last cycle): the part of the way below 0 at the Neg rate, the
 * rest at the other. */
static double remaining_time(const RlState *s, const RlPrepared *p, double y, double uc) {
    const RlConfig *c = &p->config;
    double below, above, total;
    if (uc > y) {
        below = y < 0 ? (uc < 0 ? uc : 0.0) - y : 0.0;
        above = uc > 0 ? uc - (y > 0 ? y : 0.0) : 0.0;
        total = rl_sum(leg_time(below, c->rateUpNeg.value, p), leg_time(above, c->rateUp.value, p));
    } else {
        below = uc < 0 ? (y < 0 ? y : 0.0) - uc : 0.0;
        above = y > 0 ? y - (uc > 0 ? uc : 0.0) : 0.0;
        total = rl_sum(leg_time(below, c->rateDownNeg.value, p), leg_time(above, c->rateDown.value, p));
    }
    if (p->durationLimited) {
        const double left = c->duration.value - rl_running_time(s);
        const double cap = left > 0 ? left : 0.0;
        if (cap < total) total = cap;
    }
    return total;
}

/* With the acceleration limit the time to uc is the block's own plan: its
 * cycles run ahead on a copy at constant inputs, counted (rules.md). A
 * plan that does not arrive within RL_PLAN_CYCLES, or stalls (a step that
 * does not move the output from rest), gives +inf. A kept plan (RlPlan)
 * is followed instead of made again while the state is one of its cycles:
 * the same count, exactly, at the cost of the cycles run since. */
#define RL_PLAN_CYCLES 67108864.0 /* 2^26 */

static bool same_double(double a, double b) {
    return memcmp(&a, &b, sizeof a) == 0; /* bit for bit: -0.0 and NaN payloads too */
}

/* What rule 6's next cycles depend on: equal in a and b */
static bool same_course(const RlState *a, const RlState *b, const RlPrepared *p) {
    return same_double(a->y, b->y) && same_double(a->yPrevious, b->yPrevious) && same_double(a->yBefore, b->yBefore) &&
           same_double(a->uPrevious, b->uPrevious) && a->decided == b->decided &&
           same_double(a->periodLast, b->periodLast) && same_double(a->periodBefore, b->periodBefore) &&
           (!p->durationLimited || (a->runCycles == b->runCycles && same_double(a->runPeriod, b->runPeriod) &&
                                    same_double(a->runBase, b->runBase)));
}

/* plan->end one cycle on at most RL_PLAN_CYCLES from plan->at, until it
 * reaches uc or stalls. */
static void plan_ahead(RlPlan *plan, const RlPrepared *p) {
    RlState *end = &plan->end;
    while (end->y != plan->uc && !plan->stalled && plan->planned < RL_PLAN_CYCLES) {
        const double before = end->y;
        const bool atRest = end->decided != RL_DECIDED_RAMP || end->y == end->yPrevious;
        rl_ramp(end, p, plan->at.uPrevious);
        plan->planned += 1;
        plan->work += 1;
        plan->stalled = atRest && end->y == before;
    }
}

/* Whether now is the plan's state after the cycles the block ran since
 * plan->at (rule 6 counts them in runCycles): plan->at moves there. */
static bool plan_followed(RlPlan *plan, const RlState *now, const RlPrepared *p) {
    if (same_course(&plan->at, now, p)) return true;
    if (now->runPeriod != plan->at.runPeriod || now->runCycles <= plan->at.runCycles ||
        !same_double(now->uPrevious, plan->at.uPrevious)) {
        return false;
    }
    const uint64_t ran = now->runCycles - plan->at.runCycles;
    if ((double)ran > plan->planned) return false;
    RlState course = plan->at;
    for (uint64_t n = 0; n < ran; n++) rl_ramp(&course, p, plan->at.uPrevious);
    plan->work += (double)ran;
    if (!same_course(&course, now, p)) return false;
    plan->at = *now;
    plan->planned -= (double)ran;
    return true;
}

static double planned_time(const RlState *s, const RlPrepared *p, RlPlan *kept, double uc) {
    RlState now = *s;
    if (now.decided == RL_DECIDED_HOLD) now.decided = RL_DECIDED_OTHER; /* hold stops the output */
    RlPlan fresh;
    RlPlan *plan = kept ? kept : &fresh;
    if (!kept || !kept->valid || !same_double(kept->uc, uc) || memcmp(&kept->prepared, p, sizeof *p) != 0 ||
        !plan_followed(kept, &now, p)) {
        plan->valid = true;
        plan->stalled = false;
        plan->at = plan->end = now;
        plan->planned = 0;
        plan->uc = uc;
        plan->prepared = *p;
    }
    plan_ahead(plan, p);
    return plan->end.y == uc && !plan->stalled ? rl_product(plan->planned, p->period) : INFINITY;
}

void rl_outputs(const RlState *s, const RlPrepared *p, RlPlan *plan, RlOutputs *o) {
    const double y = s->y, yp = s->yPrevious;
    const double uc = rl_target(s->uPrevious, p);
    const bool ramped = s->decided == RL_DECIDED_RAMP;
    const bool jumped = p->durationLimited && isgreaterequal(rl_running_time(s), p->durationReached);
    const bool negative = isless(yp, 0);
    const bool real = p->config.real;
    const double maxUp = negative ? p->maxUpNeg : p->maxUp, maxDown = negative ? p->maxDownNeg : p->maxDown;
    o->rampActive = ramped && y != uc;
    if (p->accelLimited) {
        /* the step is at the velocity limit, short of uc */
        o->limitingUp = ramped && !jumped && isless(y, uc) &&
                        (real ? rl_at_limit_real(yp, maxUp, y) : rl_at_limit_lreal(yp, maxUp, y));
        o->limitingDown = ramped && !jumped && isgreater(y, uc) &&
                          (real ? rl_at_limit_real(yp, -maxDown, y) : rl_at_limit_lreal(yp, -maxDown, y));
    } else {
        o->limitingUp = ramped && !jumped && (real ? rl_cut_up_real(yp, maxUp, uc) : rl_cut_up_lreal(yp, maxUp, uc));
        o->limitingDown = ramped && !jumped &&
                          (real ? rl_cut_down_real(yp, maxDown, uc) : rl_cut_down_lreal(yp, maxDown, uc));
    }
    o->highLimit = isfinite(y) && isgreaterequal(y, p->yHigh);
    o->lowLimit = isfinite(y) && islessequal(y, p->yLow);
    o->dydt = s->decided != RL_DECIDED_NOTHING && isfinite(y) && isfinite(yp)
                  ? (real ? rl_dydt_real(y, yp, p->period) : rl_dydt_lreal(y, yp, p->period))
                  : 0.0;
    const bool remains = (ramped || s->decided == RL_DECIDED_HOLD) && y != uc && isfinite(y) && isfinite(uc);
    o->remainingTime = !remains ? 0.0 : p->accelLimited ? planned_time(s, p, plan, uc) : remaining_time(s, p, y, uc);
    o->d2ydt2 = !ramped || !isfinite(o->dydt) ? 0.0
                : real                        ? rl_d2ydt2_real(o->dydt, s, p->period)
                                              : rl_d2ydt2_lreal(o->dydt, s, p->period);
}
