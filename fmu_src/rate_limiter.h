/* Rate limiter kernel: the cycle rules (docs/rules.md), shared by
 * every model. Pure C99: no FMI types, no allocation, no globals. */
#ifndef RATE_LIMITER_H
#define RATE_LIMITER_H

#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* Compiler hints, portable: GCC and clang read them, any other compiler
 * (MSVC compiling the source FMU) gets nothing; FMU_PORTABLE forces that
 * (a test compiles the sources so). They change speed, never results. */
#if defined(__GNUC__) && !defined(FMU_PORTABLE)
#define FMU_NOINLINE __attribute__((noinline))
#define FMU_COLD __attribute__((cold))
#else
#define FMU_NOINLINE
#define FMU_COLD
#endif

/* Linkage of what the kernel, the model, the core and the glue share
 * (docs/fmi.md, Source FMUs). An FMU is one translation unit that defines
 * RL_UNIT and includes them all: there everything is static, so that only
 * the fmi* functions have external linkage and any number of FMUs link
 * into one binary. A file compiled on its own (the kernel's C tests, the
 * fuzzers) gets extern. The declarations carry RL_LINKAGE: a function
 * defined later without a storage class keeps it (C99 6.2.2p5; C++ agrees).
 * An object has no such rule: its definition carries RL_DEFINITION, and
 * the unit defines it before any use instead of declaring it. Not every
 * model calls every function: GCC and clang are told so (FMU_MAYBE_UNUSED). */
#if defined(__GNUC__)
#define FMU_MAYBE_UNUSED __attribute__((unused))
#else
#define FMU_MAYBE_UNUSED
#endif
#ifdef RL_UNIT
#define RL_LINKAGE static FMU_MAYBE_UNUSED
#define RL_DEFINITION static
#else
#define RL_LINKAGE extern
#define RL_DEFINITION
#endif

/* REAL arithmetic (rules.md, Arithmetic) rounds every float operation to float:
 * a target that evaluates floats in a wider type (x87) would not. */
#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
#error "the kernel needs FLT_EVAL_METHOD 0 (each float operation rounded to float): build with SSE, not x87"
#endif

/* Status words (Siemens convention: RL_STATUS_ERROR and above are errors). */
enum {
    RL_STATUS_OK = 0x0000,
    RL_STATUS_ERROR = 0x8000, /* the first error word */
    RL_STATUS_RATE_NEGATIVE = 0x8200,
    RL_STATUS_RATE_NAN = 0x8201,
    RL_STATUS_RATE_PERIOD = 0x8202,
    RL_STATUS_DURATION = 0x8203,
    RL_STATUS_LIMITS = 0x8204,
    RL_STATUS_ACCELERATION = 0x8205,
    RL_STATUS_NO_CYCLE = 0x8601
};

enum { RL_ZERO_RATE_HOLD = 1, RL_ZERO_RATE_NO_LIMIT = 2 };

enum { RL_INIT_VALUE = 1, RL_INIT_INPUT = 2, RL_INIT_INPUT_DELAYED = 3 };

enum { RL_ARITHMETIC_LREAL = 1, RL_ARITHMETIC_REAL = 2 };

/* Which rule decided the last cycle, for the outputs derived from it */
enum {
    RL_DECIDED_NOTHING = 0, /* no cycle yet */
    RL_DECIDED_OTHER = 1,   /* rules 1 to 5 */
    RL_DECIDED_HOLD = 2,    /* rule 5b */
    RL_DECIDED_RAMP = 3
}; /* rule 6, the duration jump included */

/* Relative tolerance for time comparisons (cycle ends, duration, delay). */
#define RL_TIME_TOLERANCE 1e-9

/* A value and the id of the variable it came from (the caller's id, e.g. a
 * value reference), so that an error can name its cause. */
typedef struct {
    double value;
    int source;
} RlValue;

static inline RlValue rl_value(double value, int source) {
    RlValue v;
    v.value = value;
    v.source = source;
    return v;
}

/* Everything but the signal u: parameters and slowly changing inputs, with
 * "or Par" inputs already resolved (rl_resolve). */
typedef struct {
    RlValue rateUp, rateDown;       /* change per ratePeriod */
    RlValue rateUpNeg, rateDownNeg; /* the same while the output is < 0 */
    RlValue yMax, yMin;             /* output limits; NaN: none */
    bool hold;                      /* rule 5b: freeze the output */
    RlValue accelMax, decelMax;     /* units/s^2; accelMax 0: no acceleration
                                  limit; decelMax 0: braking at accelMax */
    RlValue ratePeriod;             /* s; 0 = change per cycle */
    RlValue duration;               /* s; 0 = never jump */
    RlValue cycleTime;              /* s; only validated here */
    bool cycleRefused;              /* no valid cycle, whatever cycleTime says (an
                                  invalid callOB): 0x8601 from cycleTime.source */
    bool bypass;
    double bypassValue; /* non-finite: output follows u */
    int zeroRate;       /* RL_ZERO_RATE_* */
    int initMode;       /* RL_INIT_* */
    double initValue;
    double initDelay; /* s */
    /* true: a non-finite u passes at once (rule 1). false (Siemens): u is
     * only compared with the output, so NaN holds and +-inf ramps. */
    bool passNonFinite;
    bool limitInitialOutput; /* the initial output within [yMin, yMax] */
    /* REAL (rules.md, Arithmetic): the signal path in binary32. rl_prepare
     * rounds the values that enter it; u is rounded each cycle (rl_input). */
    bool real;
} RlConfig;

/* Per-configuration values derived once, not every cycle. */
typedef struct {
    RlConfig config;
    double period;               /* T the limits were computed for */
    double maxUp, maxDown;       /* per-cycle limits; +inf = no limit */
    double maxUpNeg, maxDownNeg; /* the same while the output is < 0 */
    /* REAL: maxUp and maxDown as the binary32 values they are (rl_prepare
     * rounds what they come from), so that rule 6 reads them unconverted */
    float maxUpReal, maxDownReal;
    double yLow, yHigh;     /* output limits; -inf and +inf for none */
    double durationReached; /* runningTime at or above this jumps */
    double initDelayEnd;    /* elapsed time up to which initMode 3 tracks */
    int status;
    int statusSource;     /* id of the variable that caused status */
    bool plain;           /* only rule 6 can decide a cycle with a
                                  finite u and y, towards u itself, at the
                                  same limits whatever the output's sign
                                  (rl_prepare says when) */
    bool durationLimited; /* duration > 0 */
    /* rules.md, Acceleration limit: accelMax > 0 and no error; then the
     * largest change of the step per cycle while it grows (accelStep =
     * accelMax * T * T) and while it shrinks (decelStep), in the
     * arithmetic's values */
    bool accelLimited;
    double accelStep, decelStep;
} RlPrepared;

/* The block's memory between cycles. runningTime is counted in whole cycles
 * of one length (runCycles * runPeriod, plus runBase when T changed), so
 * that it does not drift. */
typedef struct {
    double y;
    double yPrevious; /* y before the last cycle */
    double yBefore;   /* y before the cycle before (d2ydt2) */
    double uPrevious;
    unsigned char decided; /* RL_DECIDED_*: what decided the last cycle */
    uint64_t runCycles;
    double runPeriod;
    double runBase;
    /* the lengths of the last cycle and the one before (d2ydt2, and the
     * acceleration limit's velocity after a change of step size) */
    double periodLast, periodBefore;
} RlState;
/* rl_shift_outputs: y, yPrevious and yBefore adjacent, in this order */
typedef char rl_outputs_adjacent[offsetof(RlState, yBefore) == offsetof(RlState, y) + 2 * sizeof(double) ? 1 : -1];

/* An error status: the block holds its output (rule 5). */
static inline bool rl_status_is_error(int status) {
    return status >= RL_STATUS_ERROR;
}

/* Rule 0: an "or Par" input that is NaN falls back to its parameter. */
RL_LINKAGE RlValue rl_resolve(double input, int inputSource, double parameter, int parameterSource);

/* rules.md, Output limits, rates below 0 and hold: off, for the vendor
 * blocks that have none of them: the same rates below 0, no output limits,
 * no hold, the initial output as it is. Call after the rates are set. */
RL_LINKAGE void rl_without_section6(RlConfig *config);

/* Status word of a configuration (first match of the status table). */
RL_LINKAGE int rl_status(const RlConfig *config, int *source);

/* Derive limits and status for cycles of length period (> 0). */
RL_LINKAGE void rl_prepare(RlPrepared *prepared, const RlConfig *config, double period);

/* Output at initialisation for the input u, from a configuration as
 * rl_prepare keeps it (its values have entered the arithmetic: the period
 * is not used). */
RL_LINKAGE void rl_init(RlState *state, const RlPrepared *prepared, double u);

/* Time the output has been ramping towards the current u. */
static inline double rl_running_time(const RlState *state) {
    return state->runBase + (double)state->runCycles * state->runPeriod;
}

/* runningTime goes on in cycles of a new length. */
static inline void rl_period_changed(RlState *s, double period) {
    s->runBase += (double)s->runCycles * s->runPeriod;
    s->runCycles = 0;
    s->runPeriod = period;
}

/* A cycle of length period sets y: y before the last cycle and the
 * lengths of the last two cycles move one back. */
static inline void rl_shift(RlState *s, double period) {
    s->yBefore = s->yPrevious;
    s->periodBefore = s->periodLast;
    s->periodLast = period;
}

/* y, yPrevious and yBefore move one back (yPrevious = y, yBefore =
 * yPrevious) as one copy of two adjacent doubles: the common step's whole
 * cost of keeping the cycle before the last. y is then set. */
static inline void rl_shift_outputs(RlState *s) {
    memmove((char *)s + offsetof(RlState, yPrevious), (char *)s + offsetof(RlState, y), 2 * sizeof(double));
}

/* The end of a cycle rule 6 decided: y after yp (ypHeld). */
static inline void rl_ramped(RlState *s, double period, double ypHeld, double y) {
    s->decided = RL_DECIDED_RAMP;
    rl_shift(s, period);
    s->yPrevious = ypHeld;
    s->y = y;
}

/* runningTime counts in cycles of period from now on. rl_ramp does this
 * itself on its first ramping cycle after T changed; done ahead, it spares
 * the steps that follow the check (rl_ramp_steady). runningTime keeps its
 * value bit for bit: runBase takes runCycles * runPeriod, cycles restart. */
static inline void rl_hold_period(RlState *s, double period) {
    if (s->runPeriod != period) rl_period_changed(s, period);
}

/* An output limit as the block reads it (rules.md, rule 0): NaN, the
 * infinity of its side or the largest finite double of its side (the
 * parameters' default, for importers that refuse infinite start values)
 * is no limit, the infinity of its side. */
static inline double rl_high_limit(double yMax) {
    return isnan(yMax) || isgreaterequal(yMax, DBL_MAX) ? INFINITY : yMax;
}

static inline double rl_low_limit(double yMin) {
    return isnan(yMin) || islessequal(yMin, -DBL_MAX) ? -INFINITY : yMin;
}

/* The target uc = min(max(u, yMin), yMax); a NaN u stays NaN. */
static inline double rl_target(double u, const RlPrepared *p) {
    return isless(u, p->yLow) ? p->yLow : isgreater(u, p->yHigh) ? p->yHigh : u;
}

/* x rounded to binary32 (to nearest, ties to even). Beyond the largest
 * float C leaves the conversion undefined (IEEE makes it an infinity):
 * what rounds to an infinity, from 2^128 - 2^103 on, is made one here. */
#define RL_FLOAT_OVERFLOW 3.4028235677973366e38
static inline float rl_binary32(double x) {
    if (isgreaterequal(fabs(x), RL_FLOAT_OVERFLOW)) {
        return x > 0 ? (float)INFINITY : -(float)INFINITY;
    }
    return (float)x;
}

/* Quiet arithmetic: the results IEEE gives, an overflow included (the
 * infinity of its sign), without raising FE_OVERFLOW, which real-time
 * targets trap (docs/fmi.md). An overflow is found before the operation:
 * from the operands' exponents, or from the operands halved (a power of 2,
 * so the halved result rounds as the whole one). */

/* m * 2^e, m 0 or in [0.25, 2], reaches 2^DBL_MAX_EXP: it overflows. */
static inline bool rl_overflows(double m, int e) {
    return m != 0 && (e > DBL_MAX_EXP + 2 || (e >= DBL_MAX_EXP - 1 && isgreaterequal(m, ldexp(1.0, DBL_MAX_EXP - e))));
}

/* a * b for a, b not NaN */
static inline double rl_product(double a, double b) {
    if (!isfinite(a) || !isfinite(b)) return a * b;
    int ea, eb;
    const double m = frexp(a, &ea) * frexp(b, &eb);
    return rl_overflows(fabs(m), ea + eb) ? copysign(INFINITY, m) : a * b;
}

/* a / 0 as IEEE has it (NaN for 0 / 0, else the infinity of the signs),
 * without raising FE_DIVBYZERO or FE_INVALID */
static inline double rl_by_zero(double a, double b) {
    return a == 0 || isnan(a) ? NAN : copysign(INFINITY, signbit(a) == signbit(b) ? 1.0 : -1.0);
}

/* a / b for a, b not NaN and not both infinite */
static inline double rl_quotient(double a, double b) {
    if (b == 0) return rl_by_zero(a, b);
    if (!isfinite(a) || !isfinite(b)) return a / b;
    int ea, eb;
    const double m = frexp(a, &ea) / frexp(b, &eb);
    return rl_overflows(fabs(m), ea - eb) ? copysign(INFINITY, m) : a / b;
}

/* a + b for a finite and b not NaN: the halved sum reaches 2^(DBL_MAX_EXP - 1) */
static inline double rl_sum(double a, double b) {
    if (islessequal(fabs(b), DBL_MAX - fabs(a)) || !isfinite(b)) return a + b;
    const double half = a * 0.5 + b * 0.5;
    return isgreaterequal(fabs(half), 8.98846567431158e307 /* 2^1023 */) ? copysign(INFINITY, half) : a + b;
}

/* x rounded to the arithmetic of a value of that size: binary32 for a
 * float, as it is for a double */
static inline double rl_binary32_or_not(double x, size_t size) {
    return size == sizeof(float) ? (double)rl_binary32(x) : x;
}

/* The same in binary32: a float operation done in binary64 and rounded to
 * binary32 once gives the binary32 result (53 >= 2 * 24 + 2 bits). */
static inline float rl_sum_real(float a, float b) {
    return rl_binary32((double)a + (double)b);
}

static inline float rl_product_real(float a, float b) {
    return rl_binary32((double)a * (double)b);
}

static inline float rl_quotient_real(float a, float b) {
    return rl_binary32(b == 0 ? rl_by_zero(a, b) : (double)a / (double)b);
}

#define rl_sum_lreal rl_sum
#define rl_product_lreal rl_product
#define rl_quotient_lreal rl_quotient

/* Error-free transformations (binary64, round to nearest, no fused
 * operations but fma's own): a + b = sum + error and a * b = product +
 * error exactly, for results that neither overflow nor underflow. They let
 * the acceleration limit decide feasibility exactly (rules.md). */
static inline double rl_two_sum(double a, double b, double *error) {
    const double sum = a + b, bb = sum - a;
    *error = (a - (sum - bb)) + (b - bb);
    return sum;
}

static inline double rl_two_product(double a, double b, double *error) {
    const double product = a * b;
    *error = fma(a, b, -product);
    return product;
}

/* Whether braking at b per cycle from a step s stops within the distance
 * e, exactly: s + sum over j >= 1 of max(0, s - j * b) <= e, for s, b > 0
 * and e >= 0 finite and below 2^1000, with n = floor(s / b) < 2^26 terms,
 * so that n * (n + 1) / 2 is exact: (n + 1) * s - b * n * (n + 1) / 2 - e,
 * its sign taken from the exact terms. */
static inline bool rl_stops_within(double s, double b, double e) {
    double n = floor(s / b);
    if (fma(n, b, -s) > 0) n -= 1; /* n * b <= s < (n + 1) * b */
    else if (fma(n + 1, b, -s) <= 0) n += 1;
    double pe, qe, e1, e2;
    const double p = rl_two_product(n + 1, s, &pe), q = rl_two_product(b, n * (n + 1) / 2, &qe);
    const double s1 = rl_two_sum(p, -q, &e1), s2 = rl_two_sum(s1, -e, &e2);
    return s2 + (((e1 + e2) + pe) - qe) <= 0;
}

/* The steady paths (the FMUs' common step, rl_run's held cycles, both
 * plain: rl_prepare) add and subtract unchecked: u, y and the per-cycle
 * limits below 2^126 in magnitude (or an infinite limit) keep every sum
 * below 2^127, finite in either arithmetic, so nothing overflows. A larger
 * value takes the general path, whose sums are quiet (rl_sum). */
#define RL_STEADY_BELOW 8.507059173023462e37 /* 2^126 */

static inline bool rl_steady_value(double x) {
    return isless(fabs(x), RL_STEADY_BELOW);
}

static inline bool rl_steady_limit(double limit) {
    return rl_steady_value(limit) || limit == INFINITY;
}

/* The kernel's arithmetic, once per type (rate_limiter_rules.h, which
 * undefines these after use): RL_ENTER brings a double that is not yet the
 * type's into it; RL_MAX_UP and RL_MAX_DOWN are the per-cycle limits in
 * the type. */
#define RL_NUM double
#define RL_SUFFIX _lreal
#define RL_ENTER(x) (x)
#define RL_MAX_UP(p) ((p)->maxUp)
#define RL_MAX_DOWN(p) ((p)->maxDown)
#define RL_NUM_MAX DBL_MAX
#define RL_MANT_DIG DBL_MANT_DIG
#define RL_MIN_EXP DBL_MIN_EXP
#define RL_NEXT_TOWARDS(x, y) nextafter(x, y)
#include "rate_limiter_rules.h"
#define RL_NUM float
#define RL_SUFFIX _real
#define RL_ENTER(x) rl_binary32(x)
#define RL_MAX_UP(p) ((p)->maxUpReal)
#define RL_MAX_DOWN(p) ((p)->maxDownReal)
#define RL_NUM_MAX FLT_MAX
#define RL_MANT_DIG FLT_MANT_DIG
#define RL_MIN_EXP FLT_MIN_EXP
#define RL_NEXT_TOWARDS(x, y) nextafterf(x, y)
#include "rate_limiter_rules.h"

/* A value as it enters the block's arithmetic: u, every cycle. */
static inline double rl_input(const RlPrepared *p, double u) {
    return p->config.real ? (double)rl_binary32(u) : u;
}

/* Rule 6 (rl_ramp_cycle_lreal / _real) for a u that has entered. */
static inline void rl_ramp(RlState *s, const RlPrepared *p, double u) {
    if (p->config.real) {
        rl_ramp_cycle_real(s, p, u);
    } else {
        rl_ramp_cycle_lreal(s, p, u);
    }
}

/* rl_ramp after rl_hold_period(s, p->period) for a finite y, with a plain
 * configuration, after a cycle rule 6 decided: the same state. false: u is not finite in the block's
 * arithmetic, nothing done (take the general path). */
static inline bool rl_ramp_steady(RlState *s, const RlPrepared *p, double u) {
    return p->config.real ? rl_ramp_steady_real(s, p, u) : rl_ramp_steady_lreal(s, p, u);
}

/* Rules 1-6 in their order, for a u that has entered (rl_input). */
RL_LINKAGE void rl_cycle_rules(RlState *state, const RlPrepared *prepared, double u, double elapsed);

/* The common case: finite u and y and a plain configuration, so that of
 * the rules only rule 6 (rl_ramp) applies. u has entered. */
static inline bool rl_only_ramps(const RlState *state, const RlPrepared *prepared, double u) {
    return prepared->plain && rl_steady_value(u) && rl_steady_value(state->y);
}

/* One cycle of length prepared->period for a u that has entered; elapsed
 * is the time from the start to the end of this cycle. Inline, as the
 * common case is a few instructions. */
static inline void rl_cycle_entered(RlState *state, const RlPrepared *prepared, double u, double elapsed) {
    if (rl_only_ramps(state, prepared, u)) {
        rl_ramp(state, prepared, u);
    } else {
        rl_cycle_rules(state, prepared, u, elapsed);
    }
}

/* u enters the arithmetic here, once per cycle. */
static inline void rl_cycle(RlState *state, const RlPrepared *prepared, double u, double elapsed) {
    rl_cycle_entered(state, prepared, rl_input(prepared, u), elapsed);
}

/* Cycles first..last (of length cycleTime, ending at n * cycleTime) with u
 * held: the same as rl_cycle for each, in fewer instructions. */
RL_LINKAGE void rl_run(RlState *state, const RlPrepared *prepared, double u, uint64_t first, uint64_t last,
                       double cycleTime);

/* rules.md, Outputs derived from the last cycle, computed when read: they
 * cost the cycles nothing. prepared must be the
 * configuration the last cycle ran with. */
typedef struct {
    bool rampActive;               /* rule 6 decided it and left y != uc */
    bool limitingUp, limitingDown; /* rule 6 ramped and that limit cut the step */
    bool highLimit, lowLimit;      /* y finite and at or beyond yMax / yMin */
    double dydt;                   /* (y - yp) / T; 0 if either is not finite */
    double remainingTime;          /* s the ramp still needs to reach uc */
    double d2ydt2;                 /* (dydt - dydt of the cycle before) / T */
} RlOutputs;

/* remainingTime's plan with the acceleration limit, kept from read to read
 * while the cycles follow it (rl_outputs): a ramp read every cycle then
 * costs a few planned cycles per cycle, not the rest of the ramp. Not the
 * block's memory: a plan the state does not follow is made again, so a
 * zeroed one, or one of another block, only costs that. */
typedef struct {
    bool valid;
    bool stalled;        /* end cannot move from rest: uc is never reached */
    RlState at;          /* the state the plan starts from (a hold released) */
    RlState end;         /* at after planned cycles of rule 6 */
    double planned;      /* at most RL_PLAN_CYCLES */
    double uc;           /* the target it runs to */
    double work;         /* cycles of rule 6 run for it so far (its cost, never reset) */
    RlPrepared prepared; /* the configuration it runs with */
} RlPlan;

/* plan: the block's kept plan, or NULL (remainingTime planned afresh). */
RL_LINKAGE void rl_outputs(const RlState *state, const RlPrepared *prepared, RlPlan *plan, RlOutputs *outputs);

/* Short meaning of a status word, for log messages. */
RL_LINKAGE const char *rl_status_text(int status);

#endif
