#include "fmu_core.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const log_category_names[3] = { "logStatusError", "logStatusWarning", "logEvents" };

const char *fmu_mode_name(int mode) {
    switch (mode) {
    case MODE_INSTANTIATED: return "Instantiated";
    case MODE_INITIALIZATION: return "Initialization Mode";
    case MODE_STEP: return "Step Mode";
    case MODE_TERMINATED: return "Terminated";
    case MODE_ERROR: return "Error (after a failed call)";
    case MODE_EVENT: return "Event Mode";
    case MODE_CONTINUOUS: return "Continuous-Time Mode";
    case MODE_CLOCK_ACTIVATION: return "Clock Activation Mode";
    default: return "unknown";
    }
}

const char *fmu_interface_name(FmuInterface interfaceType) {
    switch (interfaceType) {
    case FMU_MODEL_EXCHANGE: return "Model Exchange";
    case FMU_SCHEDULED_EXECUTION: return "Scheduled Execution";
    default: return "Co-Simulation";
    }
}

/* with its article, for "is a Real variable" */
static const char *type_name(FmuType type) {
    switch (type) {
    case FMU_REAL: return "a Real";
    case FMU_INTEGER: return "an Integer";
    case FMU_BOOLEAN: return "a Boolean";
    case FMU_ENUMERATION: return "an Enumeration";
    default: return "an unsupported";
    }
}

void fmu_init_instance(FmuInstance *instance) {
    instance->model = &fmuModel;
    instance->inputVr = fmuModel.inputVr;
    instance->outputVr = fmuModel.outputVr;
    instance->plan = NULL;
    fmu_reset(instance);
}

void fmu_free_instance(FmuInstance *instance) {
    if (instance->plan) instance->release(instance, instance->plan);
    instance->plan = NULL;
}

/* The instance's kept plan, made at its first use; NULL if no memory
 * (remainingTime is then planned afresh at each read: the same value). */
static RlPlan *kept_plan(FmuInstance *instance) {
    if (!instance->plan) {
        instance->plan = (RlPlan *)instance->allocate(instance, sizeof *instance->plan);
        if (instance->plan) memset(instance->plan, 0, sizeof *instance->plan);
    }
    return instance->plan;
}

void fmu_reset(FmuInstance *instance) {
    FmuCore *core = &instance->core;
    const ModelDefinition *model = instance->model;
    memset(core, 0, sizeof *core);
    for (unsigned i = 0; i < model->count; i++) {
        core->values[i] = model->variables[i].start;
    }
    core->mode = MODE_INSTANTIATED;
    fmu_latch_values(instance); /* values this FMU could have */
    memset(&instance->prepared, 0, sizeof instance->prepared);
    instance->prepared.period = NAN;
    if (instance->plan) instance->plan->valid = false; /* (a plan is only ever a cost saved) */
    instance->reportedInterval = NAN;
    /* the start values are the outputs until Initialization Mode */
    instance->outputsStale = FMU_FRESH;
    fmu_invalidate(instance);
}

/* fmu_configure sets prepareDue and cycleTime, so that neither needs setting
 * here: configDirty guarantees a configure before the next cycle (a step
 * configures first; Initialization Mode's outputs and its end initialize
 * the block, which configures). */
void fmu_invalidate(FmuInstance *instance) {
    instance->configDirty = true;
    fmu_disarm(instance);
    if (instance->core.mode == MODE_INITIALIZATION) {
        instance->outputsStale = FMU_STALE_ALL;
    }
}

static void log_message(FmuInstance *instance, FmuStatus status, const char *fmt, va_list args) {
    const int category = status >= FMU_ERROR ? LOG_ERROR : status == FMU_WARNING ? LOG_WARNING : LOG_EVENTS;
    const char *name = log_category_names[category == LOG_ERROR ? 0 : category == LOG_WARNING ? 1 : 2];
    char message[512];

    if (!instance->logFunction || !(instance->logCategories & category)) {
        return;
    }
    vsnprintf(message, sizeof message, fmt, args);
    /* FMI 2 loggers may treat the message as a format string */
    for (char *c = message; *c; c++) {
        if (*c == '%') *c = '?';
    }
    instance->logFunction(instance, status, name, message);
}

void fmu_log(FmuInstance *instance, FmuStatus status, const char *fmt, ...) {
    va_list args;
    va_start(args, fmt);
    log_message(instance, status, fmt, args);
    va_end(args);
}

FmuStatus fmu_set_debug_logging(FmuInstance *instance, const char *function, bool loggingOn, size_t nCategories,
                                const char *const categories[], int alwaysOn) {
    int enabled = 0;
    if (nCategories > 0 && !categories) {
        return fmu_error(instance, function, "the category array is NULL");
    }
    for (size_t i = 0; i < nCategories; i++) {
        int bit = 0;
        for (int k = 0; k < 3; k++) {
            if (categories[i] && strcmp(categories[i], log_category_names[k]) == 0) bit = 1 << k;
        }
        if (!bit) {
            return fmu_error(instance, function, "unknown log category \"%s\"",
                             categories[i] ? categories[i] : "(null)");
        }
        enabled |= bit;
    }
    if (loggingOn && nCategories == 0) {
        enabled = LOG_ALL;
    }
    instance->logCategories = (loggingOn ? enabled : 0) | alwaysOn;
    return FMU_OK;
}

FmuStatus fmu_error(FmuInstance *instance, const char *function, const char *fmt, ...) {
    char reason[400];
    va_list args;
    va_start(args, fmt);
    vsnprintf(reason, sizeof reason, fmt, args);
    va_end(args);
    fmu_log(instance, FMU_ERROR, "%s: %s", function, reason);
    instance->core.mode = instance->errorMode;
    return FMU_ERROR;
}

FmuStatus fmu_mode_error(FmuInstance *instance, const char *function) {
    return fmu_error(instance, function, "not allowed in %s", fmu_mode_name(instance->core.mode));
}

FmuStatus fmu_array_error(FmuInstance *instance, const char *function, const void *vr) {
    return fmu_error(instance, function, vr ? "the value array is NULL" : "the value reference array is NULL");
}

/* Why fmu_check_get or fmu_check_set refused a value reference. */
FmuStatus fmu_access_error(FmuInstance *instance, const char *function, int typeMask, unsigned vr, double value) {
    const ModelDefinition *model = instance->model;
    if (vr >= model->count) {
        return fmu_error(instance, function, "unknown value reference %u", vr);
    }
    const FmuVariable *v = &model->variables[vr];
    if (!(TYPE_BIT(v->type) & typeMask)) {
        return fmu_error(instance, function, "%s (value reference %u) is %s variable, which %s cannot access", v->name,
                         vr, type_name(v->type), function);
    }
    /* a get is refused only for the two reasons above (fmu_readable): a set from here */
    if (v->causality == FMU_OUTPUT || v->causality == FMU_INDEPENDENT) {
        return fmu_error(instance, function, "%s is an %s and cannot be set", v->name,
                         v->causality == FMU_OUTPUT ? "output" : "independent variable");
    }
    if (v->variability == FMU_FIXED && !(instance->core.mode & (MODE_INSTANTIATED | MODE_INITIALIZATION))) {
        return fmu_error(instance, function, "%s is a fixed parameter and cannot be set after initialization", v->name);
    }
    return fmu_error(instance, function, "%s = %.17g is outside its range [%g, %g]", v->name, value, v->min, v->max);
}

/* The time, and the block's outputs when a cycle ran since they were
 * published (a step that runs no cycle changes no output). */
static void publish(FmuInstance *instance, bool block) {
    instance->core.values[0] = instance->core.time; /* the independent variable */
    if (block) {
        RlPlan *plan = instance->prepared.accelLimited ? kept_plan(instance) : NULL;
        instance->model->publish(&instance->core.block, &instance->prepared, instance->modelMode, plan,
                                 instance->core.values);
    }
    instance->outputsStale = FMU_FRESH;
}

/* The sub-cycle length a configuration sets: 0 (one cycle per step) unless finite and > 0. */
static double cycle_of(const RlConfig *config) {
    const double c = config->cycleTime.value;
    return isgreater(c, 0) && isfinite(c) ? c : 0.0;
}

double fmu_configured_cycle(const FmuInstance *instance) {
    RlConfig config = instance->prepared.config; /* a copy: configure fills it, nothing else changes */
    instance->model->configure(instance->core.values, &config);
    return cycle_of(&config);
}

/* Kernel configuration from the current values; the cycle length and
 * limits are derived again before the next cycle. The outputs derived from
 * the last cycle are published first: they need its configuration. */
void fmu_configure(FmuInstance *instance) {
    if (instance->outputsStale == FMU_STALE_ALL) {
        publish(instance, true);
    }
    instance->modelMode = instance->model->configure(instance->core.values, &instance->prepared.config);
    instance->cycleTime = cycle_of(&instance->prepared.config);
    instance->prepareDue = true;
    instance->configDirty = false;
}

/* not inline: keeps the step's frame small */
FMU_NOINLINE static void prepare(FmuInstance *instance, double period) {
    fmu_disarm(instance);
    RlConfig config = instance->prepared.config;
    rl_prepare(&instance->prepared, &config, period);
    instance->prepareDue = false;
    /* the status is known from here; the block's outputs after a cycle */
    const FmuStatusOutputs *outputs = instance->model->statusOutputs;
    if (outputs) {
        const int status = instance->prepared.status;
        instance->core.values[outputs->errorVr] = rl_status_is_error(status);
        instance->core.values[outputs->statusVr] = status;
        instance->core.values[outputs->causeVr] = rl_status_is_error(status) ? instance->prepared.statusSource : 0;
    }
}

/* Model Exchange, after fmu_configure: there is no communication step to
 * stand in for the cycle, so without cycleTime there is no cycle. (Not in
 * fmu_configure: Co-Simulation's step does not pay for it.) */
void fmu_refuse_no_cycle(FmuInstance *instance) {
    RlConfig *config = &instance->prepared.config;
    config->cycleRefused = config->cycleRefused || instance->cycleTime == 0;
}

/* Outputs at the start from the current parameters and inputs. */
static void initialize_block(FmuInstance *instance) {
    FmuCore *core = &instance->core;
    fmu_configure(instance);
    if (instance->interfaceType != FMU_CO_SIMULATION) {
        fmu_refuse_no_cycle(instance);
    }
    /* with cycleTime 0 the cycle length is only known at the first step */
    prepare(instance, instance->cycleTime > 0 ? instance->cycleTime : NAN);
    rl_init(&core->block, &instance->prepared, core->values[instance->model->inputVr]);
    publish(instance, true);
}

void fmu_refresh_outputs(FmuInstance *instance) {
    if (instance->core.mode == MODE_INITIALIZATION) {
        initialize_block(instance);
    } else {
        publish(instance, instance->outputsStale == FMU_STALE_ALL);
    }
}

FmuStatus fmu_setup_experiment(FmuInstance *instance, const char *function, double startTime, bool stopTimeDefined,
                               double stopTime) {
    if (stopTimeDefined && !isgreaterequal(stopTime, startTime)) {
        return fmu_error(instance, function, "stopTime %g is before startTime %g", stopTime, startTime);
    }
    if (!isfinite(startTime)) {
        return fmu_error(instance, function, "startTime %g is not finite", startTime);
    }
    instance->core.startTime = startTime;
    instance->core.time = startTime;
    instance->core.values[0] = startTime;
    return FMU_OK;
}

void fmu_terminate(FmuInstance *instance) {
    instance->core.mode = MODE_TERMINATED;
}

FmuStatus fmu_enter_initialization(FmuInstance *instance) {
    instance->core.mode = MODE_INITIALIZATION;
    fmu_invalidate(instance);
    return FMU_OK;
}

/* Log a change of the status word once. A status is the PLC block's
 * business, not an FMI error: the call that sees it returns OK (importers
 * such as OMSimulator stop on any other status) and an error status is
 * logged as a message of status Warning in logStatusWarning. */
void fmu_log_status(FmuInstance *instance) {
    const RlPrepared *p = &instance->prepared;
    instance->core.reportedStatus = p->status;
    if (rl_status_is_error(p->status)) {
        const FmuVariable *cause = &instance->model->variables[p->statusSource];
        const bool noCycle = instance->interfaceType != FMU_CO_SIMULATION && p->status == RL_STATUS_NO_CYCLE;
        fmu_log(instance, FMU_WARNING, "status 16#%04X: %s (%s = %g); the output holds%s", (unsigned)p->status,
                rl_status_text(p->status), cause->name, instance->core.values[p->statusSource],
                noCycle ? (instance->interfaceType == FMU_MODEL_EXCHANGE
                               ? ". Model Exchange runs the block at the ends of its cycles: set cycleTime to the PLC "
                                 "cycle (the interval of the cyclic interrupt OB or task)"
                               : ". Scheduled Execution's clock ticks once per PLC cycle: set cycleTime to the PLC "
                                 "cycle (the interval of the cyclic interrupt OB or task)")
                        : "");
    } else {
        fmu_log(instance, FMU_OK, "status 16#%04X: %s", (unsigned)p->status, rl_status_text(p->status));
    }
}

FmuStatus fmu_exit_initialization(FmuInstance *instance) {
    initialize_block(instance);
    /* Model Exchange: Event Mode at the start time, whose instant the
     * first cycle takes its values from */
    static const int firstMode[] = { MODE_STEP, MODE_EVENT, MODE_CLOCK_ACTIVATION }; /* by FmuInterface */
    instance->core.mode = firstMode[instance->interfaceType];
    instance->core.cycles = 0;
    instance->core.eventTime = instance->core.time;
    fmu_latch_values(instance);
    return fmu_report_status(instance);
}

/* The number of whole cycles that end by the time end (a time within
 * RL_TIME_TOLERANCE of a cycle end counts as that end): the inverse of
 * fmu_cycle_end (fmu_model_exchange.c). */
static double cycles_ended_by(const FmuCore *core, double cycle, double end) {
    return floor(rl_quotient(rl_sum(end, -core->startTime), cycle) + RL_TIME_TOLERANCE);
}

/* Sub-cycling (cycleTime > 0): the cycles that end in (t, end], each end
 * t0 + n*cycleTime computed afresh from the whole cycle count n. */
/* Sets *ran when a cycle ran. */
FmuStatus fmu_run_cycles(FmuInstance *instance, const char *function, double end, double h, double u, bool *ran) {
    FmuCore *core = &instance->core;
    const double cycle = instance->cycleTime;
    const double last = cycles_ended_by(core, cycle, end);
    const double pending = last - (double)core->cycles;
    if (!islessequal(pending, FMU_MAX_CYCLES_PER_STEP)) {
        return fmu_error(instance, function, "a step of %g s would run %g cycles of %g s; at most %g per step", h,
                         pending, cycle, FMU_MAX_CYCLES_PER_STEP);
    }
    *ran = pending >= 1;
    if (*ran) {
        if (instance->prepareDue || instance->prepared.period != cycle) {
            prepare(instance, cycle);
        }
        rl_run(&core->block, &instance->prepared, u, core->cycles + 1, (uint64_t)last, cycle);
        core->cycles = (uint64_t)last;
    }
    return FMU_OK;
}

/* Every step but the common one: checks that failed, a changed
 * configuration or step size, sub-cycling, a status to report. */
FmuStatus fmu_do_step_general(FmuInstance *instance, const char *function, double t, double h) {
    FmuCore *core = &instance->core;

    if (!(isgreater(h, 0) && islessequal(h, DBL_MAX))) {
        return fmu_error(instance, function, "communicationStepSize must be finite and > 0, not %g", h);
    }
    if (!fmu_time_matches(t, core->time)) {
        return fmu_error(instance, function, "currentCommunicationPoint %.17g is not the FMU's time %.17g", t,
                         core->time);
    }
    const double end = rl_sum(t, h);
    if (isinf(end)) {
        return fmu_error(instance, function, "a step of %g s from %g would end past the largest time", h, t);
    }
    if (instance->configDirty) {
        fmu_configure(instance);
    }
    const double u = core->values[instance->model->inputVr];
    bool ran = true;
    if (instance->cycleTime > 0) {
        if (fmu_run_cycles(instance, function, end, h, u, &ran) != FMU_OK) return FMU_ERROR;
    } else {
        /* one cycle of length h */
        if (instance->prepareDue || instance->prepared.period != h) {
            prepare(instance, h);
        }
        rl_cycle(&core->block, &instance->prepared, u, rl_sum(end, -core->startTime));
    }
    core->time = end;
    if (ran) {
        instance->outputsStale = FMU_STALE_ALL;
    } else if (instance->outputsStale == FMU_FRESH) {
        instance->outputsStale = FMU_STALE_TIME;
    }
    /* The next step may be the common one (fmu_step_fast) if it has this h,
     * the configuration stays, one cycle per step, only rule 6 applies to
     * any finite u (plain), y is finite and rule 6 decided this cycle: then
     * it stays so. */
    /* (The common step adds h to the time and takes t - time unchecked:
     * with h <= 2^900 and |time| <= 2^968 the time needs 2^67 steps to
     * reach 2^969, and below 2^970, t - time is at most DBL_MAX in
     * magnitude for any t: nothing overflows.) */
    if (instance->cycleTime == 0 && instance->prepared.plain && rl_steady_value(core->block.y) &&
        core->block.decided == RL_DECIDED_RAMP && core->block.periodBefore == h &&
        islessequal(h, 8.452712498170644e+270 /* 2^900 */) &&
        islessequal(fabs(core->time), 2.4948003869184e+291 /* 2^968 */)) {
        rl_hold_period(&core->block, h);
        const bool real = instance->prepared.config.real;
        instance->fastPeriodReal = real ? h : NAN;
        instance->fastPeriodLreal = real ? NAN : h;
        /* the general tolerance, RL_TIME_TOLERANCE * |time|, only grows
         * from here while time >= 0 (steps go forward): taken now, it is
         * never more than the general one later; before 0, exact times */
        instance->fastTolerance = core->time >= 0 ? RL_TIME_TOLERANCE * core->time : 0.0;
    } else {
        fmu_disarm(instance);
    }
    return fmu_report_status(instance);
}

/* The common path of an activation is the general one: it is one cycle,
 * at most as often as the PLC's OB runs. */
FmuStatus fmu_activate(FmuInstance *instance, const char *function, double activationTime) {
    FmuCore *core = &instance->core;
    if (!(isfinite(activationTime) && isgreater(activationTime, core->time))) {
        return fmu_error(instance, function,
                         "activationTime %.17g is not finite or not after the last activation (or the start) at %.17g",
                         activationTime, core->time);
    }
    if (instance->configDirty) {
        fmu_configure(instance);
        fmu_refuse_no_cycle(instance);
    }
    const double cycle = instance->cycleTime;
    if (cycle > 0) {
        if (instance->prepareDue || instance->prepared.period != cycle) {
            prepare(instance, cycle);
        }
        /* the cycle's time is the activation's: with the ticks at
         * startTime + n*cycleTime it is Co-Simulation's cycle n */
        rl_cycle(&core->block, &instance->prepared, core->values[instance->inputVr],
                 rl_sum(activationTime, -core->startTime));
        instance->outputsStale = FMU_STALE_ALL;
    } else if (instance->outputsStale == FMU_FRESH) {
        instance->outputsStale = FMU_STALE_TIME;
    }
    core->time = activationTime;
    return fmu_report_status(instance);
}
