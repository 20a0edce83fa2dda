/* FMU states and their serialization, for both FMI versions: the glue
 * converts types only. A state is a tagged copy of the core (a foreign
 * pointer is refused, not read); serialized, it is a header, the payload
 * and a CRC-32. *state NULL: a new state is allocated, else the given one
 * is overwritten. */
#ifndef FMU_STATE_H
#define FMU_STATE_H

#include "fmu_core.h"

RL_LINKAGE FmuStatus fmu_get_state(FmuInstance *instance, const char *function, void **state);
RL_LINKAGE FmuStatus fmu_set_state(FmuInstance *instance, const char *function, const void *state);
RL_LINKAGE FmuStatus fmu_free_state(FmuInstance *instance, const char *function, void **state);
RL_LINKAGE FmuStatus fmu_serialized_state_size(FmuInstance *instance, const char *function, const void *state,
                                               size_t *size);
RL_LINKAGE FmuStatus fmu_serialize_state(FmuInstance *instance, const char *function, const void *state,
                                         unsigned char *out, size_t size);
RL_LINKAGE FmuStatus fmu_deserialize_state(FmuInstance *instance, const char *function, const unsigned char *in,
                                           size_t size, void **state);

#endif
