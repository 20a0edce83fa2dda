/* Unit tests of the rate limiter kernel: every rule (0 to 6, 5b) and every
 * status code (docs/rules.md), and the outputs derived from a
 * cycle. Expected values are worked by hand. */
#include <fenv.h>
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "rate_limiter.h"

static int failures = 0;
static int checks = 0;

#define CHECK_EQ(actual, expected) check_eq(__FILE__, __LINE__, #actual, (double)(actual), (double)(expected))
#define CHECK_BITS(actual, expected) check_bits(__FILE__, __LINE__, #actual, (actual), (expected))
#define CHECK_TRUE(condition) check_eq(__FILE__, __LINE__, #condition, (condition) ? 1.0 : 0.0, 1.0)

/* exact comparison; NaN equals NaN */
static void check_eq(const char *file, int line, const char *what, double actual, double expected) {
    checks++;
    if (actual == expected || (isnan(actual) && isnan(expected))) return;
    failures++;
    printf("%s:%d: %s is %.17g, expected %.17g\n", file, line, what, actual, expected);
}

/* the same bits: tells -0.0 from +0.0 */
static void check_bits(const char *file, int line, const char *what, double actual, double expected) {
    checks++;
    if (memcmp(&actual, &expected, sizeof actual) == 0) return;
    failures++;
    printf("%s:%d: %s is %+.17g, expected %+.17g (bit for bit)\n", file, line, what, actual, expected);
}

enum {
    SRC_RATE_UP = 2,
    SRC_RATE_DOWN = 3,
    SRC_DURATION = 6,
    SRC_RATE_UP_PAR = 7,
    SRC_RATE_DOWN_PAR = 8,
    SRC_DURATION_PAR = 10,
    SRC_RATE_PERIOD = 11,
    SRC_CYCLE_TIME = 13,
    SRC_RATE_UP_NEG = 23,
    SRC_RATE_DOWN_NEG = 24,
    SRC_Y_MAX = 25,
    SRC_Y_MIN = 26,
    SRC_Y_MAX_PAR = 28,
    SRC_Y_MIN_PAR = 29,
    SRC_FOLLOWS = 99 /* a Neg rate not set: the other one's value */
};

/* The unified block's defaults: rates 1 per 1 s, no duration, init = input. */
static RlConfig defaults(void) {
    RlConfig c;
    memset(&c, 0, sizeof c);
    c.rateUp = (RlValue){ 1.0, SRC_RATE_UP_PAR };
    c.rateDown = (RlValue){ 1.0, SRC_RATE_DOWN_PAR };
    c.ratePeriod = (RlValue){ 1.0, SRC_RATE_PERIOD };
    c.duration = (RlValue){ 0.0, SRC_DURATION_PAR };
    c.cycleTime = (RlValue){ 0.0, SRC_CYCLE_TIME };
    c.bypassValue = NAN;
    c.zeroRate = RL_ZERO_RATE_HOLD;
    c.initMode = RL_INIT_INPUT;
    c.passNonFinite = true;
    c.rateUpNeg = (RlValue){ NAN, SRC_FOLLOWS };
    c.rateDownNeg = (RlValue){ NAN, SRC_FOLLOWS };
    c.yMax = (RlValue){ INFINITY, SRC_Y_MAX_PAR };
    c.yMin = (RlValue){ -INFINITY, SRC_Y_MIN_PAR };
    c.limitInitialOutput = true;
    return c;
}

/* Rule 0 for the Neg rates, as the unified block resolves them: one not
 * set takes the other rate's value (again after every change of it). */
static RlConfig *resolved(RlConfig *c) {
    if (c->rateUpNeg.source == SRC_FOLLOWS) c->rateUpNeg.value = c->rateUp.value;
    if (c->rateDownNeg.source == SRC_FOLLOWS) c->rateDownNeg.value = c->rateDown.value;
    return c;
}

/* The defaults with all four rates set and the output starting at y0. */
static RlConfig with_rates(double up, double upNeg, double down, double downNeg, double y0) {
    RlConfig c = defaults();
    c.rateUp.value = up;
    c.rateUpNeg = (RlValue){ upNeg, SRC_RATE_UP_NEG };
    c.rateDown.value = down;
    c.rateDownNeg = (RlValue){ downNeg, SRC_RATE_DOWN_NEG };
    c.initMode = RL_INIT_VALUE;
    c.initValue = y0;
    return c;
}

typedef struct {
    RlConfig config;
    RlPrepared prepared;
    RlState state;
    double period;
    long cycles;
} Block;

static void start(Block *b, const RlConfig *config, double u, double period) {
    RlConfig copy = *config;
    const RlConfig *c = resolved(&copy);
    b->config = *c;
    b->period = period;
    b->cycles = 0;
    rl_prepare(&b->prepared, c, period);
    rl_init(&b->state, &b->prepared, u);
}

static double cycle(Block *b, double u) {
    b->cycles++;
    rl_cycle(&b->state, &b->prepared, u, (double)b->cycles * b->period);
    return b->state.y;
}

static RlOutputs outputs(const Block *b) {
    RlOutputs o;
    rl_outputs(&b->state, &b->prepared, NULL, &o);
    return o;
}

static void reconfigure(Block *b, const RlConfig *config) {
    RlConfig copy = *config;
    const RlConfig *c = resolved(&copy);
    b->config = *c;
    rl_prepare(&b->prepared, c, b->period);
}

static void test_rule0_resolve(void) {
    RlValue v = rl_resolve(NAN, SRC_RATE_UP, 3.0, SRC_RATE_UP_PAR);
    CHECK_EQ(v.value, 3.0);
    CHECK_EQ(v.source, SRC_RATE_UP_PAR);
    v = rl_resolve(2.0, SRC_RATE_UP, 3.0, SRC_RATE_UP_PAR);
    CHECK_EQ(v.value, 2.0);
    CHECK_EQ(v.source, SRC_RATE_UP);
    v = rl_resolve(INFINITY, SRC_RATE_UP, 3.0, SRC_RATE_UP_PAR); /* only NaN falls back */
    CHECK_EQ(v.value, INFINITY);
    v = rl_resolve(NAN, SRC_RATE_UP, NAN, SRC_RATE_UP_PAR);
    CHECK_TRUE(isnan(v.value));
}

static void test_rule0_limits(void) {
    RlConfig c = defaults();
    RlPrepared p;
    c.rateUp.value = 10.0;
    c.rateDown.value = 4.0;
    c.ratePeriod.value = 2.0;
    rl_prepare(&p, resolved(&c), 0.5); /* 10 * 0.5 / 2 and 4 * 0.5 / 2 */
    CHECK_EQ(p.maxUp, 2.5);
    CHECK_EQ(p.maxDown, 1.0);
    c.ratePeriod.value = 0.0; /* per cycle, whatever T */
    rl_prepare(&p, resolved(&c), 0.5);
    CHECK_EQ(p.maxUp, 10.0);
    CHECK_EQ(p.maxDown, 4.0);
    c.rateUp.value = INFINITY; /* +inf: no limit */
    rl_prepare(&p, resolved(&c), 0.5);
    CHECK_EQ(p.maxUp, INFINITY);
    c.rateUp.value = 0.0; /* 0: hold (zeroRate 1) ... */
    rl_prepare(&p, resolved(&c), 0.5);
    CHECK_EQ(p.maxUp, 0.0);
    c.zeroRate = RL_ZERO_RATE_NO_LIMIT; /* ... or no limit (zeroRate 2) */
    rl_prepare(&p, resolved(&c), 0.5);
    CHECK_EQ(p.maxUp, INFINITY);
    CHECK_EQ(p.maxDown, 4.0);
    /* Siemens seed: 10 per second at 1 s / 100 ms / 10 ms adds 10 / 1 / 0.1 */
    c = defaults();
    c.rateUp.value = 10.0;
    rl_prepare(&p, resolved(&c), 1.0);
    CHECK_EQ(p.maxUp, 10.0);
    rl_prepare(&p, resolved(&c), 0.1);
    CHECK_EQ(p.maxUp, 1.0);
    rl_prepare(&p, resolved(&c), 0.01);
    CHECK_EQ(p.maxUp, 0.1);
}

static void test_status_codes(void) {
    RlConfig c = defaults();
    int source = -1;
    CHECK_EQ(rl_status(resolved(&c), &source), RL_STATUS_OK);
    CHECK_EQ(source, 0);

    c = defaults();
    c.rateDown.value = -1.0;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8200);
    CHECK_EQ(source, SRC_RATE_DOWN_PAR);
    c = defaults();
    c.rateUp = (RlValue){ -0.5, SRC_RATE_UP };
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8200);
    CHECK_EQ(source, SRC_RATE_UP);
    c = defaults();
    c.rateUp.value = -INFINITY;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8200);

    c = defaults();
    c.rateUp.value = NAN;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8201);
    CHECK_EQ(source, SRC_RATE_UP_PAR);
    c = defaults();
    c.rateDown.value = NAN;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8201);
    CHECK_EQ(source, SRC_RATE_DOWN_PAR);
    /* first match wins: a negative rate before a NaN one */
    c = defaults();
    c.rateUp.value = NAN;
    c.rateDown.value = -1.0;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8200);
    CHECK_EQ(source, SRC_RATE_DOWN_PAR);

    c = defaults();
    c.ratePeriod.value = -1.0;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8202);
    CHECK_EQ(source, SRC_RATE_PERIOD);
    c.ratePeriod.value = INFINITY;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8202);
    c.ratePeriod.value = NAN;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8202);

    c = defaults();
    c.duration = (RlValue){ -3.0, SRC_DURATION };
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8203);
    CHECK_EQ(source, SRC_DURATION);
    c.duration = (RlValue){ NAN, SRC_DURATION_PAR };
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8203);
    CHECK_EQ(source, SRC_DURATION_PAR);
    c.duration.value = INFINITY; /* never reached, but valid */
    CHECK_EQ(rl_status(resolved(&c), &source), RL_STATUS_OK);

    c = defaults();
    c.cycleTime.value = -0.01;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8601);
    CHECK_EQ(source, SRC_CYCLE_TIME);
    c.cycleTime.value = INFINITY;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8601);
    c.cycleTime.value = NAN;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8601);

    /* the table's order: rate before ratePeriod before duration before cycle */
    c = defaults();
    c.cycleTime.value = -1;
    c.duration.value = -1;
    c.ratePeriod.value = -1;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8202);
    c.ratePeriod.value = 1;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8203);
    c.duration.value = 0;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8601);
    /* each status word's text, as the FMUs log it */
    static const struct {
        int status;
        const char *text;
    } texts[] = {
        { 0x0000, "no error" },
        { 0x8200, "a rate is negative" },
        { 0x8201, "a rate is NaN after falling back to its parameter" },
        { 0x8202, "ratePeriod is negative or not finite" },
        { 0x8203, "duration is negative, or NaN after falling back to its parameter" },
        { 0x8204, "yMin is above yMax" },
        { 0x8601, "no valid cycle configured" },
        { 0x8000, "unknown status" },
    };
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
        const char *text = rl_status_text(texts[i].status);
        checks++;
        if (strcmp(text, texts[i].text) != 0) {
            failures++;
            printf("%s:%d: rl_status_text(0x%04X) is \"%s\", expected \"%s\"\n", __FILE__, __LINE__,
                   (unsigned)texts[i].status, text, texts[i].text);
        }
    }
}

static void test_initialisation(void) {
    Block b;
    RlConfig c = defaults();
    c.initMode = RL_INIT_VALUE;
    c.initValue = 7.0;
    start(&b, &c, 3.0, 1.0);
    CHECK_EQ(b.state.y, 7.0);
    CHECK_EQ(rl_running_time(&b.state), 0.0);
    CHECK_EQ(cycle(&b, 3.0), 6.0); /* ramps down from initValue at 1/s */
    c.initMode = RL_INIT_INPUT;
    start(&b, &c, 3.0, 1.0);
    CHECK_EQ(b.state.y, 3.0);
    c.initMode = RL_INIT_INPUT_DELAYED;
    start(&b, &c, 3.0, 1.0);
    CHECK_EQ(b.state.y, 3.0);
}

static void test_rule1_non_finite_input(void) {
    Block b;
    RlConfig c = defaults();
    c.duration.value = 100.0;
    start(&b, &c, 0.0, 1.0);
    CHECK_EQ(cycle(&b, 10.0), 1.0);
    CHECK_EQ(rl_running_time(&b.state), 1.0);
    CHECK_TRUE(isnan(cycle(&b, NAN)));        /* passes at once */
    CHECK_EQ(rl_running_time(&b.state), 0.0); /* and resets runningTime */
    CHECK_TRUE(!outputs(&b).rampActive);
    CHECK_EQ(cycle(&b, INFINITY), INFINITY);
    CHECK_EQ(cycle(&b, -INFINITY), -INFINITY);
    CHECK_EQ(cycle(&b, 5.0), 5.0); /* rule 4: valid after invalid */

    /* rule 1 wins over a configuration error (rule 5) and bypass (rule 2) */
    c.rateUp.value = -1.0;
    c.bypass = true;
    c.bypassValue = 2.0;
    reconfigure(&b, &c);
    CHECK_TRUE(isnan(cycle(&b, NAN)));
}

static void test_siemens_comparison(void) {
    /* passNonFinite false: u is only compared with the output */
    Block b;
    RlConfig c = defaults();
    c.passNonFinite = false;
    c.rateUp.value = c.rateDown.value = 2.0;
    start(&b, &c, 0.0, 1.0);
    CHECK_EQ(cycle(&b, 10.0), 2.0);
    CHECK_EQ(cycle(&b, NAN), 2.0); /* neither > nor <: hold */
    CHECK_EQ(cycle(&b, NAN), 2.0);
    CHECK_EQ(cycle(&b, INFINITY), 4.0); /* ramps towards +inf */
    CHECK_EQ(cycle(&b, -INFINITY), 2.0);
    CHECK_EQ(cycle(&b, 3.0), 3.0); /* a number again: ramps */
}

static void test_rule2_bypass(void) {
    Block b;
    RlConfig c = defaults();
    start(&b, &c, 0.0, 1.0);
    CHECK_EQ(cycle(&b, 10.0), 1.0);
    c.bypass = true;
    c.bypassValue = 8.0;
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 10.0), 8.0); /* jumps to bypassValue */
    CHECK_TRUE(!outputs(&b).rampActive);
    CHECK_EQ(rl_running_time(&b.state), 0.0);
    c.bypassValue = NAN; /* no bypass value: y = u */
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 4.0), 4.0);
    c.bypassValue = INFINITY; /* not finite: y = u */
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 4.5), 4.5);
    c.bypassValue = -2.0;
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 4.5), -2.0);
    c.bypass = false; /* released: ramps from -2 */
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 4.5), -1.0);
    CHECK_TRUE(outputs(&b).rampActive);
    CHECK_EQ(cycle(&b, 4.5), 0.0);
    /* bypass wins over a configuration error */
    c.bypass = true;
    c.bypassValue = 9.0;
    c.ratePeriod.value = -1.0;
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 4.5), 9.0);
}

static void test_rule3_init_delay(void) {
    Block b;
    RlConfig c = defaults();
    c.initMode = RL_INIT_INPUT_DELAYED;
    c.initDelay = 0.3;
    start(&b, &c, 0.0, 0.1);
    CHECK_EQ(cycle(&b, 5.0), 5.0);   /* ends at 0.1 */
    CHECK_EQ(cycle(&b, -5.0), -5.0); /* 0.2 */
    CHECK_EQ(cycle(&b, 6.0), 6.0);   /* 3 * 0.1 = 0.30000000000000004: at 0.3 within rounding */
    CHECK_TRUE(!outputs(&b).rampActive);
    CHECK_EQ(cycle(&b, 10.0), 6.1); /* 0.4: ramps at 1/s */
    CHECK_TRUE(outputs(&b).rampActive);
    /* initMode 2 ignores initDelay */
    c.initMode = RL_INIT_INPUT;
    start(&b, &c, 0.0, 0.1);
    CHECK_EQ(cycle(&b, 5.0), 0.1);
    /* tracking ends with the cycle that ends at most initDelay + 1e-9 * T:
     * the tolerance scales with the cycle (5e-9 s is 5e-8 of 0.1 s but 5e-10 of 10 s) */
    c.initMode = RL_INIT_INPUT_DELAYED;
    c.initDelay = 0.3 - 5e-9;
    start(&b, &c, 0.0, 0.1);
    cycle(&b, 0.0);
    cycle(&b, 0.0);
    CHECK_EQ(cycle(&b, 5.0), 0.1); /* ends at 0.3: past the delay, ramps */
    c.initDelay = 30.0 - 5e-9;
    start(&b, &c, 0.0, 10.0);
    cycle(&b, 0.0);
    cycle(&b, 0.0);
    CHECK_EQ(cycle(&b, 500.0), 500.0); /* ends at 30: within 1e-9 * 10 s, tracks */
    CHECK_EQ(cycle(&b, 0.0), 490.0);
    /* the edge itself: a cycle ending at exactly initDelay + 1e-9 * T tracks */
    c.initDelay = 0.3;
    start(&b, &c, 0.0, 0.1);
    const double edge = 0.3 + 1e-9 * 0.1;
    rl_cycle(&b.state, &b.prepared, 5.0, edge);
    CHECK_EQ(b.state.y, 5.0);
    rl_cycle(&b.state, &b.prepared, -5.0, nextafter(edge, INFINITY));
    CHECK_EQ(b.state.y, 4.9);
    /* and resets runningTime (an initMode set to 3 while ramping) */
    c.initMode = RL_INIT_INPUT;
    start(&b, &c, 0.0, 1.0);
    cycle(&b, 10.0);
    cycle(&b, 10.0);
    CHECK_EQ(rl_running_time(&b.state), 2.0);
    c.initMode = RL_INIT_INPUT_DELAYED;
    c.initDelay = 100.0;
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 10.0), 10.0);
    CHECK_EQ(rl_running_time(&b.state), 0.0);
}

static void test_rule4_invalid_previous_output(void) {
    Block b;
    RlConfig c = defaults();
    c.initMode = RL_INIT_VALUE;
    c.initValue = NAN;
    start(&b, &c, 3.0, 1.0);
    CHECK_TRUE(isnan(b.state.y));
    CHECK_EQ(cycle(&b, 3.0), 3.0);
    /* rule 4 comes before a configuration error */
    c.rateUp.value = -1;
    start(&b, &c, 3.0, 1.0);
    CHECK_EQ(cycle(&b, 4.0), 4.0);
    /* an output ramped to +inf (Siemens comparison, no limit): a NaN u is
     * not valid, the output stays; a number is passed and resets runningTime */
    c = defaults();
    c.passNonFinite = false;
    c.rateUp.value = INFINITY;
    start(&b, &c, 0.0, 1.0);
    CHECK_EQ(cycle(&b, INFINITY), INFINITY);
    CHECK_EQ(rl_running_time(&b.state), 1.0);
    CHECK_EQ(cycle(&b, NAN), INFINITY);
    CHECK_EQ(cycle(&b, 5.0), 5.0);
    CHECK_EQ(rl_running_time(&b.state), 0.0);
}

static void test_rule5_configuration_error_holds(void) {
    Block b;
    RlConfig c = defaults();
    start(&b, &c, 0.0, 1.0);
    CHECK_EQ(cycle(&b, 10.0), 1.0);
    c.rateDown.value = -1.0;
    reconfigure(&b, &c);
    CHECK_EQ(b.prepared.status, 0x8200);
    CHECK_EQ(cycle(&b, 10.0), 1.0);
    CHECK_EQ(cycle(&b, -3.0), 1.0);
    CHECK_TRUE(!outputs(&b).rampActive);
    c.rateDown.value = 1.0; /* fixed: ramps on from the held value */
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, -3.0), 0.0);
}

static void test_rule6_ramp(void) {
    Block b;
    RlConfig c = defaults();
    c.rateUp.value = 2.0;
    c.rateDown.value = 0.5;
    start(&b, &c, 0.0, 0.5);
    CHECK_EQ(cycle(&b, 3.0), 1.0); /* +2/s * 0.5 s */
    CHECK_TRUE(outputs(&b).rampActive);
    CHECK_EQ(rl_running_time(&b.state), 0.5);
    CHECK_EQ(cycle(&b, 3.0), 2.0);
    CHECK_EQ(rl_running_time(&b.state), 1.0);
    CHECK_EQ(cycle(&b, 3.0), 3.0); /* reaches u, no overshoot */
    CHECK_TRUE(!outputs(&b).rampActive);
    CHECK_EQ(rl_running_time(&b.state), 1.5);
    CHECK_EQ(cycle(&b, 3.0), 3.0); /* y == u: the timer value remains */
    CHECK_EQ(rl_running_time(&b.state), 1.5);
    CHECK_EQ(cycle(&b, 2.5), 2.75); /* -0.5/s * 0.5 s; new u resets the timer */
    CHECK_EQ(rl_running_time(&b.state), 0.5);
    CHECK_EQ(cycle(&b, 2.5), 2.5);
    CHECK_EQ(cycle(&b, 2.5), 2.5);
    CHECK_TRUE(!outputs(&b).rampActive);

    /* zeroRate 1: a rate of 0 holds that direction only */
    c = defaults();
    c.rateUp.value = 0.0;
    start(&b, &c, 1.0, 1.0);
    CHECK_EQ(cycle(&b, 5.0), 1.0);
    CHECK_TRUE(outputs(&b).rampActive);
    CHECK_EQ(cycle(&b, -5.0), 0.0);
    /* zeroRate 2: no limit */
    c.zeroRate = RL_ZERO_RATE_NO_LIMIT;
    start(&b, &c, 1.0, 1.0);
    CHECK_EQ(cycle(&b, 5.0), 5.0);
    CHECK_TRUE(!outputs(&b).rampActive);
}

static void test_rule6_duration(void) {
    Block b;
    RlConfig c = defaults();
    c.rateUp.value = 0.1;
    c.duration.value = 3.0;
    start(&b, &c, 0.0, 0.1);
    for (int k = 1; k < 30; k++) {
        cycle(&b, 100.0);
        CHECK_TRUE(b.state.y < 100.0);
    }
    CHECK_EQ(rl_running_time(&b.state), 29 * 0.1);
    CHECK_EQ(cycle(&b, 100.0), 100.0); /* 30 cycles of 0.1 s reach 3 s */
    CHECK_TRUE(!outputs(&b).rampActive);
    CHECK_EQ(rl_running_time(&b.state), 30 * 0.1);
    CHECK_EQ(cycle(&b, 100.0), 100.0);
    CHECK_EQ(rl_running_time(&b.state), 30 * 0.1); /* remains */

    /* the edge of the tolerance: a runningTime of duration * (1 - 1e-9)
     * jumps (no limit cut that step), one a bit shorter ramps; in one
     * cycle, and in rl_run's second of two half as long */
    c = defaults();
    c.duration.value = 1.0;
    const double edge = 1.0 * (1.0 - 1e-9);
    const double shorter = nextafter(edge, 0.0);
    start(&b, &c, 0.0, edge);
    CHECK_EQ(cycle(&b, 5.0), 5.0);
    CHECK_TRUE(!outputs(&b).limitingUp);
    start(&b, &c, 0.0, shorter);
    CHECK_EQ(cycle(&b, 5.0), shorter); /* 1 per 1 s for one cycle */
    CHECK_TRUE(outputs(&b).limitingUp);
    start(&b, &c, 0.0, edge / 2);
    rl_run(&b.state, &b.prepared, 5.0, 1, 2, edge / 2);
    CHECK_EQ(b.state.y, 5.0);
    start(&b, &c, 0.0, shorter / 2);
    rl_run(&b.state, &b.prepared, 5.0, 1, 2, shorter / 2);
    CHECK_EQ(b.state.y, shorter);

    /* 48 h Duration at 10 ms: the jump comes at cycle 25,920,000 exactly */
    c = defaults();
    c.rateUp.value = 1e-9;
    c.duration.value = 259200.0;
    start(&b, &c, 0.0, 0.01);
    long jump = 0;
    for (long k = 1; k <= 25920001 && !jump; k++) {
        if (cycle(&b, 1e6) == 1e6) jump = k;
    }
    CHECK_EQ(jump, 25920000);
    CHECK_EQ(rl_running_time(&b.state), 259200.0);
}

/* Rule 6 compares with < and >, so -0.0 and +0.0 are equal: "y = yp if
 * equal" keeps yp's zero; a step that ends on the target gives the target
 * (min and max keep their first argument, u, on a tie); a u equal to a
 * limit is its own target (uc = min(max(u, yMin), yMax) likewise). */
static void test_signed_zeros(void) {
    Block b;
    RlConfig c = defaults(); /* 1 per cycle of 1 s */
    start(&b, &c, 0.0, 1.0);
    CHECK_BITS(cycle(&b, -0.0), 0.0); /* u == yp: y = yp */
    start(&b, &c, -0.0, 1.0);
    CHECK_BITS(cycle(&b, 0.0), -0.0);
    start(&b, &c, -1.0, 1.0);
    CHECK_BITS(cycle(&b, -0.0), -0.0); /* min(u, -1 + 1 = +0.0): u */
    start(&b, &c, 1.0, 1.0);
    CHECK_BITS(cycle(&b, -0.0), -0.0); /* max(u, 1 - 1 = +0.0): u */
    c.yMin.value = 0.0;                /* u == yMin: uc = u */
    start(&b, &c, 1.0, 1.0);
    CHECK_BITS(cycle(&b, -0.0), -0.0);
    c = defaults();
    c.yMax.value = -0.0; /* u == yMax: uc = u */
    start(&b, &c, -1.0, 1.0);
    CHECK_BITS(cycle(&b, 0.0), 0.0);
}

static void test_running_time_period_change(void) {
    Block b;
    RlConfig c = defaults();
    c.rateUp.value = 0.001;
    start(&b, &c, 0.0, 0.25);
    cycle(&b, 1.0);
    cycle(&b, 1.0);
    b.period = 0.5; /* variable steps: T changes */
    reconfigure(&b, &c);
    rl_cycle(&b.state, &b.prepared, 1.0, 1.0);
    CHECK_EQ(rl_running_time(&b.state), 1.0); /* 0.25 + 0.25 + 0.5 */
}

static void check_same_state(const RlState *a, const RlState *b) {
    CHECK_EQ(a->y, b->y);
    CHECK_EQ(a->uPrevious, b->uPrevious);
    CHECK_EQ(a->yPrevious, b->yPrevious);
    CHECK_EQ(a->decided, b->decided);
    CHECK_EQ(a->runCycles, b->runCycles);
    CHECK_EQ(a->runPeriod, b->runPeriod);
    CHECK_EQ(a->runBase, b->runBase);
}

static void check_same_outputs(const RlState *a, const RlState *b, const RlPrepared *p) {
    RlOutputs x, y;
    rl_outputs(a, p, NULL, &x);
    rl_outputs(b, p, NULL, &y);
    CHECK_EQ(x.rampActive, y.rampActive);
    CHECK_EQ(x.limitingUp, y.limitingUp);
    CHECK_EQ(x.limitingDown, y.limitingDown);
    CHECK_EQ(x.highLimit, y.highLimit);
    CHECK_EQ(x.lowLimit, y.lowLimit);
    CHECK_EQ(x.dydt, y.dydt);
    CHECK_EQ(x.remainingTime, y.remainingTime);
}

/* The fast paths against the rules in order, over a grid of configurations,
 * start values and inputs: rl_cycle (inline common case) must equal
 * rl_cycle_rules, and rl_run over n cycles must equal n rl_cycle calls. */
static void test_fast_paths_equal_rules(void) {
    const double rates[] = { 0.0, 0.3, 1e308, -1.0 };
    const double durations[] = { 0.0, 0.05, 1.0 };
    const double starts[] = { 0.0, NAN, INFINITY };
    const double inputs[][2] = { { 5.0, -5.0 }, { -5.0, 5.0 },           { 0.1, 0.1 },
                                 { NAN, 2.0 },  { INFINITY, -INFINITY }, { 1e308, -1e308 } };
    const unsigned long counts[] = { 1, 2, 7, 50 };
    const double T = 0.01;
    for (size_t r = 0; r < 4; r++)
        for (size_t d = 0; d < 3; d++)
            for (int zero = RL_ZERO_RATE_HOLD; zero <= RL_ZERO_RATE_NO_LIMIT; zero++)
                for (int init = RL_INIT_VALUE; init <= RL_INIT_INPUT_DELAYED; init++)
                    for (int flags = 0; flags < 4; flags++)
                        for (size_t y0 = 0; y0 < 3; y0++)
                            for (size_t in = 0; in < 6; in++)
                                for (size_t n = 0; n < 4; n++)
                                    for (int extra = 0; extra < 6; extra++)
                                        for (int real = 0; real <= 1; real++) {
                                            RlConfig c = defaults();
                                            c.real = real;
                                            c.rateUp.value = rates[r];
                                            c.rateDown.value = rates[(r + 1) % 4];
                                            c.duration.value = durations[d];
                                            c.zeroRate = zero;
                                            c.initMode = init;
                                            c.initValue = starts[y0];
                                            c.initDelay = 0.02;
                                            c.bypass = flags & 1;
                                            c.passNonFinite = flags & 2;
                                            /* output limits, rates below 0 and hold in play, one at a time (each must clear plain): other
         * rates below 0, a high or a low limit, hold */
                                            if (extra == 1) c.rateUpNeg = (RlValue){ 0.7, SRC_RATE_UP_NEG };
                                            if (extra == 2) c.rateDownNeg = (RlValue){ 2.0, SRC_RATE_DOWN_NEG };
                                            if (extra == 3) c.yMax.value = 2.0;
                                            if (extra == 4) c.yMin.value = -3.0;
                                            if (extra == 5) c.hold = true;
                                            RlPrepared p;
                                            rl_prepare(&p, resolved(&c), T);
                                            RlState run, cycles, rules;
                                            rl_init(&run, &p, 1.0);
                                            cycles = rules = run;
                                            uint64_t first = 1;
                                            for (int k = 0; k < 2; k++) { /* two inputs in turn: resets too */
                                                const double u = inputs[in][k];
                                                const uint64_t last = first + counts[n] - 1;
                                                rl_run(&run, &p, u, first, last, T);
                                                for (uint64_t m = first; m <= last; m++) {
                                                    rl_cycle(&cycles, &p, u, (double)m * T);
                                                    rl_cycle_rules(&rules, &p, rl_input(&p, u), (double)m * T);
                                                }
                                                check_same_state(&run, &cycles);
                                                check_same_state(&cycles, &rules);
                                                check_same_outputs(&run, &rules, &p);
                                                first = last + 1;
                                            }
                                        }
}

/* rl_run of an empty range (first > last) runs no cycle */
static void test_run_of_no_cycles(void) {
    Block b;
    RlConfig c = defaults();
    start(&b, &c, 0.0, 0.5);
    cycle(&b, 3.0);
    const RlState before = b.state;
    rl_run(&b.state, &b.prepared, 5.0, 3, 2, 0.5);
    check_same_state(&b.state, &before);
}

/* The common step of the FMUs against the rules: once a cycle has run,
 * the FMU moves runningTime to the new period ahead (rl_hold_period) and
 * then runs rl_ramp_steady while u and y are finite and the configuration
 * is plain. Over period changes, input steps, durations and huge values,
 * y, uPrevious, rampActive and runningTime must equal rl_cycle_rules'. */
static void test_steady_ramp_equals_rules(void) {
    const double rates[] = { 0.0, 0.3, 1e308 };
    const double durations[] = { 0.0, 0.05, 0.3 };
    enum { STEPS = 9, ROWS = 5 };
    const double periods[STEPS] = { 0.01, 0.01, 0.02, 0.02, 0.02, 0.005, 0.005, 0.01, 0.01 };
    const double inputs[ROWS][STEPS] = { { 5.0, 5.0, 5.0, -5.0, -5.0, 5.0, 5.0, 5.0, 5.0 },
                                         { 0.1, 0.1, 0.2, 0.2, 0.2, 0.2, 0.2, -0.1, -0.1 },
                                         { 1e308, -1e308, 1e308, 1e308, 0.0, 0.0, 0.0, -1e308, -1e308 },
                                         { 1.0, NAN, 1.0, 1.0, 2.0, INFINITY, INFINITY, 3.0, 3.0 },
                                         /* at rest while T shrinks, then a new u at that T */
                                         { 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0 } };
    for (size_t r = 0; r < 3; r++)
        for (size_t d = 0; d < 3; d++)
            for (int zero = RL_ZERO_RATE_HOLD; zero <= RL_ZERO_RATE_NO_LIMIT; zero++)
                for (size_t in = 0; in < ROWS; in++)
                    for (int repeat = 1; repeat <= 12; repeat += 11)
                        for (int real = 0; real <= 1; real++) {
                            RlConfig c = defaults();
                            c.real = real;
                            c.rateUp.value = rates[r];
                            c.rateDown.value = rates[(r + 2) % 3];
                            c.duration.value = durations[d];
                            c.zeroRate = zero;
                            RlPrepared p;
                            RlState steady, rules;
                            rl_prepare(&p, resolved(&c), periods[0]);
                            rl_init(&steady, &p, 1.0);
                            rules = steady;
                            bool held = false; /* the FMU's fastPeriod: steady steps allowed */
                            double elapsed = 0.0;
                            for (size_t k = 0; k < STEPS; k++) {
                                if (k == 0 || periods[k] != periods[k - 1]) {
                                    rl_prepare(&p, resolved(&c), periods[k]);
                                    held = false;
                                }
                                for (int n = 0; n < repeat; n++) {
                                    const double u = inputs[in][k];
                                    elapsed += periods[k];
                                    /* as the FMU: the common step unless u is not finite in the arithmetic */
                                    if (!(held && rl_ramp_steady(&steady, &p, u))) {
                                        rl_cycle(&steady, &p, u, elapsed);
                                    }
                                    held = p.plain && isfinite(steady.y) && steady.decided == RL_DECIDED_RAMP;
                                    if (held) rl_hold_period(&steady, periods[k]);
                                    rl_cycle_rules(&rules, &p, rl_input(&p, u), elapsed);
                                    CHECK_EQ(steady.y, rules.y);
                                    CHECK_EQ(steady.uPrevious, rules.uPrevious);
                                    CHECK_EQ(steady.yPrevious, rules.yPrevious);
                                    CHECK_EQ(steady.decided, rules.decided);
                                    CHECK_EQ(rl_running_time(&steady), rl_running_time(&rules));
                                }
                            }
                        }
}

/* The common step onto a zero target of the other sign: a limited step
 * that lands exactly on +0 while u is -0 ends at the target, -0, as rule
 * 6 says (the limited value is not below the target, so the target is
 * taken); the bits tell the two zeros apart where == does not. */
static void test_steady_ramp_onto_a_zero_of_the_other_sign(void) {
    const double starts[] = { -1.0, 1.0 }; /* up from -1, down from +1, by 1 per cycle */
    for (int real = 0; real <= 1; real++)
        for (size_t k = 0; k < 2; k++) {
            RlConfig c = defaults();
            c.real = real;
            c.rateUp.value = 2.0; /* 2 per s for a cycle of 0.5 s: exactly 1 per cycle */
            c.rateDown.value = 2.0;
            RlPrepared p;
            RlState steady, rules;
            rl_prepare(&p, resolved(&c), 0.5);
            rl_init(&steady, &p, starts[k]);
            rl_cycle(&steady, &p, starts[k], 0.5); /* a decided cycle arms the common step */
            CHECK_TRUE(p.plain && steady.decided == RL_DECIDED_RAMP);
            rules = steady;
            rl_hold_period(&steady, 0.5);
            CHECK_TRUE(rl_ramp_steady(&steady, &p, -0.0));
            rl_cycle_rules(&rules, &p, rl_input(&p, -0.0), 1.0);
            CHECK_BITS(rules.y, -0.0);
            CHECK_BITS(steady.y, rules.y);
        }
}

/* ---- rules.md, Output limits, rates below 0 and hold ------------------ */

static void test_status_section6(void) {
    RlConfig c = defaults();
    int source = -1;
    /* 0x8200 over rateUp, rateDown, rateUpNeg, rateDownNeg in that order */
    c.rateDownNeg = (RlValue){ -1.0, SRC_RATE_DOWN_NEG };
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8200);
    CHECK_EQ(source, SRC_RATE_DOWN_NEG);
    c.rateUpNeg = (RlValue){ -2.0, SRC_RATE_UP_NEG };
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8200);
    CHECK_EQ(source, SRC_RATE_UP_NEG);
    c.rateDown.value = -1.0;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8200);
    CHECK_EQ(source, SRC_RATE_DOWN_PAR);
    /* a NaN Neg rate that does not fall back (the Siemens advanced block) */
    c = defaults();
    c.rateUpNeg = (RlValue){ NAN, SRC_RATE_UP_NEG };
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8201);
    CHECK_EQ(source, SRC_RATE_UP_NEG);
    /* 0x8204: yMin > yMax, after 0x8203 and before 0x8601 */
    c = defaults();
    c.yMax = (RlValue){ 1.0, SRC_Y_MAX };
    c.yMin = (RlValue){ 2.0, SRC_Y_MIN_PAR };
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8204);
    CHECK_EQ(source, SRC_Y_MIN_PAR);
    c.cycleTime.value = -1.0;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8204);
    c.duration.value = -1.0;
    CHECK_EQ(rl_status(resolved(&c), &source), 0x8203);
    c = defaults();
    c.yMax.value = NAN;
    c.yMin.value = 5.0; /* NaN: no limit, never inverted */
    CHECK_EQ(rl_status(resolved(&c), &source), RL_STATUS_OK);
    c.yMax.value = 5.0; /* equal limits are fine */
    CHECK_EQ(rl_status(resolved(&c), &source), RL_STATUS_OK);
    CHECK_TRUE(strlen(rl_status_text(0x8204)) > 0);
}

static void test_rates_by_sign(void) {
    Block b;
    RlConfig c = with_rates(2.0, 1.0, 4.0, 0.5, -1.0);
    start(&b, &c, 3.0, 0.5);
    CHECK_TRUE(!b.prepared.plain);
    CHECK_EQ(cycle(&b, 3.0), -0.5); /* below 0: rateUpNeg * 0.5 */
    CHECK_EQ(cycle(&b, 3.0), 0.0);
    CHECK_EQ(cycle(&b, 3.0), 1.0);    /* at 0: rateUp * 0.5 */
    CHECK_EQ(cycle(&b, -3.0), -1.0);  /* from 1 >= 0: rateDown * 0.5 = 2 */
    CHECK_EQ(cycle(&b, -3.0), -1.25); /* below 0: rateDownNeg * 0.5 */
    /* a Neg rate equal to the other keeps the fast paths */
    c = defaults();
    start(&b, &c, 0.0, 0.5);
    CHECK_TRUE(b.prepared.plain);
}

static void test_output_limits(void) {
    Block b;
    RlConfig c = defaults();
    start(&b, &c, 5.0, 0.5);
    CHECK_EQ(b.state.y, 5.0);
    c.yMax.value = 2.0; /* tightened below y: ramps into the band */
    reconfigure(&b, &c);
    CHECK_TRUE(!b.prepared.plain);
    CHECK_EQ(cycle(&b, 5.0), 4.5);
    CHECK_TRUE(outputs(&b).highLimit && outputs(&b).limitingDown && outputs(&b).rampActive);
    for (int k = 0; k < 5; k++) cycle(&b, 5.0);
    CHECK_EQ(b.state.y, 2.0); /* settles at the limit */
    CHECK_TRUE(outputs(&b).highLimit && !outputs(&b).rampActive && !outputs(&b).limitingDown);
    c.yMin.value = 3.0; /* inverted: status, hold */
    reconfigure(&b, &c);
    CHECK_EQ(b.prepared.status, 0x8204);
    CHECK_EQ(cycle(&b, -5.0), 2.0);
    CHECK_TRUE(outputs(&b).lowLimit && outputs(&b).highLimit);
    c.yMax.value = NAN; /* NaN after fallback: no limit */
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, -5.0), 2.5); /* target max(-5, 3) = 3 */
    CHECK_TRUE(!outputs(&b).highLimit && outputs(&b).lowLimit);
    /* rules 1 to 4 ignore the limits */
    c.passNonFinite = true;
    CHECK_EQ(cycle(&b, INFINITY), INFINITY);
    CHECK_TRUE(!outputs(&b).highLimit && !outputs(&b).lowLimit); /* not finite */
    c.bypass = true;
    c.bypassValue = -7.0;
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 1.0), -7.0);
    /* the initial output is limited, unless asked not to or inverted */
    c = defaults();
    c.yMin.value = 1.0;
    start(&b, &c, -4.0, 1.0);
    CHECK_EQ(b.state.y, 1.0);
    c.limitInitialOutput = false;
    start(&b, &c, -4.0, 1.0);
    CHECK_EQ(b.state.y, -4.0);
    c = defaults();
    c.yMin.value = 1.0;
    c.yMax.value = 0.0;
    start(&b, &c, -4.0, 1.0);
    CHECK_EQ(b.state.y, -4.0);
    /* ... and only a finite one: an infinite initial output stays as it is */
    c = defaults();
    c.yMin.value = -1.0;
    c.yMax.value = 2.0;
    start(&b, &c, INFINITY, 1.0);
    CHECK_EQ(b.state.y, INFINITY);
    start(&b, &c, -INFINITY, 1.0);
    CHECK_EQ(b.state.y, -INFINITY);
    c.initMode = RL_INIT_VALUE;
    c.initValue = INFINITY;
    start(&b, &c, 0.0, 1.0);
    CHECK_EQ(b.state.y, INFINITY);
    /* a NaN u stays NaN as the target (the Siemens comparison holds) */
    c = defaults();
    c.passNonFinite = false;
    c.yMax.value = 2.0;
    start(&b, &c, 1.0, 1.0);
    CHECK_EQ(cycle(&b, NAN), 1.0);
}

static void test_rule5b_hold(void) {
    Block b;
    RlConfig c = defaults();
    c.initMode = RL_INIT_VALUE;
    start(&b, &c, 10.0, 0.5);
    cycle(&b, 10.0);
    CHECK_EQ(cycle(&b, 10.0), 1.0);
    CHECK_EQ(rl_running_time(&b.state), 1.0);
    c.hold = true;
    reconfigure(&b, &c);
    CHECK_TRUE(!b.prepared.plain);
    CHECK_EQ(cycle(&b, 10.0), 1.0);
    CHECK_EQ(cycle(&b, 20.0), 1.0); /* u changes: still frozen, runningTime too */
    CHECK_EQ(rl_running_time(&b.state), 1.0);
    CHECK_TRUE(!outputs(&b).rampActive && !outputs(&b).limitingUp);
    CHECK_EQ(outputs(&b).dydt, 0.0);
    CHECK_EQ(outputs(&b).remainingTime, 19.0); /* as if hold were off: (20 - 1) / 1 */
    c.hold = false;
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 20.0), 1.5); /* u as in the last cycle: runningTime goes on */
    CHECK_EQ(rl_running_time(&b.state), 1.5);
    /* an error holds first (rule 5 before 5b) */
    c.hold = true;
    c.rateUp.value = -1.0;
    reconfigure(&b, &c);
    cycle(&b, 20.0);
    CHECK_EQ(outputs(&b).remainingTime, 0.0);
}

static void test_derived_outputs(void) {
    Block b;
    RlConfig c = defaults();
    c.rateUp.value = 2.0;
    c.rateUpNeg = (RlValue){ 1.0, SRC_RATE_UP_NEG };
    c.initMode = RL_INIT_VALUE;
    c.initValue = -2.0;
    start(&b, &c, 3.0, 0.5);
    RlOutputs o = outputs(&b); /* before any cycle */
    CHECK_EQ(o.dydt, 0.0);
    CHECK_EQ(o.remainingTime, 0.0);
    CHECK_TRUE(!o.rampActive && !o.limitingUp && !o.limitingDown);
    cycle(&b, 3.0); /* -1.5: 1.5 / 1 below 0, 3 / 2 above */
    o = outputs(&b);
    CHECK_EQ(o.dydt, 1.0);
    CHECK_EQ(o.remainingTime, 3.0);
    CHECK_TRUE(o.limitingUp && !o.limitingDown && o.rampActive);
    /* a rate of 0: +inf when it holds, 0 for its leg when unlimited */
    c.rateUpNeg.value = 0.0;
    reconfigure(&b, &c);
    cycle(&b, 3.0);
    CHECK_EQ(b.state.y, -1.5);
    CHECK_EQ(outputs(&b).remainingTime, INFINITY);
    c.zeroRate = RL_ZERO_RATE_NO_LIMIT;
    c.rateUp.value = 0.0;
    reconfigure(&b, &c);
    cycle(&b, 3.0); /* both unlimited: the jump */
    CHECK_EQ(b.state.y, 3.0);
    CHECK_EQ(outputs(&b).remainingTime, 0.0);
    CHECK_EQ(outputs(&b).dydt, 9.0); /* (3 - -1.5) / 0.5 */
    /* ratePeriod 0: the rate is per cycle, per second rate / T */
    c = defaults();
    c.ratePeriod.value = 0.0;
    c.rateDown.value = 0.5;
    start(&b, &c, 2.0, 0.25);
    cycle(&b, 0.0);
    CHECK_EQ(b.state.y, 1.5);
    CHECK_EQ(outputs(&b).remainingTime, 0.75); /* 1.5 / (0.5 / 0.25) */
    CHECK_EQ(outputs(&b).dydt, -2.0);
    CHECK_TRUE(outputs(&b).limitingDown);
    /* a rate per ratePeriod of 2 s: 1 per 2 s is 0.5 per second */
    c = defaults();
    c.ratePeriod.value = 2.0;
    start(&b, &c, 0.0, 1.0);
    CHECK_EQ(cycle(&b, 3.0), 0.5);
    CHECK_EQ(outputs(&b).remainingTime, 5.0); /* 2.5 / 0.5 */
    /* the duration caps it: what is left of it, when that is less */
    c = defaults();
    c.duration.value = 3.0;
    start(&b, &c, 0.0, 0.5);
    cycle(&b, 10.0);
    CHECK_EQ(outputs(&b).remainingTime, 2.5); /* min(9.5, 3 - 0.5) */
    c.duration.value = 100.0;
    start(&b, &c, 0.0, 0.5);
    cycle(&b, 10.0);
    CHECK_EQ(outputs(&b).remainingTime, 9.5); /* min(9.5, 100 - 0.5) */
    /* held past a duration cut below runningTime: nothing is left, 0 */
    c = defaults();
    c.duration.value = 10.0;
    start(&b, &c, 0.0, 1.0);
    cycle(&b, 10.0);
    cycle(&b, 10.0);
    c.hold = true;
    c.duration.value = 1.5;
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 10.0), 2.0);
    CHECK_EQ(outputs(&b).remainingTime, 0.0); /* min(8, max(0, 1.5 - 2)) */
    c = defaults();
    c.duration.value = 1.0;
    start(&b, &c, 0.0, 0.5);
    cycle(&b, 10.0);
    CHECK_EQ(outputs(&b).remainingTime, 0.5); /* min(9.5, 1 - 0.5) */
    cycle(&b, 10.0);
    CHECK_EQ(b.state.y, 10.0); /* the jump */
    CHECK_TRUE(!outputs(&b).limitingUp);
    CHECK_EQ(outputs(&b).dydt, 19.0); /* (10 - 0.5) / 0.5 */
    /* a leg at a rate of 0 that does not limit takes no time; the other
     * one its own: 2 down to -3, 1.5 above 0 at 1/s */
    c = defaults();
    c.zeroRate = RL_ZERO_RATE_NO_LIMIT;
    c.rateDownNeg = (RlValue){ 0.0, SRC_RATE_DOWN_NEG };
    start(&b, &c, 2.0, 0.5);
    CHECK_EQ(cycle(&b, -3.0), 1.5);
    CHECK_EQ(outputs(&b).remainingTime, 1.5);
    /* a leg of no length takes no time, even at a rate of 0 that holds */
    c = defaults();
    c.rateUpNeg = (RlValue){ 0.0, SRC_RATE_UP_NEG };
    start(&b, &c, 2.0, 0.5);
    CHECK_EQ(cycle(&b, 5.0), 2.5);
    CHECK_EQ(outputs(&b).remainingTime, 2.5);
    /* not finite: dydt 0, no limit flag */
    c = defaults();
    start(&b, &c, 0.0, 1.0);
    cycle(&b, NAN);
    CHECK_EQ(outputs(&b).dydt, 0.0);
    CHECK_TRUE(!outputs(&b).highLimit && !outputs(&b).lowLimit);
    CHECK_EQ(outputs(&b).remainingTime, 0.0);
}

/* The vendor blocks have no output limits, rates below 0 or hold: rl_without_section6 turns every
 * one of its features off, whatever the configuration held. */
/* remainingTime over the legs of the way, each sign of y and uc, up and
 * down: below 0 at the Neg rate, above at the other. Rates per 1 s: up 1,
 * upNeg 0.5, down 2, downNeg 4; T = 0.25; y after one cycle from y0. */
static void test_remaining_time_legs(void) {
    static const struct {
        double y0, u, y, remaining;
    } ways[] = {
        { -3.0, -1.0, -2.875, 3.75 },  /* up, both below 0: 1.875 / 0.5 */
        { -3.0, -0.5, -2.875, 4.75 },  /* 2.375 / 0.5 */
        { -3.0, 0.5, -2.875, 6.25 },   /* 2.875 / 0.5 + 0.5 / 1 */
        { -0.5, 2.0, -0.375, 2.75 },   /* 0.375 / 0.5 + 2 / 1 */
        { 1.0, 3.0, 1.25, 1.75 },      /* both above: 1.75 / 1 */
        { 3.0, 1.0, 2.5, 0.75 },       /* down, both above 0: 1.5 / 2 */
        { 3.0, 0.5, 2.5, 1.0 },        /* 2 / 2 */
        { 3.0, -0.5, 2.5, 1.375 },     /* 2.5 / 2 + 0.5 / 4 */
        { 0.75, -2.0, 0.25, 0.625 },   /* 0.25 / 2 + 2 / 4 */
        { -1.0, -3.0, -2.0, 0.25 },    /* both below: 1 / 4 */
        { -0.5, -3.0, -1.5, 0.375 },   /* 1.5 / 4 */
        { 0.125, 2.0, 0.375, 1.625 },  /* up from above 0: 1.625 / 1 */
        { 0.25, -3.0, -0.25, 0.6875 }, /* down from below 0: 2.75 / 4 */
    };
    for (size_t i = 0; i < sizeof ways / sizeof ways[0]; i++) {
        Block b;
        RlConfig c = with_rates(1.0, 0.5, 2.0, 4.0, ways[i].y0);
        start(&b, &c, ways[i].u, 0.25);
        CHECK_EQ(cycle(&b, ways[i].u), ways[i].y);
        CHECK_EQ(outputs(&b).remainingTime, ways[i].remaining);
    }
}

/* The derived outputs after each kind of cycle. Rates per cycle of 1 s:
 * up and down 1, upNeg and downNeg 0.5, picked by the sign of yp. */
static void test_derived_outputs_by_cycle(void) {
    static const struct {
        double yp, u, y;
        bool limitingUp, limitingDown;
    } steps[] = {
        { -2.0, -1.25, -1.5, true, false },                                     /* below 0: 0.5 per cycle */
        { -0.5, 0.25, 0.0, true, false },    { 0.0, 0.75, 0.75, false, false }, /* 0 and above: 1 per cycle */
        { 0.5, 1.25, 1.25, false, false },   { 2.0, 2.75, 2.75, false, false },
        { 2.0, 3.0, 3.0, false, false }, /* the step ends on u: not cut */
        { -2.0, -2.75, -2.5, false, true },  { -0.5, -1.25, -1.0, false, true },
        { 0.0, -0.75, -0.75, false, false }, { 0.5, -0.25, -0.25, false, false },
        { 2.0, 1.25, 1.25, false, false },   { 2.0, 1.0, 1.0, false, false },
    };
    Block b;
    RlConfig c;
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++) {
        c = with_rates(1.0, 0.5, 1.0, 0.5, steps[i].yp);
        start(&b, &c, steps[i].u, 1.0);
        CHECK_EQ(cycle(&b, steps[i].u), steps[i].y);
        CHECK_EQ(outputs(&b).limitingUp, steps[i].limitingUp);
        CHECK_EQ(outputs(&b).limitingDown, steps[i].limitingDown);
    }
    /* hold and the duration jump cut no step */
    c = defaults();
    start(&b, &c, 2.0, 1.0);
    c.hold = true;
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, 0.0), 2.0);
    CHECK_TRUE(!outputs(&b).limitingDown);
    c = defaults();
    c.duration.value = 1.0;
    start(&b, &c, 10.0, 0.5);
    CHECK_EQ(cycle(&b, 0.0), 9.5);
    CHECK_TRUE(outputs(&b).limitingDown);
    CHECK_EQ(cycle(&b, 0.0), 0.0);
    CHECK_TRUE(!outputs(&b).limitingDown);
    /* lowLimit: at yMin or below, finite */
    c = defaults();
    c.yMin.value = 1.0;
    start(&b, &c, 3.0, 1.0);
    CHECK_EQ(cycle(&b, 0.0), 2.0);
    CHECK_TRUE(!outputs(&b).lowLimit);
    CHECK_EQ(cycle(&b, 0.0), 1.0);
    CHECK_TRUE(outputs(&b).lowLimit);
    CHECK_EQ(cycle(&b, -INFINITY), -INFINITY);
    CHECK_TRUE(!outputs(&b).lowLimit);
    /* dydt after a jump of rules 1 to 4 (bypass): the jump per second */
    c = defaults();
    c.bypass = true;
    c.bypassValue = 8.0;
    start(&b, &c, 1.0, 0.5);
    CHECK_EQ(cycle(&b, 1.0), 8.0);
    CHECK_EQ(outputs(&b).dydt, 14.0);
    /* Siemens comparison: ramping towards +inf, remainingTime is 0 (uc not
     * finite); at no limit the output reaches +inf, dydt 0; an output at
     * +inf above a new yMax stays there, remainingTime 0 (y not finite) */
    c = defaults();
    c.passNonFinite = false;
    start(&b, &c, 0.0, 1.0);
    CHECK_EQ(cycle(&b, INFINITY), 1.0);
    CHECK_EQ(outputs(&b).remainingTime, 0.0);
    c.rateUp.value = INFINITY;
    start(&b, &c, 0.0, 1.0);
    CHECK_EQ(cycle(&b, INFINITY), INFINITY);
    CHECK_EQ(outputs(&b).dydt, 0.0);
    c.yMax.value = 5.0;
    reconfigure(&b, &c);
    CHECK_EQ(cycle(&b, INFINITY), INFINITY);
    CHECK_TRUE(outputs(&b).rampActive);
    CHECK_EQ(outputs(&b).remainingTime, 0.0);
}

static void test_without_section6(void) {
    RlConfig c = defaults();
    c.rateUp = (RlValue){ 4.0, SRC_RATE_UP };
    c.rateDown = (RlValue){ 3.0, SRC_RATE_DOWN };
    c.rateUpNeg = (RlValue){ 2.0, SRC_RATE_UP_NEG };
    c.rateDownNeg = (RlValue){ 1.0, SRC_RATE_DOWN_NEG };
    c.yMax = (RlValue){ 5.0, SRC_Y_MAX };
    c.yMin = (RlValue){ -5.0, SRC_Y_MIN };
    c.hold = true;
    c.limitInitialOutput = true;
    rl_without_section6(&c);
    CHECK_EQ(c.rateUpNeg.value, 4.0);
    CHECK_EQ(c.rateUpNeg.source, SRC_RATE_UP);
    CHECK_EQ(c.rateDownNeg.value, 3.0);
    CHECK_EQ(c.rateDownNeg.source, SRC_RATE_DOWN);
    CHECK_TRUE(isnan(c.yMax.value) && isnan(c.yMin.value));
    CHECK_TRUE(!c.hold);
    CHECK_TRUE(!c.limitInitialOutput);
    /* and so a held vendor block ramps */
    Block b;
    start(&b, &c, 0.0, 1.0);
    cycle(&b, 10.0);
    CHECK_EQ(b.state.y, 4.0);
}

/* rl_init sets every field of the state: a state that held another run
 * (an instance reset, a block reused) starts afresh. */
static void test_init_of_a_used_state(void) {
    RlConfig c = defaults();
    RlState s = { .y = 7.0,
                  .uPrevious = 8.0,
                  .yPrevious = 9.0,
                  .decided = RL_DECIDED_RAMP,
                  .runCycles = 5,
                  .runPeriod = 0.5,
                  .runBase = 3.0 };
    RlPrepared p;
    rl_prepare(&p, &c, 1.0);
    rl_init(&s, &p, 2.0);
    CHECK_EQ(s.y, 2.0);
    CHECK_EQ(s.yPrevious, 2.0);
    CHECK_EQ(s.uPrevious, 2.0);
    CHECK_EQ(s.decided, RL_DECIDED_NOTHING);
    CHECK_EQ(s.runCycles, 0);
    CHECK_EQ(s.runPeriod, 0.0);
    CHECK_EQ(s.runBase, 0.0);
}

/* ---- rules.md, Arithmetic: REAL---------------------------------------- */

/* binary32 rounding as a value enters: to nearest, ties to even, and
 * from 2^128 - 2^103 on (halfway above FLT_MAX) an infinity */
static void test_binary32_entry(void) {
    CHECK_BITS((double)rl_binary32(0.01), 0.009999999776482582);
    CHECK_BITS((double)rl_binary32(1.0 + ldexp(1.0, -24)), 1.0); /* a tie: to even */
    CHECK_BITS((double)rl_binary32(1.0 + 3 * ldexp(1.0, -24)), 1.0 + ldexp(1.0, -22));
    CHECK_BITS((double)rl_binary32(RL_FLOAT_OVERFLOW), INFINITY);
    CHECK_BITS((double)rl_binary32(-RL_FLOAT_OVERFLOW), -INFINITY);
    CHECK_BITS((double)rl_binary32(nextafter(RL_FLOAT_OVERFLOW, 0.0)), (double)FLT_MAX);
    CHECK_BITS((double)rl_binary32(1e300), INFINITY);
    CHECK_BITS((double)rl_binary32(-1e-50), -0.0);
    CHECK_TRUE(isnan(rl_binary32(NAN)));
}

/* Worked by hand (rules.md, Arithmetic): 0.01 per cycle from 262000. In REAL the
 * step is the float 0.009999999776, which below 2^18 rounds up to the
 * float spacing 2^-6 and at 2^18 = 262144 (spacing 2^-5) rounds away: the
 * ramp stalls there, still limited. In LREAL each step is 0.01 rounded to
 * the double spacing, 171798692 * 2^-34 on both sides of 2^18. */
static void test_real_ramp_stalls_at_2_pow_18(void) {
    RlConfig c = defaults();
    c.ratePeriod.value = 0.0;
    c.rateUp.value = c.rateDown.value = 0.01;
    c.initMode = RL_INIT_VALUE;
    c.initValue = 262000.0;
    for (int real = 0; real <= 1; real++) {
        c.real = real;
        Block b;
        start(&b, &c, 1e6, 0.01);
        for (int n = 1; n <= 9216; n++) {
            cycle(&b, 1e6);
            if (real && (n == 1 || n == 9215)) CHECK_BITS(b.state.y, 262000.0 + n / 64.0);
        }
        CHECK_BITS(b.state.y, real ? 262144.0 : 262000.0 + ldexp(9216.0 * 171798692.0, -34));
        RlState run = b.state;
        for (int n = 0; n < 20000 - 9216; n++) cycle(&b, 1e6);
        rl_run(&run, &b.prepared, 1e6, 9217, 20000, 0.01);
        check_same_state(&run, &b.state);
        CHECK_BITS(b.state.y, real ? 262144.0 : 262000.0 + ldexp(20000.0 * 171798692.0, -34));
        const RlOutputs o = outputs(&b);
        CHECK_TRUE(o.rampActive && o.limitingUp); /* REAL: yp + maxUp = 262144 < 1e6, and no move */
        CHECK_BITS(o.dydt, real ? 0.0 : ldexp(171798692.0, -34) / 0.01);
    }
}

/* 1e-5 per cycle from 20 to 30: the float step is 5.24 spacings of 2^-19
 * and rounds to 5, so 30 takes 2^20 = 1,048,576 cycles; the double step
 * 2814749767 * 2^-48 is a little under 1e-5: 1,000,001 cycles. */
static void test_real_slow_ramp(void) {
    RlConfig c = defaults();
    c.ratePeriod.value = 0.0;
    c.rateUp.value = c.rateDown.value = 1e-5;
    c.initMode = RL_INIT_VALUE;
    c.initValue = 20.0;
    Block b;
    c.real = true;
    start(&b, &c, 30.0, 0.01);
    rl_run(&b.state, &b.prepared, 30.0, 1, (1u << 20) - 1, 0.01);
    CHECK_BITS(b.state.y, 30.0 - 5 * ldexp(1.0, -19));
    rl_run(&b.state, &b.prepared, 30.0, 1u << 20, 1u << 20, 0.01);
    CHECK_BITS(b.state.y, 30.0);
    c.real = false;
    start(&b, &c, 30.0, 0.01);
    rl_run(&b.state, &b.prepared, 30.0, 1, 1000000, 0.01);
    CHECK_BITS(b.state.y, 20.0 + ldexp(1000000.0 * 2814749767.0, -48));
    rl_run(&b.state, &b.prepared, 30.0, 1000001, 1000001, 0.01);
    CHECK_BITS(b.state.y, 30.0);
}

/* What enters is judged in binary32: values beyond the float range are
 * infinities, tiny ones zeros, and values equal as floats are equal. */
static void test_real_entry_values(void) {
    for (int real = 0; real <= 1; real++) {
        RlConfig c = defaults();
        c.real = real;
        RlPrepared p;
        c.rateUp.value = -1e-50; /* -0 in binary32: not negative */
        rl_prepare(&p, resolved(&c), 0.1);
        CHECK_EQ(p.status, real ? RL_STATUS_OK : RL_STATUS_RATE_NEGATIVE);
        CHECK_EQ(p.maxUp, real ? 0.0 : -1e-50 * 0.1); /* a rate of 0 holds */
        c = defaults();
        c.real = real;
        c.ratePeriod.value = 1e39; /* +inf in binary32 */
        rl_prepare(&p, resolved(&c), 0.1);
        CHECK_EQ(p.status, real ? RL_STATUS_RATE_PERIOD : RL_STATUS_OK);
        c = defaults();
        c.real = real;
        c.yMax.value = 1.0;
        c.yMin.value = 1.00000001; /* the same float */
        rl_prepare(&p, resolved(&c), 0.1);
        CHECK_EQ(p.status, real ? RL_STATUS_OK : RL_STATUS_LIMITS);
        /* a u beyond the float range passes as +inf (rule 1); a finite one ramps */
        c = defaults();
        c.real = real;
        Block b;
        start(&b, &c, 0.0, 0.1);
        CHECK_BITS(cycle(&b, 1e39), real ? INFINITY : 0.1);
        /* inputs that differ below float precision are the same input */
        start(&b, &c, 0.0, 0.1);
        cycle(&b, 5.0);
        cycle(&b, 5.0000000001);
        CHECK_EQ(rl_running_time(&b.state), real ? 0.2 : 0.1);
        CHECK_BITS(b.state.uPrevious, real ? 5.0 : 5.0000000001);
        /* the initial output enters too */
        c.initMode = RL_INIT_VALUE;
        c.initValue = 0.1;
        start(&b, &c, 0.0, 0.1);
        CHECK_BITS(b.state.y, real ? 0.10000000149011612 : 0.1);
        /* the limit: rate * T / ratePeriod, each step in binary32 */
        c = defaults();
        c.real = real;
        c.rateUp.value = 3.0;
        c.ratePeriod.value = 0.7;
        rl_prepare(&p, resolved(&c), 0.1);
        CHECK_BITS(p.maxUp, real ? (double)((3.0f * 0.1f) / 0.7f) : 3.0 * 0.1 / 0.7);
    }
}

/* dydt in binary32: (y - yp) / T, T rounded; a step of 2^-6 over the float
 * 0.01 is 1.5625000349, the float 1.5625 */
static void test_real_dydt(void) {
    RlConfig c = defaults();
    c.real = true;
    c.initMode = RL_INIT_VALUE;
    c.initValue = 262000.0;
    Block b;
    start(&b, &c, 1e6, 0.01);
    cycle(&b, 1e6);
    CHECK_BITS(b.state.y, 262000.015625);
    CHECK_BITS(outputs(&b).dydt, 1.5625);
}

/* d2ydt2 after a duration jump of about the largest value times T^2
 * (rules.md, Outputs derived from the last cycle): both dydt finite, the
 * quotient (dydt - dydt') / T beyond the arithmetic's range, so 0; no
 * floating-point exception on the way. Worked in powers of 2 (exact):
 * T = 2^-10 s, rateUp = 2^(k+10) per s, so 2^k per cycle; u = 2^(k+20);
 * the duration is 3 cycles. Cycle 1: y = 2^k, dydt = 2^(k+10), d2ydt2 =
 * 2^(k+20) (finite: kept). Cycle 2: y = 2^(k+1), d2ydt2 = 0. Cycle 3
 * jumps: y = 2^(k+20), dydt = 2^(k+30) - 2^(k+11), (dydt - 2^(k+10)) / T
 * = 2^(k+40) - 3 * 2^(k+20): beyond the largest value for k = 90 (REAL,
 * 2^128) and k = 990 (LREAL, 2^1024). Cycle 4 at rest: dydt = 0, (0 -
 * dydt') / T = -(2^(k+40) - 2^(k+21)), beyond it too. */
static void test_d2ydt2_overflow_is_0(void) {
    static const struct {
        bool real;
        int k;
    } cases[] = { { true, 90 }, { false, 990 } };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const int k = cases[i].k;
        const double T = ldexp(1.0, -10);
        RlConfig c = defaults();
        c.real = cases[i].real;
        c.rateUp.value = ldexp(1.0, k + 10);
        c.duration.value = 3 * T;
        Block b;
        start(&b, &c, 0.0, T);
        const double u = ldexp(1.0, k + 20);
        feclearexcept(FE_ALL_EXCEPT);
        CHECK_BITS(cycle(&b, u), ldexp(1.0, k));
        CHECK_BITS(outputs(&b).dydt, ldexp(1.0, k + 10));
        CHECK_BITS(outputs(&b).d2ydt2, ldexp(1.0, k + 20));
        CHECK_BITS(cycle(&b, u), ldexp(1.0, k + 1));
        CHECK_BITS(outputs(&b).d2ydt2, 0.0);
        CHECK_BITS(cycle(&b, u), u);
        CHECK_BITS(outputs(&b).dydt, ldexp(1.0, k + 30) - ldexp(1.0, k + 11));
        CHECK_BITS(outputs(&b).d2ydt2, 0.0);
        CHECK_BITS(cycle(&b, u), u);
        CHECK_BITS(outputs(&b).dydt, 0.0);
        CHECK_BITS(outputs(&b).d2ydt2, 0.0);
        CHECK_EQ(fetestexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW), 0);
        feclearexcept(FE_ALL_EXCEPT);
    }
}

/* the same bits, or both NaN (an invalid operation's NaN has the
 * platform's sign) */
#define CHECK_SAME(actual, expected) \
    ((isnan(actual) && isnan(expected)) ? CHECK_TRUE(isnan(actual)) : CHECK_BITS(actual, expected))

/* The quiet operations (rate_limiter.h) give IEEE's result bit for bit,
 * an overflow's infinity included, and raise none of the exceptions a
 * real-time target traps; the plain operations here are the reference. */
static void test_quiet_arithmetic(void) {
    static const double values[] = {
        0.0, -0.0, 5e-324, 1e-300, 0.5, 1.0, 1.0000000000000002, 2.0, 3.0, 1e300, 1e308, -1e308,
        8.98846567431158e307 /* 2^1023 */, 1.348269851146737e308 /* 1.5 * 2^1023 */, DBL_MAX, -DBL_MAX,
        1.7976931348623155e308 /* DBL_MAX - 1 ulp */, 9.9792015476736e291 /* 2^970 */,
        3.4028234663852886e38 /* FLT_MAX */, 3.4028235677973366e38, -3.4028234663852886e38, 1.8446744073709552e19,
        /* exact results of 2^1024 (infinity) or just below: 2^1023 + 2^1023, 2^512 * 2^512,
         * DBL_MAX + DBL_MAX * 2^-53, DBL_MAX / (1 - 2^-53); (2^512 - ulp) * 2^512 is DBL_MAX */
        -8.98846567431158e307 /* -2^1023 */, 1.3407807929942597e154 /* 2^512 */, -1.3407807929942597e154,
        1.3407807929942596e154 /* 2^512 - ulp */, 1.9958403095347196e292 /* DBL_MAX * 2^-53 */,
        9.979201547673598e291 /* 2^970 - ulp */, 0.9999999999999999 /* 1 - 2^-53 */, 1.9999999999999998 /* 2 - 2^-52 */,
        INFINITY, -INFINITY
    };
    const int n = (int)(sizeof values / sizeof values[0]);
    int raised = 0;
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            volatile double a = values[i], b = values[j];
            const bool both_infinite = isinf(a) && isinf(b);
            double sum = 0, product = 0, quotient = 0;
            float sum32 = 0, product32 = 0, quotient32 = 0;
            const float a32 = rl_binary32(a), b32 = rl_binary32(b);
            feclearexcept(FE_ALL_EXCEPT);
            if (isfinite(a)) sum = rl_sum(a, b);
            if (!(isinf(a) && b == 0) && !(isinf(b) && a == 0)) product = rl_product(a, b);
            if (!both_infinite) quotient = rl_quotient(a, b);
            if (isfinite(a32)) sum32 = rl_sum_real(a32, b32);
            if (!(isinf(a32) && b32 == 0) && !(isinf(b32) && a32 == 0)) product32 = rl_product_real(a32, b32);
            if (!(isinf(a32) && isinf(b32))) quotient32 = rl_quotient_real(a32, b32);
            raised |= fetestexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
            if (isfinite(a)) CHECK_SAME(sum, a + b);
            if (!(isinf(a) && b == 0) && !(isinf(b) && a == 0)) CHECK_SAME(product, a * b);
            if (!both_infinite) CHECK_SAME(quotient, a / b);
            if (isfinite(a32)) CHECK_SAME((double)sum32, (double)(float)(a32 + b32));
            if (!(isinf(a32) && b32 == 0) && !(isinf(b32) && a32 == 0)) {
                CHECK_SAME((double)product32, (double)(float)(a32 * b32));
            }
            if (!(isinf(a32) && isinf(b32))) CHECK_SAME((double)quotient32, (double)(float)(a32 / b32));
        }
    }
    CHECK_EQ(raised, 0);
    feclearexcept(FE_ALL_EXCEPT);
}

/* rules.md, Acceleration limit: the helpers its steps are written with,
 * against values worked by hand (dyadic, so exact). */
static void test_acceleration_helpers(void) {
    /* one unit in the last place: 0's is the smallest subnormal */
    CHECK_BITS(rl_ulp_lreal(0.0), ldexp(1.0, -1074));
    CHECK_BITS(rl_ulp_lreal(1.0), ldexp(1.0, -52));
    CHECK_BITS(rl_ulp_lreal(-3.0), ldexp(1.0, -51));
    CHECK_BITS((double)rl_ulp_real(0.0f), ldexp(1.0, -149));
    CHECK_BITS((double)rl_ulp_real(1.0f), ldexp(1.0, -23));
    /* braking distance B(s) with b = 0.25: the steps s - 0.25, s - 0.5, ... while positive */
    CHECK_EQ(rl_braking_distance_lreal(0.1, 0.25), 0.0); /* n = 0: 0 * (0.1 - 0.125) = -0 */
    CHECK_BITS(rl_braking_distance_lreal(0.25, 0.25), 0.0);
    CHECK_BITS(rl_braking_distance_lreal(0.5, 0.25), 0.25);
    CHECK_BITS(rl_braking_distance_lreal(0.75, 0.25), 0.75);
    CHECK_BITS(rl_braking_distance_lreal(1.0, 0.25), 1.5);
    CHECK_BITS((double)rl_braking_distance_real(1.0f, 0.25f), 1.5);
    /* S(E): the largest step that stops within E */
    CHECK_BITS(rl_stoppable_step_lreal(0.0, 0.25), 0.0);
    CHECK_BITS(rl_stoppable_step_lreal(0.25, 0.25), 0.25);
    CHECK_BITS(rl_stoppable_step_lreal(0.75, 0.25), 0.5);
    CHECK_BITS(rl_stoppable_step_lreal(1.5, 0.25), 0.75);
    CHECK_BITS(rl_stoppable_step_lreal(2.5, 0.25), 1.0);
    CHECK_BITS((double)rl_stoppable_step_real(1.5f, 0.25f), 0.75);
    /* exact feasibility: 0.75 + B(0.75) = 1.5 stops within 1.5, one unit more does not */
    CHECK_TRUE(rl_stops_within_lreal(0.75, 0.25, 1.5));
    CHECK_TRUE(!rl_stops_within_lreal(nextafter(0.75, 1.0), 0.25, 1.5));
    CHECK_TRUE(!rl_stops_within_lreal(0.75, 0.25, nextafter(1.5, 0.0)));
    CHECK_TRUE(rl_stops_within_real(0.75f, 0.25f, 1.5f));
    CHECK_TRUE(!rl_stops_within_real(nextafterf(0.75f, 1.0f), 0.25f, 1.5f));
    /* directed sums: 1 + 2^-60 rounds to 1, below the exact sum; 1 - 2^-60 to 1, above it */
    CHECK_BITS(rl_directed_sum_lreal(1.0, ldexp(1.0, -60), true), 1.0);
    CHECK_BITS(rl_directed_sum_lreal(1.0, ldexp(1.0, -60), false), nextafter(1.0, 2.0));
    CHECK_BITS(rl_directed_sum_lreal(1.0, -ldexp(1.0, -60), true), nextafter(1.0, 0.0));
    CHECK_BITS(rl_directed_sum_lreal(1.0, -ldexp(1.0, -60), false), 1.0);
    CHECK_BITS(rl_directed_sum_lreal(-1.0, -ldexp(1.0, -60), false), nextafter(-1.0, -2.0));
    CHECK_BITS((double)rl_directed_sum_real(1.0f, (float)ldexp(1.0, -30), false), (double)nextafterf(1.0f, 2.0f));
    CHECK_BITS(rl_directed_sum_lreal(0.5, 0.25, true), 0.75); /* exact: as it is */
}

/* remainingTime with a kept plan (RlPlan) is the fresh plan's, read after
 * every cycle, after runs of cycles, through a hold, a target moved and a
 * limit changed; and the output reaches uc after exactly that time. */
static void test_kept_plan_equals_fresh_plan(void) {
    for (int real = 0; real <= 1; real++) {
        Block b;
        RlConfig c = defaults();
        c.rateUp.value = 3.0;
        c.rateDown.value = 3.0;
        c.accelMax.value = 0.7;
        c.decelMax.value = 0.4;
        c.real = real;
        start(&b, &c, 0.0, 0.01);
        RlPlan plan;
        memset(&plan, 0, sizeof plan);
        double u = 25.0, predictedEnd = -1;
        int mismatches = 0, arrivals = 0;
        for (int n = 1; n <= 9000; n++) {
            if (n == 1500) u = 11.0; /* the target moved mid-ramp */
            if (n == 3000) c.hold = true, reconfigure(&b, &c);
            if (n == 3040) c.hold = false, reconfigure(&b, &c);
            if (n == 3500) c.accelMax.value = 0.9, reconfigure(&b, &c);
            if (n == 4000) u = -7.5; /* across 0 */
            cycle(&b, u);
            if (n % 7 == 3) continue; /* runs of cycles unread */
            RlOutputs kept, fresh;
            rl_outputs(&b.state, &b.prepared, &plan, &kept);
            rl_outputs(&b.state, &b.prepared, NULL, &fresh);
            rl_outputs(&b.state, &b.prepared, &plan, &kept); /* read twice: the same */
            mismatches += memcmp(&kept.remainingTime, &fresh.remainingTime, sizeof(double)) != 0;
            if (n > 4000 && predictedEnd < 0 && isfinite(kept.remainingTime) && kept.remainingTime > 0) {
                predictedEnd = n + kept.remainingTime / 0.01;
            }
            if (n > 4000 && b.state.y == (real ? (double)(float)u : u) && predictedEnd > 0) {
                CHECK_TRUE(fabs(n - predictedEnd) < 1e-6 * predictedEnd); /* arrived when it said */
                predictedEnd = 0;
                arrivals++;
            }
        }
        CHECK_EQ(mismatches, 0);
        CHECK_EQ(arrivals, 1);
        /* a plan made afresh at every read would run about 10^7 cycles */
        CHECK_TRUE(plan.work < 40000);
    }
}

/* REAL: a step from rest onto a tiny target 7.3e11 away lands on it with
 * a speed a unit in the last place (65536) above b after rounding; the
 * output then rests on the target instead of passing it by that unit. */
static void test_landing_leaves_no_speed(void) {
    Block b;
    RlConfig c = defaults();
    c.rateUp.value = c.rateDown.value = 117771771536283.81;
    c.ratePeriod.value = 1.0;
    c.accelMax.value = 7285355228600680.0;
    c.real = true;
    start(&b, &c, -728535465984.0, 0.01);
    const double uc = (double)(float)1.175494351e-26;
    CHECK_BITS(cycle(&b, 1.175494351e-26), uc); /* one step from rest: the landing */
    for (int n = 0; n < 3; n++) CHECK_BITS(cycle(&b, 1.175494351e-26), uc);
}

/* The zone step against its definition, counted: the largest s whose K =
 * ceil((s - v) / b) steps above v all start before the boundary z away,
 * (K - 1) * s - b * (K - 1) * (K - 2) / 2 <= z (values whose sums are exact). */
static double zone_step_counted(double z, double v, double b) {
    double best = v + b; /* K = 1 */
    for (int k = 2; k < 100000; k++) {
        const double low = v + (k - 1) * b, cap = z / (k - 1) + b * (k - 2) / 2;
        const double s = v + k * b < cap ? v + k * b : cap;
        if (s > low && s > best) best = s;
        if (cap <= low) break;
    }
    return best;
}

static void test_zone_step_counted(void) {
    const double zs[] = { 0, 0.75, 1, 2.5, 7, 40, 1000, 123456.5 }, vs[] = { 0, 0.5, 2, 3.25 }, bs[] = { 0.25, 1, 2 };
    for (int i = 0; i < 8; i++) {
        for (int j = 0; j < 4; j++) {
            for (int k = 0; k < 3; k++) {
                CHECK_BITS(rl_zone_step_lreal(zs[i], vs[j], bs[k]), zone_step_counted(zs[i], vs[j], bs[k]));
            }
        }
    }
}

int main(void) {
    test_quiet_arithmetic();
    test_acceleration_helpers();
    test_kept_plan_equals_fresh_plan();
    test_landing_leaves_no_speed();
    test_zone_step_counted();
    test_rule0_resolve();
    test_rule0_limits();
    test_status_codes();
    test_initialisation();
    test_rule1_non_finite_input();
    test_siemens_comparison();
    test_rule2_bypass();
    test_rule3_init_delay();
    test_rule4_invalid_previous_output();
    test_rule5_configuration_error_holds();
    test_rule6_ramp();
    test_rule6_duration();
    test_signed_zeros();
    test_running_time_period_change();
    test_fast_paths_equal_rules();
    test_run_of_no_cycles();
    test_steady_ramp_equals_rules();
    test_steady_ramp_onto_a_zero_of_the_other_sign();
    test_status_section6();
    test_rates_by_sign();
    test_output_limits();
    test_rule5b_hold();
    test_derived_outputs();
    test_remaining_time_legs();
    test_derived_outputs_by_cycle();
    test_without_section6();
    test_init_of_a_used_state();
    test_binary32_entry();
    test_real_ramp_stalls_at_2_pow_18();
    test_real_slow_ramp();
    test_real_entry_values();
    test_real_dydt();
    test_d2ydt2_overflow_is_0();
    printf("%d passed, %d failed\n", checks - failures, failures);
    return failures ? 1 : 0;
}
