#!/usr/bin/env python3
"""Reference scenarios: run each through fmpy.simulate_fmu on the FMI 2 and
FMI 3 FMUs, compare with the reference trace, and write a report.

A scenario is a folder <root>/<Model>/<name>/ in the FMI cross-check
layout:

  <Model>_ref.opt    StartTime, StopTime, StepSize, RelTol (fmpy reads it)
  <Model>_in.csv     input signals (optional); a row holds from its time on
  <Model>_ref.csv    the reference trace, worked by hand from the contract
  <Model>_start.csv  start values, one "name,value" line each (optional)
  README.md          what it shows and how the reference was worked out

StepSize is the communication step. A sample is a match when
|fmu - ref| <= RelTol * max(1, |ref|); NaN matches NaN, inf matches inf.

Main job:  python -m fmutrace.campaign tests/scenarios --build-dir build --report build/report
On a cluster:  python -m fmutrace.campaign ... --scheduler tcp://host:8786

Runs are Dask tasks: on a local cluster of processes (one per core) by
default, on a Dask distributed scheduler with --scheduler, in this process
with --serial. A task carries the scenario and the FMU's bytes and returns
the result, its comparison and its plot, so workers need the same Python
packages (fmutrace itself is uploaded to them) but no shared file system;
the report is written here.
"""
import argparse
import contextlib
import hashlib
import html
import io
import math
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu
from fmpy.util import read_csv, read_ref_opt_file, write_csv

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


def discover(root, models=None):
    """The scenarios under root (<root>/<Model>/<name>/), optionally of
    some models only."""
    folders = sorted(p.parent for p in Path(root).glob("*/*/*_ref.opt"))
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


def compare(scenario, result, reference=None):
    """Differences between a result and the reference (or the rows of it
    given), as readable lines."""
    ref = scenario.reference if reference is None else reference
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
    """The plot as PNG into path (a file name or a binary stream)."""
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
    fig.savefig(path, dpi=80, format="png", metadata={"Software": None})
    plt.close(fig)


def fmu_on_this_host(fmu_bytes):
    """The FMU written once per worker process, named by its content."""
    path = Path(tempfile.gettempdir()) / f"rl-campaign-{hashlib.sha256(fmu_bytes).hexdigest()[:16]}.fmu"
    if not path.exists():
        partial = path.with_suffix(f".{os.getpid()}.part")
        partial.write_bytes(fmu_bytes)
        partial.replace(path)
    return path


def run_one(scenario, fmu_bytes, version, with_plot=True):
    """One scenario on one FMU: where the work happens (any worker)."""
    started = time.perf_counter()
    outcome = Outcome(scenario.id, version)
    result = None
    try:
        result = simulate(scenario, fmu_on_this_host(fmu_bytes))
        outcome.problems = compare(scenario, result)
    except Exception as exception:  # a failed simulation is a failed scenario
        outcome.problems = [f"simulation failed: {exception}"]
    outcome.seconds = time.perf_counter() - started
    png = b""
    if with_plot and result is not None:
        stream = io.BytesIO()
        plot(scenario, result, stream, version)
        png = stream.getvalue()
    return outcome, result, png


def write_outputs(outcome, scenario, result, png, report_dir):
    stem = Path(report_dir) / f"fmi{outcome.version}" / scenario.model / scenario.name
    stem.parent.mkdir(parents=True, exist_ok=True)
    if result is not None:
        write_csv(f"{stem}_out.csv", result)
        outcome.csv = f"{stem}_out.csv"
    if png:
        Path(f"{stem}.png").write_bytes(png)
        outcome.plot = f"{stem}.png"


def write_report(outcomes, report_dir, wall, where):
    """summary.md and index.html: the pass/fail table and the plots."""
    report_dir = Path(report_dir)
    passed = sum(o.passed for o in outcomes)
    headline = f"{passed} of {len(outcomes)} runs match their reference; wall time {wall:.1f} s on {where}."
    lines = ["# Reference scenarios", "", headline, "",
             "| scenario | FMI | result | seconds | plot |", "|---|---|---|---|---|"]
    rows = []
    for o in outcomes:
        plot_link = os.path.relpath(o.plot, report_dir) if o.plot else ""
        verdict = "pass" if o.passed else "FAIL: " + "; ".join(o.problems[:3])
        lines.append(f"| {o.scenario} | {o.version} | {verdict} | {o.seconds:.2f} | "
                     + (f"[png]({plot_link})" if plot_link else "") + " |")
        cls = "pass" if o.passed else "fail"
        image = f'<a href="{plot_link}"><img src="{plot_link}" loading="lazy"></a>' if plot_link else ""
        rows.append(f'<tr class="{cls}"><td>{html.escape(o.scenario)}</td><td>{o.version}</td>'
                    f'<td>{html.escape(verdict)}</td><td>{o.seconds:.2f}</td><td>{image}</td></tr>')
    (report_dir / "summary.md").write_text("\n".join(lines) + "\n")
    (report_dir / "index.html").write_text(f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>Reference scenarios</title>
<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}
td,th{{border:1px solid #ccc;padding:.3em .6em;vertical-align:top}}tr.pass td:nth-child(3){{color:#176617}}
tr.fail td:nth-child(3){{color:#b00;font-weight:bold}}img{{max-width:480px}}</style></head><body>
<h1>Reference scenarios</h1><p>{html.escape(headline)}</p>
<table><tr><th>scenario</th><th>FMI</th><th>result</th><th>seconds</th><th>plot</th></tr>
{chr(10).join(rows)}
</table></body></html>
""")
    return passed


def package_zip():
    """fmutrace as a zip (for Dask's upload_file), made once per process."""
    import zipfile

    target = Path(tempfile.gettempdir()) / f"fmutrace-{os.getpid()}.zip"
    if not target.exists():
        package = Path(__file__).resolve().parent
        with zipfile.ZipFile(target, "w") as z:
            for source in sorted(package.glob("*.py")):
                z.write(source, f"fmutrace/{source.name}")
    return target


def campaign(scenarios, build_dir, versions=FMI_VERSIONS, scheduler=None, serial=False, jobs=None, with_plot=True,
             timeout=None):
    """Every scenario on every FMI version; returns [(outcome, scenario,
    result, png)] in scenario order, and where it ran. timeout: seconds
    to wait for the cluster's results (None: no bound)."""
    fmus = {(s.model, v): fmu_path(build_dir, s.model, v).read_bytes() for s in scenarios for v in versions}
    work = [(s, v) for s in scenarios for v in versions]
    if serial:
        done = [run_one(s, fmus[(s.model, v)], v, with_plot) for s, v in work]
        where = "1 process (serial)"
    else:
        from dask.distributed import Client, LocalCluster

        cluster = None
        if scheduler:
            client = Client(scheduler)
        else:
            cluster = LocalCluster(n_workers=jobs or os.cpu_count(), threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        try:
            client.upload_file(str(package_zip()))  # fmutrace, to every worker: nothing to install there but packages
            workers = len(client.scheduler_info()["workers"])
            shared = {key: client.scatter(data, broadcast=True) for key, data in fmus.items()}
            futures = [client.submit(run_one, s, shared[(s.model, v)], v, with_plot, pure=False) for s, v in work]
            from dask.distributed import wait
            wait(futures, timeout=timeout)  # TimeoutError names the bound
            done = client.gather(futures)
            where = f"Dask, {workers} workers" + (f" at {scheduler}" if scheduler else " (local processes)")
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    return [(o, s, r, png) for (o, r, png), (s, _) in zip(done, work)], where


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", help="folder of scenarios: <Model>/<name>/ in the cross-check layout")
    parser.add_argument("--build-dir", default="build")
    parser.add_argument("--report", default=None, help="folder for result CSVs, plots, summary.md and index.html")
    parser.add_argument("--model", action="append", help="only these models (repeatable)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count(), help="local Dask workers (default: every core)")
    parser.add_argument("--scheduler", default=None, help="address of a Dask distributed scheduler to run on")
    parser.add_argument("--serial", action="store_true", help="run in this process, without Dask")
    args = parser.parse_args(argv)

    scenarios = discover(args.scenarios, args.model)
    if not scenarios:
        print("no scenarios found")
        return 1
    report = Path(args.report) if args.report else None
    started = time.perf_counter()
    runs, where = campaign(scenarios, args.build_dir, scheduler=args.scheduler, serial=args.serial, jobs=args.jobs,
                           with_plot=report is not None)
    wall = time.perf_counter() - started
    outcomes = []
    for outcome, scenario, result, png in runs:
        if report:
            write_outputs(outcome, scenario, result, png, report)
        outcomes.append(outcome)
        print(f"{'pass' if outcome.passed else 'FAIL'}  FMI {outcome.version}  {outcome.scenario}")
        for problem in outcome.problems[:10]:
            print(f"      {problem}")
    passed = sum(o.passed for o in outcomes)
    if report:
        report.mkdir(parents=True, exist_ok=True)
        write_report(outcomes, report, wall, where)
        print(f"report: {report / 'index.html'}")
    print(f"{passed} passed, {len(outcomes) - passed} failed (wall time {wall:.1f} s on {where})")
    return 0 if passed == len(outcomes) else 1


if __name__ == "__main__":
    sys.exit(main())
