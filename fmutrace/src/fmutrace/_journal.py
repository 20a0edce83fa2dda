"""A campaign's journal: results.jsonl in the report folder, one line per
finished case, appended and flushed as each case finishes, so that a
campaign whose client is killed loses nothing it finished; a resumed
campaign reads it back and runs only the rest. The folder is locked while a
campaign writes it: a second campaign into the same folder is refused.

The first line describes the campaign (comparison, plots, the FMUs by
content hash); a resumed campaign must be the same campaign, and a
journal whose first line is damaged or not this one's is refused. A line
cut short by a kill is ignored, a damaged one skipped with a warning (its
case runs again).
"""

import hashlib
import json
import os
import re
import sys
from pathlib import Path
from typing import ClassVar

from ._comparison import Mode
from ._errors import InputError
from ._names import Names, name_of
from ._reading import MAX_LINE
from ._outcome import CaseOutcome, Outcomes
from ._traces import read_trace

JOURNAL = "results.jsonl"
JOURNAL_LINE = 16 * MAX_LINE  # bytes of a journal line read at most (a case's entry with every signal's verdict)
LOCK = ".fmutrace.lock"


if sys.platform == "win32":
    import msvcrt

    def _try_lock(file):
        """Locks the file's first byte without waiting; OSError if another process holds it."""
        file.seek(0)
        msvcrt.locking(file.fileno(), msvcrt.LK_NBLCK, 1)

    def _unlock(file):
        file.seek(0)
        msvcrt.locking(file.fileno(), msvcrt.LK_UNLCK, 1)
else:
    import fcntl

    def _try_lock(file):
        """Locks the file without waiting; OSError if another process holds it."""
        fcntl.flock(file, fcntl.LOCK_EX | fcntl.LOCK_NB)

    def _unlock(file):
        fcntl.flock(file, fcntl.LOCK_UN)


class ReportLock:
    """An exclusive lock on a report folder, on a file in it (flock on
    POSIX, a locked byte on Windows): the lock goes with the process that
    holds it, however it ends. The holder's pid is written after the
    locked byte (Windows refuses a read of a byte another process locked)."""

    _held: ClassVar[dict[str, "ReportLock"]] = {}  # real path -> this process's lock on that folder

    def __init__(self, folder):
        self.folder = Path(folder)
        self.path = self.folder / LOCK
        self.key = os.path.realpath(self.folder)
        if self.key in ReportLock._held:  # held by this process already (check, then its compare): one lock
            self.file = None
            return
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            self.file = open(self.path, "a+")
        except OSError as error:  # a file of that name, a folder not writable
            raise InputError(
                f"{self.folder}: cannot write the report there ({error.strerror or error}); choose another folder"
            ) from None
        try:
            _try_lock(self.file)
        except OSError:
            self.file.seek(1)
            holder = self.file.read(80).strip() or "another process"  # (' pid N': a file of others' is cut)
            self.file.close()
            raise InputError(
                f"{self.folder}: another campaign is writing this report folder ({holder}); wait for "
                "it to finish or choose another folder"
            ) from None
        self.file.seek(0)
        self.file.truncate()
        self.file.write(f" pid {os.getpid()}\n")
        self.file.flush()
        ReportLock._held[self.key] = self

    def release(self):
        if self.file is not None and not self.file.closed:
            ReportLock._held.pop(self.key, None)
            self.file.seek(1)
            self.file.truncate()
            _unlock(self.file)
            self.file.close()


def campaign_key(fmu_bytes: dict, mode: Mode, plots: str, recordings: dict | None = None) -> dict:
    """What makes a campaign the same campaign: its FMUs (by content), comparison, plots and how
    recordings are read."""
    key = {
        "mode": mode.name,
        "tolerance": mode.settings(),
        "plots": plots,
        "fmus": sorted(hashlib.sha256(data).hexdigest() for data in fmu_bytes.values()),
    }
    if recordings:
        key["recordings"] = recordings
    return key


def fmu_digest(fmu_bytes: bytes) -> str:
    """An FMU as a journal knows it: by its content, whatever path names it."""
    return hashlib.sha256(fmu_bytes).hexdigest()


def case_key(digest, folder):
    """A case in the journal: its FMU's fmu_digest and its folder's real path."""
    return f"{digest}|{os.path.realpath(folder)}"


class Journal:
    """results.jsonl: read back for a resume, appended to as cases finish.
    A case's entry is found again by where its line starts (done, record):
    the campaign keeps that offset, not the outcome."""

    def __init__(self, folder, key, resume, names: Names = ()):
        """names: the caller's words for the settings (RecordingOptions.names)."""
        self.path = Path(folder) / JOURNAL
        self.done: dict[str, int] | None = {}  # key -> offset of the case's line, of a campaign resumed
        if resume and self.path.exists():
            with open(self.path, "rb") as journal:
                first = journal.readline(JOURNAL_LINE + 1)
                header = _parse(first) if first.strip() and len(first) <= JOURNAL_LINE else None
                if first.strip() and not (isinstance(header, dict) and isinstance(header.get("campaign"), dict)):
                    raise InputError(
                        f"{self.path}: its first line is damaged or not a fmutrace journal's, so which options "
                        f"made its verdicts is unknown; start afresh without {name_of(names, 'resume')}"
                    )
                if header is not None and header["campaign"] != key:
                    raise InputError(
                        f"{self.path}: made by a campaign with other FMUs or options; resume it with "
                        f"the same ones, or start afresh without {name_of(names, 'resume')}"
                    )
                offset, number = journal.tell(), 1
                while line := journal.readline(JOURNAL_LINE + 1):  # (no line of a damaged file held whole)
                    number += 1
                    length, ended = len(line), line.endswith(b"\n")
                    if length > JOURNAL_LINE:
                        entry, problem = None, f"longer than {JOURNAL_LINE:,} bytes"
                        more, ended = _past_the_line(journal)
                        length += more
                    else:
                        entry, problem = _entry(line)
                    if problem is None:
                        self.done[entry["key"]] = offset
                    elif ended:  # (a last line without its end was cut short by a kill: no news)
                        warning = f"{self.path}, line {number}: {problem}; its case runs again"
                        print(f"fmutrace: warning: {warning}", file=sys.stderr)
                    offset += length
            self.file = open(self.path, "ab")
            if self.file.tell() and not _ends_a_line(self.path):
                self.file.write(b"\n")  # close a line cut short by the kill: the next entry starts afresh
            if header is None:
                self._write({"campaign": key})
        else:
            self.file = open(self.path, "wb")
            self._write({"campaign": key})
        self.reader = open(self.path, "rb")

    def _write(self, entry):
        offset = self.file.tell()
        self.file.write(json.dumps(entry).encode() + b"\n")
        self.file.flush()  # in the OS's hands: a killed client loses nothing written
        return offset

    def record(self, key, entry):
        """Append a finished case; the offset of its line."""
        return self._write(dict(entry, key=key))

    def entry(self, offset):
        self.reader.seek(offset)
        return json.loads(self.reader.readline())

    def close(self):
        self.file.close()
        self.reader.close()


def _past_the_line(journal):
    """(bytes read, whether the line ended) reading past the rest of a line longer than JOURNAL_LINE."""
    skipped = 0
    while part := journal.readline(JOURNAL_LINE):
        skipped += len(part)
        if part.endswith(b"\n"):
            return skipped, True
    return skipped, False


def _ends_a_line(path):
    with open(path, "rb") as journal:
        journal.seek(-1, os.SEEK_END)
        return journal.read(1) == b"\n"


def _entry(line):
    """(entry, None) of a journal line that is a case's entry, else (None, what is wrong)."""
    entry = _parse(line)
    if not isinstance(entry, dict):
        return None, "not a case's entry" if entry is not None else "not JSON"
    try:
        key = entry["key"]
        outcome = CaseOutcome.from_json(entry, "")
    except KeyError as missing:
        return None, f"a case's entry without its {missing}"
    except (TypeError, ValueError, AttributeError) as error:
        return None, f"a case's entry with a bad value ({error})"
    if not (
        isinstance(key, str)
        and re.fullmatch(r"[0-9a-f]{64}\|.+", key, re.DOTALL) is not None
        and isinstance(outcome.messages, list)
        and all(isinstance(v, str) for v in (outcome.case, outcome.fmu, outcome.fmu_file, *outcome.messages))
        and isinstance(outcome.seconds, (int, float))
        and all(isinstance(p, str) and _in_report(p) for p in (outcome.csv, outcome.plot))
    ):
        return None, "a case's entry with a bad value"
    return entry, None


def _in_report(path):
    """Whether a path an entry names is a file of the report folder (or none)."""
    return not path or not (os.path.isabs(path) or ".." in Path(path).parts)


def _parse(line):
    try:
        return json.loads(line)
    except ValueError:
        return None  # cut short by a kill


class JournaledOutcomes(Outcomes):
    """The outcomes of a campaign with a report folder, read from its
    journal when asked: the client keeps where each case's line starts (8
    bytes a case), so its memory does not grow with the campaign. A case
    with a result CSV in the report gets its result read from it (bit for
    bit the one written); light() leaves the results out."""

    def __init__(self, report_dir, journal_path, offsets, fmus):
        """fmus: fmu_digest -> the labels of the FMU of those bytes in this campaign (the path named now)."""
        self.report_dir, self.path = Path(report_dir), Path(journal_path)
        self.offsets, self.fmus = offsets, fmus

    def __len__(self):
        return len(self.offsets)

    def _outcome(self, journal, offset, results=True):
        journal.seek(offset)
        entry = json.loads(journal.readline())
        labels = self.fmus[entry["key"].partition("|")[0]]
        outcome = CaseOutcome.from_json(dict(entry, **labels), labels["fmu_folder"])
        if results and outcome.csv:
            outcome.result = read_trace(self.report_dir / outcome.csv)
        return outcome

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        with open(self.path, "rb") as journal:
            return self._outcome(journal, self.offsets[index])

    def _outcomes(self, results):
        with open(self.path, "rb") as journal:
            for offset in self.offsets:
                yield self._outcome(journal, offset, results)

    def __iter__(self):
        return self._outcomes(results=True)

    def light(self):
        return self._outcomes(results=False)
