"""The PassThrough fixture's case, worked by hand from its equation
y(t + h) = u(t), y = 0 before the first step, and fmutrace's command as
users start it: what the tests of hostile and careless use attack."""

import os
import subprocess
import sys
import tempfile
import time

import pytest

from support.fmu_driver import BUILD_DIR
from support.process import kill_session
from support.process import run as run_bounded

PASS_THROUGH = BUILD_DIR / "benchmarks" / "fmi2" / "PassThrough.fmu"
# PassThrough on h = 0.1: u is 1 up to 0.2 and 3 from then on
OPT = "StartTime,0\nStopTime,0.5\nStepSize,0.1\nRelTol,1e-6\n"
INPUT = "time,u\n0,1\n0.2,3\n"
REF = "time,y\n0,0\n0.1,1\n0.2,1\n0.3,3\n0.4,3\n0.5,3\n"


@pytest.fixture(autouse=True)
def commands_start_from_the_defaults(monkeypatch):
    """Each command makes its own folder for unpacked FMUs (not the one an
    in-process campaign of this test process made: its children inherit
    it) and reads under the default read bound. Autouse in each test module that
    imports it."""
    monkeypatch.delenv("FMUTRACE_UNPACK_ROOT", raising=False)
    monkeypatch.delenv("FMUTRACE_READ_LIMIT", raising=False)


def run_fmutrace(*args, env=None, timeout=300, preexec_fn=None):
    """The command, as users start it, in a process of its own."""
    return run_bounded(
        [sys.executable, "-m", "fmutrace", *map(os.fsdecode, args)],
        timeout=timeout,
        what="fmutrace " + " ".join(map(os.fsdecode, args[:2])),
        env=env,
        preexec_fn=preexec_fn,
    )


def output(done):
    return done.stdout + done.stderr


def write_case(folder, readme=None, ref=REF):
    """A PassThrough case in folder (a path, or bytes: a name that is not
    UTF-8), with ref as its reference and readme as its README.md."""
    os.makedirs(folder, exist_ok=True)
    for name, text in (("PassThrough_ref.csv", ref), ("PassThrough_in.csv", INPUT), ("PassThrough_ref.opt", OPT)):
        with open(os.path.join(folder, os.fsencode(name) if isinstance(folder, bytes) else name), "w") as file:
            file.write(text)
    if readme is not None:
        with open(os.path.join(folder, b"README.md" if isinstance(folder, bytes) else "README.md"), "w") as file:
            file.write(readme)
    return folder


def signalled_campaign(cases, report, signum):
    """fmutrace compare of PassThrough on the folder cases into report, in
    a session of its own, sent signum half a second after its journal
    begins (within 120 s): its exit status, standard output and error."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        process = subprocess.Popen(
            [sys.executable, "-m", "fmutrace", "compare", str(PASS_THROUGH), str(cases), "--report", str(report),
             "--plots", "none"],
            stdout=out, stderr=err, start_new_session=True,
        )  # fmt: skip
        try:
            deadline = time.monotonic() + 120
            while not (report / "results.jsonl").exists() and time.monotonic() < deadline:
                assert process.poll() is None, "the campaign ended before the signal"
                time.sleep(0.1)
            time.sleep(0.5)
            process.send_signal(signum)
            code = process.wait(timeout=60)
        finally:
            kill_session(process)
        out.seek(0)
        err.seek(0)
        return code, out.read(), err.read()
