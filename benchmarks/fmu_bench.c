/* Per-step cost of a built FMU binary, loaded with dlopen as an importer
 * loads it, next to a direct call of the kernel's cycle function (the
 * floor). Prints one line per figure: "name value unit".
 *
 *   fmu_bench <2|3> <binary.so> <token> <u_vr> <y_vr> <cycleTime_vr|-1> <steps> <repeats> [vr=value ...]
 *
 * vr=value: Real start values set before initialisation (the benchmark of
 * a configuration with output limits and rates below 0 in use).
 *
 * FMI 3 with a cycleTime: Scheduled Execution's activation beside
 * Co-Simulation's doStep of one cycle (the Clock's value reference read
 * from the modelDescription.xml two folders above the binary, as an FMU
 * and its stage are laid out: the Scheduled Execution FMU's, whose binary
 * is the Co-Simulation FMU's and whose description alone has the Clock).
 *
 * Under valgrind --tool=callgrind each measured loop is bracketed by client
 * requests (zero, then dump with the loop's name), so that the caller can
 * read instructions per step from the dumps; natively the loops are timed. */
#define _GNU_SOURCE /* clock_gettime, dladdr */
#include <dlfcn.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#include "rate_limiter.h"

#ifdef HAVE_CALLGRIND_H
#include <valgrind/callgrind.h>
#else
#define CALLGRIND_ZERO_STATS
#define CALLGRIND_DUMP_STATS_AT(label) ((void)(label))
#endif

/* ---- allocation counting: FMI 2 callbacks and an interposed malloc ---- */

extern void *__libc_malloc(size_t size);
extern void *__libc_calloc(size_t count, size_t size);
extern void *__libc_realloc(void *pointer, size_t size);
extern void __libc_free(void *pointer);

static size_t mallocCalls, mallocBytes;

void *malloc(size_t size) {
    mallocCalls++;
    mallocBytes += size;
    return __libc_malloc(size);
}

void *calloc(size_t count, size_t size) {
    mallocCalls++;
    mallocBytes += count * size;
    return __libc_calloc(count, size);
}

void *realloc(void *pointer, size_t size) {
    mallocCalls++;
    mallocBytes += size;
    return __libc_realloc(pointer, size);
}

void free(void *pointer) {
    __libc_free(pointer);
}

static size_t callbackCalls, callbackBytes;

static void *count_allocate(size_t count, size_t size) {
    callbackCalls++;
    callbackBytes += count * size;
    return __libc_calloc(count, size);
}

static void count_free(void *pointer) {
    __libc_free(pointer);
}

static void log2_message(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                         fmi2String message, ...) {
    (void)env;
    fprintf(stderr, "[%s] %d %s: %s\n", name, (int)status, category, message);
}

static void log3_message(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    fprintf(stderr, "%d %s: %s\n", (int)status, category, message);
}

/* ---- the FMU as an importer sees it ----------------------------------- */

static struct {
    int version;
    void *library;
    const char *token;
    unsigned uVr, yVr;
    long cycleVr;
    fmi2InstantiateTYPE *fmi2Instantiate;
    fmi2FreeInstanceTYPE *fmi2FreeInstance;
    fmi2SetupExperimentTYPE *fmi2SetupExperiment;
    fmi2EnterInitializationModeTYPE *fmi2EnterInitializationMode;
    fmi2ExitInitializationModeTYPE *fmi2ExitInitializationMode;
    fmi2SetRealTYPE *fmi2SetReal;
    fmi2GetRealTYPE *fmi2GetReal;
    fmi2DoStepTYPE *fmi2DoStep;
    fmi3InstantiateCoSimulationTYPE *fmi3InstantiateCoSimulation;
    fmi3FreeInstanceTYPE *fmi3FreeInstance;
    fmi3EnterInitializationModeTYPE *fmi3EnterInitializationMode;
    fmi3ExitInitializationModeTYPE *fmi3ExitInitializationMode;
    fmi3SetFloat64TYPE *fmi3SetFloat64;
    fmi3GetFloat64TYPE *fmi3GetFloat64;
    fmi3DoStepTYPE *fmi3DoStep;
    fmi3InstantiateScheduledExecutionTYPE *fmi3InstantiateScheduledExecution;
    fmi3ActivateModelPartitionTYPE *fmi3ActivateModelPartition;
    long clockVr; /* -1: no Clock found */
} F;

static const fmi2CallbackFunctions callbacks = { log2_message, count_allocate, count_free, NULL, NULL };

static void *symbol(const char *name) {
    void *s = dlsym(F.library, name);
    if (!s) {
        fprintf(stderr, "fmu_bench: %s not exported\n", name);
        exit(2);
    }
    return s;
}

#define LOAD(name) (*(void **)&F.name = symbol(#name))

static void load(const char *path) {
    F.library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!F.library) {
        fprintf(stderr, "fmu_bench: %s\n", dlerror());
        exit(2);
    }
    if (F.version == 2) {
        LOAD(fmi2Instantiate);
        LOAD(fmi2FreeInstance);
        LOAD(fmi2SetupExperiment);
        LOAD(fmi2EnterInitializationMode);
        LOAD(fmi2ExitInitializationMode);
        LOAD(fmi2SetReal);
        LOAD(fmi2GetReal);
        LOAD(fmi2DoStep);
    } else {
        LOAD(fmi3InstantiateCoSimulation);
        LOAD(fmi3FreeInstance);
        LOAD(fmi3EnterInitializationMode);
        LOAD(fmi3ExitInitializationMode);
        LOAD(fmi3SetFloat64);
        LOAD(fmi3GetFloat64);
        LOAD(fmi3DoStep);
        LOAD(fmi3InstantiateScheduledExecution);
        LOAD(fmi3ActivateModelPartition);
    }
}

/* The Clock's value reference in the modelDescription.xml of the FMU whose
 * binary is at path (<fmu>/binaries/<platform>/<name>.so); -1 if none. */
static long clock_vr(const char *path) {
    char description[4096];
    const char *slash = strrchr(path, '/');
    const int folder = slash ? (int)(slash - path) : 0;
    snprintf(description, sizeof description, "%.*s/../../modelDescription.xml", folder, path);
    FILE *file = fopen(description, "rb");
    if (!file) return -1;
    static char text[1 << 20];
    const size_t n = fread(text, 1, sizeof text - 1, file);
    fclose(file);
    text[n] = 0;
    const char *clock = strstr(text, "<Clock ");
    const char *vr = clock ? strstr(clock, "valueReference=\"") : NULL;
    return vr ? strtol(vr + strlen("valueReference=\""), NULL, 10) : -1;
}

static void must(int status, const char *what) {
    if (status != 0) {
        fprintf(stderr, "fmu_bench: %s returned %d\n", what, status);
        exit(1);
    }
}

static void *instantiate(void) {
    void *c = F.version == 2
                  ? F.fmi2Instantiate("bench", fmi2CoSimulation, F.token, "", &callbacks, fmi2False, fmi2False)
                  : F.fmi3InstantiateCoSimulation("bench", F.token, NULL, fmi3False, fmi3False, fmi3False, fmi3False,
                                                  NULL, 0, NULL, log3_message, NULL);
    if (!c) {
        fprintf(stderr, "fmu_bench: instantiation failed\n");
        exit(1);
    }
    return c;
}

static void set_real(void *c, unsigned vr, double value) {
    must(F.version == 2 ? F.fmi2SetReal(c, &vr, 1, &value) : F.fmi3SetFloat64(c, &vr, 1, &value, 1), "set");
}

/* the start values given on the command line */
static unsigned startVrs[16];
static double startValues[16];
static int startCount;

static void start(void *c, double cycleTime) {
    if (cycleTime > 0) set_real(c, (unsigned)F.cycleVr, cycleTime);
    for (int i = 0; i < startCount; i++) set_real(c, startVrs[i], startValues[i]);
    if (F.version == 2) {
        must(F.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), "fmi2SetupExperiment");
        must(F.fmi2EnterInitializationMode(c), "fmi2EnterInitializationMode");
        must(F.fmi2ExitInitializationMode(c), "fmi2ExitInitializationMode");
    } else {
        must(F.fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0), "fmi3EnterInitializationMode");
        must(F.fmi3ExitInitializationMode(c), "fmi3ExitInitializationMode");
    }
}

/* Scheduled Execution: the preemption callbacks of an importer whose
 * locks cost a call each (locked), or none (an importer that does not
 * preempt) */
static size_t preemptionLocks;
static void lock_preemption(void) {
    preemptionLocks++;
}
static void unlock_preemption(void) {
    preemptionLocks--;
}

static void *start_scheduled(double cycleTime, int locked) {
    void *c = F.fmi3InstantiateScheduledExecution("bench", F.token, NULL, fmi3False, fmi3False, NULL, log3_message,
                                                  NULL, locked ? lock_preemption : NULL,
                                                  locked ? unlock_preemption : NULL);
    if (!c) {
        fprintf(stderr, "fmu_bench: instantiation for Scheduled Execution failed\n");
        exit(1);
    }
    set_real(c, (unsigned)F.cycleVr, cycleTime);
    for (int i = 0; i < startCount; i++) set_real(c, startVrs[i], startValues[i]);
    must(F.fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0), "fmi3EnterInitializationMode");
    must(F.fmi3ExitInitializationMode(c), "fmi3ExitInitializationMode");
    return c;
}

static void release(void *c) {
    if (F.version == 2) F.fmi2FreeInstance(c);
    else F.fmi3FreeInstance(c);
}

/* The input: a square wave of +-1000 every 4096 steps, so that the output
 * ramps (rule 6 with its limits) on every step. */
static double input(uint64_t i) {
    return (i & 4096) ? -1000.0 : 1000.0;
}

#define H 0.001

static double sink;

/* ---- measured loops ---------------------------------------------------- */

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef double Loop(uint64_t steps, double cycleTime);

static double loop_empty(uint64_t steps, double cycleTime) {
    (void)cycleTime;
    double sum = 0;
    CALLGRIND_ZERO_STATS;
    const double t0 = now();
    for (uint64_t i = 0; i < steps; i++) {
        *(volatile double *)&sink = input(i);
    }
    const double t1 = now();
    CALLGRIND_DUMP_STATS_AT("empty");
    (void)sum;
    return t1 - t0;
}

/* rl_cycle through a volatile pointer: a real call, as from another file */
static void (*volatile cycleFunction)(RlState *, const RlPrepared *, double, double) = rl_cycle;

static double loop_kernel(uint64_t steps, double cycleTime) {
    (void)cycleTime;
    RlConfig config;
    RlPrepared prepared;
    RlState state;
    memset(&config, 0, sizeof config);
    config.rateUp.value = 1.0;
    config.rateDown.value = 1.0;
    config.ratePeriod.value = 1.0;
    config.initMode = RL_INIT_INPUT;
    config.zeroRate = RL_ZERO_RATE_HOLD;
    config.passNonFinite = true;
    rl_prepare(&prepared, &config, H);
    rl_init(&state, &prepared, 0.0);
    void (*cycle)(RlState *, const RlPrepared *, double, double) = cycleFunction;

    CALLGRIND_ZERO_STATS;
    const double t0 = now();
    for (uint64_t i = 0; i < steps; i++) {
        cycle(&state, &prepared, input(i), (double)(i + 1) * H);
        *(volatile double *)&sink = state.y;
    }
    const double t1 = now();
    CALLGRIND_DUMP_STATS_AT("kernel");
    return t1 - t0;
}

static double loop_fmu(uint64_t steps, double cycleTime, int setAndGet, const char *label) {
    void *c = instantiate();
    start(c, cycleTime);
    const unsigned uVr = F.uVr, yVr = F.yVr;
    double y = 0, t0, t1;
    if (F.version == 2) {
        fmi2SetRealTYPE *setReal = F.fmi2SetReal;
        fmi2GetRealTYPE *getReal = F.fmi2GetReal;
        fmi2DoStepTYPE *doStep = F.fmi2DoStep;
        double u = input(0);
        setReal(c, &uVr, 1, &u);
        CALLGRIND_ZERO_STATS;
        t0 = now();
        for (uint64_t i = 0; i < steps; i++) {
            u = input(i);
            if (setAndGet) setReal(c, &uVr, 1, &u);
            if (doStep(c, (double)i * H, H, fmi2True) != fmi2OK) exit(1);
            if (setAndGet) getReal(c, &yVr, 1, &y);
            *(volatile double *)&sink = y;
        }
        t1 = now();
        CALLGRIND_DUMP_STATS_AT(label);
    } else {
        fmi3SetFloat64TYPE *setFloat64 = F.fmi3SetFloat64;
        fmi3GetFloat64TYPE *getFloat64 = F.fmi3GetFloat64;
        fmi3DoStepTYPE *doStep = F.fmi3DoStep;
        fmi3Boolean eventHandlingNeeded, terminateSimulation, earlyReturn;
        fmi3Float64 lastSuccessfulTime;
        double u = input(0);
        setFloat64(c, &uVr, 1, &u, 1);
        CALLGRIND_ZERO_STATS;
        t0 = now();
        for (uint64_t i = 0; i < steps; i++) {
            u = input(i);
            if (setAndGet) setFloat64(c, &uVr, 1, &u, 1);
            if (doStep(c, (double)i * H, H, fmi3True, &eventHandlingNeeded, &terminateSimulation, &earlyReturn,
                       &lastSuccessfulTime) != fmi3OK)
                exit(1);
            if (setAndGet) getFloat64(c, &yVr, 1, &y, 1);
            *(volatile double *)&sink = y;
        }
        t1 = now();
        CALLGRIND_DUMP_STATS_AT(label);
    }
    release(c);
    return t1 - t0;
}

/* A plant of INSTANCES limiters stepped in turn (set u, doStep, get y of
 * each per communication point), steps calls of each in all: what a
 * simulator of many blocks pays, with the instances' memory out of the
 * cache lines of one. Each instance's square wave has its own phase. */
#define INSTANCES 1000
static double loop_instances(uint64_t steps, double cycleTime) {
    static void *c[INSTANCES];
    for (int k = 0; k < INSTANCES; k++) {
        c[k] = instantiate();
        start(c[k], cycleTime);
    }
    const unsigned uVr = F.uVr, yVr = F.yVr;
    const uint64_t points = steps / INSTANCES + 1;
    double y = 0;
    fmi3Boolean eventHandlingNeeded, terminateSimulation, earlyReturn;
    fmi3Float64 lastSuccessfulTime;
    CALLGRIND_ZERO_STATS;
    const double t0 = now();
    for (uint64_t i = 0; i < points; i++) {
        for (int k = 0; k < INSTANCES; k++) {
            double u = input(i + 37 * (uint64_t)k);
            if (F.version == 2) {
                F.fmi2SetReal(c[k], &uVr, 1, &u);
                if (F.fmi2DoStep(c[k], (double)i * H, H, fmi2True) != fmi2OK) exit(1);
                F.fmi2GetReal(c[k], &yVr, 1, &y);
            } else {
                F.fmi3SetFloat64(c[k], &uVr, 1, &u, 1);
                if (F.fmi3DoStep(c[k], (double)i * H, H, fmi3True, &eventHandlingNeeded, &terminateSimulation,
                                 &earlyReturn, &lastSuccessfulTime) != fmi3OK)
                    exit(1);
                F.fmi3GetFloat64(c[k], &yVr, 1, &y, 1);
            }
            *(volatile double *)&sink = y;
        }
    }
    const double t1 = now();
    CALLGRIND_DUMP_STATS_AT("instances");
    for (int k = 0; k < INSTANCES; k++) release(c[k]);
    return (t1 - t0) * (double)steps / (double)(points * INSTANCES);
}

/* One activation per PLC cycle: set u, activate at the tick, get y (the
 * counterpart of loop_cycle_1's set, doStep of one cycle, get). */
static double loop_scheduled(uint64_t steps, double cycleTime, int locked, const char *label) {
    void *c = start_scheduled(cycleTime, locked);
    fmi3SetFloat64TYPE *setFloat64 = F.fmi3SetFloat64;
    fmi3GetFloat64TYPE *getFloat64 = F.fmi3GetFloat64;
    fmi3ActivateModelPartitionTYPE *activate = F.fmi3ActivateModelPartition;
    const unsigned uVr = F.uVr, yVr = F.yVr, clock = (unsigned)F.clockVr;
    double y = 0;
    CALLGRIND_ZERO_STATS;
    const double t0 = now();
    for (uint64_t i = 0; i < steps; i++) {
        double u = input(i);
        setFloat64(c, &uVr, 1, &u, 1);
        if (activate(c, clock, (double)(i + 1) * cycleTime) != fmi3OK) exit(1);
        getFloat64(c, &yVr, 1, &y, 1);
        *(volatile double *)&sink = y;
    }
    const double t1 = now();
    CALLGRIND_DUMP_STATS_AT(label);
    if (preemptionLocks != 0) {
        fprintf(stderr, "fmu_bench: %zu preemption locks left held\n", preemptionLocks);
        exit(1);
    }
    release(c);
    return t1 - t0;
}

static double loop_activation(uint64_t steps, double cycleTime) {
    return loop_scheduled(steps, cycleTime, 0, "activation");
}
static double loop_activation_locked(uint64_t steps, double cycleTime) {
    return loop_scheduled(steps, cycleTime, 1, "activationLocked");
}

static double loop_step(uint64_t steps, double cycleTime) {
    return loop_fmu(steps, cycleTime, 1, "step");
}
static double loop_do_step(uint64_t steps, double cycleTime) {
    return loop_fmu(steps, cycleTime, 0, "doStep");
}
static double loop_cycle_1(uint64_t steps, double cycleTime) {
    return loop_fmu(steps, cycleTime, 1, "cycles1");
}
static double loop_cycle_n(uint64_t steps, double cycleTime) {
    return loop_fmu(steps, cycleTime, 1, "cyclesN");
}

static int compare(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* median ns per step over the repeats */
static double median_ns(Loop *loop, uint64_t steps, double cycleTime, int repeats) {
    double times[64];
    for (int r = 0; r < repeats; r++) times[r] = loop(steps, cycleTime) / (double)steps * 1e9;
    qsort(times, (size_t)repeats, sizeof times[0], compare);
    return times[repeats / 2];
}

/* ---- allocations and memory ------------------------------------------- */

static void allocations(void) {
    size_t calls0 = mallocCalls + callbackCalls, bytes0 = mallocBytes + callbackBytes;
    void *c = instantiate();
    const size_t instanceBytes = mallocBytes + callbackBytes - bytes0;
    const size_t instanceCalls = mallocCalls + callbackCalls - calls0;
    start(c, 0.0);
    release(c);
    printf("instance_bytes %zu bytes\n", instanceBytes);
    printf("instance_allocations %zu calls\n", instanceCalls);

    const uint64_t runs[2] = { 10, 1000000 };
    for (int k = 0; k < 2; k++) {
        c = instantiate();
        start(c, 0.0);
        const size_t before = mallocCalls + callbackCalls;
        double u, y;
        for (uint64_t i = 0; i < runs[k]; i++) {
            u = input(i);
            if (F.version == 2) {
                F.fmi2SetReal(c, &F.uVr, 1, &u);
                F.fmi2DoStep(c, (double)i * H, H, fmi2True);
                F.fmi2GetReal(c, &F.yVr, 1, &y);
            } else {
                fmi3Boolean a, b, e;
                fmi3Float64 last;
                F.fmi3SetFloat64(c, &F.uVr, 1, &u, 1);
                F.fmi3DoStep(c, (double)i * H, H, fmi3True, &a, &b, &e, &last);
                F.fmi3GetFloat64(c, &F.yVr, 1, &y, 1);
            }
        }
        printf("allocations_in_%llu_steps %zu calls\n", (unsigned long long)runs[k],
               mallocCalls + callbackCalls - before);
        release(c);
    }
}

int main(int argc, char **argv) {
    if (argc < 9 || argc > 9 + 16) {
        fprintf(stderr, "usage: fmu_bench <2|3> <binary.so> <token> <u_vr> <y_vr> <cycleTime_vr|-1> <steps> <repeats>"
                        " [vr=value ...]\n");
        return 2;
    }
    for (int i = 9; i < argc; i++) {
        char *end = NULL;
        startVrs[startCount] = (unsigned)strtoul(argv[i], &end, 10);
        if (!end || *end != '=') {
            fprintf(stderr, "fmu_bench: not vr=value: %s\n", argv[i]);
            return 2;
        }
        startValues[startCount++] = strtod(end + 1, NULL);
    }
    F.version = atoi(argv[1]);
    F.token = argv[3];
    F.uVr = (unsigned)atoi(argv[4]);
    F.yVr = (unsigned)atoi(argv[5]);
    F.cycleVr = atol(argv[6]);
    const uint64_t steps = strtoull(argv[7], NULL, 10);
    int repeats = atoi(argv[8]);
    if (repeats < 1) repeats = 1;
    if (repeats > 64) repeats = 64;
    load(argv[2]);
    F.clockVr = F.version == 3 ? clock_vr(argv[2]) : -1;

    const double empty = median_ns(loop_empty, steps, 0.0, repeats);
    const double kernel = median_ns(loop_kernel, steps, 0.0, repeats);
    const double step = median_ns(loop_step, steps, 0.0, repeats);
    const double doStep = median_ns(loop_do_step, steps, 0.0, repeats);
    const double instances = median_ns(loop_instances, steps, 0.0, repeats);
    printf("empty_loop_ns %.2f ns/step\n", empty);
    printf("kernel_ns %.2f ns/step\n", kernel);
    printf("step_ns %.2f ns/step\n", step);
    printf("doStep_ns %.2f ns/step\n", doStep);
    printf("instances%d_ns %.2f ns/step\n", INSTANCES, instances);
    printf("step_over_kernel %.3f ratio\n", step / kernel);
    if (F.cycleVr >= 0) {
        const double one = median_ns(loop_cycle_1, steps / 100 + 1, H, repeats);
        const double many = median_ns(loop_cycle_n, steps / 100 + 1, H / 100, repeats);
        printf("subcycle_extra_ns %.2f ns/cycle\n", (many - one) / 99);
        if (F.clockVr >= 0) {
            /* per PLC cycle, set u and get y included: Co-Simulation's
             * doStep of one cycle (cycleTime = the step) and Scheduled
             * Execution's activation, without and with preemption locks */
            const double activation = median_ns(loop_activation, steps, H, repeats);
            const double locked = median_ns(loop_activation_locked, steps, H, repeats);
            const double cycleStep = median_ns(loop_cycle_1, steps, H, repeats);
            printf("cycle_doStep_ns %.2f ns/cycle\n", cycleStep);
            printf("activation_ns %.2f ns/cycle\n", activation);
            printf("activation_locked_ns %.2f ns/cycle\n", locked);
            printf("activation_over_doStep %.3f ratio\n", activation / cycleStep);
        }
    }
    allocations();
    return 0;
}
