"""The report of a campaign: index.html (pass/fail table, one plot per
case), summary.md, results.json and, when asked, JUnit XML; and each
case's result as <case>_out.csv."""

import html
import json
import os
import shutil
from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

from ._outcome import CampaignResult, CaseOutcome, Status
from ._traces import write_trace

RESULTS_FORMAT = 1

STYLE = (
    "<style>body{font-family:sans-serif;margin:1em 2em}"
    "table{border-collapse:collapse;width:100%;table-layout:fixed}\n"
    "td,th{border:1px solid #ccc;padding:.3em .6em;vertical-align:top;overflow-wrap:anywhere}"
    "tr.pass td:nth-child(3){color:#176617}\n"
    "tr.fail td:nth-child(3),tr.error td:nth-child(3),tr.invalid td:nth-child(3){color:#b00;font-weight:bold}"
    "img{max-width:100%;height:auto}</style>"
)
COLUMNS = "<colgroup>" + "".join(f'<col style="width:{w}%">' for w in (16, 10, 28, 6, 40)) + "</colgroup>"


def write_case_files(outcome: CaseOutcome, report_dir):
    """<fmu folder>/<case>_out.csv and .png; their paths into outcome."""
    if outcome.result is None and not outcome.png and not outcome.result_path:
        return
    stem = Path(report_dir) / outcome.fmu_folder / outcome.case
    stem.parent.mkdir(parents=True, exist_ok=True)
    if outcome.result is not None:
        write_trace(f"{stem}_out.csv", outcome.result)
        outcome.csv = os.path.relpath(f"{stem}_out.csv", report_dir)
    elif outcome.result_path:
        shutil.move(outcome.result_path, f"{stem}_out.csv")
        outcome.csv = os.path.relpath(f"{stem}_out.csv", report_dir)
    if outcome.png:
        Path(f"{stem}.png").write_bytes(outcome.png)
        outcome.plot = os.path.relpath(f"{stem}.png", report_dir)


def write_results_json(campaign: CampaignResult, path):
    """results.json, a case at a time (a campaign's cases may not fit in memory at once)."""
    head = {
        "format": RESULTS_FORMAT,
        "mode": campaign.mode.name,
        "tolerance": campaign.mode.settings(),
        "passed": campaign.passed,
        "counts": campaign.counts(),
        "where": campaign.where,
        "seconds": round(campaign.seconds, 3),
    }
    with open(path, "w") as out:
        out.write(json.dumps(head)[:-1] + ', "cases": [')
        for n, o in enumerate(campaign.cases.light()):
            out.write(("," if n else "") + "\n" + json.dumps(o.to_json()))
        out.write("\n]}\n")


def write_junit(campaign: CampaignResult, path):
    """JUnit XML: a test suite per FMU, a test case per case; a suite's
    totals first (one pass over the cases), then its cases (one pass per FMU)."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    counts = campaign.counts()
    suites: dict[str, list] = {}  # fmu -> [tests, failures, errors, seconds]
    for o in campaign.cases.light():
        totals = suites.setdefault(o.fmu, [0, 0, 0, 0.0])
        totals[0] += 1
        totals[1] += o.status == Status.FAIL
        totals[2] += o.status in (Status.ERROR, Status.INVALID)
        totals[3] += o.seconds
    with open(path, "w") as out:
        out.write("<?xml version='1.0' encoding='utf-8'?>\n")
        out.write(
            f'<testsuites name="fmutrace" tests="{len(campaign.cases)}" failures="{counts[Status.FAIL]}" '
            f'errors="{counts[Status.ERROR] + counts[Status.INVALID]}" time="{campaign.seconds:.3f}">\n'
        )
        for fmu, (tests, failures, errors, seconds) in suites.items():
            out.write(
                f'  <testsuite name={quoteattr(fmu)} tests="{tests}" failures="{failures}" errors="{errors}" '
                f'time="{seconds:.3f}">\n'
            )
            for o in campaign.cases.light():
                if o.fmu != fmu:
                    continue
                case = f'    <testcase name={quoteattr(o.case)} classname={quoteattr(fmu)} time="{o.seconds:.3f}"'
                if o.passed:
                    out.write(case + " />\n")
                    continue
                kind = "failure" if o.status == Status.FAIL else "error"
                message = o.messages[0] if o.messages else o.status
                out.write(
                    f"{case}>\n      <{kind} message={quoteattr(message)}>{escape(chr(10).join(o.messages))}"
                    f"</{kind}>\n    </testcase>\n"
                )
            out.write("  </testsuite>\n")
        out.write("</testsuites>\n")


def _verdict(o):
    return "pass" if o.passed else f"{o.status.upper()}: " + "; ".join(o.messages[:3])


def write_report(campaign: CampaignResult, report_dir):
    """index.html, summary.md and results.json into report_dir, a case at
    a time (the case files are written as the cases finish)."""
    report_dir = Path(report_dir)
    report_dir.mkdir(parents=True, exist_ok=True)
    headline = campaign.headline()
    with open(report_dir / "summary.md", "w") as summary, open(report_dir / "index.html", "w") as page:
        summary.write(
            "\n".join(
                [
                    "# fmutrace",
                    "",
                    headline,
                    "",
                    f"Comparison: {campaign.mode.describe()}.",
                    "",
                    "| case | FMU | result | seconds | plot |",
                    "|---|---|---|---|---|",
                ]
            )
            + "\n"
        )
        page.write(f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>fmutrace report</title>
{STYLE}
</head><body>
<h1>fmutrace report</h1><p>{html.escape(headline)}</p><p>Comparison: {html.escape(campaign.mode.describe())}.</p>
<table>{COLUMNS}
<tr><th>case</th><th>FMU</th><th>result</th><th>seconds</th><th>plot</th></tr>
""")
        for o in campaign.cases.light():
            verdict = _verdict(o)
            summary.write(
                f"| {o.case} | {o.fmu} | {verdict.replace('|', '/')} | {o.seconds:.2f} | "
                + (f"[png]({o.plot})" if o.plot else "")
                + " |\n"
            )
            image = (
                f'<a href="{html.escape(o.plot)}"><img src="{html.escape(o.plot)}" loading="lazy"></a>'
                if o.plot
                else ""
            )
            csv = f'<br><a href="{html.escape(o.csv)}">result CSV</a>' if o.csv else ""
            page.write(
                f'<tr class="{o.status}"><td>{html.escape(o.case)}</td><td>{html.escape(o.fmu)}</td>'
                f"<td>{html.escape(verdict)}{csv}</td><td>{o.seconds:.2f}</td><td>{image}</td></tr>\n"
            )
        page.write("</table></body></html>\n")
    write_results_json(campaign, report_dir / "results.json")
