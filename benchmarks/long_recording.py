#!/usr/bin/env python3
"""Long-recording benchmark: a recorder's soak test of 1 h, 12 h and 48 h
at a 10 ms cycle (360,000 to 17,280,000 cycles) through fmutrace.

    long_recording.py --build-dir build [--hours 1 12 48] [--smoke]

1. Generates each recording once (kept under build/benchmarks/long/ while
   the generator is the same): the RateLimiter FMU (FMI 3), one input u
   and one output y as a case of the FMI cross-check layout. u is a random
   walk in steps of 1/64 that stays within the rate (100 per s, 1 per
   cycle), so the limiter passes it on: y is u one cycle later (a
   recorder's row holds the input and the output of the same cycle, fmpy
   records the output at the end of the step).
   The same soak test is also written as one file of a recorder's table
   export (time in ms, u and y in a row per cycle), and once more with
   stamps that jitter by up to 4 ms (40 % of the cycle; the cycle fit,
   recordings/_clock.py, lays each row on its cycle).
2. Prints, each in a fresh process: the wall time, user CPU time and the
   peak resident memory (VmHWM) of `fmutrace compare FMU CASE --report DIR`,
   of `fmutrace compare FMU RECORDING.csv --report DIR` (the one-file
   recording, streamed) and of `fmutrace run FMU --input IN.csv -o OUT.csv`; the time to only read the
   case's two files with fmutrace's CSV reader (the floor); and
   fmpy.simulate_fmu on the shortest recording (the anchor), with the
   ratio to `fmutrace run` on it.
Targets: 48 h compared (as a case and as a recording) and run in at most
60 s and 1 GB each; exit 1 if one is missed
(not with --smoke, which runs a 36 s recording to keep the script working
in CI).
"""

import argparse
import hashlib
import inspect
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

MODEL = "RateLimiter"
RECORDING = "recording.csv"  # the one-file recording beside the case folder
JITTERED = "recording_jitter.csv"  # the same with stamps that jitter by up to 40 % of the cycle (whole ms)
STEP = 0.01
TARGET_SECONDS, TARGET_MEGABYTES = 60.0, 1024.0


def recording(cycles, seed=31):
    """(time, u, y) of a recording of so many cycles (arrays)."""
    rng = np.random.default_rng(seed)
    steps = rng.integers(-16, 17, cycles, dtype=np.int64)  # in 1/64: at most 0.25 per cycle
    steps[0] = 0
    u = np.cumsum(steps) / 64.0  # exact: whole multiples of 1/64 far below 2^53
    time = np.arange(cycles + 1) / 100.0  # the cycle's start as the recorder writes it (k / 100, rounded once)
    y = np.concatenate([u[:1], u])  # initMode inputValue: y starts at u; then the input of the cycle before
    return time, u, y


def write_columns(path, columns):
    """A CSV file of named float64 columns (pyarrow's writer: numbers that read back bit for bit)."""
    import pyarrow as pa
    import pyarrow.csv as pcsv

    table = pa.table({name: values for name, values in columns.items()})
    pcsv.write_csv(table, path, write_options=pcsv.WriteOptions(quoting_style="none", batch_size=1 << 16))


def generator_key():
    return hashlib.sha256(
        (inspect.getsource(recording) + inspect.getsource(write_case) + inspect.getsource(write_recording)).encode()
    ).hexdigest()[:16]


def write_recording(path, cycles, jitter_ms=0, seed=7):
    """The same soak test as one file of a recorder's table export: a row per cycle, its time in ms, the
    cycle's input u and its output y (the limiter passes u on: y = u in the same cycle). jitter_ms: each
    stamp that many ms early or late at most (uniform, whole ms), as a cyclic interrupt's start jitters;
    the block takes its cycle from the step (nominal cycle lengths), so y is still u."""
    import pyarrow as pa
    import pyarrow.csv as pcsv

    _, u, _ = recording(cycles)
    stamps = np.arange(cycles, dtype=np.int64) * 10
    if jitter_ms:
        stamps[1:] += np.random.default_rng(seed).integers(-jitter_ms, jitter_ms + 1, cycles - 1)
    table = pa.table({"Time [ms]": stamps, "u": u, "y": u})
    pcsv.write_csv(table, path, write_options=pcsv.WriteOptions(quoting_style="none", batch_size=1 << 16))


def write_case(folder, cycles):
    time, u, y = recording(cycles)
    folder.mkdir(parents=True, exist_ok=True)
    write_columns(folder / f"{MODEL}_in.csv", {"time": time[:-1], "u": u})
    write_columns(folder / f"{MODEL}_ref.csv", {"time": time, "y": y})
    (folder / f"{MODEL}_start.csv").write_text("rateUpPar,100\nrateDownPar,100\n")
    (folder / f"{MODEL}_ref.opt").write_text(f"StartTime,0\nStopTime,{float(time[-1])!r}\nStepSize,{STEP!r}\n")
    (folder / "README.md").write_text(f"# {cycles} cycles of 10 ms: a random walk the limiter passes on\n")


def compare_recording(cli, fmu, path, cycles, long, recorded_lengths=False):
    """(seconds, MB, user seconds) of fmutrace compare on a one-file recording of so many cycles, which
    must pass, streamed if long (its report beside it). recorded_lengths: each step as long as the
    recorded interval (--cycle-lengths recorded), a verdict either way: the recording's outputs are those
    of steps of one cycle."""
    report = path.parent / f"report_{path.stem}{'_recorded' * recorded_lengths}"
    seconds, megabytes, status, output, user = measured(
        cli
        + ["compare", str(fmu), str(path), "--set", "rateUpPar=100", "--set", "rateDownPar=100"]
        + ["--report", str(report)]
        + (["--cycle-lengths", "recorded"] if recorded_lengths else [])
    )
    if status not in ((0, 1) if recorded_lengths else (0,)) or f"{cycles} samples" not in output:
        raise SystemExit(f"compare of {path} exited {status}:\n{output[-3000:]}")
    # a case is always read in chunks; a long one-file recording is streamed, a short one (--smoke) read whole
    streamed = [c.get("streamed", False) for c in json.loads((report / "results.json").read_text())["cases"]]
    if streamed != [long]:
        raise SystemExit(f"{path} was {'not ' * long}streamed")
    return seconds, megabytes, user


def generate(root, hours):
    """The case folder of a recording of so many hours (made once per generator)."""
    cycles = round(hours * 3600 / STEP)
    folder = root / f"{hours:g}h" / "case"
    stamp = folder.parent / f"generator-{generator_key()}.stamp"
    if not stamp.exists():
        for old in folder.parent.glob("generator-*.stamp"):
            old.unlink()
        started = time.perf_counter()
        # in a child: a forked command's peak memory (wait4's ru_maxrss) counts this process's pages at the fork
        subprocess.run([sys.executable, __file__, "--child", "generate", str(folder), str(cycles)], check=True)
        stamp.touch()
        print(f"generated {cycles:,} cycles in {folder} ({time.perf_counter() - started:.1f} s)", flush=True)
    return folder, cycles


def measured(command, timeout=None):
    """(seconds, peak MB, exit status, output, user CPU seconds) of a command in a fresh process: its own
    VmHWM and CPU time, from wait4. Killed after timeout seconds (status -9)."""
    started = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    timer = None
    if timeout is not None:
        import threading

        timer = threading.Timer(timeout, process.kill)
        timer.start()
    output = process.stdout.read()
    if timer is not None:
        timer.cancel()
    _, status, usage = os.wait4(process.pid, 0)
    seconds = time.perf_counter() - started
    process.returncode = os.waitstatus_to_exitcode(status)
    return seconds, usage.ru_maxrss / 1024, process.returncode, output.decode(errors="replace"), usage.ru_utime


def read_floor(paths):
    """Child: read the files with fmutrace's reader (chunks of columns, nothing else); prints the rows."""
    from fmutrace._traces import trace_chunks

    rows = 0
    for path in paths:
        for chunk in trace_chunks(path):
            rows += len(chunk)
    print(rows)


def fmpy_anchor(fmu, case):
    """Child: fmpy.simulate_fmu on the case as a user would call it; prints its seconds."""
    import fmpy

    inputs = fmpy.read_csv(str(case / f"{MODEL}_in.csv"))
    stop = float(np.loadtxt(case / f"{MODEL}_ref.opt", delimiter=",", dtype=str)[1, 1])
    started = time.perf_counter()
    fmpy.simulate_fmu(
        str(fmu),
        start_time=0.0,
        stop_time=stop,
        output_interval=STEP,
        input=inputs,
        start_values={"rateUpPar": 100.0, "rateDownPar": 100.0},
        output=["y"],
    )
    print(time.perf_counter() - started)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build-dir", type=Path, default=Path("build"))
    parser.add_argument("--hours", type=float, nargs="+", default=[1, 12, 48])
    parser.add_argument("--smoke", action="store_true", help="a 36 s recording: keeps the script working in CI")
    parser.add_argument("--anchor-timeout", type=float, default=900.0, help="seconds fmpy may take (default 900)")
    parser.add_argument("--child", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        kind, *rest = args.child
        if kind == "read":
            read_floor(rest)
        elif kind == "generate":
            write_case(Path(rest[0]), int(rest[1]))
            write_recording(Path(rest[0]).parent / RECORDING, int(rest[1]))
            write_recording(Path(rest[0]).parent / JITTERED, int(rest[1]), jitter_ms=4)
        else:
            fmpy_anchor(Path(rest[0]), Path(rest[1]))
        return 0
    if args.smoke:
        args.hours = [0.01]
    build = args.build_dir.resolve()
    fmu = build / "fmi3" / f"{MODEL}.fmu"
    root = build / "benchmarks" / "long"
    cli = [sys.executable, "-m", "fmutrace"]
    from fmutrace._recording import streamable
    from fmutrace._runner import C_STEPS

    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}; fmutrace's step loop in "
        f"{'C (_steps.c)' if C_STEPS is not None else 'Python (_steps.c is not built)'}"
    )
    rows, missed = [], []
    for hours in sorted(args.hours):
        case, cycles = generate(root, hours)
        report = root / f"{hours:g}h" / "report"
        seconds, megabytes, status, output, user = measured(
            cli + ["compare", str(fmu), str(case), "--report", str(report)]
        )
        if status != 0:
            raise SystemExit(f"compare of {hours:g} h exited {status}:\n{output[-3000:]}")
        one_file = case.parent / RECORDING
        rec_seconds, rec_megabytes, rec_user = compare_recording(cli, fmu, one_file, cycles, streamable(one_file))
        jit_seconds, jit_megabytes, jit_user = compare_recording(
            cli, fmu, case.parent / JITTERED, cycles, streamable(one_file)
        )
        lengths_seconds, lengths_megabytes, lengths_user = compare_recording(
            cli, fmu, case.parent / JITTERED, cycles, streamable(one_file), recorded_lengths=True
        )
        run_out = root / f"{hours:g}h" / "run_out.csv"
        run_seconds, run_megabytes, status, output, run_user = measured(
            cli
            + [
                "run",
                str(fmu),
                "--input",
                str(case / f"{MODEL}_in.csv"),
                "--set",
                "rateUpPar=100",
                "--set",
                "rateDownPar=100",
                "--step-size",
                repr(STEP),
                "--stop-time",
                repr(cycles * STEP),
                "--output",
                "y",
                "-o",
                str(run_out),
            ]
        )
        if status != 0:
            raise SystemExit(f"run of {hours:g} h exited {status}:\n{output[-3000:]}")
        read_seconds, read_megabytes, status, output, _ = measured(
            [sys.executable, __file__, "--child", "read", str(case / f"{MODEL}_in.csv"), str(case / f"{MODEL}_ref.csv")]
        )
        if status != 0 or int(output.split()[-1]) != 2 * cycles + 1:
            raise SystemExit(f"the reader read {output[-300:]!r}, expected {2 * cycles + 1} rows")
        rows.append(
            {
                "hours": hours,
                "cycles": cycles,
                "compare_s": seconds,
                "compare_user_s": user,
                "compare_MB": megabytes,
                "recording_s": rec_seconds,
                "recording_user_s": rec_user,
                "recording_MB": rec_megabytes,
                "jitter_s": jit_seconds,
                "jitter_user_s": jit_user,
                "jitter_MB": jit_megabytes,
                "lengths_s": lengths_seconds,
                "lengths_user_s": lengths_user,
                "lengths_MB": lengths_megabytes,
                "run_s": run_seconds,
                "run_user_s": run_user,
                "run_MB": run_megabytes,
                "read_s": read_seconds,
                "read_MB": read_megabytes,
            }
        )
        if hours == max(args.hours) and not args.smoke and hours >= 48:
            for what, s_, mb in (
                ("compare", seconds, megabytes),
                ("compare of the one-file recording", rec_seconds, rec_megabytes),
                ("compare of the jittered recording", jit_seconds, jit_megabytes),
                ("compare of the jittered recording, recorded cycle lengths", lengths_seconds, lengths_megabytes),
                ("run", run_seconds, run_megabytes),
            ):
                if s_ > TARGET_SECONDS or mb > TARGET_MEGABYTES:
                    missed.append(
                        f"{what} of {hours:g} h: {s_:.1f} s, {mb:.0f} MB "
                        f"(target {TARGET_SECONDS:g} s, {TARGET_MEGABYTES:g} MB)"
                    )
    print()
    print(
        "| recording | cycles | compare s (user) | compare MB | one-file recording s (user) | recording MB "
        "| jittered recording s (user) | jittered MB | recorded cycle lengths s (user) | recorded lengths MB "
        "| run s (user) | run MB | read only s | read MB |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(
            f"| {r['hours']:g} h | {r['cycles']:,} | {r['compare_s']:.1f} ({r['compare_user_s']:.1f}) | "
            f"{r['compare_MB']:.0f} | {r['recording_s']:.1f} ({r['recording_user_s']:.1f}) | "
            f"{r['recording_MB']:.0f} | {r['jitter_s']:.1f} ({r['jitter_user_s']:.1f}) | {r['jitter_MB']:.0f} | "
            f"{r['lengths_s']:.1f} ({r['lengths_user_s']:.1f}) | {r['lengths_MB']:.0f} | "
            f"{r['run_s']:.1f} ({r['run_user_s']:.1f}) | {r['run_MB']:.0f} | "
            f"{r['read_s']:.1f} | {r['read_MB']:.0f} |"
        )
    print("(MB: peak resident memory, VmHWM; user: the process's user CPU seconds)")

    shortest = rows[0]
    case = root / f"{shortest['hours']:g}h" / "case"
    seconds, _, status, output, _ = measured(
        [sys.executable, __file__, "--child", "fmpy", str(fmu), str(case)], timeout=args.anchor_timeout
    )
    if status == -9:
        anchor = None
        print(
            f"\nanchor: fmpy.simulate_fmu on {shortest['hours']:g} h ({shortest['cycles']:,} cycles) did not finish "
            f"within {args.anchor_timeout:g} s; fmutrace run on it: {shortest['run_s']:.1f} s in all, more than "
            f"{args.anchor_timeout / shortest['run_s']:.0f} times faster"
        )
    elif status != 0:
        raise SystemExit(f"fmpy.simulate_fmu failed:\n{output[-3000:]}")
    else:
        anchor = float(output.split()[-1])
        print(
            f"\nanchor: fmpy.simulate_fmu on {shortest['hours']:g} h ({shortest['cycles']:,} cycles): {anchor:.1f} s "
            f"of simulation ({anchor / shortest['cycles'] * 1e6:.1f} us per cycle); fmutrace run on it: "
            f"{shortest['run_s']:.1f} s in all, {anchor / shortest['run_s']:.1f} times faster"
        )
    print(json.dumps({"rows": rows, "fmpy_seconds": anchor}))
    for line in missed:
        print(f"MISSED: {line}")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
