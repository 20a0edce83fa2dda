"""The report of a campaign: index.html (pass/fail table, one plot per
case), summary.md, results.json and, when asked, JUnit XML; and each
case's result as <case>_out.csv."""
import html
import io
import json
import os
from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from .comparison import tube_bounds
from .traces import write_trace

RESULTS_FORMAT = 1


def plot_case(case, result, tolerance, label):
    """PNG bytes: the inputs, each compared signal (reference and result;
    the tube's band in tube mode) and the deviation."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = case.outputs
    has_inputs = case.inputs is not None
    rows = len(names) + 1 + has_inputs
    fig, axes = plt.subplots(rows, 1, sharex=True, figsize=(8, 1.6 * rows + 0.6), squeeze=False)
    for ax in axes[:, 0]:
        ax.tick_params(labelsize=7)
    axes = list(axes[:, 0])
    if has_inputs:
        ax = axes.pop(0)
        stop = case.options["StopTime"]
        for name in case.inputs.dtype.names[1:]:
            ax.step(np.append(case.inputs["time"], stop), np.append(case.inputs[name], case.inputs[name][-1]),
                    where="post", label=f"input {name}")
        ax.legend(loc="best", fontsize=7)
    deviation_axis = axes.pop()
    ref = case.reference
    for ax, name in zip(axes, names):
        if tolerance.mode == "tube":
            lower, upper = tube_bounds(ref["time"], ref[name].astype(float), result["time"], tolerance.tube_time,
                                       tolerance.tube_value)
            ax.fill_between(result["time"], lower, upper, color="0.85", step=None, label="tube")
            ax.plot(ref["time"], ref[name], color="0.5", linewidth=1, label=f"{name} reference")
        else:
            ax.step(ref["time"], ref[name], where="post", color="0.6", linewidth=4, label=f"{name} reference")
        ax.step(result["time"], result[name], where="post", color="C1", linewidth=1.2, marker=".", markersize=3,
                label=f"{name} {label}")
        ax.legend(loc="best", fontsize=7)
        if tolerance.mode == "tube":
            with np.errstate(invalid="ignore"):
                value = result[name].astype(float)
                off = np.where(value > upper, value - upper, np.where(value < lower, value - lower, 0.0))
            deviation_axis.plot(result["time"], off, drawstyle="steps-post", label=name)
        else:
            at = np.searchsorted(result["time"], ref["time"]).clip(0, len(result) - 1)
            with np.errstate(invalid="ignore"):
                deviation_axis.plot(ref["time"], result[name][at].astype(float) - ref[name].astype(float),
                                    drawstyle="steps-post", label=name)
    deviation_axis.set_ylabel("outside the tube" if tolerance.mode == "tube" else "result - ref", fontsize=7)
    deviation_axis.legend(loc="best", fontsize=7)
    deviation_axis.set_xlabel("time [s]")
    title = f"{case.name} on {label}" + (f": {case.description}" if case.description else "")
    fig.suptitle(title if len(title) < 110 else title[:107] + "...", fontsize=9)
    height = 1.6 * rows + 0.6  # fixed margins: tight_layout would cost more than the rest of the plot
    fig.subplots_adjust(left=0.1, right=0.98, top=1 - 0.45 / height, bottom=0.45 / height, hspace=0.12)
    stream = io.BytesIO()
    fig.savefig(stream, dpi=80, format="png", metadata={"Software": None})
    plt.close(fig)
    return stream.getvalue()


def light(cases):
    """The outcomes, without their results where they must be read (a journaled campaign's)."""
    return cases.light() if hasattr(cases, "light") else iter(cases)


def write_case_files(outcome, report_dir):
    """<fmu folder>/<case>_out.csv and .png; their paths into outcome."""
    if outcome.result is None and not outcome.png:
        return
    stem = Path(report_dir) / outcome.fmu_folder / outcome.case
    stem.parent.mkdir(parents=True, exist_ok=True)
    if outcome.result is not None:
        write_trace(f"{stem}_out.csv", outcome.result)
        outcome.csv = os.path.relpath(f"{stem}_out.csv", report_dir)
    if outcome.png:
        Path(f"{stem}.png").write_bytes(outcome.png)
        outcome.plot = os.path.relpath(f"{stem}.png", report_dir)


def write_results_json(campaign, path):
    """results.json, a case at a time (a campaign's cases may not fit in memory at once)."""
    head = {
        "format": RESULTS_FORMAT,
        "mode": campaign.tolerance.mode,
        "tolerance": {k: v for k, v in vars(campaign.tolerance).items() if v is not None},
        "passed": campaign.passed,
        "counts": campaign.counts(),
        "where": campaign.where,
        "seconds": round(campaign.seconds, 3),
    }
    with open(path, "w") as out:
        out.write(json.dumps(head)[:-1] + ', "cases": [')
        for n, o in enumerate(light(campaign.cases)):
            out.write(("," if n else "") + "\n" + json.dumps(case_json(o)))
        out.write("\n]}\n")


def case_json(o):
    entry = {"case": o.case, "fmu": o.fmu, "fmu_file": o.fmu_file, "status": o.status, "messages": o.messages,
             "seconds": round(o.seconds, 4), "signals": [d.as_dict() for d in o.deviations]}
    if o.csv:
        entry["result_csv"] = o.csv
    if o.plot:
        entry["plot"] = o.plot
    return entry


def write_junit(campaign, path):
    """JUnit XML: a test suite per FMU, a test case per case; a suite's
    totals first (one pass over the cases), then its cases (one pass per FMU)."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    counts = campaign.counts()
    suites = {}  # fmu -> [tests, failures, errors, seconds]
    for o in light(campaign.cases):
        totals = suites.setdefault(o.fmu, [0, 0, 0, 0.0])
        totals[0] += 1
        totals[1] += o.status == "fail"
        totals[2] += o.status in ("error", "invalid")
        totals[3] += o.seconds
    with open(path, "w") as out:
        out.write("<?xml version='1.0' encoding='utf-8'?>\n")
        out.write(f'<testsuites name="fmutrace" tests="{len(campaign.cases)}" failures="{counts["fail"]}" '
                  f'errors="{counts["error"] + counts["invalid"]}" time="{campaign.seconds:.3f}">\n')
        for fmu, (tests, failures, errors, seconds) in suites.items():
            out.write(f'  <testsuite name={quoteattr(fmu)} tests="{tests}" failures="{failures}" errors="{errors}" '
                      f'time="{seconds:.3f}">\n')
            for o in light(campaign.cases):
                if o.fmu != fmu:
                    continue
                case = f'    <testcase name={quoteattr(o.case)} classname={quoteattr(fmu)} time="{o.seconds:.3f}"'
                if o.status == "pass":
                    out.write(case + " />\n")
                    continue
                kind = "failure" if o.status == "fail" else "error"
                message = o.messages[0] if o.messages else o.status
                out.write(f"{case}>\n      <{kind} message={quoteattr(message)}>{escape(chr(10).join(o.messages))}"
                          f"</{kind}>\n    </testcase>\n")
            out.write("  </testsuite>\n")
        out.write("</testsuites>\n")


def _verdict(o):
    return "pass" if o.passed else f"{o.status.upper()}: " + "; ".join(o.messages[:3])


def write_report(campaign, report_dir):
    """index.html, summary.md and results.json into report_dir, a case at
    a time (the case files are written as the cases finish)."""
    report_dir = Path(report_dir)
    report_dir.mkdir(parents=True, exist_ok=True)
    headline = campaign.headline()
    with open(report_dir / "summary.md", "w") as summary, open(report_dir / "index.html", "w") as page:
        summary.write("\n".join(["# fmutrace", "", headline, "", f"Comparison: {campaign.tolerance.describe()}.", "",
                                 "| case | FMU | result | seconds | plot |", "|---|---|---|---|---|"]) + "\n")
        page.write(f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>fmutrace report</title>
<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}
td,th{{border:1px solid #ccc;padding:.3em .6em;vertical-align:top}}tr.pass td:nth-child(3){{color:#176617}}
tr.fail td:nth-child(3),tr.error td:nth-child(3),tr.invalid td:nth-child(3){{color:#b00;font-weight:bold}}img{{max-width:480px}}</style>
</head><body>
<h1>fmutrace report</h1><p>{html.escape(headline)}</p><p>Comparison: {html.escape(campaign.tolerance.describe())}.</p>
<table><tr><th>case</th><th>FMU</th><th>result</th><th>seconds</th><th>plot</th></tr>
""")
        for o in light(campaign.cases):
            verdict = _verdict(o)
            summary.write(f"| {o.case} | {o.fmu} | {verdict.replace('|', '/')} | {o.seconds:.2f} | "
                          + (f"[png]({o.plot})" if o.plot else "") + " |\n")
            image = f'<a href="{html.escape(o.plot)}"><img src="{html.escape(o.plot)}" loading="lazy"></a>' \
                if o.plot else ""
            csv = f'<br><a href="{html.escape(o.csv)}">result CSV</a>' if o.csv else ""
            page.write(f'<tr class="{o.status}"><td>{html.escape(o.case)}</td><td>{html.escape(o.fmu)}</td>'
                       f'<td>{html.escape(verdict)}{csv}</td><td>{o.seconds:.2f}</td><td>{image}</td></tr>\n')
        page.write("</table></body></html>\n")
    write_results_json(campaign, report_dir / "results.json")
