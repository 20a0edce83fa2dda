"""The PLC's real clock: a corpus of recordings whose cyclic interrupt
jitters, overruns, and whose recorder samples every k-th cycle on a clock
of its own, compared exact in each format that carries time stamps.

The reference is the FMU itself, run here through fmpy's FMI calls
(support.fmu_driver, not fmutrace) as the OB ran the block: one doStep
per execution of the OB, as long as the interval since the execution
before (in whole ms, as a TIME is) for a block that measures elapsed time
(cycleTime = 0), or one cycle of the configured cycle per execution for
a block that takes its cycle from a parameter. The recordings are written
here from each export's documented structure (tests/recordings/samples.py
names the sources), never by fmutrace; then fmutrace must lay every sample
on the cycle it was taken in and replay the same steps: every comparison
exact, a perturbed sample failing at its cycle, a skipped cycle named.
"""

import re
from datetime import datetime, timedelta, timezone

import numpy as np
import pytest

import fmutrace
from fmutrace import RecordingOptions, RunOptions
from support.fmu_driver import Instance, fmu_file

T_MS = 10  # the OB's interval
CYCLES = 240
START = datetime(2026, 11, 20, 13, 0, 0, tzinfo=timezone.utc)
OLE_EPOCH = datetime(1899, 12, 30, tzinfo=timezone.utc)


def _u(n):
    """The input of cycle n: steps the limiter ramps after, changing on every third cycle only (a
    recorder that samples every third cycle sees every value)."""
    block = n // 3
    return float([0, 5, 5, -3, 2, 2, 7, -6][(block // 10) % 8])


# -- the OB: which cycles ran, at what time of the PLC's clock (whole ms) ------------------------------------
def uniform(rng):
    """Each execution up to 40 % of the interval early or late (whole ms)."""
    n = np.arange(CYCLES)
    return n, n * T_MS + rng.integers(-4, 5, CYCLES)


def gaussian(rng):
    """Gaussian jitter of 1.5 ms (whole ms, less than 40 % of the interval)."""
    n = np.arange(CYCLES)
    jitter = np.rint(rng.normal(0, 1.5, CYCLES))
    return n, n * T_MS + np.clip(jitter, -4, 4).astype(np.int64)


def overrun(rng):
    """Every 7th cycle does not run (the one before overran), the others jitter by up to 2 ms."""
    n = np.arange(CYCLES)
    n = n[(n % 7 != 6) | (n == 0)]
    return n, n * T_MS + rng.integers(-2, 3, len(n))


# -- the reference: the FMU run as the OB ran the block --------------------------------------------------------
MODELS = {
    # model, version, start values, input, output
    "RateLimiter LREAL": ("RateLimiter", 3, {"rateUpPar": 100.0, "rateDownPar": 50.0}, "u", "y"),
    "RateLimiter REAL": ("RateLimiter", 2, {"rateUpPar": 100.0, "rateDownPar": 50.0, "arithmetic": 2}, "u", "y"),
    "Ramp (TIME in ms)": ("Ramp", 3, {"rVariation": 90.0, "tTime": 1.0}, "rIn", "rOut"),
    "LGF_LimRateOfChangeCI": ("LGF_LimRateOfChangeCI", 3, {"setChangeRate": 70.0}, "value", "delayedValue"),
}


def run_ob(model, cycles, executions_ms, cycle_time):
    """(inputs, outputs) of each execution: the FMU stepped once per execution, for the interval since
    the one before (the first for one interval), or with cycleTime set, for one configured cycle."""
    name, version, start, input_name, output_name = MODELS[model]
    fmu = Instance(name, version)
    fmu.start(**start, **({"cycleTime": cycle_time} if cycle_time else {}))
    inputs, outputs, before = [], [], None
    for n, at in zip(cycles.tolist(), executions_ms.tolist(), strict=True):
        u = _u(n)
        fmu.set(**{input_name: u})
        interval = T_MS if before is None or cycle_time else at - before
        fmu.step(interval / 1000)
        inputs.append(u)
        outputs.append(fmu.get(output_name))
        before = at
    fmu.fmu.terminate()
    return np.array(inputs), np.array(outputs)


# -- the recordings, from each export's documented structure ---------------------------------------------------
def _ms(value):
    return repr(int(value)) if float(value).is_integer() else repr(float(value))


def _num(value, comma=False):
    text = repr(float(value))
    text = text[:-2] if text.endswith(".0") else text
    return text.replace(".", ",") if comma else text


def write_csv(path, stamps_ms, channels):
    """A table export: time in ms, a row per sample."""
    names = list(channels)
    rows = [";".join(["time [ms]"] + names)]
    rows += [";".join([_ms(t)] + [_num(channels[c][i]) for c in names]) for i, t in enumerate(stamps_ms)]
    path.write_text("\n".join(rows) + "\n")


def write_twincat(path, stamps_ms, channels):
    """TwinCAT Scope View CSV, timelines 'All' (a time column per channel, ms from the first point), tab,
    decimal comma, as samples.twincat_every_cycle writes it."""
    names = list(channels)
    lines = ["Name\tjitter", "File\tC:\\TwinCAT\\3.1\\Scope\\jitter.csv", "", ""]
    properties = [
        ("Name", lambda n: n),
        ("SymbolComment", lambda n: ""),
        ("Data-Type", lambda n: "REAL64"),
        ("SampleTime[ms]", lambda n: str(T_MS)),
        ("SymbolName", lambda n: f"MAIN.fbRamp.{n}"),
        ("NetID", lambda n: "5.80.201.232.1.1"),
        ("Port", lambda n: "851"),
    ]
    for key, value in properties:
        lines.append("\t".join(f"{key}\t{value(n)}" for n in names))
    lines.append("")
    first = stamps_ms[0]
    for i, t in enumerate(stamps_ms):
        lines.append("\t".join(f"{_ms(t - first)}\t{_num(channels[n][i], comma=True)}" for n in names))
    lines.append("EOF")
    path.write_text("\r\n".join(lines) + "\r\n")


def write_mdf(path, stamps_ms, channels):
    """MDF 4.10 by asammdf's own writer: the input in one channel group, the output in another, each
    group with its own time channel (s)."""
    from asammdf import MDF, Signal

    names = list(channels)
    seconds = np.asarray(stamps_ms, dtype=np.float64) / 1000
    mdf = MDF(version="4.10")
    mdf.append([Signal(np.asarray(channels[names[0]], dtype=float), seconds, name=names[0])], comment="input")
    mdf.append([Signal(np.asarray(channels[names[1]], dtype=float), seconds, name=names[1])], comment="output")
    mdf.save(str(path), overwrite=True)
    mdf.close()


def write_wincc(path, stamps_ms, channels):
    """WinCC data log: a row per tag and time stamp, ';' and a decimal comma, Time_ms as OLE days times
    1e6 to four decimals, as samples.wincc writes it; UTF-16 with a BOM."""
    lines = ['"VarName";"TimeString";"VarValue";"Validity";"Time_ms"']
    for i, t in enumerate(stamps_ms):
        moment = START + timedelta(milliseconds=int(t))
        ole = f"{(moment - OLE_EPOCH) / timedelta(days=1) * 1e6:.4f}".replace(".", ",")
        for name in channels:
            stamp = moment.strftime("%d.%m.%Y %H:%M:%S")
            lines.append(f'"{name}";"{stamp}";{_num(channels[name][i], True)};1;{ole}')
    path.write_bytes(("\ufeff" + "\r\n".join(lines) + "\r\n").encode("utf-16-le"))


FORMATS = {"csv": write_csv, "twincat": write_twincat, "mdf": write_mdf, "wincc": write_wincc}
SUFFIX = {"csv": ".csv", "twincat": ".csv", "mdf": ".mf4", "wincc": ".csv"}


def compare(model, path, cycle_lengths, step_size=None, cycle_time=0.0):
    name, version, start, input_name, output_name = MODELS[model]
    options = RecordingOptions(
        step_size=step_size,
        maps={input_name: "in", output_name: "out"},
        start_values={**start, "cycleTime": cycle_time},
        cycle_lengths=cycle_lengths,
    )
    return fmutrace.compare(str(fmu_file(name, version)), str(path), recording=options, run=RunOptions(jobs=1))


# (scenario, the OB, model, the block's cycle from cycleTime, recorded cycle lengths)
ELAPSED = [
    ("uniform", uniform, "RateLimiter LREAL"),
    ("gaussian", gaussian, "RateLimiter REAL"),
    ("overrun", overrun, "Ramp (TIME in ms)"),
    ("uniform", uniform, "Ramp (TIME in ms)"),
]


def corpus(scenarios):
    """Every format of every scenario; the fast lane runs CSV for each scenario and each other format for one
    of them (the k-th format the k-th scenario), the slow lane the rest."""
    return [
        pytest.param(
            writer, scenario, ob, model, id=f"{scenario}-{model.split()[0]}-{model.split()[-1]}-{writer}",
            marks=() if writer == "csv" or list(FORMATS).index(writer) == k + 1 else pytest.mark.slow,
        )
        for k, (scenario, ob, model) in enumerate(scenarios)
        for writer in FORMATS
    ]  # fmt: skip


@pytest.mark.parametrize("writer, scenario, ob, model", corpus(ELAPSED))
def test_a_jittered_ob_replayed_with_its_recorded_cycle_lengths_is_exact(tmp_path, writer, scenario, ob, model):
    """A block that measures elapsed time (cycleTime 0) on an OB that jitters: each recorded execution
    one step of its recorded interval reproduces it bit for bit; a perturbed sample fails at its cycle;
    the nominal cycle lengths do not reproduce it."""
    rng = np.random.default_rng(sum(map(ord, scenario + model)))
    cycles, executions = ob(rng)
    inputs, outputs = run_ob(model, cycles, executions, cycle_time=0)
    path = tmp_path / f"{scenario}{SUFFIX[writer]}"
    FORMATS[writer](path, executions, {"in": inputs, "out": outputs})
    campaign = compare(model, path, "recorded")
    assert campaign.passed, campaign.summary()
    [case] = campaign.cases
    assert "cycle lengths as recorded" in case.messages[0] and "jitter up to" in case.messages[0]
    if writer == "csv":  # a plain table is read in blocks as it runs, unless a cycle is missing (read whole)
        assert case.streamed == (scenario != "overrun")
    assert case.clock["largest_percent"] < 50 and case.clock["sampled_every"] == 1
    missing = sorted(set(range(int(cycles[-1]) + 1)) - set(cycles.tolist()))
    assert case.clock["missing_cycles"] == len(missing) and case.clock["first_missing"] == missing
    if missing:  # each named, in order
        named = ", ".join(map(str, missing))
        assert any(
            f"{len(missing)} of {int(cycles[-1]) + 1} cycles have no sample (cycles {named} from" in m
            for m in case.messages
        ), case.messages

    # one sample of the output perturbed: the failure is named at its cycle
    at = len(cycles) // 2 + 5
    perturbed = outputs.copy()
    perturbed[at] += 0.125
    FORMATS[writer](path, executions, {"in": inputs, "out": perturbed})
    campaign = compare(model, path, "recorded")
    assert not campaign.passed
    [case] = campaign.cases
    assert any(f"first differs at the recording's sample of cycle {int(cycles[at])} " in m for m in case.messages), (
        case.messages
    )

    # the nominal cycle lengths step 10 ms each: the block's elapsed times are not the OB's
    FORMATS[writer](path, executions, {"in": inputs, "out": outputs})
    assert not compare(model, path, "nominal").passed


SPARSE_CYCLES = 6000  # a minute: the recorder's clock drifts 0.6 of a cycle from the PLC's


def sparse(rng):
    """The OB's executions jitter by up to 30 %; a recorder with its own clock (started 3.7 s before,
    running 100 ppm fast) samples every third, stamping when it reads (up to 1 ms later): up to 40 % of
    a cycle from its grid, stamped to the ms (WinCC) or the us."""
    n = np.arange(0, SPARSE_CYCLES, 3)
    executions = n * T_MS + rng.integers(-3, 4, len(n))
    return n, (3700 + executions * (1 + 100e-6) + rng.uniform(0, 1, len(n))) * 1.0


CONFIGURED = [
    ("uniform", uniform, "LGF_LimRateOfChangeCI"),
    ("sparse", sparse, "LGF_LimRateOfChangeCI"),
    ("sparse", sparse, "RateLimiter LREAL"),
]


@pytest.mark.parametrize("writer, scenario, ob, model", corpus(CONFIGURED))
def test_a_block_that_takes_its_cycle_from_a_parameter_is_exact_on_nominal_cycles(
    tmp_path, writer, scenario, ob, model
):
    """A block that takes its cycle from a parameter (cycleTime = the OB's interval): the OB's jitter
    and the recorder's own clock only move the stamps; sampled every third cycle on a clock that
    drifts 100 ppm, every sample still falls on its own cycle."""
    rng = np.random.default_rng(sum(map(ord, scenario + model)))
    cycles, stamps = ob(rng)
    every_cycle = np.arange(int(cycles[-1]) + 1)
    inputs, outputs = run_ob(model, every_cycle, every_cycle * T_MS, cycle_time=T_MS / 1000)
    if writer != "mdf":
        stamps = np.round(stamps, 3) if stamps.dtype.kind == "f" else stamps
    path = tmp_path / f"{scenario}{SUFFIX[writer]}"
    channels = {"in": inputs[cycles], "out": outputs[cycles]}
    FORMATS[writer](path, stamps if writer != "wincc" else np.rint(stamps), channels)
    campaign = compare(model, path, "nominal", step_size=T_MS / 1000, cycle_time=T_MS / 1000)
    assert campaign.passed, campaign.summary()
    [case] = campaign.cases
    every = int(np.median(np.diff(cycles)))
    assert case.clock["sampled_every"] == every and case.clock["missing_cycles"] == 0
    if scenario == "sparse":
        assert case.clock["cycle_s"] == pytest.approx(T_MS / 1000 * (1 + 100e-6), rel=2e-5)

    perturbed = dict(channels, out=channels["out"].copy())
    at = len(cycles) // 2
    perturbed["out"][at] -= 0.5
    FORMATS[writer](path, stamps if writer != "wincc" else np.rint(stamps), perturbed)
    campaign = compare(model, path, "nominal", step_size=T_MS / 1000, cycle_time=T_MS / 1000)
    [case] = campaign.cases
    assert not campaign.passed and any(
        f"first differs at the recording's sample of cycle {int(cycles[at])} " in m for m in case.messages
    ), case.messages


def test_stamps_that_fit_no_grid_are_refused_with_the_best_cycle_found(tmp_path):
    """Samples every 50 ms that jitter by up to 20 ms, given a step of 10 ms: they are up to two of its
    cycles off any grid of it (as stamps at random are), so refused, naming the cycle their own
    intervals give and how far they are from it."""
    rng = np.random.default_rng(5)
    stamps = (np.arange(200) * 50 + rng.uniform(-20, 20, 200)).round(3)
    path = tmp_path / "every_50_ms.csv"
    write_csv(path, stamps, {"in": np.zeros(200), "out": np.zeros(200)})
    campaign = compare("RateLimiter LREAL", path, "nominal", step_size=0.01)
    [case] = campaign.cases
    assert str(case.status) == "invalid", case.messages
    assert "fit no grid of cycles of 0.01 s" in case.messages[0], case.messages
    assert re.search(r"their own intervals give a cycle of 0\.0(49[89]|50[01])\d* s, up to \d", case.messages[0])


def test_recorded_cycle_lengths_need_every_cycle(tmp_path):
    rng = np.random.default_rng(3)
    cycles, stamps = sparse(rng)
    path = tmp_path / "sparse.csv"
    write_csv(path, np.round(stamps, 3), {"in": np.zeros(len(cycles)), "out": np.zeros(len(cycles))})
    [case] = compare("RateLimiter LREAL", path, "recorded", step_size=0.01).cases
    assert str(case.status) == "invalid"
    assert "replays every execution of the OB, but the recording samples only every 3 cycles" in case.messages[0]


@pytest.mark.parametrize("model", ["RateLimiter LREAL", "Ramp (TIME in ms)"])
def test_a_case_folder_replays_the_cycle_lengths_of_its_reference(tmp_path, model):
    """A case folder (the FMI cross-check layout) whose _ref.opt says CycleLengths,recorded: each
    reference row is one execution of the OB, a step from the row before for the interval between
    their times (whole ms here, an OB that overruns every 7th cycle and jitters by 2 ms). The reference
    is the FMU stepped so through fmpy's FMI calls (the input row of time t set before the step from t,
    as the layout reads it): exact. Without the key (nominal steps) it is not; a perturbed row fails at
    its time; a value of the key that is not one is refused at its line and column."""
    name, version, start, input_name, output_name = MODELS[model]
    _, executions = overrun(np.random.default_rng(7))
    times = executions - executions[0]  # ms from the first execution
    inputs = [_u(k) for k in range(len(times) - 1)]  # the first is 0, the input's start value
    fmu = Instance(name, version)
    fmu.start(**start)
    outputs = [fmu.get(output_name)]
    for k in range(1, len(times)):
        fmu.set(**{input_name: inputs[k - 1]})
        assert fmu.raw_step_at(times[k - 1] / 1000, (times[k] - times[k - 1]) / 1000) == 0
        outputs.append(fmu.get(output_name))
    fmu.fmu.terminate()
    folder = tmp_path / "jittered"
    folder.mkdir()
    seconds = [repr(t / 1000) for t in times.tolist()]
    (folder / f"{name}_in.csv").write_text(
        f"time,{input_name}\n" + "".join(f"{t},{u!r}\n" for t, u in zip(seconds, inputs, strict=False))
    )
    (folder / f"{name}_start.csv").write_text("".join(f"{k},{v!r}\n" for k, v in start.items()))

    def compare(opt, outputs):
        (folder / f"{name}_ref.opt").write_text(opt)
        (folder / f"{name}_ref.csv").write_text(
            f"time,{output_name}\n" + "".join(f"{t},{y!r}\n" for t, y in zip(seconds, outputs, strict=True))
        )
        campaign = fmutrace.compare(str(fmu_file(name, version)), str(folder), run=RunOptions(jobs=1))
        return campaign, campaign.cases[0]

    campaign, case = compare("CycleLengths,recorded\n", outputs)
    assert campaign.passed, case.messages
    assert len(set(np.diff(times).tolist())) > 3  # (the steps were not all one length)
    campaign, case = compare("", outputs)
    assert not campaign.passed
    at = len(outputs) // 2
    perturbed = list(outputs)
    perturbed[at] += 0.125
    campaign, case = compare("RelTol,1e-6\nCycleLengths,recorded\n", perturbed)
    assert not campaign.passed
    assert any(f"differs first at t={seconds[at]}:" in m for m in case.messages), case.messages
    campaign, case = compare("CycleLengths,sometimes\n", outputs)
    assert str(case.status) == "invalid"
    assert (
        f"{name}_ref.opt, line 1, column 2: CycleLengths 'sometimes' is not one of nominal, recorded"
        in (case.messages[0])
    ), case.messages
