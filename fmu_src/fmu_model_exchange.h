/* Model Exchange (docs/fmi.md, Model Exchange), for both FMI versions: no
 * continuous states, no event indicators; the cycle ends are time events,
 * and each cycle runs in Event Mode at its end with the values latched
 * when the instant before it was left (fmu_latch_values: Continuous-Time
 * Mode entered, or the time set anew in Event Mode). */
#ifndef FMU_MODEL_EXCHANGE_H
#define FMU_MODEL_EXCHANGE_H

#include "fmu_core.h"

/* Event Mode entered: an instant at the FMU's time. */
RL_LINKAGE void fmu_enter_event_mode(FmuInstance *instance);
/* The event update: the cycles that ended by the FMU's time, with the
 * latched values. *nextEventTime: the next cycle end; none (0, and
 * *nextEventTimeDefined false) without a valid cycle. */
RL_LINKAGE FmuStatus fmu_update_discrete_states(FmuInstance *instance, const char *function, bool *nextEventTimeDefined,
                                                double *nextEventTime);
/* Continuous-Time Mode entered: the instant is left. */
RL_LINKAGE void fmu_enter_continuous_time_mode(FmuInstance *instance);
/* fmi2SetTime / fmi3SetTime: a finite time, not before the last event. */
RL_LINKAGE FmuStatus fmu_set_time(FmuInstance *instance, const char *function, double time);
/* A call that passes arrays of continuous states or event indicators:
 * this FMU has none, so n must be 0. */
RL_LINKAGE FmuStatus fmu_check_none(FmuInstance *instance, const char *function, const char *what, size_t n,
                                    const void *array);

#endif
