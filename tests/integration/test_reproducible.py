"""The .fmu files depend on their contents alone: packaging the same staged
files again, copied elsewhere (new access and change times), with other
permission bits (umask) and, where the test may, another owner, gives the
same bytes. Without zip_normalize they differ (the control)."""

import os
import re
import shutil
import zipfile

import pytest

from support.fmu_driver import BUILD_DIR, MODELS as PRODUCT_MODELS, REPO, SCHEDULED_EXECUTION_FOLDER, fmu_file
from support.process import run as run_bounded

MODELS = PRODUCT_MODELS + ["PassThrough"]


def build_setting(pattern, text):
    match = re.search(pattern, text, re.M)
    assert match, pattern
    return match.group(1)


def cmake_command():
    """The build's own CMake: the venv's pip cmake may bring another libarchive."""
    return build_setting(r"^CMAKE_COMMAND:INTERNAL=(.*)$", (BUILD_DIR / "CMakeCache.txt").read_text())


def zip_mtime():
    return build_setting(r'set\(FMU_ZIP_MTIME "([^"]+)"\)', (REPO / "cmake" / "Fmu.cmake").read_text())


def fmu_path(model, version, scheduled=False):
    path = fmu_file(model, version, scheduled)
    return path if path.exists() else BUILD_DIR / "benchmarks" / f"fmi{version}" / f"{model}.fmu"


def repackage(model, version, tmp_path, normalize, scheduled=False):
    """Stage the FMU's files again, disturbed, and package them as the build does."""
    built = fmu_path(model, version, scheduled)
    names = zipfile.ZipFile(built).namelist()
    stage = tmp_path / "stage"
    folder = SCHEDULED_EXECUTION_FOLDER if scheduled else f"fmi{version}"
    shutil.copytree(BUILD_DIR / "stage" / folder / model, stage)
    for name in names:
        path = stage / name
        os.chmod(path, os.stat(path).st_mode | 0o020)  # as under umask 002
        os.utime(path, (1234567890, os.stat(path).st_mtime))
        if os.geteuid() == 0:
            os.chown(path, 1234, 5678)
    out = tmp_path / f"{model}.fmu"
    # as the build runs them: without the sanitizer tree's preloaded runtime
    # (under it cmake -E tar hangs), which an instrumented tool links anyway
    env = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
    run_bounded(
        [cmake_command(), "-E", "tar", "cf", str(out), "--format=zip", f"--mtime={zip_mtime()}", "--", *names],
        cwd=stage,
        env=env,
        check=True,
        timeout=120,
        what="cmake -E tar (packaging)",
    )
    if normalize:
        run_bounded(
            [str(BUILD_DIR / "zip_normalize"), str(out)], env=env, check=True, timeout=120, what="zip_normalize"
        )
    return built.read_bytes(), out.read_bytes()


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_fmu_bytes_depend_on_contents_alone(model, version, tmp_path):
    built, again = repackage(model, version, tmp_path, normalize=True)
    assert again == built
    assert zipfile.ZipFile(fmu_path(model, version)).testzip() is None


@pytest.mark.parametrize("model", PRODUCT_MODELS)
def test_scheduled_execution_fmu_bytes_depend_on_contents_alone(model, tmp_path):
    built, again = repackage(model, 3, tmp_path, normalize=True, scheduled=True)
    assert again == built
    assert zipfile.ZipFile(fmu_path(model, 3, scheduled=True)).testzip() is None


@pytest.mark.parametrize("version", [2, 3])
def test_without_normalizing_the_bytes_differ(version, tmp_path):
    built, again = repackage("RateLimiter", version, tmp_path, normalize=False)
    assert again != built


def test_normalized_entries_carry_no_machine_or_user_data():
    for version in (2, 3):
        with zipfile.ZipFile(fmu_file("RateLimiter", version)) as z:
            for info in z.infolist():
                mode = info.external_attr >> 16
                assert mode & 0o7777 in (0o644, 0o755), (info.filename, oct(mode))
                assert info.date_time == (2000, 1, 1, 0, 0, 0)
                # local header: "UT" times all equal the modification time, "ux" owner 0/0
                z.fp.seek(info.header_offset)
                header = z.fp.read(30)
                name_length, extra_length = (
                    int.from_bytes(header[26:28], "little"),
                    int.from_bytes(header[28:30], "little"),
                )
                extra = z.fp.read(name_length + extra_length)[name_length:]
                fields = {}
                at = 0
                while at + 4 <= len(extra):
                    tag, size = (
                        int.from_bytes(extra[at : at + 2], "little"),
                        int.from_bytes(extra[at + 2 : at + 4], "little"),
                    )
                    fields[tag] = extra[at + 4 : at + 4 + size]
                    at += 4 + size
                times = fields[0x5455][1:]
                assert len(times) == 12 and times[0:4] == times[4:8] == times[8:12], info.filename
                owner = fields[0x7875]
                assert owner[1:] == bytes([4, 0, 0, 0, 0, 4, 0, 0, 0, 0]), info.filename
