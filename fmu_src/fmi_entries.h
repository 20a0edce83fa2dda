/* The entry points whose bodies are the same in FMI 2 and FMI 3, written
 * once: the end of the life cycle, the FMU-state functions and Model
 * Exchange's, each the mode check and a call into the core. Included by
 * each glue, which defines BEGIN_AS(function, modes) and BEGIN_ME_AS; the
 * macros take the version's prefix (fmi2, fmi3), its types and
 * the full names of the functions they define (fmi2Reset, ...), so that
 * each name appears where its function is defined. A name is stringized
 * and pasted here (#NAME, MODES_##NAME), before FMI*_FUNCTION_PREFIX
 * expands it. */
#ifndef FMI_ENTRIES_H
#define FMI_ENTRIES_H

#include "fmu_core.h"
#include "fmu_model_exchange.h"
#include "fmu_state.h"

/* The end of initialization, termination and reset. */
#define LIFECYCLE_ENTRIES(P, INSTANCE, EXIT_INITIALIZATION_MODE, TERMINATE, RESET) \
    P##Status EXIT_INITIALIZATION_MODE(INSTANCE instance) { \
        BEGIN_AS(#EXIT_INITIALIZATION_MODE, MODES_##EXIT_INITIALIZATION_MODE); \
        return (P##Status)fmu_exit_initialization(I); \
    } \
    P##Status TERMINATE(INSTANCE instance) { \
        BEGIN_AS(#TERMINATE, MODES_##TERMINATE); \
        fmu_terminate(I); \
        return P##OK; \
    } \
    P##Status RESET(INSTANCE instance) { \
        BEGIN_AS(#RESET, MODES_##RESET); \
        fmu_reset(I); \
        return P##OK; \
    }

/* The FMU-state functions (fmu_state.h); BYTE is the version's fmiXByte. */
#define FMU_STATE_ENTRIES(P, INSTANCE, STATE, BYTE, GET, SET, FREE, SIZE, SERIALIZE, DESERIALIZE) \
    P##Status GET(INSTANCE instance, STATE *state) { \
        BEGIN_AS(#GET, MODES_##GET); \
        return (P##Status)fmu_get_state(I, FN, state); \
    } \
    P##Status SET(INSTANCE instance, STATE state) { \
        BEGIN_AS(#SET, MODES_##SET); \
        return (P##Status)fmu_set_state(I, FN, state); \
    } \
    P##Status FREE(INSTANCE instance, STATE *state) { \
        BEGIN_AS(#FREE, MODES_##FREE); \
        return (P##Status)fmu_free_state(I, FN, state); \
    } \
    P##Status SIZE(INSTANCE instance, STATE state, size_t *size) { \
        BEGIN_AS(#SIZE, MODES_##SIZE); \
        return (P##Status)fmu_serialized_state_size(I, FN, state, size); \
    } \
    P##Status SERIALIZE(INSTANCE instance, STATE state, BYTE serialized[], size_t size) { \
        BEGIN_AS(#SERIALIZE, MODES_##SERIALIZE); \
        return (P##Status)fmu_serialize_state(I, FN, state, (unsigned char *)serialized, size); \
    } \
    P##Status DESERIALIZE(INSTANCE instance, const BYTE serialized[], size_t size, STATE *state) { \
        BEGIN_AS(#DESERIALIZE, MODES_##DESERIALIZE); \
        return (P##Status)fmu_deserialize_state(I, FN, (const unsigned char *)serialized, size, state); \
    }

/* Model Exchange with no continuous states and no event indicators
 * (fmu_model_exchange.h), but for the event update, whose outputs differ
 * between the versions; DERIVATIVES is the version's derivatives' getter. */
#define MODEL_EXCHANGE_ENTRIES(P, INSTANCE, REAL, BOOLEAN, ENTER_EVENT_MODE, ENTER_CONTINUOUS_TIME_MODE, \
                               COMPLETED_INTEGRATOR_STEP, SET_TIME, SET_CONTINUOUS_STATES, GET_CONTINUOUS_STATES, \
                               DERIVATIVES, GET_NOMINALS, GET_EVENT_INDICATORS) \
    P##Status ENTER_EVENT_MODE(INSTANCE instance) { \
        BEGIN_ME_AS(#ENTER_EVENT_MODE, MODES_##ENTER_EVENT_MODE); \
        fmu_enter_event_mode(I); \
        return P##OK; \
    } \
    P##Status ENTER_CONTINUOUS_TIME_MODE(INSTANCE instance) { \
        BEGIN_ME_AS(#ENTER_CONTINUOUS_TIME_MODE, MODES_##ENTER_CONTINUOUS_TIME_MODE); \
        fmu_enter_continuous_time_mode(I); \
        return P##OK; \
    } \
    P##Status COMPLETED_INTEGRATOR_STEP(INSTANCE instance, BOOLEAN noSetFMUStatePriorToCurrentPoint, \
                                        BOOLEAN *enterEventMode, BOOLEAN *terminateSimulation) { \
        (void)noSetFMUStatePriorToCurrentPoint; \
        BEGIN_ME_AS(#COMPLETED_INTEGRATOR_STEP, MODES_##COMPLETED_INTEGRATOR_STEP); \
        if (!enterEventMode || !terminateSimulation) { \
            return (P##Status)fmu_error(I, FN, "an output argument pointer is NULL"); \
        } \
        *enterEventMode = P##False; \
        *terminateSimulation = P##False; \
        return P##OK; \
    } \
    P##Status SET_TIME(INSTANCE instance, REAL time) { \
        BEGIN_ME_AS(#SET_TIME, MODES_##SET_TIME); \
        return (P##Status)fmu_set_time(I, FN, time); \
    } \
    NO_STATES_ENTRY(P, INSTANCE, SET_CONTINUOUS_STATES, #SET_CONTINUOUS_STATES, MODES_##SET_CONTINUOUS_STATES, \
                    const REAL, "continuous states") \
    NO_STATES_ENTRY(P, INSTANCE, GET_CONTINUOUS_STATES, #GET_CONTINUOUS_STATES, MODES_##GET_CONTINUOUS_STATES, REAL, \
                    "continuous states") \
    NO_STATES_ENTRY(P, INSTANCE, DERIVATIVES, #DERIVATIVES, MODES_##DERIVATIVES, REAL, "continuous states") \
    NO_STATES_ENTRY(P, INSTANCE, GET_NOMINALS, #GET_NOMINALS, MODES_##GET_NOMINALS, REAL, "continuous states") \
    NO_STATES_ENTRY(P, INSTANCE, GET_EVENT_INDICATORS, #GET_EVENT_INDICATORS, MODES_##GET_EVENT_INDICATORS, REAL, \
                    "event indicators")

/* a function that passes an array of what this FMU has none of: n is 0 */
#define NO_STATES_ENTRY(P, INSTANCE, NAME, FUNCTION, MODES, TYPE, WHAT) \
    P##Status NAME(INSTANCE instance, TYPE array[], size_t n) { \
        BEGIN_ME_AS(FUNCTION, MODES); \
        return (P##Status)fmu_check_none(I, FN, WHAT, n, array); \
    }

#endif
