"""fmutrace gives every pair of the labelled corpus (tests/support/corpus.py:
faults injected into every model's reference scenarios, labelled by
construction) its label: no false pass, no false fail."""

import collections

import numpy as np
import pytest

from fmutrace import Criteria, compare_traces, parse_mode
from support.corpus import corpus

PAIRS = corpus()


def verdict(pair):
    mode = Criteria({pair.signal: parse_mode(pair.criterion)}, discrete={pair.signal} if pair.discrete else set())
    return "pass" if compare_traces(pair.result, pair.reference, mode).passed else "fail"


def test_the_corpus_covers_every_model_and_fault():
    models = {p.name.split("/")[0] for p in PAIRS} - {"hard"}
    assert models == {
        "LGF_LimRateOfChangeAdvancedCI",
        "LGF_LimRateOfChangeCI",
        "Ramp",
        "RateLimit",
        "RateLimiter",
        "RateLimiterStatic",
    }
    faults = collections.Counter((p.name.split("/")[3], p.label) for p in PAIRS)
    for fault, label in [
        ("status bit flipped for a cycle", "fail"),
        ("late by 2 cycles", "fail"),
        ("late by 2 cycles", "pass"),
        ("one binary32 ulp off", "pass"),
        ("one binary32 ulp off", "fail"),
        ("ramp 1% too slow", "fail"),
        ("one-sample glitch", "fail"),
        ("one-sample glitch (in the reference)", "fail"),
        ("late by 2 cycles (in the reference)", "pass"),
        ("late by 1 cycle", "pass"),
        ("event half a cycle late", "pass"),
        ("signal missing", "fail"),
        ("none", "pass"),
        ("funnel#54 a zero value tolerance", "fail"),
        ("csv-compare#77 a reference shorter than the result", "pass"),
        ("csv-compare#74 a constant reference, relative tolerance", "pass"),
        ("csv-compare#20 a trace with events against itself", "pass"),
    ]:
        assert faults[fault, label] > 0, (fault, label)


def test_fmutrace_gives_every_pair_its_label():
    wrong = [(p.name, p.label) for p in PAIRS if verdict(p) != p.label]
    assert not wrong, f"{len(wrong)} of {len(PAIRS)} pairs mislabelled, e.g. {wrong[:5]}"


@pytest.mark.parametrize("criterion,label", [("discrete:cycles=1", "fail"), ("discrete:cycles=2", "pass")])
def test_a_boolean_two_cycles_late_by_the_corpus(criterion, label):
    late = [p for p in PAIRS if "/late by 2 cycles/" in p.name and p.criterion == criterion]
    assert late and all(p.label == label and verdict(p) == label for p in late)


def messages(pair):
    mode = Criteria({pair.signal: parse_mode(pair.criterion)}, discrete={pair.signal} if pair.discrete else set())
    return compare_traces(pair.result, pair.reference, mode).messages()


def of_fault(fault, criterion, label=None):
    chosen = [
        p
        for p in PAIRS
        if p.name.split("/")[3] == fault and p.criterion.startswith(criterion) and label in (None, p.label)
    ]
    assert chosen, (fault, criterion)
    return chosen


def glitch_time(pair):
    """The time of the sample where result and reference differ (the one glitch)."""
    differs = pair.result[pair.signal] != pair.reference[pair.signal]
    (at,) = pair.reference["time"][differs]
    return float(at)


@pytest.mark.parametrize(
    "fault,side",
    [
        ("one-sample glitch", "the result leaves the tube around the reference"),
        ("one-sample glitch (in the reference)", "the reference leaves the tube around the result"),
    ],
)
def test_a_glitch_under_a_one_cycle_tube_fails_and_says_which_trace_left_the_tube(fault, side):
    """A one-cycle +10 spike is no shift in time: in the reference it fails
    as in the result, the message naming the side that left the tube and
    the spike's time (first, or as the other side failing too where the
    spike also took a value the result's sample needed from the tube)."""
    for pair in of_fault(fault, "tube:", "fail"):
        (message,) = messages(pair)
        at = glitch_time(pair)
        assert message.startswith(f"{pair.signal} (tube of ")
        assert f": {side} first at t={at!r}: " in message or f"; {side} too, first at t={at!r}" in message, message


def test_the_reference_glitch_passes_a_one_sided_tube_as_csv_compare_judges_it():
    """Where the reference is flat around its glitch, the spike only widens
    the tube around the reference: the one-sided tube (sides=1) passes it."""
    flat = []
    for pair in of_fault("one-sample glitch (in the reference)", "tube:", "fail"):
        clean = pair.result[pair.signal]
        k = int(np.flatnonzero(clean != pair.reference[pair.signal])[0])
        if 2 <= k <= len(clean) - 3 and (clean[k - 2 : k + 3] == clean[k]).all():
            flat.append(pair)
            one_sided = Criteria({pair.signal: parse_mode(pair.criterion + ",sides=1")})
            assert compare_traces(pair.result, pair.reference, one_sided).passed, pair.name
    assert flat


def test_a_spurious_pulse_in_the_reference_is_a_pulse_missing_from_the_result_at_its_time():
    """The Boolean's one-cycle pulse in the reference: missing at its own
    time, not a later change paired with it (changes are paired nearest
    first, same direction)."""
    pairs = [p for p in of_fault("one-sample glitch (in the reference)", "discrete:") if "status" not in p.signal]
    for pair in pairs:
        at, value = glitch_time(pair), pair.reference[pair.signal][pair.reference["time"] == glitch_time(pair)][0]
        assert messages(pair) == [
            f"{pair.signal} (exact, up to 1 cycle early or late): the reference's pulse to {int(value)} at t={at!r} "
            "(1 cycle) is missing from the result"
        ], pair.name


def test_a_pulse_the_reference_lacks_is_named_with_both_its_times():
    for pair in [p for p in of_fault("one-sample glitch", "discrete:") if "status" not in p.signal]:
        at = glitch_time(pair)
        (message,) = messages(pair)
        assert (
            f": changes to {int(pair.result[pair.signal][pair.result['time'] == at][0])} at t={at!r} and back at t="
            in (message)
            and message.endswith(", a pulse the reference lacks")
        ), message


@pytest.mark.parametrize("fault", ["late by 2 cycles", "late by 2 cycles (in the reference)"])
def test_boolean_changes_within_the_cycles_allowed_pass_late_or_early(fault):
    for pair in of_fault(fault, "discrete:cycles=2"):
        assert pair.label == "pass" and verdict(pair) == "pass", pair.name
        (message,) = messages(pair)
        assert message.endswith("time allowance used: 2 of 2 cycles at t=" + message.rsplit("t=", 1)[1]), message
