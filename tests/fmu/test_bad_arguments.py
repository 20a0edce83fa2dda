"""Bad arguments the other tests do not reach: a NULL instance for every
exported function, nValues 0 and mismatched, duplicate value references,
stop time before start time. Each gets the right status, and the instance
stays usable where the standard allows."""

import ctypes
from ctypes import byref, c_bool, c_char_p, c_double, c_int, c_size_t, c_uint, c_void_p

import pytest
from fmpy import calloc, free
from fmpy.fmi2 import (
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.fmi3 import fmi3LogMessageCallback

from support.fmu_driver import STATE_FUNCTIONS, Instance, call_status, state_api
from test_conformance import NOT_INSTANCE_CALLS, exported_functions, raw


@pytest.fixture(params=[2, 3])
def fmu(request):
    """A started RateLimiter instance of FMI 2 and of FMI 3, freed after the test."""
    instance = Instance("RateLimiter", request.param)
    try:
        instance.start()
        yield instance
    finally:
        instance.free()


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


@pytest.mark.parametrize("access", ["Get", "Set"])
def test_fmi3_nvalues_must_match_the_scalars(access):
    """Every variable is a scalar: nValues must equal nvr, more or fewer is
    an error saying both, with nothing read or written."""
    fmu = Instance("RateLimiter", 3)
    try:
        fmu.start()
        c, dll = fmu.fmu.component, fmu.fmu.dll
        name = f"fmi3{access}Float64"
        function = getattr(dll, name)
        function.argtypes, function.restype = [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t], c_int
        vr = (c_uint * 2)(fmu.vr("y" if access == "Get" else "u"), fmu.vr("y" if access == "Get" else "u"))
        values = (c_double * 2)(7.0, 7.0)
        assert function(c, vr, 0, None, 0) == 0  # nothing asked, nothing given: fine
        for nvr, n_values in ((1, 2), (1, 0), (2, 1), (2, 3), (0, 1)):
            assert function(c, vr, nvr, values, n_values) == 3, (nvr, n_values)
            assert fmu.errors()[-1][2] == f"{name}: nValues = {n_values}, but the {nvr} variables are scalars"
            fmu.fmu.reset()
            fmu.start()
        assert list(values) == [7.0, 7.0] and fmu.get("u") == 0.0
        assert function(c, vr, 1, values, 1) == 0
    finally:
        fmu.free()


def test_zero_values_with_null_arrays_is_fine(fmu):
    """nvr = 0 with every array NULL (FMI 3's valueSizes of Binary too): every getter and setter is OK."""
    version = fmu.version
    c = fmu.fmu.component
    for kind in ALL_ACCESSOR_TYPES[version]:
        for access in ("Get", "Set"):
            name = f"fmi{version}{access}{kind}"
            if version == 2:
                argtypes, args = [c_void_p, c_void_p, c_size_t, c_void_p], (None,)
            elif kind == "Binary":  # valueSizes and values
                argtypes, args = [c_void_p, c_void_p, c_size_t, c_void_p, c_void_p, c_size_t], (None, None, 0)
            else:
                argtypes, args = [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t], (None, 0)
            assert raw(fmu, name, argtypes, c, None, 0, *args) == 0, name
    assert fmu.messages == []
    fmu.step(0.1)


def test_duplicate_value_references_take_the_last_value(fmu):
    version = fmu.version
    vr = [fmu.vr("u"), fmu.vr("u")]
    setter = fmu.fmu.setReal if version == 2 else fmu.fmu.setFloat64
    getter = fmu.fmu.getReal if version == 2 else fmu.fmu.getFloat64
    setter(vr, [5.0, 0.25])
    fmu.step(1.0)
    assert list(getter([fmu.vr("y"), fmu.vr("y")])) == [0.25, 0.25]


def raw_begin(fmu):
    """(name, begin(start, stop defined, stop) -> status): the function that
    takes the experiment's times, called through ctypes (fmpy's wrapper
    would not pass every value on)."""
    c, dll = fmu.fmu.component, fmu.fmu.dll
    if fmu.version == 2:
        setup = dll.fmi2SetupExperiment
        setup.argtypes, setup.restype = [c_void_p, c_int, c_double, c_double, c_int, c_double], c_int
        return "fmi2SetupExperiment", lambda start, defined, stop: setup(c, 0, 0.0, start, defined, stop)
    enter = dll.fmi3EnterInitializationMode
    enter.argtypes, enter.restype = [c_void_p, c_bool, c_double, c_double, c_bool, c_double], c_int
    return "fmi3EnterInitializationMode", lambda start, defined, stop: enter(c, False, 0.0, start, defined, stop)


@pytest.mark.parametrize("version", [2, 3])
def test_stop_time_before_start_time_is_refused(version):
    """A stop time before the start time is refused; one equal to it (an
    experiment of no length) is not, nor one that is not defined."""
    fmu = Instance("RateLimiter", version)
    try:
        name, begin = raw_begin(fmu)
        assert begin(10.0, True, 5.0) == 3
        assert fmu.errors()[-1][2] == f"{name}: stopTime 5 is before startTime 10"
        fmu.fmu.reset()  # the standard's way on from an error
        fmu.start(start_time=10.0)
        fmu.step(0.5)
        for stop, defined in ((10.0, True), (5.0, False)):
            fmu.fmu.reset()
            assert begin(10.0, defined, stop) == 0, (stop, defined)
            if version == 2:
                fmu.fmu.enterInitializationMode()
            fmu.fmu.exitInitializationMode()
            fmu.t = 10.0
            fmu.step(0.5)
            assert fmu.get("time") == 10.5
        assert not fmu.errors()[1:]
    finally:
        fmu.free()


# ---- the checks of every value reference, whatever its place in the array ----


def real_accessors(fmu):
    f = fmu.fmu
    return (f.getReal, f.setReal) if fmu.version == 2 else (f.getFloat64, f.setFloat64)


def test_every_value_reference_of_an_array_is_checked_before_any_is_used(fmu):
    version = fmu.version
    get, set_ = real_accessors(fmu)
    y, u, bypass = fmu.vr("y"), fmu.vr("u"), fmu.vr("bypass")
    function = {2: ("fmi2GetReal", "fmi2SetReal"), 3: ("fmi3GetFloat64", "fmi3SetFloat64")}[version]
    for vrs in ([y, 999], [999, y], [999, y, y]):
        assert call_status(get, vrs) == 3, vrs
        assert fmu.errors()[-1][2] == f"{function[0]}: unknown value reference 999"
        fmu.fmu.reset()
        fmu.start()
    first_unknown = len(fmu.variables)  # value references are 0 to count - 1
    for access, values in ((get, ()), (set_, ([7.0],))):
        assert call_status(access, [first_unknown], *values) == 3
        assert fmu.errors()[-1][2] == f"{function[access is set_]}: unknown value reference {first_unknown}"
        fmu.fmu.reset()
        fmu.start()
    for vrs in ([bypass, y], [y, bypass]):  # a Boolean among Reals
        assert call_status(get, vrs) == 3, vrs
        assert fmu.errors()[-1][2] == (
            f"{function[0]}: bypass (value reference {bypass}) is a Boolean variable, which {function[0]} cannot access"
        )
        fmu.fmu.reset()
        fmu.start()
    for vrs in ([u, 999], [999, u]):  # nothing is set when one is refused
        assert call_status(set_, vrs, [7.0, 7.0]) == 3, vrs
        assert fmu.errors()[-1][2] == f"{function[1]}: unknown value reference 999"
        fmu.fmu.reset()
        fmu.start()
        assert fmu.get("u") == 0.0


def test_time_and_outputs_cannot_be_set(fmu):
    version = fmu.version
    set_ = real_accessors(fmu)[1]
    name = "fmi2SetReal" if version == 2 else "fmi3SetFloat64"
    assert call_status(set_, [fmu.vr("time")], [5.0]) == 3
    assert fmu.errors()[-1][2] == f"{name}: time is an independent variable and cannot be set"
    fmu.fmu.reset()
    fmu.start()
    assert call_status(set_, [fmu.vr("y")], [5.0]) == 3
    assert fmu.errors()[-1][2] == f"{name}: y is an output and cannot be set"


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("start_time", [float("inf"), float("nan")])
def test_a_start_time_that_is_not_finite_is_refused_naming_the_function(version, start_time):
    fmu = Instance("RateLimiter", version)
    try:
        name, begin = raw_begin(fmu)
        assert begin(start_time, False, 0.0) == 3
        assert [m[2] for m in fmu.errors()] == [f"{name}: startTime {start_time} is not finite"]
    finally:
        fmu.free()


# ---- instantiation: refusals, and an importer without a logger ----


def fmi3_instantiate(dll, name, token, event_mode=False, n_required=0, logging=True, log=None, environment=None):
    """log: a Python function, or an fmi3LogMessageCallback the caller keeps alive for the instance's life."""
    instantiate = dll.fmi3InstantiateCoSimulation
    instantiate.argtypes = [
        c_char_p,
        c_char_p,
        c_char_p,
        c_bool,
        c_bool,
        c_bool,
        c_bool,
        c_void_p,
        c_size_t,
        c_void_p,
        fmi3LogMessageCallback,
        c_void_p,
    ]
    instantiate.restype = c_void_p
    required = (c_uint * 1)(1)
    if not isinstance(log, fmi3LogMessageCallback):
        log = fmi3LogMessageCallback(log) if log else fmi3LogMessageCallback()
    return instantiate(
        name, token, None, False, logging, event_mode, False, required, n_required, environment, log, None
    )


def test_fmi3_instantiation_refusals_name_the_first_problem():
    fmu = Instance("RateLimiter", 3)
    try:
        token = fmu.md.instantiationToken.encode()
        cases = [
            ((b"", b"wrong", True, 1), "instanceName is missing"),
            ((None, token, False, 0), "instanceName is missing"),
            ((b"a", b"wrong", True, 1), "the instantiationToken does not match this FMU's model description"),
            ((b"a", None, False, 0), "the instantiationToken does not match this FMU's model description"),
            # compared whole: one character more or less does not match either
            ((b"a", token + b"0", False, 0), "the instantiationToken does not match this FMU's model description"),
            ((b"a", token[:-1], False, 0), "the instantiationToken does not match this FMU's model description"),
            ((b"a", token, True, 1), "this FMU has no Event Mode in Co-Simulation (hasEventMode = false)"),
            ((b"a", token, False, 1), "this FMU provides no intermediate update"),
        ]
        messages = []
        log = lambda env, status, category, message: messages.append((status, category, message))  # noqa: E731
        for (name, given, event_mode, n_required), reason in cases:
            messages.clear()
            assert fmi3_instantiate(fmu.fmu.dll, name, given, event_mode, n_required, log=log) is None
            assert messages == [(3, b"logStatusError", reason.encode())], (reason, messages)
            # without loggingOn, or without a logger: refused, nothing said, nothing called
            messages.clear()
            assert fmi3_instantiate(fmu.fmu.dll, name, given, event_mode, n_required, logging=False, log=log) is None
            assert fmi3_instantiate(fmu.fmu.dll, name, given, event_mode, n_required) is None
            assert messages == []
    finally:
        fmu.free()


def fmi2_instantiate_function(dll):
    instantiate = dll.fmi2Instantiate
    instantiate.argtypes = [c_char_p, c_int, c_char_p, c_char_p, c_void_p, c_int, c_int]
    instantiate.restype = c_void_p
    return instantiate


def test_fmi2_instantiation_refusals_name_the_first_problem():
    fmu = Instance("RateLimiter", 2)
    try:
        instantiate = fmi2_instantiate_function(fmu.fmu.dll)
        messages = []
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(lambda e, n, s, c, m: messages.append((n, s, c, m)))
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        guid = fmu.md.guid.encode()
        cases = [
            ((b"", 0, b"wrong"), "instanceName is missing"),
            ((None, 1, guid), "instanceName is missing"),
            ((b"a", 0, b"wrong"), "the GUID does not match this FMU's model description"),  # Model Exchange
            ((b"a", 1, b"wrong"), "the GUID does not match this FMU's model description"),
            ((b"a", 1, None), "the GUID does not match this FMU's model description"),
            ((b"a", 1, guid + b"0"), "the GUID does not match this FMU's model description"),
            ((b"a", 1, guid[:-1]), "the GUID does not match this FMU's model description"),
            ((b"a", 2, guid), "fmuType is neither fmi2ModelExchange nor fmi2CoSimulation"),
        ]  # not an fmi2Type
        for (name, kind, given), reason in cases:
            messages.clear()
            assert instantiate(name, kind, given, None, byref(callbacks), 0, 0) is None
            # a missing name is logged as "?"
            assert messages == [(b"?" if name is None else name, 3, b"logStatusError", reason.encode())], (
                reason,
                messages,
            )
        assert instantiate(b"a", 1, guid, None, None, 0, 0) is None  # no callbacks: nothing to allocate with
        for missing in ("allocateMemory", "freeMemory"):  # half a memory manager: nothing allocated
            partial = fmi2CallbackFunctions()
            partial.logger = callbacks.logger
            partial.allocateMemory = (
                callbacks.allocateMemory if missing == "freeMemory" else fmi2CallbackAllocateMemoryTYPE()
            )
            partial.freeMemory = callbacks.freeMemory if missing == "allocateMemory" else fmi2CallbackFreeMemoryTYPE()
            assert instantiate(b"a", 1, guid, None, byref(partial), 0, 0) is None, missing
        silent = fmi2CallbackFunctions()  # no logger: refused, nothing called
        silent.allocateMemory, silent.freeMemory = callbacks.allocateMemory, callbacks.freeMemory
        messages.clear()
        assert instantiate(b"a", 1, b"wrong", None, byref(silent), 0, 0) is None and messages == []
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_an_importer_without_a_logger_gets_statuses_and_no_crash(version):
    """A NULL logger is allowed (FMI 3 says so; FMI 2 importers pass one):
    errors are returned, nothing is called."""
    fmu = Instance("RateLimiter", version)
    try:
        dll = fmu.fmu.dll
        if version == 2:
            instantiate = dll.fmi2Instantiate
            instantiate.argtypes = [c_char_p, c_int, c_char_p, c_char_p, c_void_p, c_int, c_int]
            instantiate.restype = c_void_p
            callbacks = fmi2CallbackFunctions()
            callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
            callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
            c = instantiate(b"quiet", 1, fmu.md.guid.encode(), None, byref(callbacks), 0, 1)
            do_step = dll.fmi2DoStep
            do_step.argtypes, do_step.restype = [c_void_p, c_double, c_double, c_int], c_int
            step = lambda: do_step(c, 0.0, 0.1, 1)  # noqa: E731
        else:
            c = fmi3_instantiate(dll, b"quiet", fmu.md.instantiationToken.encode())
            do_step = dll.fmi3DoStep
            do_step.argtypes = [c_void_p, c_double, c_double, c_bool] + [c_void_p] * 4
            do_step.restype = c_int
            flags, when = (c_bool * 3)(), c_double()
            step = lambda: do_step(c, 0.0, 0.1, True, flags, byref(flags, 1), byref(flags, 2), byref(when))  # noqa: E731
        assert c
        assert step() == 3  # a step before initialization: refused, said to nobody
        release = getattr(dll, f"fmi{version}FreeInstance")
        release.argtypes, release.restype = [c_void_p], None
        release(c)
    finally:
        fmu.free()


# FMI 3 accessors of types that no variable of these FMUs has
NO_VARIABLES = ("Float32", "Int8", "UInt8", "Int16", "UInt16", "UInt32", "UInt64", "String", "Binary")


@pytest.mark.parametrize("kind", NO_VARIABLES)
def test_fmi3_accessors_of_types_without_variables_refuse_every_value_reference(kind):
    fmu = Instance("RateLimiter", 3)
    try:
        fmu.start()
        c, dll = fmu.fmu.component, fmu.fmu.dll
        u = fmu.vr("u")
        buffer = ctypes.create_string_buffer(4096)
        sizes = (c_size_t * 4)()
        for access in ("Get", "Set"):
            name = f"fmi3{access}{kind}"
            function = getattr(dll, name)
            if kind == "Binary":  # (instance, vr, nvr, valueSizes, values, nValues)
                function.argtypes = [c_void_p, c_void_p, c_size_t, c_void_p, c_void_p, c_size_t]
            else:
                function.argtypes = [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t]
            function.restype = c_int
            cases = [
                ([u], f"u (value reference {u}) is a Real variable, which {name} cannot access"),
                ([u, u], f"u (value reference {u}) is a Real variable, which {name} cannot access"),
                ([999, u], "unknown value reference 999"),
            ]
            if kind == "Binary":
                cases.append(([u], "the valueSizes array is NULL"))
            for number, (vrs, message) in enumerate(cases):
                array = (c_uint * len(vrs))(*vrs)
                args = ((sizes if number < 3 else None), buffer) if kind == "Binary" else (buffer,)
                assert function(c, array, len(vrs), *args, len(vrs)) == 3, (name, vrs)
                assert fmu.errors()[-1][2] == f"{name}: {message}", (name, vrs)
                fmu.fmu.reset()
                fmu.start()
        assert fmu.get("u") == 0.0
    finally:
        fmu.free()


def free_instance(fmu, c):
    """fmi*FreeInstance of an instance made by hand beside fmu's, from fmu's library (still loaded)."""
    function = getattr(fmu.fmu.dll, f"fmi{fmu.version}FreeInstance")
    function.argtypes, function.restype = [c_void_p], None
    function(c)


class ImporterMemory:
    """FMI 2 memory callbacks that keep count of the blocks live and refuse an allocation when refuse()
    says so (called after the allocation is counted in calls)."""

    def __init__(self, logger=lambda e, n, s, c, m: None):
        self.live, self.calls, self.refuse = set(), [], lambda: False
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(logger)
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(self._allocate)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(self._release)

    def _allocate(self, count, size):
        self.calls.append(size)
        if self.refuse():
            return None
        block = calloc(count, size)
        self.live.add(block)
        return block

    def _release(self, block):
        self.live.discard(block)
        free(block)


def test_fmi2_instantiation_with_memory_refused_returns_null_and_frees_what_it_got():
    """The importer's allocateMemory fails on its first call (the instance)
    or its second (the name): no instance, nothing held, no crash."""
    fmu = Instance("RateLimiter", 2)
    try:
        instantiate = fmi2_instantiate_function(fmu.fmu.dll)
        for failing in (1, 2):
            memory = ImporterMemory()
            memory.refuse = lambda memory=memory, failing=failing: len(memory.calls) == failing
            assert instantiate(b"a", 1, fmu.md.guid.encode(), None, byref(memory.callbacks), 0, 0) is None, failing
            assert len(memory.calls) == 2 and memory.live == set(), (failing, memory.calls, memory.live)
    finally:
        fmu.free()


def accessor(fmu, name):
    function = getattr(fmu.fmu.dll, name)
    function.argtypes = [c_void_p, c_void_p, c_size_t, c_void_p] + ([c_size_t] if fmu.version == 3 else [])
    function.restype = c_int
    return function


ACCESSOR_TYPES = {2: ("Real", "Integer", "Boolean", "String"), 3: ("Float64", "Int32", "Int64", "Boolean", "String")}


def test_a_null_array_is_refused_naming_which_one(fmu):
    """Every getter and setter, one value or two: a NULL value reference
    array or a NULL value array is an error that says which, not a crash."""
    version = fmu.version
    values = ctypes.create_string_buffer(64)
    vrs = (c_uint * 2)(fmu.vr("u"), fmu.vr("u"))
    for kind in ACCESSOR_TYPES[version]:
        for access in ("Get", "Set"):
            name = f"fmi{version}{access}{kind}"
            function = accessor(fmu, name)
            for n in (1, 2):
                for vr, array, which in ((None, values, "value reference array"), (vrs, None, "value array")):
                    assert function(fmu.fmu.component, vr, n, array, *([n] if version == 3 else [])) == 3
                    assert fmu.errors()[-1][2] == f"{name}: the {which} is NULL", (name, n)
                    fmu.fmu.reset()
                    fmu.start()


def test_a_foreign_fmu_state_is_refused_by_every_state_function(fmu):
    """Its size, serializing it, getting or deserializing into it and freeing
    it: an error naming the function, nothing written or freed, no crash
    (setting one: test_misuse.py)."""
    version = fmu.version
    c, dll = fmu.fmu.component, fmu.fmu.dll
    junk = ctypes.create_string_buffer(b"\x5a" * 4096)
    foreign = ctypes.cast(junk, c_void_p)
    names = [STATE_FUNCTIONS[version][which] for which in ("size", "serialize", "get", "deserialize", "free")]
    api = state_api(fmu)
    good = api["get"]()
    data = bytes(api["serialize"](good))
    api["free"](good)
    size, out = c_size_t(7), ctypes.create_string_buffer(4096)
    calls = {
        names[0]: ([c_void_p, c_void_p, c_void_p], (c, foreign, byref(size))),
        names[1]: ([c_void_p, c_void_p, c_void_p, c_size_t], (c, foreign, out, 4096)),
        # given a state to fill, it must be one of this FMU's
        names[2]: ([c_void_p, c_void_p], (c, byref(foreign))),
        names[3]: ([c_void_p, c_char_p, c_size_t, c_void_p], (c, data, len(data), byref(foreign))),
        names[4]: ([c_void_p, c_void_p], (c, byref(foreign))),
    }
    for name, (argtypes, args) in calls.items():
        function = getattr(dll, name)
        function.argtypes, function.restype = argtypes, c_int
        assert function(*args) == 3, name
        assert fmu.errors()[-1][2].startswith(f"{name}: ") and "not an FMU state" in fmu.errors()[-1][2], fmu.errors()[
            -1
        ]
        fmu.fmu.reset()
        fmu.start()
    assert size.value == 7 and out.raw == bytes(4096) and foreign.value == ctypes.addressof(junk)
    assert junk.raw == b"\x5a" * 4096 + b"\0"


@pytest.mark.parametrize("version", [2, 3])
def test_set_debug_logging_refuses_a_null_category_array_and_escapes_a_bad_name(version):
    """nCategories 1 with no array, or a NULL entry in it: an error, not a
    read through NULL. An unknown category is quoted in the error with every
    '%' made '?', since FMI 2 loggers may treat the message as a format
    string; a reason is cut at 399 characters."""
    fmu = Instance("RateLimiter", version)
    try:
        name = f"fmi{version}SetDebugLogging"
        function = getattr(fmu.fmu.dll, name)
        function.argtypes = [c_void_p, c_bool if version == 3 else c_int, c_size_t, c_void_p]
        function.restype = c_int
        assert function(fmu.fmu.component, 1, 1, None) == 3
        assert fmu.errors()[-1][2] == f"{name}: the category array is NULL"
        fmu.fmu.reset()
        categories = (c_char_p * 1)(b"bad%s%n")
        assert function(fmu.fmu.component, 1, 1, categories) == 3
        assert fmu.errors()[-1][2] == f'{name}: unknown log category "bad?s?n"'
        fmu.fmu.reset()
        categories = (c_char_p * 2)(b"logEvents", None)  # a NULL entry: refused by name, not read
        assert function(fmu.fmu.component, 1, 2, categories) == 3
        assert fmu.errors()[-1][2] == f'{name}: unknown log category "(null)"'
        fmu.fmu.reset()
        long_name = "x" * 1000  # the reason is cut at 399 characters (docs/fmi.md)
        assert function(fmu.fmu.component, 1, 1, (c_char_p * 1)(long_name.encode())) == 3
        assert fmu.errors()[-1][2] == f"{name}: " + f'unknown log category "{long_name}"'[:399]
    finally:
        fmu.free()


def test_serializing_into_a_short_byte_array_is_refused_and_writes_nothing(fmu):
    """One byte short: an error giving both sizes, not a write past the end;
    exactly the size: fine."""
    version = fmu.version
    api = state_api(fmu)
    state = api["get"]()
    c, name = fmu.fmu.component, STATE_FUNCTIONS[version]["serialize"]
    size = c_size_t()
    assert raw(fmu, STATE_FUNCTIONS[version]["size"], [c_void_p, c_void_p, c_void_p], c, state, byref(size)) == 0
    n = size.value
    out = ctypes.create_string_buffer(b"\xa5" * (n + 8), n + 8)
    assert raw(fmu, name, [c_void_p, c_void_p, c_void_p, c_size_t], c, state, out, n - 1) == 3
    assert fmu.errors()[-1][2] == f"{name}: the byte array has {n - 1} bytes; the state needs {n}"
    assert out.raw == b"\xa5" * (n + 8)
    fmu.fmu.reset()
    assert raw(fmu, name, [c_void_p, c_void_p, c_void_p, c_size_t], c, state, out, n) == 0
    assert out.raw[:n] == bytes(api["serialize"](state)) and out.raw[n:] == b"\xa5" * 8
    api["free"](state)


def test_fmi2_a_state_without_memory_is_an_error_and_nothing_is_held():
    """The importer's allocateMemory refuses the state (FMI 2 keeps FMU
    states in the importer's memory): getting or deserializing one is an
    error saying so, the pointer stays NULL, the instance runs on after a
    reset."""
    fmu = Instance("RateLimiter", 2)
    try:
        messages = []
        memory = ImporterMemory(lambda e, n, s, c, m: messages.append((s, m.decode())))
        live = memory.live
        dll = fmu.fmu.dll
        c = fmi2_instantiate_function(dll)(b"a", 1, fmu.md.guid.encode(), None, byref(memory.callbacks), 0, 1)
        assert c
        held = set(live)  # the instance and its name
        state = c_void_p()
        assert raw(fmu, "fmi2GetFMUstate", [c_void_p, c_void_p], c, byref(state)) == 0
        data = ctypes.create_string_buffer(4096)
        size = c_size_t()
        assert raw(fmu, "fmi2SerializedFMUstateSize", [c_void_p, c_void_p, c_void_p], c, state, byref(size)) == 0
        assert (
            raw(fmu, "fmi2SerializeFMUstate", [c_void_p, c_void_p, c_void_p, c_size_t], c, state, data, size.value) == 0
        )
        assert raw(fmu, "fmi2FreeFMUstate", [c_void_p, c_void_p], c, byref(state)) == 0 and live == held
        memory.refuse = lambda: True
        for name, argtypes, args in (
            ("fmi2GetFMUstate", [c_void_p, c_void_p], ()),
            ("fmi2DeSerializeFMUstate", [c_void_p, c_void_p, c_size_t, c_void_p], (data, size.value)),
        ):
            messages.clear()
            empty = c_void_p()
            assert raw(fmu, name, argtypes, c, *args, byref(empty)) == 3
            assert messages == [(3, f"{name}: out of memory")] and empty.value is None and live == held
            assert raw(fmu, "fmi2Reset", [c_void_p], c) == 0
        memory.refuse = lambda: False
        assert raw(fmu, "fmi2GetFMUstate", [c_void_p, c_void_p], c, byref(state)) == 0 and state.value
        assert raw(fmu, "fmi2FreeFMUstate", [c_void_p, c_void_p], c, byref(state)) == 0 and live == held
        free_instance(fmu, c)
        assert live == set()
    finally:
        fmu.free()


def test_fmi2_status_queries_answer_only_what_this_fmu_has():
    """fmi2GetXXXStatus: the last successful time (fmi2LastSuccessfulTime = 2)
    and 'terminated' (fmi2Terminated = 3, always false: the FMU never stops a
    run) are answered; every other kind is fmi2Discard (nothing asynchronous
    here: doStep never returns fmi2Pending). A NULL value pointer for an
    answered kind is an error, not a write through NULL."""
    fmu = Instance("RateLimiter", 2)
    try:
        fmu.start(rateUpPar=2.0)
        fmu.set(u=5.0)
        fmu.step(0.5)
        fmu.step(0.25)
        c = fmu.fmu.component
        real, flag, integer = c_double(-1.0), c_int(7), c_int(7)
        text = c_char_p(b"untouched")
        query = [c_void_p, c_int, c_void_p]
        for kind in (0, 1, 2, 3, 4, 99, -1):  # the four fmi2StatusKinds, and numbers that are none
            answered_real, answered_flag = kind == 2, kind == 3
            assert raw(fmu, "fmi2GetRealStatus", query, c, kind, byref(real)) == (0 if answered_real else 2), kind
            assert raw(fmu, "fmi2GetBooleanStatus", query, c, kind, byref(flag)) == (0 if answered_flag else 2), kind
            for name, value in (
                ("fmi2GetStatus", integer),
                ("fmi2GetIntegerStatus", integer),
                ("fmi2GetStringStatus", text),
            ):
                assert raw(fmu, name, query, c, kind, byref(value)) == 2, (name, kind)
        assert real.value == 0.75 and flag.value == 0 and integer.value == 7 and text.value == b"untouched"
        assert fmu.messages == []
        for name, kind in (("fmi2GetRealStatus", 2), ("fmi2GetBooleanStatus", 3)):
            fmu.fmu.reset()
            fmu.start(rateUpPar=2.0)
            fmu.set(u=5.0)
            fmu.step(0.5)
            assert raw(fmu, name, query, c, kind, None) == 3
            assert fmu.errors()[-1][2] == f"{name}: the value pointer is NULL"
            assert fmu.get("y") == 1.0  # the last good values
    finally:
        fmu.free()


def test_the_version_functions_name_the_standard():
    fmu2, fmu3 = Instance("RateLimiter", 2), Instance("RateLimiter", 3)
    try:
        for fmu, name, expected in (
            (fmu2, "fmi2GetTypesPlatform", b"default"),
            (fmu2, "fmi2GetVersion", b"2.0"),
            (fmu3, "fmi3GetVersion", b"3.0"),
        ):
            function = getattr(fmu.fmu.dll, name)
            function.argtypes, function.restype = [], c_char_p
            assert function() == expected, name
    finally:
        fmu2.free()
        fmu3.free()


def test_fmi3_a_step_with_a_null_output_pointer_is_refused_and_the_time_stays():
    """Each of fmi3DoStep's four output pointers NULL in turn: an error
    naming the function, the time and outputs stay at the last good step."""
    fmu = Instance("RateLimiter", 3)
    try:
        for missing in range(4):
            fmu.start(rateUpPar=2.0)
            fmu.set(u=5.0)
            fmu.step(0.5)
            flags, when = (c_bool * 3)(), c_double()
            outputs = [byref(flags, 0), byref(flags, 1), byref(flags, 2), byref(when)]
            outputs[missing] = None
            assert (
                raw(
                    fmu,
                    "fmi3DoStep",
                    [c_void_p, c_double, c_double, c_bool] + [c_void_p] * 4,
                    fmu.fmu.component,
                    0.5,
                    0.5,
                    True,
                    *outputs,
                )
                == 3
            ), missing
            assert fmu.errors()[-1][2] == "fmi3DoStep: an output argument pointer is NULL", missing
            assert (fmu.get("time"), fmu.get("y")) == (0.5, 1.0), missing
            fmu.fmu.reset()
    finally:
        fmu.free()


@pytest.mark.parametrize(
    "case,reason",
    [
        ("token", "the instantiationToken does not match this FMU's model description"),
        ("one lock callback", "lockPreemption and unlockPreemption must both be given, or neither"),
    ],
)
def test_fmi3_scheduled_execution_refusals_give_a_reason(case, reason):
    """fmi3InstantiateScheduledExecution refuses a foreign token and a
    lockPreemption without its unlockPreemption: NULL, the reason to the
    logger when logging is on, and nothing called otherwise."""
    fmu = Instance("RateLimiter", 3, scheduled=True)
    try:
        function = fmu.fmu.dll.fmi3InstantiateScheduledExecution
        lock_type = ctypes.CFUNCTYPE(None)
        function.argtypes = [c_char_p, c_char_p, c_char_p, c_bool, c_bool, c_void_p, fmi3LogMessageCallback]
        function.argtypes += [c_void_p, lock_type, lock_type]
        function.restype = c_void_p
        messages = []
        log = fmi3LogMessageCallback(
            lambda env, status, category, message: messages.append((status, category, message))
        )
        lock = lock_type(lambda: None)
        token = fmu.md.instantiationToken.encode()
        args = (b"{wrong}", lock, lock) if case == "token" else (token, lock, lock_type())
        assert function(b"a", args[0], None, False, True, None, log, None, *args[1:]) is None
        assert messages == [(3, b"logStatusError", reason.encode())]
        messages.clear()
        assert function(b"a", args[0], None, False, False, None, log, None, *args[1:]) is None
        assert function(b"a", args[0], None, False, True, None, fmi3LogMessageCallback(), None, *args[1:]) is None
        assert messages == []
    finally:
        fmu.free()


def test_fmi2_string_accessors_refuse_every_value_reference():
    """No variable is a String: any value reference is refused, naming the
    variable's own type, or as unknown."""
    fmu = Instance("RateLimiter", 2)
    try:
        fmu.start()
        c, u = fmu.fmu.component, fmu.vr("u")
        texts = (c_char_p * 2)(b"a", b"b")
        for access in ("Get", "Set"):
            name = f"fmi2{access}String"
            for vrs, message in (
                ([u], f"u (value reference {u}) is a Real variable, which {name} cannot access"),
                ([999], "unknown value reference 999"),
            ):
                array = (c_uint * len(vrs))(*vrs)
                assert raw(fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p], c, array, len(vrs), texts) == 3
                assert fmu.errors()[-1][2] == f"{name}: {message}", (name, vrs)
                fmu.fmu.reset()
                fmu.start()
        assert texts[0] == b"a" and fmu.get("u") == 0.0
    finally:
        fmu.free()


def test_freeing_through_a_null_pointer_or_a_null_state_does_nothing(fmu):
    """FMI: freeing a NULL state is a no-op; a NULL pointer to one too."""
    version = fmu.version
    name = STATE_FUNCTIONS[version]["free"]
    empty = c_void_p()
    assert raw(fmu, name, [c_void_p, c_void_p], fmu.fmu.component, None) == 0
    assert raw(fmu, name, [c_void_p, c_void_p], fmu.fmu.component, byref(empty)) == 0
    assert fmu.messages == []
    fmu.step(0.5)


def test_fmi2_any_boolean_other_than_false_is_true():
    """fmi2Boolean is an int: 2 or -1 set as a Boolean is true (the block
    passes u through), one value or two at once, reads back as fmi2True
    (1), and is kept as true in an FMU state."""
    fmu = Instance("RateLimiter", 2)
    try:
        c, bypass = fmu.fmu.component, fmu.vr("bypass")
        function = [c_void_p, c_void_p, c_size_t, c_void_p]
        for values in ([2], [-1], [0, 7]):
            fmu.fmu.reset()
            fmu.start(rateUpPar=1.0)
            fmu.set(u=5.0)
            vrs = (c_uint * len(values))(*([bypass] * len(values)))
            assert raw(fmu, "fmi2SetBoolean", function, c, vrs, len(values), (c_int * len(values))(*values)) == 0
            fmu.step(0.5)
            read = (c_int * 2)(9, 9)
            assert raw(fmu, "fmi2GetBoolean", function, c, (c_uint * 2)(bypass, bypass), 2, read) == 0
            assert list(read) == [1, 1] and fmu.get("y") == 5.0, values
            # stored as true itself: a state holding it deserializes (only 0 and 1 are possible there)
            api = state_api(fmu)
            state = api["get"]()
            api["free"](api["deserialize"](bytes(api["serialize"](state))))
            api["free"](state)
        assert fmu.messages == []
    finally:
        fmu.free()


def test_fmi2_a_freed_state_whose_memory_is_still_there_is_refused():
    """FMI 2 states live in the importer's memory. An importer whose
    freeMemory keeps the block (a pool) and that uses a state after freeing
    it gets an error, not a state: freeing marks the state as no longer
    one. Setting it, serializing it and freeing it again are refused."""
    fmu = Instance("RateLimiter", 2)
    try:
        kept, messages = [], []
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(lambda e, n, s, c, m: messages.append((s, m.decode())))
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(kept.append)  # released at the end
        dll = fmu.fmu.dll
        c = fmi2_instantiate_function(dll)(b"a", 1, fmu.md.guid.encode(), None, byref(callbacks), 0, 0)
        state = c_void_p()
        assert raw(fmu, "fmi2GetFMUstate", [c_void_p, c_void_p], c, byref(state)) == 0
        stale = c_void_p(state.value)
        assert raw(fmu, "fmi2FreeFMUstate", [c_void_p, c_void_p], c, byref(state)) == 0
        assert state.value is None and kept == [stale.value]
        out, size = ctypes.create_string_buffer(4096), c_size_t()
        for name, argtypes, args in (
            ("fmi2SetFMUstate", [c_void_p, c_void_p], (stale,)),
            ("fmi2SerializedFMUstateSize", [c_void_p, c_void_p, c_void_p], (stale, byref(size))),
            ("fmi2SerializeFMUstate", [c_void_p, c_void_p, c_void_p, c_size_t], (stale, out, 4096)),
            ("fmi2FreeFMUstate", [c_void_p, c_void_p], (byref(stale),)),
        ):
            messages.clear()
            assert raw(fmu, name, argtypes, c, *args) == 3, name
            assert messages == [(3, f"{name}: not an FMU state of this FMU")], name
            assert raw(fmu, "fmi2Reset", [c_void_p], c) == 0
        assert len(kept) == 1  # not freed twice
        free_instance(fmu, c)
        for block in kept:
            free(block)
    finally:
        fmu.free()


@pytest.mark.parametrize("logging_on", [1, 0])
def test_fmi2_the_logger_gets_the_name_and_environment_given_and_only_what_loggingon_allows(logging_on):
    """The logger is called with the componentEnvironment and the instance
    name given to fmi2Instantiate (a copy: the importer's string may change
    after the call). With loggingOn = fmi2False only warnings and errors
    are logged: the status cleared (an event) is not."""
    fmu = Instance("RateLimiter", 2)
    try:
        messages = []
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(lambda e, n, s, c, m: messages.append((e, n, s, c.decode())))
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        callbacks.componentEnvironment = 0x5EED
        name = ctypes.create_string_buffer(b"pump 1")
        dll = fmu.fmu.dll
        c = fmi2_instantiate_function(dll)(name, 1, fmu.md.guid.encode(), None, byref(callbacks), 0, logging_on)
        name.value = b"other"
        rate = (c_uint * 1)(fmu.vr("rateUpPar"))
        set_real = [c_void_p, c_void_p, c_size_t, c_void_p]
        assert raw(fmu, "fmi2SetReal", set_real, c, rate, 1, (c_double * 1)(-1.0)) == 0
        assert raw(fmu, "fmi2EnterInitializationMode", [c_void_p], c) == 0
        assert raw(fmu, "fmi2ExitInitializationMode", [c_void_p], c) == 0  # status 16#8200: OK, a warning logged
        assert raw(fmu, "fmi2SetReal", set_real, c, rate, 1, (c_double * 1)(1.0)) == 0
        assert raw(fmu, "fmi2DoStep", [c_void_p, c_double, c_double, c_int], c, 0.0, 0.5, 1) == 0  # cleared
        assert raw(fmu, "fmi2ExitInitializationMode", [c_void_p], c) == 3  # not in Step Mode: an error
        expected = [
            (0x5EED, b"pump 1", 1, "logStatusWarning"),
            (0x5EED, b"pump 1", 0, "logEvents"),
            (0x5EED, b"pump 1", 3, "logStatusError"),
        ]
        assert messages == (expected if logging_on else [expected[0], expected[2]])
        free_instance(fmu, c)
    finally:
        fmu.free()


@pytest.mark.parametrize("logging_on", [True, False])
def test_fmi3_the_logger_gets_the_environment_given_and_nothing_when_logging_is_off(logging_on):
    """fmi3LogMessageCallback gets the instanceEnvironment given to
    fmi3InstantiateCoSimulation. With loggingOn = false the FMU logs
    nothing at all (FMI 3 has no categories that are always on): the
    statuses of failed calls and the block's status outputs say what
    happened."""
    fmu = Instance("RateLimiter", 3)
    try:
        messages = []
        log = fmi3LogMessageCallback(
            lambda env, status, category, message: messages.append((env, status, category.decode()))
        )
        dll = fmu.fmu.dll
        c = fmi3_instantiate(
            dll, b"pump 1", fmu.md.instantiationToken.encode(), logging=logging_on, log=log, environment=0x5EED
        )
        rate = (c_uint * 1)(fmu.vr("rateUpPar"))
        set_float = [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t]
        assert raw(fmu, "fmi3SetFloat64", set_float, c, rate, 1, (c_double * 1)(-1.0), 1) == 0
        assert (
            raw(
                fmu,
                "fmi3EnterInitializationMode",
                [c_void_p, c_bool, c_double, c_double, c_bool, c_double],
                c,
                False,
                0.0,
                0.0,
                False,
                0.0,
            )
            == 0
        )
        assert raw(fmu, "fmi3ExitInitializationMode", [c_void_p], c) == 0  # status 16#8200: OK, a warning logged
        assert raw(fmu, "fmi3SetFloat64", set_float, c, rate, 1, (c_double * 1)(1.0), 1) == 0
        flags, when = (c_bool * 3)(), c_double()
        assert (
            raw(
                fmu,
                "fmi3DoStep",
                [c_void_p, c_double, c_double, c_bool] + [c_void_p] * 4,
                c,
                0.0,
                0.5,
                True,
                byref(flags, 0),
                byref(flags, 1),
                byref(flags, 2),
                byref(when),
            )
            == 0
        )  # cleared: an event
        assert raw(fmu, "fmi3ExitInitializationMode", [c_void_p], c) == 3  # not in Step Mode: an error
        expected = [(0x5EED, 1, "logStatusWarning"), (0x5EED, 0, "logEvents"), (0x5EED, 3, "logStatusError")]
        assert messages == (expected if logging_on else [])
        free_instance(fmu, c)
    finally:
        fmu.free()


ALL_ACCESSOR_TYPES = {
    2: ("Real", "Integer", "Boolean", "String"),
    3: ("Float64", "Int32", "Int64", "Boolean") + NO_VARIABLES,
}


def test_zero_values_with_arrays_given_reads_and_writes_nothing(fmu):
    """nvr = 0 with real arrays (the first entry an unknown value reference):
    every getter and setter returns OK without looking at them."""
    version = fmu.version
    c = fmu.fmu.component
    vrs = (c_uint * 1)(999)
    buffer = ctypes.create_string_buffer(b"\x5a" * 64, 64)
    sizes = (c_size_t * 1)(7)
    for kind in ALL_ACCESSOR_TYPES[version]:
        for access in ("Get", "Set"):
            name = f"fmi{version}{access}{kind}"
            if kind == "Binary":
                args = [c_void_p, c_void_p, c_size_t, c_void_p, c_void_p, c_size_t], (c, vrs, 0, sizes, buffer, 0)
            elif version == 3:
                args = [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t], (c, vrs, 0, buffer, 0)
            else:
                args = [c_void_p, c_void_p, c_size_t, c_void_p], (c, vrs, 0, buffer)
            assert raw(fmu, name, args[0], *args[1]) == 0, name
    assert buffer.raw == b"\x5a" * 64 and sizes[0] == 7 and fmu.messages == []
    fmu.step(0.5)
