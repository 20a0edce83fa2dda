"""The project's reference scenarios (tests/scenarios), read and run by the
campaign runner of fmutrace, the product code the main job runs."""
from pathlib import Path

import fmutrace.campaign
from fmutrace.campaign import (FMI_VERSIONS, campaign, compare, fmu_path, load, same, simulate, write_outputs,
                               write_report)

__all__ = ["FMI_VERSIONS", "SCENARIO_ROOT", "campaign", "compare", "discover", "fmu_path", "load", "same", "simulate",
           "write_outputs", "write_report"]

SCENARIO_ROOT = Path(__file__).resolve().parents[1] / "scenarios"


def discover(models=None):
    return fmutrace.campaign.discover(SCENARIO_ROOT, models)
