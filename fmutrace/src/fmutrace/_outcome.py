"""What a campaign gives back: each case's outcome (CaseOutcome, its
Status) and the campaign's result (CampaignResult), with their JSON both
ways (the journal's lines and results.json)."""

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path

import numpy as np

from ._comparison import Deviation, Mode
from ._errors import ExitStatus


class Status(StrEnum):
    PASS = "pass"
    FAIL = "fail"  # the result differs from the reference
    ERROR = "error"  # the simulation failed
    INVALID = "invalid"  # the case's files are bad (the message names file, line and column)

    @property
    def exit_code(self) -> ExitStatus:
        return (
            ExitStatus.SUCCESS
            if self is Status.PASS
            else ExitStatus.BAD_INPUT
            if self is Status.INVALID
            else ExitStatus.FAILURE
        )


@dataclass
class CaseOutcome:
    """One case on one FMU. result and png are kept for the cases that get
    a plot."""

    case: str
    fmu: str  # the FMU's label, e.g. "RateLimiter (FMI 3)"
    fmu_file: str
    fmu_folder: str  # its folder in the report
    status: Status = Status.PASS
    messages: list = field(default_factory=list)
    deviations: list = field(default_factory=list)  # Deviation of the failing signals
    seconds: float = 0.0
    result: np.ndarray | None = None  # structured array
    png: bytes = b""  # the static figure (plots "png")
    plot_js: str = ""  # the case page's plot data, a script (report.py writes it beside the page)
    plot_tiles: list = field(default_factory=list)  # a long case's finer level, a script per part of its span
    result_path: str = ""  # a long case's result, in a file of its own (the report moves it in)
    csv: str = ""  # paths in the report folder
    plot: str = ""
    plot_data: str = ""
    criteria: str = ""  # what the case is judged by (its own criteria before the campaign's)
    streamed: bool = False  # read, run and compared in chunks (a long case), not in memory
    clock: dict = field(default_factory=dict)  # a recording's cycle fit: its cycle, jitter, missing cycles
    retried: str = ""  # why the case ran a second time (its first run's process died), else ""

    @property
    def passed(self) -> bool:
        return self.status == Status.PASS

    def to_json(self) -> dict:
        entry = {
            "case": self.case,
            "fmu": self.fmu,
            "fmu_file": self.fmu_file,
            "status": str(self.status),
            "messages": self.messages,
            "seconds": round(self.seconds, 4),
            "signals": [d.to_json() for d in self.deviations],
        }
        if self.csv:
            entry["result_csv"] = self.csv
        if self.plot:
            entry["plot"] = self.plot
        if self.plot_data:
            entry["plot_data"] = self.plot_data
        if self.criteria:
            entry["criteria"] = self.criteria
        if self.streamed:
            entry["streamed"] = True
        if self.clock:
            entry["clock"] = self.clock
        if self.retried:
            entry["retried"] = self.retried
        return entry

    @classmethod
    def from_json(cls, entry: dict, fmu_folder: str) -> "CaseOutcome":
        """The outcome of its JSON (without its result and plot: files in the report)."""
        return cls(
            case=entry["case"],
            fmu=entry["fmu"],
            fmu_file=entry["fmu_file"],
            fmu_folder=fmu_folder,
            status=Status(entry["status"]),
            messages=entry["messages"],
            deviations=[Deviation.from_json(d) for d in entry["signals"]],
            seconds=entry["seconds"],
            csv=entry.get("result_csv", ""),
            plot=entry.get("plot", ""),
            plot_data=entry.get("plot_data", ""),
            criteria=entry.get("criteria", ""),
            streamed=entry.get("streamed", False),
            clock=entry.get("clock", {}),
            retried=entry.get("retried", ""),
        )


def ran_again(outcome: CaseOutcome) -> str:
    """What a case run a second time says of it (outcome.retried: why)."""
    return f"ran a second time, on a fresh process, after its first run's process ended: {outcome.retried}"


class Outcomes(Sequence):
    """A campaign's outcomes, in the order of the FMUs and their cases."""

    def light(self) -> Iterator[CaseOutcome]:
        """The outcomes, leaving out what must be read from disk to give
        them (each case's result): for the report's pages and counts."""
        return iter(self)


class KeptOutcomes(Outcomes):
    """Outcomes kept in memory (a campaign without a report folder)."""

    def __init__(self, outcomes):
        self.outcomes = list(outcomes)

    def __len__(self):
        return len(self.outcomes)

    def __getitem__(self, index):
        return self.outcomes[index]


@dataclass
class CampaignResult:
    cases: Outcomes
    mode: Mode  # the comparison
    where: str = ""
    seconds: float = 0.0
    report_dir: Path | None = None
    _counts: dict | None = field(default=None, repr=False)  # by status, when known
    problems: list = field(default_factory=list)  # what was given and could not be run at all, each a message

    @property
    def passed(self) -> bool:
        return self.counts()[Status.PASS] == len(self.cases) and not self.problems

    @property
    def exit_code(self) -> ExitStatus:
        """The worst case's: 0 every case passes, 1 one differs or failed to simulate, 2 one is invalid."""
        worst = max((status.exit_code for status, n in self.counts().items() if n), default=ExitStatus.SUCCESS)
        return max(worst, ExitStatus.BAD_INPUT) if self.problems else worst

    def counts(self) -> dict:
        """{status: cases}, every status."""
        if self._counts is None:
            self._counts = dict.fromkeys(Status, 0)
            for o in self.cases.light():
                self._counts[o.status] += 1
        return self._counts

    def failed(self, results: bool = True) -> list:
        """The outcomes that did not pass; results=False leaves out what a journaled campaign must read from
        disk (each case's result), keeping the messages."""
        return [o for o in (self.cases if results else self.cases.light()) if not o.passed]

    def headline(self) -> str:
        c = self.counts()
        text = f"{c[Status.PASS]} of {len(self.cases)} cases pass"
        if c[Status.PASS] != len(self.cases):
            text += (
                f", {c[Status.FAIL]} differ"
                + (f", {c[Status.ERROR]} failed to simulate" if c[Status.ERROR] else "")
                + (f", {c[Status.INVALID]} invalid" if c[Status.INVALID] else "")
            )
        return text + f" ({self.seconds:.1f} s on {self.where})."

    def summary(self) -> str:
        """The headline and every failing case with its messages."""
        lines = [self.headline()] + [f"not run: {problem}" for problem in self.problems]
        for o in self.failed(results=False):
            lines.append(f"{o.status.upper()}  {o.case} on {o.fmu}")
            lines += [f"      {m}" for m in o.messages]
        return "\n".join(lines)
