"""The Python sources (product, tests, build scripts) have no unused
imports, undefined names or other mistakes pyflakes finds."""
import sys

from support.fmu_driver import REPO
from support.process import run


def test_pyflakes_finds_nothing():
    folders = [REPO / name for name in ("fmutrace", "tests", "benchmarks", "modelDescription")]
    done = run([sys.executable, "-m", "pyflakes", *map(str, folders)], timeout=120, what="pyflakes")
    assert done.returncode == 0, done.stdout + done.stderr
