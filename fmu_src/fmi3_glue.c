/* FMI 3.0 Co-Simulation (no event mode), Model Exchange and Scheduled
 * Execution (one input Clock, the PLC's cyclic interrupt) interfaces,
 * shared by every model. */
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "fmi_entries.h"

/* Modes each function may be called in: FMI 3.0.2, section 2.3 (common
 * states), 3.2 (Model Exchange), 4.2 (Co-Simulation without Event Mode)
 * and 5.2 (Scheduled Execution). "If any function called in super state FMU State Settable
 * returns fmi3Error, the FMU enters state Terminated" (2.3): there is no
 * Error state, a failed call leaves the instance Terminated (errorMode),
 * where the values can be read and the FMU-state functions, reset and
 * free are allowed. Step Mode is only ever a Co-Simulation instance's,
 * Clock Activation Mode a Scheduled Execution instance's, Event Mode and
 * Continuous-Time Mode a Model Exchange instance's; the
 * functions of Model Exchange alone also refuse a Co-Simulation instance
 * (BEGIN_ME). Beyond the standard: the sets of Event Mode are taken in
 * Continuous-Time Mode too, where it has only continuous-time inputs, as
 * importers such as OMSimulator set every input at each step; the next
 * cycle uses the values the instant before it is left with
 * (fmu_latch_values), wherever they were set. */
#define INST MODE_INSTANTIATED
#define INIT MODE_INITIALIZATION
#define STEP MODE_STEP
#define TERM MODE_TERMINATED
#define EVENT MODE_EVENT
#define CONT MODE_CONTINUOUS
#define CLOCK MODE_CLOCK_ACTIVATION
/* the super state FMU State Settable: every state of this FMU (Scheduled
 * Execution's FMU-state functions are called between activations: this
 * FMU's one model partition runs within fmi3ActivateModelPartition) */
#define SETTABLE (INST | INIT | STEP | EVENT | CONT | CLOCK | TERM)
/* the super state Initialized */
#define INITIALIZED (STEP | EVENT | CONT | CLOCK | TERM)

#define MODES_fmi3SetDebugLogging SETTABLE
#define MODES_fmi3EnterInitializationMode (INST)
#define MODES_fmi3ExitInitializationMode (INIT)
#define MODES_fmi3Terminate (STEP | EVENT | CONT | CLOCK)
#define MODES_fmi3Reset SETTABLE
#define MODES_Get (INIT | STEP | EVENT | CONT | CLOCK | TERM)
#define MODES_Set (INST | INIT | STEP | EVENT | CONT | CLOCK)
#define MODES_fmi3GetFMUState SETTABLE
#define MODES_fmi3SetFMUState SETTABLE
#define MODES_fmi3FreeFMUState SETTABLE
#define MODES_fmi3SerializedFMUStateSize SETTABLE
#define MODES_fmi3SerializeFMUState SETTABLE
#define MODES_fmi3DeserializeFMUState SETTABLE
#define MODES_fmi3DoStep (STEP)
/* Scheduled Execution and its clock: the interval and shift of a fixed
 * periodic Clock without intervalDecimal are asked in Initialization Mode,
 * the interval again in Clock Activation Mode (2.2.9.3) */
#define MODES_fmi3ActivateModelPartition (CLOCK)
#define MODES_fmi3GetIntervalDecimal (INIT | CLOCK)
#define MODES_fmi3GetShiftDecimal (INIT)
/* Model Exchange */
#define MODES_fmi3EnterEventMode (CONT)
#define MODES_fmi3UpdateDiscreteStates (EVENT)
#define MODES_fmi3EnterContinuousTimeMode (EVENT)
#define MODES_fmi3CompletedIntegratorStep (CONT)
#define MODES_fmi3SetTime (CONT)
#define MODES_fmi3SetContinuousStates (CONT)
#define MODES_fmi3GetContinuousStateDerivatives (INIT | EVENT | CONT | TERM)
#define MODES_fmi3GetEventIndicators MODES_fmi3GetContinuousStateDerivatives
#define MODES_fmi3GetContinuousStates MODES_fmi3GetContinuousStateDerivatives
#define MODES_fmi3GetNominalsOfContinuousStates (INIT | INITIALIZED)
#define MODES_fmi3GetNumberOfEventIndicators (INST | EVENT | CONT)
#define MODES_fmi3GetNumberOfContinuousStates MODES_fmi3GetNumberOfEventIndicators
/* every fmi3Get<Type> and fmi3Set<Type> */
#define MODES_fmi3GetFloat32 MODES_Get
#define MODES_fmi3SetFloat32 MODES_Set
#define MODES_fmi3GetFloat64 MODES_Get
#define MODES_fmi3SetFloat64 MODES_Set
#define MODES_fmi3GetInt8 MODES_Get
#define MODES_fmi3SetInt8 MODES_Set
#define MODES_fmi3GetUInt8 MODES_Get
#define MODES_fmi3SetUInt8 MODES_Set
#define MODES_fmi3GetInt16 MODES_Get
#define MODES_fmi3SetInt16 MODES_Set
#define MODES_fmi3GetUInt16 MODES_Get
#define MODES_fmi3SetUInt16 MODES_Set
#define MODES_fmi3GetInt32 MODES_Get
#define MODES_fmi3SetInt32 MODES_Set
#define MODES_fmi3GetUInt32 MODES_Get
#define MODES_fmi3SetUInt32 MODES_Set
#define MODES_fmi3GetInt64 MODES_Get
#define MODES_fmi3SetInt64 MODES_Set
#define MODES_fmi3GetUInt64 MODES_Get
#define MODES_fmi3SetUInt64 MODES_Set
#define MODES_fmi3GetBoolean MODES_Get
#define MODES_fmi3SetBoolean MODES_Set
#define MODES_fmi3GetString MODES_Get
#define MODES_fmi3SetString MODES_Set
#define MODES_fmi3GetBinary MODES_Get
#define MODES_fmi3SetBinary MODES_Set

typedef struct {
    FmuInstance base; /* first: an fmi3Instance is an FmuInstance */
    fmi3LogMessageCallback logMessage;
    /* Scheduled Execution's critical sections (5.1.2), NULL otherwise or
     * when the importer does not preempt */
    fmi3LockPreemptionCallback lockPreemption;
    fmi3UnlockPreemptionCallback unlockPreemption;
} Fmi3Instance;

/* The start of every entry point; name is its full name (fmi3DoStep), the modes it may
 * be called in MODES_<name>. The _AS forms are for macros (fmi_entries.h). */
#define BEGIN(name) BEGIN_AS(#name, MODES_##name)
#define BEGIN_AS(function, modes) \
    FmuInstance *I = (FmuInstance *)instance; \
    static const char FN[] = function; \
    if (!I) return fmi3Error; \
    if (!(I->core.mode & (modes))) return (fmi3Status)fmu_mode_error(I, FN)

/* a Model Exchange function: an instance of another interface is refused */
#define BEGIN_ME(name) BEGIN_ME_AS(#name, MODES_##name)
#define BEGIN_ME_AS(function, modes) \
    BEGIN_AS(function, modes); \
    if (I->interfaceType != FMU_MODEL_EXCHANGE) return (fmi3Status)other_interface(I, FN, FMU_MODEL_EXCHANGE)

/* a Scheduled Execution function (the Clock's): an instance of another
 * interface is refused, as the Clock ticks in Scheduled Execution only */
#define BEGIN_SE(name) \
    BEGIN_AS(#name, MODES_##name); \
    if (I->interfaceType != FMU_SCHEDULED_EXECUTION) return (fmi3Status)other_interface(I, FN, FMU_SCHEDULED_EXECUTION)

#define CHECK(expression) \
    do { \
        const FmuStatus status_ = (expression); \
        if (status_ > FMU_WARNING) return (fmi3Status)status_; \
    } while (0)

#define NO_CS_EVENT_MODE "this FMU has no Event Mode in Co-Simulation (hasEventMode = false)"

/* A function of interface own called on an instance of another. */
FMU_COLD static FmuStatus other_interface(FmuInstance *I, const char *function, FmuInterface own) {
    return fmu_error(I, function, "a %s function, and this instance was instantiated for %s", fmu_interface_name(own),
                     fmu_interface_name(I->interfaceType));
}

/* Scheduled Execution's critical sections: the values and the block,
 * which an activation and the gets and sets of other tasks share. */
static void lock_preemption(FmuInstance *instance) {
    const Fmi3Instance *g = (const Fmi3Instance *)instance;
    if (g->lockPreemption) g->lockPreemption();
}

static void unlock_preemption(FmuInstance *instance) {
    const Fmi3Instance *g = (const Fmi3Instance *)instance;
    if (g->unlockPreemption) g->unlockPreemption();
}

static void log_to_importer(FmuInstance *instance, FmuStatus status, const char *category, const char *message) {
    const Fmi3Instance *g = (const Fmi3Instance *)instance;
    g->logMessage(instance->environment, (fmi3Status)status, category, message);
}

/* FMI 3 has no memory callbacks: FMU states use the C heap */
static void *allocate_state(FmuInstance *instance, size_t size) {
    (void)instance;
    return malloc(size);
}

static void release_state(FmuInstance *instance, void *memory) {
    (void)instance;
    free(memory);
}

const char *fmi3GetVersion(void) {
    return fmi3Version;
}

/* A new instance; NULL, said why, on the first problem: those of every
 * instance, then the interface's own (interfaceRefusal, if not NULL). */
static Fmi3Instance *instantiate(const char *interfaceRefusal, FmuInterface interfaceType, fmi3String instanceName,
                                 fmi3String instantiationToken, fmi3Boolean loggingOn,
                                 fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage) {
    const char *reason = interfaceRefusal;
    if (!instanceName || !*instanceName) {
        reason = "instanceName is missing";
    } else if (!instantiationToken || strcmp(instantiationToken, fmuModel.token) != 0) {
        reason = "the instantiationToken does not match this FMU's model description";
    }
    if (reason) {
        if (logMessage && loggingOn) logMessage(instanceEnvironment, fmi3Error, "logStatusError", reason);
        return NULL;
    }
    Fmi3Instance *g = (Fmi3Instance *)calloc(1, sizeof *g);
    if (!g) return NULL;
    g->logMessage = logMessage;
    g->base.environment = instanceEnvironment;
    g->base.logFunction = logMessage ? log_to_importer : NULL;
    g->base.logCategories = loggingOn ? LOG_ALL : 0;
    g->base.errorMode = MODE_TERMINATED;
    g->base.interfaceType = interfaceType;
    g->base.allocate = allocate_state;
    g->base.release = release_state;
    fmu_init_instance(&g->base);
    return g;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath;
    (void)visible;
    (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables;
    (void)intermediateUpdate;
    const char *reason = eventModeUsed                        ? NO_CS_EVENT_MODE
                         : nRequiredIntermediateVariables > 0 ? "this FMU provides no intermediate update"
                                                              : NULL;
    return instantiate(reason, FMU_CO_SIMULATION, instanceName, instantiationToken, loggingOn, instanceEnvironment,
                       logMessage);
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)resourcePath;
    (void)visible;
    return instantiate(NULL, FMU_MODEL_EXCHANGE, instanceName, instantiationToken, loggingOn, instanceEnvironment,
                       logMessage);
}

void fmi3FreeInstance(fmi3Instance instance) {
    if (instance) fmu_free_instance((FmuInstance *)instance);
    free(instance);
}

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    BEGIN(fmi3SetDebugLogging);
    return (fmi3Status)fmu_set_debug_logging(I, FN, loggingOn, nCategories, categories, 0);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    BEGIN(fmi3EnterInitializationMode);
    CHECK(fmu_setup_experiment(I, FN, startTime, stopTimeDefined, stopTime));
    return (fmi3Status)fmu_enter_initialization(I);
}

LIFECYCLE_ENTRIES(fmi3, fmi3Instance, fmi3ExitInitializationMode, fmi3Terminate, fmi3Reset)

/* ---- variable access ---------------------------------------------------- */

static FmuStatus check_arrays(FmuInstance *I, const char *function, const fmi3ValueReference vr[], size_t nvr,
                              const void *values, size_t nValues) {
    if (fmu_check_array(I, function, nvr, vr, values) != FMU_OK) return FMU_ERROR;
    if (nValues != nvr) {
        return fmu_error(I, function, "nValues = %zu, but the %zu variables are scalars", nValues, nvr);
    }
    return FMU_OK;
}

/* One value is the common call: straight-line code without a frame; any
 * other count goes through the loops (all checked before any is set).
 * Scheduled Execution's Clock Activation Mode takes the out-of-line path
 * (_preemptible): the call is a critical section there, so that neither it
 * nor an activation sees the other half done; Co-Simulation's and Model
 * Exchange's calls pay nothing for it. */
#define BEGIN_ACCESS(function, modes, PREEMPTIBLE) \
    FmuInstance *I = (FmuInstance *)instance; \
    static const char FN[] = function; \
    if (!I) return fmi3Error; \
    if (!(I->core.mode & (modes) & ~CLOCK)) return PREEMPTIBLE(I, FN, vr, nvr, values, nValues)

#define PREEMPTIBLE_ACCESS(NAME, ARRAY, MODES, CONST, TYPE) \
    FMU_NOINLINE static fmi3Status NAME(FmuInstance *I, const char *FN, const fmi3ValueReference vr[], size_t nvr, \
                                        CONST TYPE values[], size_t nValues) { \
        if (!(I->core.mode & (MODES))) return (fmi3Status)fmu_mode_error(I, FN); \
        lock_preemption(I); \
        const fmi3Status status = ARRAY(I, FN, vr, nvr, values, nValues); \
        unlock_preemption(I); \
        return status; \
    }

#define ACCESSORS(GET, SET, TYPE, TYPE_MASK, TO_FMI) \
    FMU_NOINLINE static fmi3Status GET##_array(FmuInstance *I, const char *FN, const fmi3ValueReference vr[], \
                                               size_t nvr, TYPE values[], size_t nValues) { \
        CHECK(check_arrays(I, FN, vr, nvr, values, nValues)); \
        for (size_t i = 0; i < nvr; i++) CHECK(fmu_check_get(I, FN, TYPE_MASK, vr[i])); \
        for (size_t i = 0; i < nvr; i++) values[i] = TO_FMI(fmu_get(I, vr[i])); \
        return fmi3OK; \
    } \
    FMU_NOINLINE static fmi3Status SET##_array(FmuInstance *I, const char *FN, const fmi3ValueReference vr[], \
                                               size_t nvr, const TYPE values[], size_t nValues) { \
        CHECK(check_arrays(I, FN, vr, nvr, values, nValues)); \
        for (size_t i = 0; i < nvr; i++) CHECK(fmu_check_set(I, FN, TYPE_MASK, vr[i], (double)values[i])); \
        for (size_t i = 0; i < nvr; i++) fmu_set(I, vr[i], (double)values[i]); \
        return fmi3OK; \
    } \
    PREEMPTIBLE_ACCESS(GET##_preemptible, GET##_array, MODES_##GET, , TYPE) \
    PREEMPTIBLE_ACCESS(SET##_preemptible, SET##_array, MODES_##SET, const, TYPE) \
    fmi3Status GET(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, TYPE values[], size_t nValues) { \
        BEGIN_ACCESS(#GET, MODES_##GET, GET##_preemptible); \
        double v_; \
        if (nvr != 1 || nValues != 1 || !vr || !values) return GET##_array(I, FN, vr, nvr, values, nValues); \
        if (!fmu_get_one(I, FN, TYPE_MASK, vr[0], &v_)) return fmi3Error; \
        values[0] = TO_FMI(v_); \
        return fmi3OK; \
    } \
    fmi3Status SET(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const TYPE values[], \
                   size_t nValues) { \
        BEGIN_ACCESS(#SET, MODES_##SET, SET##_preemptible); \
        if (nvr != 1 || nValues != 1 || !vr || !values) return SET##_array(I, FN, vr, nvr, values, nValues); \
        return fmu_set_one(I, FN, TYPE_MASK, vr[0], (double)values[0]) ? fmi3OK : fmi3Error; \
    }

#define AS_FLOAT64(x) (x)
#define AS_INT(x) (x)
#define AS_BOOLEAN(x) ((x) != 0)
#define NO_TYPE TYPE_BIT(FMU_UNSUPPORTED_TYPE)

ACCESSORS(fmi3GetFloat64, fmi3SetFloat64, fmi3Float64, TYPE_BIT(FMU_REAL), AS_FLOAT64)
ACCESSORS(fmi3GetInt32, fmi3SetInt32, fmi3Int32, TYPE_BIT(FMU_INTEGER), (fmi3Int32)AS_INT)
ACCESSORS(fmi3GetInt64, fmi3SetInt64, fmi3Int64, TYPE_BIT(FMU_ENUMERATION), (fmi3Int64)AS_INT)
ACCESSORS(fmi3GetBoolean, fmi3SetBoolean, fmi3Boolean, TYPE_BIT(FMU_BOOLEAN), AS_BOOLEAN)
/* no variables of these types: any value reference is refused */
ACCESSORS(fmi3GetFloat32, fmi3SetFloat32, fmi3Float32, NO_TYPE, (fmi3Float32)AS_INT)
ACCESSORS(fmi3GetInt8, fmi3SetInt8, fmi3Int8, NO_TYPE, (fmi3Int8)AS_INT)
ACCESSORS(fmi3GetUInt8, fmi3SetUInt8, fmi3UInt8, NO_TYPE, (fmi3UInt8)AS_INT)
ACCESSORS(fmi3GetInt16, fmi3SetInt16, fmi3Int16, NO_TYPE, (fmi3Int16)AS_INT)
ACCESSORS(fmi3GetUInt16, fmi3SetUInt16, fmi3UInt16, NO_TYPE, (fmi3UInt16)AS_INT)
ACCESSORS(fmi3GetUInt32, fmi3SetUInt32, fmi3UInt32, NO_TYPE, (fmi3UInt32)AS_INT)
ACCESSORS(fmi3GetUInt64, fmi3SetUInt64, fmi3UInt64, NO_TYPE, (fmi3UInt64)AS_INT)

fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3String values[],
                         size_t nValues) {
    BEGIN(fmi3GetString);
    CHECK(check_arrays(I, FN, vr, nvr, values, nValues));
    for (size_t i = 0; i < nvr; i++) CHECK(fmu_check_get(I, FN, NO_TYPE, vr[i]));
    return fmi3OK;
}

fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3String values[],
                         size_t nValues) {
    BEGIN(fmi3SetString);
    CHECK(check_arrays(I, FN, vr, nvr, values, nValues));
    for (size_t i = 0; i < nvr; i++) CHECK(fmu_check_set(I, FN, NO_TYPE, vr[i], 0.0));
    return fmi3OK;
}

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, size_t valueSizes[],
                         fmi3Binary values[], size_t nValues) {
    BEGIN(fmi3GetBinary);
    CHECK(check_arrays(I, FN, vr, nvr, values, nValues));
    if (nvr > 0 && !valueSizes) return (fmi3Status)fmu_error(I, FN, "the valueSizes array is NULL");
    for (size_t i = 0; i < nvr; i++) CHECK(fmu_check_get(I, FN, NO_TYPE, vr[i]));
    return fmi3OK;
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const size_t valueSizes[],
                         const fmi3Binary values[], size_t nValues) {
    BEGIN(fmi3SetBinary);
    CHECK(check_arrays(I, FN, vr, nvr, values, nValues));
    if (nvr > 0 && !valueSizes) return (fmi3Status)fmu_error(I, FN, "the valueSizes array is NULL");
    for (size_t i = 0; i < nvr; i++) CHECK(fmu_check_set(I, FN, NO_TYPE, vr[i], 0.0));
    return fmi3OK;
}

/* ---- FMU states (fmu_state.c) --------------------------------------------- */

FMU_STATE_ENTRIES(fmi3, fmi3Instance, fmi3FMUState, fmi3Byte, fmi3GetFMUState, fmi3SetFMUState, fmi3FreeFMUState,
                  fmi3SerializedFMUStateSize, fmi3SerializeFMUState, fmi3DeserializeFMUState)

/* ---- Co-Simulation -------------------------------------------------------- */

/* The step of both versions (fmu_do_step); its outputs: no events, no
 * early return. */
fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    (void)noSetFMUStatePriorToCurrentPoint;
    BEGIN(fmi3DoStep);
    if (!eventHandlingNeeded || !terminateSimulation || !earlyReturn || !lastSuccessfulTime) {
        return (fmi3Status)fmu_error(I, FN, "an output argument pointer is NULL");
    }
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    const FmuStatus status = fmu_do_step(I, FN, currentCommunicationPoint, communicationStepSize);
    *lastSuccessfulTime = I->core.time;
    return (fmi3Status)status;
}

/* ---- Model Exchange: no continuous states, no event indicators; the cycle
 * ends are time events (fmu_model_exchange.h) ---------------------------- */

MODEL_EXCHANGE_ENTRIES(fmi3, fmi3Instance, fmi3Float64, fmi3Boolean, fmi3EnterEventMode, fmi3EnterContinuousTimeMode,
                       fmi3CompletedIntegratorStep, fmi3SetTime, fmi3SetContinuousStates, fmi3GetContinuousStates,
                       fmi3GetContinuousStateDerivatives, fmi3GetNominalsOfContinuousStates, fmi3GetEventIndicators)

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    BEGIN_ME(fmi3UpdateDiscreteStates);
    if (!discreteStatesNeedUpdate || !terminateSimulation || !nominalsOfContinuousStatesChanged ||
        !valuesOfContinuousStatesChanged || !nextEventTimeDefined || !nextEventTime) {
        return (fmi3Status)fmu_error(I, FN, "an output argument pointer is NULL");
    }
    CHECK(fmu_update_discrete_states(I, FN, nextEventTimeDefined, nextEventTime));
    *discreteStatesNeedUpdate = fmi3False;
    *terminateSimulation = fmi3False;
    *nominalsOfContinuousStatesChanged = fmi3False;
    *valuesOfContinuousStatesChanged = fmi3False;
    return fmi3OK;
}

#define NUMBER_OF_NONE(NAME) \
    fmi3Status NAME(fmi3Instance instance, size_t *n) { \
        BEGIN_ME_AS(#NAME, MODES_##NAME); \
        if (!n) return (fmi3Status)fmu_error(I, FN, "the pointer is NULL"); \
        *n = 0; \
        return fmi3OK; \
    }

NUMBER_OF_NONE(fmi3GetNumberOfEventIndicators)
NUMBER_OF_NONE(fmi3GetNumberOfContinuousStates)

/* ---- Scheduled Execution: the PLC's cyclic interrupt as an input Clock ------
 * (docs/fmi.md, Scheduled Execution). One model partition, the block's
 * cycle, activated at each tick of the Clock (fmuModel.clockName), a fixed
 * periodic Clock whose interval and shift are cycleTime; the variables are
 * not clocked, so that Co-Simulation and Model Exchange keep them. */

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)resourcePath;
    (void)visible;
    (void)clockUpdate; /* no output or countdown Clock to announce */
    /* both or neither: an importer that does not preempt may give neither */
    const char *reason = !lockPreemption != !unlockPreemption
                             ? "lockPreemption and unlockPreemption must both be given, or neither"
                             : NULL;
    Fmi3Instance *g = instantiate(reason, FMU_SCHEDULED_EXECUTION, instanceName, instantiationToken, loggingOn,
                                  instanceEnvironment, logMessage);
    if (g) {
        g->lockPreemption = lockPreemption;
        g->unlockPreemption = unlockPreemption;
    }
    return g;
}

/* The Clock's value reference, else why not (a variable's, or none). */
static FmuStatus check_clock(FmuInstance *I, const char *function, fmi3ValueReference vr) {
    const ModelDefinition *model = I->model;
    if (vr == model->clockVr) return FMU_OK;
    if (vr < model->count) {
        return fmu_error(I, function, "%s (value reference %u) is not a Clock; the Clock is %s (value reference %u)",
                         model->variables[vr].name, vr, model->clockName, model->clockVr);
    }
    return fmu_error(I, function, "unknown Clock reference %u; the Clock is %s (value reference %u)", vr,
                     model->clockName, model->clockVr);
}

static FmuStatus check_clocks(FmuInstance *I, const char *function, const fmi3ValueReference vr[], size_t nvr,
                              const void *values) {
    if (fmu_check_array(I, function, nvr, vr, values) != FMU_OK) return FMU_ERROR;
    for (size_t i = 0; i < nvr; i++) {
        if (check_clock(I, function, vr[i]) != FMU_OK) return FMU_ERROR;
    }
    return FMU_OK;
}

/* The Clock's interval: cycleTime, which must be set (finite, > 0). */
static FmuStatus clock_interval(FmuInstance *I, const char *function, double *interval) {
    *interval = fmu_configured_cycle(I);
    if (*interval == 0) {
        return fmu_error(I, function,
                         "%s has no interval: cycleTime is not a PLC cycle (finite, > 0); set it to the interval of "
                         "the cyclic interrupt OB or task",
                         I->model->clockName);
    }
    return FMU_OK;
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    BEGIN_SE(fmi3ActivateModelPartition);
    CHECK(check_clock(I, FN, clockReference));
    lock_preemption(I);
    const FmuStatus status = fmu_activate(I, FN, activationTime);
    unlock_preemption(I);
    return (fmi3Status)status;
}

/* Initialization Mode: the interval changed if it is not the one reported
 * last (2.2.9.6); Clock Activation Mode: a fixed Clock's never changes. */
fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                  fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {
    BEGIN_SE(fmi3GetIntervalDecimal);
    CHECK(check_clocks(I, FN, vr, nvr, intervals));
    if (nvr > 0 && !qualifiers) return (fmi3Status)fmu_error(I, FN, "the qualifier array is NULL");
    if (nvr == 0) return fmi3OK;
    double interval;
    const bool preemptible = I->core.mode == CLOCK;
    if (preemptible) lock_preemption(I);
    const FmuStatus status = clock_interval(I, FN, &interval);
    if (preemptible) unlock_preemption(I);
    if (status != FMU_OK) return (fmi3Status)status;
    const bool changed = !preemptible && interval != I->reportedInterval;
    I->reportedInterval = interval;
    for (size_t i = 0; i < nvr; i++) {
        intervals[i] = interval;
        qualifiers[i] = changed ? fmi3IntervalChanged : fmi3IntervalUnchanged;
    }
    return fmi3OK;
}

/* The first tick one cycle after the start, as Co-Simulation's first step
 * and Model Exchange's first time event end the first cycle. */
fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 shifts[]) {
    BEGIN_SE(fmi3GetShiftDecimal);
    CHECK(check_clocks(I, FN, vr, nvr, shifts));
    if (nvr == 0) return fmi3OK;
    double interval;
    CHECK(clock_interval(I, FN, &interval));
    for (size_t i = 0; i < nvr; i++) shifts[i] = interval;
    return fmi3OK;
}

#define NO_FRACTION "the Clock's timing is decimal only (supportsFraction = false): use fmi3GetIntervalDecimal"
#define CLOCK_FOLLOWS_CYCLE \
    "the Clock's interval and shift are cycleTime's (a fixed periodic Clock without intervalDecimal): set cycleTime"

#define NOT_OUTPUT_CLOCK "the Clock is an input Clock; fmi3GetClock reads output Clocks, and this FMU has none"
#define SCHEDULED_ONLY \
    "the Clock ticks in Scheduled Execution only (fmi3ActivateModelPartition); in Co-Simulation the " \
    "communication step and in Model Exchange the time events run the cycles"

/* The Clock functions this Clock has no use for, each refused with why;
 * the value references first (a wrong one is the first mistake to name). */
static fmi3Status refuse_clock_call(fmi3Instance instance, const char *function, const fmi3ValueReference vr[],
                                    size_t nvr, const char *why) {
    if (!instance) return fmi3Error;
    FmuInstance *I = (FmuInstance *)instance;
    CHECK(check_clocks(I, function, vr, nvr, vr));
    return (fmi3Status)fmu_error(I, function, "%s", why);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                   fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[]) {
    (void)counters;
    (void)resolutions;
    (void)qualifiers;
    return refuse_clock_call(instance, "fmi3GetIntervalFraction", vr, nvr, NO_FRACTION);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 counters[],
                                fmi3UInt64 resolutions[]) {
    (void)counters;
    (void)resolutions;
    return refuse_clock_call(instance, "fmi3GetShiftFraction", vr, nvr, NO_FRACTION);
}

/* The Clock's setters, Interval and Shift, each Decimal and Fraction: its
 * timing is cycleTime's. Their values are not read. */
#define REFUSED_CLOCK_SETTERS(DECIMAL, FRACTION) \
    fmi3Status DECIMAL(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 values[]) { \
        (void)values; \
        return refuse_clock_call(instance, #DECIMAL, vr, nvr, CLOCK_FOLLOWS_CYCLE); \
    } \
    fmi3Status FRACTION(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3UInt64 counters[], \
                        const fmi3UInt64 resolutions[]) { \
        (void)counters; \
        (void)resolutions; \
        return refuse_clock_call(instance, #FRACTION, vr, nvr, CLOCK_FOLLOWS_CYCLE); \
    }
REFUSED_CLOCK_SETTERS(fmi3SetIntervalDecimal, fmi3SetIntervalFraction)
REFUSED_CLOCK_SETTERS(fmi3SetShiftDecimal, fmi3SetShiftFraction)

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[]) {
    (void)values;
    return refuse_clock_call(instance, "fmi3GetClock", vr, nvr, NOT_OUTPUT_CLOCK);
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock values[]) {
    (void)values;
    return refuse_clock_call(instance, "fmi3SetClock", vr, nvr, SCHEDULED_ONLY);
}

/* The FMI 3 functions this FMU does not provide: one file of their own. */
#include "fmi3_unsupported.h"
