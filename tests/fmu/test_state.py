"""FMU states: rollback with get/set, and serialize / deserialize into a new
process, continue bit-identically; bad serialized bytes are refused."""

import json
import math
import struct
import sys
import zlib

from ctypes import byref, c_char_p, c_int, c_size_t, c_void_p

import pytest

from support.fmu_driver import MODELS, STATE_FUNCTIONS, TESTS, Instance, call_status, run_steps, state_api
from support.process import run as run_bounded

# inputs and step sizes of a run: ramps, a change, NaN, sub-cycling steps
STEPS = [
    (0.25, {"u": 10.0}),
    (0.25, {}),
    (0.5, {"u": -3.0}),
    (0.3, {}),
    (0.25, {"u": float("nan")}),
    (0.5, {"u": 4.0}),
    (0.1, {}),
    (0.75, {"rateUp": 0.5}),
    (0.25, {}),
    (1.0, {"u": 100.0}),
] * 3
START = {"rateUpPar": 3.0, "rateDownPar": 1.5, "cycleTime": 0.05, "durationPar": 2.0}


def started(version):
    fmu = Instance("RateLimiter", version)
    fmu.start(**START)
    return fmu


@pytest.mark.parametrize("version", [2, 3])
def test_rollback_repeats_the_run(version):
    fmu = started(version)
    api = state_api(fmu)
    run_steps(fmu, STEPS[:7])
    state, t = api["get"](), fmu.t
    first = run_steps(fmu, STEPS[7:])
    fmu.restore(state, t)
    assert run_steps(fmu, STEPS[7:]) == first
    api["free"](state)
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_state_taken_before_the_outputs_were_read_holds_them(version):
    """Outputs are published when read: a state taken after a step whose
    outputs nobody read restores that step's outputs. 2 per s in cycles of
    0.25 s: 0.5 per cycle."""
    fmu = Instance("RateLimiter", version)
    try:
        api = state_api(fmu)
        fmu.start(rateUpPar=2.0, cycleTime=0.25)
        fmu.set(u=10.0)
        fmu.step(0.5)
        state = api["get"]()
        fmu.step(0.5)
        assert (fmu.get("y"), fmu.get("runningTime")) == (2.0, 1.0)
        fmu.restore(state, 0.5)
        assert (fmu.get("y"), fmu.get("runningTime"), fmu.get("time")) == (1.0, 0.5, 0.5)
        api["free"](state)
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_restored_state_has_its_own_outputs(version):
    """After a rate changed, a restored state's outputs and rate are still
    its own: remainingTime 9 s at 1 per s, not at the 4 per s set since,
    whether the outputs were read before the restore or not, and the next
    step ramps at 1 per s again."""
    fmu = Instance("RateLimiter", version)
    try:
        api = state_api(fmu)
        fmu.start(rateUpPar=1.0)
        fmu.set(u=10.0)
        fmu.step(1.0)
        assert (fmu.get("y"), fmu.get("remainingTime")) == (1.0, 9.0)
        state = api["get"]()
        fmu.set(rateUp=4.0)
        fmu.step(1.0)
        assert (fmu.get("y"), fmu.get("remainingTime")) == (5.0, 1.25)
        fmu.step(1.0)  # y = 9, not read
        fmu.restore(state, 1.0)
        assert (fmu.get("y"), fmu.get("remainingTime")) == (1.0, 9.0)
        assert math.isnan(fmu.get("rateUp"))  # the state's input: not connected
        fmu.step(1.0)
        assert (fmu.get("y"), fmu.get("remainingTime")) == (2.0, 8.0)
        api["free"](state)
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("mode", ["Instantiated", "Initialization Mode", "Step Mode"])
def test_a_restored_state_serializes_to_the_same_bytes(version, mode):
    """Get, set and get again: the two states serialize alike, in each mode
    a state can be taken in."""
    fmu = Instance("RateLimiter", version)
    try:
        api = state_api(fmu)
        if mode != "Instantiated":
            fmu.enter_initialization()
            fmu.set(u=2.0)
        if mode == "Step Mode":
            fmu.fmu.exitInitializationMode()
            fmu.set(u=5.0)
            fmu.step(0.5)
        first = api["get"]()
        api["set"](first)
        second = api["get"]()
        assert bytes(api["serialize"](second)) == bytes(api["serialize"](first))
        api["free"](first)
        api["free"](second)
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_leaving_initialization_mode_counts_cycles_from_zero(version):
    """A state of Initialization Mode with a cycle count (resealed: no run
    makes one) starts afresh: leaving Initialization Mode counts cycles from
    0. 2 per s in cycles of 0.25 s: two cycles of 0.5 in 0.5 s."""
    fmu = Instance("RateLimiter", version)
    try:
        api = state_api(fmu)
        fmu.enter_initialization()
        fmu.set(rateUpPar=2.0, cycleTime=0.25)
        state = api["get"]()
        data = bytes(api["serialize"](state))
        counted = api["deserialize"](value_at(data, values_end(data) + BLOCK + 16, struct.pack("<Q", 5)))
        api["set"](counted)
        fmu.fmu.exitInitializationMode()
        fmu.set(u=10.0)
        fmu.step(0.5)
        assert (fmu.get("y"), fmu.get("runningTime")) == (1.0, 0.5)
        api["free"](counted)
        api["free"](state)
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_serialized_state_continues_bit_identically_in_a_new_process(version, tmp_path):
    fmu = started(version)
    api = state_api(fmu)
    run_steps(fmu, STEPS[:12])
    state = api["get"]()
    (tmp_path / "state.bin").write_bytes(bytes(api["serialize"](state)))
    uninterrupted = run_steps(fmu, STEPS[12:])
    fmu.free()
    out = run_bounded(
        [
            sys.executable,
            "-m",
            "support.continue_from_state",
            str(version),
            str(tmp_path / "state.bin"),
            json.dumps(STEPS[12:]),
        ],
        check=True,
        cwd=TESTS,
        timeout=120,
        what="the run continued in a new process",
    )
    assert json.loads(out.stdout.strip().splitlines()[-1]) == uninterrupted


def reseal(data):
    """Recompute the CRC-32 so that only the header field under test is wrong."""
    return data[:-4] + struct.pack("<I", zlib.crc32(data[:-4]))


def value_at(d, offset, packed):
    return reseal(d[:offset] + packed + d[offset + len(packed) :])


def values_end(d):
    """Offset after the values: header 16, count 4, 8 bytes per value."""
    return 20 + 8 * struct.unpack_from("<I", d, 16)[0]


BLOCK = 8 + 8 + 8 + 1 + 8 + 8 + 8  # y, uPrevious, yPrevious, decided, runCycles, runPeriod, runBase
MODE_OFFSET = -12  # mode, reported status, CRC at the end
EVENT_TIME_OFFSET = MODE_OFFSET - 8  # the last event's time, just before the mode
ERROR_MODE = 16  # FMI 2's Error state, as the core numbers its modes

BAD_BYTES = {
    "truncated": lambda d: d[: len(d) // 2],
    "empty": lambda d: b"",
    "padded": lambda d: d + b"\0",
    "corrupted": lambda d: d[:40] + bytes([d[40] ^ 0x10]) + d[41:],
    "foreign magic": lambda d: b"XXXX" + d[4:],
    "future version": lambda d: reseal(d[:4] + struct.pack("<I", 99) + d[8:]),
    "another model": lambda d: reseal(d[:8] + struct.pack("<I", 0x12345678) + d[12:]),
    "invalid mode": lambda d: value_at(d, len(d) + MODE_OFFSET, struct.pack("<I", 12345)),
    # checksums right, values impossible (found by the fuzzer: a NaN enumeration)
    "enumeration NaN": lambda d: value_at(d, 20 + 8 * 12, struct.pack("<d", float("nan"))),  # zeroRate
    "boolean 2": lambda d: value_at(d, 20 + 8 * 4, struct.pack("<d", 2.0)),  # bypass
    "start time infinite": lambda d: value_at(d, values_end(d) + BLOCK, struct.pack("<d", float("inf"))),
    "cycle count 2^60": lambda d: value_at(d, values_end(d) + BLOCK + 16, struct.pack("<Q", 1 << 60)),
    "running time period NaN": lambda d: value_at(d, values_end(d) + 33, struct.pack("<d", float("nan"))),
    "running time base negative": lambda d: value_at(d, values_end(d) + 41, struct.pack("<d", -1.0)),
    "deciding rule unknown": lambda d: value_at(d, values_end(d) + 24, bytes([7])),
    # an Integer (status, vr 21) one past the int32 range; at the range's end it is fine (below)
    "integer 2^31": lambda d: value_at(d, 20 + 8 * 21, struct.pack("<d", 2147483648.0)),
    "integer not whole": lambda d: value_at(d, 20 + 8 * 21, struct.pack("<d", 0.5)),
    # short or foreign bytes with a valid CRC: refused by size and magic, not by the CRC
    "truncated, resealed": lambda d: reseal(d[:-12]),
    "foreign magic, resealed": lambda d: reseal(b"XXXX" + d[4:]),
    "foreign magic below, resealed": lambda d: reseal(b"ABCD" + d[4:]),  # sorts before the magic
    # counts are exact doubles up to 2^53 (accepted there, below), not one past
    "cycle count 2^53 + 1": lambda d: value_at(d, values_end(d) + BLOCK + 16, struct.pack("<Q", (1 << 53) + 1)),
    "running cycle count 2^53 + 1": lambda d: value_at(d, values_end(d) + 25, struct.pack("<Q", (1 << 53) + 1)),
    "enumeration below its range": lambda d: value_at(d, 20 + 8 * 12, struct.pack("<d", 0.0)),  # zeroRate
    "enumeration above its range": lambda d: value_at(d, 20 + 8 * 12, struct.pack("<d", 3.0)),
    # the header's own edges: 16 bytes (magic, version, model, payload size), read, then refused by size;
    # fewer, or the magic alone, refused before any field past the bytes given is read
    "header alone": lambda d: d[:16],
    "header one byte short": lambda d: d[:15],
    "magic alone": lambda d: d[:4],
    "payload size wrong, resealed": lambda d: value_at(
        d, 12, struct.pack("<I", struct.unpack_from("<I", d, 12)[0] + 8)
    ),
    "boolean -1": lambda d: value_at(d, 20 + 8 * 4, struct.pack("<d", -1.0)),  # bypass
    "boolean one half": lambda d: value_at(d, 20 + 8 * 4, struct.pack("<d", 0.5)),
    "integer -2^31 - 1": lambda d: value_at(d, 20 + 8 * 21, struct.pack("<d", -2147483649.0)),
    "time infinite": lambda d: value_at(d, values_end(d) + BLOCK + 8, struct.pack("<d", float("inf"))),
    "running time period infinite": lambda d: value_at(d, values_end(d) + 33, struct.pack("<d", float("inf"))),
    "running time base infinite": lambda d: value_at(d, values_end(d) + 41, struct.pack("<d", float("inf"))),
    # the variable count (after the header) disagrees with the model; size and CRC right
    "variable count one more": lambda d: value_at(d, 16, struct.pack("<I", struct.unpack_from("<I", d, 16)[0] + 1)),
    "variable count one fewer": lambda d: value_at(d, 16, struct.pack("<I", struct.unpack_from("<I", d, 16)[0] - 1)),
    # modes: none, two at once, a negative int
    "mode 0": lambda d: value_at(d, len(d) + MODE_OFFSET, struct.pack("<I", 0)),
    "mode 3": lambda d: value_at(d, len(d) + MODE_OFFSET, struct.pack("<I", 3)),
    "mode -1": lambda d: value_at(d, len(d) + MODE_OFFSET, struct.pack("<I", 0xFFFFFFFF)),
    # running time fields just below 0 (above -1)
    "running time period -0.5": lambda d: value_at(d, values_end(d) + 33, struct.pack("<d", -0.5)),
    "running time base -0.5": lambda d: value_at(d, values_end(d) + 41, struct.pack("<d", -0.5)),
    # each header field and the checksum wrong by one either way: every one is compared whole, for equality
    "magic's last byte wrong, resealed": lambda d: reseal(d[:3] + b"X" + d[4:]),
    "older version": lambda d: reseal(d[:4] + struct.pack("<I", struct.unpack_from("<I", d, 4)[0] - 1) + d[8:]),
    "model one below": lambda d: value_at(d, 8, struct.pack("<I", (struct.unpack_from("<I", d, 8)[0] - 1) % 2**32)),
    "model one above": lambda d: value_at(d, 8, struct.pack("<I", (struct.unpack_from("<I", d, 8)[0] + 1) % 2**32)),
    "payload size short, resealed": lambda d: value_at(
        d, 12, struct.pack("<I", struct.unpack_from("<I", d, 12)[0] - 8)
    ),
    "checksum one more": lambda d: d[:-4] + struct.pack("<I", (zlib.crc32(d[:-4]) + 1) % 2**32),
    "checksum one less": lambda d: d[:-4] + struct.pack("<I", (zlib.crc32(d[:-4]) - 1) % 2**32),
}


# each refused for its own reason
REASONS = {
    "truncated": "bytes; expected",
    "empty": "no header",
    "padded": "bytes; expected",
    "corrupted": "checksum",
    "foreign magic": "no header",
    "future version": "format version 99",
    "another model": "another model",
    "invalid mode": "invalid mode",
    "enumeration NaN": "impossible value nan for zeroRate",
    "boolean 2": "impossible value 2 for bypass",
    "start time infinite": "impossible time",
    "cycle count 2^60": "impossible time or cycle count",
    "running time period NaN": "impossible time",
    "running time base negative": "impossible time",
    "deciding rule unknown": "invalid rule 7",
    "integer 2^31": "impossible value 2.14748e+09 for status",
    "integer not whole": "impossible value 0.5 for status",
    "truncated, resealed": "bytes; expected",
    "foreign magic, resealed": "no header",
    "foreign magic below, resealed": "no header",
    "cycle count 2^53 + 1": "impossible time or cycle count",
    "running cycle count 2^53 + 1": "impossible time or cycle count",
    "enumeration below its range": "impossible value 0 for zeroRate",
    "enumeration above its range": "impossible value 3 for zeroRate",
    "mode 0": "invalid mode 0",
    "mode 3": "invalid mode 3",
    "mode -1": "invalid mode -1",
    "running time period -0.5": "impossible time",
    "running time base -0.5": "impossible time",
    "variable count one more": "wrong number of variables",
    "variable count one fewer": "wrong number of variables",
    "magic's last byte wrong, resealed": "no header",
    "older version": "format version 2",
    "model one below": "another model",
    "model one above": "another model",
    "payload size short, resealed": "bytes; expected",
    "checksum one more": "checksum",
    "checksum one less": "checksum",
    "header alone": "16 bytes; expected",
    "header one byte short": "(15 bytes, no header)",
    "magic alone": "(4 bytes, no header)",
    "payload size wrong, resealed": "bytes; expected",
    "boolean -1": "impossible value -1 for bypass",
    "boolean one half": "impossible value 0.5 for bypass",
    "integer -2^31 - 1": "impossible value -2.14748e+09 for status",
    "time infinite": "impossible time",
    "running time period infinite": "impossible time",
    "running time base infinite": "impossible time",
}


@pytest.mark.parametrize("version", [2, 3])
def test_a_state_is_got_or_deserialized_into_an_existing_one_in_place(version):
    """Given a state it returned before, getting or deserializing overwrites
    that state and returns the same pointer (FMI 2.0 section 2.1.8, FMI 3.0
    section 2.2.6.4: "typically reuses the memory of this FMUstate")."""
    fmu = started(version)
    api = state_api(fmu)
    c, dll = fmu.fmu.component, fmu.fmu.dll
    run_steps(fmu, STEPS[:4])
    got, deserialized = api["get"](), api["get"]()
    run_steps(fmu, STEPS[4:8])
    t = fmu.t
    get, deserialize = (getattr(dll, STATE_FUNCTIONS[version][name]) for name in ("get", "deserialize"))
    get.argtypes, get.restype = [c_void_p, c_void_p], c_int
    deserialize.argtypes, deserialize.restype = [c_void_p, c_char_p, c_size_t, c_void_p], c_int
    handle = c_void_p(got.value)
    assert get(c, byref(handle)) == 0 and handle.value == got.value
    data = bytes(api["serialize"](got))  # at t now
    handle = c_void_p(deserialized.value)
    assert deserialize(c, data, len(data), byref(handle)) == 0 and handle.value == deserialized.value
    expected = run_steps(fmu, STEPS[8:12])
    for state in (got, deserialized):
        fmu.restore(state, t)  # a state still at the earlier time would refuse the step at t
        assert run_steps(fmu, STEPS[8:12]) == expected
        api["free"](state)
    assert not fmu.errors()
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_the_reported_status_travels_with_the_state(version):
    """A status word is logged once, when it changes (rules.md, Status words). A
    state carries what was reported: an instance set to a serialized state
    whose error status was already reported steps with fmi*OK and logs
    nothing; from a state taken before, the same error is reported as the
    run leaves Initialization Mode."""
    fmu = Instance("RateLimiter", version)
    api = state_api(fmu)
    fmu.enter_initialization()
    before = bytes(api["serialize"](api["get"]()))  # nothing reported yet
    fmu.set(rateUpPar=-1.0)
    fmu.fmu.exitInitializationMode()  # reports 16#8200 (a warning)
    assert fmu.raw_step(0.5) == 0
    after = bytes(api["serialize"](api["get"]()))
    fmu.free()
    for data, t, logged in ((after, 0.5, []), (before, 0.0, ["status 16#8200"])):
        fresh = Instance("RateLimiter", version, name="fresh")
        fresh_api = state_api(fresh)
        fresh.restore(fresh_api["deserialize"](data), t)
        if t == 0.0:
            fresh.set(rateUpPar=-1.0)
            fresh.fmu.exitInitializationMode()
        assert fresh.raw_step(0.5) == 0
        assert [m[2][:14] for m in fresh.messages] == logged
        fresh.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_state_taken_after_an_error_carries_the_error_mode_fmi2_only(version):
    """FMI 2 may get, serialize and set a state in its Error state: the
    instance set to it is in Error (a step is refused, the last good values
    are read), and reset recovers it. FMI 3 has no Error state (an error
    leads to Terminated), so bytes claiming one are refused."""
    fmu = started(version)
    api = state_api(fmu)
    fmu.set(u=10.0)
    fmu.step(0.5)  # 3 per s: y = 1.5
    assert call_status(fmu.fmu.doStep, fmu.t + 1.0, 0.5) == 3
    data = bytes(api["serialize"](api["get"]()))
    error_mode = struct.unpack_from("<I", data, len(data) + MODE_OFFSET)[0]
    assert error_mode == (ERROR_MODE if version == 2 else 8)
    fresh = Instance("RateLimiter", version, name="fresh")
    try:
        fresh_api = state_api(fresh)
        if version == 3:
            claimed = value_at(data, len(data) + MODE_OFFSET, struct.pack("<I", ERROR_MODE))
            assert call_status(fresh_api["deserialize"], claimed) == 3
            assert "invalid mode 16" in fresh.errors()[-1][2]
            fresh.fmu.reset()
        fresh.restore(fresh_api["deserialize"](data), 0.5)
        assert fresh.get("y") == 1.5
        assert call_status(fresh.step, 0.5) == 3
        assert f"not allowed in {'Error' if version == 2 else 'Terminated'}" in fresh.errors()[-1][2]
        fresh.fmu.reset()
        fresh.start(rateUpPar=2.0)
        fresh.set(u=1.0)
        fresh.step(0.25)
        assert fresh.get("y") == 0.5
    finally:
        fresh.release()
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("damage", sorted(BAD_BYTES))
def test_bad_serialized_state_is_refused_and_the_instance_recovers(version, damage):
    fmu = started(version)
    api = state_api(fmu)
    run_steps(fmu, STEPS[:5])
    good = api["get"]()
    data = bytes(api["serialize"](good))
    t = fmu.t
    expected = run_steps(fmu, STEPS[5:9])
    fmu.restore(good, t)
    assert call_status(api["deserialize"], BAD_BYTES[damage](data)) == 3
    errors = fmu.errors()
    assert len(errors) == 1 and errors[0][2].startswith(f"{STATE_FUNCTIONS[version]['deserialize']}: "), errors
    assert REASONS[damage] in errors[0][2], errors
    # refused until recovery, as the standard says; a good state recovers it
    assert call_status(fmu.step, 0.25) == 3
    fmu.restore(good, t)
    assert run_steps(fmu, STEPS[5:9]) == expected
    api["free"](good)
    fmu.free()


# values at the ends of their variable's range: accepted (one past them is refused, above)
RANGE_ENDS = {
    "status": (21, (2147483647, -2147483648)),  # an Integer: the int32 range
    "zeroRate": (12, (1, 2)),
}  # an Enumeration: hold, no limit


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("name", sorted(RANGE_ENDS))
def test_values_at_the_ends_of_their_range_in_a_state_are_accepted(version, name):
    fmu = started(version)
    api = state_api(fmu)
    data = bytes(api["serialize"](api["get"]()))
    vr, values = RANGE_ENDS[name]
    for value in values:
        state = api["deserialize"](value_at(data, 20 + 8 * vr, struct.pack("<d", float(value))))
        api["set"](state)
        assert fmu.get(name) == value
        api["free"](state)
    assert not fmu.errors()
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_counts_and_running_time_at_the_ends_of_their_range_in_a_state_are_accepted(version):
    """Cycle counts up to 2^53 (exact in a double); the running time's period
    and base from 0 to the largest finite double."""
    fmu = started(version)
    api = state_api(fmu)
    data = bytes(api["serialize"](api["get"]()))
    ends = [
        (values_end(data) + BLOCK + 16, struct.pack("<Q", 1 << 53)),  # cycles
        (values_end(data) + 25, struct.pack("<Q", 1 << 53)),
    ]  # running cycles
    ends += [
        (values_end(data) + offset, struct.pack("<d", value))  # running period, base
        for offset in (33, 41)
        for value in (0.0, sys.float_info.max)
    ]
    for offset, packed in ends:
        state = api["deserialize"](value_at(data, offset, packed))
        api["free"](state)
    assert not fmu.errors()
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_state_taken_in_terminated_is_accepted_and_restores_terminated(version):
    fmu = started(version)
    api = state_api(fmu)
    fmu.set(u=1.0)
    fmu.step(0.5)
    fmu.fmu.terminate()
    data = bytes(api["serialize"](api["get"]()))
    fresh = Instance("RateLimiter", version, name="fresh")
    try:
        fresh.restore(state_api(fresh)["deserialize"](data), 0.5)
        assert fresh.get("y") == fmu.get("y") and fresh.get("time") == 0.5
        assert call_status(fresh.step, 0.5) == 3
        assert fresh.errors()[-1][2].endswith("not allowed in Terminated")
    finally:
        fresh.release()
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_state_in_event_mode_at_a_time_other_than_its_events_is_refused(version):
    """Event Mode is an instant: entering it, SetTime in it and the end of
    initialisation make the time the event's, and SetTime's test for a new
    instant relies on it. Bytes that claim Event Mode at a later or an
    earlier time are refused; Continuous-Time Mode after the event is what
    a run makes, and is accepted."""
    fmu = Instance("RateLimiter", version, model_exchange=True)
    api = state_api(fmu)
    update = fmu.fmu.newDiscreteStates if version == 2 else fmu.fmu.updateDiscreteStates
    fmu.start(cycleTime=0.25)
    update()
    fmu.fmu.enterContinuousTimeMode()
    fmu.fmu.setTime(0.25)
    fmu.fmu.enterEventMode()
    update()
    good = api["get"]()
    in_event = bytes(api["serialize"](good))
    time_at = values_end(in_event) + BLOCK + 8
    assert struct.unpack_from("<d", in_event, time_at)[0] == 0.25
    assert struct.unpack_from("<d", in_event, len(in_event) + EVENT_TIME_OFFSET)[0] == 0.25
    fmu.fmu.enterContinuousTimeMode()
    fmu.fmu.setTime(0.4)
    in_continuous = bytes(api["serialize"](api["get"]()))
    name = STATE_FUNCTIONS[version]["deserialize"]
    for time in (0.4, 0.1):
        assert call_status(api["deserialize"], value_at(in_event, time_at, struct.pack("<d", time))) == 3
        assert fmu.errors()[-1][2] == (
            f"{name}: serialized state is in Event Mode at time {time:.17g}, not at its event's 0.25"
        )
        fmu.restore(good, 0.25)
    assert len(fmu.errors()) == 2
    for data in (in_event, in_continuous):
        state = api["deserialize"](data)
        api["set"](state)
        api["free"](state)
    assert fmu.get("time") == 0.4 and len(fmu.errors()) == 2
    api["free"](good)
    fmu.free()


def fnv1a(text):
    h = 2166136261
    for byte in text.encode():
        h = ((h ^ byte) * 16777619) % 2**32
    return h


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_serialized_state_layout(version, model):
    """docs/fmi.md: magic "RLFS", format version 3, the FNV-1a hash of the
    instantiation token, the payload size, the values; a CRC-32 of all before it at the end."""
    fmu = Instance(model, version)
    fmu.start()
    api = state_api(fmu)
    data = bytes(api["serialize"](api["get"]()))
    token = fmu.md.guid if version == 2 else fmu.md.instantiationToken
    magic, format_version, model_hash, payload, count = struct.unpack_from("<4sIIII", data)
    assert (magic, format_version, model_hash) == (b"RLFS", 3, fnv1a(token))
    assert payload == len(data) - 16 - 4 and count == len(fmu.md.modelVariables)
    assert struct.unpack("<I", data[-4:])[0] == zlib.crc32(data[:-4])
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_null_serialized_state_is_refused(version):
    fmu = started(version)
    dll, c = fmu.fmu.dll, fmu.fmu.component
    name = "fmi2DeSerializeFMUstate" if version == 2 else "fmi3DeserializeFMUState"
    function = getattr(dll, name)
    function.argtypes, function.restype = [c_void_p, c_void_p, c_size_t, c_void_p], c_int
    state = c_void_p()
    assert function(c, None, 100, byref(state)) == 3
    assert [m[2] for m in fmu.errors()] == [f"{name}: the serialized state is NULL"]
    assert not state
    fmu.free()
