"""The choices made where the vendor documents are silent (models.md,
Vendor interpretations), each checked."""

import math

import pytest

from support.fmu_driver import Instance, call_status


@pytest.fixture(params=[2, 3])
def version(request):
    return request.param


def started(model, version, **start):
    fmu = Instance(model, version)
    fmu.start(**start)
    return fmu


def test_siemens_default_rate_holds_until_a_rate_is_connected(version):
    fmu = started("LGF_LimRateOfChangeCI", version, value=5.0)
    for _ in range(3):
        fmu.step(1.0)
    assert fmu.get("delayedValue") == 0.0 and fmu.get("error") is False
    fmu.free()


def test_siemens_nan_rate_is_status_8201_naming_set_change_rate(version):
    fmu = started("LGF_LimRateOfChangeCI", version, value=5.0, setChangeRate=math.nan)
    fmu.step(1.0)
    assert fmu.get("status") == 0x8201 and fmu.get("subFunctionStatus") == fmu.vr("setChangeRate")
    assert fmu.get("delayedValue") == 0.0
    fmu.free()


def test_siemens_non_finite_default_value_is_not_output(version):
    fmu = started(
        "LGF_LimRateOfChangeCI", version, value=3.0, setChangeRate=1.0, defaultOutValue=math.inf, enDefaultOutValue=True
    )
    fmu.step(1.0)
    assert fmu.get("delayedValue") == 3.0
    fmu.free()


def test_siemens_cycle_time_error_names_cycle_time(version):
    fmu = started("LGF_LimRateOfChangeCI", version, cycleTime=-1.0, callOB=35)
    assert fmu.get("status") == 0x8601 and fmu.get("subFunctionStatus") == fmu.vr("cycleTime")
    fmu.free()


def test_irmn4_negative_rate_holds_and_logs_a_warning(version):
    fmu = started("RateLimit", version, UpRatePar=-2.0)
    fmu.set(In=10.0)
    fmu.step(1.0)
    assert fmu.get("Out") == 0.0
    warnings = [m for m in fmu.messages if m[0] == 1]
    assert len(warnings) == 1 and "UpRatePar" in warnings[0][2] and "16#8200" in warnings[0][2]
    fmu.free()


@pytest.mark.parametrize(
    "model,name,value",
    [
        ("RateLimit", "DurationPar", 259201.0),
        ("RateLimit", "DurationPar", -1.0),
        ("Ramp", "rVariation", 100.5),
        ("Ramp", "rVariation", -1.0),
        ("Ramp", "tTime", -0.1),
        ("Ramp", "tTime", math.inf),
        ("Ramp", "tInitDelay", math.nan),
    ],
)
def test_values_outside_the_vendor_range_are_refused(model, name, value, version):
    fmu = Instance(model, version)
    setter = fmu.fmu.setReal if version == 2 else fmu.fmu.setFloat64
    assert call_status(setter, [fmu.vr(name)], [value]) == 3
    assert "outside its range" in fmu.errors()[-1][2]
    fmu.free()


def test_ramp_range_limits_themselves_are_accepted(version):
    fmu = started("Ramp", version, rVariation=100.0, tTime=0.0, rIn=0.0)
    fmu.set(rIn=1000.0)
    fmu.step(0.5)
    assert fmu.get("rOut") == 100.0  # tTime 0: 100 per cycle
    fmu.free()
