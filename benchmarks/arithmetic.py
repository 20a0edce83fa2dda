#!/usr/bin/env python3
"""REAL against LREAL on three ramps of 10 ms cycles: the CODESYS Ramp FMU
(binary32) beside the RateLimiter FMU in its default LREAL (binary64),
each cycle compared, and how long each takes to reach its target.

    arithmetic.py --build-dir build [--oracle]

--oracle runs the same ramps through the tests' independent oracle
(tests/support/oracle.py, the rules in single and double precision)
instead of the FMUs: the same figures, bit for bit, much slower (minutes).
"""

import argparse
import copy
import sys
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

REPO = Path(__file__).resolve().parents[1]
CYCLE = 0.01
# (name, start, target, change per period, period in s)
RAMPS = [
    ("0 -> 100 at 100 per 10 s", 0.0, 100.0, 100.0, 10.0),
    ("0 -> 1e6 at 1 per s (0.01 per cycle)", 0.0, 1e6, 1.0, 1.0),
    ("20 -> 30 at 1 per 1000 s (1e-5 per cycle)", 20.0, 30.0, 1.0, 1000.0),
]
COARSE = 1000  # cycles per step while nothing is compared cycle by cycle


class FmuRamp:
    """A ramp in a model's FMU (FMI 2), stepped whole cycles at a time."""

    def __init__(self, build_dir, model, start, target, rate, period):
        unzipdir = extract(str(Path(build_dir) / "fmi2" / f"{model}.fmu"))
        md = read_model_description(unzipdir)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=model, instanceName=model)
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        if model == "Ramp":
            reals = {"cycleTime": CYCLE, "rInitValue": start, "rIn": target, "rVariation": rate, "tTime": period}
            self.fmu.setInteger([self.vr["eInitial"]], [1])
            self.output = self.vr["rOut"]
        else:
            reals = {"cycleTime": CYCLE, "initValue": start, "u": target, "rateUpPar": rate, "ratePeriod": period}
            self.fmu.setInteger([self.vr["initMode"]], [1])
            self.output = self.vr["y"]
        self.fmu.setReal([self.vr[k] for k in reals], list(reals.values()))
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        self.cycles = 0

    def run(self, cycles):
        self.fmu.doStep(currentCommunicationPoint=self.cycles * CYCLE, communicationStepSize=cycles * CYCLE)
        self.cycles += cycles
        return self.fmu.getReal([self.output])[0]

    def save(self):
        return self.fmu.getFMUstate(), self.cycles

    def restore(self, saved):
        self.fmu.setFMUstate(saved[0])
        self.cycles = saved[1]


class OracleRamp:
    """The same ramp in the oracle (REAL or LREAL)."""

    def __init__(self, arithmetic, start, target, rate, period):
        sys.path.insert(0, str(REPO / "tests"))
        from support.oracle import RateLimiterOracle

        self.oracle = RateLimiterOracle(
            {},
            {
                "arithmetic": arithmetic,
                "cycleTime": CYCLE,
                "initMode": 1,
                "initValue": start,
                "u": target,
                "rateUpPar": rate,
                "ratePeriod": period,
            },
        )
        self.cycles = 0

    def run(self, cycles):
        out = self.oracle.do_step(self.cycles * CYCLE, cycles * CYCLE)
        self.cycles += cycles
        return out["y"]

    def save(self):
        return copy.deepcopy(self.oracle), self.cycles

    def restore(self, saved):
        self.oracle, self.cycles = copy.deepcopy(saved[0]), saved[1]


def arrival(ramp, target):
    """(the value the ramp ends at, the cycle it first has it): stepped
    COARSE cycles at a time until it reaches target or stops moving, then
    the step it got there in again cycle by cycle."""
    saved, last = [ramp.save()], None
    while True:
        y = ramp.run(COARSE)
        if y == target:
            ramp.restore(saved[-1])  # reached in this step
            break
        if y == last:
            ramp.restore(saved[-2])  # stopped moving in the step before
            break
        saved, last = saved[-1:] + [ramp.save()], y
    while ramp.run(1) != y:
        pass
    return y, ramp.cycles


def compare(real, lreal, cycles):
    """Cycle by cycle: the largest difference (absolute and relative) and
    the first cycle from which they agree within 1e-9 for good."""
    largest, relative, agreeing_from = 0.0, 0.0, None
    for n in range(1, cycles + 1):
        a, b = real.run(1), lreal.run(1)
        gap = abs(a - b)
        if gap > largest:
            largest, relative = gap, gap / abs(b)
        if gap <= 1e-9:
            agreeing_from = agreeing_from or n
        else:
            agreeing_from = None
    return largest, relative, agreeing_from


def value_at(make, end, arrived, cycles):
    """A ramp's output after cycles: its end value once it has arrived."""
    return end if cycles >= arrived else make().run(cycles)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build-dir", default=str(REPO / "build"))
    parser.add_argument("--oracle", action="store_true", help="the tests' oracle instead of the FMUs")
    args = parser.parse_args()

    def make(real, ramp):
        _, start, target, rate, period = ramp
        if args.oracle:
            return OracleRamp(2 if real else 1, start, target, rate, period)
        return FmuRamp(args.build_dir, "Ramp" if real else "RateLimiter", start, target, rate, period)

    source = "oracle (REAL / LREAL)" if args.oracle else "Ramp FMU (REAL) / RateLimiter FMU (LREAL)"
    print(f"10 ms cycles; {source}")
    print("| ramp | REAL ends at | after cycles | LREAL ends at | after cycles | largest difference |")
    print("|---|---|---|---|---|---|")
    for ramp in RAMPS:
        target = ramp[2]
        real_end, real_cycles = arrival(make(True, ramp), target)
        lreal_end, lreal_cycles = arrival(make(False, ramp), target)
        if max(real_cycles, lreal_cycles) <= 100000:
            largest, relative, agreeing = compare(make(True, ramp), make(False, ramp), max(real_cycles, lreal_cycles))
            gap = f"{largest:.3g} (relative {relative:.2g}); within 1e-9 from cycle {agreeing or '-'} on"
        else:  # the largest difference is where one of them ends
            gaps = []
            for at in sorted({real_cycles, lreal_cycles}):
                a = value_at(lambda ramp=ramp: make(True, ramp), real_end, real_cycles, at)
                b = value_at(lambda ramp=ramp: make(False, ramp), lreal_end, lreal_cycles, at)
                gaps.append((abs(a - b), abs(a - b) / abs(b), at))
            absolute, relative, at = max(gaps)
            gap = f"{absolute:.6g} ({relative:.1%}) at cycle {at:,}"
        print(f"| {ramp[0]} | {real_end!r} | {real_cycles:,} | {lreal_end!r} | {lreal_cycles:,} | {gap} |")


if __name__ == "__main__":
    main()
