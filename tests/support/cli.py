"""The fmutrace command's entry point (fmutrace.cli:main) run in this
process, as a finished process reports it: a test of what the command
prints and exits with spares a second interpreter's start-up (about a
second of CPU each). The console script itself is started by the tests
that need a process of its own (the install, the README's commands, the
hostile-use modules: memory caps, signals, children)."""

import contextlib
import io
import os
import subprocess

from fmutrace import cli


WHERE_CASES_RUN = ("--jobs", "-j", "--scheduler", "--case-timeout")


def fmutrace_in_process(*args, cwd=None) -> subprocess.CompletedProcess:
    """`fmutrace args...` in this process (in cwd, if given): its exit status, standard output and error.
    A campaign's cases run in this process too (--jobs 1) unless the arguments say where they run: the
    worker process the command starts by default costs half a second of start-up, and the tests of
    where cases run (test_fmutrace_campaigns, the hostile-use modules) choose it themselves."""
    argv = [os.fspath(a) if isinstance(a, os.PathLike) else str(a) for a in args]
    if argv[:1] in (["compare"], ["check"]) and not any(a.split("=")[0] in WHERE_CASES_RUN for a in argv):
        argv += ["--jobs", "1"]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.ExitStack() as stack:
        if cwd is not None:
            stack.enter_context(contextlib.chdir(cwd))
        stack.enter_context(contextlib.redirect_stdout(out))
        stack.enter_context(contextlib.redirect_stderr(err))
        try:
            status = cli.main(argv, out=out)
        except SystemExit as done:  # argparse's usage errors and --help end the command
            status = done.code if isinstance(done.code, int) else 0 if done.code is None else 1
    return subprocess.CompletedProcess(["fmutrace", *argv], status, out.getvalue(), err.getvalue())
