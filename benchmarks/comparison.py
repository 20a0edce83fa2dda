#!/usr/bin/env python3
"""fmutrace and pyfunnel on the labelled corpus: false passes and false fails.

    comparison.py [--smoke]

The corpus (tests/support/corpus.py) injects faults into every model's
reference scenarios, one signal at a time, each pair labelled must-pass
or must-fail by construction with the criterion a careful user states
for the signal. fmutrace judges each pair by that criterion (per-signal
criteria, the signal's discrete type named); pyfunnel (LBNL's funnel,
pinned in tests/requirements.txt) by the same allowances in its terms:
a time tolerance of k cycles is atolx = k * step, a value tolerance
atoly, one binary32 ulp ltoly = 2^-23 (its largest size relative to the local value). A
pair pyfunnel cannot state (a signal missing from the result) is counted
apart. Prints one row per fault and criterion (h: the scenario's cycle,
a tube's time of one cycle), and the totals; --smoke takes every 20th
pair (its figures mean little). pyfunnel checks each result sample in
the funnel around the reference alone, as fmutrace's one-sided tube: a
glitch in the reference only widens its funnel.
"""

import argparse
import collections
import contextlib
import io
import os
import re
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))

from fmutrace import Criteria, compare_traces, parse_mode  # noqa: E402
from support.corpus import corpus  # noqa: E402


def fmutrace_verdict(pair):
    mode = Criteria({pair.signal: parse_mode(pair.criterion)}, discrete={pair.signal} if pair.discrete else set())
    return "pass" if compare_traces(pair.result, pair.reference, mode).passed else "fail"


def funnel_verdict(pyfunnel, pair, folder):
    """pass, fail, or None where pyfunnel cannot state the pair."""
    if pair.funnel is None or pair.signal not in (pair.result.dtype.names or ()):
        return None
    x_ref, y_ref = pair.reference["time"], pair.reference[pair.signal]
    x_test, y_test = pair.result["time"], pair.result[pair.signal]
    if not (np.isfinite(y_ref).all() and np.isfinite(y_test).all()):
        return None  # (funnel takes finite numbers only)
    with contextlib.redirect_stdout(io.StringIO()):
        status = pyfunnel.compareAndReport(
            list(map(float, x_ref)),
            list(map(float, y_ref)),
            list(map(float, x_test)),
            list(map(float, y_test)),
            outputDirectory=folder,
            **pair.funnel,
        )
    if status != 0:
        return "fail"
    errors = np.loadtxt(os.path.join(folder, "errors.csv"), delimiter=",", skiprows=1, ndmin=2)
    return "fail" if len(errors) and np.any(errors[:, 1] != 0) else "pass"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="every 20th pair: keeps it working in CI")
    args = parser.parse_args()
    try:
        import pyfunnel
    except ImportError:
        pyfunnel = None
    pairs = corpus()[:: 20 if args.smoke else 1]
    rows: dict = collections.defaultdict(collections.Counter)
    with tempfile.TemporaryDirectory(prefix="fmutrace-funnel-") as folder:
        for pair in pairs:
            row = rows[pair.name.split("/")[3], re.sub(r"^tube:time=[^,]+", "tube:time=h", pair.criterion), pair.label]
            row["pairs"] += 1
            for tool, verdict in [
                ("fmutrace", fmutrace_verdict(pair)),
                ("pyfunnel", funnel_verdict(pyfunnel, pair, folder) if pyfunnel is not None else None),
            ]:
                if verdict is None:
                    row[f"{tool} n/a"] += 1
                elif verdict != pair.label:
                    row[f"{tool} false {verdict}"] += 1  # a must-fail that passed is a false pass
    columns = [
        "fmutrace false pass",
        "fmutrace false fail",
        "pyfunnel false pass",
        "pyfunnel false fail",
        "pyfunnel n/a",
    ]
    print(
        "| fault | criterion | label | pairs | " + " | ".join(c.replace("n/a", "cannot state") for c in columns) + " |"
    )
    print("|" + "---|" * (4 + len(columns)))
    total: collections.Counter = collections.Counter()
    for (fault, criterion, label), row in sorted(rows.items()):
        total.update(row)
        print(
            f"| {fault} | `{criterion}` | must {label} | {row['pairs']} | "
            + " | ".join(str(row[c]) for c in columns)
            + " |"
        )
    print(f"| all | | | {total['pairs']} | " + " | ".join(str(total[c]) for c in columns) + " |")
    if pyfunnel is None:
        print("pyfunnel is not installed (tests/requirements.txt pins it): its columns are empty")
    if args.smoke:
        print("(SMOKE: every 20th pair)")


if __name__ == "__main__":
    main()
