"""fmutrace under hostile and careless use, second round (issue 51): every
read bounded (a file read whole, a line, an FMU and its entries inflated),
devices and FIFOs refused by name before a byte is read, outputs written as
the user named them, a report folder that stays the user's, a case file
that is there but cannot be read counted as an invalid case, a worker's
reason shown. Each attack runs through the command (a process of its own;
the memory attacks under a cap of 3 GiB of address space, on sparse files
that take no disk) and ends with a named refusal: no traceback, nothing
written outside, no case dropped from the counts.

The FMU is the PassThrough fixture, its case worked by hand
(support/pass_through.py)."""

import hashlib
import json
import os
import re
import signal
import stat
import subprocess
import sys
import threading
import time
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

import fmutrace
from fmutrace import _lsref
from support.fmu_driver import BUILD_DIR
from support.pass_through import (  # noqa: F401  (commands_start_from_the_defaults: autouse here)
    INPUT,
    PASS_THROUGH,
    REF,
    commands_start_from_the_defaults,
    output,
    run_fmutrace,
    signalled_campaign,
    write_case,
)
from support.process import kill_session

RATE_LIMITER = BUILD_DIR / "fmi3" / "RateLimiter.fmu"
GiB = 1 << 30
MEMORY_CAP = 3 * GiB  # the issue's: each memory attack ends with a named refusal inside it


def capped():
    """A child's address space bounded: one that allocates without a bound fails instead of taking the machine."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))


def fmutrace_command(*args, env=None, timeout=300, cap=True, preexec_fn=None):
    """The command, as users start it, in a process of its own (under the memory cap)."""
    return run_fmutrace(*args, env=env, timeout=timeout, preexec_fn=preexec_fn or (capped if cap else None))


def refused(done, *phrases, status=2):
    """The command ended with status, one line on standard error per
    invalid case at most, no traceback, and each phrase said."""
    text = output(done)
    assert "Traceback" not in text and "MemoryError" not in text, text[-3000:]
    assert done.returncode == status, text[-3000:]
    for phrase in phrases:
        assert phrase in done.stderr, done.stderr[-3000:]
    assert len(done.stderr) < 4000, f"a message of {len(done.stderr)} characters"


def sparse(path, size):
    """A file of size bytes, all zeros, that takes no disk."""
    with open(path, "wb") as file:
        file.truncate(size)
    return path


def with_env(**variables):
    return dict(os.environ, **variables)


# 1. Every read bounded, devices and FIFOs refused by name


@pytest.mark.slow
@pytest.mark.parametrize("jobs", [["--jobs", "1"], []], ids=["in this process", "in workers"])
@pytest.mark.parametrize("name", ["PassThrough_ref.csv", "PassThrough_in.csv", "PassThrough_ref.opt"])
def test_a_2_gib_case_file_is_refused_by_the_read_bound(tmp_path, name, jobs):
    """A sparse 2 GiB case file (all NUL bytes) grew a worker to 23.7 GB
    (--jobs 1: a MemoryError traceback, no report): it is refused by its
    size, the file and the bound named, the other case passes and the
    report is written, within the memory cap."""
    write_case(tmp_path / "cases" / "good")
    bad = write_case(tmp_path / "cases" / "huge")
    sparse(bad / name, 2 * GiB)
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--report", tmp_path / "report", *jobs)
    refused(done, f"{bad / name}: 2,147,483,648 bytes: more than the read bound of 536,870,912 bytes")
    assert "FMUTRACE_READ_LIMIT" in done.stderr
    assert "1 of 2 cases pass" in done.stdout, done.stdout
    assert (tmp_path / "report" / "index.html").is_file() and (tmp_path / "report" / "results.json").is_file()


@pytest.mark.slow
def test_a_300_mb_line_is_refused_and_not_quoted(tmp_path):
    """A 300 MB reference of one line (sparse: NUL bytes), within the read
    bound: refused at its line, the message short (a 300 MB header line
    was quoted whole)."""
    case = write_case(tmp_path / "cases" / "one")
    sparse(case / "PassThrough_ref.csv", 300_000_000)
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--jobs", "1")
    refused(done, "PassThrough_ref.csv, line 1: a line longer than the bound of 4,194,304")


def test_a_long_line_is_quoted_by_its_first_characters(tmp_path):
    """A 1,000,000-character line of an .opt file that is no option: the
    message quotes its first 60 characters and says how long it is."""
    case = write_case(tmp_path / "cases" / "one")
    (case / "PassThrough_ref.opt").write_text("x" * 1_000_000 + "\n")
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--jobs", "1")
    refused(done, f"found {'x' * 60!r}... (1,000,000 characters)")


@pytest.mark.slow
def test_the_read_bound_is_raised_and_lowered_by_one_setting(tmp_path):
    """FMUTRACE_READ_LIMIT: 100M refuses a 300 MB _start.csv by its size;
    1G lets a 900 MB reference be read (refused at its first line instead
    of its size), within the memory cap; a limit that is no size is refused."""
    case = write_case(tmp_path / "cases" / "one")
    sparse(case / "PassThrough_start.csv", 300_000_000)
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", env=with_env(FMUTRACE_READ_LIMIT="100M"))
    refused(done, "PassThrough_start.csv: 300,000,000 bytes: more than the read bound of 104,857,600 bytes")
    (case / "PassThrough_start.csv").unlink()
    sparse(case / "PassThrough_ref.csv", 900_000_000)
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--jobs", "1")
    refused(done, "PassThrough_ref.csv: 900,000,000 bytes: more than the read bound of 536,870,912 bytes")
    done = fmutrace_command(
        "compare", PASS_THROUGH, tmp_path / "cases", "--jobs", "1", env=with_env(FMUTRACE_READ_LIMIT="1G")
    )
    refused(done, "PassThrough_ref.csv, line 1: a line longer than the bound")
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", env=with_env(FMUTRACE_READ_LIMIT="lots"))
    refused(done, "FMUTRACE_READ_LIMIT='lots': not a number of bytes")


@pytest.mark.parametrize(
    "name,target,kind",
    [
        ("README.md", "/dev/zero", "a character device"),
        ("PassThrough_in.csv", "/dev/urandom", "a character device"),
        ("PassThrough_ref.csv", "/dev/zero", "a character device"),
        ("PassThrough_start.csv", "fifo", "a FIFO"),
        ("PassThrough_ref.csv", "fifo", "a FIFO"),
    ],
)
def test_a_device_or_fifo_as_a_case_file_is_refused_by_name(tmp_path, name, target, kind):
    """A case file linked to a device or made a FIFO: the case is invalid,
    named and counted, not a byte read (a FIFO without a writer would block
    for ever), the other case passes."""
    write_case(tmp_path / "cases" / "good")
    bad = write_case(tmp_path / "cases" / "special")
    (bad / name).unlink(missing_ok=True)
    if target == "fifo":
        os.mkfifo(bad / name)
    else:
        (bad / name).symlink_to(target)
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", timeout=120)
    refused(done, f"{bad / name}: {kind}, not a regular file: not read")
    assert "1 of 2 cases pass" in done.stdout, done.stdout


@pytest.mark.slow
def test_a_recording_that_is_a_fifo_is_refused_by_name(tmp_path):
    os.mkfifo(tmp_path / "rec.csv")
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "rec.csv", timeout=120)
    refused(done, "rec.csv: a FIFO, not a regular file: not read")


@pytest.mark.slow
def test_a_6_gib_fmu_is_refused_by_the_read_bound(tmp_path):
    """A valid FMU behind 6 GiB of zeros (a zip may carry data before its
    entries; sparse): refused by its size before it is read whole."""
    fmu = tmp_path / "big.fmu"
    data = PASS_THROUGH.read_bytes()
    with open(fmu, "wb") as file:
        file.truncate(6 * GiB)
        file.seek(6 * GiB)
        file.write(data)
    write_case(tmp_path / "cases" / "one")
    done = fmutrace_command("compare", fmu, tmp_path / "cases")
    refused(done, f"{fmu}: {6 * GiB + len(data):,} bytes: more than the read bound")


def deflated_zeros(archive, name, size):
    """An entry of size zero bytes, deflated (a zip bomb: about a thousandth of it in the archive)."""
    block = bytes(1 << 24)
    info = zipfile.ZipInfo(name)
    info.compress_type = zipfile.ZIP_DEFLATED
    with archive.open(info, "w", force_zip64=True) as entry:
        for _ in range(size // len(block)):
            entry.write(block)


@pytest.mark.slow
def test_a_huge_resources_entry_is_refused_before_it_is_unpacked(tmp_path):
    """A resources/ entry inflating past the read bound (64 MiB here, to
    keep the test short; 6 GiB took 52 s per worker): refused once, naming
    the entry, before anything is unpacked."""
    fmu = tmp_path / "heavy.fmu"
    with zipfile.ZipFile(PASS_THROUGH) as source, zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as target:
        for item in source.infolist():
            target.writestr(item, source.read(item))
        deflated_zeros(target, "resources/blob.bin", 128 << 20)
    write_case(tmp_path / "cases" / "one")
    write_case(tmp_path / "cases" / "two")
    done = fmutrace_command(
        "compare", fmu, tmp_path / "cases", "--jobs", "2", env=with_env(FMUTRACE_READ_LIMIT="64M", TMPDIR=str(tmp_path))
    )
    refused(done, "'resources/blob.bin': inflates to 134,217,728 bytes: more than the read bound of 67,108,864")
    assert done.stderr.count("blob.bin") == 1, done.stderr
    assert not list(tmp_path.glob("fmutrace-*")), "left unpacked"


def ls_ref_reference(fmu):
    """The path in the FMU of the reference of its first smoke-test experiment."""
    with zipfile.ZipFile(fmu) as archive:
        found, _, _ = _lsref.experiments(archive, str(fmu), "smoke-test")
    return found[0].files["references"]


@pytest.mark.slow
def test_a_zip_bomb_in_an_ls_ref_reference_is_refused_before_it_is_inflated(tmp_path):
    """An LS-REF reference.csv replaced by 128 MiB of zeros deflated to
    under 1 MB, the bound 64 MiB (to keep the test short; 8.5 MB to 4 GiB
    gave a MemoryError traceback): check refuses it by its inflated size,
    naming the entry, before it inflates it."""
    reference = ls_ref_reference(RATE_LIMITER)
    fmu = tmp_path / "bomb.fmu"
    with zipfile.ZipFile(RATE_LIMITER) as source, zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as target:
        for item in source.infolist():
            if item.filename != reference:
                target.writestr(item, source.read(item))
        deflated_zeros(target, reference, 128 << 20)
    assert fmu.stat().st_size < 2 << 20
    done = fmutrace_command("check", fmu, env=with_env(FMUTRACE_READ_LIMIT="64M"))
    refused(done, f"{reference!r}: inflates to 134,217,728 bytes: more than the read bound of 67,108,864")


# 2. Outputs as the user named them


@pytest.mark.slow
def test_junit_into_a_link_writes_the_file_it_leads_to(tmp_path):
    """--junit names a link to the user's file: the XML goes into that file,
    the link stays a link (it was replaced by a regular file)."""
    write_case(tmp_path / "cases" / "one")
    mine = tmp_path / "mine.xml"
    mine.write_text("old")
    link = tmp_path / "link.xml"
    link.symlink_to(mine)
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--junit", link)
    refused(done, status=0)
    assert link.is_symlink() and os.readlink(link) == str(mine)
    assert [c.get("name") for c in ET.parse(mine).getroot().iter("testcase")] == ["one"]


def test_junit_into_a_fifo_is_written_into_it(tmp_path):
    """--junit names a FIFO (a pipe to another program): the XML is written
    into it, the FIFO stays one."""
    write_case(tmp_path / "cases" / "one")
    fifo = tmp_path / "junit.fifo"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(Path(fifo).read_bytes()), daemon=True)
    reader.start()
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--junit", fifo, timeout=120)
    reader.join(timeout=60)
    refused(done, status=0)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert got and [c.get("name") for c in ET.fromstring(got[0]).iter("testcase")] == ["one"]


@pytest.mark.slow
def test_junit_into_a_missing_folder_is_an_error_and_makes_no_folder(tmp_path):
    write_case(tmp_path / "cases" / "one")
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--junit", tmp_path / "no" / "dir" / "j.xml")
    refused(done, f"no folder {tmp_path / 'no' / 'dir'} to write it into")
    assert not (tmp_path / "no").exists()
    report = tmp_path / "report"  # (the report folder the command makes may hold it)
    done = fmutrace_command(
        "compare", PASS_THROUGH, tmp_path / "cases", "--report", report, "--junit", report / "j.xml"
    )
    refused(done, status=0)
    assert (report / "j.xml").is_file()


# 3. The report folder is the user's


@pytest.mark.slow
def test_check_does_not_replace_a_users_experiments_folder(tmp_path):
    """report/experiments holds the user's own file: check refuses it, the
    file stays (it was deleted without a word)."""
    report = tmp_path / "report"
    (report / "experiments").mkdir(parents=True)
    (report / "experiments" / "notes.txt").write_text("mine")
    done = fmutrace_command("check", RATE_LIMITER, "--role", "smoke-test", "--report", report)
    refused(done, f"{report / 'experiments'}: not written by fmutrace check")
    assert (report / "experiments" / "notes.txt").read_text() == "mine"


@pytest.mark.slow
def test_check_refuses_a_link_from_its_experiments_folder_to_outside(tmp_path):
    """report/experiments is a link to a folder outside: refused, nothing
    written or deleted there (outside/checked was deleted)."""
    report, outside = tmp_path / "report", tmp_path / "outside"
    (outside / "checked").mkdir(parents=True)
    (outside / "checked" / "keep").write_text("mine")
    report.mkdir()
    (report / "experiments").symlink_to(outside)
    done = fmutrace_command("check", RATE_LIMITER, "--role", "smoke-test", "--report", report)
    refused(done, "a link in the report folder")
    assert sorted(p.relative_to(outside) for p in outside.rglob("*")) == [Path("checked"), Path("checked/keep")]


@pytest.mark.slow
def test_check_replaces_its_own_experiments_and_a_second_check_waits_its_turn(tmp_path):
    """A check's experiments/ is replaced by the next check; a check into a
    report another campaign holds (its lock) is refused before it changes
    anything."""
    report = tmp_path / "report"
    done = fmutrace_command("check", RATE_LIMITER, "--role", "smoke-test", "--report", report)
    refused(done, status=0)
    before = {p: p.read_bytes() for p in (report / "experiments").rglob("*") if p.is_file()}
    assert len(before) > 3
    import fcntl  # (POSIX's; the tests of this tier run on Linux)

    with open(report / ".fmutrace.lock", "a+") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)  # a campaign running
        done = fmutrace_command("check", RATE_LIMITER, "--report", report)
    refused(done, "another campaign is writing this report folder")
    assert {p: p.read_bytes() for p in (report / "experiments").rglob("*") if p.is_file()} == before
    done = fmutrace_command("check", RATE_LIMITER, "--role", "smoke-test", "--report", report)
    refused(done, status=0)


# 4. A case file there but unreadable: an invalid case, named and counted


def test_a_dangling_criteria_file_is_no_default(tmp_path):
    """_criteria.csv a dangling link: the case is invalid, the link named
    (it passed with the command's --abs-tol instead of its own 'exact')."""
    write_case(tmp_path / "cases" / "good")
    bad = write_case(tmp_path / "cases" / "dangling", ref=REF.replace("0.3,3", "0.3,2.5"))
    (bad / "PassThrough_criteria.csv").symlink_to(tmp_path / "gone.csv")
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--abs-tol", "1")
    refused(done, f"{bad / 'PassThrough_criteria.csv'}: a link to {str(tmp_path / 'gone.csv')!r}, which does not exist")
    assert "1 of 2 cases pass" in done.stdout, done.stdout


def modes_binding():
    """The child bound by files' modes: as root, without the capabilities that let root pass them
    (CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH: dropped from the bounding set, so the Python it starts lacks them)."""
    if os.getuid() == 0:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        for capability in (1, 2):
            assert libc.prctl(24, capability, 0, 0, 0) == 0, os.strerror(ctypes.get_errno())  # PR_CAPBSET_DROP


@pytest.mark.slow
def test_a_folder_or_file_without_permission_is_an_invalid_case(tmp_path):
    """A chmod-000 case folder and a chmod-000 input: each is an invalid
    case that says why; none vanishes from the counts ('2 of 3')."""
    cases = tmp_path / "cases"
    write_case(cases / "good")
    write_case(cases / "unreadable")
    (cases / "unreadable" / "PassThrough_in.csv").chmod(0o000)
    closed = write_case(cases / "closed")
    closed.chmod(0o000)
    try:
        done = fmutrace_command("compare", PASS_THROUGH, cases, preexec_fn=modes_binding)
    finally:
        closed.chmod(0o755)
    refused(
        done,
        f"{closed / 'PassThrough_ref.csv'}: Permission denied",
        f"{cases / 'unreadable' / 'PassThrough_in.csv'}: Permission denied",
    )
    assert "1 of 3 cases pass" in done.stdout, output(done)


# 5. A worker's reason reaches the user


@pytest.mark.slow
def test_an_fmu_with_illegal_zip_paths_says_so_once_with_any_jobs(tmp_path):
    """An entry named with a backslash (fmpy refuses to unpack it): one
    line, the reason, exit 2, with --jobs 2 as with --jobs 1 (each case
    said 'exited with status 1')."""
    fmu = tmp_path / "illegal.fmu"
    with zipfile.ZipFile(PASS_THROUGH) as source, zipfile.ZipFile(fmu, "w") as target:
        for item in source.infolist():
            target.writestr(item, source.read(item))
        target.writestr("resources\\evil.txt", "x")
    for n in range(4):
        write_case(tmp_path / "cases" / f"c{n}")
    for jobs in ("1", "2"):
        done = fmutrace_command("compare", fmu, tmp_path / "cases", "--jobs", jobs)
        refused(done, "the FMU cannot be unpacked (Illegal path resources\\evil.txt")
        assert len(done.stderr.strip().splitlines()) == 1, done.stderr
        assert "exited with status" not in output(done)


def no_file_beyond_4_kib():
    """Every write past 4 KiB fails with EFBIG ('File too large'), as one on a full disk fails with ENOSPC."""
    import resource

    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # (else the signal ends the process)
    resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))


@pytest.mark.slow
@pytest.mark.parametrize("jobs", ["1", "2"])
def test_a_workers_errno_reaches_the_user(tmp_path, jobs):
    """The FMU cannot be unpacked for a reason of the machine's (a file
    system that takes no more): the errno's text reaches the user, once
    (81 cases 'exited with status 1' and the reason appeared nowhere)."""
    for n in range(3):
        write_case(tmp_path / "cases" / f"c{n}")
    done = fmutrace_command(
        "compare", PASS_THROUGH, tmp_path / "cases", "--jobs", jobs, cap=False, preexec_fn=no_file_beyond_4_kib
    )
    refused(done, "the FMU cannot be unpacked ([Errno 27] File too large")
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert "exited with status" not in output(done)


# 6. The smaller points


@pytest.mark.slow
@pytest.mark.parametrize("address", ["garbage://x", "tcp://[::1"])
def test_a_scheduler_address_that_is_none_is_a_clear_error(tmp_path, address):
    write_case(tmp_path / "cases" / "one")
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--scheduler", address, cap=False)
    refused(done, f"scheduler {address!r}: not the address of a Dask scheduler")
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr


@pytest.mark.slow
def test_an_underscore_is_no_digit_separator_in_a_mode(tmp_path):
    """'tol:abs=1_0' in a case's criteria is not abs = 10 (the docs: 1_0 is no number)."""
    case = write_case(tmp_path / "cases" / "one")
    (case / "PassThrough_criteria.csv").write_text("y,tol:abs=1_0\n")
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases")
    refused(done, "abs '1_0' is not a number")


@pytest.mark.slow
def test_a_line_break_in_an_ssp_parameter_name_is_refused():
    """An SSP parameter named 'k\\nRateLimiter_extra,1' would add a line of
    its own to the case's _start.csv."""
    ssv = (
        '<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" '
        'name="p"><ssv:Parameters><ssv:Parameter name="k&#10;rateUp,99"><ssv:Real value="1"/></ssv:Parameter>'
        "</ssv:Parameters></ssv:ParameterSet>"
    ).encode()
    with pytest.raises(fmutrace.InputError, match="holds a line break"):
        _lsref.parameter_lines("the FMU", "p.ssv", ssv)


@pytest.mark.slow
def test_a_line_break_in_an_experiment_attribute_is_refused(tmp_path):
    """An experiment's stopTime '2&#10;StepSize,1e-9' would add an option line to the case's .opt file
    (each experiment file changed, the manifest's checksums made theirs)."""
    fmu = tmp_path / "inject.fmu"
    with zipfile.ZipFile(RATE_LIMITER) as source, zipfile.ZipFile(fmu, "w") as target:
        changed, digests = {}, []
        for item in source.infolist():
            data = source.read(item)
            if b"<Experiment " in data:
                changed[item.filename] = re.sub(rb'stopTime="[^"]*"', b'stopTime="2&#10;StepSize,1e-9"', data)
                digests.append([hashlib.sha256(d).hexdigest().encode() for d in (data, changed[item.filename])])
        assert changed
        for item in source.infolist():
            data = changed.get(item.filename) or source.read(item)
            if item.filename.endswith("fmi-ls-manifest.xml"):
                for old, new in digests:
                    data = data.replace(old, new)
            target.writestr(item, data)
    done = fmutrace_command("check", fmu, "--role", "smoke-test")
    refused(done, "'s stopTime '2\\nStepSize,1e-9' holds a line break")


@pytest.mark.slow
def test_a_checks_messages_name_the_fmu_not_a_vanished_temporary_file(tmp_path):
    """check without a report: a reference the FMU carries with a cell that
    is no number is named by the FMU and its experiment (the message named
    a file in a temporary folder removed before it was shown)."""
    reference = ls_ref_reference(RATE_LIMITER)
    fmu = tmp_path / "bad.fmu"
    with zipfile.ZipFile(RATE_LIMITER) as source, zipfile.ZipFile(fmu, "w") as target:
        old = source.read(reference)
        lines = old.decode().splitlines(keepends=True)
        lines[2] = "abc" + lines[2][lines[2].index(",") :]
        new = "".join(lines).encode()
        for item in source.infolist():
            data = source.read(item)
            if item.filename == reference:
                data = new
            elif item.filename.endswith("fmi-ls-manifest.xml"):
                data = data.replace(*(hashlib.sha256(d).hexdigest().encode() for d in (old, new)))
            target.writestr(item, data)
    done = fmutrace_command("check", fmu, "--role", "smoke-test", "--junit", tmp_path / "j.xml")
    refused(done, f"fmutrace: error: {fmu}: experiment ", "line 3, column 1: 'abc' in column")
    assert "check-" not in output(done) and "fmutrace-" not in output(done), output(done)
    assert f"{fmu}: experiment " in (tmp_path / "j.xml").read_text()


@pytest.mark.slow
def test_a_case_timeout_of_0_is_refused(tmp_path):
    write_case(tmp_path / "cases" / "one")
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--case-timeout", "0", cap=False)
    refused(done, "--case-timeout: 0 must be greater than 0")
    with pytest.raises(fmutrace.InputError, match="case_timeout must be more than 0"):
        fmutrace.RunOptions(case_timeout=0)


@pytest.mark.slow
def test_sigterm_ends_the_command_with_a_line(tmp_path):
    """SIGTERM in the middle of a campaign: 143 and one line that says so (it ended without a word)."""
    slow = "StartTime,0\nStopTime,1000000\nStepSize,0.01\n"  # 10^8 steps: seconds
    case = write_case(tmp_path / "cases" / "slow")
    (case / "PassThrough_ref.opt").write_text(slow)
    report = tmp_path / "report"
    code, _, stderr = signalled_campaign(tmp_path / "cases", report, signal.SIGTERM)
    assert "Traceback" not in stderr, stderr
    assert code == 143, stderr
    assert stderr.strip().splitlines() == [
        f"fmutrace: terminated (SIGTERM); the finished cases are in {report}: --resume continues"
    ]


@pytest.mark.slow
def test_a_killed_checks_temporary_cases_are_removed_by_the_next_command(tmp_path):
    """check without a report, killed (SIGKILL) while its cases run: the
    next command removes the cases it wrote (a killed check left its
    temporary folder for good)."""
    shared = tmp_path / "tmp"
    shared.mkdir()
    env = with_env(TMPDIR=str(shared))
    check = subprocess.Popen(
        [sys.executable, "-m", "fmutrace", "check", str(RATE_LIMITER), "--role", "validation", "--jobs", "1"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, start_new_session=True,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while not list(shared.glob("*/check-*/*")) and time.monotonic() < deadline:
            assert check.poll() is None, "the check ended before it was killed"
            time.sleep(0.02)
        written = list(shared.glob("*/check-*"))
        assert written, "no cases written"
        check.kill()
        check.wait(timeout=60)
    finally:
        kill_session(check)
    assert written[0].is_dir(), "the killed check's cases are gone already"
    write_case(tmp_path / "cases" / "one")
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", env=env)
    refused(done, status=0)
    assert not list(shared.iterdir()), list(shared.rglob("*"))


@pytest.mark.slow
def test_the_same_fmu_given_twice_is_one_fmu(tmp_path):
    """The same FMU named twice (once through a link): its cases run once (72 rows linked to 36 pages)."""
    write_case(tmp_path / "cases" / "one")
    write_case(tmp_path / "cases" / "two")
    (tmp_path / "again.fmu").symlink_to(PASS_THROUGH)
    done = fmutrace_command(
        "compare", PASS_THROUGH, tmp_path / "again.fmu", tmp_path / "cases", "--report", tmp_path / "report"
    )
    refused(done, status=0)
    assert "2 of 2 cases pass" in done.stdout, done.stdout
    cases = json.loads((tmp_path / "report" / "results.json").read_text())["cases"]
    assert sorted(c["case"] for c in cases) == ["one", "two"]


# 7. The corpus: every hostile case of this file in one campaign


def test_a_hostile_corpus_runs_with_no_traceback_no_write_outside_and_no_silent_drop(tmp_path):
    """One campaign over a folder of hostile cases beside a good one, under
    the memory cap, bound by files' modes: exit 2, no traceback, each bad
    case named once, every case counted, nothing written outside the report
    folder (and the temporary folder left as it was)."""
    cases, shared = tmp_path / "cases", tmp_path / "tmp"
    shared.mkdir()
    write_case(cases / "good")
    hostile = {}

    def case(name, file, make):
        folder = write_case(cases / name)
        (folder / file).unlink(missing_ok=True)
        make(folder / file)
        hostile[name] = folder / file

    case("huge_ref", "PassThrough_ref.csv", lambda p: sparse(p, 2 * GiB))
    case("zero_readme", "README.md", lambda p: p.symlink_to("/dev/zero"))
    case("random_input", "PassThrough_in.csv", lambda p: p.symlink_to("/dev/urandom"))
    case("fifo_start", "PassThrough_start.csv", os.mkfifo)
    case("fifo_ref", "PassThrough_ref.csv", os.mkfifo)
    case("dangling_criteria", "PassThrough_criteria.csv", lambda p: p.symlink_to(tmp_path / "gone"))
    case("long_opt", "PassThrough_ref.opt", lambda p: p.write_text("x" * 1_000_000))
    case("underscore_mode", "PassThrough_criteria.csv", lambda p: p.write_text("y,tol:abs=1_0\n"))
    case("closed_input", "PassThrough_in.csv", lambda p: (p.write_text(INPUT), p.chmod(0)))
    closed = write_case(cases / "closed_folder")
    closed.chmod(0)
    hostile["closed_folder"] = closed
    report = tmp_path / "report"
    before = files_and_links(tmp_path)
    try:
        done = fmutrace_command(
            "compare", PASS_THROUGH, cases, "--report", report, env=with_env(TMPDIR=str(shared)), preexec_fn=bounded
        )
    finally:
        closed.chmod(0o755)
    refused(done)
    assert f"1 of {len(hostile) + 1} cases pass" in done.stdout, output(done)
    for name, path in hostile.items():  # its file (the folder's reference) named, once
        assert str(path) in done.stderr and done.stderr.count(f"{cases / name}{os.sep}") == 1, (name, done.stderr)
    new = files_and_links(tmp_path) - before
    outside = sorted(p for p in new if p != report and report not in p.parents)
    assert not outside, outside
    assert not list(shared.iterdir())


def files_and_links(folder):
    return {Path(root) / name for root, dirs, names in os.walk(folder) for name in names + dirs}


def bounded():
    capped()
    modes_binding()


@pytest.mark.slow
def test_a_message_quoting_a_huge_name_is_cut(tmp_path):
    """A criteria file naming a signal of 3,000,000 characters (within the
    line bound): the message that quotes it is cut to its first 2,000
    characters and says how long it was (it was 3 MB on one line)."""
    case = write_case(tmp_path / "cases" / "one")
    (case / "PassThrough_criteria.csv").write_text("z" * 3_000_000 + ",exact\n")
    done = fmutrace_command("compare", PASS_THROUGH, tmp_path / "cases", "--jobs", "1")
    refused(done, "PassThrough_criteria.csv, line 1, column 1: column 'zzzz", "characters, cut)")


def test_a_campaigns_read_bound_travels_with_its_cases(tmp_path, monkeypatch):
    """A Dask worker has its own environment, not the client's: the bound the client has when a campaign
    starts (FMUTRACE_READ_LIMIT) goes with the cases' settings, and bounds a case run in a worker's
    thread without the variable, and only that thread (another case, of a campaign without a bound, reads
    the same 300 kB start file)."""
    from fmutrace import Exact, RunOptions
    from fmutrace import _executors
    from fmutrace._worker import CaseSettings, Target, run_case, worker_fmu

    case = write_case(tmp_path / "cases" / "one")
    (case / "PassThrough_start.csv").write_text("# " + "x" * 300_000 + "\n")
    given = []
    monkeypatch.setattr(_executors, "run_case", lambda *args: given.append(args[-1]) or run_case(*args))
    monkeypatch.setenv("FMUTRACE_READ_LIMIT", "200K")
    fmutrace.compare(str(PASS_THROUGH), str(tmp_path / "cases"), run=RunOptions(jobs=1))
    assert [settings.read_limit for settings in given] == [200 << 10]
    monkeypatch.delenv("FMUTRACE_READ_LIMIT")

    runner, fmu = worker_fmu(PASS_THROUGH.read_bytes(), str(PASS_THROUGH))
    target = Target(runner, fmu, {"fmu": fmu.label, "fmu_file": str(PASS_THROUGH), "fmu_folder": "f"})
    outcomes = {}

    def in_a_thread(key, settings):
        thread = threading.Thread(
            target=lambda: outcomes.setdefault(key, run_case(str(case), key, None, target, settings))
        )
        thread.start()
        thread.join(timeout=60)

    in_a_thread("bound", CaseSettings(Exact(), read_limit=200 << 10))
    in_a_thread("free", CaseSettings(Exact()))
    assert str(outcomes["bound"].status) == "invalid"
    assert (
        "PassThrough_start.csv: 300,003 bytes: more than the read bound of 204,800 bytes"
        in outcomes["bound"].messages[0]
    )
    assert outcomes["free"].passed, outcomes["free"].messages
