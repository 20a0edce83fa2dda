/* libFuzzer target: arbitrary bytes as a serialized FMU state, FMI 2 and 3.
 * A refusal must be an error; an accepted state must run (set state, step,
 * get) without a fault. Built with ASan and UBSan, so any memory or
 * undefined-behaviour fault stops the run. When the first byte is odd the
 * rest gets a valid CRC-32 trailer, so that the fuzzer also reaches the
 * checks behind the checksum (sizes, mode, values); its bit 1 makes the
 * instances Model Exchange ones (an accepted state runs an event update). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmi3Functions.h"
/* the model under test: RateLimiter unless the build names another */
#ifndef MODEL_VARIABLES
#define MODEL_VARIABLES RateLimiter_variables.h
#endif
#define QUOTED_(x) #x
#define QUOTED(x) QUOTED_(x)
#include QUOTED(MODEL_VARIABLES)

static void logger2(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...) {
    (void)e;
    (void)n;
    (void)s;
    (void)c;
    (void)m;
}

static void *allocate(size_t n, size_t size) {
    return calloc(n, size);
}

static const fmi2CallbackFunctions callbacks = { logger2, allocate, free, NULL, NULL };

static void run2(const uint8_t *data, size_t size, int modelExchange) {
    fmi2Component c = fmi2Instantiate("fuzz", modelExchange ? fmi2ModelExchange : fmi2CoSimulation, MODEL_TOKEN, "",
                                      &callbacks, fmi2False, fmi2False);
    fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0);
    fmi2EnterInitializationMode(c);
    fmi2ExitInitializationMode(c);
    fmi2DoStep(c, 0.0, 0.1, fmi2True);
    fmi2FMUstate state = NULL;
    fmi2EventInfo info;
    if (fmi2DeSerializeFMUstate(c, (const fmi2Byte *)data, size, &state) == fmi2OK) {
        if (fmi2SetFMUstate(c, state) == fmi2OK) {
            fmi2Real y;
            const fmi2ValueReference vr = fmuModel.outputVr;
            fmi2Real time = 0;
            fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &time);
            fmi2DoStep(c, time, 0.1, fmi2True);
            fmi2EnterEventMode(c);
            fmi2NewDiscreteStates(c, &info);
            fmi2GetReal(c, &vr, 1, &y);
        }
        fmi2FreeFMUstate(c, &state);
    }
    fmi2FreeInstance(c);
}

static void logger3(fmi3InstanceEnvironment e, fmi3Status s, fmi3String c, fmi3String m) {
    (void)e;
    (void)s;
    (void)c;
    (void)m;
}

static void run3(const uint8_t *data, size_t size, int modelExchange) {
    fmi3Instance c = modelExchange
                         ? fmi3InstantiateModelExchange("fuzz", MODEL_TOKEN, NULL, fmi3False, fmi3False, NULL, logger3)
                         : fmi3InstantiateCoSimulation("fuzz", MODEL_TOKEN, NULL, fmi3False, fmi3False, fmi3False,
                                                       fmi3False, NULL, 0, NULL, logger3, NULL);
    fmi3EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0);
    fmi3ExitInitializationMode(c);
    fmi3FMUState state = NULL;
    if (fmi3DeserializeFMUState(c, data, size, &state) == fmi3OK) {
        if (fmi3SetFMUState(c, state) == fmi3OK) {
            fmi3Boolean a, b, e;
            fmi3Float64 last, y;
            const fmi3ValueReference vr = fmuModel.outputVr;
            fmi3DoStep(c, 0.0, 0.1, fmi3True, &a, &b, &e, &last);
            fmi3Boolean n, v, defined;
            fmi3EnterEventMode(c);
            fmi3UpdateDiscreteStates(c, &a, &b, &n, &v, &defined, &last);
            fmi3GetFloat64(c, &vr, 1, &y, 1);
        }
        fmi3FreeFMUState(c, &state);
    }
    fmi3FreeInstance(c);
}

/* CRC-32 (IEEE), written here again rather than taken from the FMU */
static uint32_t crc32(const uint8_t *data, size_t size) {
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < size; i++) {
        crc ^= data[i];
        for (int k = 0; k < 8; k++) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size == 0) return 0;
    const int fixChecksum = data[0] & 1, modelExchange = data[0] & 2;
    data++;
    size--;
    if (fixChecksum && size >= 4) {
        uint8_t *copy = malloc(size);
        memcpy(copy, data, size);
        const uint32_t crc = crc32(copy, size - 4);
        for (int i = 0; i < 4; i++) copy[size - 4 + i] = (uint8_t)(crc >> (8 * i));
        run2(copy, size, modelExchange);
        run3(copy, size, modelExchange);
        free(copy);
    } else {
        run2(data, size, modelExchange);
        run3(data, size, modelExchange);
    }
    return 0;
}
