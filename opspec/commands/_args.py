"""Argument types shared by the subcommands (argparse turns their errors into usage errors)."""

from __future__ import annotations

import argparse

__all__ = ["seed", "share", "sweep"]

def seed(text: str) -> int:
    """A run seed: the rule of every door (:func:`opspec.run_rules.check_seed`)."""
    from opspec.errors import ConfigurationError
    from opspec.run_rules import check_seed

    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    try:
        return check_seed(value)
    except ConfigurationError as error:
        raise argparse.ArgumentTypeError(error.message) from None


def sweep(text: str) -> tuple[str, tuple[str, ...]]:
    """``--sweep PARAM=v1,v2,…``: the parameter's name and its values as written (read in the
    parameter's unit by opspec.evaluation.parameters); ``list`` alone lists the names."""
    name, equals, values = text.partition("=")
    if not equals:
        if text.strip() == "list":
            return "list", ()
        raise argparse.ArgumentTypeError(
            f"{text!r}: write PARAM=v1,v2,... (e.g. spec.notify_workflow.wait_report.deadline="
            "3min,5min,10min), or 'list' for the parameters the spec and user model have")
    parts = tuple(v.strip() for v in values.split(","))
    if not name.strip() or not all(parts):
        raise argparse.ArgumentTypeError(f"{text!r}: a parameter name and values separated "
                                         "by commas, none empty (PARAM=v1,v2,...)")
    return name.strip(), parts


def share(text: str) -> float:
    """A share of users: ``95%`` or ``0.95``, above 0 and at most 1."""
    stripped = text.strip()
    percent = stripped.endswith("%")
    try:
        value = float(stripped[:-1] if percent else stripped) / (100.0 if percent else 1.0)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a share: write 95% or "
                                         "0.95") from None
    if not 0.0 < value <= 1.0:
        raise argparse.ArgumentTypeError(f"{text!r}: a share of users lies above 0 and at "
                                         "most 100%")
    return value


def add_branch_option(parser: argparse.ArgumentParser) -> None:
    """``--branch``, the same for every command that runs a spec (run, evaluate)."""
    parser.add_argument("--branch", action="append", default=[],
                        metavar="GATEWAY=FLOW:P[,FLOW:P...]",
                        help="branch probabilities for a gateway the diagram leaves undecided "
                        "(by id or name, as validate prints them), replacing the file's; "
                        "repeatable; docs/bpmn.md, Undecided gateways")
