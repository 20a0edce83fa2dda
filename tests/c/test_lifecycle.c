/* An FMU binary's lifecycle as an importer drives it (dlopen), FMI 2 and 3:
 *
 *   test_lifecycle <2|3> <staged FMU folder> <instantiations> <instances> [<staged SE FMU folder>]
 *
 * (FMI 3 only, and required there: the Scheduled Execution FMU's folder, build/stage/fmi3-se/<Model>, whose model description
 * declares the Clock; its binary is the Co-Simulation FMU's, and runs Scheduled Execution after 1.)
 * 1. a full simulation using every kind of call (set, step, get, FMU states,
 *    serialize and deserialize, reset, terminate, free), so that valgrind
 *    memcheck can watch all of it; then the same as Model Exchange (time
 *    events, event updates, Continuous-Time Mode, its FMU states), each
 *    output equal to Co-Simulation's at the same cycle end;
 * 2. <instantiations> instantiate/free cycles: afterwards as many blocks
 *    are live as before (FMI 2 memory callbacks and an interposed malloc);
 * 3. <instances> instances alive at once, each stepped with its own input,
 *    each output checked against a run of one instance alone;
 * 4. out of memory: each allocation of an instantiation, of an FMU state
 *    and of a deserialized one refused in turn: no instance or state, an
 *    error, no crash, nothing held, and the instance runs on after a reset.
 * Exit 0 when every check passes. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#include "fmu_library.h"

/* ---- live allocations: interposed malloc and FMI 2 callbacks ------------ */

static long liveBlocks; /* allocated minus freed, from the FMU's side */
static int counting;
static long failCountdown; /* > 0: the FMU's allocation that many from now is refused */

static int refuse_allocation(void) {
    return failCountdown > 0 && --failCountdown == 0;
}

#if defined(__SANITIZE_ADDRESS__)
/* ASan owns malloc: the FMU's own blocks are not counted here, and
 * LeakSanitizer reports any still held at exit instead. */
#define LIBC(function) function
#else
#define LIBC(function) __libc_##function
extern void *__libc_malloc(size_t size);
extern void *__libc_calloc(size_t count, size_t size);
extern void *__libc_realloc(void *pointer, size_t size);
extern void __libc_free(void *pointer);

void *malloc(size_t size) {
    if (counting && refuse_allocation()) return NULL;
    void *p = __libc_malloc(size);
    if (counting && p) liveBlocks++;
    return p;
}

void *calloc(size_t count, size_t size) {
    if (counting && refuse_allocation()) return NULL;
    void *p = __libc_calloc(count, size);
    if (counting && p) liveBlocks++;
    return p;
}

void *realloc(void *pointer, size_t size) {
    void *p = __libc_realloc(pointer, size);
    if (counting && p && !pointer) liveBlocks++;
    return p;
}

void free(void *pointer) {
    if (counting && pointer) liveBlocks--;
    __libc_free(pointer);
}
#endif

static long callbackBlocks;

static void *allocate(size_t count, size_t size) {
    if (refuse_allocation()) return NULL;
    void *p = LIBC(calloc)(count, size);
    if (p) callbackBlocks++;
    return p;
}

static void release_memory(void *p) {
    if (p) callbackBlocks--;
    LIBC(free)(p);
}

static int messages;

static void log2_message(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                         fmi2String message, ...) {
    (void)env;
    (void)name;
    (void)category;
    (void)status;
    (void)message;
    messages++;
}

static void log3_message(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    (void)status;
    (void)category;
    (void)message;
    messages++;
}

/* ---- checks ---------------------------------------------------------- */

static int failures;

#define CHECK(condition) \
    do { \
        if (!(condition)) { \
            failures++; \
            fprintf(stderr, "%s:%d: %s\n", __FILE__, __LINE__, #condition); \
        } \
    } while (0)

/* ---- the FMU --------------------------------------------------------- */

static int version;
static char token[128];
static unsigned uVr, yVr, cycleTimeVr;
static unsigned clockVr; /* FMI 3: Scheduled Execution's Clock */
static int accelVr = -1; /* accelMax, where the model has it: its plan is made, kept and freed */

#define F2(name) ((name##TYPE *)function(#name))
#define F3(name) ((name##TYPE *)function(#name))

static const fmi2CallbackFunctions callbacks = { log2_message, allocate, release_memory, NULL, NULL };

static void *instantiate(const char *name) {
    if (version == 2) {
        return F2(fmi2Instantiate)(name, fmi2CoSimulation, token, "", &callbacks, fmi2False, fmi2False);
    }
    return F3(fmi3InstantiateCoSimulation)(name, token, NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, NULL,
                                           log3_message, NULL);
}

static void *instantiate_model_exchange(const char *name) {
    if (version == 2) {
        return F2(fmi2Instantiate)(name, fmi2ModelExchange, token, "", &callbacks, fmi2False, fmi2False);
    }
    return F3(fmi3InstantiateModelExchange)(name, token, NULL, fmi3False, fmi3False, NULL, log3_message);
}

static int set_real(void *c, unsigned vr, double value) {
    return version == 2 ? F2(fmi2SetReal)(c, &vr, 1, &value) : F3(fmi3SetFloat64)(c, &vr, 1, &value, 1);
}

static void release(void *c) {
    if (version == 2) F2(fmi2FreeInstance)(c);
    else F3(fmi3FreeInstance)(c);
}

static int start(void *c) {
    if (version == 2) {
        return F2(fmi2SetupExperiment)(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK &&
               F2(fmi2EnterInitializationMode)(c) == fmi2OK && F2(fmi2ExitInitializationMode)(c) == fmi2OK;
    }
    return F3(fmi3EnterInitializationMode)(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) == fmi3OK &&
           F3(fmi3ExitInitializationMode)(c) == fmi3OK;
}

static int set_u(void *c, double u) {
    return version == 2 ? F2(fmi2SetReal)(c, &uVr, 1, &u) : F3(fmi3SetFloat64)(c, &uVr, 1, &u, 1);
}

static double get_y(void *c) {
    double y = NAN;
    int status = version == 2 ? F2(fmi2GetReal)(c, &yVr, 1, &y) : F3(fmi3GetFloat64)(c, &yVr, 1, &y, 1);
    CHECK(status == 0);
    return y;
}

static int step(void *c, double t, double h) {
    if (version == 2) return F2(fmi2DoStep)(c, t, h, fmi2True);
    fmi3Boolean a, b, e;
    fmi3Float64 last;
    return F3(fmi3DoStep)(c, t, h, fmi3True, &a, &b, &e, &last);
}

static int set_debug_logging(void *c, size_t n, const char *const categories[]) {
    return version == 2 ? F2(fmi2SetDebugLogging)(c, fmi2True, n, categories)
                        : F3(fmi3SetDebugLogging)(c, fmi3True, n, categories);
}

static double input(int k, int i) {
    return ((k + i) % 7) * 1.5 - 4.0;
}

/* ---- 1. a full simulation, every kind of call ------------------------- */

/* FMU state: get, serialize, deserialize (corrupted bytes: refused, then
 * recovered), set, free */
static void state_round_trip(void *c) {
    void *state = NULL, *copy = NULL, *bad = NULL;
    size_t size = 0;
    if (version == 2) {
        CHECK(F2(fmi2GetFMUstate)(c, &state) == fmi2OK);
        CHECK(F2(fmi2SerializedFMUstateSize)(c, state, &size) == fmi2OK);
        fmi2Byte *bytes = LIBC(malloc)(size);
        CHECK(F2(fmi2SerializeFMUstate)(c, state, bytes, size) == fmi2OK);
        CHECK(F2(fmi2DeSerializeFMUstate)(c, bytes, size, &copy) == fmi2OK);
        bytes[size / 2] ^= 0x40;
        CHECK(F2(fmi2DeSerializeFMUstate)(c, bytes, size, &bad) == fmi2Error && bad == NULL);
        LIBC(free)(bytes);
        CHECK(F2(fmi2SetFMUstate)(c, copy) == fmi2OK);
        CHECK(F2(fmi2FreeFMUstate)(c, &copy) == fmi2OK);
        CHECK(F2(fmi2FreeFMUstate)(c, &state) == fmi2OK);
    } else {
        CHECK(F3(fmi3GetFMUState)(c, &state) == fmi3OK);
        CHECK(F3(fmi3SerializedFMUStateSize)(c, state, &size) == fmi3OK);
        fmi3Byte *bytes = LIBC(malloc)(size);
        CHECK(F3(fmi3SerializeFMUState)(c, state, bytes, size) == fmi3OK);
        CHECK(F3(fmi3DeserializeFMUState)(c, bytes, size, &copy) == fmi3OK);
        bytes[size / 2] ^= 0x40;
        CHECK(F3(fmi3DeserializeFMUState)(c, bytes, size, &bad) == fmi3Error && bad == NULL);
        LIBC(free)(bytes);
        CHECK(F3(fmi3SetFMUState)(c, copy) == fmi3OK);
        CHECK(F3(fmi3FreeFMUState)(c, &copy) == fmi3OK);
        CHECK(F3(fmi3FreeFMUState)(c, &state) == fmi3OK);
    }
}

static void full_simulation(void) {
    void *c = instantiate("full");
    CHECK(c != NULL);
    if (!c) return;
    CHECK(start(c));
    /* debug logging: every category by name */
    static const char *const every[] = { "logStatusError", "logStatusWarning", "logEvents" };
    CHECK(set_debug_logging(c, 3, every) == 0);
    if (accelVr >= 0) CHECK(set_real(c, (unsigned)accelVr, 40.0) == 0); /* remainingTime's plan in use */
    double t = 0.0;
    for (int k = 0; k < 200; k++, t += 0.01) {
        CHECK(set_u(c, input(k, 0)) == 0);
        CHECK(step(c, t, 0.01) == 0);
        get_y(c);
    }
    state_round_trip(c);
    for (int k = 0; k < 100; k++, t += 0.01) {
        set_u(c, input(k, 1));
        CHECK(step(c, t, 0.01) == 0);
    }
    /* an unknown (NULL) category: refused; the reset below recovers */
    static const char *const unknown[] = { "logEvents", NULL };
    CHECK(set_debug_logging(c, 2, unknown) == fmi2Error);
    /* reset and run again, then terminate */
    CHECK((version == 2 ? F2(fmi2Reset)(c) : F3(fmi3Reset)(c)) == 0);
    CHECK(start(c));
    CHECK(step(c, 0.0, 0.5) == 0);
    CHECK((version == 2 ? F2(fmi2Terminate)(c) : F3(fmi3Terminate)(c)) == 0);
    get_y(c);
    release(c);
}

/* ---- 1b. the same block as Model Exchange ------------------------------- */

/* The event update; returns the next event time (NaN: none). */
static double update(void *c) {
    double next = NAN;
    if (version == 2) {
        fmi2EventInfo info;
        CHECK(F2(fmi2NewDiscreteStates)(c, &info) == fmi2OK);
        CHECK(!info.newDiscreteStatesNeeded && !info.terminateSimulation && !info.valuesOfContinuousStatesChanged);
        if (info.nextEventTimeDefined) next = info.nextEventTime;
    } else {
        fmi3Boolean again, stop, nominals, values, defined;
        CHECK(F3(fmi3UpdateDiscreteStates)(c, &again, &stop, &nominals, &values, &defined, &next) == fmi3OK);
        CHECK(!again && !stop && !values);
        if (!defined) next = NAN;
    }
    return next;
}

static int enter_continuous_time_mode(void *c) {
    return version == 2 ? (int)F2(fmi2EnterContinuousTimeMode)(c) : (int)F3(fmi3EnterContinuousTimeMode)(c);
}

/* From Continuous-Time Mode to the event at t, as an importer without
 * states does: set the time, check the (empty) states and indicators,
 * complete the step, enter Event Mode. */
static void to_event(void *c, double t) {
    double none[1];
    fmi2Boolean enter2 = fmi2True, stop2 = fmi2True;
    fmi3Boolean enter3 = fmi3True, stop3 = fmi3True;
    if (version == 2) {
        CHECK(F2(fmi2SetTime)(c, t) == fmi2OK);
        CHECK(F2(fmi2GetDerivatives)(c, none, 0) == fmi2OK && F2(fmi2GetEventIndicators)(c, none, 0) == fmi2OK);
        CHECK(F2(fmi2CompletedIntegratorStep)(c, fmi2True, &enter2, &stop2) == fmi2OK && !enter2 && !stop2);
        CHECK(F2(fmi2EnterEventMode)(c) == fmi2OK);
    } else {
        size_t n = 1;
        CHECK(F3(fmi3GetNumberOfContinuousStates)(c, &n) == fmi3OK && n == 0);
        CHECK(F3(fmi3SetTime)(c, t) == fmi3OK);
        CHECK(F3(fmi3GetContinuousStateDerivatives)(c, none, 0) == fmi3OK &&
              F3(fmi3GetEventIndicators)(c, none, 0) == fmi3OK);
        CHECK(F3(fmi3CompletedIntegratorStep)(c, fmi3True, &enter3, &stop3) == fmi3OK && !enter3 && !stop3);
        CHECK(F3(fmi3EnterEventMode)(c) == fmi3OK);
    }
}

/* What Model Exchange and Scheduled Execution must give: Co-Simulation's
 * y after each of n cycles of cycleTime = cycle, the inputs input(k, 2). */
static void co_simulation_outputs(double cycle, int n, double expected[]) {
    void *cs = instantiate("reference");
    CHECK(cs != NULL && set_real(cs, cycleTimeVr, cycle) == 0 && start(cs));
    for (int k = 0; k < n; k++) {
        set_u(cs, input(k, 2));
        CHECK(step(cs, k * cycle, cycle) == 0);
        expected[k] = get_y(cs);
    }
    release(cs);
}

static void model_exchange_simulation(void) {
    enum { CYCLES = 200 };
    const double cycle = 0.01;
    double expected[CYCLES];
    co_simulation_outputs(cycle, CYCLES, expected);

    void *c = instantiate_model_exchange("model exchange");
    CHECK(c != NULL);
    if (!c) return;
    CHECK(set_real(c, cycleTimeVr, cycle) == 0);
    CHECK(start(c));
    double next = update(c);
    CHECK(next == cycle);
    int mismatches = 0;
    for (int k = 0; k < CYCLES; k++) {
        CHECK(set_u(c, input(k, 2)) == 0); /* the input of this instant: the next cycle's */
        if (k > 0) {
            next = update(c);
            mismatches += get_y(c) != expected[k - 1];
        }
        CHECK(enter_continuous_time_mode(c) == 0);
        if (k == CYCLES / 2) state_round_trip(c); /* in Continuous-Time Mode */
        CHECK(next == (k + 1) * cycle);
        to_event(c, next);
    }
    next = update(c);
    mismatches += get_y(c) != expected[CYCLES - 1];
    CHECK(mismatches == 0);
    CHECK((version == 2 ? F2(fmi2Terminate)(c) : F3(fmi3Terminate)(c)) == 0);
    get_y(c);
    release(c);
    printf("Model Exchange: %d cycles as time events, mismatches with Co-Simulation %d\n", CYCLES, mismatches);
}

/* FMI 3 Scheduled Execution: the Clock's interval and shift from
 * cycleTime, one activation per cycle giving Co-Simulation's outputs, an
 * FMU state in Clock Activation Mode, every activation, get and set there
 * inside lockPreemption ... unlockPreemption */
static long preemptionDepth, preemptionSections;
static void lock_preemption(void) {
    if (preemptionDepth++ == 0) preemptionSections++;
}
static void unlock_preemption(void) {
    preemptionDepth--;
}

static void scheduled_execution_simulation(void) {
    enum { CYCLES = 200 };
    const double cycle = 0.01;
    double expected[CYCLES];
    co_simulation_outputs(cycle, CYCLES, expected);

    void *c = F3(fmi3InstantiateScheduledExecution)("scheduled", token, NULL, fmi3False, fmi3False, NULL, log3_message,
                                                    NULL, lock_preemption, unlock_preemption);
    CHECK(c != NULL);
    if (!c) return;
    CHECK(set_real(c, cycleTimeVr, cycle) == 0);
    CHECK(F3(fmi3EnterInitializationMode)(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) == fmi3OK);
    fmi3Float64 interval = 0, shift = 0;
    fmi3IntervalQualifier qualifier = fmi3IntervalNotYetKnown;
    CHECK(F3(fmi3GetIntervalDecimal)(c, &clockVr, 1, &interval, &qualifier) == fmi3OK);
    CHECK(interval == cycle && qualifier == fmi3IntervalChanged);
    CHECK(F3(fmi3GetShiftDecimal)(c, &clockVr, 1, &shift) == fmi3OK && shift == cycle);
    CHECK(F3(fmi3ExitInitializationMode)(c) == fmi3OK);
    CHECK(preemptionSections == 0);
    int mismatches = 0;
    for (int k = 0; k < CYCLES; k++) {
        CHECK(set_u(c, input(k, 2)) == 0);
        CHECK(F3(fmi3ActivateModelPartition)(c, clockVr, shift + k * interval) == fmi3OK);
        mismatches += get_y(c) != expected[k];
        if (k == CYCLES / 2) state_round_trip(c); /* between activations */
    }
    CHECK(mismatches == 0);
    CHECK(preemptionDepth == 0 && preemptionSections == 3 * CYCLES);
    CHECK(F3(fmi3Terminate)(c) == fmi3OK);
    get_y(c);
    release(c);
    printf("Scheduled Execution: %d activations, mismatches with Co-Simulation %d\n", CYCLES, mismatches);
}

/* ---- 2. instantiate/free cycles leave nothing behind ------------------- */

static void instantiate_free(long cycles) {
    const long blocks = liveBlocks, callbackLive = callbackBlocks;
    for (long i = 0; i < cycles; i++) {
        void *c = instantiate("c"); /* the shortest name: its copy must fit exactly */
        CHECK(c != NULL);
        if (i % 1000 == 0 && c) { /* now and then a used instance */
            CHECK(start(c));
            CHECK(step(c, 0.0, 0.1) == 0);
        }
        release(c);
    }
    CHECK(liveBlocks == blocks);
    CHECK(callbackBlocks == callbackLive);
    printf("instantiate/free cycles %ld, live blocks after %ld (before %ld)\n", cycles, liveBlocks + callbackBlocks,
           blocks + callbackLive);
}

/* ---- 3. many instances alive at once ----------------------------------- */

static void many_instances(int n) {
    void **all = LIBC(calloc)((size_t)n, sizeof *all);
    char name[32];
    for (int i = 0; i < n; i++) {
        snprintf(name, sizeof name, "i%d", i);
        all[i] = instantiate(name);
        CHECK(all[i] != NULL);
        if (!all[i]) return;
        CHECK(start(all[i]));
    }
    for (int k = 0; k < 20; k++) {
        for (int i = 0; i < n; i++) {
            set_u(all[i], input(k, i));
            CHECK(step(all[i], k * 0.1, 0.1) == 0);
        }
    }
    /* each output equals that of one instance run alone with its input */
    double expected[7];
    for (int phase = 0; phase < 7; phase++) {
        void *alone = instantiate("alone");
        CHECK(start(alone));
        for (int k = 0; k < 20; k++) {
            set_u(alone, input(k, phase));
            step(alone, k * 0.1, 0.1);
        }
        expected[phase] = get_y(alone);
        release(alone);
    }
    int mismatches = 0;
    for (int i = 0; i < n; i++) {
        if (get_y(all[i]) != expected[i % 7]) mismatches++;
        release(all[i]);
    }
    CHECK(mismatches == 0);
    LIBC(free)(all);
    printf("instances alive at once %d, mismatches %d\n", n, mismatches);
}

/* ---- 4. out of memory --------------------------------------------------- */

static int get_state(void *c, void **state) {
    return version == 2 ? (int)F2(fmi2GetFMUstate)(c, state) : (int)F3(fmi3GetFMUState)(c, state);
}

static int free_state(void *c, void **state) {
    return version == 2 ? (int)F2(fmi2FreeFMUstate)(c, state) : (int)F3(fmi3FreeFMUState)(c, state);
}

static int reset(void *c) {
    return version == 2 ? (int)F2(fmi2Reset)(c) : (int)F3(fmi3Reset)(c);
}

/* Whether this program's malloc is the one the FMU gets: not under ASan or
 * valgrind, which bring their own (called through a volatile pointer, so
 * that the compiler cannot assume what malloc returns). */
static int malloc_is_ours(void) {
    void *(*volatile allocator)(size_t) = malloc;
    failCountdown = 1;
    void *p = allocator(16);
    failCountdown = 0;
    free(p);
    return p == NULL;
}

static void out_of_memory(void) {
    if (version == 3 && !malloc_is_ours()) { /* FMI 3 allocates with malloc */
        printf("out of memory: not checked for FMI 3 here (malloc belongs to ASan or valgrind)\n");
        return;
    }
    const long blocks = liveBlocks, callbackLive = callbackBlocks;
    /* instantiation: FMI 2 allocates the instance and its name, FMI 3 one block */
    const long allocations = version == 2 ? 2 : 1;
    for (long n = 1; n <= allocations; n++) {
        failCountdown = n;
        CHECK(instantiate("no memory") == NULL);
        CHECK(failCountdown == 0);
        CHECK(liveBlocks == blocks && callbackBlocks == callbackLive);
    }
    failCountdown = 0;
    void *c = instantiate("states");
    CHECK(c != NULL);
    if (!c) return;
    CHECK(start(c));
    CHECK(step(c, 0.0, 0.1) == 0);
    void *state = NULL;
    size_t size = 0;
    CHECK(get_state(c, &state) == 0);
    CHECK((version == 2 ? (int)F2(fmi2SerializedFMUstateSize)(c, state, &size)
                        : (int)F3(fmi3SerializedFMUStateSize)(c, state, &size)) == 0);
    unsigned char *bytes = LIBC(malloc)(size);
    CHECK((version == 2 ? (int)F2(fmi2SerializeFMUstate)(c, state, (fmi2Byte *)bytes, size)
                        : (int)F3(fmi3SerializeFMUState)(c, state, bytes, size)) == 0);
    CHECK(free_state(c, &state) == 0);
    const double y = get_y(c);
    for (int deserializing = 0; deserializing <= 1; deserializing++) {
        void *refused = NULL;
        failCountdown = 1;
        const int status = !deserializing ? get_state(c, &refused)
                           : version == 2 ? (int)F2(fmi2DeSerializeFMUstate)(c, (const fmi2Byte *)bytes, size, &refused)
                                          : (int)F3(fmi3DeserializeFMUState)(c, bytes, size, &refused);
        CHECK(status == 3 && refused == NULL && failCountdown == 0);
        failCountdown = 0;
        CHECK(get_y(c) == y); /* the last good values, readable after the error */
        CHECK(reset(c) == 0);
        CHECK(start(c));
        CHECK(step(c, 0.0, 0.1) == 0);
    }
    LIBC(free)(bytes);
    release(c);
    CHECK(liveBlocks == blocks && callbackBlocks == callbackLive);
    printf("out of memory: %ld instantiation and 2 FMU-state allocations refused, live blocks after %ld (before %ld)\n",
           allocations, liveBlocks + callbackBlocks, blocks + callbackLive);
}

/* The attribute value after `after` in the model description, from `from`. */
static const char *attribute(const char *text, const char *from, const char *after, char *out, size_t size) {
    const char *p = from ? strstr(text, from) : text;
    if (p) p = strstr(p, after);
    if (!p) {
        fprintf(stderr, "modelDescription.xml: no %s %s\n", from ? from : "", after);
        exit(2);
    }
    p += strlen(after);
    size_t n = strcspn(p, "\"");
    if (n >= size) exit(2);
    memcpy(out, p, n);
    out[n] = 0;
    return out;
}

/* The value reference of the first Real (FMI 3: Float64) variable of this
 * causality: every model's cycle input u and its output y come first. */
static unsigned first_real(const char *text, const char *causality) {
    const char *open = version == 2 ? "<ScalarVariable" : "<Float64 ";
    const char *close = version == 2 ? "</ScalarVariable>" : ">";
    char element[4096], number[32];
    for (const char *p = strstr(text, open); p; p = strstr(p + 1, open)) {
        const char *end = strstr(p, close);
        const size_t n = end ? (size_t)(end - p) : 0;
        if (n == 0 || n >= sizeof element) break;
        memcpy(element, p, n);
        element[n] = 0;
        if (strstr(element, causality) && (version == 3 || strstr(element, "<Real"))) {
            return (unsigned)atoi(attribute(element, NULL, "valueReference=\"", number, sizeof number));
        }
    }
    fprintf(stderr, "modelDescription.xml: no Real variable with %s\n", causality);
    exit(2);
}

/* the staged FMU's model description, in a buffer of its own kept until the next call */
static const char *description_text(const char *stage) {
    char path[4096];
    snprintf(path, sizeof path, "%s/modelDescription.xml", stage);
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "cannot read %s\n", path);
        exit(2);
    }
    static char text[1 << 16];
    const size_t n = fread(text, 1, sizeof text - 1, f);
    text[n] = 0;
    fclose(f);
    return text;
}

/* the Scheduled Execution FMU's Clock; that FMU declares nothing else of the binary's interfaces */
static void read_clock(const char *stage, const char *identifier) {
    const char *text = description_text(stage);
    char number[32], se_identifier[256];
    attribute(text, "<ScheduledExecution", "modelIdentifier=\"", se_identifier, sizeof se_identifier);
    CHECK(strcmp(se_identifier, identifier) == 0);
    CHECK(!strstr(text, "<CoSimulation") && !strstr(text, "<ModelExchange"));
    clockVr = (unsigned)atoi(attribute(text, "<Clock ", "valueReference=\"", number, sizeof number));
}

static void read_description(const char *stage, char *identifier, size_t size) {
    const char *text = description_text(stage);
    attribute(text, NULL, version == 2 ? "guid=\"" : "instantiationToken=\"", token, sizeof token);
    attribute(text, "<CoSimulation", "modelIdentifier=\"", identifier, size);
    uVr = first_real(text, "causality=\"input\"");
    yVr = first_real(text, "causality=\"output\"");
    /* every model has the parameter cycleTime */
    char number[32];
    cycleTimeVr = (unsigned)atoi(attribute(text, "name=\"cycleTime\"", "valueReference=\"", number, sizeof number));
    CHECK(!strstr(text, "<Clock") && !strstr(text, "<ScheduledExecution")); /* FMI 3.0, 4.4: the SE FMU's */
    if (strstr(text, "name=\"accelMax\"")) {
        accelVr = atoi(attribute(text, "name=\"accelMax\"", "valueReference=\"", number, sizeof number));
    }
}

int main(int argc, char **argv) {
    if (argc != (argc > 1 && atoi(argv[1]) == 3 ? 6 : 5)) {
        fprintf(stderr, "usage: test_lifecycle <2|3> <staged FMU folder> <instantiations> <instances> "
                        "[<staged Scheduled Execution FMU folder> (FMI 3 only, required)]\n");
        return 2;
    }
    version = atoi(argv[1]);
    char identifier[128], binary[4096];
    read_description(argv[2], identifier, sizeof identifier);
#if defined(__aarch64__)
    const char *platform = version == 2 ? "aarch64-linux (none in FMI 2)" : "aarch64-linux";
#else
    const char *platform = version == 2 ? "linux64" : "x86_64-linux";
#endif
    snprintf(binary, sizeof binary, "%s/binaries/%s/%s.so", argv[2], platform, identifier);
    if (!open_library(binary)) return 2;
    counting = 1;
    full_simulation();
    model_exchange_simulation();
    if (version == 3) {
        read_clock(argv[5], identifier);
        scheduled_execution_simulation();
    }
    instantiate_free(atol(argv[3]));
    many_instances(atoi(argv[4]));
    out_of_memory();
    counting = 0;
    dlclose(library); /* so that memcheck sees every block freed */
    printf("FMI %d: %s (%d log messages)\n", version, failures ? "FAILED" : "passed", messages);
    return failures ? 1 : 0;
}
