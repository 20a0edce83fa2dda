/* PassThrough, FMI 2: the least a Co-Simulation FMU can do per step
 * (y = u). The functions it does not need are stubs (tests/fixtures/stubs.py). */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#ifndef FIXTURE_VARIABLES_H /* another fixture built from these sources names its own */
#define FIXTURE_VARIABLES_H "PassThrough_variables.h"
#endif
#include FIXTURE_VARIABLES_H

typedef struct {
    fmi2CallbackFunctions functions;
    double values[MODEL_VARIABLE_COUNT];
} Instance;

const char *fmi2GetTypesPlatform(void) {
    return fmi2TypesPlatform;
}
const char *fmi2GetVersion(void) {
    return fmi2Version;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)instanceName;
    (void)fmuResourceLocation;
    (void)visible;
    (void)loggingOn;
    if (fmuType != fmi2CoSimulation || !fmuGUID || strcmp(fmuGUID, MODEL_TOKEN) != 0 || !functions) return NULL;
    Instance *instance = functions->allocateMemory(1, sizeof *instance);
    if (instance) instance->functions = *functions;
    return instance;
}

void fmi2FreeInstance(fmi2Component c) {
    Instance *instance = c;
    if (instance) instance->functions.freeMemory(instance);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    (void)c;
    (void)loggingOn;
    (void)nCategories;
    (void)categories;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    ((Instance *)c)->values[VR_time] = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    (void)c;
    return fmi2OK;
}
fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    (void)c;
    return fmi2OK;
}
fmi2Status fmi2Terminate(fmi2Component c) {
    (void)c;
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    Instance *instance = c;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] != VR_u) return fmi2Error;
        instance->values[VR_u] = value[i];
    }
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    const Instance *instance = c;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= MODEL_VARIABLE_COUNT) return fmi2Error;
        value[i] = instance->values[vr[i]];
    }
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    Instance *instance = c;
#ifdef FIXTURE_FAULTS /* the Faulty fixture of the campaign tests: u = 13 crashes, u = 17 hangs, u = 19 is
                        killed (as from outside) once: when the file $FAULTY_ONCE names exists (it is removed) */
    if (instance->values[VR_u] == 13.0) raise(SIGSEGV);
    if (instance->values[VR_u] == 17.0)
        for (;;) {
        }
    if (instance->values[VR_u] == 19.0 && getenv("FAULTY_ONCE") && remove(getenv("FAULTY_ONCE")) == 0) raise(SIGKILL);
#endif
    instance->values[VR_y] = instance->values[VR_u];
    instance->values[VR_time] = currentCommunicationPoint + communicationStepSize;
    return fmi2OK;
}
