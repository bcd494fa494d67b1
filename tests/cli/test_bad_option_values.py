"""A bad value of an option is one line, as every other error of the command line is: the
command, the option, the value and what the option takes, exit status 2 (`opspec evaluate
--seed abc` printed thirteen lines of usage before "argument --seed: 'abc' is not a whole
number"). Checked for every option of every command that converts or chooses its value; an
unknown option still shows the command's usage (test_usage_and_completion.py)."""

from __future__ import annotations

import argparse
from collections.abc import Iterator

import pytest

from opspec.cli import build_parser, main


def _commands(parser: argparse.ArgumentParser, words: tuple[str, ...] = ()
              ) -> Iterator[tuple[tuple[str, ...], argparse.ArgumentParser]]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield (*words, name), sub
                yield from _commands(sub, (*words, name))


def _options() -> list[tuple[tuple[str, ...], str, str]]:
    """(command words, option, what it takes) of every option whose value is a number or
    one of some choices."""
    found = []
    for words, parser in _commands(build_parser()):
        for action in parser._actions:
            if not action.option_strings or action.nargs == 0:
                continue
            option = max(action.option_strings, key=len)
            if action.choices is not None:
                found.append((words, option, "takes one of"))
            elif action.type is int:
                found.append((words, option, "takes a whole number"))
            elif action.type is float:
                found.append((words, option, "takes a number"))
    return found


OPTIONS = _options()


def test_there_are_options_to_check() -> None:
    commands = {words[0] for words, _, _ in OPTIONS}
    assert {"run", "evaluate", "new", "fit", "model-check"} <= commands, commands


@pytest.mark.parametrize(("words", "option", "takes"), OPTIONS,
                         ids=[" ".join((*w, o)) for w, o, _ in OPTIONS])
def test_a_bad_value_is_one_line_naming_option_value_and_what_it_takes(
        words: tuple[str, ...], option: str, takes: str,
        capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main([*words, option, "zz9"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "usage:" not in err, err
    assert err.startswith(f"opspec {' '.join(words)}: {option} {takes}")
    assert err.rstrip().endswith("not 'zz9'"), err


@pytest.mark.parametrize(("args", "line"), [
    (["evaluate", "--seed", "abc"], ("opspec evaluate: --seed: 'abc' is not a whole number "
                                     "(a seed is a whole number from 0 to 2**63 - 1)")),
    (["evaluate", "--target-users", "2"], ("opspec evaluate: --target-users: '2': a share of "
                                           "users lies above 0 and at most 100%")),
    (["run", "x.xpdl", "--days"], "opspec run: --days needs a value (D)"),
])
def test_an_options_own_check_and_a_missing_value_are_one_line(
        args: list[str], line: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(args)
    assert exit_.value.code == 2
    assert capsys.readouterr().err == line + "\n"
