"""Comments and docs cite the rules by the headings of the repository's own
docs ("rules.md, rule 5b", "fmi.md, FMI behaviour"): every such citation in
what the repository ships (C sources, model descriptions, fmutrace, tests and
their scenario READMEs, benchmarks, build files, docs) names a heading that
is there, and none of it cites a document outside the repository: neither the
contract the rules were first written in nor the vendor documents by the
numbers they were handed over under."""

import re

import pytest

from support.fmu_driver import REPO

DOCS = ("rules.md", "fmi.md", "models.md")
CITATION = re.compile(r"\b(rules|fmi|models)\.md, \"?([^\n.;:)\]\"]+)")
SHIPPED = (
    "README.md",
    "CMakeLists.txt",
    ".ci/run",
    "cmake/**/*",
    "docs/*.md",
    "fmu_src/**/*.[ch]",
    "modelDescription/**/*.toml",
    "modelDescription/*.py",
    "fmutrace/*.toml",
    "fmutrace/*.txt",
    "fmutrace/src/**/*.py",
    "tests/**/*.py",
    "tests/**/README.md",
    "tests/*.txt",
    "tests/*.ini",
    "tests/*.sh",
    "tests/c/*.[ch]",
    "tests/fuzz/*.c",
    "tests/fixtures/**/*.[ch]",
    "tests/fixtures/**/*.toml",
    "benchmarks/**/*.py",
    "benchmarks/**/*.[ch]",
    "benchmarks/**/*.toml",
)
SOURCES = sorted(
    {p for pattern in SHIPPED for p in REPO.glob(pattern) if p.is_file()}
    - {REPO / "tests" / "repo" / "test_citations.py"}
)
# The contract by its name, a vendor document by the number it was handed over under.
OUTSIDE = re.compile(r"\bSPEC\b|\b[Ss]eed 00\d\b|\.\./shared/")


def headings(doc):
    return [
        line.lstrip("#").strip().lower()
        for line in (REPO / "docs" / doc).read_text().splitlines()
        if line.startswith("#")
    ]


def cited_heading(doc, words):
    """The heading a citation names: one that starts with its words, which
    may run on over a line break and comment marks."""
    words = " ".join(re.sub(r"^\s*(\*|#)", " ", words).split()).lower()
    return next((h for h in headings(doc) if h.startswith(words) or words.startswith(h)), None)


@pytest.mark.parametrize("source", SOURCES, ids=lambda p: str(p.relative_to(REPO)))
def test_citations_name_headings(source):
    text = source.read_text()
    for match in CITATION.finditer(text):
        doc, words = f"{match.group(1)}.md", match.group(2)
        assert cited_heading(doc, words), (
            f"{source.relative_to(REPO)}: '{match.group(0)}' names no heading of docs/{doc}"
        )


def test_nothing_shipped_cites_a_document_outside_the_repository():
    for source in SOURCES:
        for number, line in enumerate(source.read_text().splitlines(), 1):
            assert not OUTSIDE.search(line), f"{source.relative_to(REPO)}:{number}: {line.strip()}"


def test_the_outside_check_reads_every_kind_of_file_shipped():
    shipped = {str(p.relative_to(REPO)) for p in SOURCES}
    for path in (
        "README.md",
        "docs/rules.md",
        "fmu_src/fmu_core.c",
        "modelDescription/Ramp.toml",
        "fmutrace/src/fmutrace/_runner.py",
        "tests/scenarios/Ramp/real_slow_ramp/README.md",
        "tests/support/oracle.py",
        "benchmarks/fmu_bench.c",
        "CMakeLists.txt",
    ):
        assert path in shipped, path
    assert OUTSIDE.search("as " + "SPEC section 8 has it") and OUTSIDE.search("Seed" + " 002: quoted")
    assert not OUTSIDE.search("SPECIAL = [0.0]") and not OUTSIDE.search("--seed 1")


def test_every_rule_has_its_heading():
    rules = headings("rules.md")
    for rule in ["0", "1", "2", "3", "4", "5", "5b", "6"]:
        assert any(h.startswith(f"rule {rule}:") for h in rules), rule
    for section in (
        "status words",
        "initialisation",
        "outputs derived from the last cycle",
        "output limits, rates below 0 and hold",
    ):
        assert section in rules
