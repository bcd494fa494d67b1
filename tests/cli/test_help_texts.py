"""Each command's ``--help`` is its documentation, written once: the description is the command
module's docstring and the line ``opspec --help`` lists is that docstring's first sentence
(as click does); an option several commands take reads the same in each."""

from __future__ import annotations

import importlib
import inspect

import pytest

from opspec.cli import COMMAND_MODULES, _subparsers, build_parser


def _commands() -> dict[str, tuple[object, object]]:
    parsers = _subparsers(build_parser())
    out = {}
    for module_name in COMMAND_MODULES:
        module = importlib.import_module(module_name)
        name = module_name.rsplit(".", 1)[-1].replace("_", "-")
        out[name] = (module, parsers[name])
    return out


@pytest.mark.parametrize("name", sorted(_commands()))
def test_the_description_is_the_module_docstring(name):
    module, parser = _commands()[name]
    assert parser.description == inspect.cleandoc(module.__doc__)
    summary = " ".join(parser.description.split("\n\n")[0].split()).removesuffix(".")
    listed = build_parser().format_help()
    assert " ".join(listed.split()).find(summary[:1].lower() + summary[1:60]) >= 0


def test_every_action_of_a_command_says_what_it_does():
    # `opspec devices list --help` printed only its usage and options
    pending = list(_subparsers(build_parser()).values())
    bare = []
    while pending:
        parser = pending.pop()
        actions = _subparsers(parser)
        pending.extend(actions.values())
        bare += [action.prog for action in actions.values() if not action.description]
    assert bare == []


def _help_of(parser, option: str) -> str | None:
    for action in parser._actions:
        if option in action.option_strings:
            return action.help
    return None


def test_days_says_the_same_default_wherever_a_spec_is_run():
    texts = {name: _help_of(parser, "--days") for name, (_, parser) in _commands().items()}
    texts = {name: text for name, text in texts.items() if text is not None}
    assert {"run", "evaluate", "walkthrough", "fit", "model-check"} <= set(texts)
    for text in texts.values():
        assert text.endswith("(default: the spec's opspec:RunLength if it declares one, else 1)")


def test_every_seed_is_checked_by_the_one_seed_rule(capsys):
    for command in (["run", "x.xpdl"], ["fit", "t.jsonl", "-o", "m.toml"],
                    ["model-check", "m.toml", "t.jsonl"]):
        with pytest.raises(SystemExit) as exit_:
            build_parser().parse_args([*command, "--seed", "-1"])
        assert exit_.value.code == 2
        assert "a seed is a whole number from 0 to 2**63 - 1" in capsys.readouterr().err


@pytest.mark.parametrize("name", sorted(_commands()))
def test_a_command_named_on_the_command_line_parses_as_in_the_full_list(name):
    # `opspec NAME ...` builds NAME's parser alone (the others' modules not imported): its
    # help, defaults and options must be those of the full parser's NAME
    alone = _subparsers(build_parser(name))
    assert list(alone) == [name]
    full = _subparsers(build_parser())[name]
    assert alone[name].format_help() == full.format_help()
    def defaults(parser):   # a handler made by register() is a new closure each time
        return {k: getattr(v, "__qualname__", v) for k, v in parser._defaults.items()}

    assert defaults(alone[name]) == defaults(full)


def test_a_mistyped_command_still_lists_every_command(capsys):
    from opspec.cli import main

    with pytest.raises(SystemExit):
        main(["valdate", "spec.xpdl"])
    err = capsys.readouterr().err
    assert "invalid choice: 'valdate'" in err and "'validate'" in err and "'model-check'" in err


def test_an_unknown_option_of_an_action_shows_that_actions_usage(capsys):
    # README: "A mistyped option shows the usage of the command it was given to"
    from opspec.cli import main

    with pytest.raises(SystemExit):
        main(["devices", "list", "--bogus"])
    err = capsys.readouterr().err
    assert err.startswith("usage: opspec devices list ")
    assert "opspec devices list: error: unrecognized arguments: --bogus" in err


def test_a_mistyped_command_or_option_names_the_one_meant(capsys):
    from opspec.cli import main

    with pytest.raises(SystemExit):
        main(["evalute", "spec.xpdl"])
    assert "invalid choice: 'evalute' (did you mean 'evaluate'?" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["run", "--dayz", "1", "spec.xpdl"])       # argparse took 1 for SPEC
    err = capsys.readouterr().err
    assert "unrecognized arguments: --dayz spec.xpdl (--dayz: did you mean --days?)" in err
