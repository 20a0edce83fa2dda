"""The report of a campaign: index.html (the summary, then a row per
case, the failing ones first, with a filter and a sort), a page per case
(<case>.html: its verdict, messages, criteria and interactive plots, their
data in <case>.plot.js), summary.md, results.json and, when asked, JUnit
XML; and each case's result as <case>_out.csv. The pages' scripts and the
plotting library (uPlot, in _static) are copied into ASSETS: the report
reads offline, from file:// too."""

import contextlib
import hashlib
import html
import json
import os
import re
import shutil
from pathlib import Path
from typing import NamedTuple
from urllib.parse import quote
from xml.sax.saxutils import escape, quoteattr

from ._errors import InputError
from ._outcome import CampaignResult, CaseOutcome, Status, ran_again
from ._traces import shown, write_trace

RESULTS_FORMAT = 1

# not shown as they are: what XML 1.0 forbids (control characters, surrogates, U+FFFE/U+FFFF)
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")
# not in a file name: separators, what Windows forbids, control characters
_NOT_IN_FILE_NAMES = re.compile('[/\\\\:*?"<>|\x00-\x1f\x7f]')
_MARKDOWN = re.compile(r"([\\`*_{}\[\]<>()#+!|~$])")
PLOT_DATA = ".plot.js"  # a case's plot data beside its page
ASSETS = "_fmutrace_assets"  # the report folder's scripts and styles
STATIC = Path(__file__).parent / "_static"
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
    """<fmu folder>/<case>_out.csv, .png, .plot.js and its tiles; their
    paths into outcome. A case's name with '/' makes folders."""
    if outcome.result is None and not outcome.png and not outcome.result_path and not outcome.plot_js:
        return
    stem = report_path(report_dir, outcome.fmu_folder, *outcome.case.split("/"))
    check_inside(report_dir, stem.parent)
    stem.parent.mkdir(parents=True, exist_ok=True)
    check_inside(report_dir, stem.parent)
    for made in (f"{stem}_out.csv", f"{stem}.png", f"{stem}{PLOT_DATA}"):
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
    if outcome.plot_js:
        Path(f"{stem}{PLOT_DATA}").write_text(outcome.plot_js, encoding="utf-8")
        outcome.plot_data = os.path.relpath(f"{stem}{PLOT_DATA}", report_dir)
    for k, tile in enumerate(outcome.plot_tiles):
        made = _tile(stem, k)
        if os.path.islink(made):
            os.unlink(made)
        Path(made).write_text(tile, encoding="utf-8")


def _tile(stem, k) -> str:
    """The file of a case's plot data tile k (the page loads it by this name as the reader zooms)."""
    return f"{stem}{PLOT_DATA.removesuffix('.js')}.{k}.js"


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


def output_problem(path) -> str | None:
    """Why a file the user names as an output cannot be written (None if it
    can): its folder must be there (none is made)."""
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        return f"{path}: no folder {folder} to write it into"
    return None


def _output(path):
    """A file the user named, to write: a regular file (or a new one) is
    replaced whole (_replaced); a link, a device or a FIFO is written into
    as it is (the file the link leads to, the device), never replaced."""
    if os.path.islink(path) or (os.path.exists(path) and not os.path.isfile(path)):
        return open(path, "w", encoding="utf-8")
    return _replaced(path)


def _results_json_head(campaign: CampaignResult) -> str:
    """results.json up to its first case (its cases follow, a line each, as write_report reads them)."""
    head = {
        "format": RESULTS_FORMAT,
        "mode": campaign.mode.name,
        "tolerance": campaign.mode.settings(),
        "passed": campaign.passed,
        "counts": campaign.counts(),
        "where": campaign.where,
        "seconds": round(campaign.seconds, 3),
        "not_run": [text(problem) for problem in campaign.problems],
    }
    return json.dumps(head)[:-1] + ', "cases": ['


def _shown_entry(entry):
    """A case's JSON with its names and messages as text (no lone surrogates: strict readers refuse them)."""
    for name in ("case", "fmu", "fmu_file"):
        entry[name] = text(entry[name])
    entry["messages"] = [text(m) for m in entry["messages"]]
    return entry


def write_junit(campaign: CampaignResult, path):
    """JUnit XML: a test suite per FMU, a test case per case; a suite's
    totals first (one pass over the cases), then its cases (one pass per FMU)."""
    counts = campaign.counts()
    suites: dict[str, list] = {}  # fmu -> [tests, failures, errors, seconds]
    for o in campaign.cases.light():
        totals = suites.setdefault(o.fmu, [0, 0, 0, 0.0])
        totals[0] += 1
        totals[1] += o.status == Status.FAIL
        totals[2] += o.status in (Status.ERROR, Status.INVALID)
        totals[3] += o.seconds
    with _output(path) as out:
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
        if campaign.problems:  # (what could not run at all: an error each, in a suite of its own)
            out.write(
                f'  <testsuite name="not run" tests="{len(campaign.problems)}" failures="0" '
                f'errors="{len(campaign.problems)}" time="0.000">\n'
            )
            for problem in campaign.problems:
                message = quoteattr(text(problem))
                out.write(
                    f'    <testcase name={message} classname="not run">\n'
                    f"      <error message={message}>{escape(text(problem))}</error>\n    </testcase>\n"
                )
            out.write("  </testsuite>\n")
        out.write("</testsuites>\n")


def _link(path):
    """A path in the report as a link's address (in Markdown and HTML alike)."""
    return html.escape(quote(Path(path).as_posix()))


def _verdict(o):
    verdict = "pass" if o.passed else f"{o.status.upper()}: " + "; ".join(o.messages[:3])
    return verdict + (f" ({ran_again(o)})" if o.retried else "")


_FMI = re.compile(r" \(FMI \d+\)$")


def model_of(fmu_label) -> str:
    """The model of an FMU's label ("RateLimiter (FMI 3)" -> "RateLimiter")."""
    return _FMI.sub("", fmu_label)


def _attribute(value) -> str:
    return html.escape(text(value), quote=True)


def _head(title, assets, styles=("report.css",)) -> str:
    """A page's head: its title, the style sheets (assets: the link to ASSETS from the page)."""
    return (
        f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f'<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{html.escape(text(title))}</title>\n"
        + "".join(f'<link rel="stylesheet" href="{assets}/{name}">\n' for name in styles)
        + "</head><body>\n"
    )


def copy_assets(report_dir):
    """The pages' scripts, style and the plotting library into report_dir/ASSETS."""
    target = Path(report_dir) / ASSETS
    check_inside(report_dir, target.parent)
    if target.is_symlink():
        target.unlink()
    target.mkdir(exist_ok=True)
    check_inside(report_dir, target)
    for source in sorted(STATIC.iterdir()):
        made = target / source.name
        if made.is_symlink():
            made.unlink()
        shutil.copyfile(source, made)


class _Tally:
    """Counts by status, overall and per FMU and per model, a case at a time."""

    def __init__(self):
        self.fmus: dict[str, dict] = {}
        self.models: dict[str, dict] = {}
        self.own_criteria = 0

    def add(self, o: CaseOutcome, campaign_criteria):
        for key, table in ((text(o.fmu), self.fmus), (text(model_of(o.fmu)), self.models)):
            table.setdefault(key, dict.fromkeys(Status, 0))[o.status] += 1
        self.own_criteria += bool(o.criteria) and o.criteria != campaign_criteria


def _count_table(title, rows) -> str:
    head = "".join(f"<th>{s}</th>" for s in Status)
    body = "".join(
        f'<tr><th scope="row">{html.escape(name)}</th>'
        + "".join(f'<td class="{s}{" some" if n[s] else ""}">{n[s]}</td>' for s in Status)
        + "</tr>"
        for name, n in rows.items()
    )
    return f'<table class="counts"><caption>{title}</caption><tr><th></th>{head}</tr>{body}</table>'


def _has_a_page(o: CaseOutcome) -> bool:
    """A case gets a page when it has more to show than its row: a failing
    case, a plot, a result file or messages. A passing case of a campaign
    that plots only its failing ones is its row alone (creating a file
    costs about half a millisecond: 10,000 of them, seconds)."""
    return not o.passed or bool(o.plot_data or o.csv or o.plot or o.messages or o.retried)


def _case_page(o: CaseOutcome, report_dir: Path, campaign_criteria) -> str:
    """The case's page beside its files; its path in the report folder."""
    stem = report_path(report_dir, o.fmu_folder, *o.case.split("/"))
    check_inside(report_dir, stem.parent)
    stem.parent.mkdir(parents=True, exist_ok=True)
    check_inside(report_dir, stem.parent)
    page = Path(f"{stem}.html")
    if page.is_symlink():
        page.unlink()

    def link(path):
        return _link(os.path.relpath(report_dir / path, stem.parent))

    assets = link(ASSETS)
    messages = "".join(f"<li>{html.escape(text(m))}</li>" for m in o.messages) or "<li>no difference</li>"
    messages += f"<li>{html.escape(text(ran_again(o)))}</li>" if o.retried else ""
    signals = "".join(
        f"<li>{html.escape(text(d.name))}: {html.escape(text(d.criterion or o.criteria or campaign_criteria))}</li>"
        for d in o.deviations
    )
    files = [f'<a href="{link(o.csv)}">result CSV</a>'] if o.csv else []
    files += [f'<a href="{link(o.plot)}">static figure (PNG)</a>'] if o.plot else []
    tiles = html.escape(quote(stem.name + PLOT_DATA.removesuffix("js")))  # its tiles' names before k.js
    plots = (
        f'<div id="plots" class="plots" data-tiles="{tiles}"></div>\n'
        f'<script src="{assets}/uPlot.iife.min.js"></script>\n'
        f'<script src="{link(o.plot_data)}"></script>\n<script src="{assets}/case.js"></script>\n'
        if o.plot_data
        else "<p>No plot: the campaign plotted only some of its cases, not this one.</p>"
    )
    with _replaced(page) as out:
        out.write(_head(f"{o.status}: {text(o.case)} on {text(o.fmu)}", assets, ("uPlot.min.css", "report.css")))
        out.write(
            f'<p class="nav"><a href="{link("index.html")}">&larr; all cases</a></p>\n'
            f'<h1><span class="badge {o.status}">{o.status.upper()}</span> {html.escape(text(o.case))}</h1>\n'
            f"<p>on {html.escape(text(o.fmu))} ({html.escape(text(o.fmu_file))}), {o.seconds:.2f} s</p>\n"
            f'<h2>Messages</h2><ul class="messages">{messages}</ul>\n'
            f"<h2>Criteria</h2><p>{html.escape(text(o.criteria or campaign_criteria))}</p>"
            + (f"<ul>{signals}</ul>" if signals else "")
            + (f"<p>{' · '.join(files)}</p>" if files else "")
            + f"\n<h2>Plots</h2>\n{plots}</body></html>\n"
        )
    return os.path.relpath(page, report_dir)


def write_report(campaign: CampaignResult, report_dir):
    """index.html, a page per case, summary.md and results.json into
    report_dir, a case at a time (the case files are written as the cases
    finish): one pass over the cases writes their pages, summary.md's and
    results.json's rows and index.html's rows into two files (failing, the
    rest), joined after the summary that the pass counted."""
    report_dir = Path(report_dir)
    report_dir.mkdir(parents=True, exist_ok=True)
    copy_assets(report_dir)
    headline = campaign.headline()
    criteria = campaign.mode.describe()
    tally = _Tally()
    rows = {failing: report_dir / f".index-{failing}.{os.getpid()}.rows" for failing in (True, False)}
    summary_rows = {failing: report_dir / f".summary-{failing}.{os.getpid()}.rows" for failing in (True, False)}
    pngs = False  # a case has a PNG: summary.md has a plot column
    fmu_cells = _FmuCells()
    try:
        with (
            _replaced(report_dir / "summary.md") as summary,
            _replaced(report_dir / "results.json") as results,
            open(rows[True], "w", encoding="utf-8") as failing_rows,
            open(rows[False], "w", encoding="utf-8") as other_rows,
            open(summary_rows[True], "w", encoding="utf-8") as failing_summary,
            open(summary_rows[False], "w", encoding="utf-8") as other_summary,
        ):
            results.write(_results_json_head(campaign))
            for n, o in enumerate(campaign.cases.light()):
                results.write(("," if n else "") + "\n" + json.dumps(_shown_entry(o.to_json())))
                tally.add(o, criteria)
                verdict = _verdict(o)
                fmu = fmu_cells[o.fmu]
                pngs = pngs or bool(o.plot)
                (other_summary if o.passed else failing_summary).write(
                    f"| {markdown(o.case)} | {fmu.markdown} | {markdown(verdict)} | {o.seconds:.2f} |"
                    + (f" [png]({_link(o.plot)}) |" if o.plot else "")
                    + "\n"
                )
                name = html.escape(text(o.case))
                if _has_a_page(o):
                    name = f'<a href="{_link(_case_page(o, report_dir, criteria))}">{name}</a>'
                message = o.messages[0] if o.messages and not o.passed else ran_again(o) if o.retried else ""
                (other_rows if o.passed else failing_rows).write(
                    f'<tr class="{o.status}" data-status="{o.status}" {fmu.attributes}>'
                    f'<td class="status">{o.status}</td>'
                    f"<td>{name}</td>"
                    f"<td>{fmu.html}</td><td>{html.escape(text(message))}</td>"
                    f'<td class="seconds">{o.seconds:.2f}</td></tr>\n'
                )
            results.write("\n]}\n")
            for part in (failing_rows, other_rows, failing_summary, other_summary):
                part.flush()
            _summary(summary, campaign, criteria, summary_rows, pngs)
            # (inside: summary.md and results.json replace theirs only once index.html is written)
            with _replaced(report_dir / "index.html") as index:
                index.write(_index_head(campaign, headline, criteria, tally))
                for failing in (True, False):
                    with open(rows[failing], encoding="utf-8") as part:
                        shutil.copyfileobj(part, index)
                index.write(f'</tbody></table>\n<script src="{ASSETS}/report.js"></script>\n</body></html>\n')
    finally:
        for path in (*rows.values(), *summary_rows.values()):
            path.unlink(missing_ok=True)


def _summary(out, campaign: CampaignResult, criteria, rows, pngs):
    """summary.md: the verdict, the headline, the criteria, then a row per
    case, the failing ones first (rows: failing -> the file of their rows),
    a plot column where a case has a PNG."""
    verdict = "PASS" if campaign.passed else "FAIL"
    not_run = "".join(f"- not run: {markdown(problem)}\n" for problem in campaign.problems)
    out.write(
        f"# fmutrace: {verdict}\n\n{campaign.headline()}\n\n{not_run + chr(10) if not_run else ''}"
        f"Comparison: {criteria}.\n\n"
        + ("| case | FMU | result | seconds | plot |\n|---|---|---|---|---|\n" if pngs else "")
        + ("| case | FMU | result | seconds |\n|---|---|---|---|\n" if not pngs else "")
    )
    for failing in (True, False):
        with open(rows[failing], encoding="utf-8") as part:
            for line in part:  # (a row with a PNG ends in its link; the others get an empty plot cell)
                out.write(line if not pngs or line.endswith(") |\n") else line[:-1] + "  |\n")


class _Cells(NamedTuple):
    markdown: str  # in summary.md's row
    html: str  # in index.html's row
    attributes: str  # of index.html's row


class _FmuCells(dict):
    """An FMU label's cells in a case's rows, made once per FMU (a campaign's cases share a few)."""

    def __missing__(self, fmu) -> _Cells:
        cells = self[fmu] = _Cells(
            markdown(fmu),
            html.escape(text(fmu)),
            f'data-fmu="{_attribute(fmu)}" data-model="{_attribute(model_of(fmu))}"',
        )
        return cells


def _index_head(campaign: CampaignResult, headline, criteria, tally: _Tally) -> str:
    """index.html up to its table's rows: the summary, the filter, the table's head."""
    counts = campaign.counts()
    numbers = "".join(
        f'<div class="number {s}{" some" if counts[s] else ""}"><span id="count-{s}">{counts[s]}</span> {s}</div>'
        for s in Status
    )
    verdict = "pass" if campaign.passed else "fail"
    own = f" {tally.own_criteria} cases with criteria of their own (on their pages)." if tally.own_criteria else ""
    options = "".join(f"<option>{html.escape(name)}</option>" for name in tally.fmus)
    models = "".join(f"<option>{html.escape(name)}</option>" for name in tally.models)
    statuses = "".join(f'<option value="{s}">{s}</option>' for s in Status)
    return (
        _head("fmutrace report", ASSETS)
        + f'<h1>fmutrace report</h1>\n<p class="headline" id="verdict" data-verdict="{verdict}">'
        f'<span class="badge {verdict}">{verdict.upper()}</span> {html.escape(headline)}</p>\n'
        + "".join(f'<p class="not-run">not run: {html.escape(text(problem))}</p>\n' for problem in campaign.problems)
        + '<section class="summary"><div class="numbers"><div class="number total">'
        f'<span id="count-total">{len(campaign.cases)}</span> cases</div>{numbers}'
        f'<div class="number time">{campaign.seconds:.1f} s on {html.escape(text(campaign.where))}</div></div>\n'
        f"<p>Comparison: {html.escape(text(criteria))}.{own}</p>\n"
        f'<div class="tables">{_count_table("per FMU", tally.fmus)}{_count_table("per model", tally.models)}</div>'
        "</section>\n"
        '<form class="filter" id="filter" onsubmit="return false">'
        f'<label>status <select id="f-status"><option value="">all</option><option value="!pass">not pass</option>'
        f"{statuses}</select></label> "
        f'<label>FMU <select id="f-fmu"><option value="">all</option>{options}</select></label> '
        f'<label>model <select id="f-model"><option value="">all</option>{models}</select></label> '
        '<label>text <input id="f-text" type="search" placeholder="case or message"></label> '
        '<span id="shown"></span></form>\n'
        '<table id="cases" class="cases"><colgroup><col class="c-status"><col class="c-case"><col class="c-fmu">'
        '<col class="c-message"><col class="c-seconds"></colgroup>\n<thead><tr>'
        '<th data-sort="text">status</th><th data-sort="text">case</th><th data-sort="text">FMU</th>'
        '<th data-sort="text">first message</th><th data-sort="number">seconds</th></tr></thead><tbody>\n'
    )
