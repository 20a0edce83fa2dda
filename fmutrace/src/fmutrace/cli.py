"""The fmutrace command.

  fmutrace run FMU [--input IN.csv] [--set NAME=VALUE]... [-o OUT.csv] ...
  fmutrace compare FMU... CASE... [--report DIR] [--rel-tol R] ...
  fmutrace check FMU... [--role smoke-test|validation] [--report DIR] ...

Exit status: errors.ExitStatus (0 success, 1 a difference or a failed
simulation, 2 bad input, 130 interrupted, 143 terminated); compare's is its
worst case's.
"""

import argparse
import contextlib
import os
import signal
import sys
import threading
from functools import partial

from . import __version__
from ._campaign import compare
from ._check import check
from ._comparison import MODE_WORDS, comparison_mode, signal_criteria
from ._executors import RunOptions
from ._errors import ExitStatus, InputError, SimulationError
from ._fmu import Fmu, is_fmu_file
from ._lsref import ROLES
from ._simulation import SimulationOptions, simulate_chunks
from ._outcome import Status, ran_again
from ._reading import READ_LIMIT_VARIABLE
from ._report import text
from .recordings import is_recording
from .recordings._align import CYCLE_LENGTHS, TIMINGS
from .recordings._options import TIME_UNITS, RecordingOptions
from ._traces import TraceWriter
from ._worker import PLOT_ALL_UP_TO, PLOTS

EXAMPLES = """examples:
  fmutrace run build/fmi3/RateLimiter.fmu --input u.csv --set rateUpPar=2 --step-size 0.1 -o y.csv
  fmutrace compare build/fmi3/RateLimiter.fmu my_traces/ --report report/
  fmutrace compare build/fmi3/LGF_LimRateOfChangeCI.fmu LGF_Ramp.csv     (a TwinCAT Scope export, say)
  fmutrace compare build/fmi2/*.fmu build/fmi3/*.fmu tests/scenarios --jobs 2 --junit junit.xml
  fmutrace check build/fmi3/RateLimiter.fmu --role smoke-test     (the experiments it carries)
"""


# setting -> its flag: the command's words for the settings, in its messages too (RecordingOptions.names)
FLAGS = {
    "step_size": "--step-size",
    "time_unit": "--time-unit",
    "timing": "--timing",
    "cycle_lengths": "--cycle-lengths",
    "maps": "--map",
    "start_values": "--set",
    "rel_tol": "--rel-tol",
    "abs_tol": "--abs-tol",
    "tube_time": "--tube-time",
    "tube_value": "--tube-value",
    "tube_sides": "--tube-sides",
    "resume": "--resume",
    "signals": "--signal",
}


def _assignment(text):
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, not {text!r}")
    return name.strip(), value.strip()


def _non_negative(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"{text} must be >= 0")
    return value


def _positive(text):
    value = _non_negative(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text} must be greater than 0")
    return value


def _positive_int(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text} must be at least 1")
    return value


COMPARE_SUMMARY = "replay cases and recordings through FMUs and compare with their references"
COMPARE_TEXT = (
    "Replay every case (FMI cross-check layout: <Model>_in.csv, <Model>_ref.csv, <Model>_ref.opt, "
    "<Model>_start.csv) through the FMUs of its model, and every recording as a controller's recorder exports it "
    "(TwinCAT Scope View CSV, CODESYS 2.3 and V3 traces, TIA Portal trace CSV, MDF 4 and 3, WinCC data logs, "
    "Niagara histories, CSV/TSV) through every FMU, and compare with the reference. Exact (bit for bit) unless a "
    "tolerance or a tube is given. With FMUs alone: as fmutrace check."
)
CHECK_SUMMARY = "run the experiments the FMUs carry (FMI-LS-REF) and compare with their references"
CHECK_TEXT = (
    "Run the experiments each FMU carries (FMI-LS-REF) and judge them by the criteria their references carry. "
    "Given case folders or recordings after the FMUs: as fmutrace compare."
)


def _compare_arguments(command):
    """The options of compare and check, in groups: what to compare, how to
    judge, what to write, where to run, recordings."""
    what = command.add_argument_group("what to compare")
    what.add_argument(
        "paths",
        nargs="+",
        metavar="FMU|CASE|RECORDING",
        help=".fmu files, then case folders or folders holding them (searched recursively), or recordings "
        "(files, or a folder of one recording's files)",
    )
    what.add_argument(
        "--role",
        choices=ROLES,
        help="with FMUs alone: the experiments of this role (default: both, each experiment once)",
    )
    what.add_argument(
        FLAGS["resume"],
        action="store_true",
        help="take the cases the report's journal holds from it and "
        "run the others (after a stopped campaign; needs --report)",
    )

    judge = command.add_argument_group("how to judge", "exact (bit for bit) unless a tolerance or a tube is given")
    judge.add_argument(
        FLAGS["rel_tol"],
        type=_non_negative,
        default=0.0,
        metavar="R",
        help="relative tolerance: |result - reference| <= A + R * |reference|",
    )
    judge.add_argument(
        FLAGS["abs_tol"], type=_non_negative, default=0.0, metavar="A", help="absolute tolerance (with or without R)"
    )
    judge.add_argument(
        FLAGS["tube_time"],
        type=_non_negative,
        metavar="S",
        help="tube half-width in time (with --tube-value), for traces sampled at other instants",
    )
    judge.add_argument(FLAGS["tube_value"], type=_non_negative, metavar="V", help="tube half-width in value")
    judge.add_argument(
        FLAGS["tube_sides"],
        type=int,
        choices=(1, 2),
        default=2,
        help="2 (default): the result within the tube around the reference and the reference within the tube "
        "around the result; 1: the result's samples only, as csv-compare checks",
    )
    judge.add_argument(
        FLAGS["signals"],
        type=_assignment,
        action="append",
        default=[],
        metavar="NAME=MODE",
        help=f"a signal's own criterion (a name or pattern, '*' for the rest; repeatable); MODE: {MODE_WORDS}",
    )

    write = command.add_argument_group("what to write")
    write.add_argument(
        "--report", metavar="DIR", help="write index.html, summary.md, results.json, the results and plots here"
    )
    write.add_argument("--junit", metavar="FILE", help="write JUnit XML for CI servers")
    write.add_argument(
        "--plots",
        choices=PLOTS,
        help="which cases get a plot and a result CSV in the report "
        f"(default: all for up to {PLOT_ALL_UP_TO} cases, else the failed ones; png: as the default, with a static "
        "PNG figure beside each interactive plot)",
    )

    where = command.add_argument_group("where to run")
    where.add_argument(
        "--jobs",
        type=_positive_int,
        metavar="N",
        help="local worker processes (1: this process; default: as many as the work pays for, up to one per core)",
    )
    where.add_argument("--scheduler", metavar="ADDR", help="a Dask distributed scheduler to run on")
    where.add_argument(
        "--shared-files",
        action="store_true",
        help="the scheduler's workers see the case folders at the same paths (else they are sent the files)",
    )
    where.add_argument(
        "--case-timeout",
        type=_positive,
        metavar="S",
        help="seconds a case may run: one over it is stopped and reported (--jobs 1 then runs in one worker process)",
    )
    where.add_argument("--timeout", dest="case_timeout", type=_positive, help=argparse.SUPPRESS)  # its old name
    where.add_argument(
        "--cluster-timeout",
        type=_positive,
        metavar="S",
        help="seconds to wait for the Dask cluster's results (default: no bound)",
    )

    rec = command.add_argument_group("recordings", "how recordings are read (docs/recordings.md)")
    rec.add_argument(
        FLAGS["step_size"],
        type=_positive,
        metavar="H",
        help="the PLC's cycle in seconds (default: the "
        "recording's sample time, else its finest interval between samples)",
    )
    rec.add_argument(
        FLAGS["maps"],
        metavar="VARIABLE=CHANNEL",
        action="append",
        type=_assignment,
        default=[],
        help="the channel that is the FMU's variable: its name, or #N for the one in column N "
        "(repeatable; default: the channel whose name's last component is the variable's name)",
    )
    rec.add_argument(
        FLAGS["start_values"],
        metavar="NAME=VALUE",
        action="append",
        type=_assignment,
        default=[],
        help="a start value of the FMU (repeatable)",
    )
    rec.add_argument(
        FLAGS["time_unit"],
        choices=TIME_UNITS,
        help="the unit of the recording's time stamps (default: "
        "what the export says, else what their size says: FILETIME, Unix ms, else seconds)",
    )
    rec.add_argument(
        FLAGS["timing"],
        choices=TIMINGS,
        default="cycle",
        help="cycle (default): a row is the input a "
        "cycle read and the output it produced, as recorders write it; fmi: a row's output is the "
        "output at its time, as fmpy and FMI cross-check files write it",
    )
    rec.add_argument(
        FLAGS["cycle_lengths"],
        choices=CYCLE_LENGTHS,
        default="nominal",
        help="nominal (default): every step is --step-size long, the stamps' jitter only places the samples; "
        "recorded: each recorded execution of the OB is one step as long as the recorded interval since the one "
        "before, a cycle without a sample no step (blocks that measure elapsed time see the jitter)",
    )


def parser():
    main = argparse.ArgumentParser(
        prog="fmutrace",
        description="Replay CSV traces through FMI 2 and FMI 3 "
        "co-simulation FMUs with fmpy and report where they differ from references.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    main.add_argument("--version", action="version", version=f"fmutrace {__version__}")
    commands = main.add_subparsers(dest="command", required=True, metavar="{run,compare,check}")

    run = commands.add_parser(
        "run",
        help="simulate an FMU on a CSV input and write the result",
        description="Simulate an FMU on CSV inputs and write the result as CSV.",
    )
    run.add_argument("fmu", metavar="FMU", help="the .fmu file to simulate")
    run.add_argument("--input", metavar="IN.csv", help="input signals (a row holds from its time on)")
    run.add_argument(
        "--set", metavar="NAME=VALUE", action="append", type=_assignment, default=[], help="a start value (repeatable)"
    )
    run.add_argument("--start-time", type=float, metavar="S", help="default: the input's first time")
    run.add_argument("--stop-time", type=float, metavar="S", help="default: the input's last time")
    run.add_argument("--step-size", type=float, metavar="H", help="communication step (default: the FMU's)")
    run.add_argument("--output-interval", type=float, metavar="H", help="a whole multiple of the step size")
    run.add_argument(
        "--output", metavar="NAME", action="append", help="a variable to record (repeatable; default: the outputs)"
    )
    run.add_argument("-o", dest="out", metavar="OUT.csv", help="result file (default: standard output)")

    for name, summary, description in (
        ("compare", COMPARE_SUMMARY, COMPARE_TEXT),
        ("check", CHECK_SUMMARY, CHECK_TEXT),
    ):
        _compare_arguments(commands.add_parser(name, help=summary, description=description))
    return main


def run_command(args, out):
    problem = Fmu(args.fmu).binary_problem()  # (compare reports it per case, as any failed simulation)
    if problem:
        raise InputError(problem)
    options = SimulationOptions(
        dict(args.set), args.start_time, args.stop_time, args.step_size, args.output_interval, args.output
    )
    written, names = 0, ("time",)  # type: tuple[int, tuple[str, ...]]
    with contextlib.ExitStack() as stack:
        stream, writer = None, None
        try:
            for chunk in simulate_chunks(args.fmu, args.input, options, progress=True):
                if writer is None:  # the file made once the run has begun: bad input leaves none
                    stream = stack.enter_context(open(args.out, "w", newline="\n")) if args.out else out
                    names = chunk.dtype.names or ("time",)
                    writer = TraceWriter(stream, names)
                writer.write(chunk)
                written += len(chunk)
        except (InputError, SimulationError):
            if args.out and stream is not None:
                stream.close()
                os.unlink(args.out)  # no half-written result
            raise
    if args.out:
        print(f"{written} samples of {len(names) - 1} signals written to {text(args.out)}", file=out)
    return ExitStatus.SUCCESS


def compare_command(args, out):
    fmus = [p for p in args.paths if p.lower().endswith(".fmu") or is_fmu_file(p)]
    cases = [p for p in args.paths if p not in fmus]
    if not fmus:
        raise InputError("no FMU given: name one or more .fmu files before the case folders")
    if args.role and cases:
        raise InputError("--role chooses among the experiments an FMU carries: give the FMUs alone")
    if args.resume and not args.report:
        raise InputError("--resume continues the campaign of a report folder: give it with --report")
    recordings = any(map(is_recording, cases))
    run = RunOptions(
        jobs=args.jobs,
        scheduler=args.scheduler,
        shared_files=args.shared_files,
        case_timeout=args.case_timeout,
        cluster_timeout=args.cluster_timeout,
    )
    # the recordings group's flags read recordings; with case folders alone the command leaves them unused, as
    # it did, and says so
    recording = (
        RecordingOptions(
            args.step_size, args.time_unit, args.timing, args.map, args.set, args.cycle_lengths, names=FLAGS
        )
        if recordings
        else RecordingOptions(names=FLAGS)
    )
    unused = [
        flag
        for flag, given in (
            ("--step-size", args.step_size is not None),
            ("--map", args.map),
            ("--set", args.set),
            ("--time-unit", args.time_unit is not None),
            ("--timing", args.timing != "cycle"),
            ("--cycle-lengths", args.cycle_lengths != "nominal"),
        )
        if given and not recordings
    ]
    if unused:
        print(
            f"fmutrace: warning: {', '.join(unused)} not used: they read recordings, and a case folder carries its "
            "own settings (<Model>_ref.opt, <Model>_start.csv)",
            file=sys.stderr,
        )
    campaign = partial(compare, fmus, cases) if cases else partial(check, fmus, role=args.role)
    result = campaign(
        mode=signal_criteria(
            args.signal,
            comparison_mode(
                args.rel_tol, args.abs_tol, args.tube_time, args.tube_value, tube_sides=args.tube_sides, names=FLAGS
            ),
            FLAGS,
        ),
        report=args.report,
        junit=args.junit,
        plots=args.plots,
        resume=args.resume,
        run=run,
        recording=recording,
    )
    for o in result.cases.light():  # the failing ones, a recording's messages, and the cases run again
        if o.status == Status.INVALID:
            print(f"fmutrace: error: {text(o.messages[0])}", file=sys.stderr)
            continue
        if o.passed and not o.retried and not (recordings and o.messages):
            continue
        print(f"{o.status.upper()}  {text(o.case)} on {text(o.fmu)}", file=out)
        for message in o.messages[:SHOWN_MESSAGES]:
            print(f"      {text(message)}", file=out)
        if len(o.messages) > SHOWN_MESSAGES:
            print(f"      {_the_rest(len(o.messages) - SHOWN_MESSAGES, args.report)}", file=out)
        if o.retried:
            print(f"      {text(ran_again(o))}", file=out)
    for problem in result.problems:
        print(f"fmutrace: error: {text(problem)}", file=sys.stderr)
    print(result.headline(), file=out)
    if args.report:
        print(f"report: {text(args.report.rstrip('/'))}/index.html", file=out)
    if args.junit:
        print(f"JUnit XML: {text(args.junit)}", file=out)
    return result.exit_code


SHOWN_MESSAGES = 10  # of a case on the terminal; the report's results.json holds them all


def _the_rest(count, report):
    """Where the messages of a case the terminal does not show are."""
    if report:
        return f"(and {count} more messages: all of them in {text(report.rstrip('/'))}/results.json)"
    return f"(and {count} more messages: --report DIR writes all of them into DIR/results.json)"


def main(argv=None, out=None):
    out = out or sys.stdout
    args = parser().parse_args(argv)
    main_thread = threading.current_thread() is threading.main_thread()  # (only it may set a handler)
    previous = signal.signal(signal.SIGTERM, _terminate) if main_thread else None
    try:
        return (run_command if args.command == "run" else compare_command)(args, out)
    except InputError as error:
        print(f"fmutrace: error: {error}", file=sys.stderr)
        return error.exit_code
    except SimulationError as error:
        print(f"fmutrace: {error}", file=sys.stderr)
        return error.exit_code
    except OSError as error:  # a file or folder given that cannot be read or written
        where = f"{text(error.filename)}: " if error.filename else ""
        print(f"fmutrace: error: {where}{error.strerror or error}", file=sys.stderr)
        return ExitStatus.BAD_INPUT
    except MemoryError:  # (the read bound keeps a file from it; the bound raised, or the work's own size)
        print(f"fmutrace: error: out of memory; {READ_LIMIT_VARIABLE}, if raised, bounds the files read whole",
              file=sys.stderr)  # fmt: skip
        return ExitStatus.BAD_INPUT
    except KeyboardInterrupt as stop:
        journal = getattr(args, "report", None)
        hint = f"; the finished cases are in {journal}: --resume continues" if journal else ""
        print(f"fmutrace: {'terminated (SIGTERM)' if isinstance(stop, Terminated) else 'interrupted'}{hint}",
              file=sys.stderr)  # fmt: skip
        return ExitStatus.TERMINATED if isinstance(stop, Terminated) else ExitStatus.INTERRUPTED
    finally:
        if main_thread:
            signal.signal(signal.SIGTERM, previous)


class Terminated(KeyboardInterrupt):
    """SIGTERM: the command ends as Ctrl-C ends it (its clean-up, a line), with its own status."""


def _terminate(signum, frame):
    raise Terminated


if __name__ == "__main__":
    sys.exit(main())
