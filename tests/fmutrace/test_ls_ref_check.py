"""fmutrace check: the experiments an FMI-LS-REF FMU carries, run and
compared as compare runs case folders (issue 43). Our FMUs' own
experiments; an LS-REF FMU another tool wrote, built here from the
standard's example manifest with its own stimuli and a reference worked by
hand (README's first simulation: RateLimiter, rateUpPar 2, u steps 0 -> 10
at t = 1, one 0.5 s cycle rises by 1); tampered files and checksums."""

import contextlib
import hashlib
import io
import json
import zipfile
from xml.etree import ElementTree

import pytest

import fmutrace
from fmutrace import cli
from fmutrace._lsref import wanted
from support.fmu_driver import BUILD_DIR, MODELS
from support.ls_ref import EXAMPLE, FOLDER
from support.scenarios import fmu_path

MANIFEST = f"{FOLDER}/fmi-ls-manifest.xml"
ONE_JOB = fmutrace.RunOptions(jobs=1)


def command(*args):
    out = io.StringIO()
    with contextlib.redirect_stderr(io.StringIO()) as err:
        status = cli.main([*map(str, args), "--jobs", "1"], out=out)
    return status, out.getvalue(), err.getvalue()


def rewritten(source, target, changes, drop=lambda name: False):
    """A copy of the FMU source with the entries changes names replaced (or added)."""
    with zipfile.ZipFile(source) as old, zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as new:
        for item in old.infolist():
            if item.filename not in changes and not drop(item.filename):
                new.writestr(item, old.read(item.filename))
        for name, data in changes.items():
            new.writestr(name, data)
    return target


def carried(name, model="RateLimiter", version=3):
    with zipfile.ZipFile(fmu_path(BUILD_DIR, model, version)) as z:
        return z.read(f"{FOLDER}/{name}")


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_every_fmu_passes_its_smoke_test(model, version, tmp_path):
    result = fmutrace.check(fmu_path(BUILD_DIR, model, version), role="smoke-test", run=ONE_JOB)
    assert result.passed, result.summary()
    assert len(result.cases) == 3


@pytest.mark.slow
@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_every_fmu_passes_its_validation(model, version):
    result = fmutrace.check(fmu_path(BUILD_DIR, model, version), role="validation", run=fmutrace.RunOptions(jobs=2))
    expected = len(list((BUILD_DIR.parent / "tests" / "scenarios" / model).glob(f"*/{model}_ref.csv")))
    assert result.passed, result.summary()
    assert len(result.cases) == expected


def test_the_command_reports_as_compare_does(tmp_path):
    fmu = fmu_path(BUILD_DIR, "RateLimiter", 3)
    status, out, err = command(
        "check", fmu, "--role", "smoke-test", "--report", tmp_path / "r", "--junit", tmp_path / "j.xml"
    )
    assert status == 0, out + err
    assert (tmp_path / "r" / "index.html").exists()
    junit = (tmp_path / "j.xml").read_text()
    assert junit.count("<testcase") == 3 and "<failure" not in junit
    # compare with the FMU alone does the same
    status, out, err = command("compare", fmu, "--role", "smoke-test")
    assert status == 0, out + err
    # --role chooses among carried experiments only
    status, _, err = command("compare", fmu, BUILD_DIR.parent / "tests" / "scenarios", "--role", "validation")
    assert status == 2 and "--role" in err


def test_fmus_of_one_model_run_its_experiments_each_and_are_each_checked(tmp_path):
    fmus = [fmu_path(BUILD_DIR, "RateLimiter", 2), fmu_path(BUILD_DIR, "RateLimiter", 3)]
    result = fmutrace.check(fmus, role="smoke-test", run=ONE_JOB)
    assert result.passed and len(result.cases) == 6, result.summary()
    reference = "asymmetric/reference.csv"
    tampered = rewritten(fmus[1], tmp_path / "RateLimiter.fmu", {f"{FOLDER}/{reference}": b"time,y\n0,0\n"})
    status, _, err = command("check", fmus[0], tampered, "--role", "smoke-test")
    assert status == 2 and f"{tampered}: {FOLDER}/{reference}: its SHA-256" in err, err


def test_a_changed_reference_fails_its_checksum(tmp_path):
    reference = "asymmetric/reference.csv"
    data = carried(reference).replace(b"\n2.5,3\n", b"\n2.5,3.5\n")
    assert data != carried(reference)
    fmu = rewritten(
        fmu_path(BUILD_DIR, "RateLimiter", 3), tmp_path / "RateLimiter.fmu", {f"{FOLDER}/{reference}": data}
    )
    status, out, err = command("check", fmu)
    assert status == 2, out + err
    assert f"{FOLDER}/{reference}: its SHA-256 is not the manifest's" in err


def test_a_changed_checksum_fails_and_a_consistent_change_is_a_difference(tmp_path):
    source = fmu_path(BUILD_DIR, "RateLimiter", 3)
    reference = "asymmetric/reference.csv"
    manifest = carried("fmi-ls-manifest.xml").decode()
    old = hashlib.sha256(carried(reference)).hexdigest()
    fmu = rewritten(source, tmp_path / "a.fmu", {MANIFEST: manifest.replace(old, "0" * 64)})
    status, _, err = command("check", fmu, "--role", "smoke-test")
    assert status == 2 and "its SHA-256 is not the manifest's" in err
    # the reference changed and its checksum with it: the FMU now differs from it (y at 2.5 s is 3, docs/rules.md)
    data = carried(reference).replace(b"\n2.5,3\n", b"\n2.5,3.5\n")
    new = hashlib.sha256(data).hexdigest()
    fmu = rewritten(source, tmp_path / "b.fmu", {MANIFEST: manifest.replace(old, new), f"{FOLDER}/{reference}": data})
    result = fmutrace.check(fmu, role="validation", run=ONE_JOB)
    failed = [o.case for o in result.failed(results=False)]
    assert failed == ["validation/asymmetric"], result.summary()
    assert result.exit_code == 1


def test_the_criteria_a_reference_carries_judge_it(tmp_path):
    """A reference 0.5 off at 2.5 s: its carried criterion (exact) fails it
    whatever the user's tolerance; a carried tolerance of 1 passes it."""
    source = fmu_path(BUILD_DIR, "RateLimiter", 3)
    reference = "asymmetric/reference.csv"
    manifest = carried("fmi-ls-manifest.xml").decode()
    data = carried(reference).replace(b"\n2.5,3\n", b"\n2.5,3.5\n")
    manifest = manifest.replace(hashlib.sha256(carried(reference)).hexdigest(), hashlib.sha256(data).hexdigest())
    changes = {MANIFEST: manifest, f"{FOLDER}/{reference}": data}
    fmu = rewritten(source, tmp_path / "a.fmu", changes)
    assert command("check", fmu, "--role", "validation", "--abs-tol", "1")[0] == 1
    start = manifest.index(f'source="{reference}"')
    criterion = 'signal="y" mode="exact"'
    at = manifest.index(criterion, start)
    changes[MANIFEST] = manifest[:at] + 'signal="y" mode="tol:abs=1,rel=0"' + manifest[at + len(criterion) :]
    fmu = rewritten(source, tmp_path / "b.fmu", changes)
    status, out, err = command("check", fmu, "--role", "validation")
    assert status == 0, out + err


def test_a_bad_manifest_is_bad_input(tmp_path):
    source = fmu_path(BUILD_DIR, "RateLimiter", 3)
    for manifest, message in [
        (b"<fmiReferences", "not XML"),
        (b"<other/>", "not an FMI-LS-REF manifest"),
    ]:
        fmu = rewritten(source, tmp_path / "x.fmu", {MANIFEST: manifest})
        status, _, err = command("check", fmu)
        assert status == 2 and message in err, err
    bare = rewritten(source, tmp_path / "bare.fmu", {}, drop=lambda name: name.startswith(FOLDER))
    status, _, err = command("check", bare)
    assert status == 2 and "carries no FMI-LS-REF experiments" in err, err


def test_an_fmu_without_experiments_leaves_the_others_checked(tmp_path):
    """check of several FMUs, one of them without experiments (listed first,
    of the same model as another): the others' experiments run and pass,
    the bare one is named, and the call ends as for bad input (2)."""
    source = fmu_path(BUILD_DIR, "RateLimiter", 3)
    bare = rewritten(source, tmp_path / "bare.fmu", {}, drop=lambda name: name.startswith(FOLDER))
    others = [source, fmu_path(BUILD_DIR, "RateLimiter", 2)]
    status, out, err = command("check", bare, *others, "--role", "smoke-test")
    assert status == 2, out + err
    assert f"fmutrace: error: {bare} carries no FMI-LS-REF experiments" in err and "not checked" in err, err
    assert "6 of 6 cases pass" in out, out  # (each FMU's 3 smoke tests)
    result = fmutrace.check([bare, *others], role="smoke-test", run=ONE_JOB)
    assert len(result.cases) == 6 and not result.passed and result.exit_code == 2
    assert [p.split(":")[0] for p in result.problems] == [f"{bare} carries no FMI-LS-REF experiments (no {MANIFEST})"]
    with pytest.raises(fmutrace.InputError, match="carries no FMI-LS-REF experiments"):
        fmutrace.check([bare, bare], run=ONE_JOB)


def test_an_fmu_left_out_of_a_check_is_named_in_its_report_and_junit(tmp_path):
    """check with a report and JUnit XML of an FMU without experiments and one with: results.json lists
    it under not_run, summary.md and index.html name it, and the JUnit XML has an error for it."""
    source = fmu_path(BUILD_DIR, "RateLimiter", 3)
    bare = rewritten(source, tmp_path / "bare.fmu", {}, drop=lambda name: name.startswith(FOLDER))
    report, junit = tmp_path / "report", tmp_path / "junit.xml"
    status, out, err = command("check", bare, source, "--role", "smoke-test", "--report", report, "--junit", junit)
    assert status == 2, out + err
    results = json.loads((report / "results.json").read_text())
    [left_out] = results["not_run"]
    assert left_out.startswith(f"{bare} carries no FMI-LS-REF experiments") and left_out.endswith("not checked")
    assert len(results["cases"]) == 3 and not results["passed"]
    [said] = [line for line in (report / "summary.md").read_text().splitlines() if line.startswith("- not run: ")]
    assert said.replace("\\", "").startswith(f"- not run: {bare} carries no FMI-LS-REF experiments")  # (unescaped)
    assert f'<p class="not-run">not run: {bare} carries' in (report / "index.html").read_text()
    suites = ElementTree.parse(junit).getroot()
    [suite] = [s for s in suites if s.get("name") == "not run"]
    assert suite.get("errors") == "1" and suite[0][0].get("message") == left_out


# ---- an LS-REF FMU another tool wrote ------------------------------------------------

# its stimuli and reference: README's first simulation, worked by hand
STIMULI = "Time;u\n0;0\n1;10\n"  # another dialect: ';' and 'Time'
TIMES = [k / 2 for k in range(17)]
REFERENCE = "time,y\n" + "".join(f"{t},{min(max(2 * (t - 1), 0), 10):g}\n" for t in TIMES)
EXPERIMENTS = """<?xml version="1.0" encoding="UTF-8"?>
<Experiments name="smoke tests">
  <Experiment name="step" startTime="0" stopTime="8" stepSize="0.5">
    <Parameters type="application/x-ssp-parameter-set" source="baseline-params.ssv"/>
    <Stimuli type="text/csv" source="data/step_in.csv"/>
    <References type="text/csv" source="data/step_ref.csv"/>
  </Experiment>
</Experiments>
"""
BASELINE = """<?xml version="1.0" encoding="UTF-8"?>
<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="baseline">
  <ssv:Parameters>
    <ssv:Parameter name="rateUpPar"><ssv:Real value="2"/></ssv:Parameter>
  </ssv:Parameters>
</ssv:ParameterSet>
"""


def foreign_fmu(tmp_path, reference=REFERENCE):
    """RateLimiter (FMI 3) without our experiments, with the standard's
    example manifest as it is (it names files that are not there: a model
    source, other parameter sets, meta-data) and the files its experiment
    needs: no checksums, no criteria."""
    changes = {
        MANIFEST: EXAMPLE.read_bytes(),
        f"{FOLDER}/smoke-tests.exp": EXPERIMENTS,
        f"{FOLDER}/baseline-params.ssv": BASELINE,
        f"{FOLDER}/data/step_in.csv": STIMULI,
        f"{FOLDER}/data/step_ref.csv": reference,
    }
    return rewritten(
        fmu_path(BUILD_DIR, "RateLimiter", 3), tmp_path / "Foreign.fmu", changes, lambda n: n.startswith(FOLDER)
    )


def test_the_reference_is_the_one_worked_by_hand():
    assert REFERENCE.splitlines()[1:5] == ["0.0,0", "0.5,0", "1.0,0", "1.5,1"]
    assert REFERENCE.splitlines()[-5:] == ["6.0,10", "6.5,10", "7.0,10", "7.5,10", "8.0,10"]


def test_an_ls_ref_fmu_another_tool_wrote_is_checked(tmp_path):
    fmu = foreign_fmu(tmp_path)
    status, out, err = command("check", fmu)
    assert status == 0, out + err
    assert "1 of 1 cases pass" in out, out
    # an experiment without a sub-role is a smoke test (the standard); it is no validation
    assert command("check", fmu, "--role", "smoke-test")[0] == 0
    status, _, err = command("check", fmu, "--role", "validation")
    assert status == 2 and "carries no experiment of role validation" in err


def test_without_criteria_the_users_choice_judges(tmp_path):
    off = REFERENCE.replace("\n1.5,1\n", "\n1.5,1.000000001\n")
    fmu = foreign_fmu(tmp_path, off)
    assert command("check", fmu)[0] == 1  # the stated default: bit for bit
    assert command("check", fmu, "--abs-tol", "1e-8")[0] == 0
    assert command("check", fmu, "--abs-tol", "1e-10")[0] == 1


def test_an_experiment_file_outside_the_fmu_is_refused(tmp_path):
    fmu = foreign_fmu(tmp_path)
    escaped = EXPERIMENTS.replace("data/step_ref.csv", "../../../step_ref.csv")
    bad = rewritten(fmu, tmp_path / "Escaped.fmu", {f"{FOLDER}/smoke-tests.exp": escaped})
    status, _, err = command("check", bad)
    assert status == 2 and "leaves the FMU" in err, err


def test_which_experiment_files_run():
    # no sub-role: a smoke test (the standard); an uncertainty analysis has no reference to compare with
    assert [wanted("experiment", r) for r in (None, "smoke-test", "validation")] == [True, True, False]
    assert [wanted("experiment/validation", r) for r in (None, "smoke-test", "validation")] == [True, False, True]
    assert not any(wanted("experiment/uncertainty-analysis", r) for r in (None, "smoke-test", "validation"))
    assert not wanted("parameter", None) and not wanted("result", None)


def test_experiment_names_stay_inside_the_case_folder(tmp_path):
    """An experiment's name becomes a folder: '../..' and separators are
    made safe, two experiments of one name both run; a source may be
    percent-encoded (a relative URI)."""
    experiments = EXPERIMENTS.replace('name="step"', 'name="../../escape"')
    second = experiments[experiments.index("  <Experiment ") : experiments.index("</Experiments>")]
    second = second.replace('stepSize="0.5"', 'stepSize="0.5" tolerance="1e-6"')  # another experiment, one name
    experiments = experiments.replace("</Experiments>", second + "</Experiments>")
    experiments = experiments.replace('source="data/step_ref.csv"', 'source="data/step%5Fref.csv"', 1)
    fmu = rewritten(foreign_fmu(tmp_path), tmp_path / "Named.fmu", {f"{FOLDER}/smoke-tests.exp": experiments})
    result = fmutrace.check(fmu, run=ONE_JOB, report=tmp_path / "report")
    assert result.passed and len(result.cases) == 2, result.summary()
    assert not (tmp_path / "escape").exists() and not (tmp_path / "report" / "escape").exists()
    root = (tmp_path / "report" / "experiments").resolve()  # <root>/<n>-<Model>/<file>/<experiment>/
    written = sorted((tmp_path / "report" / "experiments").rglob("RateLimiter_ref.csv"))
    assert len(written) == 2 and all(p.resolve().parents[3] == root for p in written), written
    assert written[0].parent.name + "-2" == written[1].parent.name  # one name, made unique
