"""The ``opspec`` command: the composition root.

Each subcommand lives in its own module under :mod:`opspec.commands` and exposes
``register(subparsers) -> None``, which adds its parser and sets ``handler`` to a function
``(args) -> int`` returning the exit status. This module only wires them together and turns
every :class:`~opspec.errors.OpspecError` into a one-line message: no traceback reaches a user.

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

from opspec import __version__
from opspec.errors import OpspecError, SpecError

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
    "opspec.commands.fit",
    "opspec.commands.devices",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="opspec",
        description="Execute operational specifications (XPDL / SISARL-XPDL) of assistive "
        "devices and their users.",
    )
    parser.add_argument("--version", action="version", version=f"opspec {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as error:
            if error.name == name:  # that command is not built yet
                continue
            raise
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the console script; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    handler = getattr(args, "handler", None)
    if handler is None:
        parser.print_help()
        return 2
    try:
        status: int = handler(args)
        return status
    except SpecError as error:
        print(f"opspec: {error}", file=sys.stderr)
        for diagnostic in error.diagnostics[1:]:
            print(f"  {diagnostic}", file=sys.stderr)
        return 1
    except OpspecError as error:
        print(f"opspec: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("opspec: interrupted", file=sys.stderr)
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
            f"opspec: internal error: {type(error).__name__}: {error} "
            "(this is a bug in opspec; rerun with OPSPEC_DEBUG=1 for a traceback and report it)",
            file=sys.stderr,
        )
        return 70


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
