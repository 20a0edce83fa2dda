/* What a model implements, and all it may use: its variable table
 * (generated from modelDescription/<Model>.toml into <Model>_variables.h,
 * which includes this header), the mapping of its variables onto the
 * kernel (rate_limiter.h), and the outputs it publishes. A model file,
 * models/<Model>.c, defines fmuModel (FMU_MODEL) and nothing else; the
 * core and the FMI glue do the rest. */
#ifndef FMU_MODEL_H
#define FMU_MODEL_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "rate_limiter.h"

typedef enum { FMU_REAL, FMU_INTEGER, FMU_BOOLEAN, FMU_ENUMERATION, FMU_UNSUPPORTED_TYPE } FmuType;
typedef enum { FMU_INDEPENDENT, FMU_PARAMETER, FMU_INPUT, FMU_OUTPUT } FmuCausality;
typedef enum { FMU_CONTINUOUS, FMU_DISCRETE, FMU_FIXED, FMU_TUNABLE } FmuVariability;

/* One row of a model's variable table. */
typedef struct {
    const char *name;
    FmuType type;
    FmuCausality causality;
    FmuVariability variability;
    double start;
    double min, max;
} FmuVariable;

/* Variables per model, at most (the generated header checks its model). */
#define FMU_MAX_VARIABLES 40

/* The status outputs of a block with the Siemens status word: error (the
 * word is an error), status (the word) and the value reference of the
 * variable that caused an error (0 without one). */
typedef struct {
    unsigned errorVr, statusVr, causeVr;
} FmuStatusOutputs;

/* A model. Value reference 0 is the independent variable time
 * (generate.py); values[] is indexed by value reference. */
typedef struct {
    const char *identifier;
    const char *token;
    const FmuVariable *variables;
    unsigned count;
    unsigned inputVr;  /* the cycle input u */
    unsigned outputVr; /* the output y: the block's state y */
    /* FMI 3's input Clock, the PLC's cyclic interrupt (OB): not a value
     * in the table, its value reference the first after it */
    const char *clockName;
    unsigned clockVr;
    /* The kernel's configuration from the current values; returns the
     * model's own mode (0 if it has none), which publish gets back with
     * the configuration of the last cycle. */
    int (*configure)(const double *values, RlConfig *config);
    /* The outputs of the block's state and of the configuration of its
     * last cycle (prepared, modelMode); plan: the block's kept plan
     * (rl_outputs). */
    void (*publish)(const RlState *block, const RlPrepared *prepared, int modelMode, RlPlan *plan, double *values);
    /* NULL: the block has no status outputs */
    const FmuStatusOutputs *statusOutputs;
} ModelDefinition;

/* A model file ends with its definition: FMU_MODEL(input u, output y,
 * configure, publish, status outputs or NULL), with the variable table of
 * its generated header. In an FMU's unit it comes before the core, which
 * uses it (rate_limiter.h, RL_LINKAGE). */
#define FMU_MODEL(inputVr, outputVr, configure, publish, statusOutputs) \
    RL_DEFINITION const ModelDefinition fmuModel = { \
        MODEL_IDENTIFIER, MODEL_TOKEN, modelVariables, MODEL_VARIABLE_COUNT, inputVr, outputVr, MODEL_CLOCK_NAME, \
        MODEL_CLOCK_VR,   configure,   publish,        statusOutputs \
    }
#ifndef RL_UNIT
extern const ModelDefinition fmuModel;
#endif

#endif
