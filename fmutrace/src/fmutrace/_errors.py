"""What goes wrong, as exceptions that carry the command's exit status.
The statuses are decided here, once; a campaign's is its worst case's
(outcome.Status)."""

import importlib.util
from enum import IntEnum


class ExitStatus(IntEnum):
    SUCCESS = 0  # compare: every case passes
    FAILURE = 1  # a result differs from its reference, or the FMU failed
    BAD_INPUT = 2  # usage, a file, an option: nothing a simulation can mend
    INTERRUPTED = 130  # Ctrl-C (SIGINT), as shells report a command it ends
    TERMINATED = 143  # SIGTERM, as shells report a command it ends


MESSAGE_CHARS = 2000  # of a message: one quoting a user's text whole (a name of millions of characters) is cut


def bounded(message: str) -> str:
    """message, or its first MESSAGE_CHARS characters and how long it was."""
    if len(message) <= MESSAGE_CHARS:
        return message
    return f"{message[:MESSAGE_CHARS]}... (a message of {len(message):,} characters, cut)"


class InputError(ValueError):
    """Bad input that no simulation can mend; its message bounded (MESSAGE_CHARS)."""

    exit_code = ExitStatus.BAD_INPUT

    def __init__(self, *args):
        super().__init__(*(bounded(a) if isinstance(a, str) else a for a in args))


class TraceError(InputError):
    """Bad input in a file: the file, the line and column (1-based, 0 if
    none) and what is wrong. str() is the message users see."""

    def __init__(self, path, line: int, column: int, message: str):
        self.path, self.line, self.column, self.message = str(path), line, column, bounded(message)
        where = str(path)
        if line:
            where += f", line {line}"
        if column:
            where += f", column {column}"
        super().__init__(f"{where}: {message}")


class SimulationError(RuntimeError):
    """The FMU failed (an FMI error status, a crash of the call)."""

    exit_code = ExitStatus.FAILURE


def require_extra(module: str, extra: str, purpose: str):
    """InputError naming the pip install line unless module (an optional
    part of fmutrace: the extra's) is installed; nothing is imported."""
    if importlib.util.find_spec(module) is None:
        raise InputError(f'{purpose} needs {module}, an optional part of fmutrace: pip install "fmutrace[{extra}]"')
