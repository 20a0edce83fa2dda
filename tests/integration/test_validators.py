"""Static validators beside fmpy's: fmutool -check (FMU Manipulation
Toolbox, FMI 2 and 3, the Scheduled Execution FMUs too) and VDMCheck2 (INTO-CPS, FMI 2, the VDM model of the
FMI 2 standard) find nothing in any FMU."""

import os
import sys
from pathlib import Path

import pytest

from support.fmu_driver import MODELS, fmu_file
from support.process import run as run_bounded


@pytest.mark.parametrize(
    "version,scheduled", [(2, False), (3, False), (3, True)], ids=["fmi2", "fmi3", "fmi3-scheduled-execution"]
)
@pytest.mark.parametrize("model", MODELS)
def test_fmutool_check(model, version, scheduled):
    fmutool = Path(sys.executable).parent / "fmutool"
    out = run_bounded(
        [str(fmutool), "-input", str(fmu_file(model, version, scheduled)), "-check"], timeout=120, what="fmutool -check"
    )
    log = out.stdout + out.stderr
    assert out.returncode == 0, log
    assert f"This FMU seems to be compliant with FMI-{version}.0" in log, log
    assert f"No semantic error against the FMI-{version} standard" in log, log
    assert "ERROR" not in log, log


@pytest.mark.parametrize("model", MODELS)
def test_vdmcheck2(model):
    jar, java = os.environ.get("RL_VDMCHECK_JAR"), os.environ.get("RL_JAVA") or "java"
    assert jar and Path(jar).exists(), "VDMCheck2 is fetched by the CMake configure step (RL_VDMCHECK_JAR)"
    out = run_bounded([java, "-jar", jar, str(fmu_file(model, 2))], timeout=300, what="VDMCheck2")
    log = out.stdout + out.stderr
    assert out.returncode == 0, log
    assert log.strip().splitlines()[-1] == "No errors found.", log
