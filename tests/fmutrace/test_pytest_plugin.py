"""fmutrace's pytest plugin, as a user's pytest loads it (the package's
pytest11 entry point; pytester runs pytest in a process of its own): every
case folder and recording an item per FMU named by the case, a failing
item showing the case's messages, and -k, -x, --lf, xdist and JUnit
working on them. The reference scenarios pass as items; a case whose
reference's last output is changed by hand (one more) fails."""

import shutil
import tomllib
from xml.etree import ElementTree

import pytest

from support.fmu_driver import BUILD_DIR, REPO
from support.scenarios import SCENARIO_ROOT, fmu_path

pytest_plugins = ["pytester"]

FMUS = [fmu_path(BUILD_DIR, "RateLimiter", version) for version in (3, 2)]
SCENARIOS = sorted(p.name for p in (SCENARIO_ROOT / "RateLimiter").iterdir() if p.is_dir())


def cases(pytester, names=("asymmetric", "step_down"), wrong=()):
    """Copies of the scenarios names into the pytester folder's cases/,
    those in wrong with their reference's last y one more; an ini file
    there, as a project has (the root of the items' names)."""
    pytester.makeini("[pytest]\n")
    root = pytester.path / "cases"
    for name in names:
        shutil.copytree(SCENARIO_ROOT / "RateLimiter" / name, root / name)
        if name in wrong:
            reference = root / name / "RateLimiter_ref.csv"
            *rows, last = reference.read_text().splitlines()
            assert rows[0].split(",")[:2] == ["time", "y"]
            t, y, *rest = last.split(",")
            reference.write_text("\n".join([*rows, ",".join([t, repr(float(y) + 1), *rest])]) + "\n")
    return root


def fmu_args(*versions):
    return [arg for v in versions for arg in ("--fmu", str(fmu_path(BUILD_DIR, "RateLimiter", v)))]


def test_pytest_is_no_dependency_of_fmutrace_and_the_plugin_its_entry_point():
    project = tomllib.loads((REPO / "fmutrace" / "pyproject.toml").read_text())["project"]
    assert not [d for d in project["dependencies"] if d.lower().startswith("pytest")]
    assert project["entry-points"]["pytest11"] == {"fmutrace": "fmutrace.pytest_plugin"}


@pytest.mark.slow
def test_the_reference_scenarios_are_items_named_by_the_case_and_pass(pytester):
    root = cases(pytester, SCENARIOS)
    collected = pytester.runpytest_subprocess(*fmu_args(3, 2), root, "--collect-only", "-q")
    items = sorted(line for line in collected.outlines if "::" in line)
    assert items == sorted(
        f"cases/{name}/RateLimiter_ref.csv::{name}[RateLimiter-fmi{v}]" for name in SCENARIOS for v in (2, 3)
    )
    result = pytester.runpytest_subprocess(*fmu_args(3, 2), root, "-n", "2")
    result.assert_outcomes(passed=2 * len(SCENARIOS))


def test_a_failing_item_shows_the_case_messages(pytester):
    root = cases(pytester, wrong=("asymmetric",))
    result = pytester.runpytest_subprocess(*fmu_args(3), root)
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines(
        [
            "*_ asymmetric[[]RateLimiter-fmi3[]] _*",
            "FAIL  asymmetric on RateLimiter (FMI 3)",
            "      y*",
        ]
    )
    assert "Traceback" not in result.stdout.str()


@pytest.mark.slow
def test_k_x_lf_and_junit_work_on_the_items(pytester):
    root = cases(pytester, ("asymmetric", "step_down", "step_up"), wrong=("asymmetric", "step_down"))
    chosen = pytester.runpytest_subprocess(*fmu_args(3, 2), root, "-k", "step_up and fmi2")
    chosen.assert_outcomes(passed=1)
    stopped = pytester.runpytest_subprocess(*fmu_args(3), root, "-x")
    stopped.assert_outcomes(failed=1)  # (asymmetric, the first, fails: nothing after it runs)
    junit = pytester.path / "junit.xml"
    everything = pytester.runpytest_subprocess(*fmu_args(3), root, f"--junitxml={junit}")
    everything.assert_outcomes(passed=1, failed=2)
    last_failed = pytester.runpytest_subprocess(*fmu_args(3), root, "--lf", "-v")
    last_failed.assert_outcomes(failed=2)
    assert "step_up" not in last_failed.stdout.str()
    suite = ElementTree.parse(junit).getroot()
    verdicts = {case.get("name"): [child.tag for child in case] for case in suite.iter("testcase")}
    assert verdicts == {
        "asymmetric[RateLimiter-fmi3]": ["failure"],
        "step_down[RateLimiter-fmi3]": ["failure"],
        "step_up[RateLimiter-fmi3]": [],
    }


def test_the_fmus_from_the_ini_file_and_a_recording_named(pytester):
    """fmutrace_fmus in the ini file (relative to it); a recording named on
    the command line is an item too (README's TwinCAT export of the Siemens
    block)."""
    model = "LGF_LimRateOfChangeCI"
    shutil.copy(fmu_path(BUILD_DIR, model, 3), pytester.path / f"{model}.fmu")
    pytester.makeini(f"[pytest]\nfmutrace_fmus =\n    {model}.fmu\n")
    recording = pytester.path / "twincat_siemens.csv"
    shutil.copy(REPO / "tests" / "recordings" / "twincat_siemens.csv", recording)
    result = pytester.runpytest_subprocess(recording, "-v")
    result.assert_outcomes(passed=1)
    result.stdout.fnmatch_lines(["twincat_siemens.csv::twincat_siemens[[]LGF_LimRateOfChangeCI-fmi3[]] PASSED*"])


@pytest.mark.slow
def test_without_fmus_the_plugin_collects_nothing(pytester):
    root = cases(pytester)
    result = pytester.runpytest_subprocess(root)
    assert result.ret == pytest.ExitCode.NO_TESTS_COLLECTED
