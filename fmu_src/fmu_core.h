/* FMI-version independent part of every FMU: variable access, the cycle
 * scheduler (SPEC section 2), FMU states and their serialization, logging.
 * fmi2_glue.c and fmi3_glue.c map the FMI C APIs onto it; a model file
 * (models/<Model>.c) maps its variables onto the kernel. */
#ifndef FMU_CORE_H
#define FMU_CORE_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rate_limiter.h"

typedef enum { FMU_REAL, FMU_INTEGER, FMU_BOOLEAN, FMU_ENUMERATION, FMU_UNSUPPORTED_TYPE } FmuType;
typedef enum { FMU_INDEPENDENT, FMU_PARAMETER, FMU_INPUT, FMU_OUTPUT } FmuCausality;
typedef enum { FMU_CONTINUOUS, FMU_DISCRETE, FMU_FIXED, FMU_TUNABLE } FmuVariability;

/* One row of a model's variable table (generated from its TOML file). */
typedef struct {
    const char *name;
    FmuType type;
    FmuCausality causality;
    FmuVariability variability;
    double start;
    double min, max;
} FmuVariable;

/* Same numbering as fmi2Status and fmi3Status. */
typedef enum { FMU_OK, FMU_WARNING, FMU_DISCARD, FMU_ERROR, FMU_FATAL } FmuStatus;

/* FMI modes as bits, so that each glue can state per function the set of
 * modes it is allowed in. */
typedef enum {
    MODE_INSTANTIATED   = 1 << 0,
    MODE_INITIALIZATION = 1 << 1,
    MODE_STEP           = 1 << 2,
    MODE_TERMINATED     = 1 << 3,
    MODE_ERROR          = 1 << 4
} FmuMode;

#define FMU_MAX_VARIABLES 32

/* A step that would run more cycles than this is refused (no endless loop
 * on a tiny cycleTime or a huge step). */
#define FMU_MAX_CYCLES_PER_STEP 100000000.0

/* Log categories (bits); names in fmu_log_category_names. */
enum { LOG_ERROR = 1, LOG_WARNING = 2, LOG_EVENTS = 4, LOG_ALL = 7 };
extern const char *const fmu_log_category_names[3];

/* What a model file provides: its variables and the mapping to the kernel. */
typedef struct {
    const char *identifier;
    const char *token;
    const FmuVariable *variables;
    unsigned count;
    unsigned inputVr;  /* the cycle input u */
    void (*configure)(const double *values, RlConfig *config);
    void (*publish)(const RlState *block, const RlPrepared *prepared, double *values);
} ModelDefinition;

extern const ModelDefinition fmuModel;

/* Everything an FMU state restores: plain data, copied as a whole. */
typedef struct {
    double values[FMU_MAX_VARIABLES];
    RlState block;
    double startTime;
    double time;
    uint64_t cycles;        /* cycles run since the start (cycleTime > 0) */
    int mode;               /* FmuMode */
    int reportedStatus;     /* status word last reported in the log */
} FmuCore;

typedef struct FmuInstance FmuInstance;
typedef void FmuLogFunction(FmuInstance *instance, FmuStatus status, const char *category, const char *message);

struct FmuInstance {
    FmuCore core;
    RlPrepared prepared;
    bool configDirty;       /* a parameter or input other than u changed */
    const ModelDefinition *model;
    FmuLogFunction *logFunction;
    int logCategories;      /* enabled categories */
    const char *instanceName;
    const void *glue;       /* the glue's callbacks */
    void *environment;      /* the importer's instance environment */
};

void fmu_init_instance(FmuInstance *instance);
void fmu_reset(FmuInstance *instance);

void fmu_log(FmuInstance *instance, FmuStatus status, const char *fmt, ...);

/* Enable log categories: all when loggingOn and none are named, else the
 * named ones; alwaysOn categories stay enabled whatever is asked. */
FmuStatus fmu_set_debug_logging(FmuInstance *instance, const char *function, bool loggingOn,
                                size_t nCategories, const char *const categories[], int alwaysOn);

/* The single error path: log why, enter the error mode, return FMU_ERROR. */
FmuStatus fmu_error(FmuInstance *instance, const char *function, const char *fmt, ...);

/* State table check: FMU_OK, or logs and returns FMU_ERROR. */
FmuStatus fmu_check_mode(FmuInstance *instance, const char *function, int allowedModes);

FmuStatus fmu_check_array(FmuInstance *instance, const char *function, size_t n, const void *vr, const void *values);

/* Variable access, value by value, values carried as double: every type
 * here (Real, Integer, Boolean, Enumeration) is exact in a double.
 * fmu_check_set validates one value without changing anything, so that a
 * call setting several values is all or nothing. */
#define TYPE_BIT(type) (1 << (type))
FmuStatus fmu_check_get(FmuInstance *instance, const char *function, int typeMask, unsigned vr);
double fmu_get(FmuInstance *instance, unsigned vr);
FmuStatus fmu_check_set(FmuInstance *instance, const char *function, int typeMask, unsigned vr, double value);
void fmu_set(FmuInstance *instance, unsigned vr, double value);

FmuStatus fmu_setup_experiment(FmuInstance *instance, double startTime);
FmuStatus fmu_enter_initialization(FmuInstance *instance);
FmuStatus fmu_exit_initialization(FmuInstance *instance);
FmuStatus fmu_do_step(FmuInstance *instance, const char *function, double t, double h);

/* Serialized FMU state: header, payload, CRC-32. */
size_t fmu_serialized_size(const FmuInstance *instance);
void fmu_serialize(const FmuInstance *instance, const FmuCore *state, unsigned char *out);
FmuStatus fmu_deserialize(FmuInstance *instance, const char *function, const unsigned char *in, size_t size, FmuCore *out);

/* Make a restored core the current one. */
void fmu_restore(FmuInstance *instance, const FmuCore *state);

const char *fmu_mode_name(int mode);

#endif
