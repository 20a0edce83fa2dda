"""fmutrace under hostile and careless use (issue 37): files, names and
journals made to hurt, each run through the command. Nothing loaded that
the user did not give, nothing written outside the report folder, names
shown as text, a damaged journal refused, every failure an exit status of
the documented table with one line of message and no traceback.

Its FMU is PassThrough, its case worked by hand (support/pass_through.py)."""

import json
import os
import shutil
import tempfile
import re
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

from fmutrace import RunOptions, _report, compare
from support.fmu_driver import BUILD_DIR
from support.pass_through import (  # noqa: F401  (commands_start_from_the_defaults: autouse here)
    INPUT,
    OPT,
    PASS_THROUGH,
    REF,
    commands_start_from_the_defaults,
    output,
    signalled_campaign,
    write_case,
)
from support.pass_through import run_fmutrace as fmutrace
from support.process import kill_session
from support.process import run as run_bounded

RAMP = BUILD_DIR / "fmi3" / "Ramp.fmu"


def no_traceback(done):
    assert "Traceback" not in output(done), output(done)


def files_under(folder):
    return {Path(root) / name for root, _, names in os.walk(folder) for name in names}


# 1. No code loaded that the user did not give


UNPACK = """
import sys
from fmutrace import _fmu
data = open(sys.argv[1], "rb").read()
folder, md = _fmu.unpacked(data)
again, _ = _fmu.unpacked(data)
import os, stat
print(folder, md.modelName, again == folder, oct(stat.S_IMODE(os.stat(folder).st_mode)))
"""


def test_an_fmu_is_unpacked_into_a_private_folder_never_one_planted(tmp_path):
    """A folder planted under the name today's code unpacks to (the FMU's
    hash prefix in the shared temporary folder) holds another FMU: it must
    not be loaded; the FMU is unpacked into a folder of this process's own
    (mode 0700), once per process, removed at exit."""
    import hashlib

    shared = tmp_path / "shared-tmp"
    shared.mkdir()
    data = PASS_THROUGH.read_bytes()
    planted = shared / f"fmutrace-{hashlib.sha256(data).hexdigest()[:20]}"
    with zipfile.ZipFile(RAMP) as other:
        other.extractall(planted)
    env = dict(os.environ, TMPDIR=str(shared))
    done = run_bounded(
        [sys.executable, "-c", UNPACK, str(PASS_THROUGH)], timeout=120, what="unpack", env=env, check=True
    )
    folder, model, reused, mode = done.stdout.split()
    assert model == "PassThrough", f"the planted folder {planted} was loaded"
    assert Path(folder) != planted
    assert reused == "True"
    assert mode == "0o700" and Path(folder).parent.parent == shared
    assert not Path(folder).exists(), "the unpacked FMU is left behind at exit"
    assert not [p for p in shared.iterdir() if p != planted], "files left in the temporary folder"


FAULTY = BUILD_DIR / "fixtures" / "fmi3" / "Faulty.fmu"  # PassThrough's equation; u = 13 crashes, u = 17 hangs


@pytest.mark.slow
def test_children_killed_leave_no_unpacked_fmu_behind(tmp_path):
    """--case-timeout runs the cases in child processes: one killed at its
    timeout (u = 17 hangs) and one crashed (u = 13) cannot remove what they
    unpacked; the command removes it at its exit. The temporary folder is
    left as it was found."""
    shared = tmp_path / "tmp"
    shared.mkdir()
    for k in (1, 13, 17):
        case = tmp_path / "cases" / f"case_{k}"
        case.mkdir(parents=True)
        (case / "Faulty_in.csv").write_text(f"time,u\n0,0\n0.2,{k}\n")
        (case / "Faulty_ref.csv").write_text(f"time,y\n0,0\n0.1,0\n0.2,0\n0.3,{k}\n0.4,{k}\n")
        (case / "Faulty_ref.opt").write_text("StartTime,0\nStopTime,0.4\nStepSize,0.1\n")
    done = fmutrace(
        "compare", FAULTY, tmp_path / "cases", "--case-timeout", "3", env=dict(os.environ, TMPDIR=str(shared))
    )
    no_traceback(done)
    assert done.returncode == 1, output(done)
    assert "ERROR  case_13" in done.stdout and "ERROR  case_17" in done.stdout, output(done)
    assert not list(shared.rglob("*")), list(shared.rglob("*"))


def children_of(pid, running):
    """The pids of a process's children whose command line holds running (Linux's /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            command = (entry / "cmdline").read_bytes()
        except (OSError, IndexError):
            continue
        if fields[1] == str(pid) and running.encode() in command:
            found.append(int(entry.name))
    return found


def alive(pid):
    try:
        return (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()[0] not in ("Z", "X")
    except OSError:
        return False


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the parent-death signal is Linux's")
def test_a_child_running_a_hanging_case_dies_with_the_command(tmp_path):
    """The command killed with SIGKILL while its child hangs in the FMU's
    doStep (u = 17, --case-timeout far away): the child does not spin on."""
    case = tmp_path / "cases" / "case_17"
    case.mkdir(parents=True)
    (case / "Faulty_in.csv").write_text("time,u\n0,0\n0.2,17\n")
    (case / "Faulty_ref.csv").write_text("time,y\n0,0\n0.1,0\n0.2,0\n0.3,17\n0.4,17\n")
    (case / "Faulty_ref.opt").write_text("StartTime,0\nStopTime,0.4\nStepSize,0.1\n")
    command = subprocess.Popen(
        [sys.executable, "-m", "fmutrace", "compare", str(FAULTY), str(tmp_path / "cases"), "--case-timeout", "600"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 120
        while not children_of(command.pid, "fmutrace") and time.monotonic() < deadline:
            assert command.poll() is None, "the command ended before its child started"
            time.sleep(0.1)
        children = children_of(command.pid, "fmutrace")
        assert children, "no child started"
        time.sleep(2)  # in the hanging doStep by now
        command.kill()
        command.wait(timeout=30)
        deadline = time.monotonic() + 30
        while any(map(alive, children)) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not any(map(alive, children)), "the child outlived the command"
    finally:
        kill_session(command)


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="POSIX: the owner's lock tells a live campaign's folder")
def test_a_killed_commands_unpack_folder_is_removed_by_the_next_one(tmp_path):
    """A command killed with SIGKILL cannot remove its folder of unpacked
    FMUs; the next command does, and leaves a live command's folder, and any
    folder not made this way, alone."""
    import fcntl

    shared = tmp_path / "tmp"
    shared.mkdir()
    write_case(tmp_path / "cases" / "one")
    env = dict(os.environ, TMPDIR=str(shared))
    killed = subprocess.Popen(
        [
            sys.executable,
            "-c",
            UNPACK + "import os, signal; sys.stdout.flush(); os.kill(os.getpid(), signal.SIGKILL)",
            str(PASS_THROUGH),
        ],
        env=env,
        stdout=subprocess.PIPE,
    )
    abandoned = Path(killed.communicate(timeout=120)[0].decode().split()[0]).parent
    assert killed.returncode == -signal.SIGKILL and abandoned.is_dir()
    live, other = shared / "fmutrace-live", shared / "fmutrace-0123456789abcdef0123"
    live.mkdir()
    other.mkdir()
    with open(live / ".owner", "w") as owner:
        fcntl.flock(owner, fcntl.LOCK_EX | fcntl.LOCK_NB)  # a campaign running
        done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--plots", "none", env=env)
    no_traceback(done)
    assert done.returncode == 0, output(done)
    assert sorted(shared.iterdir()) == [other, live]


def test_a_root_being_made_is_not_taken_for_an_abandoned_one(tmp_path, monkeypatch):
    """Another command's clean-up that runs while this one makes its folder of unpacked FMUs (between
    the owner file's creation and its lock, when that file is free to lock) leaves it alone: the folder is
    named a root only once it is locked."""
    from fmutrace import _fmu

    monkeypatch.delenv(_fmu.UNPACK_ROOT, raising=False)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    locking = _fmu._lock

    def cleaned_first(file):
        monkeypatch.setattr(_fmu, "_lock", locking)
        _fmu._remove_abandoned()  # (as another command's start would, at this moment)
        locking(file)

    monkeypatch.setattr(_fmu, "_lock", cleaned_first)
    root = _fmu.unpack_root()
    try:
        assert os.path.basename(root).startswith("fmutrace-") and os.path.isfile(os.path.join(root, _fmu.OWNER))
        assert [p.name for p in tmp_path.iterdir()] == [os.path.basename(root)]
        _fmu._remove_abandoned()  # and later, while this process lives
        assert os.path.isdir(root)
    finally:
        _fmu._owned.pop().close()
        shutil.rmtree(root, ignore_errors=True)


@pytest.mark.slow
def test_local_workers_leave_no_unpacked_fmu_behind(tmp_path):
    """--jobs 2: the local worker processes unpack into the command's folder,
    removed when the command ends, however the workers are stopped."""
    shared = tmp_path / "tmp"
    shared.mkdir()
    write_case(tmp_path / "cases" / "one")
    write_case(tmp_path / "cases" / "two")
    done = fmutrace(
        "compare", PASS_THROUGH, tmp_path / "cases", "--jobs", "2", env=dict(os.environ, TMPDIR=str(shared))
    )
    no_traceback(done)
    assert done.returncode == 0, output(done)
    assert "2 local processes" in done.stdout, done.stdout
    assert not [p for p in shared.rglob("*") if "fmutrace" in p.name or p.name.startswith("fmu-")]


# 2. Text from users' files shown as text everywhere


@pytest.mark.slow
def test_tex_like_text_in_a_name_or_readme_is_drawn_as_text(tmp_path):
    """$...$ in a case's README and folder name is not matplotlib's
    mathtext: the plot is drawn (a broken formula used to abort the whole
    campaign) and the case passes."""
    write_case(tmp_path / "cases" / "cost $x^$ and $", readme="# unit price in $\\frac{$ per $m^2\n")
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", tmp_path / "report", "--plots", "png")
    no_traceback(done)
    assert done.returncode == 0, output(done)
    pngs = list((tmp_path / "report").rglob("*.png"))
    assert len(pngs) == 1 and pngs[0].read_bytes().startswith(b"\x89PNG")


def test_markdown_and_html_show_a_name_as_text(tmp_path):
    """A case name with Markdown's table bar, a link and HTML is one cell
    of summary.md's table and no markup."""
    name = "a|b [x](javascript:alert(1)) <b>bold</b> *star*"
    write_case(tmp_path / "cases" / name)
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", tmp_path / "report")
    no_traceback(done)
    assert done.returncode == 0, output(done)
    summary = (tmp_path / "report" / "summary.md").read_text()
    rows = [line for line in summary.splitlines() if line.startswith("| a")]
    assert len(rows) == 1, summary
    cells = re.split(r"(?<!\\)\|", rows[0])[1:-1]  # a bar not escaped separates cells
    assert len(cells) == 4, rows[0]  # (no plot column: no PNG was asked for)
    assert "<b>" not in summary and "](javascript" not in summary, summary
    page = (tmp_path / "report" / "index.html").read_text()
    assert "<b>bold" not in page and "&lt;b&gt;bold" in page
    [case_page] = [p for p in (tmp_path / "report").rglob("*.html") if p.name != "index.html"]
    page = case_page.read_text()
    assert "<b>bold" not in page and "&lt;b&gt;bold" in page
    data = case_page.with_name(case_page.name.removesuffix(".html") + ".plot.js").read_text()
    assert "<" not in data and "\\u003cb>bold" in data  # (JSON's escape: the name itself once read)


def test_control_characters_in_names_leave_junit_xml_valid(tmp_path):
    """Control characters (XML 1.0 forbids them even as references) in a
    case's name: junit.xml parses, the character shown replaced."""
    write_case(tmp_path / "cases" / "ctl\x01\x1b[31mred")
    junit = tmp_path / "junit.xml"
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--junit", junit, "--report", tmp_path / "report")
    no_traceback(done)
    assert done.returncode == 0, output(done)
    names = [case.get("name") for case in ET.parse(junit).getroot().iter("testcase")]
    assert names == ["ctl\ufffd\ufffd[31mred"]


@pytest.mark.slow
def test_a_name_that_is_not_utf8_is_shown_with_replacement_characters(tmp_path):
    """A case folder named in Latin-1 bytes: the campaign runs, the name is
    shown with U+FFFD in the output, the pages, results.json and junit.xml."""
    write_case(os.path.join(os.fsencode(tmp_path / "cases"), b"r\xe9sum\xe9"))
    junit = tmp_path / "junit.xml"
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", tmp_path / "report", "--junit", junit)
    no_traceback(done)
    assert done.returncode == 0, output(done)
    results = json.loads((tmp_path / "report" / "results.json").read_text(encoding="utf-8"))
    assert [c["case"] for c in results["cases"]] == ["r\ufffdsum\ufffd"]
    assert "r\ufffdsum\ufffd" in (tmp_path / "report" / "summary.md").read_text(encoding="utf-8")
    assert "r\ufffdsum\ufffd" in (tmp_path / "report" / "index.html").read_text(encoding="utf-8")
    assert [c.get("name") for c in ET.parse(junit).getroot().iter("testcase")] == ["r\ufffdsum\ufffd"]


@pytest.mark.slow
def test_paths_given_that_are_not_utf8_are_printed_with_replacement_characters(tmp_path):
    """--report and --junit named in Latin-1 bytes, printed to a strict UTF-8
    standard output (a terminal's): the lines that name them show U+FFFD."""
    write_case(tmp_path / "cases" / "one")
    base = os.fsencode(tmp_path)
    report, junit = os.path.join(base, b"r\xe9port"), os.path.join(base, b"j\xe9.xml")
    env = dict(os.environ, PYTHONIOENCODING="utf-8:strict")
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", report, "--junit", junit, env=env)
    no_traceback(done)
    assert done.returncode == 0, output(done)
    assert f"report: {tmp_path}/r\ufffdport/index.html" in done.stdout, done.stdout
    assert f"JUnit XML: {tmp_path}/j\ufffd.xml" in done.stdout, done.stdout
    assert os.path.isfile(os.path.join(report, b"index.html")) and os.path.isfile(junit)


@pytest.mark.slow
def test_a_250_byte_name_becomes_a_file_name_shortened_with_a_hash(tmp_path):
    """A case folder of 250 bytes (the file system allows 255): its result
    file and plot get names that fit, distinct for two names that share
    their beginning."""
    long = ["é" * 124 + "ab", "é" * 124 + "ac"]  # 250 bytes each
    for name in long:
        write_case(tmp_path / "cases" / name)
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", tmp_path / "report", "--plots", "png")
    no_traceback(done)
    assert done.returncode == 0, output(done)
    results = json.loads((tmp_path / "report" / "results.json").read_text())
    assert [c["case"] for c in results["cases"]] == long
    csvs = [c["result_csv"] for c in results["cases"]]
    assert len(set(csvs)) == 2
    for case in results["cases"]:
        for key in ("result_csv", "plot", "plot_data"):
            path = tmp_path / "report" / case[key]
            assert path.is_file() and len(os.fsencode(path.name)) <= 255
        page = tmp_path / "report" / (case["plot_data"].removesuffix(".plot.js") + ".html")  # the case's page
        assert page.is_file() and len(os.fsencode(page.name)) <= 255
    rows = (tmp_path / "report" / csvs[0]).read_text().splitlines()[1:]
    assert [float(row.split(",")[1]) for row in rows] == [0, 1, 1, 3, 3, 3]


# 3. Nothing written outside the report folder


def escaping_fmu(tmp_path, model_name):
    """PassThrough (FMI 2) with another modelName (the binary is found by
    its modelIdentifier, which stays)."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    path = tmp_path / "escaping.fmu"
    with zipfile.ZipFile(PASS_THROUGH) as source, zipfile.ZipFile(path, "w") as target:
        for item in source.infolist():
            data = source.read(item)
            if item.filename == "modelDescription.xml":
                data = data.replace(b'modelName="PassThrough"', f'modelName="{model_name}"'.encode())
                assert model_name.encode() in data
            target.writestr(item, data)
    return path


def test_a_model_name_with_dot_dot_writes_nothing_outside_the_report(tmp_path):
    """modelName '../../../ESCAPED' names the FMU's folder in the report:
    every file of the campaign stays under the report folder."""
    fmu = escaping_fmu(tmp_path / "fmu", "../../../ESCAPED")
    workspace = tmp_path / "work" / "a" / "b"
    write_case(workspace / "case")
    # the case's files carry the model's name: find_cases looks for ../../../ESCAPED_ref.csv
    for suffix, text in (("_ref.csv", REF), ("_in.csv", INPUT), ("_ref.opt", OPT)):
        (workspace / "case" / f"../../../ESCAPED{suffix}").write_text(text)
    report = tmp_path / "work" / "a" / "b" / "case" / "report"
    before = files_under(tmp_path)
    done = fmutrace("compare", fmu, workspace / "case", "--report", report)
    no_traceback(done)
    new = files_under(tmp_path) - before
    outside = [p for p in new if report not in p.parents]
    assert not outside, f"written outside the report folder: {outside}\n{output(done)}"
    assert done.returncode == 0, output(done)
    assert (report / "index.html").is_file()
    assert any(p.name.endswith("_out.csv") for p in new)


def test_a_link_in_the_report_folder_does_not_lead_its_files_outside(tmp_path):
    """The FMU's folder in the report is a link to a folder outside it: no
    file is written through it; exit 2 and a line that says why."""
    write_case(tmp_path / "cases" / "one")
    report, outside = tmp_path / "report", tmp_path / "outside"
    report.mkdir()
    outside.mkdir()
    (report / "PassThrough-fmi2").symlink_to(outside)
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", report)
    no_traceback(done)
    assert not list(outside.iterdir())
    assert done.returncode == 2, output(done)
    assert "outside the report folder" in done.stderr and len(done.stderr.strip().splitlines()) == 1, done.stderr


@pytest.mark.slow
def test_two_recordings_of_one_file_name_keep_their_own_results(tmp_path):
    """a/rec.csv and b/rec.csv: two cases of two names, each with its own
    result file (the second used to overwrite the first's)."""
    for folder, (low, high) in (("a", (1, 3)), ("b", (5, 7))):
        (tmp_path / folder).mkdir()
        # a recorded cycle: the input it read and the output it wrote (PassThrough's y is its u)
        rows = [(0, low), (0.1, low), (0.2, high), (0.3, high)]
        (tmp_path / folder / "rec.csv").write_text("time,u,y\n" + "".join(f"{t},{u},{u}\n" for t, u in rows))
    report = tmp_path / "report"
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "a" / "rec.csv", tmp_path / "b" / "rec.csv", "--report", report)
    no_traceback(done)
    assert done.returncode == 0, output(done)
    cases = json.loads((report / "results.json").read_text())["cases"]
    assert [c["case"] for c in cases] == ["a/rec.csv", "b/rec.csv"]
    for case, (low, high) in zip(cases, ((1, 3), (5, 7)), strict=True):
        rows = (report / case["result_csv"]).read_text().splitlines()[1:]
        assert [float(row.split(",")[1]) for row in rows] == [0, low, low, high, high]


def test_a_report_page_is_replaced_whole_or_not_at_all(tmp_path, monkeypatch):
    """Writing the pages fails half way (here: the second case's verdict):
    the pages of the campaign before stay as they were, no half page, no
    file left beside them."""
    write_case(tmp_path / "cases" / "one")
    write_case(tmp_path / "cases" / "two")
    report = tmp_path / "report"
    result = compare(PASS_THROUGH, tmp_path / "cases", report=report)
    assert result.passed
    pages = {name: (report / name).read_bytes() for name in ("index.html", "summary.md", "results.json")}
    verdicts = []

    def failing(outcome):
        verdicts.append(outcome)
        if len(verdicts) == 2:
            raise OSError(28, "No space left on device")
        return "pass"

    monkeypatch.setattr(_report, "_verdict", failing)
    with pytest.raises(OSError):
        _report.write_report(result, report)
    assert {name: (report / name).read_bytes() for name in pages} == pages
    assert sorted(p.name for p in report.iterdir() if p.is_file()) == sorted(
        [*pages, "results.jsonl", ".fmutrace.lock"]
    )


def test_a_campaign_started_while_another_writes_its_report_is_refused(tmp_path, monkeypatch):
    """The race that lost a campaign's results: a second campaign started
    in the moment the first writes its pages (made certain here: the first
    starts it from inside its report writing) is refused, and the first
    one's journal and pages hold all its cases."""
    from fmutrace import _campaign

    for name in ("one", "two", "three"):
        write_case(tmp_path / "cases" / name)
    report = tmp_path / "report"
    raced = []
    write_report = _campaign.write_report

    def race_then_write(*args, **kwargs):
        raced.append(fmutrace("compare", PASS_THROUGH, tmp_path / "cases" / "one", "--report", report))
        return write_report(*args, **kwargs)

    monkeypatch.setattr(_campaign, "write_report", race_then_write)
    first = compare([PASS_THROUGH], [tmp_path / "cases"], report=report, run=RunOptions(jobs=1))
    [second] = raced
    no_traceback(second)
    assert second.returncode == 2 and "another campaign is writing this report folder" in second.stderr, output(second)
    assert first.passed and len(first.cases) == 3, first.summary()
    journal = (report / "results.jsonl").read_text().splitlines()
    assert len(journal) == 4, journal  # its header and the three cases
    assert json.loads((report / "results.json").read_text())["counts"]["pass"] == 3
    page = (report / "index.html").read_text()
    assert all(name in page for name in ("one", "two", "three"))


# 4. Resumes wrongly


def campaign_with_journal(tmp_path):
    write_case(tmp_path / "cases" / "one")
    write_case(tmp_path / "cases" / "two")
    report = tmp_path / "report"
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", report)
    assert done.returncode == 0, output(done)
    return report, (report / "results.jsonl").read_text().splitlines(keepends=True)


@pytest.mark.slow
def test_a_journal_with_a_damaged_header_is_refused(tmp_path):
    """Its header line damaged, a journal no longer says which options made
    its verdicts: resuming it under other options (--abs-tol 1e6) is refused
    with exit 2 and what to do, not taken with the old verdicts."""
    report, lines = campaign_with_journal(tmp_path)
    (report / "results.jsonl").write_text(lines[0][:20] + "\n" + "".join(lines[1:]))
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", report, "--resume", "--abs-tol", "1e6")
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert "results.jsonl" in done.stderr and "without --resume" in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr


@pytest.mark.slow
def test_the_same_fmu_named_by_another_path_resumes_from_the_journal(tmp_path):
    """A journal knows an FMU by its bytes: the campaign resumed with a copy
    of the FMU elsewhere takes every case from the journal, runs none again,
    and names the FMU by the path given now."""
    report, lines = campaign_with_journal(tmp_path)
    copy = tmp_path / "elsewhere" / PASS_THROUGH.name
    copy.parent.mkdir()
    copy.write_bytes(PASS_THROUGH.read_bytes())
    done = fmutrace("compare", copy, tmp_path / "cases", "--report", report, "--resume")
    no_traceback(done)
    assert done.returncode == 0, output(done)
    assert "on the journal" in done.stdout, done.stdout  # all done: nothing ran
    assert (report / "results.jsonl").read_text().splitlines(keepends=True) == lines  # nothing appended
    cases = json.loads((report / "results.json").read_text())["cases"]
    assert cases and all(c["fmu_file"] == str(copy) for c in cases), cases


@pytest.mark.slow
def test_a_journal_of_another_program_is_refused(tmp_path):
    """A JSON first line that is not a campaign's header (a list): exit 2, one line."""
    report, lines = campaign_with_journal(tmp_path)
    (report / "results.jsonl").write_text("[1, 2]\n" + "".join(lines[1:]))
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", report, "--resume")
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr


@pytest.mark.slow
@pytest.mark.parametrize(
    "damage",
    [
        lambda entry: dict(entry, status="bogus"),
        lambda entry: {k: v for k, v in entry.items() if k != "case"},
        lambda entry: [entry],
        lambda entry: dict(entry, signals=[{"nonsense": 1}]),
        lambda entry: dict(entry, messages=7),
        lambda entry: dict(entry, result_csv="../../outside_out.csv"),
    ],
    ids=["unknown status", "no case", "not an object", "bad signal", "messages a number", "a path outside"],
)
def test_a_bad_journal_line_is_skipped_with_a_message_and_its_case_runs_again(tmp_path, damage):
    """A journal line with an unknown status, without its case, or not a
    case's entry at all: the resume says so, runs that case again and
    reports both cases, passing."""
    report, lines = campaign_with_journal(tmp_path)
    bad = json.dumps(damage(json.loads(lines[1]))) + "\n"
    (report / "results.jsonl").write_text(lines[0] + bad + lines[2])
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", report, "--resume")
    no_traceback(done)
    assert done.returncode == 0, output(done)
    assert "results.jsonl, line 2" in done.stderr and "runs again" in done.stderr, done.stderr
    assert "2 of 2 cases pass" in done.stdout
    results = json.loads((report / "results.json").read_text())
    assert sorted(c["case"] for c in results["cases"]) == ["one", "two"]


@pytest.mark.slow
def test_a_journal_line_longer_than_its_bound_is_skipped_unread(tmp_path):
    """A second line of 64 MiB and more (a foreign or damaged file) is not read whole: the resume says it
    is too long, runs that case again and keeps the entry after it."""
    from fmutrace._journal import JOURNAL_LINE

    report, lines = campaign_with_journal(tmp_path)
    with open(report / "results.jsonl", "w") as journal:
        journal.write(lines[0])
        for _ in range(JOURNAL_LINE // (1 << 20) + 1):
            journal.write("x" * (1 << 20))
        journal.write("\n" + lines[2])
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", report, "--resume")
    no_traceback(done)
    assert done.returncode == 0, output(done)
    assert f"results.jsonl, line 2: longer than {JOURNAL_LINE:,} bytes; its case runs again" in done.stderr
    assert "2 of 2 cases pass" in done.stdout


# 5. Exit codes and no traceback


@pytest.mark.slow
def test_a_report_folder_that_is_a_file_is_bad_input(tmp_path):
    write_case(tmp_path / "cases" / "one")
    (tmp_path / "report").write_text("not a folder")
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", tmp_path / "report")
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert done.stderr.startswith("fmutrace: error: ") and len(done.stderr.strip().splitlines()) == 1


@pytest.mark.slow
def test_a_report_folder_that_cannot_be_written_is_bad_input(tmp_path):
    """A read-only report folder (as root, whom modes do not stop: a folder
    under a file stands in for it)."""
    write_case(tmp_path / "cases" / "one")
    report = tmp_path / "report"
    report.mkdir()
    report.chmod(0o555)
    if os.access(report, os.W_OK):  # root
        report.chmod(0o755)
        (tmp_path / "file").write_text("")
        report = tmp_path / "file" / "report"
    try:
        done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--report", report)
    finally:
        (tmp_path / "report").chmod(0o755)
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert done.stderr.startswith("fmutrace: error: ") and len(done.stderr.strip().splitlines()) == 1


@pytest.mark.slow
def test_an_fmu_without_a_binary_for_this_platform_is_bad_input(tmp_path):
    """PassThrough without its Linux binary: run says so in one line, exit 2."""
    fmu = tmp_path / "windows_only.fmu"
    with zipfile.ZipFile(PASS_THROUGH) as source, zipfile.ZipFile(fmu, "w") as target:
        for item in source.infolist():
            if not item.filename.startswith("binaries/linux64/"):
                target.writestr(item, source.read(item))
    (tmp_path / "in.csv").write_text(INPUT)
    done = fmutrace("run", fmu, "--input", tmp_path / "in.csv", "--stop-time", "0.5", "--step-size", "0.1")
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert "no binaries/linux64/PassThrough.so in the FMU" in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr


@pytest.mark.slow
def test_ctrl_c_ends_the_command_with_130_and_one_line(tmp_path):
    """SIGINT (Ctrl-C) in the middle of a campaign: exit 130, one line, no traceback."""
    slow = "StartTime,0\nStopTime,1000000\nStepSize,0.01\nRelTol,1e-6\n"  # 10^8 steps a case: seconds
    for n in range(3):
        os.makedirs(tmp_path / "cases" / f"c{n}")
        (tmp_path / "cases" / f"c{n}" / "PassThrough_ref.csv").write_text("time,y\n0,0\n1000000,1\n")
        (tmp_path / "cases" / f"c{n}" / "PassThrough_in.csv").write_text("time,u\n0,1\n")
        (tmp_path / "cases" / f"c{n}" / "PassThrough_ref.opt").write_text(slow)
    code, stdout, stderr = signalled_campaign(tmp_path / "cases", tmp_path / "report", signal.SIGINT)
    assert "Traceback" not in stdout + stderr, stdout + stderr
    assert code == 130, stdout + stderr
    assert len(stderr.strip().splitlines()) == 1, stderr


@pytest.mark.slow
def test_no_copy_of_the_tests_fmus_is_left_in_the_temporary_folder(tmp_path):
    """A campaign in its own temporary folder leaves nothing there (its
    unpacked FMU removed at exit)."""
    shared = tmp_path / "tmp"
    shared.mkdir()
    write_case(tmp_path / "cases" / "one")
    done = fmutrace(
        "compare", PASS_THROUGH, tmp_path / "cases", "--plots", "none", env=dict(os.environ, TMPDIR=str(shared))
    )
    no_traceback(done)
    assert done.returncode == 0, output(done)
    assert not list(shared.iterdir())


@pytest.mark.slow
@pytest.mark.parametrize("identification,version,name", [(b"MDF     ", 410, "damaged"), (b"UnFinMF ", 411, "logger")])
def test_a_damaged_mdf_file_leaves_no_copy_and_no_traceback(identification, version, name, tmp_path):
    """An MDF 4 file marked not finalized (as a CAN logger leaves its file, 'UnFinMF ', too), its
    blocks garbage: asammdf copies it into the temporary folder to finalize it and fails. The case
    is invalid (exit 2, one line), the copy gone, no traceback of asammdf's clean-up."""
    shared = tmp_path / "tmp"
    shared.mkdir()
    text = f"{version // 100}.{version % 100}    ".encode()
    header = identification + text + b"fmutrace" + bytes(4) + version.to_bytes(2, "little") + bytes(30)
    header += (1).to_bytes(2, "little") + bytes(2)  # unfinalized standard flags: 1
    (tmp_path / f"{name}.mf4").write_bytes(header + b"##HD" + b"\xff" * 200)
    done = fmutrace("compare", PASS_THROUGH, tmp_path / f"{name}.mf4", env=dict(os.environ, TMPDIR=str(shared)))
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert f"{name}.mf4: not a readable MDF file" in done.stderr, done.stderr
    assert not list(shared.iterdir())


@pytest.mark.slow
def test_a_small_mdf_file_declaring_more_samples_than_the_bound_is_refused_before_reading(tmp_path):
    """Issue 37: a small MDF4 file whose channel group declares 300 million samples (its cycle count,
    the uint64 after the CG block's record id) is refused at once, naming the file, channel, count and
    bound; nothing is read or allocated for them."""
    from asammdf import MDF, Signal

    mdf = MDF(version="4.10")
    mdf.append([Signal(np.arange(3.0), np.arange(3.0), name="u"), Signal(np.arange(3.0), np.arange(3.0), name="y")])
    mdf.save(str(tmp_path / "small.mf4"), overwrite=True)
    mdf.close()
    data = bytearray((tmp_path / "small.mf4").read_bytes())
    at = data.index(b"##CG")
    count = at + 24 + 8 * int.from_bytes(data[at + 16 : at + 24], "little") + 8
    data[count : count + 8] = (300_000_000).to_bytes(8, "little")
    (tmp_path / "small.mf4").write_bytes(bytes(data))
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "small.mf4", timeout=60)
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert (
        f"{tmp_path / 'small.mf4'}: channel 'u' (and 1 more) of channel group 0: 300,000,000 samples, each a cycle "
        "of its own: more than the bound of 200,000,000 steps"
    ) in done.stderr


@pytest.mark.slow
def test_recording_options_on_case_folders_are_not_left_unused_silently(tmp_path):
    """--step-size and --set read recordings; given with case folders alone
    they change nothing, and the command says so (the case passes as its
    own settings make it)."""
    write_case(tmp_path / "cases" / "one")
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", "--step-size", "0.2", "--set", "u=7")
    no_traceback(done)
    assert done.returncode == 0, output(done)
    assert "fmutrace: warning: --step-size, --set not used" in done.stderr, done.stderr


def bounded_memory():
    """A child's address space bounded (2 GiB): a command that allocates without bound fails instead of
    taking the machine."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))


@pytest.mark.slow
@pytest.mark.parametrize("times", [("--step-size", "1e-12", "--stop-time", "1"), ("--stop-time", "1e300")])
def test_run_refuses_more_steps_than_the_bound_before_it_allocates(tmp_path, times):
    """fmutrace run --step-size 1e-12 (10^12 steps) or a stop time of 1e300:
    refused at once, exit 2, the value and the bound named."""
    done = run_bounded(
        [sys.executable, "-m", "fmutrace", "run", str(PASS_THROUGH), "--step-size", "0.1", *times],
        timeout=60,
        what="fmutrace run " + " ".join(times),
        preexec_fn=bounded_memory,
    )
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert "more than the bound of 200,000,000 steps" in done.stderr, done.stderr


@pytest.mark.slow
def test_a_recording_of_millions_of_columns_is_refused_at_once(tmp_path):
    """A CSV recording of 2.5 million columns (a 21 MB header line: 9 + 2.5e6
    'c' + 16,388,890 digits + 2,499,999 commas; and one row): refused naming
    the line and the bound, within a bounded memory, instead of minutes of
    work towards a MemoryError."""
    columns = 2_500_000
    header = "time,u,y," + ",".join(f"c{i}" for i in range(columns))
    (tmp_path / "wide.csv").write_text(header + "\n" + "0,1,1," + ",".join("0" * columns) + "\n")
    done = run_bounded(
        [sys.executable, "-m", "fmutrace", "compare", str(PASS_THROUGH), str(tmp_path / "wide.csv")],
        timeout=120,
        what="fmutrace compare wide.csv",
        preexec_fn=bounded_memory,
    )
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert "wide.csv, line 1: a line of 21,388,898 characters: more than the 4,194,304" in done.stderr, done.stderr


# 6. Numbers


@pytest.mark.slow
def test_an_underscore_is_no_digit_separator_in_a_case_file(tmp_path):
    """'1_0' is Python's literal for 10, not a number of a CSV file: the case
    is invalid, its message at the cell (a recording reads IEC's 1_000 on purpose)."""
    case = write_case(tmp_path / "cases" / "underscore")
    (case / "PassThrough_in.csv").write_text("time,u\n0,1\n0.2,1_0\n")
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases")
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert "PassThrough_in.csv, line 3, column 2: '1_0' in column 'u' is not a number" in done.stderr, done.stderr


@pytest.mark.slow
@pytest.mark.parametrize("line", ["StepSize,inf", "StopTime,inf", "StartTime,-inf"])
def test_a_case_time_that_is_not_finite_is_refused(line, tmp_path):
    case = write_case(tmp_path / "cases" / "infinite")
    key = line.split(",")[0]
    opt = "".join(o + "\n" for o in OPT.splitlines() if not o.startswith(key + ",")) + line + "\n"
    (case / "PassThrough_ref.opt").write_text(opt)
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases")
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert f"PassThrough_ref.opt, line 4, column 2: {key} '{line.split(',')[1]}' is not a finite number" in (
        done.stderr
    ), done.stderr


@pytest.mark.slow
def test_a_case_of_more_steps_than_the_bound_is_refused_before_it_runs(tmp_path):
    """StopTime 1e300 at 0.1 s: the case is invalid at once (the run's bound: one bound for every way to ask)."""
    case = write_case(tmp_path / "cases" / "endless")
    (case / "PassThrough_ref.opt").write_text(OPT.replace("StopTime,0.5", "StopTime,1e300"))
    started = time.monotonic()
    done = fmutrace("compare", PASS_THROUGH, tmp_path / "cases", timeout=120)
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert "PassThrough_ref.opt: 1e+301 steps of 0.1 s from 0.0 to 1e+300 s: more than the bound of 200,000,000" in (
        done.stderr
    ), done.stderr
    assert time.monotonic() - started < 60


@pytest.mark.slow
def test_a_plot_that_cannot_be_drawn_costs_the_figure_not_the_verdict(tmp_path, monkeypatch):
    from fmutrace import _pipeline

    def broken(*args, **kwargs):
        raise OverflowError("Exceeded cell block limit")  # as Agg says of a path too complex to draw

    monkeypatch.setattr(_pipeline, "draw", broken)
    write_case(tmp_path / "cases" / "differs", ref=REF.replace("0.3,3", "0.3,2"))
    write_case(tmp_path / "cases" / "same")
    campaign = compare(
        [PASS_THROUGH], [tmp_path / "cases"], report=tmp_path / "report", plots="png", run=RunOptions(jobs=1)
    )
    by_name = {c.case: c for c in campaign.cases}
    assert (by_name["differs"].status, by_name["same"].status) == ("fail", "pass")
    for c in by_name.values():
        assert c.messages[-1] == "no plot: drawing it failed (OverflowError: Exceeded cell block limit)"
    assert (tmp_path / "report" / "index.html").exists()


@pytest.mark.slow
def test_a_time_stamp_that_is_not_finite_is_refused_in_a_recording(tmp_path):
    """A recording's time stamp nan (or inf): exit 2 and the cell, not a comparison at a garbage time."""
    recording = tmp_path / "rec.csv"
    recording.write_text("time,u,y\n0,1,0\nnan,1,1\n0.2,3,1\n0.3,3,3\n")
    done = fmutrace("compare", PASS_THROUGH, recording)
    no_traceback(done)
    assert done.returncode == 2, output(done)
    assert "rec.csv, line 3, column 1: time nan in column 'time' is not a finite number" in done.stderr, done.stderr
