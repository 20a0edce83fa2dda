/* libFuzzer target: arbitrary bytes as a sequence of FMI calls on one
 * instance (FMI 2 or 3, Co-Simulation or Model Exchange, by the first
 * byte): each call an opcode byte and
 * its arguments (value reference byte, 8-byte double, ...). Whatever the
 * order, state or values, no call may fault; ASan and UBSan watch. */
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

typedef struct {
    const uint8_t *data;
    size_t size;
} Input;

static uint8_t byte(Input *in) {
    if (!in->size) return 0;
    in->size--;
    return *in->data++;
}

static double real(Input *in) {
    double x = 0;
    uint8_t b[8] = { 0 };
    for (int i = 0; i < 8; i++) b[i] = byte(in);
    memcpy(&x, b, sizeof x);
    return x;
}

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

static void run2(Input *in, int modelExchange) {
    fmi2Component c = fmi2Instantiate("fuzz", modelExchange ? fmi2ModelExchange : fmi2CoSimulation, MODEL_TOKEN, "",
                                      &callbacks, fmi2False, byte(in) & 1);
    fmi2FMUstate state = NULL;
    fmi2Real t = 0;
    while (in->size) {
        fmi2ValueReference vr = byte(in) % (MODEL_VARIABLE_COUNT + 2);
        fmi2Real r = 0;
        fmi2Integer i = 0;
        fmi2Boolean b = 0;
        fmi2Real none[1];
        fmi2EventInfo info;
        switch (byte(in) % 26) {
        case 0:
            r = real(in);
            fmi2SetReal(c, &vr, 1, &r);
            break;
        case 1:
            i = (fmi2Integer)(int8_t)byte(in);
            fmi2SetInteger(c, &vr, 1, &i);
            break;
        case 2:
            b = byte(in);
            fmi2SetBoolean(c, &vr, 1, &b);
            break;
        case 3: fmi2GetReal(c, &vr, 1, &r); break;
        case 4: fmi2GetInteger(c, &vr, 1, &i); break;
        case 5: fmi2GetBoolean(c, &vr, 1, &b); break;
        case 6: fmi2SetupExperiment(c, fmi2False, 0, real(in), byte(in) & 1, real(in)); break;
        case 7: fmi2EnterInitializationMode(c); break;
        case 8: fmi2ExitInitializationMode(c); break;
        case 9:
        case 10:
        case 11: {
            const double h = (byte(in) & 1) ? real(in) : 0.1 * (1 + byte(in) % 8);
            if (fmi2DoStep(c, (byte(in) & 7) ? t : real(in), h, fmi2True) <= fmi2Warning) t += h;
            break;
        }
        case 12: fmi2Terminate(c); break;
        case 13:
            fmi2Reset(c);
            t = 0;
            break;
        case 14: fmi2GetFMUstate(c, &state); break;
        case 15:
            if (state) fmi2SetFMUstate(c, state);
            break;
        case 16: fmi2FreeFMUstate(c, &state); break;
        case 17:
            if (state) {
                size_t n = 0;
                if (fmi2SerializedFMUstateSize(c, state, &n) == fmi2OK && n < 4096) {
                    fmi2Byte bytes[4096];
                    if (fmi2SerializeFMUstate(c, state, bytes, n) == fmi2OK) {
                        bytes[byte(in) % n] ^= (fmi2Byte)byte(in);
                        fmi2DeSerializeFMUstate(c, bytes, n - (byte(in) & 1), &state);
                    }
                }
                break;
            }
        case 18: {
            fmi2Real when;
            fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &when);
            break;
        }
        /* Model Exchange */
        case 19: fmi2EnterEventMode(c); break;
        case 20: fmi2NewDiscreteStates(c, (byte(in) & 7) ? &info : NULL); break;
        case 21: fmi2EnterContinuousTimeMode(c); break;
        case 22: {
            const double next = (byte(in) & 1) ? real(in) : t + 0.05 * (1 + byte(in) % 8);
            if (fmi2SetTime(c, next) <= fmi2Warning) t = next;
            break;
        }
        case 23: fmi2CompletedIntegratorStep(c, fmi2True, &b, &b); break;
        case 24:
            fmi2GetEventIndicators(c, none, byte(in) % 2);
            fmi2GetContinuousStates(c, none, byte(in) % 2);
            break;
        default:
            fmi2SetReal(c, &vr, 0, NULL);
            fmi2GetReal(c, NULL, 1, NULL);
            break;
        }
    }
    if (state) fmi2FreeFMUstate(c, &state);
    fmi2FreeInstance(c);
}

static void logger3(fmi3InstanceEnvironment e, fmi3Status s, fmi3String c, fmi3String m) {
    (void)e;
    (void)s;
    (void)c;
    (void)m;
}

static void run3(Input *in, int modelExchange) {
    fmi3Instance c = modelExchange ? fmi3InstantiateModelExchange("fuzz", MODEL_TOKEN, NULL, fmi3False, byte(in) & 1,
                                                                  NULL, logger3)
                                   : fmi3InstantiateCoSimulation("fuzz", MODEL_TOKEN, NULL, fmi3False, byte(in) & 1,
                                                                 fmi3False, fmi3False, NULL, 0, NULL, logger3, NULL);
    fmi3FMUState state = NULL;
    double t = 0;
    while (in->size) {
        fmi3ValueReference vr = byte(in) % (MODEL_VARIABLE_COUNT + 2);
        fmi3Float64 r = 0;
        fmi3Int32 i = 0;
        fmi3Int64 e = 0;
        fmi3Boolean b = 0, x1, x2, x3;
        fmi3Float64 none[1], next;
        fmi3Boolean x4, x5;
        size_t count;
        switch (byte(in) % 24) {
        case 0:
            r = real(in);
            fmi3SetFloat64(c, &vr, 1, &r, 1);
            break;
        case 1:
            e = (int8_t)byte(in);
            fmi3SetInt64(c, &vr, 1, &e, 1);
            break;
        case 2:
            b = byte(in) & 1;
            fmi3SetBoolean(c, &vr, 1, &b, 1);
            break;
        case 3: fmi3GetFloat64(c, &vr, 1, &r, byte(in) % 3); break;
        case 4: fmi3GetInt32(c, &vr, 1, &i, 1); break;
        case 5: fmi3GetBoolean(c, &vr, 1, &b, 1); break;
        case 6: fmi3EnterInitializationMode(c, fmi3False, 0, real(in), byte(in) & 1, real(in)); break;
        case 7: fmi3ExitInitializationMode(c); break;
        case 8:
        case 9:
        case 10: {
            const double h = (byte(in) & 1) ? real(in) : 0.1 * (1 + byte(in) % 8);
            fmi3Float64 last;
            if (fmi3DoStep(c, (byte(in) & 7) ? t : real(in), h, fmi3True, &x1, &x2, &x3, &last) <= fmi3Warning) t += h;
            break;
        }
        case 11: fmi3Terminate(c); break;
        case 12:
            fmi3Reset(c);
            t = 0;
            break;
        case 13: fmi3GetFMUState(c, &state); break;
        case 14:
            if (state) fmi3SetFMUState(c, state);
            break;
        case 15: fmi3FreeFMUState(c, &state); break;
        case 16:
            if (state) {
                size_t n = 0;
                if (fmi3SerializedFMUStateSize(c, state, &n) == fmi3OK && n < 4096) {
                    fmi3Byte bytes[4096];
                    if (fmi3SerializeFMUState(c, state, bytes, n) == fmi3OK) {
                        bytes[byte(in) % n] ^= byte(in);
                        fmi3DeserializeFMUState(c, bytes, n - (byte(in) & 1), &state);
                    }
                }
                break;
            }
        /* Model Exchange */
        case 17: fmi3EnterEventMode(c); break;
        case 18: fmi3UpdateDiscreteStates(c, &x1, &x2, &x3, &x4, (byte(in) & 7) ? &x5 : NULL, &next); break;
        case 19: fmi3EnterContinuousTimeMode(c); break;
        case 20: {
            const double when = (byte(in) & 1) ? real(in) : t + 0.05 * (1 + byte(in) % 8);
            if (fmi3SetTime(c, when) <= fmi3Warning) t = when;
            break;
        }
        case 21: fmi3CompletedIntegratorStep(c, fmi3True, &x1, &x2); break;
        case 22:
            fmi3GetEventIndicators(c, none, byte(in) % 2);
            fmi3GetNumberOfContinuousStates(c, &count);
            break;
        default:
            fmi3SetFloat64(c, &vr, 1, NULL, 1);
            fmi3DoStep(c, t, 0.1, fmi3True, NULL, NULL, NULL, NULL);
            break;
        }
    }
    if (state) fmi3FreeFMUState(c, &state);
    fmi3FreeInstance(c);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    Input in = { data, size };
    const uint8_t first = byte(&in);
    if (first & 1) run3(&in, first & 2);
    else run2(&in, first & 2);
    return 0;
}
