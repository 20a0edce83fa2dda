"""Bad arguments the other tests do not reach: a NULL instance for every
exported function, nValues 0 and mismatched, duplicate value references,
stop time before start time. Each gets the right status, and the instance
stays usable where the standard allows."""
from ctypes import c_bool, c_double, c_int, c_size_t, c_uint, c_void_p

import pytest

from support.fmu_driver import Instance
from test_conformance import NOT_INSTANCE_CALLS, exported_functions


@pytest.mark.parametrize("version", [2, 3])
def test_null_instance_is_refused_by_every_function(version):
    fmu = Instance("RateLimiter", version)
    try:
        dll = fmu.fmu.dll
        for name, n in sorted(exported_functions(version).items()):
            if name in NOT_INSTANCE_CALLS or n == 0:
                continue
            function = getattr(dll, name)
            function.argtypes, function.restype = [c_void_p] * n, c_int
            assert function(*([None] * n)) == 3, name
        for name in (f"fmi{version}FreeInstance",):  # nothing to free: no crash
            function = getattr(dll, name)
            function.argtypes, function.restype = [c_void_p], None
            function(None)
    finally:
        fmu.free()


def test_fmi3_nvalues_must_match_the_scalars():
    fmu = Instance("RateLimiter", 3)
    try:
        fmu.start()
        c, dll = fmu.fmu.component, fmu.fmu.dll
        get = dll.fmi3GetFloat64
        get.argtypes, get.restype = [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t], c_int
        vr = (c_uint * 1)(fmu.vr("y"))
        values = (c_double * 2)()
        assert get(c, vr, 0, None, 0) == 0  # nothing asked, nothing given: fine
        assert get(c, vr, 1, values, 1) == 0
        assert get(c, vr, 1, values, 2) == 3
        assert "nValues" in fmu.errors()[-1][2]
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_zero_values_with_null_arrays_is_fine(version):
    fmu = Instance("RateLimiter", version)
    try:
        fmu.start()
        c, dll = fmu.fmu.component, fmu.fmu.dll
        for name in ("SetReal", "GetReal") if version == 2 else ("SetFloat64", "GetFloat64"):
            function = getattr(dll, f"fmi{version}{name}")
            n = 4 if version == 2 else 5
            function.argtypes, function.restype = [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t][:n], c_int
            assert function(*([c, None, 0, None, 0][:n])) == 0, name
        fmu.step(0.1)
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_duplicate_value_references_take_the_last_value(version):
    fmu = Instance("RateLimiter", version)
    try:
        fmu.start()
        vr = [fmu.vr("u"), fmu.vr("u")]
        setter = fmu.fmu.setReal if version == 2 else fmu.fmu.setFloat64
        getter = fmu.fmu.getReal if version == 2 else fmu.fmu.getFloat64
        setter(vr, [5.0, 0.25])
        fmu.step(1.0)
        assert list(getter([fmu.vr("y"), fmu.vr("y")])) == [0.25, 0.25]
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_stop_time_before_start_time_is_refused(version):
    fmu = Instance("RateLimiter", version)
    try:
        c, dll = fmu.fmu.component, fmu.fmu.dll
        if version == 2:
            setup = dll.fmi2SetupExperiment
            setup.argtypes, setup.restype = [c_void_p, c_int, c_double, c_double, c_int, c_double], c_int
            assert setup(c, 0, 0.0, 10.0, 1, 5.0) == 3
        else:
            enter = dll.fmi3EnterInitializationMode
            enter.argtypes, enter.restype = [c_void_p, c_bool, c_double, c_double, c_bool, c_double], c_int
            assert enter(c, False, 0.0, 10.0, True, 5.0) == 3
        assert "stopTime" in fmu.errors()[-1][2]
        fmu.fmu.reset()  # the standard's way on from an error
        fmu.start(start_time=10.0)
        fmu.step(0.5)
    finally:
        fmu.free()
