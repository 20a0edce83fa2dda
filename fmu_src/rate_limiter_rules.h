/* The kernel's arithmetic over one value type RL_NUM, one source compiled
 * twice: rate_limiter.h includes it with RL_NUM double (names ending
 * _lreal) and float (_real), rules.md, Arithmetic. Outside these functions the
 * block keeps its values as doubles (state, limits, configuration): in
 * REAL they are binary32 values widened, so the conversions here are exact
 * and every operation below is one RL_NUM operation, rounded as C rounds
 * it with FLT_EVAL_METHOD 0, in the order rules.md writes them. No include
 * guard: it is meant to be included once per type, and it undefines its
 * parameters (RL_NUM ... RL_MAX_DOWN) at the end. */

#define RL_NAME(name) RL_NAME_(name, RL_SUFFIX)
#define RL_NAME_(name, suffix) RL_NAME__(name, suffix)
#define RL_NAME__(name, suffix) name##suffix

/* Rule 0's per-cycle limit of a rate other than 0: rate * T / ratePeriod
 * left to right, or the rate itself per cycle. */
static inline double RL_NAME(rl_per_cycle)(double rate, double period, double ratePeriod) {
    if (isgreater(ratePeriod, 0)) {
        if (!isfinite(ratePeriod)) return rate; /* status 16#8202: the block holds, the limit is not used */
        return (double)RL_NAME(rl_quotient)(RL_NAME(rl_product)((RL_NUM)rate, RL_ENTER(period)), (RL_NUM)ratePeriod);
    }
    return rate;
}

/* Rule 6's step of y towards the target at the per-cycle limits, never
 * past it: every path that ramps (rl_ramp_cycle, rl_run's sub-cycles, and
 * through them the FMUs' common step) takes it from here. */
/* steady (a constant): the operands are steady values (RL_STEADY_BELOW),
 * so the sums are unchecked; else they are quiet, and so are the
 * comparisons with the target, which a Siemens block's NaN input reaches
 * (neither holds: y stays). Inside a branch nothing is NaN. */
static inline RL_NUM RL_NAME(rl_step_towards)(RL_NUM y, RL_NUM target, RL_NUM maxUp, RL_NUM maxDown, bool steady) {
    if (steady ? target > y : isgreater(target, y)) {
        const RL_NUM limited = steady ? y + maxUp : RL_NAME(rl_sum)(y, maxUp);
        return limited < target ? limited : target;
    }
    if (steady ? target < y : isless(target, y)) {
        const RL_NUM limited = steady ? y - maxDown : RL_NAME(rl_sum)(y, -maxDown);
        return limited > target ? limited : target;
    }
    return y;
}

/* The common step's limited step of steady operands (the cycle's
 * direction chosen by the caller): y and the limits are values of the
 * arithmetic widened, so their binary64 sum rounded to the arithmetic once
 * is the arithmetic's own sum (binary64 holds 2 * 24 + 2 bits), compared
 * with the target in the arithmetic, where both are. Nothing here is NaN
 * (RL_STEADY_BELOW): the comparisons are quiet. */
static inline double RL_NAME(rl_step_up)(double y, RL_NUM target, double maxUp) {
    const RL_NUM limited = (RL_NUM)(y + maxUp);
    return (double)(limited < target ? limited : target);
}

static inline double RL_NAME(rl_step_down)(double y, RL_NUM target, double maxDown) {
    const RL_NUM limited = (RL_NUM)(y - maxDown);
    return (double)(limited > target ? limited : target);
}

/* Rule 6: ramp towards uc at the limits picked by the output's sign, or
 * jump to uc once the duration has run out. u has entered the block's
 * arithmetic (rl_input). */
static inline void RL_NAME(rl_ramp_cycle)(RlState *s, const RlPrepared *p, double u) {
    const double ypHeld = s->y;
    const RL_NUM yp = (RL_NUM)ypHeld;
    const bool negative = isless(yp, 0);
    const RL_NUM target = (RL_NUM)rl_target(u, p);
    RL_NUM y = yp;
    /* a u equal to uPrevious (a zero of the other sign included: nothing
     * tells them apart) is not stored, so that a held u costs no store */
    if (u != s->uPrevious) {
        s->runCycles = 0;
        s->runBase = 0.0;
        s->uPrevious = u;
    }
    if (y != target) {
        if (p->period != s->runPeriod) rl_period_changed(s, p->period);
        s->runCycles++;
    }
    if (p->durationLimited && rl_running_time(s) >= p->durationReached) { /* both finite */
        y = target;
    } else {
        y = RL_NAME(rl_step_towards)(y, target, negative ? (RL_NUM)p->maxUpNeg : RL_MAX_UP(p),
                                     negative ? (RL_NUM)p->maxDownNeg : RL_MAX_DOWN(p), false);
    }
    s->decided = RL_DECIDED_RAMP;
    s->yPrevious = ypHeld;
    s->y = (double)y;
}

/* The common step's cycle: false (nothing done) if u is not a steady value
 * (RL_STEADY_BELOW: finite in either arithmetic, its sums too), else
 * rl_ramp_cycle, the direction compared once (rl_step_up, rl_step_down),
 * for what the caller has checked: the configuration plain (uc is u, the limits the same for both
 * signs), y steady, runPeriod p->period (rl_hold_period) and rule 6 decided
 * the last cycle, which spares the checks, the conversions and the stores
 * of decided and runPeriod. */
static inline bool RL_NAME(rl_ramp_steady)(RlState *s, const RlPrepared *p, double uIn) {
    if (!rl_steady_value(uIn)) {
        return false;
    }
    const RL_NUM target = (RL_NUM)uIn;
    const double u = (double)target, yp = s->y;
    if (u != s->uPrevious) {
        s->runCycles = 0;
        s->runBase = 0.0;
        s->uPrevious = u;
    }
    double y = yp;
    if (u > yp) {
        s->runCycles++;
        y = RL_NAME(rl_step_up)(yp, target, p->maxUp);
    } else if (u < yp) {
        s->runCycles++;
        y = RL_NAME(rl_step_down)(yp, target, p->maxDown);
    }
    if (p->durationLimited && rl_running_time(s) >= p->durationReached) {
        y = u;
    }
    s->y = y;
    s->yPrevious = yp;
    return true;
}

/* rl_run's cycles after the first, u held and plain: each is rule 6
 * without its resets; once y reaches u nothing changes any more. */
static inline void RL_NAME(rl_run_steady)(RlState *s, const RlPrepared *p, double uHeld, uint64_t first, uint64_t last) {
    const RL_NUM u = (RL_NUM)uHeld, maxUp = RL_MAX_UP(p), maxDown = RL_MAX_DOWN(p);
    RL_NUM y = (RL_NUM)s->y, yp = (RL_NUM)s->yPrevious;
    uint64_t cycles = s->runCycles;
    uint64_t n = first + 1;
    for (; n <= last && y != u; n++) {
        cycles++;
        yp = y;
        if (p->durationLimited && s->runBase + (double)cycles * s->runPeriod >= p->durationReached) {
            y = u;
        } else {
            y = RL_NAME(rl_step_towards)(y, u, maxUp, maxDown, true);
        }
    }
    if (n <= last) {
        yp = y; /* cycles that found y at u */
    }
    s->y = (double)y;
    s->yPrevious = (double)yp;
    s->runCycles = cycles;
}

/* The derived outputs that compute: dydt = (y - yp) / T, and whether the
 * step's limit cut it (yp + maxUp < uc, yp - maxDown > uc). */
static inline double RL_NAME(rl_dydt)(double y, double yp, double period) {
    return (double)RL_NAME(rl_quotient)(RL_NAME(rl_sum)((RL_NUM)y, -(RL_NUM)yp), RL_ENTER(period));
}

static inline bool RL_NAME(rl_cut_up)(double yp, double maxUp, double uc) {
    return isless(RL_NAME(rl_sum)((RL_NUM)yp, (RL_NUM)maxUp), (RL_NUM)uc);
}

static inline bool RL_NAME(rl_cut_down)(double yp, double maxDown, double uc) {
    return isgreater(RL_NAME(rl_sum)((RL_NUM)yp, -(RL_NUM)maxDown), (RL_NUM)uc);
}

#undef RL_NAME
#undef RL_NAME_
#undef RL_NAME__
#undef RL_NUM
#undef RL_SUFFIX
#undef RL_ENTER
#undef RL_MAX_UP
#undef RL_MAX_DOWN
