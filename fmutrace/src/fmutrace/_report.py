"""The report of a campaign: index.html (pass/fail table, one plot per
case), summary.md, results.json and, when asked, JUnit XML; and each
case's result as <case>_out.csv."""

import contextlib
import hashlib
import html
import json
import os
import re
import shutil
from pathlib import Path
from urllib.parse import quote
from xml.sax.saxutils import escape, quoteattr

from ._errors import InputError
from ._outcome import CampaignResult, CaseOutcome, Status
from ._traces import shown, write_trace

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


# not shown as they are: what XML 1.0 forbids (control characters, surrogates, U+FFFE/U+FFFF)
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")
# not in a file name: separators, what Windows forbids, control characters
_NOT_IN_FILE_NAMES = re.compile('[/\\\\:*?"<>|\x00-\x1f\x7f]')
_MARKDOWN = re.compile(r"([\\`*_{}\[\]<>()#+!|~$])")
FILE_NAME_BYTES = 200  # a name's part of a file name (255 at most) before its suffix, _out.csv


def text(value) -> str:
    """A name or message from users' files as text any page can hold: not
    UTF-8 and XML's forbidden characters as U+FFFD."""
    return _NOT_XML.sub("\ufffd", shown(value))


def markdown(value) -> str:
    """Text in a Markdown table cell: markup characters escaped, one line."""
    return _MARKDOWN.sub(r"\\\1", " ".join(text(value).splitlines()))


def file_name(name) -> str:
    """A name as one component of a path in the report: as it is when it
    is safe; else (a separator, '..', a character some file system refuses,
    not UTF-8, too long) its safe form shortened to FILE_NAME_BYTES and a
    hash of the name, so that two names do not become one."""
    safe = _NOT_IN_FILE_NAMES.sub("_", text(name))
    if safe.strip(".") == "":
        safe = safe.replace(".", "_") or "_"
    if safe == name and len(safe.encode()) <= FILE_NAME_BYTES:
        return safe
    digest = hashlib.sha256(str(name).encode("utf-8", "surrogatepass")).hexdigest()[:12]
    cut = safe.encode()[: FILE_NAME_BYTES - len(digest) - 1].decode("utf-8", "ignore")
    return f"{cut}-{digest}"


def report_path(report_dir, *names) -> Path:
    """report_dir/<names>, each name one component made a safe file name
    (file_name)."""
    return Path(report_dir).joinpath(*map(file_name, names))


def check_inside(report_dir, path):
    """InputError unless path, links already there resolved, is under report_dir."""
    base = os.path.realpath(report_dir)
    if os.path.commonpath([base, os.path.realpath(path)]) != base:
        raise InputError(f"{path}: a link leads outside the report folder {report_dir}; remove it or choose another")


def write_case_files(outcome: CaseOutcome, report_dir):
    """<fmu folder>/<case>_out.csv and .png; their paths into outcome. A
    case's name with '/' makes folders."""
    if outcome.result is None and not outcome.png and not outcome.result_path:
        return
    stem = report_path(report_dir, outcome.fmu_folder, *outcome.case.split("/"))
    check_inside(report_dir, stem.parent)
    stem.parent.mkdir(parents=True, exist_ok=True)
    check_inside(report_dir, stem.parent)
    for made in (f"{stem}_out.csv", f"{stem}.png"):
        if os.path.islink(made):  # written through, it would write where it points
            os.unlink(made)
    if outcome.result is not None:
        write_trace(f"{stem}_out.csv", outcome.result)
        outcome.csv = os.path.relpath(f"{stem}_out.csv", report_dir)
    elif outcome.result_path:
        shutil.move(outcome.result_path, f"{stem}_out.csv")
        outcome.csv = os.path.relpath(f"{stem}_out.csv", report_dir)
    if outcome.png:
        Path(f"{stem}.png").write_bytes(outcome.png)
        outcome.plot = os.path.relpath(f"{stem}.png", report_dir)


@contextlib.contextmanager
def _replaced(path):
    """A text file written whole or not at all: written as a new file
    beside it, renamed over it when complete (a reader, or a campaign that
    fails half way, never sees half a page)."""
    path = Path(path)
    new = path.with_name(f".{path.name}.{os.getpid()}.new")
    try:
        with open(new, "w", encoding="utf-8") as out:
            yield out
        os.replace(new, path)
    finally:
        if new.exists():
            new.unlink()


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
    with _replaced(path) as out:
        out.write(json.dumps(head)[:-1] + ', "cases": [')
        for n, o in enumerate(campaign.cases.light()):
            out.write(("," if n else "") + "\n" + json.dumps(_shown_entry(o.to_json())))
        out.write("\n]}\n")


def _shown_entry(entry):
    """A case's JSON with its names and messages as text (no lone surrogates: strict readers refuse them)."""
    for name in ("case", "fmu", "fmu_file"):
        entry[name] = text(entry[name])
    entry["messages"] = [text(m) for m in entry["messages"]]
    return entry


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
    with _replaced(path) as out:
        out.write("<?xml version='1.0' encoding='utf-8'?>\n")
        out.write(
            f'<testsuites name="fmutrace" tests="{len(campaign.cases)}" failures="{counts[Status.FAIL]}" '
            f'errors="{counts[Status.ERROR] + counts[Status.INVALID]}" time="{campaign.seconds:.3f}">\n'
        )
        for fmu, (tests, failures, errors, seconds) in suites.items():
            out.write(
                f'  <testsuite name={quoteattr(text(fmu))} tests="{tests}" failures="{failures}" errors="{errors}" '
                f'time="{seconds:.3f}">\n'
            )
            for o in campaign.cases.light():
                if o.fmu != fmu:
                    continue
                case = (
                    f"    <testcase name={quoteattr(text(o.case))} classname={quoteattr(text(fmu))} "
                    f'time="{o.seconds:.3f}"'
                )
                if o.passed:
                    out.write(case + " />\n")
                    continue
                kind = "failure" if o.status == Status.FAIL else "error"
                message = text(o.messages[0] if o.messages else o.status)
                out.write(
                    f"{case}>\n      <{kind} message={quoteattr(message)}>{escape(text(chr(10).join(o.messages)))}"
                    f"</{kind}>\n    </testcase>\n"
                )
            out.write("  </testsuite>\n")
        out.write("</testsuites>\n")


def _link(path):
    """A path in the report as a link's address (in Markdown and HTML alike)."""
    return html.escape(quote(Path(path).as_posix()))


def _verdict(o):
    return "pass" if o.passed else f"{o.status.upper()}: " + "; ".join(o.messages[:3])


def write_report(campaign: CampaignResult, report_dir):
    """index.html, summary.md and results.json into report_dir, a case at
    a time (the case files are written as the cases finish)."""
    report_dir = Path(report_dir)
    report_dir.mkdir(parents=True, exist_ok=True)
    headline = campaign.headline()
    with (
        _replaced(report_dir / "summary.md") as summary,
        _replaced(report_dir / "index.html") as page,
    ):
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
                f"| {markdown(o.case)} | {markdown(o.fmu)} | {markdown(verdict)} | {o.seconds:.2f} | "
                + (f"[png]({_link(o.plot)})" if o.plot else "")
                + " |\n"
            )
            image = f'<a href="{_link(o.plot)}"><img src="{_link(o.plot)}" loading="lazy"></a>' if o.plot else ""
            csv = f'<br><a href="{_link(o.csv)}">result CSV</a>' if o.csv else ""
            page.write(
                f'<tr class="{o.status}"><td>{html.escape(text(o.case))}</td><td>{html.escape(text(o.fmu))}</td>'
                f"<td>{html.escape(text(verdict))}{csv}</td><td>{o.seconds:.2f}</td><td>{image}</td></tr>\n"
            )
        page.write("</table></body></html>\n")
    write_results_json(campaign, report_dir / "results.json")
