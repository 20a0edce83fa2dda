"""The labelled corpus of comparisons (issue 44): faults injected into every
model's reference scenarios, each pair of traces labelled must-pass or
must-fail by construction, with the criterion a careful user states for
the signal, in fmutrace's words and as pyfunnel's allowances.

The references are the scenarios' hand-worked ones (tests/scenarios); a
pair's result is the reference with one fault injected, one signal at a
time (pyfunnel compares one signal). A signal's kind comes from its type
in modelDescription/<Model>.toml (Boolean, Integer, Enumeration: discrete;
Real). A label follows from the fault and the criterion's definition
(docs/fmutrace.md, Comparison), never from a tool's verdict:

- a status bit flipped for one cycle: a change the reference lacks: fails
  "discrete:cycles=1" (each change within one cycle, none added);
- a Boolean late by 2 cycles: each change 2 cycles late: fails with
  cycles=1, passes with cycles=2;
- a REAL off by one binary32 ulp at one sample: passes "ulps:1,binary32",
  fails "exact";
- a ramp 1 % too slow (the result the reference stretched in time by 1 %
  from its first sample): fails "tol:abs=1e-6" where it moves a sample by
  more than 1e-6 (checked here, in exact rational arithmetic);
- a one-sample glitch (+10 on a REAL, the other value on a Boolean, a bit
  on a status word, at a sample whose neighbours hold its value): fails
  "tol:abs=1e-6" and "discrete:cycles=1"; on a REAL it fails a one-cycle
  tube of value 1e-6 too where it rises above its neighbours by more
  than 1e-6 (the tube is checked both ways: a glitch in the reference
  fails as one in the result); on a Boolean in the reference it is a
  pulse missing from the result;
- a REAL one cycle late: passes a one-cycle tube of value 1e-6 (each
  sample is its reference's sample one cycle before, which the tube's
  time reaches; one way only: one cycle early, the last sample's value
  is one the reference reaches after its end);
- an event shifted by half a cycle (the reference's row of a discrete
  change stamped half a cycle late, as a recorder on another clock might):
  within one cycle: passes "discrete:cycles=1";
- a signal missing from the result: fails any criterion;
- no fault: passes every criterion above.

Each fault but the last three is also put the other way round (in the
reference, the result clean): a label holds both ways. Beside them, the
known hard cases of funnel's and csv-compare's issue trackers, rebuilt
from their descriptions (hard_cases).
"""

import dataclasses
import functools
import tomllib
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from fmutrace import read_trace

from support.fmu_driver import REPO
from support.scenarios import SCENARIO_ROOT

DISCRETE_TYPES = ("Boolean", "Integer", "Enumeration")
GLITCH = 10.0
RAMP_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Pair:
    name: str  # <Model>/<scenario>/<signal>/<fault>/<criterion>
    reference: np.ndarray  # (time, signal)
    result: np.ndarray  # (time, signal), or (time,) alone: the signal missing
    signal: str
    criterion: str  # fmutrace's words (--signal NAME=MODE)
    funnel: dict | None  # pyfunnel's allowances (atolx, atoly, rtoly); None: it cannot state the pair
    label: str  # "pass" or "fail"
    discrete: bool


def variable_types(model):
    with open(REPO / "modelDescription" / f"{model}.toml", "rb") as file:
        return {v["name"]: v["type"] for v in tomllib.load(file)["variable"]}


def step_of(folder, model):
    for line in (folder / f"{model}_ref.opt").read_text().splitlines():
        if line.startswith("StepSize,"):
            return float(line.split(",")[1])
    raise AssertionError(f"{folder}: no StepSize")


def one_signal(times, values, name):
    table = np.zeros(len(times), dtype=[("time", np.float64), (name, np.float64)])
    table["time"], table[name] = times, values
    return table


def changes(values):
    """The rows where values change."""
    return np.flatnonzero(values[1:] != values[:-1]) + 1


def late(values, cycles):
    moved = values.copy()
    moved[cycles:] = values[:-cycles]
    return moved


def quiet_sample(values, near):
    """The row nearest to near whose neighbours hold its value (None if none)."""
    quiet = np.flatnonzero((values[1:-1] == values[:-2]) & (values[1:-1] == values[2:])) + 1
    return None if not len(quiet) else int(quiet[np.argmin(np.abs(quiet - near))])


def stretched_moves(times, values, factor):
    """The reference stretched in time by factor from its first sample, at
    its own times (linear between samples), and whether that moves a sample
    by more than RAMP_TOLERANCE: worked in fractions, not in the tools'
    floating point."""
    t = [Fraction(x) for x in times]
    v = [Fraction(x) for x in values]
    out, moved = [], False
    for ti, vi in zip(t, v, strict=True):
        at = t[0] + (ti - t[0]) / Fraction(factor)
        k = max(j for j in range(len(t)) if t[j] <= at)
        w = v[k] if k == len(t) - 1 or t[k + 1] == t[k] else v[k] + (v[k + 1] - v[k]) * (at - t[k]) / (t[k + 1] - t[k])
        out.append(float(w))
        moved = moved or abs(w - vi) > Fraction(RAMP_TOLERANCE)
    return np.array(out), moved


def scenario_pairs(folder):
    model = folder.parent.name
    types = variable_types(model)
    step = step_of(folder, model)
    reference = read_trace(folder / f"{model}_ref.csv")
    times = reference["time"]
    on_cycles = len(times) > 4 and np.allclose(np.diff(times), step, rtol=0, atol=1e-9 * max(1.0, abs(times[-1])))
    if not on_cycles:  # (events, sparser references: the faults below are defined on cycles)
        return
    middle = len(times) // 2
    for signal in reference.dtype.names[1:]:
        values = reference[signal].astype(np.float64)
        discrete = types[signal] in DISCRETE_TYPES
        prefix = f"{model}/{folder.name}/{signal}"

        def pair(fault, result_values, criterion, funnel, label, ref_times=times, result_times=times, **bound):
            signal, values, prefix, discrete = bound["signal"], bound["values"], bound["prefix"], bound["discrete"]
            result = (
                np.zeros(len(result_times), dtype=[("time", np.float64)])
                if result_values is None
                else one_signal(result_times, result_values, signal)
            )
            if result_values is None:
                result["time"] = result_times
            return Pair(
                f"{prefix}/{fault}/{criterion}",
                one_signal(ref_times, values, signal),
                result,
                signal,
                criterion,
                funnel,
                label,
                discrete,
            )

        pair = functools.partial(pair, signal=signal, values=values, prefix=prefix, discrete=discrete)
        if discrete:
            one_cycle = {"atolx": step, "atoly": 0.0}
            yield pair("none", values, "discrete:cycles=1", one_cycle, "pass")
            glitched = values.copy()
            calm = quiet_sample(values, middle)  # (a flip beside a change would be that change a cycle off)
            if "status" in signal.lower() and calm is not None:
                glitched[calm] = float(int(values[calm]) ^ 0x0100)
                yield pair("status bit flipped for a cycle", glitched, "discrete:cycles=1", one_cycle, "fail")
            elif types[signal] == "Boolean" and calm is not None:
                glitched[calm] = 1.0 - values[calm]
                yield pair("one-sample glitch", glitched, "discrete:cycles=1", one_cycle, "fail")
            at = changes(values)
            if types[signal] == "Boolean" and len(at) and at[0] >= 2 and at[-1] <= len(values) - 3:
                two = {"atolx": 2 * step, "atoly": 0.0}
                yield pair("late by 2 cycles", late(values, 2), "discrete:cycles=1", one_cycle, "fail")
                yield pair("late by 2 cycles", late(values, 2), "discrete:cycles=2", two, "pass")
            if len(at) and at[0] >= 1:
                shifted = times.copy()
                shifted[at[0]] += step / 2
                yield pair("event half a cycle late", values, "discrete:cycles=1", one_cycle, "pass", ref_times=shifted)
        else:
            tolerance = {"atolx": 0.0, "atoly": RAMP_TOLERANCE}
            one_cycle_tube, tube_allowances = (
                f"tube:time={step!r},value={RAMP_TOLERANCE}",
                {"atolx": step, "atoly": RAMP_TOLERANCE},
            )
            yield pair("none", values, f"tol:abs={RAMP_TOLERANCE}", tolerance, "pass")
            finite = np.isfinite(values)
            if finite[middle]:
                off = values.copy()
                off[middle] = float(np.nextafter(np.float32(values[middle]), np.float32(np.inf)))
                ulp = {"atolx": 0.0, "atoly": 0.0, "ltoly": 2.0**-23}
                yield pair("one binary32 ulp off", off, "ulps:1,binary32", ulp, "pass")
                yield pair("one binary32 ulp off", off, "exact", {"atolx": 0.0, "atoly": 0.0}, "fail")
                glitched = values.copy()
                glitched[middle] += GLITCH
                yield pair("one-sample glitch", glitched, f"tol:abs={RAMP_TOLERANCE}", tolerance, "fail")
            if finite.all():  # (a NaN sample is outside any tube)
                # under a one-cycle tube: the glitch fails where it leaves the window of its neighbours
                neighbours = values[max(middle - 1, 0) : middle + 2]
                spike = "fail" if glitched[middle] > neighbours.max() + RAMP_TOLERANCE else "pass"
                yield pair("one-sample glitch", glitched, one_cycle_tube, tube_allowances, spike)
                yield pair("late by 1 cycle", late(values, 1), one_cycle_tube, tube_allowances, "pass")
            if finite.all() and len(changes(values)):
                slow, moved = stretched_moves(times, values, 1.01)
                label = "fail" if moved else "pass"
                yield pair("ramp 1% too slow", slow, f"tol:abs={RAMP_TOLERANCE}", tolerance, label)
        yield pair("signal missing", None, "exact", None, "fail")


def grid(first, last, step):
    return np.round(np.arange(round((last - first) / step) + 1) * step + first, 12)


def hard_cases():
    """The known hard cases of funnel's and csv-compare's issue trackers,
    rebuilt from their descriptions (one signal x each), labelled from
    what their reporters expected."""
    t = grid(0.0, 1.0, 0.1)
    short = grid(0.0, 0.4, 0.1)
    longer = np.where(t <= 0.4, t, 100.0)
    events = np.array([0.0, 0.1, 0.2, 0.2, 0.3, 0.4, 0.4, 0.5])
    steps = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0])
    constant = np.full(len(t), 293586.68524)
    cases = [
        # lbl-srg/funnel#54: a value tolerance of 0 (below 1e-10) was taken as a wider one
        ("funnel#54 a zero value tolerance", t, np.zeros(len(t)), t, np.full(len(t), 1e-11), "tol:abs=0",
         {"atolx": 0.0, "atoly": 0.0}, "fail"),
        # modelica-tools/csv-compare#77: a reference shorter than the run says nothing after its end
        ("csv-compare#77 a reference shorter than the result", short, short, t, longer, "tube:time=0.01,value=0.001",
         {"atolx": 0.01, "atoly": 0.001}, "pass"),
        # modelica-tools/csv-compare#74: a constant reference's relative tube too tight
        ("csv-compare#74 a constant reference, relative tolerance", t, constant, t, constant * (1 + 1e-6),
         "tol:abs=0,rel=0.001", {"atolx": 0.0, "atoly": 0.0, "ltoly": 1e-3}, "pass"),
        # modelica-tools/csv-compare#20: a trace with events compared with itself reported errors
        ("csv-compare#20 a trace with events against itself", events, steps, events, steps,
         "tube:time=0.01,value=0.001", {"atolx": 0.01, "atoly": 0.001}, "pass"),
    ]  # fmt: skip
    for fault, ref_t, ref_v, res_t, res_v, criterion, funnel, label in cases:
        yield Pair(
            f"hard/{fault.split()[0]}/x/{fault}/{criterion}",
            one_signal(ref_t, ref_v, "x"),
            one_signal(res_t, res_v, "x"),
            "x",
            criterion,
            funnel,
            label,
            False,
        )


# the faults that are where they are said to be (a REAL one cycle early is not one cycle late: see above)
ONE_WAY = ("none", "signal missing", "event half a cycle late", "late by 1 cycle")


def corpus():
    """Every pair of every model's reference scenarios; each fault also
    the other way round, in the reference (a glitch the controller recorded
    and the FMU lacks): a label holds both ways."""
    pairs = []
    for ref in sorted(SCENARIO_ROOT.glob("*/*/*_ref.csv")):
        for pair in scenario_pairs(ref.parent):
            pairs.append(pair)
            if pair.name.split("/")[3] not in ONE_WAY:
                model, scenario, signal, fault, criterion = pair.name.split("/", 4)
                name = f"{model}/{scenario}/{signal}/{fault} (in the reference)/{criterion}"
                pairs.append(dataclasses.replace(pair, name=name, reference=pair.result, result=pair.reference))
    return pairs + list(hard_cases())
