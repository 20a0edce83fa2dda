#include "fmu_core.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const log_category_names[3] = { "logStatusError", "logStatusWarning", "logEvents" };

#define SERIAL_MAGIC "RLFS"
#define SERIAL_VERSION 3u /* with the payload's size, checked too: the cycle before the last added 24 bytes */
/* magic, version, model hash, payload size; CRC-32 after the payload */
#define SERIAL_HEADER 16u
#define SERIAL_TRAILER 4u

const char *fmu_mode_name(int mode) {
    switch (mode) {
    case MODE_INSTANTIATED: return "Instantiated";
    case MODE_INITIALIZATION: return "Initialization Mode";
    case MODE_STEP: return "Step Mode";
    case MODE_TERMINATED: return "Terminated";
    case MODE_ERROR: return "Error (after a failed call)";
    case MODE_EVENT: return "Event Mode";
    case MODE_CONTINUOUS: return "Continuous-Time Mode";
    default: return "unknown";
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
    fmu_reset(instance);
}

void fmu_reset(FmuInstance *instance) {
    FmuCore *core = &instance->core;
    const ModelDefinition *model = instance->model;
    memset(core, 0, sizeof *core);
    for (unsigned i = 0; i < model->count; i++) {
        core->values[i] = model->variables[i].start;
    }
    core->mode = MODE_INSTANTIATED;
    fmu_leave_instant(instance); /* latched: values this FMU could have */
    memset(&instance->prepared, 0, sizeof instance->prepared);
    instance->prepared.period = NAN;
    /* the start values are the outputs until Initialization Mode */
    instance->outputsStale = FMU_FRESH;
    fmu_invalidate(instance);
}

/* configure() sets prepareDue and cycleTime, so that neither needs setting
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

FmuStatus fmu_set_debug_logging(FmuInstance *instance, const char *function, bool loggingOn,
                                size_t nCategories, const char *const categories[], int alwaysOn) {
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
            return fmu_error(instance, function, "unknown log category \"%s\"", categories[i] ? categories[i] : "(null)");
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
        return fmu_error(instance, function, "%s (value reference %u) is %s variable, which %s cannot access",
                         v->name, vr, type_name(v->type), function);
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
        instance->model->publish(&instance->core.block, &instance->prepared, instance->modelMode, instance->core.values);
    }
    instance->outputsStale = FMU_FRESH;
}

/* Kernel configuration from the current values; the cycle length and
 * limits are derived again before the next cycle. The outputs derived from
 * the last cycle are published first: they need its configuration. */
FMU_NOINLINE static void configure(FmuInstance *instance) {
    if (instance->outputsStale == FMU_STALE_ALL) {
        publish(instance, true);
    }
    instance->modelMode = instance->model->configure(instance->core.values, &instance->prepared.config);
    const double c = instance->prepared.config.cycleTime.value;
    instance->cycleTime = isgreater(c, 0) && isfinite(c) ? c : 0.0;
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

/* Model Exchange, after configure: there is no communication step to
 * stand in for the cycle, so without cycleTime there is no cycle. (Not in
 * configure: Co-Simulation's step does not pay for it.) */
static void refuse_no_cycle(FmuInstance *instance) {
    RlConfig *config = &instance->prepared.config;
    config->cycleRefused = config->cycleRefused || instance->cycleTime == 0;
}

/* Outputs at the start from the current parameters and inputs. */
static void initialize_block(FmuInstance *instance) {
    FmuCore *core = &instance->core;
    configure(instance);
    if (instance->modelExchange) {
        refuse_no_cycle(instance);
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

/* The current core, outputs published, for an FMU state. */
static void snapshot(FmuInstance *instance, FmuCore *state) {
    if (instance->outputsStale) fmu_refresh_outputs(instance);
    *state = instance->core;
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
FMU_NOINLINE static void log_status(FmuInstance *instance) {
    const RlPrepared *p = &instance->prepared;
    instance->core.reportedStatus = p->status;
    if (rl_status_is_error(p->status)) {
        const FmuVariable *cause = &instance->model->variables[p->statusSource];
        const bool noCycleInME = instance->modelExchange && p->status == RL_STATUS_NO_CYCLE;
        fmu_log(instance, FMU_WARNING, "status 16#%04X: %s (%s = %g); the output holds%s",
                (unsigned)p->status, rl_status_text(p->status), cause->name, instance->core.values[p->statusSource],
                noCycleInME ? ". Model Exchange runs the block at the ends of its cycles: set cycleTime to the PLC "
                              "cycle (the interval of the cyclic interrupt OB or task)" : "");
    } else {
        fmu_log(instance, FMU_OK, "status 16#%04X: %s", (unsigned)p->status, rl_status_text(p->status));
    }
}

static inline FmuStatus report_status(FmuInstance *instance) {
    if (instance->prepared.status != instance->core.reportedStatus) {
        log_status(instance);
    }
    return FMU_OK;
}

FmuStatus fmu_exit_initialization(FmuInstance *instance) {
    initialize_block(instance);
    /* Model Exchange: Event Mode at the start time, whose instant the
     * first cycle takes its values from */
    instance->core.mode = instance->modelExchange ? MODE_EVENT : MODE_STEP;
    instance->core.cycles = 0;
    instance->core.eventTime = instance->core.time;
    fmu_leave_instant(instance);
    return report_status(instance);
}

/* The end of cycle n, t0 + n*cycleTime, computed afresh from the whole
 * cycle count (no drift): the next time event of Model Exchange. */
static double cycle_end(const FmuCore *core, double cycle, uint64_t n) {
    return rl_sum(core->startTime, (double)n * cycle);
}

/* The number of whole cycles that end by the time end (a time within
 * RL_TIME_TOLERANCE of a cycle end counts as that end): the inverse of
 * cycle_end. */
static double cycles_ended_by(const FmuCore *core, double cycle, double end) {
    return floor(rl_quotient(rl_sum(end, -core->startTime), cycle) + RL_TIME_TOLERANCE);
}

/* Sub-cycling (cycleTime > 0): the cycles that end in (t, end], each end
 * t0 + n*cycleTime computed afresh from the whole cycle count n. */
/* Sets *ran when a cycle ran. */
FMU_NOINLINE static FmuStatus run_cycles(FmuInstance *instance, const char *function, double end, double h, double u,
                                         bool *ran) {
    FmuCore *core = &instance->core;
    const double cycle = instance->cycleTime;
    const double last = cycles_ended_by(core, cycle, end);
    const double pending = last - (double)core->cycles;
    if (!islessequal(pending, FMU_MAX_CYCLES_PER_STEP)) {
        return fmu_error(instance, function, "a step of %g s would run %g cycles of %g s; at most %g per step",
                         h, pending, cycle, FMU_MAX_CYCLES_PER_STEP);
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
        return fmu_error(instance, function, "currentCommunicationPoint %.17g is not the FMU's time %.17g", t, core->time);
    }
    const double end = rl_sum(t, h);
    if (isinf(end)) {
        return fmu_error(instance, function, "a step of %g s from %g would end past the largest time", h, t);
    }
    if (instance->configDirty) {
        configure(instance);
    }
    const double u = core->values[instance->model->inputVr];
    bool ran = true;
    if (instance->cycleTime > 0) {
        if (run_cycles(instance, function, end, h, u, &ran) != FMU_OK) return FMU_ERROR;
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
        islessequal(h, 8.452712498170644e+270 /* 2^900 */) && islessequal(fabs(core->time), 2.4948003869184e+291 /* 2^968 */)) {
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
    return report_status(instance);
}

/* ---- Model Exchange ------------------------------------------------------ */

static bool latched_slot(const FmuVariable *v) {
    return v->causality == FMU_INPUT || v->causality == FMU_PARAMETER;
}

/* Exchange the inputs and parameters of the values and the latched ones;
 * true if any differs from its counterpart (bit for bit: a NaN is the same
 * NaN). Done twice, it changes nothing. */
static bool swap_latched(FmuInstance *instance) {
    FmuCore *core = &instance->core;
    bool differ = false;
    for (unsigned i = 0; i < instance->model->count; i++) {
        if (latched_slot(&instance->model->variables[i])) {
            const double value = core->values[i];
            differ = differ || memcmp(&value, &core->latched[i], sizeof value) != 0;
            core->values[i] = core->latched[i];
            core->latched[i] = value;
        }
    }
    return differ;
}

void fmu_leave_instant(FmuInstance *instance) {
    memcpy(instance->core.latched, instance->core.values, sizeof instance->core.latched);
}

/* The cycles ended by now, run with the latched values: the values of now
 * set aside meanwhile, the configuration taken from the latched ones and
 * again from the current ones before the next cycle if they differ. */
static FmuStatus run_latched_cycles(FmuInstance *instance, const char *function) {
    FmuCore *core = &instance->core;
    const bool differ = swap_latched(instance);
    if (differ || instance->configDirty) {
        configure(instance);
        refuse_no_cycle(instance);
    }
    bool ran = false;
    FmuStatus status = FMU_OK;
    if (instance->cycleTime > 0) {
        const double since = rl_sum(core->time, -cycle_end(core, instance->cycleTime, core->cycles));
        status = run_cycles(instance, function, core->time, since, core->values[instance->inputVr], &ran);
    }
    if (ran) {
        instance->outputsStale = FMU_STALE_ALL;
    }
    swap_latched(instance);
    if (differ) {
        fmu_invalidate(instance);
    }
    return status;
}

void fmu_enter_event_mode(FmuInstance *instance) {
    instance->core.mode = MODE_EVENT;
    instance->core.eventTime = instance->core.time;
}

FmuStatus fmu_update_discrete_states(FmuInstance *instance, const char *function, bool *nextEventTimeDefined,
                                     double *nextEventTime) {
    FmuCore *core = &instance->core;
    if (run_latched_cycles(instance, function) != FMU_OK) {
        return FMU_ERROR;
    }
    *nextEventTimeDefined = instance->cycleTime > 0;
    *nextEventTime = *nextEventTimeDefined ? cycle_end(core, instance->cycleTime, core->cycles + 1) : 0.0;
    return report_status(instance);
}

void fmu_enter_continuous_time_mode(FmuInstance *instance) {
    fmu_leave_instant(instance);
    instance->core.mode = MODE_CONTINUOUS;
}

FmuStatus fmu_set_time(FmuInstance *instance, const char *function, double time) {
    FmuCore *core = &instance->core;
    if (!isfinite(time) || isless(time, core->eventTime)) {
        return fmu_error(instance, function, "time %.17g is not finite or before the last event at %.17g", time,
                         core->eventTime);
    }
    if (core->mode == MODE_EVENT && time != core->time) {
        /* a pure discrete-time FMU's next event instant (FMI 2.0.4,
         * section 3.2.3, fmi2SetTime in Event Mode): this one is left */
        fmu_leave_instant(instance);
        core->eventTime = time;
    }
    core->time = time;
    if (instance->outputsStale == FMU_FRESH) {
        instance->outputsStale = FMU_STALE_TIME;
    }
    return FMU_OK;
}

FmuStatus fmu_check_none(FmuInstance *instance, const char *function, const char *what, size_t n, const void *array) {
    if (n != 0) {
        return fmu_error(instance, function, "this FMU has no %s; n = %zu, not 0", what, n);
    }
    (void)array; /* none to read or write */
    return FMU_OK;
}

/* Make a restored core the current one. */
static void restore(FmuInstance *instance, const FmuCore *state) {
    instance->core = *state;
    /* the outputs are the state's (snapshot published them); one taken in
     * Initialization Mode initializes again on a get */
    instance->outputsStale = FMU_FRESH;
    fmu_invalidate(instance);
}

/* ---- serialization ---------------------------------------------------- */

static uint32_t crc32(const unsigned char *data, size_t size) {
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < size; i++) {
        crc ^= data[i];
        for (int k = 0; k < 8; k++) {
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
    }
    return ~crc;
}

static uint32_t model_hash(const ModelDefinition *model) {
    uint32_t hash = 2166136261u; /* FNV-1a */
    for (const char *c = model->token; *c; c++) {
        hash = (hash ^ (unsigned char)*c) * 16777619u;
    }
    return hash;
}

static unsigned char *put_u32(unsigned char *p, uint32_t v) {
    for (int i = 0; i < 4; i++) *p++ = (unsigned char)(v >> (8 * i));
    return p;
}

static unsigned char *put_u64(unsigned char *p, uint64_t v) {
    for (int i = 0; i < 8; i++) *p++ = (unsigned char)(v >> (8 * i));
    return p;
}

static unsigned char *put_f64(unsigned char *p, double v) {
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    return put_u64(p, bits);
}

static uint32_t get_u32(const unsigned char **p) {
    uint32_t v = 0;
    for (int i = 0; i < 4; i++) v |= (uint32_t)(*p)[i] << (8 * i);
    *p += 4;
    return v;
}

static uint64_t get_u64(const unsigned char **p) {
    uint64_t v = 0;
    for (int i = 0; i < 8; i++) v |= (uint64_t)(*p)[i] << (8 * i);
    *p += 8;
    return v;
}

static double get_f64(const unsigned char **p) {
    const uint64_t bits = get_u64(p);
    double v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

static size_t payload_size(const ModelDefinition *model) {
    return 4 + 8 * (size_t)model->count      /* values */
         + 8 + 8 + 8 + 1 + 8 + 8 + 8         /* block */
         + 8 + 8 + 8                         /* startTime, time, cycles */
         + 8 + 8 + 8                         /* block: the cycle before the last */
         + 8 * (size_t)model->count + 8      /* latched values, eventTime */
         + 4 + 4;                            /* mode, status */
}

static size_t serialized_size(const FmuInstance *instance) {
    return SERIAL_HEADER + payload_size(instance->model) + SERIAL_TRAILER;
}

static void serialize(const FmuInstance *instance, const FmuCore *s, unsigned char *out) {
    const ModelDefinition *model = instance->model;
    unsigned char *p = out;
    memcpy(p, SERIAL_MAGIC, 4);
    p += 4;
    p = put_u32(p, SERIAL_VERSION);
    p = put_u32(p, model_hash(model));
    p = put_u32(p, (uint32_t)payload_size(model));
    p = put_u32(p, model->count);
    for (unsigned i = 0; i < model->count; i++) p = put_f64(p, s->values[i]);
    p = put_f64(p, s->block.y);
    p = put_f64(p, s->block.uPrevious);
    p = put_f64(p, s->block.yPrevious);
    *p++ = s->block.decided;
    p = put_u64(p, s->block.runCycles);
    p = put_f64(p, s->block.runPeriod);
    p = put_f64(p, s->block.runBase);
    p = put_f64(p, s->startTime);
    p = put_f64(p, s->time);
    p = put_u64(p, s->cycles);
    p = put_f64(p, s->block.yBefore);
    p = put_f64(p, s->block.periodLast);
    p = put_f64(p, s->block.periodBefore);
    for (unsigned i = 0; i < model->count; i++) p = put_f64(p, s->latched[i]);
    p = put_f64(p, s->eventTime);
    p = put_u32(p, (uint32_t)s->mode);
    p = put_u32(p, (uint32_t)s->reportedStatus);
    put_u32(p, crc32(out, (size_t)(p - out)));
}

/* A mode of this instance's interface (an FMU state taken by an instance
 * of the other one is refused). */
static bool fmu_mode_possible(const FmuInstance *instance, int mode) {
    const int modes = MODE_INSTANTIATED | MODE_INITIALIZATION | MODE_TERMINATED | instance->errorMode |
                      (instance->modelExchange ? MODE_EVENT | MODE_CONTINUOUS : MODE_STEP);
    return mode > 0 && (mode & (mode - 1)) == 0 && (mode & modes) != 0; /* > 0: no mode - 1 overflow */
}

/* Cycle counts stay exact in a double (2^53). */
#define MAX_EXACT_CYCLES ((uint64_t)1 << 53)

/* A value of the variable's type and declared range (NaN only for an
 * unranged Real), as fmu_check_set would accept it. */
static bool value_possible(const FmuVariable *v, double value) {
    switch (v->type) {
    case FMU_REAL:
        return fmu_in_range(v, value);
    case FMU_BOOLEAN:
        return value == 0.0 || value == 1.0;
    default: /* Integer, Enumeration: an int32 in range */
        return value == floor(value) && isgreaterequal(value, -2147483648.0) && islessequal(value, 2147483647.0) &&
               isgreaterequal(value, v->min) && islessequal(value, v->max);
    }
}

static FmuStatus deserialize(FmuInstance *instance, const char *function, const unsigned char *in, size_t size,
                             FmuCore *out) {
    const ModelDefinition *model = instance->model;
    const size_t expected = serialized_size(instance);
    const unsigned char *p = in;

    if (!in) {
        return fmu_error(instance, function, "the serialized state is NULL");
    }
    if (size < SERIAL_HEADER || memcmp(in, SERIAL_MAGIC, 4) != 0) {
        return fmu_error(instance, function, "not a serialized state of this FMU (%zu bytes, no header)", size);
    }
    p += 4;
    const uint32_t version = get_u32(&p);
    if (version != SERIAL_VERSION) {
        return fmu_error(instance, function, "serialized state has format version %u; this FMU reads version %u",
                         (unsigned)version, SERIAL_VERSION);
    }
    if (get_u32(&p) != model_hash(model)) {
        return fmu_error(instance, function, "serialized state belongs to another model or version, not %s %s",
                         model->identifier, model->token);
    }
    if (size != expected || get_u32(&p) != payload_size(model)) {
        return fmu_error(instance, function, "serialized state has %zu bytes; expected %zu (truncated or padded)", size, expected);
    }
    const unsigned char *trailer = in + size - SERIAL_TRAILER;
    if (crc32(in, size - SERIAL_TRAILER) != get_u32(&trailer)) {
        return fmu_error(instance, function, "serialized state is corrupted (checksum mismatch)");
    }
    FmuCore s;
    memset(&s, 0, sizeof s);
    if (get_u32(&p) != model->count) {
        return fmu_error(instance, function, "serialized state has the wrong number of variables");
    }
    for (unsigned i = 0; i < model->count; i++) s.values[i] = get_f64(&p);
    s.block.y = get_f64(&p);
    s.block.uPrevious = get_f64(&p);
    s.block.yPrevious = get_f64(&p);
    s.block.decided = *p++;
    s.block.runCycles = get_u64(&p);
    s.block.runPeriod = get_f64(&p);
    s.block.runBase = get_f64(&p);
    s.startTime = get_f64(&p);
    s.time = get_f64(&p);
    s.cycles = get_u64(&p);
    s.block.yBefore = get_f64(&p);
    s.block.periodLast = get_f64(&p);
    s.block.periodBefore = get_f64(&p);
    for (unsigned i = 0; i < model->count; i++) s.latched[i] = get_f64(&p);
    s.eventTime = get_f64(&p);
    s.mode = (int)get_u32(&p);
    s.reportedStatus = (int)get_u32(&p);
    if (!fmu_mode_possible(instance, s.mode)) {
        return fmu_error(instance, function, "serialized state has an invalid mode %d", s.mode);
    }
    /* a checksum only proves the bytes arrived as written: every value must
     * also be one that this FMU could have made */
    for (unsigned i = 0; i < 2 * model->count; i++) {
        const FmuVariable *v = &model->variables[i % model->count];
        const double value = i < model->count ? s.values[i] : s.latched[i - model->count];
        if (!value_possible(v, value)) {
            return fmu_error(instance, function, "serialized state has an impossible value %g for %s", value, v->name);
        }
    }
    if (s.block.decided > RL_DECIDED_RAMP) {
        return fmu_error(instance, function, "serialized state has an invalid rule %u", (unsigned)s.block.decided);
    }
    /* runningTime is a sum of whole cycles: no NaN, infinity or negative */
    if (!isfinite(s.startTime) || !isfinite(s.time) || !isfinite(s.eventTime) || s.cycles > MAX_EXACT_CYCLES ||
        s.block.runCycles > MAX_EXACT_CYCLES || !(isgreaterequal(s.block.runPeriod, 0) && islessequal(s.block.runPeriod, DBL_MAX)) ||
        !(isgreaterequal(s.block.runBase, 0) && islessequal(s.block.runBase, DBL_MAX)) ||
        !(isgreaterequal(s.block.periodLast, 0) && islessequal(s.block.periodLast, DBL_MAX)) ||
        !(isgreaterequal(s.block.periodBefore, 0) && islessequal(s.block.periodBefore, DBL_MAX))) {
        return fmu_error(instance, function, "serialized state has an impossible time or cycle count");
    }
    /* Event Mode is an instant: entering it, SetTime in it and the end of
     * initialisation make the time that of the event (fmu_set_time relies on it) */
    if (s.mode == MODE_EVENT && s.time != s.eventTime) {
        return fmu_error(instance, function, "serialized state is in Event Mode at time %.17g, not at its event's %.17g",
                         s.time, s.eventTime);
    }
    *out = s;
    return FMU_OK;
}

/* ---- FMU states --------------------------------------------------------- */

#define STATE_TAG 0x524c5354u /* "RLST" */
typedef struct {
    uint32_t tag;
    FmuCore core;
} FmuState;

static FmuStatus check_state(FmuInstance *instance, const char *function, const void *state) {
    if (!state) {
        return fmu_error(instance, function, "the FMU state is NULL");
    }
    if (((const FmuState *)state)->tag != STATE_TAG) {
        return fmu_error(instance, function, "not an FMU state of this FMU");
    }
    return FMU_OK;
}

/* *state, checked, or a new one, tagged; NULL after an error */
static FmuState *state_to_fill(FmuInstance *instance, const char *function, void **state) {
    FmuState *target = (FmuState *)*state;
    if (target) {
        return check_state(instance, function, target) == FMU_OK ? target : NULL;
    }
    target = (FmuState *)instance->allocate(instance, sizeof *target);
    if (!target) {
        fmu_error(instance, function, "out of memory");
        return NULL;
    }
    target->tag = STATE_TAG;
    return target;
}

FmuStatus fmu_get_state(FmuInstance *instance, const char *function, void **state) {
    if (!state) {
        return fmu_error(instance, function, "the FMU state pointer is NULL");
    }
    FmuState *target = state_to_fill(instance, function, state);
    if (!target) {
        return FMU_ERROR;
    }
    snapshot(instance, &target->core);
    *state = target;
    return FMU_OK;
}

FmuStatus fmu_set_state(FmuInstance *instance, const char *function, const void *state) {
    if (check_state(instance, function, state) != FMU_OK) {
        return FMU_ERROR;
    }
    if (!fmu_mode_possible(instance, ((const FmuState *)state)->core.mode)) {
        return fmu_error(instance, function, "an FMU state of %s, which this %s instance cannot be in",
                         fmu_mode_name(((const FmuState *)state)->core.mode),
                         instance->modelExchange ? "Model Exchange" : "Co-Simulation");
    }
    restore(instance, &((const FmuState *)state)->core);
    return FMU_OK;
}

FmuStatus fmu_free_state(FmuInstance *instance, const char *function, void **state) {
    if (!state || !*state) {
        return FMU_OK;
    }
    if (check_state(instance, function, *state) != FMU_OK) {
        return FMU_ERROR;
    }
    ((FmuState *)*state)->tag = 0;
    instance->release(instance, *state);
    *state = NULL;
    return FMU_OK;
}

FmuStatus fmu_serialized_state_size(FmuInstance *instance, const char *function, const void *state, size_t *size) {
    if (check_state(instance, function, state) != FMU_OK) {
        return FMU_ERROR;
    }
    if (!size) {
        return fmu_error(instance, function, "the size pointer is NULL");
    }
    *size = serialized_size(instance);
    return FMU_OK;
}

FmuStatus fmu_serialize_state(FmuInstance *instance, const char *function, const void *state, unsigned char *out,
                              size_t size) {
    if (check_state(instance, function, state) != FMU_OK) {
        return FMU_ERROR;
    }
    if (!out) {
        return fmu_error(instance, function, "the byte array is NULL");
    }
    if (size < serialized_size(instance)) {
        return fmu_error(instance, function, "the byte array has %zu bytes; the state needs %zu", size,
                         serialized_size(instance));
    }
    serialize(instance, &((const FmuState *)state)->core, out);
    return FMU_OK;
}

FmuStatus fmu_deserialize_state(FmuInstance *instance, const char *function, const unsigned char *in, size_t size,
                                void **state) {
    FmuCore core;
    if (!state) {
        return fmu_error(instance, function, "the FMU state pointer is NULL");
    }
    if (deserialize(instance, function, in, size, &core) != FMU_OK) {
        return FMU_ERROR;
    }
    FmuState *target = state_to_fill(instance, function, state);
    if (!target) {
        return FMU_ERROR;
    }
    target->core = core;
    *state = target;
    return FMU_OK;
}
