#include "fmu_model_exchange.h"

#include <math.h>
#include <string.h>

/* The end of cycle n, t0 + n*cycleTime, computed afresh from the whole
 * cycle count (no drift): the next time event. */
static double cycle_end(const FmuCore *core, double cycle, uint64_t n) {
    return rl_sum(core->startTime, (double)n * cycle);
}

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

/* The cycles ended by now, run with the latched values: the values of now
 * set aside meanwhile, the configuration taken from the latched ones and
 * again from the current ones before the next cycle if they differ. */
static FmuStatus run_latched_cycles(FmuInstance *instance, const char *function) {
    FmuCore *core = &instance->core;
    const bool differ = swap_latched(instance);
    if (differ || instance->configDirty) {
        fmu_configure(instance);
        fmu_refuse_no_cycle(instance);
    }
    bool ran = false;
    FmuStatus status = FMU_OK;
    if (instance->cycleTime > 0) {
        const double since = rl_sum(core->time, -cycle_end(core, instance->cycleTime, core->cycles));
        status = fmu_run_cycles(instance, function, core->time, since, core->values[instance->inputVr], &ran);
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
    return fmu_report_status(instance);
}

void fmu_enter_continuous_time_mode(FmuInstance *instance) {
    fmu_latch_values(instance); /* the instant is left */
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
        fmu_latch_values(instance); /* the instant is left */
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
