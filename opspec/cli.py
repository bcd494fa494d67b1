# PYTHON_ARGCOMPLETE_OK  (argcomplete's global completion looks for this line)
"""The ``opspec`` command: the composition root.

Each subcommand lives in its own module under :mod:`opspec.commands` and exposes
``register(subparsers) -> None``, which adds its parser and sets ``handler`` to a function
``(args) -> int`` returning the exit status. This module only wires them together and turns
every :class:`~opspec.errors.OpspecError` into a one-line message: no traceback reaches a user.
Each message begins with the command that was run (``opspec run: ...``, ``opspec devices
list: ...``), as argparse's usage errors do; ``opspec:`` alone where no command was parsed.

Exit statuses: 0 success, 1 a problem found in the user's input or run (a spec error, a failed
check), 2 usage, configuration or I/O errors, 130 interrupted.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import traceback
from collections.abc import Sequence

from opspec import __version__, _native
from opspec.errors import OpspecError, SpecError, ZeroTimeCycleError

__all__ = ["build_parser", "main"]

# The subcommands, in the order ``opspec --help`` lists them. Listed explicitly (no plugin
# discovery) so the CLI's surface is visible in one place; modules import lazily so that
# ``opspec validate`` never pays for Textual or NumPy.
COMMAND_MODULES: tuple[str, ...] = (
    "opspec.commands.validate",
    "opspec.commands.show",
    "opspec.commands.compile",
    "opspec.commands.preprocess",
    "opspec.commands.run",
    "opspec.commands.evaluate",
    "opspec.commands.check",
    "opspec.commands.walkthrough",
    "opspec.commands.study",
    "opspec.commands.fit",
    "opspec.commands.model_check",
    "opspec.commands.devices",
    "opspec.commands.new",
)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The ``opspec`` parser with every subcommand, or with command ``only`` alone (its
    module named after it: ``model-check`` is ``opspec.commands.model_check``), which spares
    importing and registering the others (about 30 ms) when the command line names one."""
    from opspec.commands._args import Parser

    # every command's parser is a Parser too (argparse makes subparsers of the parent's class)
    parser = Parser(
        prog="opspec",
        description="Execute operational specifications (XPDL / SISARL-XPDL, or BPMN 2.0) of "
        "assistive "
        "devices and their users.",
    )
    parser.add_argument("--version", action="version",
                        version=f"opspec {__version__} (engine: {_native.STATUS})")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    modules = COMMAND_MODULES if only is None else [
        name for name in COMMAND_MODULES
        if name.rsplit(".", 1)[-1].replace("_", "-") == only]
    for name in modules:
        try:
            module = importlib.import_module(name)
            module.register(subparsers)
        except ModuleNotFoundError as error:
            if error.name == name:  # that command is not built yet
                continue
            _register_broken(subparsers, name, error)
        except Exception as error:  # noqa: BLE001 - a broken command must not break the others
            _register_broken(subparsers, name, error)
    return parser


def _register_broken(subparsers: argparse._SubParsersAction[argparse.ArgumentParser],
                     module: str, error: Exception) -> None:
    """Stand in for a command whose module fails to import or register: the other commands
    keep working, and this one says what is wrong in one line when it is used."""
    command = module.rsplit(".", 1)[-1].replace("_", "-")   # as build_parser names it
    if command in subparsers.choices:
        return
    reason = " ".join(f"{type(error).__name__}: {error}".split())
    parser = subparsers.add_parser(command, help="(unavailable: this command failed to load)",
                                   add_help=False)

    def broken(_args: argparse.Namespace) -> int:
        print(f"{parser.prog}: internal error: the {command!r} command cannot be loaded "
              f"({reason}) (this is a bug in opspec; rerun with OPSPEC_DEBUG=1 for a "
              "traceback and report it)", file=sys.stderr)
        if os.environ.get("OPSPEC_DEBUG"):
            traceback.print_exception(error)
        return 70

    parser.add_argument("rest", nargs=argparse.REMAINDER, help=argparse.SUPPRESS)
    parser.set_defaults(handler=broken)


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """The subcommands' parsers by name."""
    for action in parser._actions:  # argparse keeps no public handle on them
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _innermost(parser: argparse.ArgumentParser, args: argparse.Namespace
               ) -> argparse.ArgumentParser:
    """The parser of the deepest command ``args`` chose (``opspec devices list``: that of
    ``list``), whose usage an unknown option is reported with and whose ``prog`` begins
    every message the command prints on stderr (``opspec devices list: ...``, as argparse's
    own errors begin)."""
    while True:
        actions = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        chosen = getattr(args, actions[0].dest, None) if actions else None
        if chosen is None or chosen not in actions[0].choices:
            return parser
        parser = actions[0].choices[chosen]


def _refuse_unknown_command(parser: argparse.ArgumentParser, name: str) -> None:
    """A name that is no command but close to one: argparse's refusal, with the one meant
    (``opspec evalute``: did you mean 'evaluate'?)."""
    import difflib

    commands = list(_subparsers(parser))
    if name in commands or name.startswith("-"):
        return
    close = difflib.get_close_matches(name, commands, n=1)
    if close:
        parser.error(f"argument COMMAND: invalid choice: {name!r} (did you mean "
                     f"{close[0]!r}? choose from {', '.join(map(repr, commands))})")


def _did_you_mean(parser: argparse.ArgumentParser, unknown: Sequence[str]) -> str:
    """The options of ``parser`` the unknown ones are likely typos of (``--dayz``: did you
    mean --days?); argparse may then have taken the typo's value for an argument."""
    import difflib

    options = [o for action in parser._actions for o in action.option_strings
               if o.startswith("--")]
    meant = []
    for typo in unknown:
        if not typo.startswith("--"):
            continue
        name = typo.split("=", 1)[0]
        # another command's option (`run --users`: evaluate's) is no typo: the closest
        # name of this command (--no-user) would point the other way
        others = _commands_with(name, parser.prog)
        close = difflib.get_close_matches(name, options, n=1)
        if others:
            meant.append(f"{name} is not an option of {parser.prog}, but of "
                         f"{', '.join(other.removeprefix('opspec ') for other in others)}")
        elif close:
            meant.append(f"{typo}: did you mean {close[0]}?")
    return f" ({'; '.join(meant)})" if meant else ""


def _commands_with(option: str, own: str) -> list[str]:
    """The commands other than ``own`` (a prog: ``opspec run``) that take ``option``, as
    their progs; every command's parser is built for this (an error's path only)."""
    found: list[str] = []
    pending = list(_subparsers(build_parser()).values())
    while pending:
        command = pending.pop(0)
        pending.extend(_subparsers(command).values())
        if command.prog != own and any(option in action.option_strings
                                       for action in command._actions):
            found.append(command.prog)
    return found


def _gather_files(parser: argparse.ArgumentParser, args: argparse.Namespace,
                  unknown: list[str]) -> list[str]:
    """``unknown`` without the files given after an option to a command taking several
    (``opspec validate a.xpdl --strict b.xpdl``, ``fit a.jsonl -o m.toml b.jsonl``), which
    join the others: argparse fills a list of files from one run of arguments and leaves
    the rest "unrecognized"."""
    if not unknown or any(value.startswith("-") for value in unknown):
        return unknown          # an unknown option: its usage error says which
    lists = [action for action in parser._actions if not action.option_strings
             and action.nargs in ("+", "*")]
    if len(lists) != 1:
        return unknown
    dest = lists[0].dest
    setattr(args, dest, [*(getattr(args, dest, None) or []), *unknown])
    return []


def _named_command(argv: Sequence[str]) -> str | None:
    """The command the command line names first, if it names one before any option (the
    top-level options, ``--help`` and ``--version``, need every command's parser)."""
    if not argv or argv[0].startswith("-") or "_ARGCOMPLETE" in os.environ:
        return None
    return argv[0]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the console script; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        named = _named_command(argv)
        parser = build_parser(named)
        if named is not None and named not in _subparsers(parser):
            parser = build_parser()        # not a command's name: the full list says so
            _refuse_unknown_command(parser, named)
    except Exception as error:  # noqa: BLE001 - no traceback reaches a user
        print(f"opspec: internal error: {' '.join(f'{type(error).__name__}: {error}'.split())} "
              "(this is a bug in opspec; please report it)", file=sys.stderr)
        return 70
    if "_ARGCOMPLETE" in os.environ:       # the shell asks for completions, then exits
        try:
            import argcomplete
        except ImportError:                 # an install older than the dependency
            return 0
        argcomplete.autocomplete(parser)
    args, unknown = parser.parse_known_args(argv)
    # the subcommand's own parser, not the top-level one: its usage says what a mistyped
    # option belongs to and what it accepts, and its prog begins the command's messages
    own = _innermost(parser, args)
    unknown = _gather_files(own, args, unknown)
    if unknown:
        own.error(f"unrecognized arguments: {' '.join(unknown)}" + _did_you_mean(own, unknown))
    handler = getattr(args, "handler", None)
    if handler is None:
        parser.print_help()
        return 2
    # The one place the prefix of what reaches here is added: an error's text carries none.
    said = f"{own.prog}:"
    try:
        status: int = handler(args)
        return status
    except SpecError as error:
        print(f"{said} {error}", file=sys.stderr)
        for diagnostic in error.diagnostics[1:]:
            print(f"  {diagnostic}", file=sys.stderr)
        return 1
    except ZeroTimeCycleError as error:         # a problem of the run, not of the usage
        print(f"{said} {error}", file=sys.stderr)
        return 1
    except OpspecError as error:
        print(f"{said} {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{said} interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # `opspec show … | head`: the reader went away; not an error worth a message.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except Exception as error:  # noqa: BLE001 - the last line of defence for users
        if os.environ.get("OPSPEC_DEBUG"):
            traceback.print_exc()
        print(
            f"{said} internal error: {type(error).__name__}: {error} "
            "(this is a bug in opspec; rerun with OPSPEC_DEBUG=1 for a traceback and report it)",
            file=sys.stderr,
        )
        return 70


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
