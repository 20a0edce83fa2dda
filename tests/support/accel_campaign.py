"""N random scenarios of the acceleration limit per arithmetic through the
FMU binaries, every cycle checked against the properties of the acceleration limit
(docs/rules.md; support/accel_properties.py). From tests/, after the build:

    python -m support.accel_campaign --scenarios 10000 --arithmetic lreal
    python -m support.accel_campaign --scenarios 10000 --arithmetic real --seed 7

Scenarios alternate RateLimiter and RateLimiterStatic, FMI 2 and 3, and
Co-Simulation (cycleTime 0 or T) and Model Exchange (every Model Exchange
scenario is also run as Co-Simulation: the outputs must be the same bits at
every cycle end). Prints how many scenarios and cycles were checked and
every violation with its scenario as JSON (a reproducer:
`--replay FILE`); exits 1 on any violation.
"""

import argparse
import collections
import random
import sys
import time

from support.accel_properties import LREAL, REAL
from support.accel_scenarios import RandomChooser, loads, replay, run_random, violations

MODELS = ("RateLimiter", "RateLimiterStatic")


def same_outputs(a, b):
    """Bit for bit (NaN equal to NaN), cycle by cycle: the first cycle that differs, or None."""
    flat_a = [c.out for s in a for c in s.cycles]
    flat_b = [c.out for s in b for c in s.cycles]
    for n, (x, y) in enumerate(zip(flat_a, flat_b, strict=False)):
        if any(repr(float(x[k])) != repr(float(y[k])) for k in x):
            return n + 1, x, y
    if len(flat_a) != len(flat_b):
        return min(len(flat_a), len(flat_b)) + 1, None, None
    return None


def one(index, arithmetic, seed, cycles):
    """Scenario number index: (scenario, its cycles, its violations as text)."""
    rng = random.Random(f"{seed}/{arithmetic}/{index}")
    model, version, me = MODELS[index % 2], 2 + (index // 2) % 2, (index // 4) % 3 == 0
    scenario, segments = run_random(RandomChooser(rng), model, version, arithmetic, model_exchange=me, cycles=cycles)
    found = [str(v) for v in violations(scenario, segments)]
    if me:
        differs = same_outputs(segments, replay(scenario, model_exchange=True))
        if differs:
            found.append(f"Model Exchange, cycle {differs[0]}: {differs[2]} where Co-Simulation gave {differs[1]}")
    return scenario, sum(len(s.cycles) for s in segments), found


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", type=int, default=1000)
    parser.add_argument("--arithmetic", choices=["lreal", "real", "both"], default="both")
    parser.add_argument("--seed", default="0")
    parser.add_argument(
        "--first", type=int, default=0, metavar="N", help="start at scenario N (a campaign split between processes)"
    )
    parser.add_argument(
        "--cycles",
        type=int,
        nargs=2,
        default=(40, 200),
        metavar=("MIN", "MAX"),
        help="cycles of a scenario before its settling tail",
    )
    parser.add_argument("--replay", help="a file with one scenario's JSON (as printed): run and check it")
    parser.add_argument("--show", type=int, default=20, help="violations printed per scenario")
    parser.add_argument(
        "--progress", type=int, default=500, metavar="N", help="a progress line on stderr every N scenarios (0: none)"
    )
    args = parser.parse_args(argv)
    if args.replay:
        with open(args.replay) as f:
            scenario = loads(f.read())
        segments = replay(scenario)
        found = violations(scenario, segments)
        for v in found:
            print(v)
        print(f"{len(found)} violations in {sum(len(s.cycles) for s in segments)} cycles")
        return 1 if found else 0
    kinds = {"lreal": [LREAL], "real": [REAL], "both": [LREAL, REAL]}[args.arithmetic]
    failed = 0
    for arithmetic in kinds:
        name = "LREAL" if arithmetic == LREAL else "REAL"
        start, cycles, bad, kinds = time.monotonic(), 0, 0, collections.Counter()
        for index in range(args.first, args.scenarios):
            scenario, n, found = one(index, arithmetic, args.seed, tuple(args.cycles))
            cycles += n
            if found:
                bad += 1
                kinds.update(v.split(",")[0] for v in found)
                print(
                    f"--- {name} scenario {index} ({scenario.model}, FMI {scenario.version}): {len(found)} violations"
                )
                for v in found[: args.show]:
                    print("   ", v)
                print("    scenario:", scenario.dumps())
                sys.stdout.flush()
            if args.progress and (index + 1) % args.progress == 0:
                print(
                    f"{name}: {index + 1} of {args.scenarios} scenarios (from {args.first}), {cycles} cycles, "
                    f"{bad} with violations, {time.monotonic() - start:.0f} s",
                    file=sys.stderr,
                    flush=True,
                )
        failed += bad
        print(
            f"{name}: scenarios {args.first} to {args.scenarios - 1}, {cycles} cycles checked in "
            f"{time.monotonic() - start:.0f} s; "
            f"{bad} scenarios with violations" + (f" ({dict(kinds)})" if kinds else "")
        )
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
