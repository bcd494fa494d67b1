"""Design targets (``opspec evaluate --sweep … --target "missed_rate < 1%"``) and whether a
design meets them, said with the uncertainty of the estimate.

A target is ``METRIC OP THRESHOLD`` (``<``, ``<=``, ``>``, ``>=``; ``≤`` and ``≥`` too), the
threshold in the metric's own terms: a ratio as ``1%`` or ``0.01``, a duration in
:mod:`opspec.clock`'s grammar (``2 min``, ``90``), a count as a number per user over the run.

The verdict on a design is three-way, as a reviewer reads an interval:

* **meets** — the whole 95 % interval lies on the target's side of the threshold;
* **fails** — the whole interval lies on the other side;
* **undecided** — the interval contains the threshold, or has no width because the few users
  it is over all gave the same value: more users would tell.

``--target-users 95%`` asks instead about each user's own value over the run (their missed
rate over the simulated days): the share of users whose own value satisfies the target, with
its exact (Clopper-Pearson) interval, against the share asked for — meets when the interval's
lower end reaches it, fails when its upper end falls short.
"""

from __future__ import annotations

import difflib
import math
import operator
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from opspec.errors import EvaluationError, OpspecError

__all__ = ["VERDICTS", "Target", "parse_target", "share_verdict", "verdict"]

VERDICTS = ("meets", "undecided", "fails")

_OPS: Mapping[str, Callable[[float, float], bool]] = {
    "<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge}
_SPELLINGS = {"≤": "<=", "≥": ">=", "=<": "<=", "=>": ">="}
_FORM = re.compile(r"\s*(?P<metric>[A-Za-z_][\w.\-]*)\s*(?P<op><=|>=|=<|=>|<|>|≤|≥)\s*"
                   r"(?P<value>\S.*?)\s*")
# seconds per unit a duration metric may declare
_UNIT_SECONDS = {"ms": 0.001, "s": 1.0, "sec": 1.0, "min": 60.0, "h": 3600.0, "d": 86_400.0}


@dataclass(frozen=True, slots=True)
class Target:
    """``metric op threshold``; ``kind`` is the metric's (count, duration, ratio), ``percent``
    whether the threshold was written as a percentage, ``unit`` a duration metric's unit."""

    text: str
    metric: str
    op: str
    threshold: float
    kind: str
    percent: bool = False
    unit: str = ""

    def holds(self, value: float) -> bool:
        return _OPS[self.op](value, self.threshold)

    @property
    def below(self) -> bool:
        """Whether the target asks for small values (``<``, ``<=``)."""
        return self.op in ("<", "<=")

    def threshold_text(self) -> str:
        if self.percent:
            return f"{100.0 * self.threshold:.4g} %"
        return f"{self.threshold:.4g}" + (f" {self.unit}" if self.unit else "")

    def describe(self) -> str:
        return f"{self.metric} {self.op} {self.threshold_text()}"

    def to_json(self) -> dict[str, Any]:
        return {"target": self.text, "metric": self.metric, "op": self.op,
                "threshold": self.threshold, "kind": self.kind}


def parse_target(text: str, definitions: Sequence[Mapping[str, Any]]) -> Target:
    """``text`` as a target on one of the declared metrics ``definitions``; an
    EvaluationError saying what is wrong (an unknown metric with the closest names, a
    threshold that is not in the metric's terms)."""
    found = _FORM.fullmatch(text or "")
    if found is None:
        raise EvaluationError(f"--target {text!r}: not a target",
                              hint='write METRIC OP VALUE, e.g. "missed_rate < 1%" or '
                              '"report_latency_s <= 3 min" (OP: <, <=, >, >=)')
    metric, op, value = found["metric"], found["op"], found["value"]
    op = _SPELLINGS.get(op, op)
    declared = {d["name"]: d for d in definitions}
    definition = declared.get(metric)
    if definition is None:
        close = difflib.get_close_matches(metric, list(declared), n=3, cutoff=0.6)
        raise EvaluationError(
            f"--target {text!r}: the spec declares no metric {metric!r}"
            + (f"; did you mean {' or '.join(close)}?" if close else ""),
            hint="its metrics: " + (", ".join(declared) or "none"))
    kind = str(definition["kind"])
    unit = str(definition.get("unit") or ("s" if kind == "duration" else ""))
    percent = value.endswith("%")

    def refuse(expected: str) -> EvaluationError:
        return EvaluationError(f"--target {text!r}: cannot read the threshold {value!r} "
                               f"of {metric} ({kind}): expected {expected}")

    if kind == "duration":
        from opspec.clock import parse_duration

        try:
            seconds = parse_duration(value, error=EvaluationError)
        except OpspecError:
            raise refuse("a duration such as 90 (seconds), 2 min or PT2M") from None
        threshold = seconds / _UNIT_SECONDS.get(unit, 1.0)
        return Target(text, metric, op, threshold, kind, unit=unit)
    try:
        threshold = float(value[:-1] if percent else value) / (100.0 if percent else 1.0)
    except ValueError:
        raise refuse("a percentage such as 1% or a number such as 0.01" if kind == "ratio"
                     else "a number (per user over the run)") from None
    if not math.isfinite(threshold):
        raise refuse("a finite number")
    if percent and kind != "ratio":
        raise refuse(f"a number: {metric} is a {kind}, not a rate")
    return Target(text, metric, op, threshold, kind, percent=percent)


def verdict(target: Target, ci: Sequence[float | None] | None, *, alike: bool = False
            ) -> str:
    """``meets``, ``fails`` or ``undecided``: where the interval ``ci`` lies against the
    threshold (undecided without an interval, and for an interval of no width because its
    few users were all ``alike``: it shows no spread, not a value known exactly,
    :mod:`opspec.statistics.no_spread`)."""
    if not ci or ci[0] is None or ci[1] is None or alike:
        return "undecided"
    low, high = float(ci[0]), float(ci[1])
    if target.below:
        if target.holds(high):
            return "meets"
        return "fails" if not target.holds(low) else "undecided"
    if target.holds(low):
        return "meets"
    return "fails" if not target.holds(high) else "undecided"


def share_verdict(share_ci: Sequence[float] | None, wanted: float) -> str:
    """Whether the share of users meeting a target reaches ``wanted``, by its interval."""
    if not share_ci:
        return "undecided"
    if share_ci[0] >= wanted:
        return "meets"
    return "fails" if share_ci[1] < wanted else "undecided"
