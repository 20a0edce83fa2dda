#include "fmu_state.h"

#include <float.h>
#include <math.h>
#include <string.h>

#define SERIAL_MAGIC "RLFS"
#define SERIAL_VERSION 3u /* with the payload's size, checked too: the cycle before the last added 24 bytes */
/* magic, version, model hash, payload size; CRC-32 after the payload */
#define SERIAL_HEADER 16u
#define SERIAL_TRAILER 4u

/* The current core, outputs published, for an FMU state. */
static void snapshot(FmuInstance *instance, FmuCore *state) {
    if (instance->outputsStale) fmu_refresh_outputs(instance);
    *state = instance->core;
}

/* Make a restored core the current one. */
static void restore(FmuInstance *instance, const FmuCore *state) {
    instance->core = *state;
    /* the outputs are the state's (snapshot published them); one taken in
     * Initialization Mode initializes again on a get */
    instance->outputsStale = FMU_FRESH;
    fmu_invalidate(instance);
}

/* ---- serialization ---------------------------------------------------- */

static uint32_t crc32(const unsigned char *data, size_t size) {
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < size; i++) {
        crc ^= data[i];
        for (int k = 0; k < 8; k++) {
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
    }
    return ~crc;
}

static uint32_t model_hash(const ModelDefinition *model) {
    uint32_t hash = 2166136261u; /* FNV-1a */
    for (const char *c = model->token; *c; c++) {
        hash = (hash ^ (unsigned char)*c) * 16777619u;
    }
    return hash;
}

static unsigned char *put_u32(unsigned char *p, uint32_t v) {
    for (int i = 0; i < 4; i++) *p++ = (unsigned char)(v >> (8 * i));
    return p;
}

static unsigned char *put_u64(unsigned char *p, uint64_t v) {
    for (int i = 0; i < 8; i++) *p++ = (unsigned char)(v >> (8 * i));
    return p;
}

static unsigned char *put_f64(unsigned char *p, double v) {
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    return put_u64(p, bits);
}

static uint32_t get_u32(const unsigned char **p) {
    uint32_t v = 0;
    for (int i = 0; i < 4; i++) v |= (uint32_t)(*p)[i] << (8 * i);
    *p += 4;
    return v;
}

static uint64_t get_u64(const unsigned char **p) {
    uint64_t v = 0;
    for (int i = 0; i < 8; i++) v |= (uint64_t)(*p)[i] << (8 * i);
    *p += 8;
    return v;
}

static double get_f64(const unsigned char **p) {
    const uint64_t bits = get_u64(p);
    double v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

static size_t payload_size(const ModelDefinition *model) {
    return 4 + 8 * (size_t)model->count   /* values */
           + 8 + 8 + 8 + 1 + 8 + 8 + 8    /* block */
           + 8 + 8 + 8                    /* startTime, time, cycles */
           + 8 + 8 + 8                    /* block: the cycle before the last */
           + 8 * (size_t)model->count + 8 /* latched values, eventTime */
           + 4 + 4;                       /* mode, status */
}

static size_t serialized_size(const FmuInstance *instance) {
    return SERIAL_HEADER + payload_size(instance->model) + SERIAL_TRAILER;
}

static void serialize(const FmuInstance *instance, const FmuCore *s, unsigned char *out) {
    const ModelDefinition *model = instance->model;
    unsigned char *p = out;
    memcpy(p, SERIAL_MAGIC, 4);
    p += 4;
    p = put_u32(p, SERIAL_VERSION);
    p = put_u32(p, model_hash(model));
    p = put_u32(p, (uint32_t)payload_size(model));
    p = put_u32(p, model->count);
    for (unsigned i = 0; i < model->count; i++) p = put_f64(p, s->values[i]);
    p = put_f64(p, s->block.y);
    p = put_f64(p, s->block.uPrevious);
    p = put_f64(p, s->block.yPrevious);
    *p++ = s->block.decided;
    p = put_u64(p, s->block.runCycles);
    p = put_f64(p, s->block.runPeriod);
    p = put_f64(p, s->block.runBase);
    p = put_f64(p, s->startTime);
    p = put_f64(p, s->time);
    p = put_u64(p, s->cycles);
    p = put_f64(p, s->block.yBefore);
    p = put_f64(p, s->block.periodLast);
    p = put_f64(p, s->block.periodBefore);
    for (unsigned i = 0; i < model->count; i++) p = put_f64(p, s->latched[i]);
    p = put_f64(p, s->eventTime);
    p = put_u32(p, (uint32_t)s->mode);
    p = put_u32(p, (uint32_t)s->reportedStatus);
    put_u32(p, crc32(out, (size_t)(p - out)));
}

/* A mode of this instance's interface (an FMU state taken by an instance
 * of the other one is refused). */
static bool fmu_mode_possible(const FmuInstance *instance, int mode) {
    const int modes = MODE_INSTANTIATED | MODE_INITIALIZATION | MODE_TERMINATED | instance->errorMode |
                      (instance->interfaceType == FMU_MODEL_EXCHANGE        ? MODE_EVENT | MODE_CONTINUOUS
                       : instance->interfaceType == FMU_SCHEDULED_EXECUTION ? MODE_CLOCK_ACTIVATION
                                                                            : MODE_STEP);
    return mode > 0 && (mode & (mode - 1)) == 0 && (mode & modes) != 0; /* > 0: no mode - 1 overflow */
}

/* Cycle counts stay exact in a double (2^53). */
#define MAX_EXACT_CYCLES ((uint64_t)1 << 53)

/* A value of the variable's type and declared range (NaN only for an
 * unranged Real), as fmu_check_set would accept it. */
static bool value_possible(const FmuVariable *v, double value) {
    switch (v->type) {
    case FMU_REAL: return fmu_in_range(v, value);
    case FMU_BOOLEAN: return value == 0.0 || value == 1.0;
    default: /* Integer, Enumeration: an int32 in range */
        return value == floor(value) && isgreaterequal(value, -2147483648.0) && islessequal(value, 2147483647.0) &&
               isgreaterequal(value, v->min) && islessequal(value, v->max);
    }
}

static FmuStatus deserialize(FmuInstance *instance, const char *function, const unsigned char *in, size_t size,
                             FmuCore *out) {
    const ModelDefinition *model = instance->model;
    const size_t expected = serialized_size(instance);
    const unsigned char *p = in;

    if (!in) {
        return fmu_error(instance, function, "the serialized state is NULL");
    }
    if (size < SERIAL_HEADER || memcmp(in, SERIAL_MAGIC, 4) != 0) {
        return fmu_error(instance, function, "not a serialized state of this FMU (%zu bytes, no header)", size);
    }
    p += 4;
    const uint32_t version = get_u32(&p);
    if (version != SERIAL_VERSION) {
        return fmu_error(instance, function, "serialized state has format version %u; this FMU reads version %u",
                         (unsigned)version, SERIAL_VERSION);
    }
    if (get_u32(&p) != model_hash(model)) {
        return fmu_error(instance, function, "serialized state belongs to another model or version, not %s %s",
                         model->identifier, model->token);
    }
    if (size != expected || get_u32(&p) != payload_size(model)) {
        return fmu_error(instance, function, "serialized state has %zu bytes; expected %zu (truncated or padded)", size,
                         expected);
    }
    const unsigned char *trailer = in + size - SERIAL_TRAILER;
    if (crc32(in, size - SERIAL_TRAILER) != get_u32(&trailer)) {
        return fmu_error(instance, function, "serialized state is corrupted (checksum mismatch)");
    }
    FmuCore s;
    memset(&s, 0, sizeof s);
    if (get_u32(&p) != model->count) {
        return fmu_error(instance, function, "serialized state has the wrong number of variables");
    }
    for (unsigned i = 0; i < model->count; i++) s.values[i] = get_f64(&p);
    s.block.y = get_f64(&p);
    s.block.uPrevious = get_f64(&p);
    s.block.yPrevious = get_f64(&p);
    s.block.decided = *p++;
    s.block.runCycles = get_u64(&p);
    s.block.runPeriod = get_f64(&p);
    s.block.runBase = get_f64(&p);
    s.startTime = get_f64(&p);
    s.time = get_f64(&p);
    s.cycles = get_u64(&p);
    s.block.yBefore = get_f64(&p);
    s.block.periodLast = get_f64(&p);
    s.block.periodBefore = get_f64(&p);
    for (unsigned i = 0; i < model->count; i++) s.latched[i] = get_f64(&p);
    s.eventTime = get_f64(&p);
    s.mode = (int)get_u32(&p);
    s.reportedStatus = (int)get_u32(&p);
    if (!fmu_mode_possible(instance, s.mode)) {
        return fmu_error(instance, function, "serialized state has an invalid mode %d", s.mode);
    }
    /* a checksum only proves the bytes arrived as written: every value must
     * also be one that this FMU could have made */
    for (unsigned i = 0; i < 2 * model->count; i++) {
        const FmuVariable *v = &model->variables[i % model->count];
        const double value = i < model->count ? s.values[i] : s.latched[i - model->count];
        if (!value_possible(v, value)) {
            return fmu_error(instance, function, "serialized state has an impossible value %g for %s", value, v->name);
        }
    }
    if (s.block.decided > RL_DECIDED_RAMP) {
        return fmu_error(instance, function, "serialized state has an invalid rule %u", (unsigned)s.block.decided);
    }
    /* runningTime is a sum of whole cycles: no NaN, infinity or negative */
    if (!isfinite(s.startTime) || !isfinite(s.time) || !isfinite(s.eventTime) || s.cycles > MAX_EXACT_CYCLES ||
        s.block.runCycles > MAX_EXACT_CYCLES ||
        !(isgreaterequal(s.block.runPeriod, 0) && islessequal(s.block.runPeriod, DBL_MAX)) ||
        !(isgreaterequal(s.block.runBase, 0) && islessequal(s.block.runBase, DBL_MAX)) ||
        !(isgreaterequal(s.block.periodLast, 0) && islessequal(s.block.periodLast, DBL_MAX)) ||
        !(isgreaterequal(s.block.periodBefore, 0) && islessequal(s.block.periodBefore, DBL_MAX))) {
        return fmu_error(instance, function, "serialized state has an impossible time or cycle count");
    }
    /* Event Mode is an instant: entering it, SetTime in it and the end of
     * initialisation make the time that of the event (fmu_set_time relies on it) */
    if (s.mode == MODE_EVENT && s.time != s.eventTime) {
        return fmu_error(instance, function,
                         "serialized state is in Event Mode at time %.17g, not at its event's %.17g", s.time,
                         s.eventTime);
    }
    *out = s;
    return FMU_OK;
}

/* ---- FMU states --------------------------------------------------------- */

#define STATE_TAG 0x524c5354u /* "RLST" */
typedef struct {
    uint32_t tag;
    FmuCore core;
} FmuState;

static FmuStatus check_state(FmuInstance *instance, const char *function, const void *state) {
    if (!state) {
        return fmu_error(instance, function, "the FMU state is NULL");
    }
    if (((const FmuState *)state)->tag != STATE_TAG) {
        return fmu_error(instance, function, "not an FMU state of this FMU");
    }
    return FMU_OK;
}

/* *state, checked, or a new one, tagged; NULL after an error */
static FmuState *state_to_fill(FmuInstance *instance, const char *function, void **state) {
    FmuState *target = (FmuState *)*state;
    if (target) {
        return check_state(instance, function, target) == FMU_OK ? target : NULL;
    }
    target = (FmuState *)instance->allocate(instance, sizeof *target);
    if (!target) {
        fmu_error(instance, function, "out of memory");
        return NULL;
    }
    target->tag = STATE_TAG;
    return target;
}

FmuStatus fmu_get_state(FmuInstance *instance, const char *function, void **state) {
    if (!state) {
        return fmu_error(instance, function, "the FMU state pointer is NULL");
    }
    FmuState *target = state_to_fill(instance, function, state);
    if (!target) {
        return FMU_ERROR;
    }
    snapshot(instance, &target->core);
    *state = target;
    return FMU_OK;
}

FmuStatus fmu_set_state(FmuInstance *instance, const char *function, const void *state) {
    if (check_state(instance, function, state) != FMU_OK) {
        return FMU_ERROR;
    }
    if (!fmu_mode_possible(instance, ((const FmuState *)state)->core.mode)) {
        return fmu_error(instance, function, "an FMU state of %s, which this %s instance cannot be in",
                         fmu_mode_name(((const FmuState *)state)->core.mode),
                         fmu_interface_name(instance->interfaceType));
    }
    restore(instance, &((const FmuState *)state)->core);
    return FMU_OK;
}

FmuStatus fmu_free_state(FmuInstance *instance, const char *function, void **state) {
    if (!state || !*state) {
        return FMU_OK;
    }
    if (check_state(instance, function, *state) != FMU_OK) {
        return FMU_ERROR;
    }
    ((FmuState *)*state)->tag = 0;
    instance->release(instance, *state);
    *state = NULL;
    return FMU_OK;
}

FmuStatus fmu_serialized_state_size(FmuInstance *instance, const char *function, const void *state, size_t *size) {
    if (check_state(instance, function, state) != FMU_OK) {
        return FMU_ERROR;
    }
    if (!size) {
        return fmu_error(instance, function, "the size pointer is NULL");
    }
    *size = serialized_size(instance);
    return FMU_OK;
}

FmuStatus fmu_serialize_state(FmuInstance *instance, const char *function, const void *state, unsigned char *out,
                              size_t size) {
    if (check_state(instance, function, state) != FMU_OK) {
        return FMU_ERROR;
    }
    if (!out) {
        return fmu_error(instance, function, "the byte array is NULL");
    }
    if (size < serialized_size(instance)) {
        return fmu_error(instance, function, "the byte array has %zu bytes; the state needs %zu", size,
                         serialized_size(instance));
    }
    serialize(instance, &((const FmuState *)state)->core, out);
    return FMU_OK;
}

FmuStatus fmu_deserialize_state(FmuInstance *instance, const char *function, const unsigned char *in, size_t size,
                                void **state) {
    FmuCore core;
    if (!state) {
        return fmu_error(instance, function, "the FMU state pointer is NULL");
    }
    if (deserialize(instance, function, in, size, &core) != FMU_OK) {
        return FMU_ERROR;
    }
    FmuState *target = state_to_fill(instance, function, state);
    if (!target) {
        return FMU_ERROR;
    }
    target->core = core;
    *state = target;
    return FMU_OK;
}
