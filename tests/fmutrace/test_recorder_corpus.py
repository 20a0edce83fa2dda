"""fmutrace on recordings that others' recorders wrote
(tests/recordings/corpus; sources, commits and licences in its README):
each file is the one the README names, and fmutrace reads it as an
independent reader does (the Scope View exports as their documented
structure reads them, support/scope_view.py; the MDF files as asammdf
does), channel by channel: names, sample counts, time stamps, values;
or refuses it for the one correct reason."""

import json
import gzip
import hashlib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from fmutrace import TraceError
from fmutrace._recorded import recorded_case
from fmutrace.recordings._options import RecordingOptions
from fmutrace.recordings import normalise, read_file
from support import scope_view
from support.cli import fmutrace_in_process
from support.fmu_driver import BUILD_DIR

CORPUS = Path(__file__).parents[1] / "recordings" / "corpus"


def _listed():
    """{file: git blob} of the README's table."""
    rows = [line.split("|") for line in (CORPUS / "README.md").read_text().splitlines() if line.startswith("| `")]
    return {row[1].strip().strip("`"): row[5].strip() for row in rows}


def _bytes(name):
    data = (CORPUS / name).read_bytes()
    return gzip.decompress(data) if name.endswith(".gz") else data


def _unpacked(name, tmp_path):
    """The file as its recorder wrote it (a .gz unpacked into tmp_path)."""
    if not name.endswith(".gz"):
        return CORPUS / name
    path = tmp_path / Path(name[:-3]).name
    path.write_bytes(_bytes(name))
    return path


def test_each_file_of_the_corpus_is_the_one_its_readme_names():
    listed = _listed()
    present = {
        str(p.relative_to(CORPUS)) for p in CORPUS.rglob("*") if p.is_file() and p.name not in ("README.md", "LICENSE")
    }
    assert present == set(listed)
    for name, blob in listed.items():
        data = _bytes(name)
        assert hashlib.sha1(b"blob %d\0" % len(data) + data).hexdigest() == blob, name
    for folder in {Path(name).parent for name in listed}:
        assert (CORPUS / folder / "LICENSE").is_file(), folder


# the export's settings, as its name says: (separator, decimal mark)
SCOPE_VIEW = {
    "tc3_scope_3_4_3145_3-default.csv.gz": ("\t", ","),
    "tc3_scope_3_4_3145_3_noOS.csv.gz": (";", ","),
    "tc3_scope_3_4_3145_3-DecimalMark_,.csv.gz": ("\t", ","),
    "tc3_scope_3_4_3145_3-ContainEOF_true.csv.gz": ("\t", "."),
    "tc3_scope_3_4_3145_3-ExcludeDoubleTimestamp_true-SortChannels_false.csv.gz": ("\t", "."),
    "tc3_scope_3_4_3145_3-ExcludeDoubleTimestamp_false-SortChannels_true.csv.gz": ("\t", "."),
    "tc3_scope_3_4_3145_3-Seperator_2.csv.gz": (":", "."),
    "tc3_scope_3_4_3145_3-Seperator_4.csv.gz": (",", "."),
}


@pytest.mark.parametrize("name", sorted(SCOPE_VIEW))
def test_scope_view_exports_read_as_their_documented_structure_reads_them(name, tmp_path):
    path = _unpacked(f"pytcs/{name}", tmp_path)
    recording = read_file(path)
    expected = scope_view.read(path, *SCOPE_VIEW[name])
    assert recording.format == "Beckhoff TwinCAT Scope View CSV export" and recording.time_unit == "ms"
    assert [c.name for c in recording.channels] == list(expected)
    for channel in recording.channels:
        oracle = expected[channel.name]
        assert channel.symbol == oracle.symbol, channel.name
        assert channel.stamps.tolist() == oracle.times_ms.tolist(), channel.name
        assert channel.values.tolist() == oracle.values.tolist(), channel.name
        if oracle.sample_time_ms is not None:
            assert channel.sample_time == oracle.sample_time_ms * 1e-3, channel.name
    declared = [e.sample_time_ms for e in expected.values() if e.sample_time_ms is not None]
    if declared:  # (a ',' export splits its sample times' decimal commas: the oracle leaves them)
        assert normalise(recording).step_size == min(declared) * 1e-3


def test_a_scope_view_export_separated_by_blanks_with_blanks_in_its_names_is_refused_for_that(tmp_path):
    """Its channels 'test space' and 'test space (1)' and its property 'Unit ScaleFactor' hold blanks:
    no reader can tell its cells apart (pytcs does not read it either)."""
    path = _unpacked("pytcs/tc3_scope_3_4_3145_3-Seperator_1.csv.gz", tmp_path)
    with pytest.raises(TraceError, match=r"\(a name with blanks, blanks separating\?\): export with another separator"):
        read_file(path)


def _asammdf_channels(path):
    """{name: (timestamps, samples)} of every channel asammdf reads, masters left out."""
    from asammdf import MDF

    mdf = MDF(str(path))
    try:
        found = {}
        for g, group in enumerate(mdf.groups):
            for i in range(len(group.channels)):
                if i != mdf.masters_db.get(g):
                    signal = mdf.get(group=g, index=i)
                    found[signal.name] = (np.asarray(signal.timestamps), np.asarray(signal.samples))
        return found
    finally:
        mdf.close()


@pytest.mark.parametrize("name", ["17BD1DB7_00000170.MF4", "FCBF0606_00000001-60B621D9.MF4"])
def test_can_logger_files_not_finalized_read_as_asammdf_reads_them(name):
    """CANedge files as the logger leaves them ('UnFinMF'): its CAN frames' numeric fields are channels,
    the frame records and the data bytes (arrays) are listed as ignored."""
    path = CORPUS / "canedge" / name
    recording = read_file(path)
    assert recording.format == "ASAM MDF4" and recording.notes[0].startswith("not finalized by its writer")
    expected = _asammdf_channels(path)
    numeric = {n: v for n, v in expected.items() if v[1].dtype.kind in "biuf" and v[1].ndim == 1}
    assert [c.name for c in recording.channels] == list(numeric)
    assert len(recording.channel("CAN_DataFrame.ID").values) > 1000  # (its LIN channels hold no frame)
    for channel in recording.channels:
        stamps, values = numeric[channel.name]
        assert len(channel.values) == len(values)
        assert channel.stamps.tolist() == stamps.tolist() and channel.values.tolist() == values.tolist()
    for other in set(expected) - set(numeric):
        assert any(f"channel {other!r}" in note and "ignored" in note for note in recording.notes), other


PASS_THROUGH = BUILD_DIR / "benchmarks" / "fmi3" / "PassThrough.fmu"  # y is u, each cycle


def test_a_scope_view_export_through_the_command_on_the_channels_mapped(tmp_path):
    """The default export: var_REAL32 sampled every 1 ms, func_OS (unmapped) every 0.2 ms. Mapped to
    PassThrough's u and y it passes with the 1 ms step of the mapped channel; its symbol, which nine
    channels share, is refused, each of them named, and one of them is chosen by its column."""
    path = _unpacked("pytcs/tc3_scope_3_4_3145_3-default.csv.gz", tmp_path)

    def compare(*maps):
        return fmutrace_in_process("compare", PASS_THROUGH, path, *[a for m in maps for a in ("--map", m)])

    done = compare("u=var_REAL32", "y=var_REAL32")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1000 samples" in done.stdout and "step 0.001 s (the recording's sample time)" in done.stdout
    done = compare("u=var_REAL32", "y=MAIN.var_REAL")
    assert done.returncode == 2, done.stdout + done.stderr
    assert "--map y=MAIN.var_REAL: 9 channels of" in done.stderr
    assert "'func_scaled' (symbol 'MAIN.var_REAL', column 26)" in done.stderr
    assert done.stderr.rstrip().endswith(
        "map one by its name, e.g. --map y=var_REAL32, or by its column, e.g. --map y=#20"
    )
    done = compare("u=#20", "y=var_REAL32")  # var_REAL32 by its column
    assert done.returncode == 0, done.stdout + done.stderr
    assert "u <- var_REAL32" in done.stdout


def test_a_map_to_a_can_logger_channel_without_samples_says_so():
    """The CANedge file's LIN channels hold no frame: mapped, they are named as holding none."""
    output = SimpleNamespace(causality="output", variability="continuous")
    fmu = SimpleNamespace(variables={"y": output}, label="M", model="M", default_step=None, start_value=lambda n, v: v)
    path = str(CORPUS / "canedge" / "17BD1DB7_00000170.MF4")
    with pytest.raises(TraceError, match=r"no samples: the channels compared or driven \('LIN_Frame.ID'\) hold none"):
        recorded_case(path, fmu, "can", RecordingOptions(maps={"y": "LIN_Frame.ID"}))


def _decoded_compared(tmp_path, name, dbc, fmu, **maps):
    """(each mapped signal's stamps, the finished command, its case in results.json) of `fmutrace compare`
    on the CANedge log `name` decoded with `dbc` (asammdf), its signals mapped to the FMU's variables."""
    from asammdf import MDF

    raw = MDF(str(_unpacked(f"canedge/{name}", tmp_path)))
    decoded = raw.extract_bus_logging({"CAN": [(str(CORPUS / "canedge" / dbc), 0)]})
    path = tmp_path / "decoded.mf4"
    decoded.save(str(path), overwrite=True)
    stamps = [np.asarray(decoded.get(signal).timestamps, dtype=np.float64) for signal in dict.fromkeys(maps.values())]
    raw.close()
    decoded.close()
    report = tmp_path / "report"
    command = ["compare", fmu, path, "--report", report]
    for variable, signal in maps.items():
        command += ["--map", f"{variable}={signal}"]
    done = fmutrace_in_process(*command)
    cases = json.loads((report / "results.json").read_text())["cases"] if (report / "results.json").exists() else [{}]
    return stamps, done, cases[0]


def test_decoded_can_signals_take_the_step_of_the_channels_mapped(tmp_path):
    """FCBF0606 decoded with its DBC (asammdf, canmatrix): EngineSpeed every 0.1 s and
    WheelBasedVehicleSpeed about every 1 s, each message with its own stamps. The speed mapped alone
    (PassThrough's u and y) takes a 1 s step, not the 0.1 s of the unmapped engine speed. The sender's
    100 ms task slips now and then (an interval of 1.1 s), so the stamps sit on no exact grid: fmutrace
    lays them on the grid of cycles they fit, each on its own cycle, says how far they are from it
    (the jitter), and names those more than a tenth of a cycle off; this test counts them on the grid
    results.json reports, numbering each stamp on its nearest cycle as the grid's definition says."""
    [stamps], done, case = _decoded_compared(
        tmp_path, "FCBF0606_00000001-60B621D9.MF4", "CSS-Electronics-SAE-J1939-DEMO.dbc", PASS_THROUGH,
        u="WheelBasedVehicleSpeed", y="WheelBasedVehicleSpeed",
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"{len(stamps)} samples" in done.stdout and "step 1 s (the finest interval" in done.stdout
    clock = case["clock"]
    cycles = (stamps - stamps[0] - clock["phase_s"]) / clock["cycle_s"]
    numbers = np.rint(cycles)
    assert (np.diff(numbers) > 0).all()  # each stamp on a cycle of its own
    distance = np.abs(cycles - numbers)
    assert clock["largest_percent"] == pytest.approx(100 * distance.max(), abs=1e-3) and distance.max() < 0.5
    off = int((distance > 0.1).sum())
    assert done.stdout.count(f"WheelBasedVehicleSpeed: {off} of its {len(stamps)} time stamps are more") == 1
    assert f"jitter up to {100 * distance.max():.1f} % of a cycle" in done.stdout
    assert "ignored: EngineSpeed" in done.stdout


RATE_LIMITER = BUILD_DIR / "fmi3" / "RateLimiter.fmu"


def _cycles_by_intervals(stamps):
    """An independent numbering of a sender's messages: each interval rounded to whole cycles of the
    median interval (at least one: a message out of turn is on a cycle of its own), then the least-squares
    line through (cycle, stamp). (its period, each stamp's distance from its cycle, the cycles missed)"""
    intervals = np.diff(stamps)
    cycles = np.concatenate([[0], np.cumsum(np.maximum(np.rint(intervals / np.median(intervals)), 1))])
    period, phase = np.polyfit(cycles, stamps, 1)
    return period, (stamps - phase) / period - cycles, int((np.diff(cycles) - 1).sum())


@pytest.mark.parametrize(
    "name, out_of_turn",
    [
        ("3BA199E2_00000164_00000001-60FE3F04.MF4.gz", False),  # 510 samples, 20 messages missing
        ("3BA199E2_00000165_00000001-60FEB68B.MF4.gz", True),  # the first two messages 0.746 s apart
        ("2F6913DB_00001089_00000001-63BEF5CD.MF4.gz", True),  # not finalized; 1.451 s, then 0.509 s
    ],
)
def test_gps_messages_stamped_by_a_can_logger_compare_cycle_for_cycle(tmp_path, name, out_of_turn):
    """CANmod.gps logs decoded with their DBC (asammdf, canmatrix), mapped as a user did: u=Speed,
    y=Heading on RateLimiter. Each message comes about once a second, stamped by the logger's clock; some
    are missing, and as the module starts one comes more than half a cycle out of turn. The case gets a
    verdict (the FMU is no GPS: they differ), with the cycle, the jitter and the missing cycles that an
    independent numbering of each channel's intervals gives (the two channels' stamps are 1 ms apart, so
    fmutrace's one grid for both is within 0.1 % of a cycle of each channel's own line)."""
    stamps, done, case = _decoded_compared(tmp_path, name, "gnss.dbc", RATE_LIMITER, u="Speed", y="Heading")
    assert done.returncode == 1, done.stdout + done.stderr
    assert "FAIL" in done.stdout and "y differs first" in done.stdout
    clock = case["clock"]
    figures = [_cycles_by_intervals(s) for s in stamps]
    for period, _, missed in figures:
        assert clock["cycle_s"] == pytest.approx(period, rel=1e-5)
        assert clock["missing_cycles"] == missed
    largest = max(float(np.abs(distance).max()) for _, distance, _ in figures)
    assert clock["largest_percent"] == pytest.approx(100 * largest, abs=0.1)
    assert f"jitter up to {clock['largest_percent']:.1f} % of a cycle" in done.stdout
    put_apart = [m for m in case["messages"] if "more than half a cycle from their cycle" in m]
    assert (largest > 0.5) == out_of_turn and len(put_apart) == (2 if out_of_turn else 0), put_apart
    if out_of_turn:
        assert put_apart[0].startswith("Speed: 1 of its") and put_apart[1].startswith("Heading: 1 of its")
