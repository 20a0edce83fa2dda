"""fmutrace installed as a user installs it, and its pinned requirements
on Windows. Both reach the package index with pip's defaults, and take
minutes: marked slow and network (`-m "not slow"` leaves them out).

- `pip install ./fmutrace` into a fresh virtual environment, from the
  dependencies pyproject.toml declares alone (not the build's pinned
  requirements), then the README's fmutrace commands through the
  installed console script, the report included: a package the code
  imports and pyproject.toml forgets fails here (pyarrow once did, at the
  report).
- `pip download --platform win_amd64 --only-binary=:all:` of every pinned
  requirement: each has a Windows wheel for Python 3.11 (docs/fmutrace.md,
  "Windows").
"""

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from support.fmu_driver import BUILD_DIR

REPO = Path(__file__).resolve().parents[2]
pytestmark = [pytest.mark.slow, pytest.mark.network]


def readme_commands():
    """The fmutrace command lines of the README's sh blocks, as words."""
    text = (REPO / "README.md").read_text()
    blocks = re.findall(r"```sh\n(.*?)```", text, re.S)
    return [
        shlex.split(line)
        for block in blocks
        for line in block.splitlines()
        if line.startswith("build/venv/bin/fmutrace ")
    ]


def run(args, **kwargs):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=1800, **kwargs)


@pytest.mark.timeout(3000)  # the downloads and the install
def test_the_readme_commands_run_in_a_fresh_environment_from_the_declared_dependencies(tmp_path):
    venv = tmp_path / "venv"
    made = run([sys.executable, "-m", "venv", venv])
    assert made.returncode == 0, made.stderr
    bin_dir = venv / ("Scripts" if os.name == "nt" else "bin")
    # the package's own folder, copied: the install builds there, and must not depend on the build's venv
    source = tmp_path / "fmutrace-source"
    shutil.copytree(
        REPO / "fmutrace", source, ignore=shutil.ignore_patterns("*.so", "*.pyd", "__pycache__", "*.egg-info", "build")
    )
    installed = run([bin_dir / "python", "-m", "pip", "install", "--quiet", source])
    assert installed.returncode == 0, installed.stdout[-3000:] + installed.stderr[-3000:]

    commands = readme_commands()
    assert len(commands) >= 3, commands  # compare with a report, run, compare a recording
    work = tmp_path / "work"
    (work / "build").mkdir(parents=True)
    for version in ("fmi2", "fmi3"):
        (work / "build" / version).symlink_to(BUILD_DIR / version)
    shutil.copytree(REPO / "tests" / "scenarios" / "RateLimiter", work / "my_traces")
    shutil.copytree(REPO / "tests" / "recordings", work / "tests" / "recordings")
    # u.csv as the README makes it: u steps from 0 to 10 at t = 1 s
    (work / "u.csv").write_text("time,u\n0,0\n1,10\n")
    environment = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    for words in commands:
        done = run([bin_dir / "fmutrace", *words[1:]], cwd=work, env=environment)
        assert done.returncode == 0, f"{shlex.join(words)}: {done.stdout[-2000:]} {done.stderr[-2000:]}"
        assert "Traceback" not in done.stderr, done.stderr
    assert (work / "my_report" / "index.html").exists() and (work / "my_report" / "results.json").exists()
    result = (work / "y.csv").read_text().splitlines()
    assert result[0].startswith('"time","y"') and len(result) == 1 + 81  # 0 to 8 s in steps of 0.1 s
    # y holds 0 until the step at t = 1, which the cycle (1, 1.1] sees; then it rises at 2 per second
    y = [float(line.split(",")[1]) for line in result[1:]]
    assert y[:11] == [0.0] * 11 and y[11:14] == pytest.approx([0.2, 0.4, 0.6], abs=1e-12) and y[60:] == [10.0] * 21


def test_every_pinned_requirement_has_a_windows_wheel(tmp_path):
    done = run(
        [
            sys.executable,
            "-m",
            "pip",
            "download",
            "--quiet",
            "--platform",
            "win_amd64",
            "--only-binary=:all:",
            "--python-version",
            "3.11",
            "-r",
            REPO / "fmutrace" / "requirements.txt",
            "-d",
            tmp_path / "wheels",
        ]
    )
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert any(
        p.name.startswith("numpy-") and p.name.endswith("-win_amd64.whl") for p in (tmp_path / "wheels").iterdir()
    )
