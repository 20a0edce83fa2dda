#!/usr/bin/env python3
"""Campaign benchmark: traces per second of fmutrace compare against a plain
loop of fmpy.simulate_fmu calls, and the workers' peak memory.

    campaign.py --build-dir build [--cases 10000] [--steps 1000] [--smoke]

1. Generates the cases (once; kept under build/benchmarks/campaign/): the
   RateLimiter FMU (FMI 3), random inputs (u, a new value every 10 cycles;
   the bypass input at times) and parameters (rates up and down, cycle
   0.01 s), references (y and status) from a first run of fmutrace's runner.
2. (a) The plain loop as a user writes it, in one process, on a sample of
   the cases: fmpy's read_csv of the inputs, simulate_fmu, read_csv of the
   reference, np.array_equal; per trace.
   (b) fmutrace compare on all cases, the command, with a local worker on
   every core (wall time from the command's start to its exit).
   (c) The same campaign on a local cluster started here, at 1/10 and all
   of the cases, each on fresh workers: the peak memory of every worker.
Prints the figures and the targets; exit 1 if a figure misses its target
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
TARGET_RATIO, TARGET_SECONDS, TARGET_MEGABYTES = 10.0, 30.0, 300.0


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
    fmutrace = Path(sys.executable).parent / "fmutrace"
    started = time.perf_counter()
    done = subprocess.run(
        [
            str(fmutrace),
            "compare",
            str(fmu),
            str(root),
            "--jobs",
            str(jobs),
            "--report",
            str(report),
            "--plots",
            "failed",
        ],
        capture_output=True,
        text=True,
        timeout=3600,
    )
    seconds = time.perf_counter() - started
    if done.returncode != 0:
        raise SystemExit(f"fmutrace compare failed ({done.returncode}): {done.stdout[-2000:]} {done.stderr[-2000:]}")
    return seconds, done.stdout.strip().splitlines()[-2]


def peak_megabytes():
    """This process's peak resident memory: VmHWM, the high-water mark of
    its own address space (ru_maxrss would carry over the parent's peak
    across exec on Linux)."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def worker_peaks(fmu, folders_root, jobs, report):
    """Peak memory (MB) of each worker of a fresh local cluster after the campaign."""
    from dask.distributed import Client, LocalCluster

    import fmutrace

    import dask

    with (
        dask.config.set({"distributed.worker.profile.enabled": False}),
        LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True, dashboard_address=None) as cluster,
        Client(cluster) as client,
    ):
        campaign = fmutrace.compare(
            fmu,
            folders_root,
            report=report,
            plots="failed",
            run=fmutrace.RunOptions(scheduler=cluster.scheduler_address, shared_files=True, cluster_timeout=3600),
        )
        if not campaign.passed:
            raise SystemExit(campaign.summary()[:3000])
        peaks = client.run(peak_megabytes)
    return sorted(peaks.values()), len(campaign.cases)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build-dir", type=Path, default=Path("build"))
    parser.add_argument("--cases", type=int, default=10_000)
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--sample", type=int, default=100, help="traces of the plain loop")
    parser.add_argument("--smoke", action="store_true", help="40 cases of 100 steps: keeps it working in CI")
    args = parser.parse_args()
    if args.smoke:
        args.cases, args.steps, args.sample = 40, 100, 5
    build = args.build_dir.resolve()
    fmu = build / "fmi3" / f"{MODEL}.fmu"
    root = build / "benchmarks" / "campaign" / f"{args.cases}x{args.steps}"
    jobs = os.cpu_count()

    generated = generate(root, fmu, args.cases, args.steps)
    folders = sorted((root / "cases").iterdir())
    sample = folders[:: max(1, len(folders) // args.sample)][: args.sample]
    plain = plain_loop(fmu, sample)
    wall, headline = command(fmu, root / "cases", jobs, root / "report")
    tenth = root / "tenth"
    if not tenth.exists():  # a tenth of the cases, as links
        tenth.mkdir()
        for folder in folders[: len(folders) // 10]:
            (tenth / folder.name).symlink_to(folder)
    peaks_tenth, n_tenth = worker_peaks(fmu, tenth, jobs, root / "report-tenth")
    peaks_all, n_all = worker_peaks(fmu, root / "cases", jobs, root / "report-all")

    plain_rate = 1 / plain
    rate = len(folders) / wall
    ratio = rate / jobs / plain_rate
    lines = [
        f"Campaign benchmark: {len(folders)} cases of {args.steps} steps, {MODEL} FMI 3, {jobs} cores "
        f"({platform.machine()}, Python {platform.python_version()})"
        f"{' (SMOKE: figures meaningless)' if args.smoke else ''}",
        f"  cases generated in {generated:.1f} s" if generated else "  cases from an earlier run",
        f"  (a) plain fmpy.simulate_fmu loop, 1 process: {plain * 1e3:.1f} ms per trace, {plain_rate:.1f} traces/s "
        f"({len(sample)} traces)",
        f"  (b) fmutrace compare, {jobs} local workers: {wall:.1f} s, {rate:.0f} traces/s "
        f"({rate / jobs:.0f} per core): {headline}",
        f"  per core, (b) / (a): {ratio:.1f} x (target >= {TARGET_RATIO:g})",
        f"  {len(folders)} traces in {wall:.1f} s (target <= {TARGET_SECONDS:g} s at 10,000 x 1,000 on 2 cores)",
        f"  worker peak memory: {', '.join(f'{p:.0f}' for p in peaks_tenth)} MB at {n_tenth} traces, "
        f"{', '.join(f'{p:.0f}' for p in peaks_all)} MB at {n_all} (target <= {TARGET_MEGABYTES:g} MB, flat)",
    ]
    print("\n".join(lines))
    (build / "benchmarks").mkdir(parents=True, exist_ok=True)
    (build / "benchmarks" / "campaign.txt").write_text("\n".join(lines) + "\n")
    if args.smoke:
        return 0
    missed = []
    if ratio < TARGET_RATIO:
        missed.append("ratio")
    if args.cases >= 10_000 and jobs <= 2 and wall > TARGET_SECONDS:
        missed.append("wall time")
    if max(peaks_all) > TARGET_MEGABYTES or max(peaks_all) > 1.1 * max(peaks_tenth) + 5:
        missed.append("memory")
    if missed:
        print(f"MISSED: {', '.join(missed)}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
