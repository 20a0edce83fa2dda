/* An FMI 2 or FMI 3 co-simulation binary driven by a script on standard
 * input, the outputs printed bit for bit: the same script gives the same
 * text on every platform whose binary computes the same numbers (the
 * aarch64 build runs under qemu-user, the Windows build under wine), and
 * with --trap the same text with the floating-point exceptions a real-time
 * target traps enabled (FE_INVALID, FE_DIVBYZERO, FE_OVERFLOW): one raised
 * in any call is SIGFPE, reported with the script line, exit 3.
 *
 *   run_trace [--fmi2] [--trap] [--keep-going] [--model-exchange] [--prefix <P>] <binary> <token> < script
 *
 * <binary> "-": the FMUs are linked into the harness (source FMUs compiled
 * with FMI2_FUNCTION_PREFIX or FMI3_FUNCTION_PREFIX), the one run is the one
 * whose prefix is P.
 * --model-exchange: the instances are Model Exchange ones, driven as an
 * importer without continuous states drives them: init ends with an event
 * update in Event Mode at the start time; "step t h" enters
 * Continuous-Time Mode and runs every time event before t + h (set the
 * time, Event Mode, update), then the event at t + h, leaving the instance
 * in Event Mode there, where the next inputs are set (t itself is not
 * checked: the time is the FMU's).
 *
 * Script lines:  set <F|I|L|B> <vr> <value>   (Float64 as C99 %a, Int32,
 *                                               Int64 (enumerations; FMI 2:
 *                                               Integer), Boolean 0/1)
 *                init <startTime>
 *                step <t> <h>                  (C99 %a)
 *                get <F|I|B> <vr>              prints the value (Float64 as %a)
 *                save <file>                   the FMU state, serialized, into file
 *                load <file>                   the FMU state of file, deserialized and set
 *                new                           a fresh instance in place of the current one
 * Exit 1 on any status above Warning, naming the line. --keep-going: such
 * a status prints "refused <line number>" and the lines up to the next
 * "new" are skipped (the instance is in its error state), exit 0. */
#if defined(__linux__) && !defined(_GNU_SOURCE)
#define _GNU_SOURCE /* feenableexcept */
#endif
#include <fenv.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#include "fmu_library.h"

#if defined(__GLIBC__)
#define HAVE_TRAPS 1
#include <ucontext.h>
#include <unistd.h> /* _exit */
#endif

enum { STATUS_OK = 0, STATUS_WARNING = 1, STATUS_ERROR = 3 }; /* as fmi2Status and fmi3Status */

/* One FMI version's calls, values as the script carries them. */
typedef struct {
    void *(*instantiate)(const char *token);
    /* Model Exchange: the event update (*next: the next event time, NaN
     * for none), Continuous-Time Mode, the time, Event Mode */
    int (*update)(void *c, double *next);
    int (*continuous)(void *c);
    int (*set_time)(void *c, double t);
    int (*event)(void *c);
    int (*init)(void *c, double start);
    int (*step)(void *c, double t, double h);
    int (*set_float)(void *c, unsigned vr, double v);
    int (*set_int)(void *c, unsigned vr, long long v, char kind);
    int (*set_bool)(void *c, unsigned vr, int v);
    int (*get_float)(void *c, unsigned vr, double *v);
    int (*get_int)(void *c, unsigned vr, long long *v);
    int (*get_bool)(void *c, unsigned vr, int *v);
    int (*save)(void *c, unsigned char *bytes, size_t capacity, size_t *size);
    int (*load)(void *c, const unsigned char *bytes, size_t size);
    void (*free_instance)(void *c);
} Fmi;

/* ---- FMI 3 ---- */

static int model_exchange;

static struct {
    fmi3InstantiateCoSimulationTYPE *instantiate;
    fmi3InstantiateModelExchangeTYPE *instantiate_me;
    fmi3UpdateDiscreteStatesTYPE *update;
    fmi3EnterContinuousTimeModeTYPE *continuous;
    fmi3SetTimeTYPE *set_time;
    fmi3EnterEventModeTYPE *event;
    fmi3EnterInitializationModeTYPE *enter;
    fmi3ExitInitializationModeTYPE *leave;
    fmi3DoStepTYPE *do_step;
    fmi3SetFloat64TYPE *set_float;
    fmi3SetInt32TYPE *set_int;
    fmi3SetInt64TYPE *set_long;
    fmi3SetBooleanTYPE *set_bool;
    fmi3GetFloat64TYPE *get_float;
    fmi3GetInt32TYPE *get_int;
    fmi3GetBooleanTYPE *get_bool;
    fmi3FreeInstanceTYPE *free_instance;
    fmi3GetFMUStateTYPE *get_state;
    fmi3SetFMUStateTYPE *set_state;
    fmi3FreeFMUStateTYPE *free_state;
    fmi3SerializedFMUStateSizeTYPE *state_size;
    fmi3SerializeFMUStateTYPE *serialize;
    fmi3DeserializeFMUStateTYPE *deserialize;
} f3;

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    (void)status;
    (void)category;
    (void)message;
}

static void *instantiate3(const char *token) {
    if (model_exchange) return f3.instantiate_me("trace", token, NULL, fmi3False, fmi3False, NULL, logger3);
    return f3.instantiate("trace", token, NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, NULL, logger3,
                          NULL);
}
static int update3(void *c, double *next) {
    fmi3Boolean again, stop, nominals, values, defined = fmi3False;
    const int status = f3.update(c, &again, &stop, &nominals, &values, &defined, next);
    if (!defined) *next = NAN;
    return status;
}
static int continuous3(void *c) {
    return f3.continuous(c);
}
static int set_time3(void *c, double t) {
    return f3.set_time(c, t);
}
static int event3(void *c) {
    return f3.event(c);
}
static int init3(void *c, double start) {
    int status = f3.enter(c, fmi3False, 0.0, start, fmi3False, 0.0);
    return status <= STATUS_WARNING ? (int)f3.leave(c) : status;
}
static int step3(void *c, double t, double h) {
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    return f3.do_step(c, t, h, fmi3True, &event, &terminate, &early, &last);
}
static int set_float3(void *c, unsigned vr, double v) {
    const fmi3ValueReference r = vr;
    return f3.set_float(c, &r, 1, &v, 1);
}
static int set_int3(void *c, unsigned vr, long long v, char kind) {
    const fmi3ValueReference r = vr;
    if (kind == 'L') {
        const fmi3Int64 value = (fmi3Int64)v;
        return f3.set_long(c, &r, 1, &value, 1);
    }
    const fmi3Int32 value = (fmi3Int32)v;
    return f3.set_int(c, &r, 1, &value, 1);
}
static int set_bool3(void *c, unsigned vr, int v) {
    const fmi3ValueReference r = vr;
    const fmi3Boolean value = v != 0;
    return f3.set_bool(c, &r, 1, &value, 1);
}
static int get_float3(void *c, unsigned vr, double *v) {
    const fmi3ValueReference r = vr;
    return f3.get_float(c, &r, 1, v, 1);
}
static int get_int3(void *c, unsigned vr, long long *v) {
    const fmi3ValueReference r = vr;
    fmi3Int32 value = 0;
    const int status = f3.get_int(c, &r, 1, &value, 1);
    *v = value;
    return status;
}
static int get_bool3(void *c, unsigned vr, int *v) {
    const fmi3ValueReference r = vr;
    fmi3Boolean value = fmi3False;
    const int status = f3.get_bool(c, &r, 1, &value, 1);
    *v = value ? 1 : 0;
    return status;
}
static int save3(void *c, unsigned char *bytes, size_t capacity, size_t *size) {
    fmi3FMUState state = NULL;
    int status = f3.get_state(c, &state);
    if (status <= STATUS_WARNING) status = f3.state_size(c, state, size);
    if (status <= STATUS_WARNING) status = *size <= capacity ? f3.serialize(c, state, bytes, *size) : STATUS_ERROR;
    f3.free_state(c, &state);
    return status;
}
static int load3(void *c, const unsigned char *bytes, size_t size) {
    fmi3FMUState state = NULL;
    int status = f3.deserialize(c, bytes, size, &state);
    if (status <= STATUS_WARNING) status = f3.set_state(c, state);
    f3.free_state(c, &state);
    return status;
}
static void free3(void *c) {
    f3.free_instance(c);
}

static Fmi load_fmi3(void) {
    f3.instantiate = (fmi3InstantiateCoSimulationTYPE *)function("fmi3InstantiateCoSimulation");
    f3.instantiate_me = (fmi3InstantiateModelExchangeTYPE *)function("fmi3InstantiateModelExchange");
    f3.update = (fmi3UpdateDiscreteStatesTYPE *)function("fmi3UpdateDiscreteStates");
    f3.continuous = (fmi3EnterContinuousTimeModeTYPE *)function("fmi3EnterContinuousTimeMode");
    f3.set_time = (fmi3SetTimeTYPE *)function("fmi3SetTime");
    f3.event = (fmi3EnterEventModeTYPE *)function("fmi3EnterEventMode");
    f3.enter = (fmi3EnterInitializationModeTYPE *)function("fmi3EnterInitializationMode");
    f3.leave = (fmi3ExitInitializationModeTYPE *)function("fmi3ExitInitializationMode");
    f3.do_step = (fmi3DoStepTYPE *)function("fmi3DoStep");
    f3.set_float = (fmi3SetFloat64TYPE *)function("fmi3SetFloat64");
    f3.set_int = (fmi3SetInt32TYPE *)function("fmi3SetInt32");
    f3.set_long = (fmi3SetInt64TYPE *)function("fmi3SetInt64");
    f3.set_bool = (fmi3SetBooleanTYPE *)function("fmi3SetBoolean");
    f3.get_float = (fmi3GetFloat64TYPE *)function("fmi3GetFloat64");
    f3.get_int = (fmi3GetInt32TYPE *)function("fmi3GetInt32");
    f3.get_bool = (fmi3GetBooleanTYPE *)function("fmi3GetBoolean");
    f3.free_instance = (fmi3FreeInstanceTYPE *)function("fmi3FreeInstance");
    f3.get_state = (fmi3GetFMUStateTYPE *)function("fmi3GetFMUState");
    f3.set_state = (fmi3SetFMUStateTYPE *)function("fmi3SetFMUState");
    f3.free_state = (fmi3FreeFMUStateTYPE *)function("fmi3FreeFMUState");
    f3.state_size = (fmi3SerializedFMUStateSizeTYPE *)function("fmi3SerializedFMUStateSize");
    f3.serialize = (fmi3SerializeFMUStateTYPE *)function("fmi3SerializeFMUState");
    f3.deserialize = (fmi3DeserializeFMUStateTYPE *)function("fmi3DeserializeFMUState");
    const Fmi fmi = { instantiate3, update3,   continuous3, set_time3, event3,    init3, step3, set_float3,
                      set_int3,     set_bool3, get_float3,  get_int3,  get_bool3, save3, load3, free3 };
    return fmi;
}

/* ---- FMI 2 ---- */

static struct {
    fmi2InstantiateTYPE *instantiate;
    fmi2NewDiscreteStatesTYPE *update;
    fmi2EnterContinuousTimeModeTYPE *continuous;
    fmi2SetTimeTYPE *set_time;
    fmi2EnterEventModeTYPE *event;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter;
    fmi2ExitInitializationModeTYPE *leave;
    fmi2DoStepTYPE *do_step;
    fmi2SetRealTYPE *set_real;
    fmi2SetIntegerTYPE *set_int;
    fmi2SetBooleanTYPE *set_bool;
    fmi2GetRealTYPE *get_real;
    fmi2GetIntegerTYPE *get_int;
    fmi2GetBooleanTYPE *get_bool;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2GetFMUstateTYPE *get_state;
    fmi2SetFMUstateTYPE *set_state;
    fmi2FreeFMUstateTYPE *free_state;
    fmi2SerializedFMUstateSizeTYPE *state_size;
    fmi2SerializeFMUstateTYPE *serialize;
    fmi2DeSerializeFMUstateTYPE *deserialize;
} f2;

static void logger2(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                    fmi2String message, ...) {
    (void)env;
    (void)name;
    (void)status;
    (void)category;
    (void)message;
}

static const fmi2CallbackFunctions callbacks2 = { logger2, calloc, free, NULL, NULL };

static void *instantiate2(const char *token) {
    return f2.instantiate("trace", model_exchange ? fmi2ModelExchange : fmi2CoSimulation, token, NULL, &callbacks2,
                          fmi2False, fmi2False);
}
static int update2(void *c, double *next) {
    fmi2EventInfo info;
    info.nextEventTimeDefined = fmi2False;
    const int status = f2.update(c, &info);
    *next = info.nextEventTimeDefined ? info.nextEventTime : NAN;
    return status;
}
static int continuous2(void *c) {
    return f2.continuous(c);
}
static int set_time2(void *c, double t) {
    return f2.set_time(c, t);
}
static int event2(void *c) {
    return f2.event(c);
}
static int init2(void *c, double start) {
    int status = f2.setup(c, fmi2False, 0.0, start, fmi2False, 0.0);
    if (status <= STATUS_WARNING) status = f2.enter(c);
    return status <= STATUS_WARNING ? (int)f2.leave(c) : status;
}
static int step2(void *c, double t, double h) {
    return f2.do_step(c, t, h, fmi2True);
}
static int set_float2(void *c, unsigned vr, double v) {
    const fmi2ValueReference r = vr;
    return f2.set_real(c, &r, 1, &v);
}
static int set_int2(void *c, unsigned vr, long long v, char kind) {
    (void)kind; /* an enumeration is an Integer in FMI 2 */
    const fmi2ValueReference r = vr;
    const fmi2Integer value = (fmi2Integer)v;
    return f2.set_int(c, &r, 1, &value);
}
static int set_bool2(void *c, unsigned vr, int v) {
    const fmi2ValueReference r = vr;
    const fmi2Boolean value = v != 0;
    return f2.set_bool(c, &r, 1, &value);
}
static int get_float2(void *c, unsigned vr, double *v) {
    const fmi2ValueReference r = vr;
    return f2.get_real(c, &r, 1, v);
}
static int get_int2(void *c, unsigned vr, long long *v) {
    const fmi2ValueReference r = vr;
    fmi2Integer value = 0;
    const int status = f2.get_int(c, &r, 1, &value);
    *v = value;
    return status;
}
static int get_bool2(void *c, unsigned vr, int *v) {
    const fmi2ValueReference r = vr;
    fmi2Boolean value = fmi2False;
    const int status = f2.get_bool(c, &r, 1, &value);
    *v = value ? 1 : 0;
    return status;
}
static int save2(void *c, unsigned char *bytes, size_t capacity, size_t *size) {
    fmi2FMUstate state = NULL;
    int status = f2.get_state(c, &state);
    if (status <= STATUS_WARNING) status = f2.state_size(c, state, size);
    if (status <= STATUS_WARNING)
        status = *size <= capacity ? f2.serialize(c, state, (fmi2Byte *)bytes, *size) : STATUS_ERROR;
    f2.free_state(c, &state);
    return status;
}
static int load2(void *c, const unsigned char *bytes, size_t size) {
    fmi2FMUstate state = NULL;
    int status = f2.deserialize(c, (const fmi2Byte *)bytes, size, &state);
    if (status <= STATUS_WARNING) status = f2.set_state(c, state);
    f2.free_state(c, &state);
    return status;
}
static void free2(void *c) {
    f2.free_instance(c);
}

static Fmi load_fmi2(void) {
    f2.instantiate = (fmi2InstantiateTYPE *)function("fmi2Instantiate");
    f2.update = (fmi2NewDiscreteStatesTYPE *)function("fmi2NewDiscreteStates");
    f2.continuous = (fmi2EnterContinuousTimeModeTYPE *)function("fmi2EnterContinuousTimeMode");
    f2.set_time = (fmi2SetTimeTYPE *)function("fmi2SetTime");
    f2.event = (fmi2EnterEventModeTYPE *)function("fmi2EnterEventMode");
    f2.setup = (fmi2SetupExperimentTYPE *)function("fmi2SetupExperiment");
    f2.enter = (fmi2EnterInitializationModeTYPE *)function("fmi2EnterInitializationMode");
    f2.leave = (fmi2ExitInitializationModeTYPE *)function("fmi2ExitInitializationMode");
    f2.do_step = (fmi2DoStepTYPE *)function("fmi2DoStep");
    f2.set_real = (fmi2SetRealTYPE *)function("fmi2SetReal");
    f2.set_int = (fmi2SetIntegerTYPE *)function("fmi2SetInteger");
    f2.set_bool = (fmi2SetBooleanTYPE *)function("fmi2SetBoolean");
    f2.get_real = (fmi2GetRealTYPE *)function("fmi2GetReal");
    f2.get_int = (fmi2GetIntegerTYPE *)function("fmi2GetInteger");
    f2.get_bool = (fmi2GetBooleanTYPE *)function("fmi2GetBoolean");
    f2.free_instance = (fmi2FreeInstanceTYPE *)function("fmi2FreeInstance");
    f2.get_state = (fmi2GetFMUstateTYPE *)function("fmi2GetFMUstate");
    f2.set_state = (fmi2SetFMUstateTYPE *)function("fmi2SetFMUstate");
    f2.free_state = (fmi2FreeFMUstateTYPE *)function("fmi2FreeFMUstate");
    f2.state_size = (fmi2SerializedFMUstateSizeTYPE *)function("fmi2SerializedFMUstateSize");
    f2.serialize = (fmi2SerializeFMUstateTYPE *)function("fmi2SerializeFMUstate");
    f2.deserialize = (fmi2DeSerializeFMUstateTYPE *)function("fmi2DeSerializeFMUstate");
    const Fmi fmi = { instantiate2, update2,   continuous2, set_time2, event2,    init2, step2, set_float2,
                      set_int2,     set_bool2, get_float2,  get_int2,  get_bool2, save2, load2, free2 };
    return fmi;
}

/* ---- Model Exchange: init and step as an importer drives them ---- */

static double next_event; /* of the last update; NaN: none */

static int init_me(const Fmi *fmi, void *c, double start) {
    int status = fmi->init(c, start);
    return status <= STATUS_WARNING ? fmi->update(c, &next_event) : status;
}

/* From Event Mode at the FMU's time to Event Mode at t + h, through every
 * time event before it (after 1000 of them straight to the end: the FMU
 * runs the cycles that ended meanwhile at its next event, as a long step
 * does). The comparisons are quiet (NaN: no event) and the sum cannot
 * overflow: no floating-point exception of the harness's own. */
static int step_me(const Fmi *fmi, void *c, double t, double h) {
    if (!(isless(fabs(t), 0x1p1022) && isless(fabs(h), 0x1p1022))) return STATUS_ERROR;
    const double end = t + h;
    int status = STATUS_OK;
    for (int at_end = 0, events = 0; !at_end && status <= STATUS_WARNING; events++) {
        at_end = !isless(next_event, end) || events >= 1000;
        const double when = at_end ? end : next_event;
        status = fmi->continuous(c);
        if (status <= STATUS_WARNING) status = fmi->set_time(c, when);
        if (status <= STATUS_WARNING) status = fmi->event(c);
        if (status <= STATUS_WARNING) status = fmi->update(c, &next_event);
    }
    return status;
}

/* ---- floating-point traps ---- */

static volatile long current_line;

#ifdef HAVE_TRAPS
/* where: the binary and the offset in it of the instruction that trapped
 * (addr2line -e <binary> <offset> names the source line) */
static void trapped(int signal_number, siginfo_t *info, void *context) {
    (void)signal_number;
    const char *what = info->si_code == FPE_FLTINV   ? "FE_INVALID"
                       : info->si_code == FPE_FLTDIV ? "FE_DIVBYZERO"
                       : info->si_code == FPE_FLTOVF ? "FE_OVERFLOW"
                                                     : "another floating-point exception";
    const char *binary = "?";
    size_t offset = 0;
#if defined(__x86_64__)
    Dl_info where;
    const greg_t pc = ((ucontext_t *)context)->uc_mcontext.gregs[REG_RIP];
    if (dladdr((void *)pc, &where) && where.dli_fname) {
        binary = where.dli_fname;
        offset = (size_t)pc - (size_t)where.dli_fbase;
    }
#else
    (void)context;
#endif
    char message[600];
    const int n = snprintf(message, sizeof message, "line %ld: SIGFPE, %s raised in %s+0x%zx\n", (long)current_line,
                           what, binary, offset);
    if (n > 0 && fwrite(message, 1, (size_t)n, stderr)) fflush(stderr);
    _exit(3);
}

static int enable_traps(void) {
    struct sigaction action;
    memset(&action, 0, sizeof action);
    action.sa_sigaction = trapped;
    action.sa_flags = SA_SIGINFO;
    sigemptyset(&action.sa_mask);
    return sigaction(SIGFPE, &action, NULL) == 0 && feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW) != -1;
}
#else
static int enable_traps(void) {
    fprintf(stderr, "--trap: this platform's C library cannot enable floating-point traps\n");
    return 0;
}
#endif

int main(int argc, char **argv) {
    int fmi2 = 0, trap = 0, keep_going = 0, a = 1;
    for (; a < argc && argv[a][0] == '-'; a++) {
        if (strcmp(argv[a], "--fmi2") == 0) fmi2 = 1;
        else if (strcmp(argv[a], "--trap") == 0) trap = 1;
        else if (strcmp(argv[a], "--keep-going") == 0) keep_going = 1;
        else if (strcmp(argv[a], "--model-exchange") == 0) model_exchange = 1;
        else if (strcmp(argv[a], "--prefix") == 0 && a + 1 < argc) function_prefix = argv[++a];
        else break;
    }
    if (argc - a != 2) {
        fprintf(stderr, "usage: run_trace [--fmi2] [--trap] [--keep-going] [--model-exchange] [--prefix <P>] <binary> "
                        "<token> < script\n");
        return 2;
    }
    if (!open_library(argv[a])) return 2;
    const Fmi fmi = fmi2 ? load_fmi2() : load_fmi3();
    const char *token = argv[a + 1];
    if (trap && !enable_traps()) return 2;

    void *c = fmi.instantiate(token);
    if (!c) {
        fprintf(stderr, "instantiation failed\n");
        return 1;
    }
    char line[256], kind, path[200];
    unsigned vr;
    long line_number = 0;
    int status = STATUS_OK, skipping = 0;
    static unsigned char bytes[1 << 16];
    while (fgets(line, sizeof line, stdin)) {
        current_line = ++line_number;
        double x, y;
        long long n;
        if (strncmp(line, "new", 3) == 0) {
            fmi.free_instance(c);
            c = fmi.instantiate(token);
            if (!c) {
                fprintf(stderr, "line %ld: instantiation failed\n", line_number);
                return 1;
            }
            skipping = 0;
            continue;
        }
        if (skipping) continue;
        if (sscanf(line, "set %c %u %lld", &kind, &vr, &n) == 3 && kind != 'F') {
            status = kind == 'B' ? fmi.set_bool(c, vr, n != 0) : fmi.set_int(c, vr, n, kind);
        } else if (sscanf(line, "set F %u %la", &vr, &x) == 2) {
            status = fmi.set_float(c, vr, x);
        } else if (sscanf(line, "init %la", &x) == 1) {
            status = model_exchange ? init_me(&fmi, c, x) : fmi.init(c, x);
        } else if (sscanf(line, "step %la %la", &x, &y) == 2) {
            status = model_exchange ? step_me(&fmi, c, x, y) : fmi.step(c, x, y);
        } else if (sscanf(line, "get %c %u", &kind, &vr) == 2) {
            if (kind == 'F') {
                double v = 0.0;
                status = fmi.get_float(c, vr, &v);
                printf("%a\n", v);
            } else if (kind == 'I') {
                long long v = 0;
                status = fmi.get_int(c, vr, &v);
                printf("%lld\n", v);
            } else {
                int v = 0;
                status = fmi.get_bool(c, vr, &v);
                printf("%d\n", v);
            }
        } else if (sscanf(line, "save %199s", path) == 1) {
            size_t size = 0;
            status = fmi.save(c, bytes, sizeof bytes, &size);
            FILE *f = fopen(path, "wb");
            if (!f || fwrite(bytes, 1, size, f) != size || fclose(f) != 0) status = STATUS_ERROR;
        } else if (sscanf(line, "load %199s", path) == 1) {
            FILE *f = fopen(path, "rb");
            const size_t size = f ? fread(bytes, 1, sizeof bytes, f) : 0;
            if (f) fclose(f);
            status = fmi.load(c, bytes, size);
        } else {
            fprintf(stderr, "line %ld: cannot read '%s'\n", line_number, line);
            return 2;
        }
        if (status > STATUS_WARNING) {
            if (!keep_going) break;
            printf("refused %ld\n", line_number);
            skipping = 1;
        }
    }
    fmi.free_instance(c);
    if (status > STATUS_WARNING && !keep_going) {
        fprintf(stderr, "line %ld: status %d\n", line_number, status);
        return 1;
    }
    return 0;
}
