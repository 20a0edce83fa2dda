/* The FMI 3 functions this FMU does not provide (configuration mode,
 * Co-Simulation's Event Mode, derivatives, variable dependencies): each
 * refuses with one message naming itself. Part of fmi3_glue.c's unit,
 * included at its end: it uses the glue's macros and the core. */
#ifndef FMI3_UNSUPPORTED_H
#define FMI3_UNSUPPORTED_H

/* ---- not provided --------------------------------------------------------- */

static fmi3Status unsupported(fmi3Instance instance, const char *function, const char *what) {
    if (!instance) return fmi3Error;
    return (fmi3Status)fmu_error((FmuInstance *)instance, function, "%s", what);
}

#define NO_DERIVATIVES "this FMU provides no derivatives or dependencies (see the model description)"
#define NO_CONFIGURATION "this FMU has no Configuration Mode (no structural parameters)"
#define NO_EVENT_CLOCKS "this FMU's Clock ticks in Scheduled Execution only: no clocked partition in Event Mode"

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference vr, size_t *n) {
    (void)vr;
    (void)n;
    return unsupported(instance, "fmi3GetNumberOfVariableDependencies", NO_DERIVATIVES);
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    (void)dependent;
    (void)elementIndicesOfDependent;
    (void)independents;
    (void)elementIndicesOfIndependents;
    (void)dependencyKinds;
    (void)nDependencies;
    return unsupported(instance, "fmi3GetVariableDependencies", NO_DERIVATIVES);
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetDirectionalDerivative", NO_DERIVATIVES);
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetAdjointDerivative", NO_DERIVATIVES);
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    return unsupported(instance, "fmi3EnterConfigurationMode", NO_CONFIGURATION);
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    return unsupported(instance, "fmi3ExitConfigurationMode", NO_CONFIGURATION);
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    return unsupported(instance, "fmi3EvaluateDiscreteStates", NO_EVENT_CLOCKS);
}

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    return unsupported(instance, "fmi3EnterStepMode", NO_CS_EVENT_MODE);
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                    const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues) {
    (void)vr;
    (void)nvr;
    (void)orders;
    (void)values;
    (void)nValues;
    return unsupported(instance, "fmi3GetOutputDerivatives", NO_DERIVATIVES);
}

#endif
