"""The mutation runner's bookkeeping (tests/support/mutation.py): how the
list of equivalent mutants names a mutant, what a resumed run keeps from
the journal, and how mutants with the same object code share an outcome.
The runs themselves: ctest mutation_sample."""

import json

import pytest

from support.mutation import Journal, Mutant, read_equivalents, report_failures, settle

LIST = """# comment
fmu_src/fmu_core.c
  - x = 0;
  + x = 1;
  why: plain entry.

fmu_src/fmu_core.c
  - } else {
  + }  {
  above: b = 2;
  above: a = 1;
  why: named by the two lines above it.
"""


def mutant(before, after, above=(), text="text"):
    return Mutant("fmu_core.c", 10, before, after, text, above=tuple(above))


def test_an_entry_names_a_mutant_by_its_line_or_also_by_the_lines_above(tmp_path):
    path = tmp_path / "list.txt"
    path.write_text(LIST)
    equivalents = read_equivalents(path)
    assert len(equivalents) == 2
    assert mutant("  x = 0;", "  x = 1;", ["anything"]).proof(equivalents) == "plain entry."
    assert mutant("x = 0;", "x = 2;").proof(equivalents) is None
    assert (
        mutant("} else {", "}  {", ["b = 2;", "a = 1;", "z"]).proof(equivalents) == "named by the two lines above it."
    )
    assert mutant("} else {", "}  {", ["b = 2;", "other"]).proof(equivalents) is None  # another line like it
    assert mutant("} else {", "}  {", ["b = 2;"]).proof(equivalents) is None


def test_an_entry_with_several_spellings_gives_each_its_proof(tmp_path):
    path = tmp_path / "list.txt"
    path.write_text("fmu_src/fmu_core.c\n  - x = y - 1;\n  + x = y * 1;\n  + x = y / 1;\n  why: both read y.\n")
    equivalents = read_equivalents(path)
    assert len(equivalents) == 2
    assert mutant("x = y - 1;", "x = y * 1;").proof(equivalents) == "both read y."
    assert mutant("x = y - 1;", "x = y / 1;").proof(equivalents) == "both read y."
    assert mutant("x = y - 1;", "x = y - 0;").proof(equivalents) is None


def test_a_list_entry_without_its_lines_is_refused(tmp_path):
    path = tmp_path / "list.txt"
    path.write_text("fmu_src/fmu_core.c\n  + x = 1;\n  why: no '-' line.\n")
    with pytest.raises(SystemExit, match="'why:' without its file, '-' and '\\+' lines"):
        read_equivalents(path)


def test_a_mutant_listed_twice_is_refused(tmp_path):
    path = tmp_path / "list.txt"
    path.write_text(LIST + LIST.split("\n\n")[0].replace("# comment\n", "\n") + "\n")
    with pytest.raises(SystemExit, match="this mutant is listed already"):
        read_equivalents(path)


def test_a_resumed_run_keeps_kills_always_and_survivors_of_the_same_tests(tmp_path):
    path = tmp_path / "journal.jsonl"
    killed, survived, stillborn = (mutant("a;", f"b{k};", text=str(k)) for k in range(3))
    for m, identity in ((killed, "k"), (survived, "s"), (stillborn, "x")):
        m.identity = identity
    journal = Journal(path, resume=False, tests="tests-1")
    journal.record(killed, "killed", "FAILED test_x")
    journal.record(survived, "survived", "")
    journal.record(stillborn, "stillborn", "error: ...")
    journal.close()
    with open(path, "a") as cut:  # a line cut by a kill
        cut.write('{"identity": "t", "outcome": "kil')
    same = Journal(path, resume=True, tests="tests-1")
    same.close()
    assert same.kept == {"k": ("killed", "FAILED test_x"), "s": ("survived", ""), "x": ("stillborn", "error: ...")}
    other = Journal(path, resume=True, tests="tests-2")
    other.close()
    assert set(other.kept) == {"k", "x"}  # a survivor meets the new tests
    records = [
        json.loads(line) for line in path.read_text().splitlines() if line.startswith("{") and line.endswith("}")
    ]
    assert [r["identity"] for r in records] == ["k", "s", "x"] and records[1]["tests"] == "tests-1"
    fresh = Journal(path, resume=False, tests="tests-1")  # not resumed: a new journal
    fresh.close()
    assert fresh.kept == {} and path.read_text().strip() == ""


def test_mutants_with_the_same_object_code_share_the_tested_ones_outcome(tmp_path):
    path = tmp_path / "list.txt"
    path.write_text(LIST)
    equivalents = read_equivalents(path)

    def group(outcome, *afters):
        members = [mutant("x = 0;", after) for after in afters]
        members[0].outcome, members[0].detail = outcome, "FAILED test_y" if outcome == "killed" else ""
        return members

    plain = group("killed", "x = 2;", "x = 3;")
    survived_listed = group("survived", "x = 2;", "x = 1;")  # a later member is on the list
    killed_listed = group("killed", "x = 2;", "x = 1;")
    listed_first = group("listed", "x = 1;", "x = 2;")  # listed, not tested
    settle([plain, survived_listed, killed_listed, listed_first], equivalents)
    assert [m.outcome for m in plain] == ["killed", "killed"]
    assert plain[1].detail == "same object code as fmu_core.c:10: x = 0;  =>  x = 2;: FAILED test_y"
    assert [m.outcome for m in survived_listed] == ["listed", "listed"]
    assert survived_listed[0].detail == "same object code as fmu_core.c:10: x = 0;  =>  x = 1;"
    assert survived_listed[1].detail == "plain entry."
    assert [m.outcome for m in killed_listed] == ["killed", "wrongly listed"]
    assert killed_listed[1].detail == "listed as equivalent, but FAILED test_y"
    assert [m.outcome for m in listed_first] == ["listed", "listed"]


def test_survivors_and_wrongly_listed_mutants_are_printed_and_counted(capsys):
    outcomes = ("killed", "survived", "listed", "wrongly listed", "stillborn", "untested")
    mutants = [mutant("x = 0;", f"x = {i};") for i in range(len(outcomes))]
    for m, outcome in zip(mutants, outcomes, strict=True):
        m.outcome, m.detail = outcome, f"why {outcome}"
    assert report_failures(mutants) == 2
    assert capsys.readouterr().out.splitlines() == [
        "SURVIVED fmu_core.c:10: x = 0;  =>  x = 1;",
        "WRONGLY LISTED fmu_core.c:10: x = 0;  =>  x = 3;: why wrongly listed",
    ]
