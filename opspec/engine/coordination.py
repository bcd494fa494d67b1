"""Behaviour-coordination built-ins of SISARL-XPDL, as pure functions, and the supervisor
mailbox for push/pull data.

- **arbiter** (fixed priority): ``inputs`` are command fields, highest priority first; the
  output is the first command that is set (not ``None``, not ``""``), else ``None``.
- **voter**: ``inputs`` are votes; the output is the option with the most votes. Ties go to
  the option listed first in ``options`` (or, without options, the value voted first).
  Votes that are ``None`` or ``""`` abstain (``""`` is the specs' "no command", as for the
  arbiter); no votes at all gives ``None``. A vote outside ``options`` still counts, ranked
  after the listed options (in the order first voted).
- **superposition**: ``inputs`` are numbers or equal-length vectors, ``weights`` their
  weights (default 1 each); the output is the weighted sum (a float or a list). Inputs that
  are ``None`` or ``""`` (a behaviour with nothing to say) are left out with their weights;
  all left out gives ``None``.
- **push**: puts the value of ``inputs[0]`` (a tuple of all inputs if several) into the
  supervisor mailbox ``channel``; never blocks.
- **pull**: takes the oldest value of mailbox ``channel`` into ``output``; when the mailbox
  is empty the activity waits until something is pushed (the supervisor holds data until
  the receiver is ready, and each value is delivered once, oldest first).
- **mode change**: switches the active workflow set to ``target_mode`` (see
  :meth:`opspec.engine.interpreter.Interpreter.change_mode`).

``opspec preprocess`` writes push, pull and mode change as standard-XPDL tasks calling the
applications ``opspec.supervisor.push`` / ``opspec.supervisor.pull`` (actual parameters: a
string literal channel and a data field) and ``opspec.engine.mode_change`` (a string literal
mode). :func:`application_builtin` turns such a task back into the built-in, so the compiler
runs a preprocessed spec exactly like the SISARL file it came from.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from opspec.model import CoordinationBuiltIn, CoordinationKind
from opspec.model.data import ActualParameter
from opspec.model.expressions import Literal, Name

__all__ = ["APPLICATION_BUILTINS", "application_builtin", "arbiter", "superposition", "voter"]

APPLICATION_BUILTINS = {
    "opspec.supervisor.push": CoordinationKind.PUSH_DATA,
    "opspec.supervisor.pull": CoordinationKind.PULL_DATA,
    "opspec.engine.mode_change": CoordinationKind.MODE_CHANGE,
}
"""The applications ``opspec preprocess`` writes for the built-ins standard XPDL lacks."""


def application_builtin(application: str, params: Sequence[ActualParameter]
                        ) -> CoordinationBuiltIn | str | None:
    """The built-in a preprocessed task calling ``application`` stands for; ``None`` when
    ``application`` is not one of :data:`APPLICATION_BUILTINS`; a problem (a ``str`` saying
    what the parameters should be) when the parameters do not fit."""
    kind = APPLICATION_BUILTINS.get(application)
    if kind is None:
        return None
    values = [p.expression for p in params]
    literal = values[0] if values else None
    if not isinstance(literal, Literal) or not isinstance(literal.value, str):
        what = "mode" if kind is CoordinationKind.MODE_CHANGE else "channel"
        return f"its first actual parameter must be the {what} as a string literal"
    if kind is CoordinationKind.MODE_CHANGE:
        return CoordinationBuiltIn(kind=kind, target_mode=literal.value)
    field = values[1] if len(values) == 2 else None
    if not isinstance(field, Name):
        return "its actual parameters must be a string literal channel and a data field"
    ref = ".".join(field.path)
    if kind is CoordinationKind.PUSH_DATA:
        return CoordinationBuiltIn(kind=kind, channel=literal.value, inputs=(ref,))
    return CoordinationBuiltIn(kind=kind, channel=literal.value, output=ref)


def arbiter(commands: Sequence[Any]) -> Any:
    """The first command that is set, in priority order."""
    for command in commands:
        if command is not None and command != "":
            return command
    return None


def voter(votes: Sequence[Any], options: Sequence[Any] = ()) -> Any:
    """The most voted value; ties broken by ``options`` order, else by first vote.
    ``None`` and ``""`` abstain."""
    counts: dict[Any, int] = {}
    for vote in votes:
        if vote is not None and vote != "":
            counts[vote] = counts.get(vote, 0) + 1
    if not counts:
        return None
    order = [o for o in options if o in counts] + [v for v in counts if v not in options]
    best = max(counts.values())
    return next(v for v in order if counts[v] == best)


def superposition(values: Sequence[Any], weights: Sequence[float] = ()) -> Any:
    """Weighted sum of numbers or of equal-length vectors; unset inputs are left out."""
    w = list(weights) or [1.0] * len(values)
    if len(w) != len(values):
        raise ValueError(f"superposition has {len(values)} inputs but {len(w)} weights")
    pairs = [(wi, v) for wi, v in zip(w, values, strict=True) if v is not None and v != ""]
    if not pairs:
        return None
    w, values = [wi for wi, _ in pairs], [v for _, v in pairs]
    if all(isinstance(v, int | float) for v in values):
        return float(sum(wi * vi for wi, vi in zip(w, values, strict=True)))
    vectors = [list(v) for v in values]
    size = len(vectors[0]) if vectors else 0
    if any(len(v) != size for v in vectors):
        raise ValueError("superposition inputs are vectors of different lengths")
    return [float(sum(wi * v[i] for wi, v in zip(w, vectors, strict=True))) for i in range(size)]
