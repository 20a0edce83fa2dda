"""Reference scenarios as scripts of tests/c/run_trace.c, the C harness
built for each platform: natively on x86_64 Linux (with floating-point
traps too), under qemu-user for aarch64 Linux, under wine for Windows."""

import os
from itertools import pairwise

from support.fmu_driver import BUILD_DIR
from support.importers import input_values
from support.process import run as run_bounded
from support.scenarios import same

QEMU = [os.environ.get("RL_QEMU_AARCH64") or "qemu-aarch64", "-L", "/usr/aarch64-linux-gnu"]
KINDS = {"Float64": "F", "Real": "F", "Int32": "I", "Integer": "I", "Enumeration": "L", "Boolean": "B"}
HARNESS = {
    "x86_64-linux": [str(BUILD_DIR / "run_trace")],
    "linux64": [str(BUILD_DIR / "run_trace")],
    "aarch64-linux": QEMU + [str(BUILD_DIR / "aarch64" / "run_trace")],
}
SUFFIX = {"x86_64-linux": ".so", "linux64": ".so", "aarch64-linux": ".so", "x86_64-windows": ".dll"}


def script_parts(scenario, md, times=None):
    """The scenario as run_trace's script: the start (start values and the
    inputs at the start, initialization, the outputs) and one block per
    step (the inputs, a row holding from its time on; the step; the
    recorded outputs). times: the communication points (default: the
    grid of the scenario's step size)."""
    variables = {v.name: v for v in md.modelVariables}

    def set_line(name, value):
        v = variables[name]
        kind = KINDS[v.type]
        literal = float(value).hex() if kind == "F" else str(int(value))
        return f"set {kind} {v.valueReference} {literal}"

    gets = [f"get {KINDS[variables[name].type]} {variables[name].valueReference}" for name in scenario.outputs]
    o = scenario.options
    start, h = o["StartTime"], o["StepSize"]
    if times is None:
        n = round((o["StopTime"] - start) / h)
        times = [start + k * h for k in range(n + 1)]
    head = [set_line(name, value) for name, value in scenario.start_values.items()]
    head += [set_line(name, value) for name, value in input_values(scenario, start).items()]
    head += [f"init {start.hex()}"] + gets
    blocks = [
        [set_line(name, value) for name, value in input_values(scenario, t).items()]
        + [f"step {t.hex()} {(end - t).hex()}"]
        + gets
        for t, end in pairwise(times)
    ]
    return head, blocks


def script(scenario, md, times=None):
    head, blocks = script_parts(scenario, md, times)
    return "\n".join(head + [line for block in blocks for line in block]) + "\n"


def run_script(platform, stage, model, token, text, tmp_path, what, wine=None, options=()):
    """run_trace's output lines for the script text, on platform's binary
    of the staged FMU (wine: the environment of a wine prefix, for Windows;
    options: run_trace's, e.g. --fmi2 for the linux64 binary, --trap)."""
    (tmp_path / "script").write_text(text)
    command = HARNESS.get(platform) or [
        os.path.join(wine["WINE_DIR"], "wine64"),
        str(BUILD_DIR / "windows" / "run_trace.exe"),
    ]
    with open(tmp_path / "script") as script_file:
        done = run_bounded(
            command + list(options) + [str(stage / "binaries" / platform / f"{model}{SUFFIX[platform]}"), token],
            timeout=300,
            stdin=script_file,
            what=what,
            cwd=tmp_path,
            env=wine,
        )
    assert done.returncode == 0, done.stderr
    return [line.strip() for line in done.stdout.splitlines()]


def halves(scenario, md, state):
    """The script's first half ending in save state, the second starting
    with load state, and the whole."""
    head, blocks = script_parts(scenario, md)
    middle = len(blocks) // 2
    first = head + [line for block in blocks[:middle] for line in block] + [f"save {state}"]
    second = [f"load {state}"] + [line for block in blocks[middle:] for line in block]
    return "\n".join(first) + "\n", "\n".join(second) + "\n", script(scenario, md)


def reference_script(scenario, md):
    """The scenario's script at its grid and every reference time (a
    reference off the grid is a step there, as fmutrace runs it), and the
    check that run_trace's output lines give the hand-worked reference."""
    o = scenario.options
    grid = [
        o["StartTime"] + k * o["StepSize"] for k in range(round((o["StopTime"] - o["StartTime"]) / o["StepSize"]) + 1)
    ]

    def on_grid(t):  # a reference time within 1e-9 of a grid point is that point
        return next((g for g in grid if abs(g - t) <= 1e-9 * max(1.0, abs(t))), t)

    reference_times = [on_grid(float(t)) for t in scenario.reference["time"]]
    times = sorted(set(grid) | set(reference_times))
    names = list(scenario.outputs)

    def check(lines):
        assert len(lines) == len(times) * len(names)
        row_of = {t: k for k, t in enumerate(times)}
        for row, t in enumerate(reference_times):
            for k, name in enumerate(names):
                text = lines[row_of[t] * len(names) + k]
                value = (
                    float.fromhex(text) if text.startswith(("0x", "-0x", "inf", "-inf", "nan", "-nan")) else int(text)
                )
                assert same(value, scenario.reference[name][row]), (name, t, text, scenario.reference[name][row])

    return script(scenario, md, times), check
