/* What the Siemens LGF blocks share (LGF_LimRateOfChangeCI and
 * LGF_LimRateOfChangeAdvancedCI). */
#ifndef SIEMENS_H
#define SIEMENS_H

#include "model.h"

/* A callOB that is no cyclic interrupt OB (30..38 or 123 and above) is a
 * configuration error, 16#8601 caused by callOB; the block still runs its
 * cycles at cycleTime (the OB interval): only the status reports it. */
static inline void siemens_cycle(RlConfig *c, double callOB, int callOBVr, double cycleTime, int cycleTimeVr) {
    const bool cyclic = (isgreaterequal(callOB, 30) && islessequal(callOB, 38)) || isgreaterequal(callOB, 123);
    c->cycleTime.value = cycleTime;
    c->cycleTime.source = cyclic ? cycleTimeVr : callOBVr;
    c->cycleRefused = !cyclic;
}

#endif
