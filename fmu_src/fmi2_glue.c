/* FMI 2.0 Co-Simulation and Model Exchange interfaces, shared by every
 * model. */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmi_entries.h"

/* Modes each function may be called in: FMI 2.0.4, section 4.2.4 (state
 * machine of a Co-Simulation slave) and section 3.2.3 (Model Exchange).
 * Step Mode stands for stepComplete, stepFailed and stepCanceled: this
 * slave never returns fmi2Pending, so there is no stepInProgress. Step
 * Mode is only ever a Co-Simulation instance's, Event Mode and
 * Continuous-Time Mode a Model Exchange instance's; the functions of one
 * interface alone also refuse an instance of the other (BEGIN_ONLY_AS).
 * Beyond the table: the sets of Event Mode are taken in Continuous-Time
 * Mode too, where the standard has only continuous-time inputs (condition
 * 5), as importers such as OMSimulator set every input at each step; the
 * next cycle uses the values the instant before it is left with
 * (fmu_latch_values), wherever they were set. */
#define INST MODE_INSTANTIATED
#define INIT MODE_INITIALIZATION
#define STEP MODE_STEP
#define TERM MODE_TERMINATED
#define ERR MODE_ERROR
#define EVENT MODE_EVENT
#define CONT MODE_CONTINUOUS
#define NO_MODE 0

#define ANY (INST | INIT | STEP | EVENT | CONT | TERM | ERR)
#define MODES_fmi2SetDebugLogging ANY
#define MODES_fmi2SetupExperiment (INST)
#define MODES_fmi2EnterInitializationMode (INST)
#define MODES_fmi2ExitInitializationMode (INIT)
#define MODES_fmi2Terminate (STEP | EVENT | CONT)
#define MODES_fmi2Reset ANY
#define MODES_fmi2GetReal (INIT | STEP | EVENT | CONT | TERM | ERR)
#define MODES_fmi2GetInteger MODES_fmi2GetReal
#define MODES_fmi2GetBoolean MODES_fmi2GetReal
#define MODES_fmi2GetString MODES_fmi2GetReal
#define MODES_fmi2SetReal (INST | INIT | STEP | EVENT | CONT)
#define MODES_fmi2SetInteger MODES_fmi2SetReal
#define MODES_fmi2SetBoolean MODES_fmi2SetReal
#define MODES_fmi2SetString MODES_fmi2SetReal
#define MODES_fmi2GetFMUstate ANY
#define MODES_fmi2SetFMUstate MODES_fmi2GetFMUstate
#define MODES_fmi2FreeFMUstate MODES_fmi2GetFMUstate
#define MODES_fmi2SerializedFMUstateSize MODES_fmi2GetFMUstate
#define MODES_fmi2SerializeFMUstate MODES_fmi2GetFMUstate
#define MODES_fmi2DeSerializeFMUstate MODES_fmi2GetFMUstate
/* Co-Simulation */
#define MODES_fmi2DoStep (STEP)
#define MODES_fmi2CancelStep NO_MODE
#define MODES_fmi2GetStatus (STEP | TERM)
#define MODES_fmi2GetRealStatus MODES_fmi2GetStatus
#define MODES_fmi2GetIntegerStatus MODES_fmi2GetStatus
#define MODES_fmi2GetBooleanStatus MODES_fmi2GetStatus
#define MODES_fmi2GetStringStatus MODES_fmi2GetStatus
/* Model Exchange */
#define MODES_fmi2EnterEventMode (EVENT | CONT)
#define MODES_fmi2NewDiscreteStates (EVENT)
#define MODES_fmi2EnterContinuousTimeMode (EVENT)
#define MODES_fmi2CompletedIntegratorStep (CONT)
#define MODES_fmi2SetTime (EVENT | CONT) /* Event Mode: a pure discrete-time FMU's next instant */
#define MODES_fmi2SetContinuousStates (CONT)
#define MODES_fmi2GetEventIndicators (INIT | EVENT | CONT | TERM | ERR)
#define MODES_fmi2GetContinuousStates MODES_fmi2GetEventIndicators
#define MODES_fmi2GetDerivatives MODES_fmi2GetEventIndicators
#define MODES_fmi2GetNominalsOfContinuousStates (INST | EVENT | CONT | TERM | ERR)

typedef struct {
    FmuInstance base; /* first: an fmi2Component is an FmuInstance */
    fmi2CallbackFunctions functions;
    const char *instanceName; /* a copy, for the logger */
} Fmi2Instance;

/* Errors and warnings are logged even with loggingOn = false: a failed call
 * must say why. */
#define ALWAYS_LOGGED (LOG_ERROR | LOG_WARNING)

/* The start of every entry point; name is its full name (fmi2DoStep), the modes it may
 * be called in MODES_<name>. The _AS forms are for macros (fmi_entries.h). */
#define BEGIN(name) BEGIN_AS(#name, MODES_##name)
#define BEGIN_AS(function, modes) \
    FmuInstance *I = (FmuInstance *)instance; \
    static const char FN[] = function; \
    if (!I) return fmi2Error; \
    if (!(I->core.mode & (modes))) return (fmi2Status)fmu_mode_error(I, FN)

/* a function of one interface: an instance of the other is refused */
#define BEGIN_ONLY_AS(function, modes, fmuType) \
    BEGIN_AS(function, modes); \
    if ((I->interfaceType == FMU_MODEL_EXCHANGE) != ((fmuType) == fmi2ModelExchange)) \
    return (fmi2Status)other_interface(I, FN)

/* a Model Exchange function (fmi_entries.h) */
#define BEGIN_ME(name) BEGIN_ME_AS(#name, MODES_##name)
#define BEGIN_ME_AS(function, modes) BEGIN_ONLY_AS(function, modes, fmi2ModelExchange)

#define CHECK(expression) \
    do { \
        const FmuStatus status_ = (expression); \
        if (status_ > FMU_WARNING) return (fmi2Status)status_; \
    } while (0)

FMU_COLD static FmuStatus other_interface(FmuInstance *I, const char *function) {
    return fmu_error(I, function, "a %s function, and this instance was instantiated for %s",
                     I->interfaceType == FMU_MODEL_EXCHANGE ? "Co-Simulation" : "Model Exchange",
                     fmu_interface_name(I->interfaceType));
}

static void log_to_importer(FmuInstance *instance, FmuStatus status, const char *category, const char *message) {
    const Fmi2Instance *g = (const Fmi2Instance *)instance;
    g->functions.logger(g->functions.componentEnvironment, g->instanceName, (fmi2Status)status, category, message);
}

/* FMU states live in the importer's memory */
static void *allocate_state(FmuInstance *instance, size_t size) {
    return ((Fmi2Instance *)instance)->functions.allocateMemory(1, size);
}

static void release_state(FmuInstance *instance, void *memory) {
    ((Fmi2Instance *)instance)->functions.freeMemory(memory);
}

const char *fmi2GetTypesPlatform(void) {
    return fmi2TypesPlatform;
}
const char *fmi2GetVersion(void) {
    return fmi2Version;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)fmuResourceLocation;
    (void)visible;
    if (!functions || !functions->allocateMemory || !functions->freeMemory) {
        return NULL; /* nothing to allocate with, nobody to tell */
    }
    const char *reason = NULL;
    if (!instanceName || !*instanceName) {
        reason = "instanceName is missing";
    } else if (fmuType != fmi2CoSimulation && fmuType != fmi2ModelExchange) {
        reason = "fmuType is neither fmi2ModelExchange nor fmi2CoSimulation";
    } else if (!fmuGUID || strcmp(fmuGUID, fmuModel.token) != 0) {
        reason = "the GUID does not match this FMU's model description";
    }
    if (reason) {
        if (functions->logger) {
            functions->logger(functions->componentEnvironment, instanceName ? instanceName : "?", fmi2Error,
                              "logStatusError", reason);
        }
        return NULL;
    }
    Fmi2Instance *g = (Fmi2Instance *)functions->allocateMemory(1, sizeof *g);
    char *name = (char *)functions->allocateMemory(strlen(instanceName) + 1, 1);
    if (!g || !name) {
        if (g) functions->freeMemory(g);
        if (name) functions->freeMemory(name);
        return NULL;
    }
    strcpy(name, instanceName);
    g->functions = *functions;
    g->instanceName = name;
    g->base.environment = functions->componentEnvironment;
    g->base.logFunction = functions->logger ? log_to_importer : NULL;
    g->base.logCategories = (loggingOn ? LOG_ALL : 0) | ALWAYS_LOGGED;
    g->base.errorMode = MODE_ERROR; /* FMI 2.0.4 section 2.1.3: only reads, reset or an FMU state lead on */
    g->base.interfaceType = fmuType == fmi2ModelExchange ? FMU_MODEL_EXCHANGE : FMU_CO_SIMULATION;
    g->base.allocate = allocate_state;
    g->base.release = release_state;
    fmu_init_instance(&g->base);
    return g;
}

void fmi2FreeInstance(fmi2Component instance) {
    Fmi2Instance *g = (Fmi2Instance *)instance;
    if (!g) return;
    fmu_free_instance(&g->base);
    const fmi2CallbackFreeMemory release = g->functions.freeMemory;
    release((void *)g->instanceName);
    release(g);
}

fmi2Status fmi2SetDebugLogging(fmi2Component instance, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    BEGIN(fmi2SetDebugLogging);
    return (fmi2Status)fmu_set_debug_logging(I, FN, loggingOn, nCategories, categories, ALWAYS_LOGGED);
}

fmi2Status fmi2SetupExperiment(fmi2Component instance, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    BEGIN(fmi2SetupExperiment);
    return (fmi2Status)fmu_setup_experiment(I, FN, startTime, stopTimeDefined, stopTime);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component instance) {
    BEGIN(fmi2EnterInitializationMode);
    return (fmi2Status)fmu_enter_initialization(I);
}

LIFECYCLE_ENTRIES(fmi2, fmi2Component, fmi2ExitInitializationMode, fmi2Terminate, fmi2Reset)

/* ---- variable access ---------------------------------------------------- */

#define AS_REAL(x) ((fmi2Real)(x))
#define AS_INTEGER(x) ((fmi2Integer)(x))
#define AS_BOOLEAN(x) ((x) != 0 ? fmi2True : fmi2False)
#define BOOLEAN_AS_REAL(x) ((x) != fmi2False ? 1.0 : 0.0)
#define INTEGER_TYPES (TYPE_BIT(FMU_INTEGER) | TYPE_BIT(FMU_ENUMERATION))

/* One value is the common call: straight-line code without a frame; any
 * other count goes through the loops (all checked before any is set). */
#define ACCESSORS(GET, SET, TYPE, TYPE_MASK, TO_FMI, FROM_FMI) \
    FMU_NOINLINE static fmi2Status GET##_array(FmuInstance *I, const char *FN, const fmi2ValueReference vr[], \
                                               size_t nvr, TYPE value[]) { \
        CHECK(fmu_check_array(I, FN, nvr, vr, value)); \
        for (size_t i = 0; i < nvr; i++) CHECK(fmu_check_get(I, FN, TYPE_MASK, vr[i])); \
        for (size_t i = 0; i < nvr; i++) value[i] = TO_FMI(fmu_get(I, vr[i])); \
        return fmi2OK; \
    } \
    FMU_NOINLINE static fmi2Status SET##_array(FmuInstance *I, const char *FN, const fmi2ValueReference vr[], \
                                               size_t nvr, const TYPE value[]) { \
        CHECK(fmu_check_array(I, FN, nvr, vr, value)); \
        for (size_t i = 0; i < nvr; i++) CHECK(fmu_check_set(I, FN, TYPE_MASK, vr[i], FROM_FMI(value[i]))); \
        for (size_t i = 0; i < nvr; i++) fmu_set(I, vr[i], FROM_FMI(value[i])); \
        return fmi2OK; \
    } \
    fmi2Status GET(fmi2Component instance, const fmi2ValueReference vr[], size_t nvr, TYPE value[]) { \
        BEGIN_AS(#GET, MODES_##GET); \
        double v_; \
        if (nvr != 1 || !vr || !value) return GET##_array(I, FN, vr, nvr, value); \
        if (!fmu_get_one(I, FN, TYPE_MASK, vr[0], &v_)) return fmi2Error; \
        value[0] = TO_FMI(v_); \
        return fmi2OK; \
    } \
    fmi2Status SET(fmi2Component instance, const fmi2ValueReference vr[], size_t nvr, const TYPE value[]) { \
        BEGIN_AS(#SET, MODES_##SET); \
        if (nvr != 1 || !vr || !value) return SET##_array(I, FN, vr, nvr, value); \
        return fmu_set_one(I, FN, TYPE_MASK, vr[0], FROM_FMI(value[0])) ? fmi2OK : fmi2Error; \
    }

ACCESSORS(fmi2GetReal, fmi2SetReal, fmi2Real, TYPE_BIT(FMU_REAL), AS_REAL, AS_REAL)
ACCESSORS(fmi2GetInteger, fmi2SetInteger, fmi2Integer, INTEGER_TYPES, AS_INTEGER, AS_REAL)
ACCESSORS(fmi2GetBoolean, fmi2SetBoolean, fmi2Boolean, TYPE_BIT(FMU_BOOLEAN), AS_BOOLEAN, BOOLEAN_AS_REAL)

fmi2Status fmi2GetString(fmi2Component instance, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    BEGIN(fmi2GetString);
    CHECK(fmu_check_array(I, FN, nvr, vr, value));
    for (size_t i = 0; i < nvr; i++) CHECK(fmu_check_get(I, FN, TYPE_BIT(FMU_UNSUPPORTED_TYPE), vr[i]));
    return fmi2OK;
}

fmi2Status fmi2SetString(fmi2Component instance, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    BEGIN(fmi2SetString);
    CHECK(fmu_check_array(I, FN, nvr, vr, value));
    for (size_t i = 0; i < nvr; i++) CHECK(fmu_check_set(I, FN, TYPE_BIT(FMU_UNSUPPORTED_TYPE), vr[i], 0.0));
    return fmi2OK;
}

/* ---- FMU states (fmu_state.c) --------------------------------------------- */

FMU_STATE_ENTRIES(fmi2, fmi2Component, fmi2FMUstate, fmi2Byte, fmi2GetFMUstate, fmi2SetFMUstate, fmi2FreeFMUstate,
                  fmi2SerializedFMUstateSize, fmi2SerializeFMUstate, fmi2DeSerializeFMUstate)

/* ---- Co-Simulation -------------------------------------------------------- */

fmi2Status fmi2DoStep(fmi2Component instance, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    BEGIN(fmi2DoStep);
    return (fmi2Status)fmu_do_step(I, FN, currentCommunicationPoint, communicationStepSize);
}

fmi2Status fmi2CancelStep(fmi2Component instance) {
    BEGIN(fmi2CancelStep);
    return fmi2Error; /* unreachable: no mode allows it */
}

/* The status getters (FMI 2.0.4, section 4.2.3): doStep never returns
 * fmi2Pending, so fmi2GetStatus, fmi2GetIntegerStatus and
 * fmi2GetStringStatus have nothing to tell; fmi2LastSuccessfulTime (Real)
 * is the FMU's time, fmi2Terminated (Boolean) is false. One body: kind
 * is the status kind the getter answers, NO_KIND for none. */
#define NO_KIND (-1)
#define STATUS_GETTER(NAME, TYPE, KIND, VALUE) \
    fmi2Status NAME(fmi2Component instance, const fmi2StatusKind s, TYPE *value) { \
        BEGIN_ONLY_AS(#NAME, MODES_##NAME, fmi2CoSimulation); \
        if ((KIND) == NO_KIND || (int)s != (KIND)) return fmi2Discard; \
        if (!value) return (fmi2Status)fmu_error(I, FN, "the value pointer is NULL"); \
        *value = VALUE; \
        return fmi2OK; \
    }

STATUS_GETTER(fmi2GetStatus, fmi2Status, NO_KIND, fmi2OK)
STATUS_GETTER(fmi2GetRealStatus, fmi2Real, fmi2LastSuccessfulTime, I->core.time)
STATUS_GETTER(fmi2GetIntegerStatus, fmi2Integer, NO_KIND, 0)
STATUS_GETTER(fmi2GetBooleanStatus, fmi2Boolean, fmi2Terminated, fmi2False)
STATUS_GETTER(fmi2GetStringStatus, fmi2String, NO_KIND, NULL)

/* ---- Model Exchange: no continuous states, no event indicators; the cycle
 * ends are time events (fmu_model_exchange.h) ---------------------------- */

MODEL_EXCHANGE_ENTRIES(fmi2, fmi2Component, fmi2Real, fmi2Boolean, fmi2EnterEventMode, fmi2EnterContinuousTimeMode,
                       fmi2CompletedIntegratorStep, fmi2SetTime, fmi2SetContinuousStates, fmi2GetContinuousStates,
                       fmi2GetDerivatives, fmi2GetNominalsOfContinuousStates, fmi2GetEventIndicators)

fmi2Status fmi2NewDiscreteStates(fmi2Component instance, fmi2EventInfo *eventInfo) {
    BEGIN_ME(fmi2NewDiscreteStates);
    if (!eventInfo) return (fmi2Status)fmu_error(I, FN, "the eventInfo pointer is NULL");
    bool nextEventTimeDefined;
    CHECK(fmu_update_discrete_states(I, FN, &nextEventTimeDefined, &eventInfo->nextEventTime));
    eventInfo->newDiscreteStatesNeeded = fmi2False;
    eventInfo->terminateSimulation = fmi2False;
    eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
    eventInfo->valuesOfContinuousStatesChanged = fmi2False;
    eventInfo->nextEventTimeDefined = nextEventTimeDefined;
    return fmi2OK;
}

/* ---- not provided: derivatives ------------------------------------------ */

static fmi2Status unsupported(fmi2Component instance, const char *function, const char *what) {
    if (!instance) return fmi2Error;
    return (fmi2Status)fmu_error((FmuInstance *)instance, function, "%s", what);
}

#define NO_DERIVATIVES "this FMU provides no derivatives (see the model description)"

fmi2Status fmi2GetDirectionalDerivative(fmi2Component instance, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    (void)vUnknown_ref;
    (void)nUnknown;
    (void)vKnown_ref;
    (void)nKnown;
    (void)dvKnown;
    (void)dvUnknown;
    return unsupported(instance, "fmi2GetDirectionalDerivative", NO_DERIVATIVES);
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component instance, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return unsupported(instance, "fmi2SetRealInputDerivatives", NO_DERIVATIVES);
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component instance, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return unsupported(instance, "fmi2GetRealOutputDerivatives", NO_DERIVATIVES);
}
