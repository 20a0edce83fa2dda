"""The serialized state every FMU carries (FMI-LS-REF role
serialized-state, docs/fmi.md "Reference experiments"): deserialized into
a new instance, it continues the second half of its scenario to the
hand-worked reference, bit for bit."""

import zipfile

import pytest
from lxml import etree

from support.fmu_driver import MODELS, REPO, Instance, fmu_file, state_api
from support.ls_ref import FOLDER
from support.scenarios import load, same

NS = {"ft": "urn:fmutrace:ls-ref:1"}


def carried_state(model, version):
    with zipfile.ZipFile(fmu_file(model, version)) as z:
        manifest = etree.fromstring(z.read(f"{FOLDER}/fmi-ls-manifest.xml"))
        (related,) = [r for r in manifest.iterfind("Related") if r.get("role") == "serialized-state"]
        (info,) = related.iterfind("Annotations/Annotation/ft:State", NS)
        return (
            info.get("experiment"),
            int(info.get("steps")),
            float(info.get("time")),
            z.read(f"{FOLDER}/{related.get('source')}"),
        )


def held(inputs, t, h):
    """The inputs a step from t sees: the last row at or before t."""
    if inputs is None:
        return {}
    rows = [row for row in inputs if row["time"] <= t + h * 1e-9]
    return {n: rows[-1][n] for n in inputs.dtype.names if n != "time"} if rows else {}


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_the_carried_state_continues_to_the_reference(model, version):
    experiment, half, time, data = carried_state(model, version)
    case = load(REPO / "tests" / "scenarios" / model / experiment)
    start, stop, h = (case.options[k] for k in ("StartTime", "StopTime", "StepSize"))
    steps = round((stop - start) / h)
    assert half == steps // 2 and time == start + half * h
    fmu = Instance(model, version)
    fmu.start(start, **case.start_values)
    api = state_api(fmu)
    fmu.restore(api["deserialize"](data), time)
    compared = 0
    reference = case.reference
    for k in range(half, steps):
        t = start + k * h
        fmu.set(**held(case.inputs, t, h))
        fmu.step(h)
        rows = [r for r in reference if abs(r["time"] - (t + h)) <= h * 1e-9]
        for row in rows[-1:]:  # (the last row of an instant: after its event)
            for name in case.outputs:
                assert same(fmu.get(name), row[name]), (name, t + h, fmu.get(name), row[name])
                compared += 1
    assert compared >= len(case.outputs)  # the second half meets the reference somewhere
    fmu.free()
