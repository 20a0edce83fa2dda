#!/usr/bin/env python3
"""Campaign benchmark: fmutrace compare with its default executor, with
--jobs 1 and with --jobs N (N: the cores), side by side, and against a
plain loop of fmpy.simulate_fmu calls.

    campaign.py --build-dir build [--campaigns 20x1000,2000x1000,10000x1000,20x1000000] [--smoke]

1. Generates each campaign's cases (once; kept under
   build/benchmarks/campaign/<cases>x<steps>/): the RateLimiter FMU (FMI 3),
   random inputs (u, a new value every 10 cycles; the bypass input at
   times) and parameters (rates up and down, cycle 0.01 s), references (y
   and status) from a first run of fmutrace's runner.
2. The plain loop as a user writes it, in one process, on a sample of
   the 1,000-step cases: fmpy's read_csv of the inputs, simulate_fmu,
   read_csv of the reference, np.array_equal; per trace.
3. Per campaign (its files read once first, so that no way pays for the
   disk), the command three ways (the report and --rel-tol 1e-9, the plots
   the command's default), each way's best of two runs, taking turns: the
   default, --jobs 1 and --jobs N; wall time from the command's start to
   its exit and its CPU (its workers' included).
Prints a table and the targets; exit 1 if a figure misses its target
(not with --smoke: figures on a few steps mean nothing).
"""

import argparse
import hashlib
import io
import contextlib
import json
import os
import platform
import resource
import subprocess
import sys
import time
from multiprocessing import Pool
from pathlib import Path

import numpy as np

MODEL = "RateLimiter"
STEP = 0.01
TARGET_RATIO, TARGET_SECONDS = 10.0, 10.0
CAMPAIGNS = "20x1000,2000x1000,10000x1000,20x1000000"
ROUNDS = 2  # each way's best of so many runs
RATIO_FROM_CASES = 1000  # the ratio's target holds from so many cases on (the command's start-up shared out)


def case_inputs(seed, steps):
    rng = np.random.default_rng(seed)
    rows = np.arange(0, steps, 10)
    u = np.round(rng.normal(0, 20, len(rows)).cumsum(), 2)
    bypass = (rng.random(len(rows)) < 0.05).astype(float)
    inputs = np.zeros(len(rows), dtype=[("time", float), ("u", float), ("bypass", float), ("bypassValue", float)])
    inputs["time"] = np.round(rows * STEP, 10)
    inputs["u"], inputs["bypass"], inputs["bypassValue"] = u, bypass, np.round(rng.normal(0, 50), 2)
    start = {"rateUpPar": round(float(rng.uniform(1, 200)), 3), "rateDownPar": round(float(rng.uniform(1, 200)), 3)}
    return inputs, start


def write_case(args):
    """One case folder with its reference from fmutrace's runner."""
    from fmutrace._fmpy import Experiment, Signals
    from fmutrace._runner import Runner
    from fmutrace._traces import write_trace

    folder, seed, steps, fmu = args
    inputs, start = case_inputs(seed, steps)
    folder.mkdir(parents=True, exist_ok=True)
    write_trace(folder / f"{MODEL}_in.csv", inputs)
    (folder / f"{MODEL}_start.csv").write_text("".join(f"{k},{v!r}\n" for k, v in start.items()))
    stop = round(steps * STEP, 10)
    (folder / f"{MODEL}_ref.opt").write_text(f"StartTime,0\nStopTime,{stop!r}\nStepSize,{STEP!r}\nRelTol,1e-6\n")
    runner = write_case.runners.get(fmu) or write_case.runners.setdefault(fmu, Runner(Path(fmu).read_bytes()))
    result = runner.run(Experiment(0.0, stop, STEP), Signals(inputs, start, ["y", "status"]))
    write_trace(folder / f"{MODEL}_ref.csv", result)


write_case.runners = {}


def generate(root, fmu, cases, steps):
    """The cases under root, made again only if the FMU or the sizes changed."""
    stamp = root / "stamp.json"
    key = {"fmu": hashlib.sha256(fmu.read_bytes()).hexdigest(), "cases": cases, "steps": steps, "version": 1}
    if stamp.exists() and json.loads(stamp.read_text()) == key:
        return 0.0
    started = time.perf_counter()
    work = [(root / "cases" / f"case_{i:05d}", i, steps, str(fmu)) for i in range(cases)]
    with Pool(os.cpu_count()) as pool:
        pool.map(write_case, work, chunksize=64)
    stamp.write_text(json.dumps(key))
    return time.perf_counter() - started


def plain_loop(fmu, folders):
    """Seconds per trace of the loop a user writes with fmpy."""
    from fmpy import simulate_fmu
    from fmpy.util import read_csv, read_ref_opt_file

    passed = 0
    started = time.perf_counter()
    for folder in folders:
        options = read_ref_opt_file(str(folder / f"{MODEL}_ref.opt"))
        inputs = read_csv(str(folder / f"{MODEL}_in.csv"))
        start = {
            k: float(v) for k, v in (line.split(",") for line in (folder / f"{MODEL}_start.csv").read_text().split())
        }
        with contextlib.redirect_stdout(io.StringIO()):
            result = simulate_fmu(
                str(fmu),
                start_time=options["StartTime"],
                stop_time=options["StopTime"],
                output_interval=options["StepSize"],
                input=inputs,
                start_values=start,
                output=["y", "status"],
            )
        reference = read_csv(str(folder / f"{MODEL}_ref.csv"))
        passed += all(np.array_equal(result[n], reference[n]) for n in ("y", "status"))
    seconds = (time.perf_counter() - started) / len(folders)
    if passed != len(folders):
        raise SystemExit(f"the plain loop found {len(folders) - passed} differences: fmpy and fmutrace disagree")
    return seconds


def command(fmu, root, jobs, report):
    """(wall seconds, CPU seconds, headline) of fmutrace compare on root's
    cases with --jobs jobs (None: the default)."""
    fmutrace = Path(sys.executable).parent / "fmutrace"
    args = [str(fmutrace), "compare", str(fmu), str(root), "--report", str(report)]
    args += ["--rel-tol", "1e-9"] + ([] if jobs is None else ["--jobs", str(jobs)])
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run(args, capture_output=True, text=True, timeout=3600)
    seconds = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if done.returncode != 0:
        raise SystemExit(f"fmutrace compare failed ({done.returncode}): {done.stdout[-2000:]} {done.stderr[-2000:]}")
    return seconds, cpu, done.stdout.strip().splitlines()[-2]


def peak_megabytes():
    """This process's peak resident memory: VmHWM, the high-water mark of
    its own address space (ru_maxrss would carry over the parent's peak
    across exec on Linux)."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def warm_up(cases):
    """Every file of the cases read once: the first way timed must not be the
    one that reads them from the disk."""
    for folder in cases.iterdir():
        for file in folder.iterdir():
            file.read_bytes()


def campaign_sizes(text):
    """'20x1000,2000x1000' -> [(20, 1000), (2000, 1000)]"""
    try:
        sizes = [tuple(int(n) for n in part.split("x")) for part in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"campaigns are CASESxSTEPS, comma separated, not {text!r}") from None
    if not sizes or any(len(size) != 2 or min(size) < 1 for size in sizes):
        raise argparse.ArgumentTypeError(f"campaigns are CASESxSTEPS, comma separated, not {text!r}")
    return sizes


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build-dir", type=Path, default=Path("build"))
    parser.add_argument("--campaigns", type=campaign_sizes, default=campaign_sizes(CAMPAIGNS))
    parser.add_argument("--sample", type=int, default=100, help="traces of the plain loop")
    parser.add_argument("--smoke", action="store_true", help="two tiny campaigns: keeps it working in CI")
    args = parser.parse_args()
    if args.smoke:
        args.campaigns, args.sample = [(20, 100), (40, 100)], 5
    build = args.build_dir.resolve()
    fmu = build / "fmi3" / f"{MODEL}.fmu"
    jobs = os.cpu_count() or 1
    root_of = {size: build / "benchmarks" / "campaign" / f"{size[0]}x{size[1]}" for size in args.campaigns}
    generated = sum(generate(root, fmu, *size) for size, root in root_of.items())

    # the plain loop on the shortest traces' campaign with the most cases (its per-step cost is what differs)
    plain_size = min(args.campaigns, key=lambda size: (size[1], -size[0]))
    folders = sorted((root_of[plain_size] / "cases").iterdir())
    sample = folders[:: max(1, len(folders) // args.sample)][: args.sample]
    plain = plain_loop(fmu, sample)

    ways = [("default", None), ("--jobs 1", 1), (f"--jobs {jobs}", jobs)]
    lines = [
        f"Campaign benchmark: {MODEL} FMI 3, {jobs} cores ({platform.machine()}, Python {platform.python_version()})"
        f"{' (SMOKE: figures meaningless)' if args.smoke else ''}",
        f"  cases generated in {generated:.1f} s" if generated else "  cases from an earlier run",
        f"  plain fmpy.simulate_fmu loop, 1 process: {plain * 1e3:.1f} ms per trace of {plain_size[1]:,} steps "
        f"({len(sample)} traces)",
        "",
        "| campaign | " + " | ".join(f"{name} wall (CPU)" for name, _ in ways) + " | default / fastest "
        "| default per core / plain |",
        "|---" * (len(ways) + 3) + "|",
    ]
    missed = []
    for size, root in root_of.items():
        cases, steps = size
        warm_up(root / "cases")
        figures = {}
        for _ in range(ROUNDS):  # each way's best of ROUNDS, the ways taking turns
            for name, j in ways:
                figure = command(fmu, root / "cases", j, root / f"report-{name.replace(' ', '')}")
                figures[name] = min(figures.get(name, figure), figure)
        default = figures["default"][0]
        fastest = min(figures[name][0] for name, _ in ways[1:])
        # traces per second per core against the plain loop's traces per second, on traces of its length
        per_core = cases * plain / (default * jobs) if steps == plain_size[1] else None
        lines.append(
            f"| {cases:,} x {steps:,} | "
            + " | ".join(f"{figures[name][0]:.2f} s ({figures[name][1]:.2f} s)" for name, _ in ways)
            + f" | {default / fastest:.2f} | "
            + (f"{per_core:.1f} x |" if per_core is not None else "- |")
        )
        lines.append(
            "|   where | " + " | ".join(figures[name][2].split(" on ")[-1].rstrip(").") for name, _ in ways) + " | | |"
        )
        if default > 1.1 * fastest:
            missed.append(f"{cases}x{steps}: the default took {default / fastest:.2f} times the fastest")
        if per_core is not None and cases >= RATIO_FROM_CASES and per_core < TARGET_RATIO:
            missed.append(f"{cases}x{steps}: {per_core:.1f} times the plain loop per core")
        if size == (10_000, 1000) and jobs <= 2 and default > TARGET_SECONDS:
            missed.append(f"10,000 x 1,000 took {default:.1f} s")
    lines.append("")
    lines.append(
        f"targets: the default within 10 % of the fastest; >= {TARGET_RATIO:g} x the plain loop per core "
        f"(from {RATIO_FROM_CASES:,} cases on); "
        f"10,000 x 1,000 in <= {TARGET_SECONDS:g} s on 2 cores"
    )
    print("\n".join(lines))
    (build / "benchmarks").mkdir(parents=True, exist_ok=True)
    (build / "benchmarks" / "campaign.txt").write_text("\n".join(lines) + "\n")
    if args.smoke or not missed:
        return 0
    print("MISSED: " + "; ".join(missed))
    return 1


if __name__ == "__main__":
    sys.exit(main())
