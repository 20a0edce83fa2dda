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

int rl_status(const RlConfig *c, int *source) {
    const RlValue *culprit = 0;
    int status = RL_STATUS_OK;

    if (c->rateUp.value < 0) {
        status = RL_STATUS_RATE_NEGATIVE; culprit = &c->rateUp;
    } else if (c->rateDown.value < 0) {
        status = RL_STATUS_RATE_NEGATIVE; culprit = &c->rateDown;
    } else if (isnan(c->rateUp.value)) {
        status = RL_STATUS_RATE_NAN; culprit = &c->rateUp;
    } else if (isnan(c->rateDown.value)) {
        status = RL_STATUS_RATE_NAN; culprit = &c->rateDown;
    } else if (!(c->ratePeriod.value >= 0) || !isfinite(c->ratePeriod.value)) {
        status = RL_STATUS_RATE_PERIOD; culprit = &c->ratePeriod;
    } else if (!(c->duration.value >= 0)) {
        status = RL_STATUS_DURATION; culprit = &c->duration;
    } else if (!(c->cycleTime.value >= 0) || !isfinite(c->cycleTime.value)) {
        status = RL_STATUS_NO_CYCLE; culprit = &c->cycleTime;
    }
    *source = culprit ? culprit->source : 0;
    return status;
}

/* Per-cycle limit of one direction; a rate of 0 holds or does not limit. */
static double cycle_limit(double rate, const RlConfig *c, double period) {
    if (rate == 0) {
        return c->zeroRate == RL_ZERO_RATE_NO_LIMIT ? INFINITY : 0.0;
    }
    if (c->ratePeriod.value > 0) {
        return rate * period / c->ratePeriod.value;
    }
    return rate;
}

void rl_prepare(RlPrepared *p, const RlConfig *c, double period) {
    p->config = *c;
    p->period = period;
    p->status = rl_status(c, &p->statusSource);
    p->maxUp = cycle_limit(c->rateUp.value, c, period);
    p->maxDown = cycle_limit(c->rateDown.value, c, period);
    p->durationReached = c->duration.value * (1.0 - RL_TIME_TOLERANCE);
    p->initDelayEnd = c->initDelay + RL_TIME_TOLERANCE * period;
    /* The fast paths (rl_cycle, rl_run, fmu_step_fast) run rule 6 alone
     * while plain: every rule before 6 that can decide a cycle with a
     * finite u and y (2 bypass, 3 delayed init, 5 error hold, and any new
     * one) must clear it here. */
    p->plain = !c->bypass && c->initMode != RL_INIT_INPUT_DELAYED && p->status < 0x8000;
    p->durationLimited = c->duration.value > 0;
}

static void running_reset(RlState *s) {
    s->runCycles = 0;
    s->runBase = 0.0;
}

void rl_init(RlState *s, const RlConfig *c, double u) {
    s->y = c->initMode == RL_INIT_VALUE ? c->initValue : u;
    s->uPrevious = u;
    s->rampActive = false;
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
    } else if (c->initMode == RL_INIT_INPUT_DELAYED && elapsed <= p->initDelayEnd) {
        y = u;
        running_reset(s);
    } else if (!isfinite(s->y) && isfinite(u)) {
        y = u;
        running_reset(s);
    } else if (p->status >= 0x8000) {
        y = s->y;
    } else {
        rl_ramp(s, p, u);
        return;
    }
    s->rampActive = false;
    s->y = y;
    s->uPrevious = u;
}

void rl_run(RlState *s, const RlPrepared *p, double u, uint64_t first, uint64_t last, double cycleTime) {
    if (first > last) {
        return;
    }
    rl_cycle(s, p, u, (double)first * cycleTime);
    if (!rl_only_ramps(s, p, u)) {
        for (uint64_t n = first + 1; n <= last; n++) {
            rl_cycle(s, p, u, (double)n * cycleTime);
        }
        return;
    }
    /* u held and only rule 6 applies: after the first cycle uPrevious is u
     * and runPeriod is T, so each cycle is rl_ramp without its resets; once
     * y reaches u nothing changes any more. */
    double y = s->y;
    uint64_t cycles = s->runCycles;
    for (uint64_t n = first + 1; n <= last && y != u; n++) {
        cycles++;
        if (p->durationLimited && s->runBase + (double)cycles * s->runPeriod >= p->durationReached) {
            y = u;
        } else {
            y = rl_step_towards(y, u, p);
        }
    }
    s->y = y;
    s->runCycles = cycles;
    s->rampActive = y != u;
}

const char *rl_status_text(int status) {
    switch (status) {
    case RL_STATUS_OK: return "no error";
    case RL_STATUS_RATE_NEGATIVE: return "a rate is negative";
    case RL_STATUS_RATE_NAN: return "a rate is NaN after falling back to its parameter";
    case RL_STATUS_RATE_PERIOD: return "ratePeriod is negative or not finite";
    case RL_STATUS_DURATION: return "duration is negative, or NaN after falling back to its parameter";
    case RL_STATUS_NO_CYCLE: return "no valid cycle configured";
    default: return "unknown status";
    }
}
