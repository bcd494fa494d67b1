"""What the subcommands declare alike, written once: the parser of every command
(:class:`Parser`: a bad value of an option is one line), how a command is added (its module
docstring is its ``--help``), the options several commands share, and the argument types
(their errors are such one-line usage errors, exit status 2)."""

from __future__ import annotations

import argparse
import inspect
from typing import Any, NoReturn

__all__ = ["Parser", "add_branch_option", "add_check_options", "add_days", "add_device_options",
           "add_engine_config", "add_json", "add_lane", "add_run_inputs", "add_seed",
           "add_spec", "add_strict", "add_translation", "add_user_model", "command", "seed",
           "share", "sweep"]


class Parser(argparse.ArgumentParser):
    """The parser of ``opspec`` and of every command (argparse gives each subparser its
    parent's class): a bad value of an option is one line, as every other error of the
    command line is (``opspec evaluate: --seed: 'abc' is not a whole number …``, exit 2),
    not argparse's usage block before it; the line names the option, the value and what
    it accepts. An unknown option still shows the command's usage (README: a mistyped option
    shows the usage of the command it was given to)."""

    _bad_value: str | None = None

    def _get_value(self, action: argparse.Action, arg_string: str) -> Any:
        try:
            return super()._get_value(action, arg_string)
        except argparse.ArgumentError as error:
            self._bad_value = _value_error(action, arg_string, error)
            raise

    def _check_value(self, action: argparse.Action, value: Any) -> None:
        try:
            super()._check_value(action, value)
        except argparse.ArgumentError as error:
            if not isinstance(action, argparse._SubParsersAction):  # a command's name: cli
                self._bad_value = _value_error(action, value, error)
            raise

    def _match_argument(self, action: argparse.Action, arg_strings_pattern: str) -> int:
        try:
            return super()._match_argument(action, arg_strings_pattern)
        except argparse.ArgumentError:
            if action.option_strings:       # an option given without its value
                metavar = action.metavar if isinstance(action.metavar, str) else (
                    action.dest.upper())
                self._bad_value = (f"{max(action.option_strings, key=len)} needs a value "
                                   f"({metavar})")
            raise

    def error(self, message: str) -> NoReturn:
        said, self._bad_value = self._bad_value, None
        if said is not None:
            self.exit(2, f"{self.prog}: {said}\n")
        super().error(message)


def _value_error(action: argparse.Action, value: Any, error: argparse.ArgumentError) -> str:
    """One line on a bad value of ``action``: the option, the value, what it accepts."""
    option = max(action.option_strings, key=len) if action.option_strings else (
        action.metavar if isinstance(action.metavar, str) else action.dest.upper())
    if action.choices is not None and value not in action.choices:
        return (f"{option} takes one of {', '.join(map(str, action.choices))}, "
                f"not {value!r}")
    if action.type in (int, float):
        return (f"{option} takes {'a whole number' if action.type is int else 'a number'}, "
                f"not {value!r}")
    # the option's own type says what is wrong and what it takes (argparse.ArgumentTypeError)
    return f"{option}: {error.message}"


#: what --days means when it is left out, wherever a spec is run
SPEC_RUN_LENGTH = "the spec's opspec:RunLength if it declares one, else 1"


def command(subparsers: Any, name: str, doc: str | None) -> argparse.ArgumentParser:
    """Add command ``name`` whose documentation is ``doc``, its module's docstring (as click
    does: a command's help is its documentation). The first paragraph, a sentence, is the
    one-line help ``opspec --help`` lists; the whole text, as written, is ``--help``'s
    description."""
    text = inspect.cleandoc(doc or "")
    summary = " ".join(text.split("\n\n", 1)[0].split()).removesuffix(".")
    parser: argparse.ArgumentParser = subparsers.add_parser(
        name, help=summary[:1].lower() + summary[1:], description=text,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    return parser


def add_spec(parser: argparse.ArgumentParser, *, optional: str = "") -> None:
    """The SPEC every command that opens one takes (``optional``: when it may be left out)."""
    parser.add_argument("spec", metavar="SPEC", nargs="?" if optional else None,
                        help="the specification (.xpdl, .bpmn or a compiled .wfs)"
                        + (f"; optional {optional}" if optional else ""))


def add_days(parser: Any, *, what: str = "", when: str = "") -> None:
    """``--days``: ``what`` the days are of, ``when`` the option counts (``with --spec: ``)."""
    parser.add_argument("--days", type=float, default=None, metavar="D",
                        help=f"{when}simulated days{what} (default: {SPEC_RUN_LENGTH})")


def add_seed(parser: argparse.ArgumentParser, *, default: int | None = 0,
             what: str = "run seed") -> None:
    """``--seed``, a whole number from 0 to 2**63 - 1 (:func:`seed`) whatever it seeds."""
    parser.add_argument("--seed", type=seed, default=default, help=f"{what} (default 0)")


def add_json(parser: argparse.ArgumentParser, what: str) -> None:
    """``--json``: print ``what`` instead of the text."""
    parser.add_argument("--json", action="store_true", help=f"print {what}")


def add_user_model(parser: Any, *, role: str = "") -> None:
    """``--user-model`` (``role``: what the model does in this command)."""
    parser.add_argument("--user-model", metavar="FILE|PRESET",
                        help=f"{role}a user model file or preset; 'A,B' chains a modifier "
                        "(default: the spec's companion SPEC.users.toml)")


def add_run_inputs(parser: argparse.ArgumentParser, *, per_user: bool) -> None:
    """The values a run reads that the spec leaves open (--param, --params, --branch);
    ``per_user``: drawn per simulated user (evaluate) rather than once (run)."""
    parser.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                        help="a value for a package data field, such as a BPMN diagram's run "
                        "input (a variable its conditions read that nothing sets), or "
                        "NAME~DISTRIBUTION ('score~uniform(0, 100)': drawn from the seed"
                        + (", one per simulated user" if per_user else "")
                        + "); repeatable; docs/bpmn.md, Run inputs")
    add_branch_option(parser)
    parser.add_argument("--params", metavar="FILE",
                        help="run-input values from a .toml/.json file (NAME = value or a "
                        "distribution table) or a .csv file ("
                        + ("one row per simulated user" if per_user
                           else "the run takes its first row") + ")")


def add_engine_config(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--engine-config", metavar="FILE", help="engine configuration TOML")


def add_device_options(parser: argparse.ArgumentParser) -> None:
    """``--bind`` and ``--devices``: real or emulated devices in place of participants."""
    parser.add_argument("--bind", action="append", default=[],
                        metavar="PARTICIPANT[:PROFILE]=URL",
                        help="bind a participant to a serial device URL (a device path, "
                        "socket://HOST:PORT, emulator://PROFILE) or 'auto'; :PROFILE picks the "
                        "profile when several serve the participant (repeatable; see "
                        "devices/README.md)")
    parser.add_argument("--devices", metavar="DIR",
                        help="folder of device profiles for --bind (default: devices/)")


def add_translation(parser: argparse.ArgumentParser, source: str, output: str,
                    default: str) -> None:
    """IN, ``-o OUT`` and ``--strict`` of a command that translates a spec into another file
    (compile, preprocess): ``source`` is what IN is, ``output`` OUT's metavar and ``default``
    where OUT goes when it is left out."""
    parser.add_argument("input", metavar="IN", help=f"the {source} specification")
    parser.add_argument("-o", "--output", metavar=output,
                        help=f"where to write (default: {default})")
    add_strict(parser)


def add_strict(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--strict", action="store_true",
                        help="treat warnings as errors: among them everything opspec runs "
                        "differently from its standard (runs-differently, docs/semantics.md)")


def add_lane(parser: argparse.ArgumentParser, done: str) -> None:
    """``--lane``: the lane or participant whose activities are ``done`` (fitted, checked)."""
    parser.add_argument("--lane", default="user",
                        help=f"lane or participant whose activities are {done} (default: user)")


def add_check_options(parser: Any, *, level_of: str) -> None:
    """How a user model is checked against people (opspec model-check, and opspec fit's
    cross-validation, which runs that check on each fold)."""
    parser.add_argument("--level", type=float, default=0.05,
                        help=f"family-wise error level of {level_of} (default: 0.05)")
    parser.add_argument("--replicates", type=int, default=399, metavar="B",
                        help="simulated groups of people for the bootstrap and the predictive "
                        "rates (default: 399)")
    parser.add_argument("--spec", metavar="SPEC",
                        help="also check the spec's outcome metrics: the spec run with the "
                        "model gives predictive intervals for what these people showed")
    add_days(parser, what=" of each run, as long as the people's sessions", when="with --spec: ")
    parser.add_argument("--runs", type=int, default=200, metavar="N",
                        help="with --spec: simulated people for the metrics (default: 200)")


def seed(text: str) -> int:
    """A run seed: the rule of every door (:func:`opspec.run_rules.check_seed`)."""
    from opspec.errors import ConfigurationError
    from opspec.run_rules import check_seed

    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number (a seed is a "
                                         "whole number from 0 to 2**63 - 1)") from None
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
