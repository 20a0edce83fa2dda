#!/usr/bin/env python3
"""Reference scenarios: run each through fmpy.simulate_fmu on the FMI 2 and
FMI 3 FMUs, compare with the reference trace, and write a report.

A scenario is a folder tests/scenarios/<Model>/<name>/ in the FMI
cross-check layout:

  <Model>_ref.opt    StartTime, StopTime, StepSize, RelTol (fmpy reads it)
  <Model>_in.csv     input signals (optional); a row holds from its time on
  <Model>_ref.csv    the reference trace, worked by hand from the contract
  <Model>_start.csv  start values, one "name,value" line each (optional)
  README.md          what it shows and how the reference was worked out

StepSize is the communication step. A sample is a match when
|fmu - ref| <= RelTol * max(1, |ref|); NaN matches NaN, inf matches inf.

Main job:  reference.py --build-dir build --report build/report
"""
import argparse
import contextlib
import io
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu
from fmpy.util import read_csv, read_ref_opt_file, write_csv

SCENARIO_ROOT = Path(__file__).resolve().parent / "scenarios"
FMI_VERSIONS = (2, 3)


@dataclass
class Scenario:
    model: str
    name: str
    folder: Path
    options: dict
    start_values: dict
    inputs: object          # structured array or None
    reference: object       # structured array
    description: str = ""

    @property
    def id(self):
        return f"{self.model}/{self.name}"

    @property
    def outputs(self):
        return [n for n in self.reference.dtype.names if n != "time"]


def read_start_values(path):
    values = {}
    if path.exists():
        for line in path.read_text().splitlines():
            if line.strip() and not line.startswith("#"):
                name, literal = (s.strip() for s in line.split(",", 1))
                values[name] = literal_value(literal)
    return values


def literal_value(literal):
    if literal in ("true", "false"):
        return literal == "true"
    number = float(literal)
    return int(number) if number.is_integer() and "." not in literal and "e" not in literal.lower() else number


def read_inputs(path, stop_time):
    """The input table; fmpy needs two samples, so a single row is held
    until StopTime by a copy there (the same signal)."""
    if not path.exists():
        return None
    inputs = np.atleast_1d(read_csv(path))
    if len(inputs) == 1:
        last = inputs.copy()
        last["time"] = stop_time
        inputs = np.concatenate([inputs, last])
    return inputs


def load(folder):
    folder = Path(folder)
    model = folder.parent.name
    readme = folder / "README.md"
    options = read_ref_opt_file(folder / f"{model}_ref.opt")
    return Scenario(
        model=model,
        name=folder.name,
        folder=folder,
        options=options,
        start_values=read_start_values(folder / f"{model}_start.csv"),
        inputs=read_inputs(folder / f"{model}_in.csv", options["StopTime"]),
        reference=read_csv(folder / f"{model}_ref.csv"),
        description=readme.read_text().strip().splitlines()[0].lstrip("# ") if readme.exists() else "",
    )


def discover(models=None):
    folders = sorted(p.parent for p in SCENARIO_ROOT.glob("*/*/*_ref.opt"))
    return [load(f) for f in folders if models is None or f.parent.name in models]


def fmu_path(build_dir, model, version):
    return Path(build_dir) / f"fmi{version}" / f"{model}.fmu"


def simulate(scenario, fmu):
    o = scenario.options
    with contextlib.redirect_stdout(io.StringIO()):  # fmpy's notes on unset inputs
        return simulate_fmu(
            str(fmu),
            start_time=o["StartTime"],
            stop_time=o["StopTime"],
            output_interval=o["StepSize"],
            input=scenario.inputs,
            start_values=scenario.start_values,
            output=scenario.outputs,
            fmi_type="CoSimulation",
        )


def same(value, expected, tolerance):
    value, expected = float(value), float(expected)
    if math.isnan(expected) or math.isinf(expected):
        return (math.isnan(value) and math.isnan(expected)) or value == expected
    return abs(value - expected) <= tolerance * max(1.0, abs(expected))


def compare(scenario, result):
    """Differences between a result and the reference, as readable lines."""
    ref = scenario.reference
    tol = scenario.options["RelTol"]
    problems = []
    if len(result) != len(ref):
        return [f"{len(result)} samples, the reference has {len(ref)}"]
    for i in range(len(ref)):
        if not same(result["time"][i], ref["time"][i], tol):
            return [f"sample {i}: time {result['time'][i]!r}, the reference has {ref['time'][i]!r}"]
        for name in scenario.outputs:
            if not same(result[name][i], ref[name][i], tol):
                problems.append(f"t={ref['time'][i]:g}: {name} = {float(result[name][i])!r}, "
                                f"reference {float(ref[name][i])!r}")
    return problems


@dataclass
class Outcome:
    scenario: str
    version: int
    problems: list = field(default_factory=list)
    seconds: float = 0.0
    csv: str = ""
    plot: str = ""

    @property
    def passed(self):
        return not self.problems


def plot(scenario, result, path, version):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = scenario.outputs
    fig, axes = plt.subplots(len(names) + (scenario.inputs is not None), 1, sharex=True,
                             figsize=(8, 1.9 * (len(names) + 1)), squeeze=False)
    axes = axes[:, 0]
    row = 0
    if scenario.inputs is not None:
        ax = axes[0]
        t_end = scenario.options["StopTime"]
        for name in scenario.inputs.dtype.names[1:]:
            t = np.append(scenario.inputs["time"], t_end)
            v = np.append(scenario.inputs[name], scenario.inputs[name][-1])
            ax.step(t, v, where="post", label=f"input {name}")
        ax.legend(loc="best", fontsize=8)
        row = 1
    for ax, name in zip(axes[row:], names):
        ax.step(scenario.reference["time"], scenario.reference[name], where="post", color="0.6",
                linewidth=4, label=f"{name} reference")
        ax.step(result["time"], result[name], where="post", color="C1", linewidth=1.2, marker=".",
                label=f"{name} FMU (FMI {version})")
        ax.legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(f"{scenario.id}: {scenario.description}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def run_one(folder, build_dir, version, report_dir=None):
    scenario = load(folder)
    started = time.perf_counter()
    outcome = Outcome(scenario.id, version)
    try:
        result = simulate(scenario, fmu_path(build_dir, scenario.model, version))
        outcome.problems = compare(scenario, result)
    except Exception as exception:  # a failed simulation is a failed scenario
        outcome.problems = [f"simulation failed: {exception}"]
        result = None
    outcome.seconds = time.perf_counter() - started
    if report_dir is not None and result is not None:
        stem = Path(report_dir) / f"fmi{version}" / scenario.model / scenario.name
        stem.parent.mkdir(parents=True, exist_ok=True)
        write_csv(f"{stem}_out.csv", result)
        plot(scenario, result, f"{stem}.png", version)
        outcome.csv, outcome.plot = f"{stem}_out.csv", f"{stem}.png"
    return outcome


def write_report(outcomes, report_dir, wall):
    report_dir = Path(report_dir)
    passed = sum(o.passed for o in outcomes)
    lines = ["# Reference scenarios", "",
             f"{passed} of {len(outcomes)} runs match their reference; wall time {wall:.1f} s.", "",
             "| scenario | FMI | result | seconds | plot |", "|---|---|---|---|---|"]
    for o in outcomes:
        plot_link = os.path.relpath(o.plot, report_dir) if o.plot else ""
        verdict = "pass" if o.passed else "FAIL: " + "; ".join(o.problems[:3])
        lines.append(f"| {o.scenario} | {o.version} | {verdict} | {o.seconds:.2f} | "
                     + (f"[png]({plot_link})" if plot_link else "") + " |")
    (report_dir / "summary.md").write_text("\n".join(lines) + "\n")
    return passed


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build-dir", default="build")
    parser.add_argument("--report", default=None, help="folder for result CSVs, plots and summary.md")
    parser.add_argument("--model", action="append", help="only these models (repeatable)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count())
    args = parser.parse_args(argv)

    scenarios = discover(args.model)
    if not scenarios:
        print("no scenarios found")
        return 1
    report = Path(args.report) if args.report else None
    if report:
        report.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    work = [(s.folder, args.build_dir, v, report) for s in scenarios for v in FMI_VERSIONS]
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        outcomes = list(pool.map(run_one, *zip(*work)))
    wall = time.perf_counter() - started
    for o in outcomes:
        print(f"{'pass' if o.passed else 'FAIL'}  FMI {o.version}  {o.scenario}")
        for problem in o.problems[:10]:
            print(f"      {problem}")
    passed = sum(o.passed for o in outcomes)
    if report:
        write_report(outcomes, report, wall)
        print(f"report: {report / 'summary.md'}")
    print(f"{passed} passed, {len(outcomes) - passed} failed (wall time {wall:.1f} s on {args.jobs} processes)")
    return 0 if passed == len(outcomes) else 1


if __name__ == "__main__":
    sys.exit(main())
