"""Comments cite the rules by the headings of the repository's own docs
("rules.md, rule 5b", "fmi.md, FMI behaviour"): every such citation in the
C sources, the model descriptions, the tests and the benchmarks names a
heading that is there, and the C sources cite no document outside the
repository."""
import re

import pytest

from support.fmu_driver import REPO

DOCS = ("rules.md", "fmi.md", "models.md")
CITATION = re.compile(r"\b(rules|fmi|models)\.md, ([^\n.;:)]+)")
SOURCES = [p for pattern in ("fmu_src/**/*.[ch]", "modelDescription/*.toml", "modelDescription/*.py",
                             "tests/**/*.py", "tests/c/*.c", "tests/fuzz/*.c", "benchmarks/*.py", "benchmarks/*.c")
           for p in sorted(REPO.glob(pattern))]


def headings(doc):
    return [line.lstrip("#").strip().lower() for line in (REPO / "docs" / doc).read_text().splitlines()
            if line.startswith("#")]


def cited_heading(doc, words):
    """The heading a citation names: one that starts with its words, which
    may run on over a line break and comment marks."""
    words = " ".join(re.sub(r"^\s*(\*|#)", " ", words).split()).lower()
    return next((h for h in headings(doc) if h.startswith(words) or words.startswith(h)), None)


@pytest.mark.parametrize("source", SOURCES, ids=lambda p: str(p.relative_to(REPO)))
def test_citations_name_headings(source):
    if source == REPO / "tests" / "test_citations.py":
        return
    text = source.read_text()
    for match in CITATION.finditer(text):
        doc, words = f"{match.group(1)}.md", match.group(2)
        assert cited_heading(doc, words), f"{source.name}: '{match.group(0)}' names no heading of docs/{doc}"


def test_c_sources_cite_no_document_outside_the_repository():
    for source in sorted(REPO.glob("fmu_src/**/*.[ch]")):
        assert "SPEC" not in source.read_text(), source.name


def test_every_rule_has_its_heading():
    rules = headings("rules.md")
    for rule in ["0", "1", "2", "3", "4", "5", "5b", "6"]:
        assert any(h.startswith(f"rule {rule}:") for h in rules), rule
    for section in ("status words", "initialisation", "outputs derived from the last cycle",
                    "output limits, rates below 0 and hold"):
        assert section in rules
