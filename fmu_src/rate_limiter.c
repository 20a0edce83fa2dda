#include "rate_limiter.h"

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
}

static void running_reset(RlState *s) {
    s->runCycles = 0;
    s->runBase = 0.0;
}

static void running_add(RlState *s, double period) {
    if (period != s->runPeriod) {
        s->runBase += (double)s->runCycles * s->runPeriod;
        s->runCycles = 0;
        s->runPeriod = period;
    }
    s->runCycles++;
}

double rl_running_time(const RlState *s) {
    return s->runBase + (double)s->runCycles * s->runPeriod;
}

void rl_init(RlState *s, const RlConfig *c, double u) {
    s->y = c->initMode == RL_INIT_VALUE ? c->initValue : u;
    s->uPrevious = u;
    s->rampActive = false;
    s->runCycles = 0;
    s->runPeriod = 0.0;
    s->runBase = 0.0;
}

/* Rule 6: ramp towards u, or jump once the duration has run out. */
static double ramp(RlState *s, const RlPrepared *p, double u) {
    const double yp = s->y;

    if (u != s->uPrevious) {
        running_reset(s);
    }
    if (yp != u) {
        running_add(s, p->period);
    }
    if (p->config.duration.value > 0 && rl_running_time(s) >= p->durationReached) {
        return u;
    }
    if (u > yp) {
        const double limited = yp + p->maxUp;
        return limited < u ? limited : u;
    }
    if (u < yp) {
        const double limited = yp - p->maxDown;
        return limited > u ? limited : u;
    }
    return yp;
}

void rl_cycle(RlState *s, const RlPrepared *p, double u, double elapsed) {
    const RlConfig *c = &p->config;
    double y;
    bool ruled = false; /* decided by rule 6 */

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
        y = ramp(s, p, u);
        ruled = true;
    }

    s->rampActive = ruled && y != u;
    s->y = y;
    s->uPrevious = u;
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
