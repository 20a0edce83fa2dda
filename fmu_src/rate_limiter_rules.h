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

/* ---- The acceleration limit (rules.md, Acceleration limit) ----------------
 * Distances and steps per cycle, in the arithmetic; b > 0 is the largest
 * decrease of the step per cycle (decelStep), a the largest increase. */

/* The unit roundoff of the arithmetic and one unit in the last place of x
 * (finite): the allowances of the rules' rounding. */
#define RL_ROUNDOFF ((RL_NUM)ldexp(1.0, -RL_MANT_DIG))
static inline RL_NUM RL_NAME(rl_ulp)(RL_NUM x) {
    int e = RL_MIN_EXP;
    if (x != 0) (void)frexp((double)x, &e);
    return (RL_NUM)ldexp(1.0, (e > RL_MIN_EXP ? e : RL_MIN_EXP) - RL_MANT_DIG);
}

static inline RL_NUM RL_NAME(rl_min)(RL_NUM x, RL_NUM y) {
    return isless(y, x) ? y : x;
}

/* Beyond this many cycles of braking the counts below are not whole
 * numbers in the arithmetic: the continuous form stands in. */
#define RL_BRAKING_COUNTED ((RL_NUM)ldexp(1.0, RL_MANT_DIG / 2))

/* b * n * (n + 1) / 2, the distance of n braking steps after b, 2b, ...: quiet */
static inline RL_NUM RL_NAME(rl_triangle)(RL_NUM b, RL_NUM n) {
    return RL_NAME(rl_product)(RL_NAME(rl_product)(b, n), n + 1) / 2;
}

/* The distance braking needs from a step s >= 0: the steps s - j*b,
 * j = 1, 2, ..., while positive; n = floor(s / b) of them:
 * n * (s - b * (n + 1) / 2). */
static inline RL_NUM RL_NAME(rl_braking_distance)(RL_NUM s, RL_NUM b) {
    if (isinf(s)) return s;
    const RL_NUM n = (RL_NUM)floor((double)RL_NAME(rl_quotient)(s, b));
    return RL_NAME(rl_product)(n, RL_NAME(rl_sum)(s, -(RL_NAME(rl_product)(b, n + 1) / 2)));
}

/* The largest step s after which braking stops within the distance e >= 0
 * (finite): s + rl_braking_distance(s, b) = e. With n braking steps after
 * it, b * n * (n + 1) / 2 <= e < b * (n + 1) * (n + 2) / 2, and
 * s = e / (n + 1) + b / 2 * n. */
static inline RL_NUM RL_NAME(rl_stoppable_step)(RL_NUM e, RL_NUM b) {
    if (isinf(b)) return e;
    const RL_NUM q = RL_NAME(rl_quotient)(e, b);
    if (!isless(q, RL_BRAKING_COUNTED * RL_BRAKING_COUNTED)) {
        /* s * s / (2 * b) = e, less b for the cycles' head start */
        const RL_NUM root = RL_NAME(rl_product)(
            (RL_NUM)rl_binary32_or_not(sqrt(rl_product(2.0, (double)b)), sizeof(RL_NUM)), (RL_NUM)sqrt((double)e));
        const RL_NUM s = RL_NAME(rl_sum)(root, -b);
        return isgreater(s, 0) ? s : 0;
    }
    RL_NUM n = (RL_NUM)floor((sqrt(8 * (double)q + 1) - 1) / 2);
    if (isgreater(RL_NAME(rl_triangle)(b, n), e)) {
        n = n - 1;
    } else if (islessequal(RL_NAME(rl_triangle)(b, n + 1), e)) {
        n = n + 1;
    }
    return RL_NAME(rl_sum)(e / (n + 1), RL_NAME(rl_product)(b / 2, n));
}

/* The largest step s from a position z >= 0 before a zone boundary after
 * which braking brings the step down to v (the new zone's velocity limit)
 * before the boundary: the K steps above v (K = ceil((s - v) / b)) all
 * start before it, (K - 1) * s - b * (K - 1) * (K - 2) / 2 <= z. */
static inline RL_NUM RL_NAME(rl_zone_reach)(RL_NUM k, RL_NUM v, RL_NUM b) {
    /* how far K steps above v take the output: (K - 1) * v + b * K * (K - 1) / 2 */
    return RL_NAME(rl_sum)(RL_NAME(rl_product)(k - 1, v), RL_NAME(rl_triangle)(b, k - 1));
}

static inline RL_NUM RL_NAME(rl_zone_step)(RL_NUM z, RL_NUM v, RL_NUM b) {
    if (isinf(b) || isinf(v)) return (RL_NUM)INFINITY;
    const RL_NUM q = RL_NAME(rl_quotient)(z, b), w = RL_NAME(rl_quotient)(v, b);
    if (!isless(q, RL_BRAKING_COUNTED * RL_BRAKING_COUNTED) || !isless(w, RL_BRAKING_COUNTED)) {
        /* s * s = v * v + 2 * b * z, less b; in binary64, quiet */
        const double s2 = rl_sum(rl_product((double)v, (double)v), rl_product(rl_product(2.0, (double)b), (double)z));
        const RL_NUM s = RL_NAME(rl_sum)((RL_NUM)rl_binary32_or_not(sqrt(s2), sizeof(RL_NUM)), -b);
        return isgreater(s, v) ? s : v;
    }
    /* the largest K >= 1 with (K - 1) * w + K * (K - 1) / 2 <= q */
    RL_NUM k = (RL_NUM)floor(
        ((1 - 2 * (double)w) + sqrt((2 * (double)w - 1) * (2 * (double)w - 1) + 8 * ((double)w + (double)q))) / 2);
    if (k < 1) k = 1;
    if (k > 1 && isgreater(RL_NAME(rl_zone_reach)(k, v, b), z)) {
        k = k - 1;
    } else if (islessequal(RL_NAME(rl_zone_reach)(k + 1, v, b), z)) {
        k = k + 1;
    }
    if (k <= 1) return RL_NAME(rl_sum)(v, b);
    return RL_NAME(rl_min)(RL_NAME(rl_sum)(v, RL_NAME(rl_product)(k, b)),
                           RL_NAME(rl_sum)(z / (k - 1), RL_NAME(rl_product)(b / 2, k - 2)));
}

/* rl_stops_within in the arithmetic: exact where its bounds hold, else
 * the sum itself, rounded */
static inline bool RL_NAME(rl_stops_within)(RL_NUM s, RL_NUM b, RL_NUM e) {
    if (!isgreater(s, b)) return islessequal(s, e);
    if (isinf(b)) return islessequal(s, e);
    const double big = 1e300; /* below 2^1000 */
    if (isless((double)s, big) && isless((double)e, big) && isgreater((double)b, 1e-290) &&
        isless((double)RL_NAME(rl_quotient)(s, b), 67108864.0 /* 2^26 */)) {
        return rl_stops_within((double)s, (double)b, (double)e);
    }
    return islessequal(RL_NAME(rl_sum)(s, RL_NAME(rl_braking_distance)(s, b)), e);
}

/* y + delta in the arithmetic, but never past the exact sum: rounded
 * towards y where rounding to nearest went beyond it (a position or a step
 * further than planned would not stop in time). */
static inline RL_NUM RL_NAME(rl_advance)(RL_NUM y, RL_NUM delta) {
    if (!(isless(fabs((double)y), 1e300) && isless(fabs((double)delta), 1e300))) {
        return RL_NAME(rl_sum)(y, delta);
    }
    double error;
    const double exact = rl_two_sum((double)y, (double)delta, &error);     /* + error */
    const RL_NUM next = (RL_NUM)rl_binary32_or_not(exact, sizeof(RL_NUM)); /* y + delta, rounded once */
    const double beyond = ((double)next - exact) - error;
    if (isgreater(delta, 0) ? isgreater(beyond, 0) : isless(beyond, 0)) {
        return RL_NEXT_TOWARDS(next, y);
    }
    return next;
}

/* a + b in the arithmetic, rounded towards 0 (towardsZero) or away from 0
 * where rounding to nearest went the other way: a distance rounded up, or a
 * speed rounded down, would plan on room the output does not have. */
static inline RL_NUM RL_NAME(rl_directed_sum)(RL_NUM a, RL_NUM b, bool towardsZero) {
    if (!(isless(fabs((double)a), 1e300) && isless(fabs((double)b), 1e300))) {
        return RL_NAME(rl_sum)(a, b);
    }
    double error;
    const double exact = rl_two_sum((double)a, (double)b, &error);        /* + error */
    const RL_NUM sum = (RL_NUM)rl_binary32_or_not(exact, sizeof(RL_NUM)); /* a + b, rounded once */
    const double beyond = ((double)sum - exact) - error;                  /* sum - (a + b) */
    const bool away = isgreater(sum, 0) ? isgreater(beyond, 0) : isless(beyond, 0);
    const bool shortOf = isgreater(sum, 0) ? isless(beyond, 0) : isgreater(beyond, 0);
    if (towardsZero ? away : shortOf) {
        return RL_NEXT_TOWARDS(sum, towardsZero ? 0 : (RL_NUM)copysign(INFINITY, (double)sum));
    }
    return sum;
}

/* One cycle of rule 6 with the acceleration limit: the output y (finite)
 * moves towards the target uc (finite); previous is the last cycle's step
 * scaled to this cycle's length (0 from rest). The step is the largest the
 * bounds allow after which braking still stops at uc and slows to the
 * velocity limit of the zone beyond 0 before reaching it; it lands on uc
 * itself when within the rounding of it, and is otherwise rounded towards
 * y, so that rounding never takes the output further than planned. */
/* Out of line: rule 6's other paths stay small enough to inline. */
static FMU_NOINLINE FMU_MAYBE_UNUSED RL_NUM RL_NAME(rl_accel_step)(RL_NUM y, RL_NUM uc, RL_NUM previous,
                                                                   const RlPrepared *p) {
    const RL_NUM a = (RL_NUM)p->accelStep, b = (RL_NUM)p->decelStep;
    const RL_NUM e = RL_NAME(rl_directed_sum)(uc, -y, true);
    /* towards the target; at the target, the way the output moves */
    const bool up = isgreater(e, 0) || (e == 0 && isgreater(previous, 0));
    RL_NUM distance = up ? e : -e;
    if (isinf(distance)) distance = RL_NUM_MAX; /* the way is longer than the largest value */
    const RL_NUM moving = up ? previous : -previous;
    const bool negative = isless(y, 0);
    const RL_NUM limit = (RL_NUM)(up ? (negative ? p->maxUpNeg : p->maxUp) : (negative ? p->maxDownNeg : p->maxDown));
    RL_NUM step;
    if (isless(moving, 0) && isgreater(-moving, b)) {
        step = RL_NAME(rl_sum)(moving, b); /* still moving away: brake */
    } else {
        /* the fastest the bounds allow: accelerate, or turn within the cycle */
        RL_NUM fastest = !isless(moving, 0) ? RL_NAME(rl_sum)(moving, a)
                         : isinf(b)         ? a
                                    : RL_NAME(rl_product)(a, RL_NAME(rl_quotient)(RL_NAME(rl_sum)(b, moving), b));
        fastest = RL_NAME(rl_min)(fastest, limit);
        /* a slower zone ahead, before the target: slow down in time */
        const bool zoneAhead = up ? negative && !isless(uc, 0) : !negative && isless(uc, 0);
        if (zoneAhead) {
            const RL_NUM zoneLimit = (RL_NUM)(up ? p->maxUp : p->maxDownNeg);
            RL_NUM z = negative ? -y : y;
            z = RL_NAME(rl_sum)(z, -(RL_NAME(rl_product)(z, 8 * RL_ROUNDOFF) + (up ? 2 * RL_NAME(rl_ulp)(z) : 0)));
            if (isless(zoneLimit, fastest)) {
                fastest = isless(z, 0) ? zoneLimit : RL_NAME(rl_min)(fastest, RL_NAME(rl_zone_step)(z, zoneLimit, b));
            }
        }
        /* the target: stop at or before it, decided exactly */
        if (!RL_NAME(rl_stops_within)(fastest, b, distance)) {
            RL_NUM stoppable = RL_NAME(rl_stoppable_step)(distance, b);
            for (int i = 0; i < 8 && isgreater(stoppable, 0) && !RL_NAME(rl_stops_within)(stoppable, b, distance);
                 i++) {
                stoppable = RL_NEXT_TOWARDS(stoppable, 0); /* the step's rounding, taken back */
            }
            /* still too far (the formula's rounding beyond eight units): no step but braking's */
            if (!RL_NAME(rl_stops_within)(stoppable, b, distance)) stoppable = 0;
            fastest = RL_NAME(rl_min)(fastest, stoppable);
        }
        /* braking harder than b is not allowed: a target too close is passed */
        if (isgreater(moving, b)) {
            const RL_NUM braked = RL_NAME(rl_directed_sum)(moving, -b, true); /* rounded down */
            step = isless(fastest, braked) ? braked : fastest;
        } else {
            step = fastest;
        }
    }
    const RL_NUM scale = isgreater(fabs((double)uc), fabs((double)y)) ? uc : y;
    const RL_NUM arrival = 4 * RL_NAME(rl_ulp)(scale);
    if (islessequal(fabs((double)RL_NAME(rl_sum)(step, -distance)), (double)arrival)) {
        return uc;
    }
    /* at uc already, with the speed the rounding of the landing step left above b: at rest. The
     * landing planned up to 4 ulp(yp, uc) past b and snapped as much again; P, its difference, one
     * ulp more: 8 ulp(uc) + 4 ulp(P), within the bounds' allowance for the braking it takes */
    if (distance == 0 && isgreater(step, 0) &&
        islessequal((double)step, 4.0 * (double)RL_NAME(rl_ulp)(moving) + 8.0 * (double)RL_NAME(rl_ulp)(uc))) {
        return uc;
    }
    const RL_NUM next = RL_NAME(rl_advance)(y, up ? step : -step);
    if (next == y && isgreater(step, 0)) {
        /* a step below the output's resolution (REAL, or a large y): one
         * unit in the last place towards uc, within the bounds' allowance */
        return RL_NEXT_TOWARDS(y, uc);
    }
    return next;
}

/* The step of the last cycle, as the acceleration limit's velocity at this
 * cycle's length: 0 after a cycle that did not ramp or jumped. */
static inline RL_NUM RL_NAME(rl_previous_step)(const RlState *s, const RlPrepared *p) {
    if (s->decided != RL_DECIDED_RAMP || (p->durationLimited && rl_running_time(s) >= p->durationReached) ||
        !isfinite(s->y) || !isfinite(s->yPrevious)) {
        return 0;
    }
    const RL_NUM step = RL_NAME(rl_directed_sum)((RL_NUM)s->y, -(RL_NUM)s->yPrevious, false);
    if (s->periodLast == p->period || !isgreater(s->periodLast, 0)) {
        return step;
    }
    return RL_NAME(rl_product)(step, RL_NAME(rl_quotient)(RL_ENTER(p->period), RL_ENTER(s->periodLast)));
}

/* Rule 6's bookkeeping of runningTime: it restarts for a new u and counts
 * the cycle while y is not at the target. A u equal to uPrevious (a zero
 * of the other sign included: nothing tells them apart) is not stored, so
 * that a held u costs no store. */
static inline void RL_NAME(rl_count_running)(RlState *s, const RlPrepared *p, double u, RL_NUM y, RL_NUM target) {
    if (u != s->uPrevious) {
        s->runCycles = 0;
        s->runBase = 0.0;
        s->uPrevious = u;
    }
    if (y != target) {
        if (p->period != s->runPeriod) rl_period_changed(s, p->period);
        s->runCycles++;
    }
}

/* Rule 6 with the acceleration limit: out of line, so that the ramp
 * without it stays as small as it was. */
static FMU_NOINLINE FMU_MAYBE_UNUSED void RL_NAME(rl_accel_cycle)(RlState *s, const RlPrepared *p, double u) {
    const double ypHeld = s->y;
    const RL_NUM yp = (RL_NUM)ypHeld;
    const RL_NUM target = (RL_NUM)rl_target(u, p);
    const RL_NUM previous = RL_NAME(rl_previous_step)(s, p); /* before this cycle counts */
    RL_NAME(rl_count_running)(s, p, u, yp, target);
    const bool jump = p->durationLimited && rl_running_time(s) >= p->durationReached;
    rl_ramped(s, p->period, ypHeld, (double)(jump ? target : RL_NAME(rl_accel_step)(yp, target, previous, p)));
}

/* Rule 6: ramp towards uc at the limits picked by the output's sign, or
 * jump to uc once the duration has run out. u has entered the block's
 * arithmetic (rl_input). */
static inline void RL_NAME(rl_ramp_cycle)(RlState *s, const RlPrepared *p, double u) {
    if (p->accelLimited) {
        RL_NAME(rl_accel_cycle)(s, p, u);
        return;
    }
    const double ypHeld = s->y;
    const RL_NUM yp = (RL_NUM)ypHeld;
    const bool negative = isless(yp, 0);
    const RL_NUM target = (RL_NUM)rl_target(u, p);
    RL_NUM y = yp;
    RL_NAME(rl_count_running)(s, p, u, yp, target);
    if (p->durationLimited && rl_running_time(s) >= p->durationReached) { /* both finite */
        y = target;
    } else {
        y = RL_NAME(rl_step_towards)(y, target, negative ? (RL_NUM)p->maxUpNeg : RL_MAX_UP(p),
                                     negative ? (RL_NUM)p->maxDownNeg : RL_MAX_DOWN(p), false);
    }
    rl_ramped(s, p->period, ypHeld, (double)y);
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
    rl_shift_outputs(s); /* both cycles of p->period (fmu_step_fast) */
    s->y = y;
    return true;
}

/* rl_run's cycles after the first, u held and plain: each is rule 6
 * without its resets; once y reaches u nothing changes any more. */
static inline void RL_NAME(rl_run_steady)(RlState *s, const RlPrepared *p, double uHeld, uint64_t first,
                                          uint64_t last) {
    const RL_NUM u = (RL_NUM)uHeld, maxUp = RL_MAX_UP(p), maxDown = RL_MAX_DOWN(p);
    RL_NUM y = (RL_NUM)s->y, yp = (RL_NUM)s->yPrevious, ypp = (RL_NUM)s->yBefore;
    uint64_t cycles = s->runCycles;
    uint64_t n = first + 1;
    for (; n <= last && y != u; n++) {
        cycles++;
        ypp = yp;
        yp = y;
        if (p->durationLimited && s->runBase + (double)cycles * s->runPeriod >= p->durationReached) {
            y = u;
        } else {
            y = RL_NAME(rl_step_towards)(y, u, maxUp, maxDown, true);
        }
    }
    if (n <= last) { /* cycles that found y at u */
        ypp = n < last ? y : yp;
        yp = y;
    }
    s->y = (double)y;
    s->yPrevious = (double)yp;
    s->yBefore = (double)ypp;
    s->periodBefore = s->periodLast; /* the first cycle's, p->period */
    s->runCycles = cycles;
}

/* The derived outputs that compute: dydt = (y - yp) / T, and whether the
 * step's limit cut it (yp + maxUp < uc, yp - maxDown > uc). */
static inline double RL_NAME(rl_dydt)(double y, double yp, double period) {
    return (double)RL_NAME(rl_quotient)(RL_NAME(rl_sum)((RL_NUM)y, -(RL_NUM)yp), RL_ENTER(period));
}

/* d2ydt2 = (dydt - dydt of the cycle before) / T; that dydt is
 * (yPrevious - yBefore) / periodBefore, 0 where it did not move. 0 where
 * that dydt, the change or the quotient is not finite: a jump of the
 * output beyond the arithmetic's largest value times T^2 (REAL, T = 1 ms:
 * 3.4e32) overflows the quotient although both dydt are finite. */
static inline double RL_NAME(rl_d2ydt2)(double dydt, const RlState *s, double period) {
    const RL_NUM moved = RL_NAME(rl_sum)((RL_NUM)s->yPrevious, -(RL_NUM)s->yBefore);
    const RL_NUM before = moved == 0 ? 0 : RL_NAME(rl_quotient)(moved, RL_ENTER(s->periodBefore));
    if (!isfinite(before)) return 0.0;
    const RL_NUM change = RL_NAME(rl_sum)((RL_NUM)dydt, -before);
    if (!isfinite(change)) return 0.0;
    const RL_NUM d2ydt2 = RL_NAME(rl_quotient)(change, RL_ENTER(period));
    return isfinite(d2ydt2) ? (double)d2ydt2 : 0.0;
}

/* the step from yp reached the (signed) limit: yp + limit is at or past y */
static inline bool RL_NAME(rl_at_limit)(double yp, double limit, double y) {
    const RL_NUM reached = RL_NAME(rl_sum)((RL_NUM)yp, (RL_NUM)limit);
    return isless(limit, 0) ? isgreaterequal(reached, (RL_NUM)y) : islessequal(reached, (RL_NUM)y);
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
#undef RL_NUM_MAX
#undef RL_MANT_DIG
#undef RL_MIN_EXP
#undef RL_NEXT_TOWARDS
#undef RL_ROUNDOFF
#undef RL_BRAKING_COUNTED
