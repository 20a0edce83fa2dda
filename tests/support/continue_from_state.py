"""Helper process for fmu/test_state.py: deserialize an FMU state into a fresh
instance, continue a run, print the outputs as exact hex floats (JSON)."""

import json
import sys

from support.fmu_driver import Instance, run_steps, state_api

version, state_file, steps = int(sys.argv[1]), sys.argv[2], json.loads(sys.argv[3])
fmu = Instance("RateLimiter", version)
api = state_api(fmu)
state = api["deserialize"](open(state_file, "rb").read())
api["set"](state)
fmu.t = fmu.get("time")
print(json.dumps(run_steps(fmu, steps)))
fmu.free()
