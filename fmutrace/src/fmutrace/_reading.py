"""Users' files read within bounds: fmutrace reads files from anyone, so no
file makes it wait on a device or a FIFO, or allocate without a bound.

- a file that is not a regular file (a FIFO, a device, a socket, a folder)
  is refused by its kind before a byte of it is read;
- a file read whole, an FMU, and an FMU's entry unpacked (its inflated
  size, as its zip header declares it and zipfile holds it to) is refused
  when it is larger than the read bound: READ_LIMIT bytes, raised by the
  environment variable FMUTRACE_READ_LIMIT (bytes, or with a K, M, G
  suffix); files read in blocks (a reference in the plain dialect, a long
  recording) have no size bound, their lines have MAX_LINE;
- a message quotes at most QUOTE_CHARS characters of a line or a cell.
"""

import os
from contextlib import contextmanager
from contextvars import ContextVar
import stat
import zipfile

from ._errors import InputError, TraceError

READ_LIMIT = 1 << 29  # bytes of a file read whole (512 MiB), unless FMUTRACE_READ_LIMIT says more
READ_LIMIT_VARIABLE = "FMUTRACE_READ_LIMIT"
MAX_LINE = 1 << 22  # characters of a line of a trace or a recording (100,000 channels of 40)
READ_BLOCK = 1 << 24  # bytes read at a time past a file's size (it grows, or says 0)
QUOTE_CHARS = 60  # of a line or a cell in a message
_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30}


# a campaign's bound where its cases run (a Dask worker has its own environment, not the client's); a
# context variable: each of a worker's threads runs a case of its own
_CAMPAIGN_LIMIT: ContextVar[int | None] = ContextVar("campaign_read_limit", default=None)


@contextmanager
def campaign_read_limit(limit: int | None):
    """read_limit() is limit (where given) in this thread until the block ends."""
    token = _CAMPAIGN_LIMIT.set(limit)
    try:
        yield
    finally:
        _CAMPAIGN_LIMIT.reset(token)


def read_limit() -> int:
    """The read bound in bytes: the campaign's where its cases run
    (campaign_read_limit), else FMUTRACE_READ_LIMIT if set, else READ_LIMIT."""
    campaign = _CAMPAIGN_LIMIT.get()
    if campaign is not None:
        return campaign
    text = os.environ.get(READ_LIMIT_VARIABLE, "").strip()
    if not text:
        return READ_LIMIT
    unit = text[-1:].upper() if text[-1:].isalpha() else ""
    digits = text[: len(text) - len(unit)].strip()
    if unit not in _UNITS or not digits.isdigit() or not int(digits):
        raise InputError(f"{READ_LIMIT_VARIABLE}={quoted(text)}: not a number of bytes (such as 4G, 800M or 1000000)")
    return int(digits) * _UNITS[unit]


def too_large(size: int, what: str = "") -> str:
    """Why a file (or an entry) of size bytes is refused."""
    return (
        f"{what}{size:,} bytes: more than the read bound of {read_limit():,} bytes "
        f"(raise it with the environment variable {READ_LIMIT_VARIABLE})"
    )


def _kind(mode) -> str | None:
    """What a file that is not a regular file is (None for a regular file)."""
    if stat.S_ISREG(mode):
        return None
    for test, kind in (
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a FIFO"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return kind
    return "not a regular file"


def open_regular(path):
    """path opened for reading in binary, a regular file; TraceError for a
    file that is none (named by its kind, before it is opened, so that a
    FIFO does not block) or cannot be opened (its errno's text)."""
    try:
        kind = _kind(os.stat(path).st_mode)
        if kind is None:  # (opened without blocking, checked again: the name may have changed meanwhile)
            handle = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
            kind = _kind(os.fstat(handle).st_mode)
            if kind is None:
                return os.fdopen(handle, "rb")
            os.close(handle)
    except OSError as error:
        raise TraceError(path, 0, 0, _reason(path, error)) from None
    raise TraceError(path, 0, 0, f"{kind}, not a regular file: not read")


def _reason(path, error: OSError) -> str:
    if isinstance(error, FileNotFoundError) and os.path.islink(path):
        return f"a link to {os.readlink(path)!r}, which does not exist"
    return error.strerror or str(error)


def read_bytes(path) -> bytes:
    """A regular file's bytes, at most the read bound; TraceError if it is no
    regular file, cannot be read, or is larger."""
    limit = read_limit()
    with open_regular(path) as file:
        size = os.fstat(file.fileno()).st_size
        if size > limit:
            raise TraceError(path, 0, 0, too_large(size))
        parts, total, want = [], 0, size + 1  # (one read where the size holds; a file that grows, a /proc file)
        while part := _read(file, path, min(want, limit + 1 - total)):
            parts.append(part)
            total += len(part)
            if total > limit:
                raise TraceError(path, 0, 0, too_large(total, "more than "))
            want = READ_BLOCK
    return b"".join(parts)


def _read(file, path, size) -> bytes:
    try:
        return file.read(size)
    except OSError as error:
        raise TraceError(path, 0, 0, error.strerror or str(error)) from None


def absent(path) -> bool:
    """Whether an optional file is not there at all: a name that exists but
    cannot be read (a dangling link, a FIFO, no permission) is there, and
    its reading says what is wrong."""
    try:
        os.lstat(path)
    except (FileNotFoundError, NotADirectoryError):
        return True
    except OSError:
        return False
    return False


def check_entries(archive: zipfile.ZipFile, label, names=None):
    """InputError if an entry of the FMU (of names, else every one) inflates
    to more than the read bound, or all of them together do."""
    limit, total = read_limit(), 0
    for info in archive.infolist():
        if names is not None and info.filename not in names:
            continue
        if info.file_size > limit:
            raise InputError(f"{label}: {info.filename!r}: {too_large(info.file_size, 'inflates to ')}")
        total += info.file_size
    if total > limit:
        raise InputError(f"{label}: its files together: {too_large(total, 'inflate to ')}")


def quoted(text, limit: int = QUOTE_CHARS) -> str:
    """repr() of text, or of its first limit characters and how long it is."""
    text = str(text)
    if len(text) <= limit:
        return repr(text)
    return f"{text[:limit]!r}... ({len(text):,} characters)"
