#!/usr/bin/env python3
"""All benchmarks, one table: per-step cost of RateLimiter in C (wall time
and callgrind instructions, next to the kernel's cycle function and the
PassThrough fixture) and through fmpy (against PassThrough).

    run.py --build-dir build [--smoke]

--smoke runs every benchmark with few steps so that CI keeps them working;
its figures mean nothing. Figures are printed, and written to
<build>/benchmarks/results.md and results.json; no figure fails the run.
"""

import argparse
import contextlib
import io
import json
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from fmpy import read_model_description, simulate_fmu

MODEL = "RateLimiter"
FIXTURE = "PassThrough"
PLATFORM = {2: "linux64", 3: "x86_64-linux"}

# the targets (docs/performance.md), and the anchors measured on the Reference FMUs
# (Feedthrough, -O3) and fmpy
TARGETS = {
    "step_instructions": 150,
    "doStep_instructions": 60,
    "subcycle_instructions": 25,
    # the same budgets for the REAL (binary32) path
    "real_step_instructions": 150,
    "real_doStep_instructions": 60,
    "real_subcycle_instructions": 25,
    "step_over_kernel": 2.0,
    "instance_bytes": 1024,
    "fmpy_ratio": 1.05,
}
ANCHORS = {
    2: {"step_instructions": 539, "doStep_instructions": 118, "fmpy_steps_per_s": 90000},
    3: {"step_instructions": 582, "doStep_instructions": 140, "fmpy_steps_per_s": 75000},
}


def model_info(build, model, version):
    stage = build / "stage" / f"fmi{version}" / model
    scheduled = build / "stage" / "fmi3-se" / model  # cmake/Fmu.cmake's FMI3_SE_FOLDER
    if version == 3 and scheduled.is_dir():
        # the Scheduled Execution FMU's stage: the same binary, and the model description with the Clock that
        # fmu_bench activates beside doStep (the Co-Simulation FMU declares none, FMI 3.0 4.4)
        stage = scheduled
    md = read_model_description(str(stage / "modelDescription.xml"))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    token = md.guid if version == 2 else md.instantiationToken
    binary = stage / "binaries" / PLATFORM[version] / f"{model}.so"
    return binary, token, vr


# Output limits and rates below 0 in use (second row): output limits far from the
# ramp and other rates below 0, so that only their cost shows
FEATURES = {"yMaxPar": 1e300, "yMinPar": -1e300, "rateUpNeg": 2.0, "rateDownNeg": 2.0}


# The REAL (binary32) path: the Ramp FB, whose pins are REAL (rules.md, Arithmetic)
REAL_MODEL = "Ramp"
# each model's input u and output y
PINS = {"RateLimiter": ("u", "y"), "Ramp": ("rIn", "rOut"), "PassThrough": ("u", "y")}


def bench_args(build, model, version, steps, repeats, start=None):
    binary, token, vr = model_info(build, model, version)
    extra = [f"{vr[name]}={value!r}" for name, value in (start or {}).items()]
    u, y = PINS[model]
    return [
        str(build / "fmu_bench"),
        str(version),
        str(binary),
        token,
        str(vr[u]),
        str(vr[y]),
        str(vr.get("cycleTime", -1)),
        str(steps),
        str(repeats),
    ] + extra


def parse(output):
    figures = {}
    for line in output.splitlines():
        name, value, _unit = line.split()
        figures[name] = float(value)
    return figures


def run_native(build, model, version, steps, repeats):
    out = subprocess.run(
        bench_args(build, model, version, steps, repeats), check=True, capture_output=True, text=True
    ).stdout
    return parse(out)


ANNOTATE_LINE = re.compile(r"^\s*([\d,]+) \([^)]*\)\s+\S*?:(\w+) \[(.+)\]$")
CALLS = {2: ("fmi2SetReal", "fmi2DoStep", "fmi2GetReal"), 3: ("fmi3SetFloat64", "fmi3DoStep", "fmi3GetFloat64")}


def inclusive_costs(dump):
    """Instructions of each function, callees included, in one dump."""
    out = subprocess.run(
        ["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(dump)],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    costs = {}
    for line in out.splitlines():
        m = ANNOTATE_LINE.match(line)
        if m:
            costs[m.group(2)] = costs.get(m.group(2), 0) + int(m.group(1).replace(",", ""))
    return costs


def run_callgrind(build, model, version, steps, start=None):
    """Instructions per call, from the calls themselves (callees included,
    the benchmark loop not), for each measured loop."""
    with tempfile.TemporaryDirectory() as tmp:
        out_file = Path(tmp) / "callgrind.out"
        subprocess.run(
            ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out_file}"]
            + bench_args(build, model, version, steps, 1, start),
            check=True,
            capture_output=True,
            text=True,
        )
        loops = {}
        for dump in Path(tmp).glob("callgrind.out.*"):
            label = re.search(r"^desc: Trigger: Client Request: (\w+)", dump.read_text(), re.M)
            if label:
                loops[label.group(1)] = inclusive_costs(dump)
    set_, do_step, get = CALLS[version]
    figures = {
        "kernel_instructions": loops["kernel"]["rl_cycle"] / steps,
        "step_instructions": sum(loops["step"].get(f, 0) for f in CALLS[version]) / steps,
        "doStep_instructions": loops["doStep"][do_step] / steps,
        "set_instructions": loops["step"].get(set_, 0) / steps,
        "get_instructions": loops["step"].get(get, 0) / steps,
    }
    if "cyclesN" in loops:
        cycle_steps = steps // 100 + 1
        figures["subcycle_instructions"] = (loops["cyclesN"][do_step] - loops["cycles1"][do_step]) / cycle_steps / 99
    return figures


def fmpy_time(fmu, steps, repeats):
    """Median wall time of simulate_fmu with one input signal and y recorded."""
    h = 1e-3
    t = np.arange(steps + 1) * h
    signal = np.array(
        list(zip(t, np.where((np.arange(steps + 1) // 4096) % 2, -1000.0, 1000.0), strict=True)),
        dtype=[("time", np.float64), ("u", np.float64)],
    )
    times = []
    for _ in range(repeats):
        # fmpy prints a warning for each input left out of the signal: they
        # keep their start values here on purpose
        with contextlib.redirect_stdout(io.StringIO()):
            start = time.perf_counter()
            simulate_fmu(
                str(fmu),
                start_time=0.0,
                stop_time=steps * h,
                step_size=h,
                output_interval=h,
                input=signal,
                output=["y"],
            )
            times.append(time.perf_counter() - start)
    return float(np.median(times))


def run_fmpy(build, version, steps, repeats):
    model_fmu = build / f"fmi{version}" / f"{MODEL}.fmu"
    fixture_fmu = build / "benchmarks" / f"fmi{version}" / f"{FIXTURE}.fmu"
    model_times, fixture_times = [], []
    for _ in range(repeats):  # interleaved, so that drift hits both alike
        model_times.append(fmpy_time(model_fmu, steps, 1))
        fixture_times.append(fmpy_time(fixture_fmu, steps, 1))
    model_s, fixture_s = float(np.median(model_times)), float(np.median(fixture_times))
    return {
        "fmpy_steps_per_s": steps / model_s,
        "fmpy_fixture_steps_per_s": steps / fixture_s,
        "fmpy_ratio": model_s / fixture_s,
    }


def check(name, value):
    target = TARGETS.get(name)
    if target is None:
        return ""
    return "yes" if value <= target else "NO"


def table(results, smoke, commands):
    rows = [
        ("instructions, set u + doStep + get y", "step_instructions", "{:.0f}", "<= 150"),
        ("instructions, doStep alone", "doStep_instructions", "{:.0f}", "<= 60"),
        (
            "instructions, set u + doStep + get y, limits and Neg rates in use",
            "features_step_instructions",
            "{:.0f}",
            "",
        ),
        ("instructions, doStep alone, limits and Neg rates in use", "features_doStep_instructions", "{:.0f}", ""),
        ("instructions per extra sub-cycle", "subcycle_instructions", "{:.1f}", "<= 25"),
        ("instructions, set u + doStep + get y, REAL (Ramp)", "real_step_instructions", "{:.0f}", "<= 150"),
        ("instructions, doStep alone, REAL (Ramp)", "real_doStep_instructions", "{:.0f}", "<= 60"),
        ("instructions per extra sub-cycle, REAL (Ramp)", "real_subcycle_instructions", "{:.1f}", "<= 25"),
        ("instructions, set u alone / get y alone", "set_get_instructions", "{}", ""),
        ("instructions, kernel rl_cycle (floor)", "kernel_instructions", "{:.0f}", ""),
        ("instructions, PassThrough set + doStep + get", "fixture_step_instructions", "{:.0f}", ""),
        ("ns, set u + doStep + get y (median)", "step_ns", "{:.2f}", ""),
        ("ns, 1,000 instances in turn, set u + doStep + get y of each (median)", "instances1000_ns", "{:.2f}", ""),
        ("ns, kernel rl_cycle call (median)", "kernel_ns", "{:.2f}", ""),
        ("ratio step / kernel", "step_over_kernel", "{:.2f}", "<= 2"),
        ("ns, PassThrough set + doStep + get", "fixture_step_ns", "{:.2f}", ""),
        ("allocations in 10 steps", "allocations_in_10_steps", "{:.0f}", "= 1e6 steps"),
        ("allocations in 1,000,000 steps", "allocations_in_1000000_steps", "{:.0f}", "= 10 steps"),
        ("bytes per instance", "instance_bytes", "{:.0f}", "<= 1024"),
        ("fmpy simulate_fmu steps/s", "fmpy_steps_per_s", "{:,.0f}", ""),
        ("fmpy PassThrough steps/s", "fmpy_fixture_steps_per_s", "{:,.0f}", ""),
        ("fmpy time ratio RateLimiter / PassThrough", "fmpy_ratio", "{:.3f}", "<= 1.05"),
    ]
    lines = ["| figure | FMI 2 | FMI 3 | target | met | anchor FMI 2 / 3 |", "|---|---|---|---|---|---|"]
    for label, key, fmt, target in rows:
        cells, met = [], []
        for version in (2, 3):
            value = results[version].get(key)
            cells.append(fmt.format(value) if value is not None else "n/a")
            if value is not None and key in TARGETS:
                met.append(check(key, value))
        if key.startswith("allocations"):
            same = results[2].get("allocations_in_10_steps") == results[2].get(
                "allocations_in_1000000_steps"
            ) and results[3].get("allocations_in_10_steps") == results[3].get("allocations_in_1000000_steps")
            met = ["yes" if same else "NO"]
        anchor = " / ".join(str(ANCHORS[v].get(key, "")) for v in (2, 3)) if key in ANCHORS[2] else ""
        verdict = "NO" if "NO" in met else ("yes" if met else "")
        lines.append(f"| {label} | {cells[0]} | {cells[1]} | {target} | {verdict} | {anchor} |")
    header = [
        f"Machine: {platform.processor() or platform.machine()}, {platform.node()}, "
        f"Python {platform.python_version()}{' (SMOKE: figures meaningless)' if smoke else ''}",
        "",
    ]
    return "\n".join(header + lines + ["", "Commands:"] + [f"- `{c}`" for c in commands]) + "\n"


def cpu_name():
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.machine()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build-dir", type=Path, default=Path("build"))
    parser.add_argument("--smoke", action="store_true", help="few steps: keeps the benchmarks working in CI")
    args = parser.parse_args()
    build = args.build_dir.resolve()

    c_steps, c_repeats = (2000, 3) if args.smoke else (1_000_000, 11)
    cg_steps = 1000 if args.smoke else 100_000
    fmpy_steps, fmpy_repeats = (1000, 1) if args.smoke else (100_000, 5)
    have_valgrind = shutil.which("valgrind") is not None

    results, commands = {}, []
    for version in (2, 3):
        r = run_native(build, MODEL, version, c_steps, c_repeats)
        fixture = run_native(build, FIXTURE, version, c_steps, c_repeats)
        r["fixture_step_ns"] = fixture["step_ns"]
        if have_valgrind:
            r.update(run_callgrind(build, MODEL, version, cg_steps))
            r["set_get_instructions"] = f"{r.pop('set_instructions'):.0f} / {r.pop('get_instructions'):.0f}"
            r["fixture_step_instructions"] = run_callgrind(build, FIXTURE, version, cg_steps)["step_instructions"]
            features = run_callgrind(build, MODEL, version, cg_steps, FEATURES)
            r["features_step_instructions"] = features["step_instructions"]
            r["features_doStep_instructions"] = features["doStep_instructions"]
            real = run_callgrind(build, REAL_MODEL, version, cg_steps)
            for key in ("step_instructions", "doStep_instructions", "subcycle_instructions"):
                r[f"real_{key}"] = real[key]
        r.update(run_fmpy(build, version, fmpy_steps, fmpy_repeats))
        results[version] = r
        print(
            f"FMI {version}: "
            + ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in sorted(r.items())),
            flush=True,
        )
    commands.append(
        " ".join(
            [
                "build/fmu_bench",
                "<2|3>",
                "<binary.so>",
                "<token>",
                "<u_vr>",
                "<y_vr>",
                "<cycleTime_vr>",
                str(c_steps),
                str(c_repeats),
            ]
        )
        + "  (wall time, allocations)"
    )
    commands.append(
        f"valgrind --tool=callgrind build/fmu_bench ... {cg_steps} 1, then callgrind_annotate --inclusive=yes"
        "  (instructions per call, callees included)"
    )
    commands.append(f"fmpy.simulate_fmu, {fmpy_steps} steps of 1 ms, input u, output y, median of {fmpy_repeats}")
    if not have_valgrind:
        print("valgrind not found: no instruction counts", file=sys.stderr)

    report = table(results, args.smoke, commands).replace(platform.processor() or platform.machine(), cpu_name(), 1)
    out_dir = build / "benchmarks"
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "results.md").write_text(report)
    (out_dir / "results.json").write_text(json.dumps({str(k): v for k, v in results.items()}, indent=2))
    print()
    print(report)


if __name__ == "__main__":
    main()
