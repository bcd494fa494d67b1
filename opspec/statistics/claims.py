"""Deciding a statistical claim (scenario files' ``then`` lines): pass, refuted, or too few runs.

A claim "X >= b with C confidence" passes when the one-sided lower confidence bound of X at
level C is at least ``b``; it is refuted when the one-sided upper bound is below ``b``; and
otherwise the data cannot decide: the message then says how many replications would, if the
estimate stayed where it is. ``in [a, b]`` uses the two-sided interval at level C.

Intervals (:mod:`opspec.statistics.intervals`): Wilson score for rates (good coverage near 0
and 1, unlike the Wald interval),
Student t for means of per-replication values, and the distribution-free order-statistic
interval (binomial) for quantiles of pooled observations.

Each ``decide_*`` returns ``None`` when the claim holds, else the failure message. A mean
claim that holds on replications that all gave the same value holds on an interval of no
width, which shows no spread between them, not a value known exactly:
:func:`alike_caveat` says so (:mod:`opspec.statistics.no_spread`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

from opspec.statistics.intervals import (
    normal_quantile,
    one_sided,
    quantile_interval,
    rate_interval,
    t_quantile,
)
from opspec.statistics.no_spread import ALIKE_SHARE, unlike_share_high

__all__ = ["alike_caveat", "confidence_text", "decide_mean", "decide_quantile", "decide_rate"]

_MAX_N = 10**9


def confidence_text(level: float) -> str:
    """A confidence for people: 95%, 99%, 98.75% (never rounded to a level it is not)."""
    return f"{level * 100:.4g}%"


def _levels(op: str, level: float) -> float:
    """The normal/t quantile level of the bounds used: one-sided, or two-sided for ``in``."""
    return (1 + level) / 2 if op == "in" else level


def _verdict(op: str, a: float, b: float | None, lo: float, hi: float) -> str | None:
    """``None`` (holds), ``"refuted"`` or ``"undecided"``."""
    if op in (">=", ">"):
        return None if (lo > a if op == ">" else lo >= a) else (
            "refuted" if hi < a else "undecided")
    if op in ("<=", "<"):
        return None if (hi < a if op == "<" else hi <= a) else (
            "refuted" if lo > a else "undecided")
    assert b is not None
    if a <= lo and hi <= b:
        return None
    return "refuted" if hi < a or lo > b else "undecided"


def _bound_text(op: str, a: float, b: float | None) -> str:
    return f"in [{a:g}, {b:g}]" if op == "in" else f"{op} {a:g}"


def _distance(op: str, a: float, b: float | None, estimate: float) -> float:
    """How far ``estimate`` is from the nearest bound that decides the claim."""
    if op == "in":
        assert b is not None
        return min(abs(estimate - a), abs(b - estimate))
    return abs(estimate - a)


def decide_rate(text: str, successes: int, trials: int, op: str, a: float, b: float | None,
                level: float, *, units: str = "trials", replications: int = 1) -> str | None:
    """Decide ``successes/trials OP a`` (or ``in [a, b]``) at confidence ``level``."""
    two_sided = one_sided(_levels(op, level))       # the interval whose ends are the bounds
    if trials == 0:
        return (f"expected {text}\n  but there were no {units} at all in {replications} "
                "replication(s): simulate longer or more users")
    _, lo, hi = rate_interval(successes, trials, two_sided)
    verdict = _verdict(op, a, b, lo, hi)
    if verdict is None:
        return None
    estimate = successes / trials
    side = "two-sided" if op == "in" else "one-sided"
    lines = [f"expected {text}",
             (f"  estimate {estimate:.4g} ({successes}/{trials} {units}, {replications} "
              f"replication(s)); {confidence_text(level)} {side} Wilson interval "
              f"[{lo:.4g}, {hi:.4g}]; "
              f"bound {_bound_text(op, a, b)}")]
    if verdict == "refuted":
        lines.append("  the claim is false at this confidence")
        return "\n".join(lines)
    if _distance(op, a, b, estimate) == 0:
        lines.append("  too few to decide, and the estimate sits on the bound: no number of "
                     "replications would settle it")
        return "\n".join(lines)
    needed = _rate_trials(estimate, two_sided, op, a, b, trials)
    per = trials / max(1, replications)
    reps = math.ceil(needed / per) if per > 0 else needed
    lines.append(f"  too few replications to decide: about {reps} replications "
                 f"(~{needed} {units}) would, if the estimate stays at {estimate:.4g}")
    return "\n".join(lines)


def _rate_trials(p: float, two_sided: float, op: str, a: float, b: float | None, start: int
                 ) -> int:
    """Smallest trial count (by doubling, then bisection) at which the Wilson interval around
    the same estimate ``p`` decides the claim."""
    def decided(n: int) -> bool:
        _, lo, hi = rate_interval(round(p * n), n, two_sided)
        return _verdict(op, a, b, lo, hi) != "undecided"

    needed = smallest_deciding(decided, start)
    return _MAX_N if needed is None else needed


def smallest_deciding(decided: Callable[[int], bool], start: int) -> int | None:
    """Smallest n >= start with ``decided(n)`` (doubling, then bisection); None past 1e9.
    How many trials or replications a claim needs (scenario ``then`` lines and the spec-test
    assertions alike)."""
    hi = max(1, start)
    while not decided(hi):
        hi *= 2
        if hi > _MAX_N:
            return None
    lo = max(1, hi // 2)
    if lo == hi or decided(lo):
        return lo
    while lo + 1 < hi:
        mid = (lo + hi) // 2
        if decided(mid):
            hi = mid
        else:
            lo = mid
    return hi


def decide_mean(text: str, values: Sequence[float], op: str, a: float, b: float | None,
                level: float) -> str | None:
    """Decide ``mean(values) OP a`` at confidence ``level`` with a Student t interval."""
    n = len(values)
    if n < 2:
        return (f"expected {text}\n  but only {n} replication(s) had a value: a mean's "
                "interval needs at least 2 (try users=30)")
    mean = sum(values) / n
    sd = math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1))
    q = t_quantile(one_sided(_levels(op, level)), n - 1)
    half = q * sd / math.sqrt(n)
    lo, hi = mean - half, mean + half
    verdict = _verdict(op, a, b, lo, hi)
    if verdict is None:
        return None
    side = "two-sided" if op == "in" else "one-sided"
    lines = [f"expected {text}",
             (f"  estimate {mean:.4g} (sd {sd:.3g}, {n} replications); "
              f"{confidence_text(level)} {side} t "
              f"interval [{lo:.4g}, {hi:.4g}]; bound {_bound_text(op, a, b)}")]
    if verdict == "refuted":
        lines.append("  the claim is false at this confidence")
        return "\n".join(lines)
    gap = _distance(op, a, b, mean)
    if gap == 0 or sd == 0:
        lines.append("  too few to decide, and the estimate sits on the bound")
    else:
        needed = max(n + 1, math.ceil((q * sd / gap) ** 2))
        lines.append(f"  too few replications to decide: about {needed} would, if the "
                     f"estimate and spread stay where they are")
    return "\n".join(lines)


def alike_caveat(text: str, values: Sequence[float], level: float) -> str | None:
    """What to say of a mean claim ``text`` that held on ``values`` all alike (a t interval of
    no width), when they are too few to bound the share of replications that could give
    another value below :data:`~opspec.statistics.no_spread.ALIKE_SHARE`; None when the
    values differ, or are enough."""
    n = len(values)
    if n < 2 or any(v != values[0] for v in values):
        return None
    share = unlike_share_high(n, level)
    if share <= ALIKE_SHARE:
        return None
    # the n at which none of n unlike bounds the share at ALIKE_SHARE (368 at 95 %)
    enough = math.ceil(math.log((1.0 - level) / 2.0) / math.log(1.0 - ALIKE_SHARE))
    return (f"{text!r} held, but all {n} replications gave {values[0]:g}: that shows no "
            f"spread between them, not a value known exactly; with none of {n} unlike, up "
            f"to {share:.0%} of replications could give another value (the exact "
            f"{confidence_text(level)} bound), and about {enough} replications all alike "
            f"would bound that below {ALIKE_SHARE:.0%}. If the spec fixes this value (a "
            "schedule, a scripted user and no chance in the devices), the claim is exact "
            "and this note does not apply")


def decide_quantile(text: str, values: Sequence[float], q: float, op: str, a: float,
                    b: float | None, level: float) -> str | None:
    """Decide ``quantile_q(values) OP a`` with the distribution-free order-statistic
    interval: the ``k``-th smallest value is an upper bound of the ``q``-quantile with
    confidence ``P(Binomial(n, q) < k)``."""
    n = len(values)
    ordered = sorted(values)
    side_level = _levels(op, level)
    if n == 0:
        return f"expected {text}\n  but there were no observations at all"
    estimate, lo, hi = quantile_interval(ordered, q, one_sided(side_level))
    verdict = _verdict(op, a, b, lo, hi)
    if verdict is None:
        return None
    below = sum(1 for v in ordered if v <= a) / n
    side = "two-sided" if op == "in" else "one-sided"
    lines = [f"expected {text}",
             (f"  estimate {estimate:.4g} ({n} observations); {confidence_text(level)} {side} "
              f"order-statistic interval [{lo:.4g}, {hi:.4g}]; bound {_bound_text(op, a, b)}")]
    if verdict == "refuted":
        lines.append("  the claim is false at this confidence")
    elif op in ("<=", "<", ">=", ">") and not math.isclose(below, q):
        z = normal_quantile(side_level)
        needed = max(n + 1, math.ceil(z * z * q * (1 - q) / (below - q) ** 2))
        lines.append(f"  too few observations to decide: about {needed} would, if the "
                     f"distribution stays ({below:.1%} of them are now <= {a:g})")
    else:
        lines.append("  too few observations to decide")
    return "\n".join(lines)
