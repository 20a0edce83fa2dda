#!/usr/bin/env python3
"""Campaign memory benchmark: the client's and each worker's peak memory
over a campaign of many short cases, at a tenth of them and at all.

    campaign_memory.py --build-dir build [--cases 100000] [--steps 10] [--smoke]

Generates the cases as campaign.py does (kept under
build/benchmarks/campaign/<cases>x<steps>/), then runs each campaign in a
fresh process: fmutrace.compare with a report folder and its default
local worker processes (the command's way). That process (the client)
reports its peak resident memory (VmHWM), and the largest of its
workers' peaks. Memory is flat when the peaks at all the cases are
within 10 % (+ 10 MB) of those at a tenth; exit 1 if not (not with
--smoke).
"""

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

from campaign import MODEL, generate, peak_megabytes

FLAT_FACTOR, FLAT_MEGABYTES = 1.1, 10.0


def child(fmu, cases, report, jobs):
    """One campaign in this process, on fmutrace's default local workers
    (jobs of them at most); prints its figures as JSON."""
    import resource

    import fmutrace

    started = time.perf_counter()
    campaign = fmutrace.compare(fmu, cases, report=report, plots="failed")
    counts = campaign.counts()
    # the largest of the workers' peaks (the kernel keeps the largest of the children waited for)
    largest_worker = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(
        json.dumps(
            {
                "cases": sum(counts.values()),
                "passed": counts["pass"],
                "client": peak_megabytes(),
                "workers": [largest_worker],
                "where": campaign.where,
                "seconds": time.perf_counter() - started,
            }
        )
    )


def measure(fmu, cases, report, jobs):
    done = subprocess.run(
        [sys.executable, __file__, "--child", str(fmu), str(cases), str(report), str(jobs)],
        capture_output=True,
        text=True,
        timeout=7200,
    )
    if done.returncode:
        raise SystemExit(f"the campaign failed ({done.returncode}): {done.stdout[-2000:]} {done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build-dir", type=Path, default=Path("build"))
    parser.add_argument("--cases", type=int, default=100_000)
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--smoke", action="store_true", help="200 cases: keeps it working in CI")
    parser.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        fmu, cases, report, jobs = args.child
        child(fmu, cases, report, int(jobs))
        return 0
    if args.smoke:
        args.cases = 200
    build = args.build_dir.resolve()
    fmu = build / "fmi3" / f"{MODEL}.fmu"
    root = build / "benchmarks" / "campaign" / f"{args.cases}x{args.steps}"
    jobs = os.cpu_count()
    generated = generate(root, fmu, args.cases, args.steps)
    tenth = root / "tenth"
    if not tenth.exists():  # a tenth of the cases, as links
        tenth.mkdir()
        for folder in sorted((root / "cases").iterdir())[: args.cases // 10]:
            (tenth / folder.name).symlink_to(folder)
    figures = {
        name: measure(fmu, folder, root / f"report-{name}", jobs)
        for name, folder in (("tenth", tenth), ("all", root / "cases"))
    }
    lines = [
        f"Campaign memory: {args.cases} cases of {args.steps} steps, {MODEL} FMI 3, {jobs} cores "
        f"({platform.machine()}, Python {platform.python_version()})"
        f"{' (SMOKE: figures meaningless)' if args.smoke else ''}",
        f"  cases generated in {generated:.0f} s" if generated else "  cases from an earlier run",
    ]
    for f in figures.values():
        lines.append(
            f"  {f['cases']} cases ({f['passed']} pass) in {f['seconds']:.0f} s on {f['where']}: client "
            f"{f['client']:.0f} MB, the largest worker {max(f['workers']):.0f} MB"
        )
    print("\n".join(lines))
    if args.smoke:
        return 0
    tenth_figures, all_figures = figures["tenth"], figures["all"]
    flat = (
        all(all_figures[k] <= FLAT_FACTOR * tenth_figures[k] + FLAT_MEGABYTES for k in ("client",))
        and max(all_figures["workers"]) <= FLAT_FACTOR * max(tenth_figures["workers"]) + FLAT_MEGABYTES
    )
    if all_figures["passed"] != args.cases or not flat:
        print("MISSED: " + ("not every case passed" if all_figures["passed"] != args.cases else "memory not flat"))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
