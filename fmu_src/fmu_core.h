/* FMI-version independent part of every FMU: the instance, variable
 * access, the cycle scheduler, Co-Simulation's step (docs/fmi.md, Time:
 * the communication step is the PLC cycle) and Scheduled Execution's
 * activation (one PLC cycle per tick of the clock), logging. Model Exchange
 * (fmu_model_exchange.h) and FMU states (fmu_state.h) build on it.
 * fmi2_glue.c and fmi3_glue.c map the FMI C APIs onto them; a model
 * (model.h, models/<Model>.c) maps its variables onto the kernel. */
#ifndef FMU_CORE_H
#define FMU_CORE_H

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "model.h"

/* Same numbering as fmi2Status and fmi3Status. */
typedef enum { FMU_OK, FMU_WARNING, FMU_DISCARD, FMU_ERROR, FMU_FATAL } FmuStatus;

/* FMI modes as bits, so that each glue can state per function the set of
 * modes it is allowed in. Step Mode is Co-Simulation's, Event Mode and
 * Continuous-Time Mode are Model Exchange's, Clock Activation Mode is
 * Scheduled Execution's (FMI 3 only); the others are shared. */
typedef enum {
    MODE_INSTANTIATED = 1 << 0,
    MODE_INITIALIZATION = 1 << 1,
    MODE_STEP = 1 << 2,
    MODE_TERMINATED = 1 << 3,
    MODE_ERROR = 1 << 4,
    MODE_EVENT = 1 << 5,
    MODE_CONTINUOUS = 1 << 6,
    MODE_CLOCK_ACTIVATION = 1 << 7
} FmuMode;

/* The interface an instance was instantiated for. */
typedef enum { FMU_CO_SIMULATION, FMU_MODEL_EXCHANGE, FMU_SCHEDULED_EXECUTION } FmuInterface;

/* A step that would run more cycles than this is refused (no endless loop
 * on a tiny cycleTime or a huge step). */
#define FMU_MAX_CYCLES_PER_STEP 100000000.0

/* Log categories (bits), named in the model description's LogCategories */
enum { LOG_ERROR = 1, LOG_WARNING = 2, LOG_EVENTS = 4, LOG_ALL = 7 };

/* What a step changed since the outputs were last published: the time
 * only (a step that ran no cycle), or the block too. */
enum { FMU_FRESH = 0, FMU_STALE_TIME = 1, FMU_STALE_ALL = 2 };

/* Everything an FMU state restores: plain data, copied as a whole. */
typedef struct {
    double values[FMU_MAX_VARIABLES];
    RlState block;
    double startTime;
    double time;
    uint64_t cycles; /* cycles run since the start (cycleTime > 0; Scheduled Execution counts none) */
    /* Model Exchange: the values as the last event instant left them, which
     * the next cycle runs with (latch), and that instant's time */
    double latched[FMU_MAX_VARIABLES];
    double eventTime;
    int mode;           /* FmuMode */
    int reportedStatus; /* status word last reported in the log */
} FmuCore;

typedef struct FmuInstance FmuInstance;
typedef void FmuLogFunction(FmuInstance *instance, FmuStatus status, const char *category, const char *message);

struct FmuInstance {
    FmuCore core;
    /* of the last cycle (or initialisation); its configuration is taken
     * from the values at the next step (configure), prepared before a
     * cycle runs (prepareDue) */
    RlPrepared prepared;
    RlPlan *plan;               /* remainingTime's with the acceleration limit, kept from read to read
                                   (rl_outputs); made at its first use, NULL until then */
    int modelMode;              /* the model's own, from the same configure */
    bool configDirty;           /* a parameter or input other than u changed */
    unsigned char outputsStale; /* FMU_STALE_*: what changed since the outputs were published */
    bool prepareDue;            /* the configuration changed: prepare before the next cycle */
    /* Step size of the common step (fmu_step_fast), one per arithmetic of
     * the prepared block, so that the step's compare of h also picks the
     * arithmetic: set (the one of the block's arithmetic, the other NaN) by
     * a general step that found the common one possible
     * (fmu_do_step_general), both NaN whenever anything it relies on
     * changes (fmu_disarm); and its time tolerance, set there too (see
     * there why it never exceeds the general one). */
    double fastPeriodReal, fastPeriodLreal, fastTolerance;
    double cycleTime; /* sub-cycle length, 0 = one cycle per step */
    /* Scheduled Execution: the clock's interval as last reported
     * (fmi3GetIntervalDecimal), NaN before; fmu_reset forgets it */
    double reportedInterval;
    /* model->inputVr and outputVr, one load nearer. Every model's u is an
     * unranged, non-fixed Real input and its y a Real output (checked
     * against each model's TOML by test_model_description.py), so the
     * calls of every step, set u and get y as Reals, need no table lookup. */
    unsigned inputVr, outputVr;
    const ModelDefinition *model;
    FmuLogFunction *logFunction;
    int logCategories;          /* enabled categories */
    int errorMode;              /* the mode a failed call leaves: FMI 2 Error, FMI 3 Terminated */
    FmuInterface interfaceType; /* what it was instantiated for */
    void *environment;          /* the importer's instance environment */
    /* memory for FMU states, as the importer provides it (FMI 2) or not */
    void *(*allocate)(FmuInstance *instance, size_t size);
    void (*release)(FmuInstance *instance, void *memory);
};

/* interfaceType and errorMode set first */
RL_LINKAGE void fmu_init_instance(FmuInstance *instance);
/* What the instance holds beyond its own memory, released (before the glue frees it) */
RL_LINKAGE void fmu_free_instance(FmuInstance *instance);
RL_LINKAGE void fmu_reset(FmuInstance *instance);

/* The values or the mode changed other than by a new u (a set, a reset, a
 * restored state, Initialization Mode entered): what the core derived from
 * them is void. The configuration is taken again before the next cycle,
 * the common step waits for a general one, and in Initialization Mode the
 * outputs follow the values. */
RL_LINKAGE void fmu_invalidate(FmuInstance *instance);

/* No common step until a general step finds it possible again. */
static inline void fmu_disarm(FmuInstance *instance) {
    instance->fastPeriodReal = instance->fastPeriodLreal = NAN;
}

RL_LINKAGE void fmu_log(FmuInstance *instance, FmuStatus status, const char *fmt, ...);

/* Enable log categories: all when loggingOn and none are named, else the
 * named ones; alwaysOn categories stay enabled whatever is asked. */
RL_LINKAGE FmuStatus fmu_set_debug_logging(FmuInstance *instance, const char *function, bool loggingOn,
                                           size_t nCategories, const char *const categories[], int alwaysOn);

/* The single error path: log why, enter the error mode, return FMU_ERROR. */
RL_LINKAGE FmuStatus fmu_error(FmuInstance *instance, const char *function, const char *fmt, ...);

/* The checks on the path of every set, doStep and get are inline, and
 * their error paths (which say why) are not: a call that passes costs a
 * few compares. */

/* Out-of-line error paths of the inline checks below. */
/* A call in a mode its function's state table does not allow. */
RL_LINKAGE FMU_COLD FmuStatus fmu_mode_error(FmuInstance *instance, const char *function);
RL_LINKAGE FmuStatus fmu_array_error(FmuInstance *instance, const char *function, const void *vr);
RL_LINKAGE FMU_COLD FmuStatus fmu_access_error(FmuInstance *instance, const char *function, int typeMask, unsigned vr,
                                               double value);
/* Publish the outputs (Initialization Mode: initialize the block first). */
RL_LINKAGE FMU_NOINLINE void fmu_refresh_outputs(FmuInstance *instance);

static inline FmuStatus fmu_check_array(FmuInstance *instance, const char *function, size_t n, const void *vr,
                                        const void *values) {
    return n == 0 || (vr && values) ? FMU_OK : fmu_array_error(instance, function, vr);
}

/* Variable access, value by value, values carried as double: every type
 * here (Real, Integer, Boolean, Enumeration) is exact in a double.
 * fmu_check_set validates one value without changing anything, so that a
 * call setting several values is all or nothing. */
#define TYPE_BIT(type) (1 << (type))

static inline bool fmu_readable(const FmuInstance *instance, int typeMask, unsigned vr) {
    const ModelDefinition *model = instance->model;
    return vr < model->count && (TYPE_BIT(model->variables[vr].type) & typeMask);
}

static inline FmuStatus fmu_check_get(FmuInstance *instance, const char *function, int typeMask, unsigned vr) {
    return fmu_readable(instance, typeMask, vr) ? FMU_OK : fmu_access_error(instance, function, typeMask, vr, 0.0);
}

/* Outputs and time are published when read, not after every step: a step
 * costs no stores that nobody reads. The block's output is its state y; the
 * rest is published together. In Initialization Mode the outputs follow
 * the inputs and parameters set so far. */
static inline double fmu_get(FmuInstance *instance, unsigned vr) {
    if (instance->outputsStale) {
        if (vr == instance->model->outputVr && instance->core.mode != MODE_INITIALIZATION) {
            return instance->core.block.y;
        }
        const FmuCausality causality = instance->model->variables[vr].causality;
        if (causality == FMU_OUTPUT || causality == FMU_INDEPENDENT) {
            fmu_refresh_outputs(instance);
        }
    }
    return instance->core.values[vr];
}

/* A declared range also refuses NaN; without one NaN means "not connected". */
static inline bool fmu_in_range(const FmuVariable *v, double value) {
    return (isgreaterequal(value, v->min) && islessequal(value, v->max)) || (v->min == -INFINITY && v->max == INFINITY);
}

static inline bool fmu_settable(const FmuInstance *instance, int typeMask, unsigned vr, double value) {
    const ModelDefinition *model = instance->model;
    if (vr >= model->count) {
        return false;
    }
    const FmuVariable *v = &model->variables[vr];
    return (TYPE_BIT(v->type) & typeMask) && (v->causality == FMU_INPUT || v->causality == FMU_PARAMETER) &&
           (v->variability != FMU_FIXED || (instance->core.mode & (MODE_INSTANTIATED | MODE_INITIALIZATION))) &&
           fmu_in_range(v, value);
}

static inline FmuStatus fmu_check_set(FmuInstance *instance, const char *function, int typeMask, unsigned vr,
                                      double value) {
    return fmu_settable(instance, typeMask, vr, value) ? FMU_OK
                                                       : fmu_access_error(instance, function, typeMask, vr, value);
}

/* fmu_set of u as a Real: nothing to check. */
static inline void fmu_set_input(FmuInstance *instance, double value) {
    instance->core.values[instance->inputVr] = value;
    if (instance->core.mode == MODE_INITIALIZATION) {
        instance->outputsStale = FMU_STALE_ALL;
    }
}

static inline void fmu_set(FmuInstance *instance, unsigned vr, double value) {
    if (vr == instance->inputVr) {
        fmu_set_input(instance, value);
    } else {
        instance->core.values[vr] = value;
        fmu_invalidate(instance);
    }
}

/* One value, the common call of every get and set: inline, the error path
 * out of line. false: refused (logged, error mode). u and y as Reals need
 * no table lookup. */
static inline bool fmu_get_one(FmuInstance *instance, const char *function, int typeMask, unsigned vr, double *value) {
    if (!(typeMask == TYPE_BIT(FMU_REAL) && vr == instance->outputVr) && !fmu_readable(instance, typeMask, vr)) {
        fmu_access_error(instance, function, typeMask, vr, 0.0);
        return false;
    }
    *value = fmu_get(instance, vr);
    return true;
}

static inline bool fmu_set_one(FmuInstance *instance, const char *function, int typeMask, unsigned vr, double value) {
    if (typeMask == TYPE_BIT(FMU_REAL) && vr == instance->inputVr) {
        fmu_set_input(instance, value);
        return true;
    }
    if (!fmu_settable(instance, typeMask, vr, value)) {
        fmu_access_error(instance, function, typeMask, vr, value);
        return false;
    }
    fmu_set(instance, vr, value);
    return true;
}

/* The experiment's times: a finite start, a stop (if defined) not before it. */
RL_LINKAGE FmuStatus fmu_setup_experiment(FmuInstance *instance, const char *function, double startTime,
                                          bool stopTimeDefined, double stopTime);
RL_LINKAGE FmuStatus fmu_enter_initialization(FmuInstance *instance);
RL_LINKAGE FmuStatus fmu_exit_initialization(FmuInstance *instance);
RL_LINKAGE void fmu_terminate(FmuInstance *instance);
/* currentCommunicationPoint within a relative RL_TIME_TOLERANCE of the
 * FMU's time (finite), whatever the step size (NaN and infinity are not);
 * the difference quiet (rl_sum): a t far from the time raises no
 * FE_OVERFLOW */
static inline bool fmu_time_matches(double t, double time) {
    return isfinite(t) && islessequal(fabs(rl_sum(-time, t)), RL_TIME_TOLERANCE * fabs(time));
}

/* The common step, inline in the glue: the same step size as the step
 * before, no sub-cycling, nothing changed but u, and a cycle in which only
 * rule 6 applies. What does not change from step to step is checked once,
 * by the general step that sets a fast period (see there); what is left is h,
 * t and a finite u. False: nothing done, take the general step. */
static inline bool fmu_step_fast(FmuInstance *instance, double t, double h) {
    FmuCore *core = &instance->core;
    /* t - time cannot overflow at the times the common step runs at
     * (fmu_do_step_general); the cycle itself, if u is finite in the
     * block's arithmetic (y stays finite) */
    const double u = core->values[instance->inputVr];
    if (h == instance->fastPeriodReal) {
        if (!(islessequal(fabs(t - core->time), instance->fastTolerance) &&
              rl_ramp_steady_real(&core->block, &instance->prepared, u))) {
            return false;
        }
    } else if (!(h == instance->fastPeriodLreal && islessequal(fabs(t - core->time), instance->fastTolerance) &&
                 rl_ramp_steady_lreal(&core->block, &instance->prepared, u))) {
        return false;
    }
    instance->outputsStale = FMU_STALE_ALL;
    core->time = t + h;
    return true; /* no status change: that needs a new configuration */
}

/* Scheduled Execution: the partition of the clock activated at
 * activationTime, after the last activation (or the start): one PLC cycle
 * of length cycleTime that ends then, whatever the time since the last
 * (a late or early tick is the OB's jitter, seen by what measures the
 * elapsed time); none without a valid cycleTime. */
RL_LINKAGE FmuStatus fmu_activate(FmuInstance *instance, const char *function, double activationTime);

/* The cycle length the parameters set now, 0 if none (not finite or not
 * > 0); nothing derived from them changes. */
RL_LINKAGE double fmu_configured_cycle(const FmuInstance *instance);

/* Any step, with every check and the status report. */
RL_LINKAGE FMU_NOINLINE FmuStatus fmu_do_step_general(FmuInstance *instance, const char *function, double t, double h);

/* The step of both FMI versions: the common one if it applies, else the
 * general one. */
static inline FmuStatus fmu_do_step(FmuInstance *instance, const char *function, double t, double h) {
    return fmu_step_fast(instance, t, h) ? FMU_OK : fmu_do_step_general(instance, function, t, h);
}

RL_LINKAGE const char *fmu_mode_name(int mode);
/* "Co-Simulation", "Model Exchange" or "Scheduled Execution" */
RL_LINKAGE const char *fmu_interface_name(FmuInterface interfaceType);

/* ---- shared with Model Exchange (fmu_model_exchange.c) ------------------ */

/* The values the next cycle runs with are the current ones (the latch,
 * FmuCore.latched): at the start, and when Model Exchange leaves an
 * instant. Core data, set here so that the core calls no interface. */
static inline void fmu_latch_values(FmuInstance *instance) {
    memcpy(instance->core.latched, instance->core.values, sizeof instance->core.latched);
}

/* The kernel's configuration from the current values (the outputs of the
 * last cycle published first: they need its configuration). */
RL_LINKAGE FMU_NOINLINE void fmu_configure(FmuInstance *instance);
/* Model Exchange and Scheduled Execution, after fmu_configure: no cycle
 * without cycleTime. */
RL_LINKAGE void fmu_refuse_no_cycle(FmuInstance *instance);
/* Sub-cycling: the cycles that end by the time end; *ran when one ran. */
RL_LINKAGE FMU_NOINLINE FmuStatus fmu_run_cycles(FmuInstance *instance, const char *function, double end, double h,
                                                 double u, bool *ran);
RL_LINKAGE FMU_NOINLINE void fmu_log_status(FmuInstance *instance);

/* A status word that changed since it was last reported is logged once
 * (fmu_log_status); the call returns OK. */
static inline FmuStatus fmu_report_status(FmuInstance *instance) {
    if (instance->prepared.status != instance->core.reportedStatus) {
        fmu_log_status(instance);
    }
    return FMU_OK;
}

#endif
