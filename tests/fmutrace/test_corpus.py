"""fmutrace gives every pair of the labelled corpus (tests/support/corpus.py:
faults injected into every model's reference scenarios, labelled by
construction) its label: no false pass, no false fail."""

import collections

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
