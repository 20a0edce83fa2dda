"""The command's help (issue 53): every option of every command says what
it does, compare's and check's options stand in groups by what they are
for, and each command's help names that command."""

import argparse

import pytest

from fmutrace import cli

GROUPS = ["what to compare", "how to judge", "what to write", "where to run", "recordings"]


def commands():
    """{name: its parser} of every command."""
    (sub,) = [a for a in cli.parser()._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(sub.choices)


def test_every_command_is_its_own_parser():
    assert sorted(commands()) == ["check", "compare", "run"]


@pytest.mark.parametrize("command", ["run", "compare", "check"])
def test_every_option_and_argument_of_a_command_has_a_help_line(command):
    silent = [
        a.option_strings or a.dest
        for a in commands()[command]._actions
        if a.help is not argparse.SUPPRESS and not (a.help or "").strip()
    ]
    assert not silent


@pytest.mark.parametrize("command", ["compare", "check"])
def test_a_commands_help_names_the_command(command, capsys):
    with pytest.raises(SystemExit) as done:
        cli.parser().parse_args([command, "--help"])
    assert done.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: fmutrace {command} ")


@pytest.mark.parametrize("command", ["compare", "check"])
def test_compares_options_stand_in_groups_and_none_among_the_general_ones(command):
    parser = commands()[command]
    titled = [g.title for g in parser._action_groups if g._group_actions]
    assert titled[1:] == GROUPS  # (the first: argparse's own, with --help alone)
    general = [a.option_strings for a in parser._action_groups[1]._group_actions]
    assert general == [["-h", "--help"]]


def test_the_judging_options_are_in_how_to_judge():
    (judge,) = [g for g in commands()["compare"]._action_groups if g.title == "how to judge"]
    flags = {flag for action in judge._group_actions for flag in action.option_strings}
    assert {"--rel-tol", "--abs-tol", "--tube-time", "--tube-value", "--signal"} <= flags
