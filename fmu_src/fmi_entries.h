/* The entry points whose bodies are the same in FMI 2 and FMI 3, written
 * once: the end of the life cycle, the FMU-state functions and Model
 * Exchange's, each the mode check and a call into fmu_core. Included by each glue after its BEGIN(name),
 * BEGIN_ME(name) and CHECK; the macros take the version's prefix (fmi2,
 * fmi3), its types and its spelling of the names. */
#ifndef FMI_ENTRIES_H
#define FMI_ENTRIES_H

#include "fmu_core.h"

/* The end of initialization, termination and reset. */
#define LIFECYCLE_ENTRIES(P, INSTANCE)                                                                    \
    P##Status P##ExitInitializationMode(INSTANCE instance) {                                              \
        BEGIN(ExitInitializationMode);                                                                    \
        return (P##Status)fmu_exit_initialization(I);                                                     \
    }                                                                                                     \
    P##Status P##Terminate(INSTANCE instance) {                                                           \
        BEGIN(Terminate);                                                                                 \
        fmu_terminate(I);                                                                                 \
        return P##OK;                                                                                     \
    }                                                                                                     \
    P##Status P##Reset(INSTANCE instance) {                                                               \
        BEGIN(Reset);                                                                                     \
        fmu_reset(I);                                                                                     \
        return P##OK;                                                                                     \
    }

/* The FMU-state functions (fmu_core.h, FMU states); BYTE is the version's
 * fmiXByte, GET to DESERIALIZE its names without the prefix. */
#define FMU_STATE_ENTRIES(P, INSTANCE, STATE, BYTE, GET, SET, FREE, SIZE, SERIALIZE, DESERIALIZE)            \
    P##Status P##GET(INSTANCE instance, STATE *state) {                                                   \
        BEGIN(GET);                                                                                       \
        return (P##Status)fmu_get_state(I, FN, state);                                                    \
    }                                                                                                     \
    P##Status P##SET(INSTANCE instance, STATE state) {                                                    \
        BEGIN(SET);                                                                                       \
        return (P##Status)fmu_set_state(I, FN, state);                                                    \
    }                                                                                                     \
    P##Status P##FREE(INSTANCE instance, STATE *state) {                                                  \
        BEGIN(FREE);                                                                                      \
        return (P##Status)fmu_free_state(I, FN, state);                                                   \
    }                                                                                                     \
    P##Status P##SIZE(INSTANCE instance, STATE state, size_t *size) {                                     \
        BEGIN(SIZE);                                                                                      \
        return (P##Status)fmu_serialized_state_size(I, FN, state, size);                                  \
    }                                                                                                     \
    P##Status P##SERIALIZE(INSTANCE instance, STATE state, BYTE serialized[], size_t size) {              \
        BEGIN(SERIALIZE);                                                                                 \
        return (P##Status)fmu_serialize_state(I, FN, state, (unsigned char *)serialized, size);           \
    }                                                                                                     \
    P##Status P##DESERIALIZE(INSTANCE instance, const BYTE serialized[], size_t size, STATE *state) {     \
        BEGIN(DESERIALIZE);                                                                               \
        return (P##Status)fmu_deserialize_state(I, FN, (const unsigned char *)serialized, size, state);   \
    }

/* Model Exchange with no continuous states and no event indicators
 * (fmu_core.h, Model Exchange), but for the event update, whose outputs
 * differ between the versions; DERIVATIVES is the version's name of the
 * derivatives' getter. */
#define MODEL_EXCHANGE_ENTRIES(P, INSTANCE, REAL, BOOLEAN, DERIVATIVES)                                     \
    P##Status P##EnterEventMode(INSTANCE instance) {                                                      \
        BEGIN_ME(EnterEventMode);                                                                         \
        fmu_enter_event_mode(I);                                                                          \
        return P##OK;                                                                                     \
    }                                                                                                     \
    P##Status P##EnterContinuousTimeMode(INSTANCE instance) {                                             \
        BEGIN_ME(EnterContinuousTimeMode);                                                                \
        fmu_enter_continuous_time_mode(I);                                                                \
        return P##OK;                                                                                     \
    }                                                                                                     \
    P##Status P##CompletedIntegratorStep(INSTANCE instance, BOOLEAN noSetFMUStatePriorToCurrentPoint,     \
                                         BOOLEAN *enterEventMode, BOOLEAN *terminateSimulation) {         \
        (void)noSetFMUStatePriorToCurrentPoint;                                                           \
        BEGIN_ME(CompletedIntegratorStep);                                                                \
        if (!enterEventMode || !terminateSimulation) {                                                    \
            return (P##Status)fmu_error(I, FN, "an output argument pointer is NULL");                     \
        }                                                                                                 \
        *enterEventMode = P##False;                                                                       \
        *terminateSimulation = P##False;                                                                  \
        return P##OK;                                                                                     \
    }                                                                                                     \
    P##Status P##SetTime(INSTANCE instance, REAL time) {                                                  \
        BEGIN_ME(SetTime);                                                                                \
        return (P##Status)fmu_set_time(I, FN, time);                                                      \
    }                                                                                                     \
    NO_STATES_ENTRY(P, INSTANCE, SetContinuousStates, const REAL, "continuous states")                    \
    NO_STATES_ENTRY(P, INSTANCE, GetContinuousStates, REAL, "continuous states")                          \
    NO_STATES_ENTRY(P, INSTANCE, DERIVATIVES, REAL, "continuous states")                                  \
    NO_STATES_ENTRY(P, INSTANCE, GetNominalsOfContinuousStates, REAL, "continuous states")                \
    NO_STATES_ENTRY(P, INSTANCE, GetEventIndicators, REAL, "event indicators")

/* a function that passes an array of what this FMU has none of: n is 0 */
#define NO_STATES_ENTRY(P, INSTANCE, NAME, TYPE, WHAT)                                                    \
    P##Status P##NAME(INSTANCE instance, TYPE array[], size_t n) {                                        \
        BEGIN_ME(NAME);                                                                                   \
        return (P##Status)fmu_check_none(I, FN, WHAT, n, array);                                          \
    }

#endif
