/* What the Siemens LGF blocks share (LGF_LimRateOfChangeCI and
 * LGF_LimRateOfChangeAdvancedCI). */
#ifndef SIEMENS_H
#define SIEMENS_H

#include "model.h"

/* cycleTime (the OB interval) counts only when callOB is a cyclic
 * interrupt OB, 30..38 or 123 and above; else there is no valid cycle,
 * and callOB is the cause. */
static inline RlValue siemens_cycle(double callOB, int callOBVr, double cycleTime, int cycleTimeVr) {
    const bool cyclic = (callOB >= 30 && callOB <= 38) || callOB >= 123;
    RlValue cycle;
    cycle.value = cyclic ? cycleTime : NAN;
    cycle.source = cyclic ? cycleTimeVr : callOBVr;
    return cycle;
}

#endif
