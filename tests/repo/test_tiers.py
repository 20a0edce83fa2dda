"""Every pytest file is in a tier folder that a ctest test runs
(docs/testing.md, The pytest tiers): a test file left at the top of tests/
or in a folder of its own would be run by no ctest test."""

import re

from support.fmu_driver import REPO

TIERS = ("fmu", "integration", "fmutrace", "repo")


def test_every_test_file_is_in_a_tier():
    files = sorted((REPO / "tests").rglob("test_*.py"))
    assert files
    tiers = {REPO / "tests" / tier for tier in TIERS}
    outside = [str(p.relative_to(REPO)) for p in files if p.parent not in tiers]
    assert outside == [], f"move these into one of tests/{{{','.join(TIERS)}}}/"


def test_ctest_runs_every_tier():
    cmake = (REPO / "CMakeLists.txt").read_text()
    run = set(re.findall(r"^ *add_pytest_tier\(pytest_\w+ (\w+) ", cmake, re.MULTILINE))
    assert run == set(TIERS)
