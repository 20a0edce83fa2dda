"""Campaigns that lose nothing: results journaled as each case finishes, a
killed client resumed without recomputing, a second campaign into the same
report folder refused, a Dask worker killed in the middle."""

import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import fmutrace
from fmutrace._worker import CaseSettings, FmuFile
from support.fmu_driver import BUILD_DIR
from support.scenarios import FMI_VERSIONS, SCENARIO_ROOT, discover, fmu_path
from support.reports import without_timings

FMUTRACE = Path(sys.executable).parent / "fmutrace"
PASS_THROUGH = BUILD_DIR / "benchmarks" / "fmi3" / "PassThrough.fmu"
WAIT = 120


def step_cases(root, model, values):
    """A case per value k, worked by hand for PassThrough's equation
    y(t + 0.1) = u(t): u = k from t = 0.2 on."""
    for k in values:
        folder = root / f"case_{k:02d}"
        folder.mkdir(parents=True)
        (folder / f"{model}_in.csv").write_text(f"time,u\n0,0\n0.2,{k}\n")
        (folder / f"{model}_ref.csv").write_text(f"time,y\n0,0\n0.1,0\n0.2,0\n0.3,{k}\n0.4,{k}\n")
        (folder / f"{model}_ref.opt").write_text("StartTime,0\nStopTime,0.4\nStepSize,0.1\n")
    return root


def pass_through_cases(root, count):
    return step_cases(root, "PassThrough", range(count))


def start(args):
    return subprocess.Popen(
        [str(FMUTRACE), *map(str, args)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def finish(process):
    try:
        out, err = process.communicate(timeout=WAIT)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        raise AssertionError("fmutrace did not finish within the bound") from None
    return process.returncode, out, err


def wait_for(condition, what):
    deadline = time.monotonic() + WAIT
    while not condition():
        assert time.monotonic() < deadline, f"{what} did not happen within {WAIT} s"
        time.sleep(0.05)


def journal_keys(report):
    lines = (report / "results.jsonl").read_text().splitlines()
    keys = []
    for line in lines[1:]:
        try:
            keys.append(json.loads(line)["key"])
        except ValueError:
            pass  # the line the kill cut short
    return keys


def comparable(report):
    results = json.loads((report / "results.json").read_text())
    return [(c["case"], c["fmu"], c["status"], c["messages"], c.get("plot_data")) for c in results["cases"]]


@pytest.mark.slow
def test_a_killed_client_resumes_without_recomputing(tmp_path):
    cases = pass_through_cases(tmp_path / "cases", 40)
    undisturbed = tmp_path / "undisturbed"
    code, out, _ = finish(
        start(["compare", PASS_THROUGH, cases, "--report", undisturbed, "--jobs", 1, "--plots", "all"])
    )
    assert code == 0, out

    report = tmp_path / "report"
    process = start(["compare", PASS_THROUGH, cases, "--report", report, "--jobs", 1, "--plots", "all"])
    wait_for(lambda: (report / "results.jsonl").exists() and len(journal_keys(report)) >= 5, "five journaled cases")
    os.killpg(process.pid, signal.SIGKILL)
    process.communicate(timeout=WAIT)
    done = journal_keys(report)
    assert 5 <= len(done) < 40 and len(set(done)) == len(done)

    code, out, err = finish(
        start(["compare", PASS_THROUGH, cases, "--report", report, "--jobs", 1, "--plots", "all", "--resume"])
    )
    assert code == 0, out + err
    assert f"({len(done)} cases from the journal)" in out
    keys = journal_keys(report)
    assert len(keys) == 40 and len(set(keys)) == 40  # every case exactly once: nothing done twice
    assert keys[: len(done)] == done
    assert comparable(report) == comparable(undisturbed)
    assert without_timings((report / "summary.md").read_text()) == without_timings(
        (undisturbed / "summary.md").read_text()
    )

    code, out, _ = finish(start(["compare", PASS_THROUGH, cases, "--report", report, "--resume"]))
    assert code == 0 and "on the journal" in out  # all done: nothing runs


@pytest.mark.slow
def test_without_options_the_command_plots_only_the_failing_cases_beyond_500(tmp_path):
    """The command's default is the documented one: a plot and a result CSV
    for every case up to 500 (test_fmutrace.py's report test: every case
    plotted), the failing ones beyond, and a page for a case with more to
    show than its row. Two of 501 cases differ at t = 0.4."""
    cases = pass_through_cases(tmp_path / "cases", 501)
    for k in (7, 300):
        reference = cases / f"case_{k:02d}" / "PassThrough_ref.csv"
        reference.write_text(f"time,y\n0,0\n0.1,0\n0.2,0\n0.3,{k}\n0.4,{k + 1}\n")
    report = tmp_path / "report"
    code, out, err = finish(start(["compare", PASS_THROUGH, cases, "--report", report]))
    assert code == 1, out + err
    assert "499 of 501 cases pass, 2 differ" in out
    failing = ["PassThrough-fmi3/case_07", "PassThrough-fmi3/case_300"]
    plotted = sorted(str(p.relative_to(report)) for p in report.rglob("*.plot.js"))
    assert plotted == [f"{c}.plot.js" for c in failing]
    assert sorted(str(p.relative_to(report)) for p in report.rglob("*_out.csv")) == [f"{c}_out.csv" for c in failing]
    assert [c["case"] for c in json.loads((report / "results.json").read_text())["cases"] if "plot_data" in c] == [
        "case_07",
        "case_300",
    ]
    # a page for each case with more to show than its row (the failing ones); the index links to them alone
    pages = sorted(str(p.relative_to(report)) for p in report.rglob("*.html") if p.name != "index.html")
    assert pages == [f"{c}.html" for c in failing]
    index = (report / "index.html").read_text()
    assert index.count('href="PassThrough-fmi3/') == 2 and ">case_08</td>" in index


def test_a_journal_line_cut_short_is_run_again_and_the_next_entries_read(tmp_path):
    cases = pass_through_cases(tmp_path / "cases", 6)
    report = tmp_path / "report"
    assert fmutrace.compare(PASS_THROUGH, cases, report=report, run=fmutrace.RunOptions(jobs=1)).passed
    journal = report / "results.jsonl"
    lines = journal.read_bytes().splitlines(keepends=True)
    journal.write_bytes(b"".join(lines[:4]) + lines[4][:25])  # three cases whole, the fourth cut by a kill
    campaign = fmutrace.compare(PASS_THROUGH, cases, report=report, run=fmutrace.RunOptions(jobs=1), resume=True)
    assert campaign.passed and campaign.where == "1 process (3 cases from the journal)"
    assert [o.case for o in campaign.cases] == [f"case_{k:02d}" for k in range(6)]
    keys = journal_keys(report)
    assert len(keys) == 6 and len(set(keys)) == 6
    assert [json.loads(c)["counts"] for c in [(report / "results.json").read_text()]] == [
        {"pass": 6, "fail": 0, "error": 0, "invalid": 0}
    ]


def test_a_journaled_campaign_gives_its_outcomes_and_results_back(tmp_path):
    """With a report, the outcomes are read back from the journal and the
    results from their CSV files: the outcomes of a campaign kept in memory,
    and the results worked by hand (y(t + 0.1) = u(t))."""
    cases = step_cases(tmp_path / "cases", "PassThrough", [3, 4])
    in_memory = fmutrace.compare(PASS_THROUGH, cases, run=fmutrace.RunOptions(jobs=1))
    journaled = fmutrace.compare(
        PASS_THROUGH, cases, run=fmutrace.RunOptions(jobs=1), plots="all", report=tmp_path / "report"
    )
    assert len(journaled.cases) == len(in_memory.cases) == 2
    for k, kept, read in zip((3, 4), in_memory.cases, journaled.cases, strict=True):
        assert (read.case, read.fmu, read.status, read.messages) == (kept.case, kept.fmu, kept.status, kept.messages)
        assert list(read.result["time"]) == pytest.approx([0, 0.1, 0.2, 0.3, 0.4], abs=1e-15)
        assert list(read.result["y"]) == [0, 0, 0, k, k]
    assert journaled.cases[-1].case == "case_04" and journaled.cases[0:1][0].case == "case_03"
    assert journaled.counts() == in_memory.counts() == {"pass": 2, "fail": 0, "error": 0, "invalid": 0}


def test_the_failed_cases_of_a_journaled_campaign_with_or_without_their_results(tmp_path):
    """The command prints the failing cases' messages only: failed(results=False) gives them without reading
    each result back from its CSV file."""
    cases = step_cases(tmp_path / "cases", "PassThrough", [3, 4, 5])
    (cases / "case_04" / "PassThrough_ref.csv").write_text("time,y\n0,0\n0.1,0\n0.2,0\n0.3,4\n0.4,9\n")
    campaign = fmutrace.compare(PASS_THROUGH, cases, run=fmutrace.RunOptions(jobs=1), report=tmp_path / "report")
    whole, light = campaign.failed(), campaign.failed(results=False)
    assert [o.case for o in whole] == [o.case for o in light] == ["case_04"]
    assert whole[0].messages == light[0].messages and whole[0].status == light[0].status == "fail"
    assert list(whole[0].result["y"]) == [0, 0, 0, 4, 4] and light[0].result is None


def test_resume_refuses_a_journal_of_another_campaign(tmp_path):
    cases = pass_through_cases(tmp_path / "cases", 3)
    report = tmp_path / "report"
    assert finish(start(["compare", PASS_THROUGH, cases, "--report", report]))[0] == 0
    code, _, err = finish(start(["compare", PASS_THROUGH, cases, "--report", report, "--resume", "--rel-tol", "1e-3"]))
    assert code == 2 and "made by a campaign with other FMUs or options" in err
    code, _, err = finish(start(["compare", PASS_THROUGH, cases, "--resume"]))
    assert code == 2 and "give it with --report" in err


@pytest.mark.slow
def test_a_second_campaign_into_the_same_report_folder_is_refused(tmp_path):
    cases = pass_through_cases(tmp_path / "cases", 30)
    report = tmp_path / "report"
    # (drawn as PNG: 30 cases that last seconds)
    first = start(["compare", PASS_THROUGH, cases, "--report", report, "--jobs", 1, "--plots", "png"])
    wait_for(lambda: (report / "results.jsonl").exists() and journal_keys(report), "the first campaign's start")
    code, out, err = finish(start(["compare", PASS_THROUGH, cases, "--report", report, "--jobs", 1]))
    assert code == 2, out + err
    assert f"another campaign is writing this report folder (pid {first.pid})" in err
    code, out, _ = finish(first)
    assert code == 0 and "30 of 30 cases pass" in out  # undisturbed
    assert len(set(journal_keys(report))) == 30
    assert json.loads((report / "results.json").read_text())["counts"]["pass"] == 30
    code, out, _ = finish(start(["compare", PASS_THROUGH, cases, "--report", report, "--jobs", 1]))
    assert code == 0  # the lock went with the first campaign


@pytest.mark.cluster
def test_a_worker_killed_in_the_middle_of_a_campaign(cluster, tmp_path):
    """SIGKILL to a Dask worker process while it works: its batches run
    again elsewhere, the campaign completes, each case once, the same
    report as a run in one process, and the cases run again say why."""
    from dask.distributed import Client

    fmus = [fmu_path(BUILD_DIR, model, version) for model in ("RateLimiter", "Ramp") for version in FMI_VERSIONS]
    cases = [SCENARIO_ROOT / "RateLimiter", SCENARIO_ROOT / "Ramp"]
    report = tmp_path / "killed"
    result = {}
    campaign = threading.Thread(
        target=lambda: result.setdefault(
            "campaign",
            fmutrace.compare(
                fmus, cases, report=report, run=fmutrace.RunOptions(scheduler=cluster, cluster_timeout=600), plots="all"
            ),
        )
    )
    campaign.start()
    wait_for(lambda: (report / "results.jsonl").exists() and len(journal_keys(report)) >= 3, "three finished cases")
    with Client(cluster, timeout=WAIT) as client:
        pids = client.run(os.getpid)
        victim = sorted(pids.values())[0]
        os.kill(victim, signal.SIGKILL)
        campaign.join(timeout=600)
        assert not campaign.is_alive()
        assert victim not in client.run(os.getpid).values()  # it died (its nanny starts another)
    killed = result["campaign"]
    assert killed.passed, killed.summary()
    # the batches the killed worker held ran again, and their cases say so
    retried = [c.get("retried") for c in json.loads((report / "results.json").read_text())["cases"]]
    assert any(retried), retried
    # (by the scheduler, or by the campaign: a batch the scheduler cancelled, its FMU's bytes lost with the worker)
    reasons = ("its Dask worker died while it held the case's batch (", "lost with its Dask worker: ")
    assert all(r.startswith(reasons) for r in retried if r), {r for r in retried if r}
    total = 2 * len(discover(["RateLimiter", "Ramp"]))
    keys = journal_keys(report)
    assert len(killed.cases) == total and len(keys) == total and len(set(keys)) == total
    fmutrace.compare(fmus, cases, report=tmp_path / "serial", run=fmutrace.RunOptions(jobs=1), plots="all")
    assert comparable(report) == comparable(tmp_path / "serial")
    for page in ("index.html", "summary.md"):  # (but for the notes of the cases run again)
        assert without_timings(re.sub(RAN_AGAIN_NOTE, "", (report / page).read_text())) == without_timings(
            (tmp_path / "serial" / page).read_text()
        )


RAN_AGAIN_NOTE = r" ?\\?\(?ran a second time, on a fresh process, [^<|]*?(?=\s?\||</td>)"  # in a row of the report
FAULTY = {v: BUILD_DIR / "fixtures" / f"fmi{v}" / "Faulty.fmu" for v in (2, 3)}
# in the sanitizer tree AddressSanitizer's handler takes the SIGSEGV: it reports and exits with status 1
CRASH = "exited with status 1" if os.environ.get("RL_SANITIZED") == "1" else "killed by signal SIGSEGV"


def faulty_cases(root, values):
    """Cases of the Faulty fixture (PassThrough's equation): k = 13 crashes
    its process, k = 17 hangs, k = 19 is killed once (as from outside: the
    OOM killer, an operator) when the file $FAULTY_ONCE names exists."""
    return step_cases(root, "Faulty", values)


KILLED = "the simulation's process was killed by signal SIGKILL while running this case"
RAN_AGAIN = "ran a second time, on a fresh process, after its first run's process ended: "


@pytest.fixture
def killed_once(tmp_path, monkeypatch):
    """The file whose removal kills the process running the Faulty fixture's case 19 (once)."""
    once = tmp_path / "kill-case-19-once"
    once.touch()
    monkeypatch.setenv("FAULTY_ONCE", str(once))
    return once


@pytest.mark.parametrize("version,jobs", [(2, 2), (3, 2), (3, 1), (2, None), (3, None)])
def test_a_case_that_crashes_its_process_fails_alone_naming_the_signal(version, jobs, tmp_path):
    """The worker it kills is replaced and only the crashing case fails:
    with two workers, with the default (no --jobs), and with --jobs 1 and
    --case-timeout (one worker process)."""
    cases = faulty_cases(tmp_path / "cases", [1, 2, 13, 4, 5, 6])
    args = ["compare", FAULTY[version], cases, "--report", tmp_path / "report"]
    args += [] if jobs is None else ["--jobs", jobs] + (["--case-timeout", 60] if jobs == 1 else [])
    code, out, err = finish(start(args))
    assert code == 1, out + err
    crashed = f"the simulation's process was {CRASH} while running this case"
    # run again once on a fresh worker, it crashed that one too: blamed, one failed case
    assert f"ERROR  case_13 on Faulty (FMI {version})\n      {crashed}\n      {RAN_AGAIN}{crashed}\n" in out
    assert "5 of 6 cases pass, 0 differ, 1 failed to simulate" in out
    assert "2 lost with a case, 1 case run again" in out  # (the headline's where)
    assert len(set(journal_keys(tmp_path / "report"))) == 6
    results = {c["case"]: c for c in json.loads((tmp_path / "report" / "results.json").read_text())["cases"]}
    assert results["case_13"]["retried"] == crashed and results["case_13"]["messages"] == [crashed]
    assert [case for case, c in results.items() if "retried" in c] == ["case_13"]


@pytest.mark.parametrize("jobs", [2, 1, None])
def test_a_case_whose_process_is_killed_once_runs_again_and_passes(jobs, killed_once, tmp_path):
    """A worker killed while it runs a case (the fixture's case 19 kills its
    process once) costs no case: the case runs again on a fresh worker and
    passes, the campaign ends 0, and the output, results.json and index.html
    say which case ran again and why."""
    cases = faulty_cases(tmp_path / "cases", [1, 2, 19, 4, 5])
    report = tmp_path / "report"
    args = ["compare", FAULTY[3], cases, "--report", report]
    args += [] if jobs is None else ["--jobs", jobs] + (["--case-timeout", 60] if jobs == 1 else [])
    code, out, err = finish(start(args))
    assert code == 0, out + err
    assert not killed_once.exists()  # (the kill happened)
    assert f"PASS  case_19 on Faulty (FMI 3)\n      {RAN_AGAIN}{KILLED}\n" in out
    assert "5 of 5 cases pass" in out and "1 lost with a case, 1 case run again)." in out
    results = {c["case"]: c for c in json.loads((report / "results.json").read_text())["cases"]}
    assert {case: (c["status"], c.get("retried")) for case, c in results.items()} == {
        "case_01": ("pass", None),
        "case_02": ("pass", None),
        "case_19": ("pass", KILLED),
        "case_04": ("pass", None),
        "case_05": ("pass", None),
    }
    assert (RAN_AGAIN + KILLED).replace("'", "&#x27;") in (report / "index.html").read_text()


@pytest.mark.parametrize("jobs", [pytest.param(1, marks=pytest.mark.slow), 2])
def test_a_case_that_hangs_is_stopped_after_the_timeout(jobs, tmp_path):
    """The hanging case is stopped once its timeout has passed (not before),
    the campaign goes on to the cases after it, and the command ends (finish
    bounds the wait)."""
    cases = faulty_cases(tmp_path / "cases", [1, 17, 3, 13, 5])
    report = tmp_path / "report"
    code, out, err = finish(
        start(["compare", FAULTY[3], cases, "--jobs", jobs, "--case-timeout", 3, "--report", report])
    )
    assert code == 1, out + err
    assert "ERROR  case_17 on Faulty (FMI 3)\n      stopped after the per-case timeout of 3 s" in out
    assert f"ERROR  case_13 on Faulty (FMI 3)\n      the simulation's process was {CRASH}" in out
    assert "3 of 5 cases pass, 0 differ, 2 failed to simulate" in out
    results = {c["case"]: c for c in json.loads((report / "results.json").read_text())["cases"]}
    assert sorted(results) == [f"case_{k:02d}" for k in (1, 3, 5, 13, 17)]
    assert results["case_17"]["status"] == "error" and results["case_17"]["seconds"] >= 3


@pytest.mark.slow
def test_spawned_workers_give_what_this_process_gives(tmp_path, monkeypatch):
    """Where a worker cannot be forked (another thread runs, or not Linux) it
    is a new Python: the same outcomes as in this process, the crashing case
    failing alone."""
    from fmutrace import _workers

    monkeypatch.setattr(_workers, "can_fork", lambda: False)
    cases = faulty_cases(tmp_path / "cases", [1, 2, 13, 4])
    spawned = fmutrace.compare(FAULTY[3], cases, run=fmutrace.RunOptions(jobs=2), plots="none")
    assert spawned.where.startswith("2 local processes"), spawned.where
    statuses = {o.case: o.status.value for o in spawned.cases}
    assert statuses == {"case_01": "pass", "case_02": "pass", "case_04": "pass", "case_13": "error"}, statuses
    [crashed] = [o for o in spawned.cases if o.case == "case_13"]
    assert crashed.messages[0].startswith(f"the simulation's process was {CRASH}"), crashed.messages
    good = faulty_cases(tmp_path / "good", [1, 2, 4])
    in_process = fmutrace.compare(FAULTY[3], good, run=fmutrace.RunOptions(jobs=1), plots="none")
    again = fmutrace.compare(FAULTY[3], good, run=fmutrace.RunOptions(jobs=2), plots="none")
    assert [(o.case, o.status, o.messages) for o in again.cases] == [
        (o.case, o.status, o.messages) for o in in_process.cases
    ]


@pytest.mark.parametrize("plots,count,workers", [("none", 6, 1), pytest.param("png", 24, 2, marks=pytest.mark.slow)])
def test_the_default_starts_the_workers_the_work_pays_for(plots, count, workers, tmp_path):
    """By default a second worker starts only when the work left pays for
    its start-up, measured: 6 cases of a millisecond or so run in one (a
    start-up loads the FMU: tens of milliseconds), 24 cases drawn as PNG (a
    tenth of a second each) in two, where there are two cores. (The command:
    its workers are forked, as users get them on Linux.)"""
    cases = pass_through_cases(tmp_path / "cases", count)
    code, out, err = finish(start(["compare", PASS_THROUGH, cases, "--report", tmp_path / "report", "--plots", plots]))
    assert code == 0 and f"{count} of {count} cases pass" in out, out + err
    expected = min(workers, len(os.sched_getaffinity(0)))
    assert f" on {expected} local process{'es' if expected > 1 else ''})." in out, out


def test_dask_batches_take_the_size_measured_when_each_starts():
    """A Dask batch's size is asked as the batch starts (one case before any
    is measured, then about a second of measured work), and a batch never
    holds two FMUs' cases."""
    from fmutrace import _executors

    first, second = object(), object()
    todo = [(i, first if i < 7 else second, f"case_{i}", f"case_{i}") for i in range(10)]
    sizes = iter([1, 3, 3, 2, 5])
    batches = list(_executors._batches(todo, lambda: next(sizes), ship_texts=False))
    assert [(fmu is first, [i for i, *_ in batch]) for fmu, batch in batches] == [
        (True, [0]),
        (True, [1, 2, 3]),
        (True, [4, 5, 6]),
        (False, [7, 8]),
        (False, [9]),
    ]


def worker_pids():
    """The pids of this process's children (its workers), as Linux lists them."""
    tasks = Path("/proc/self/task")
    return {int(pid) for task in tasks.iterdir() for pid in (task / "children").read_text().split()}


def windows_code_path(monkeypatch):
    """The worker pool as Windows runs it, on Linux: spawned workers (no
    fork), no os.set_blocking (Windows' Python 3.11 has none for pipes)."""
    from fmutrace import _workers

    monkeypatch.setattr(_workers, "can_fork", lambda: False)
    monkeypatch.delattr(os, "set_blocking")


@pytest.mark.slow
def test_the_windows_code_path_runs_a_campaign_with_a_worker_killed_from_outside(killed_once, tmp_path, monkeypatch):
    """A campaign of 300 cases on spawned workers waited on portably, one
    worker killed with SIGKILL from outside in the middle and the fixture's
    case 19 killing its own process once: every case reported once, all
    pass, the case that was running on a killed worker ran again."""
    windows_code_path(monkeypatch)
    values = [k for k in range(302) if k not in (13, 17)]
    cases = faulty_cases(tmp_path / "cases", values)
    report = tmp_path / "report"
    killed = []

    def kill_a_worker():
        wait_for(lambda: (report / "results.jsonl").exists() and len(journal_keys(report)) >= 100, "100 cases")
        victim = min(worker_pids())
        os.kill(victim, signal.SIGKILL)
        killed.append(victim)

    killer = threading.Thread(target=kill_a_worker)
    killer.start()
    result = fmutrace.compare(FAULTY[2], cases, report=report, run=fmutrace.RunOptions(jobs=2), plots="none")
    killer.join(timeout=WAIT)
    assert killed and killed[0] not in worker_pids()
    assert result.passed and result.exit_code == 0, result.summary()
    assert result.where.startswith("2 local processes"), result.where
    results = json.loads((report / "results.json").read_text())["cases"]
    assert sorted(c["case"] for c in results) == sorted(f"case_{k:02d}" for k in values)
    assert len(set(journal_keys(report))) == 300
    retried = {c["case"]: c["retried"] for c in results if "retried" in c}
    assert retried["case_19"] == KILLED
    # the worker killed from outside ran a case then (a batch's cases follow each other closely) or none
    assert set(retried.values()) == {KILLED} and len(retried) <= 2, retried


@pytest.mark.parametrize("spawned", [False, True])
def test_the_first_error_of_a_campaign_is_the_one_raised(spawned, tmp_path, monkeypatch):
    """An error in the middle of a campaign (here the caller's) ends it with
    that error, its workers stopped, whatever the clean-up meets (here a
    worker that will not end): the clean-up's trouble is a note on it."""
    from fmutrace import _workers

    if spawned:
        windows_code_path(monkeypatch)
    cases = faulty_cases(tmp_path / "cases", range(1, 9))
    before = worker_pids()

    def finished(i, outcome):
        raise RuntimeError(f"the caller's own error at case {i}")

    def stubborn(worker, kill):
        worker.process.kill()
        worker.process.wait(timeout=WAIT)
        raise OSError("the worker would not end")

    monkeypatch.setattr(_workers._Worker, "end", stubborn)
    path = str(FAULTY[3])
    labels = {"fmu": "Faulty (FMI 3)", "fmu_file": path, "fmu_folder": "Faulty-fmi3"}
    fmus = {path: (FAULTY[3].read_bytes(), FmuFile(path, labels))}
    todo = [(i, path, (str(cases / f"case_{k:02d}"), f"case_{k:02d}", None)) for i, k in enumerate(range(1, 9))]
    pool = _workers.Pool(fmus, CaseSettings(fmutrace.Exact()), jobs=2)
    with pytest.raises(RuntimeError, match="the caller's own error at case") as raised:
        pool.run(todo, finished)
    assert "(stopping the workers then: OSError: the worker would not end)" in raised.value.__notes__
    assert not pool.workers and worker_pids() == before
