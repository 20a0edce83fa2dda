/* PassThrough, FMI 3: the least a Co-Simulation FMU can do per step
 * (y = u). The functions it does not need are stubs (tests/fixtures/stubs.py). */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#ifndef FIXTURE_VARIABLES_H /* another fixture built from these sources names its own */
#define FIXTURE_VARIABLES_H "PassThrough_variables.h"
#endif
#include FIXTURE_VARIABLES_H

typedef struct {
    double values[MODEL_VARIABLE_COUNT];
} Instance;

const char *fmi3GetVersion(void) {
    return fmi3Version;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)instanceName;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    (void)eventModeUsed;
    (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables;
    (void)instanceEnvironment;
    (void)logMessage;
    (void)intermediateUpdate;
    if (!instantiationToken || strcmp(instantiationToken, MODEL_TOKEN) != 0) return NULL;
    return calloc(1, sizeof(Instance));
}

void fmi3FreeInstance(fmi3Instance instance) {
    free(instance);
}

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    (void)instance;
    (void)loggingOn;
    (void)nCategories;
    (void)categories;
    return fmi3OK;
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    ((Instance *)instance)->values[VR_time] = startTime;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    (void)instance;
    return fmi3OK;
}
fmi3Status fmi3Terminate(fmi3Instance instance) {
    (void)instance;
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 values[],
                          size_t nValues) {
    (void)nValues;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] != VR_u) return fmi3Error;
        ((Instance *)instance)->values[VR_u] = values[i];
    }
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 values[],
                          size_t nValues) {
    (void)nValues;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= MODEL_VARIABLE_COUNT) return fmi3Error;
        values[i] = ((const Instance *)instance)->values[vr[i]];
    }
    return fmi3OK;
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    (void)noSetFMUStatePriorToCurrentPoint;
    Instance *self = instance;
#ifdef FIXTURE_FAULTS /* the Faulty fixture of the campaign tests: u = 13 crashes, u = 17 hangs, u = 19 is
                        killed (as from outside) once: when the file $FAULTY_ONCE names exists (it is removed) */
    if (self->values[VR_u] == 13.0) raise(SIGSEGV);
    if (self->values[VR_u] == 17.0)
        for (;;) {
        }
    if (self->values[VR_u] == 19.0 && getenv("FAULTY_ONCE") && remove(getenv("FAULTY_ONCE")) == 0) raise(SIGKILL);
#endif
    self->values[VR_y] = self->values[VR_u];
    self->values[VR_time] = currentCommunicationPoint + communicationStepSize;
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = self->values[VR_time];
    return fmi3OK;
}
