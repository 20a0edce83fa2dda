/* An FMI 3 co-simulation binary driven by a script on standard input, the
 * outputs printed bit for bit: the same script gives the same text on every
 * platform whose binary computes the same numbers (the aarch64 build runs
 * under qemu-user, the Windows build under wine).
 *
 *   run_trace <binary.so> <instantiationToken> < script
 *
 * Script lines:  set <F|I|L|B> <vr> <value>   (Float64 as C99 %a, Int32,
 *                                               Int64 (enumerations), Boolean 0/1)
 *                init <startTime>
 *                step <t> <h>                  (C99 %a)
 *                get <F|I|B> <vr>              prints the value (Float64 as %a)
 *                save <file>                   the FMU state, serialized, into file
 *                load <file>                   the FMU state of file, deserialized and set
 * Exit 1 on any status above Warning, naming the line. */
#include <stdio.h>

#include "fmi3FunctionTypes.h"
#include "fmu_library.h"

static void log_message(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    (void)status;
    (void)category;
    (void)message;
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: run_trace <binary.so> <instantiationToken> < script\n");
        return 2;
    }
    if (!open_library(argv[1])) return 2;
    fmi3InstantiateCoSimulationTYPE *instantiate = (fmi3InstantiateCoSimulationTYPE *)function("fmi3InstantiateCoSimulation");
    fmi3EnterInitializationModeTYPE *enter = (fmi3EnterInitializationModeTYPE *)function("fmi3EnterInitializationMode");
    fmi3ExitInitializationModeTYPE *leave = (fmi3ExitInitializationModeTYPE *)function("fmi3ExitInitializationMode");
    fmi3DoStepTYPE *do_step = (fmi3DoStepTYPE *)function("fmi3DoStep");
    fmi3SetFloat64TYPE *set_float = (fmi3SetFloat64TYPE *)function("fmi3SetFloat64");
    fmi3SetInt32TYPE *set_int = (fmi3SetInt32TYPE *)function("fmi3SetInt32");
    fmi3SetInt64TYPE *set_long = (fmi3SetInt64TYPE *)function("fmi3SetInt64");
    fmi3SetBooleanTYPE *set_bool = (fmi3SetBooleanTYPE *)function("fmi3SetBoolean");
    fmi3GetFloat64TYPE *get_float = (fmi3GetFloat64TYPE *)function("fmi3GetFloat64");
    fmi3GetInt32TYPE *get_int = (fmi3GetInt32TYPE *)function("fmi3GetInt32");
    fmi3GetBooleanTYPE *get_bool = (fmi3GetBooleanTYPE *)function("fmi3GetBoolean");
    fmi3FreeInstanceTYPE *free_instance = (fmi3FreeInstanceTYPE *)function("fmi3FreeInstance");
    fmi3GetFMUStateTYPE *get_state = (fmi3GetFMUStateTYPE *)function("fmi3GetFMUState");
    fmi3SetFMUStateTYPE *set_state = (fmi3SetFMUStateTYPE *)function("fmi3SetFMUState");
    fmi3FreeFMUStateTYPE *free_state = (fmi3FreeFMUStateTYPE *)function("fmi3FreeFMUState");
    fmi3SerializedFMUStateSizeTYPE *state_size = (fmi3SerializedFMUStateSizeTYPE *)function("fmi3SerializedFMUStateSize");
    fmi3SerializeFMUStateTYPE *serialize = (fmi3SerializeFMUStateTYPE *)function("fmi3SerializeFMUState");
    fmi3DeserializeFMUStateTYPE *deserialize = (fmi3DeserializeFMUStateTYPE *)function("fmi3DeserializeFMUState");

    fmi3Instance c = instantiate("trace", argv[2], NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, NULL,
                                 log_message, NULL);
    if (!c) {
        fprintf(stderr, "instantiation failed\n");
        return 1;
    }
    char line[256], kind, path[200];
    unsigned vr;
    long line_number = 0;
    int status = fmi3OK;
    while (status <= fmi3Warning && fgets(line, sizeof line, stdin)) {
        line_number++;
        double a, b;
        long long n;
        if (sscanf(line, "set %c %u %lld", &kind, &vr, &n) == 3 && kind != 'F') {
            const fmi3ValueReference r = vr;
            if (kind == 'I') {
                const fmi3Int32 v = (fmi3Int32)n;
                status = set_int(c, &r, 1, &v, 1);
            } else if (kind == 'L') {
                const fmi3Int64 v = (fmi3Int64)n;
                status = set_long(c, &r, 1, &v, 1);
            } else {
                const fmi3Boolean v = n != 0;
                status = set_bool(c, &r, 1, &v, 1);
            }
        } else if (sscanf(line, "set F %u %la", &vr, &a) == 2) {
            const fmi3ValueReference r = vr;
            status = set_float(c, &r, 1, &a, 1);
        } else if (sscanf(line, "init %la", &a) == 1) {
            status = enter(c, fmi3False, 0.0, a, fmi3False, 0.0);
            if (status <= fmi3Warning) status = leave(c);
        } else if (sscanf(line, "step %la %la", &a, &b) == 2) {
            fmi3Boolean event, terminate, early;
            fmi3Float64 last;
            status = do_step(c, a, b, fmi3True, &event, &terminate, &early, &last);
        } else if (sscanf(line, "get %c %u", &kind, &vr) == 2) {
            const fmi3ValueReference r = vr;
            if (kind == 'F') {
                fmi3Float64 v;
                status = get_float(c, &r, 1, &v, 1);
                printf("%a\n", v);
            } else if (kind == 'I') {
                fmi3Int32 v;
                status = get_int(c, &r, 1, &v, 1);
                printf("%d\n", (int)v);
            } else {
                fmi3Boolean v;
                status = get_bool(c, &r, 1, &v, 1);
                printf("%d\n", v ? 1 : 0);
            }
        } else if (sscanf(line, "save %199s", path) == 1) {
            fmi3FMUState state = NULL;
            size_t size = 0;
            static fmi3Byte bytes[1 << 16];
            status = get_state(c, &state);
            if (status <= fmi3Warning) status = state_size(c, state, &size);
            if (status <= fmi3Warning && size <= sizeof bytes) status = serialize(c, state, bytes, size);
            FILE *f = fopen(path, "wb");
            if (!f || fwrite(bytes, 1, size, f) != size || fclose(f) != 0 || size > sizeof bytes) status = fmi3Error;
            free_state(c, &state);
        } else if (sscanf(line, "load %199s", path) == 1) {
            static fmi3Byte bytes[1 << 16];
            FILE *f = fopen(path, "rb");
            const size_t size = f ? fread(bytes, 1, sizeof bytes, f) : 0;
            if (f) fclose(f);
            fmi3FMUState state = NULL;
            status = deserialize(c, bytes, size, &state);
            if (status <= fmi3Warning) status = set_state(c, state);
            free_state(c, &state);
        } else {
            fprintf(stderr, "line %ld: cannot read '%s'\n", line_number, line);
            return 2;
        }
    }
    free_instance(c);
    if (status > fmi3Warning) {
        fprintf(stderr, "line %ld: status %d\n", line_number, status);
        return 1;
    }
    return 0;
}
