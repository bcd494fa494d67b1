"""Statistical assertions over many simulated users, and the numeric core behind them.

::

    from opspec.testing.assertions import assert_mean, assert_quantile, assert_rate

    assert_rate(result, ("doses_taken", "doses_due"), at_least=0.95, confidence=0.95)
    assert_mean(result, "alarms_per_dose", between=(1.1, 1.3))
    assert_quantile(result, "report_latency_s", 0.95, at_most=600)

A claim passes when the confidence bound on its side clears the bound (``at_least``: the
one-sided lower bound at ``confidence``; ``at_most``: the upper; both or ``between``: the
two-sided interval lies inside). It fails as *refuted* when the bound on the other side is
on the wrong side too, and otherwise as *undecided*, saying how many replications would
decide it if the estimate stayed where it is. Every message states the estimate, its
interval, the bound and n.

Intervals (from :mod:`opspec.statistics`, re-exported here; they return
``Estimate(estimate, lo, hi)``, two-sided at the given
confidence; a one-sided bound at level C is one end of the two-sided interval at 2C-1):

* rates: Wilson score (default; good coverage near 0 and 1) or Clopper-Pearson (exact,
  conservative), over pooled successes/trials. Pooling assumes the trials are independent;
  doses of one user are not quite, so prefer per-user claims (``assert_mean``) when users
  differ a lot.
* means of per-replication values: Student t (default) or a seeded BCa bootstrap
  (``scipy.stats.bootstrap``, 9999 resamples), for skewed values and small n.
* quantiles of pooled observations: the distribution-free order-statistic interval (the ranks
  come from the binomial distribution; valid for any continuous distribution).

A mean claim that passes on replications that all gave the same value passes on an interval
of no width: that shows no spread between them, not a value known exactly, and unless they
are enough (368 at 95 %) to bound the share that could give another value below 1 %,
:func:`assert_mean` says so in an :class:`AllAlikeWarning` (pytest lists it in its warnings
summary).

Sequential mode (:func:`assert_rate_sequential`) simulates batches until the claim is decided
or ``max_users`` is reached; with at most K looks it decides each look at confidence
``1 - (1 - C)/K`` (Bonferroni), so the chance of a wrong pass (or a wrong refutation) over
all looks stays at most ``1 - C``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from opspec.errors import ConfigurationError
from opspec.statistics import (
    RATE_METHODS,
    mean_interval,
    normal_quantile,
    quantile_interval,
    rate_interval,
    t_quantile,
)
from opspec.statistics import Interval as Estimate
from opspec.statistics.claims import alike_caveat, confidence_text, smallest_deciding

__all__ = [
    "AllAlikeWarning",
    "Decision",
    "Estimate",
    "SequentialOutcome",
    "assert_mean",
    "assert_quantile",
    "assert_rate",
    "assert_rate_sequential",
    "decide",
    "mean_interval",
    "quantile_interval",
    "rate_interval",
]



def _check_confidence(confidence: float) -> None:
    if not 0.5 <= confidence < 1.0:
        raise ConfigurationError(f"confidence must be at least 0.5 and below 1, not "
                                 f"{confidence!r}", hint="e.g. confidence=0.95")


# ---------------------------------------------------------------- deciding
class AllAlikeWarning(UserWarning):
    """A mean claim passed on replications that all gave the same value, too few of them to
    bound the share of replications that could give another (:func:`assert_mean`)."""


@dataclass(frozen=True, slots=True, repr=False)
class Decision:
    """The outcome of a statistical claim: ``verdict`` is ``"pass"``, ``"refuted"`` or
    ``"undecided"``; ``needed`` is the estimated number of replications that would decide an
    undecided claim (``None`` when none would: the estimate sits on the bound)."""

    claim: str
    verdict: str
    estimate: float
    lo: float
    hi: float
    n: int
    confidence: float
    sides: str                  # "one-sided" or "two-sided"
    interval: str               # "Wilson", "t", ...
    bound: str                  # ">= 0.95", "in [1, 2]"
    detail: str = ""            # "(40/40 doses_due, 10 replications)"
    needed: int | None = None
    unit: str = "replications"

    def __repr__(self) -> str:
        return f"<Decision {self.verdict}: {self.claim}; estimate {self.estimate:.4g} " \
               f"[{self.lo:.4g}, {self.hi:.4g}], n={self.n}>"

    def __str__(self) -> str:
        return self.message()

    @property
    def passed(self) -> bool:
        return self.verdict == "pass"

    def message(self) -> str:
        lines = [f"expected {self.claim}",
                 f"  estimate {self.estimate:.4g} {self.detail}".rstrip() + f"; n = {self.n}",
                 (f"  {confidence_text(self.confidence)} {self.sides} {self.interval} interval "
                 f"[{self.lo:.4g}, {self.hi:.4g}]; bound {self.bound}")]
        if self.verdict == "refuted":
            lines.append(f"  refuted: the claim is false at {confidence_text(self.confidence)} confidence")
        elif self.verdict == "undecided":
            if self.n == 0:
                lines.append("  nothing to judge: simulate longer or more users")
            elif self.needed is None:
                lines.append("  too few to decide, and the estimate sits on the bound: no "
                             "number of replications would settle it")
            else:
                lines.append(f"  too few {self.unit} to decide: about {self.needed} "
                             f"{self.unit} would, if the estimate stays at "
                             f"{self.estimate:.4g}")
        return "\n".join(lines)


def _target(at_least: float | None, at_most: float | None,
            between: tuple[float, float] | None) -> tuple[float | None, float | None]:
    if between is not None:
        if at_least is not None or at_most is not None:
            raise ConfigurationError("give between=(lo, hi) or at_least/at_most, not both")
        at_least, at_most = float(between[0]), float(between[1])
    if at_least is None and at_most is None:
        raise ConfigurationError("a statistical assertion needs a bound",
                                 hint="give at_least=, at_most= or between=(lo, hi)")
    if at_least is not None and at_most is not None and at_least > at_most:
        raise ConfigurationError(f"the range [{at_least}, {at_most}] is empty")
    return at_least, at_most


def _bound_text(at_least: float | None, at_most: float | None) -> str:
    if at_least is not None and at_most is not None:
        return f"in [{at_least:g}, {at_most:g}]"
    return f">= {at_least:g}" if at_least is not None else f"<= {at_most:g}"


def _two_sided_level(confidence: float, at_least: float | None, at_most: float | None
                     ) -> float:
    """The two-sided level whose ends are the bounds used (one-sided at C: 2C - 1)."""
    both = at_least is not None and at_most is not None
    return confidence if both else 2 * confidence - 1


def decide(lo: float, hi: float, at_least: float | None, at_most: float | None) -> str:
    """``"pass"``, ``"refuted"`` or ``"undecided"`` for an interval and bounds."""
    ok = (at_least is None or lo >= at_least) and (at_most is None or hi <= at_most)
    if ok:
        return "pass"
    wrong = (at_least is not None and hi < at_least) or (at_most is not None and lo > at_most)
    return "refuted" if wrong else "undecided"


def _distance(estimate: float, at_least: float | None, at_most: float | None) -> float:
    gaps = [abs(estimate - b) for b in (at_least, at_most) if b is not None]
    return min(gaps)


def _rate_decision(claim: str, successes: int, trials: int, at_least: float | None,
                   at_most: float | None, confidence: float, method: str, replications: int,
                   units: str) -> Decision:
    level = _two_sided_level(confidence, at_least, at_most)
    sides = "two-sided" if level == confidence else "one-sided"
    name = "Wilson" if method == "wilson" else "Clopper-Pearson"
    if trials == 0:
        return Decision(claim, "undecided", math.nan, 0.0, 1.0, 0, confidence, sides, name,
                        _bound_text(at_least, at_most),
                        f"(no {units} at all in {replications} replication(s))", None)
    est, lo, hi = rate_interval(successes, trials, level, method=method)
    verdict = decide(lo, hi, at_least, at_most)
    needed = None
    if verdict == "undecided" and _distance(est, at_least, at_most) > 0:
        def settles(n: int) -> bool:
            _, a, b = rate_interval(round(est * n), n, level, method=method)
            return decide(a, b, at_least, at_most) != "undecided"

        trials_needed = smallest_deciding(settles, trials)
        if trials_needed is not None:
            per = trials / max(1, replications)
            needed = max(replications + 1, math.ceil(trials_needed / per))
    return Decision(claim, verdict, est, lo, hi, trials, confidence, sides, name,
                    _bound_text(at_least, at_most),
                    f"({successes}/{trials} {units}, {replications} replication(s))", needed)


def _rate_counts(result: Any, metric: Any) -> tuple[int, int, str, str]:
    """(successes, trials, claim subject, unit name) of ``metric`` in ``result``."""
    if isinstance(metric, tuple) and len(metric) == 2:
        num, den = metric
        if isinstance(num, int) and isinstance(den, int):
            return num, den, f"{num}/{den}", "trials"
        s, t = result.counts(str(num), str(den))
        return s, t, f"{num}/{den}", str(den)
    if isinstance(metric, str):
        result.value(metric)                  # unknown names: ConfigurationError listing them
        definition = next(m for m in result.spec.metrics if m.name == metric)
        if definition.numerator and definition.denominator:
            s, t = result.counts(definition.numerator, definition.denominator)
            return s, t, metric, definition.denominator
        raise ConfigurationError(f"metric {metric!r} is not a ratio of two counts",
                                 hint="name a ratio metric or pass (numerator, denominator)")
    raise ConfigurationError(f"a rate is a ratio metric's name or a (numerator, denominator) "
                             f"pair, not {metric!r}")


def _require(result: Any, who: str, needs: str) -> None:
    __tracebackhide__ = True
    # imported here: the numeric core stays free of the engine
    from opspec.testing.simulation import require_result

    require_result(result, who, needs)


def _fail(decision: Decision, result: Any) -> None:
    __tracebackhide__ = True
    if decision.passed:
        return
    seed = getattr(result, "seed", None)
    tail = f"\n(seed {seed}, {result.replications} replication(s))" if seed is not None else ""
    raise AssertionError(decision.message() + tail)


# ---------------------------------------------------------------- assertions
def assert_rate(result: Any, metric: str | tuple[Any, Any], *, at_least: float | None = None,
                at_most: float | None = None, confidence: float = 0.95,
                method: str = "wilson") -> Decision:
    """Assert a proportion pooled over replications: ``metric`` is a ratio metric of two
    counts (``"taken_ratio"``), a pair of count metrics (``("doses_taken", "doses_due")``),
    or a pair of ints. Returns the :class:`Decision` when it passes."""
    __tracebackhide__ = True
    if not (isinstance(metric, tuple) and all(isinstance(x, int) for x in metric)):
        _require(result, "assert_rate", "counts")
    _check_confidence(confidence)
    at_least, at_most = _target(at_least, at_most, None)
    if method not in RATE_METHODS:
        raise ConfigurationError(f"unknown rate method {method!r}",
                                 hint="use " + " or ".join(RATE_METHODS))
    if (at_least is not None and at_least > 1.0) or (at_most is not None and at_most < 0.0):
        raise ConfigurationError(
            f"a rate lies between 0 and 1: {_bound_text(at_least, at_most)} can never hold",
            hint="write the bound as a fraction (95 % is 0.95)")
    s, t, subject, units = _rate_counts(result, metric)
    claim = f"rate {subject} {_bound_text(at_least, at_most)} with {confidence_text(confidence)} confidence"
    decision = _rate_decision(claim, s, t, at_least, at_most, confidence, method,
                              getattr(result, "replications", 1), units)
    _fail(decision, result)
    return decision


def _claim(subject: str, confidence: float, at_least: float | None, at_most: float | None,
           between: tuple[float, float] | None
           ) -> tuple[float | None, float | None, str, str, float, str]:
    """The parts every interval claim is stated with: its bounds (checked), the bound and the
    claim in words, the interval's level and whether it is one- or two-sided."""
    _check_confidence(confidence)
    at_least, at_most = _target(at_least, at_most, between)
    bound = _bound_text(at_least, at_most)
    level = _two_sided_level(confidence, at_least, at_most)
    return (at_least, at_most, bound,
            f"{subject} {bound} with {confidence_text(confidence)} confidence", level,
            "two-sided" if level == confidence else "one-sided")


def assert_mean(result: Any, metric: str, *, at_least: float | None = None,
                at_most: float | None = None, between: tuple[float, float] | None = None,
                confidence: float = 0.95, method: str = "t", seed: int = 0) -> Decision:
    """Assert the mean of ``metric``'s per-replication values (``result.samples``), with a
    Student t or seeded BCa bootstrap interval. Replications where the metric has no value (a
    duration never observed) are left out of the mean, and the decision says how many: a
    mean over the successful runs only says nothing about how often runs fail."""
    __tracebackhide__ = True
    _require(result, "assert_mean", "samples")
    at_least, at_most, bound, claim, level, sides = _claim(
        f"mean {metric}", confidence, at_least, at_most, between)
    values = result.samples(metric)
    name = "Student t" if method == "t" else "BCa bootstrap"
    n = len(values)
    if n < 2:
        decision = Decision(claim, "undecided", values[0] if values else math.nan, -math.inf,
                            math.inf, n, confidence, sides, name, bound,
                            "(a mean's interval needs at least 2 replications with a value)",
                            30)
        _fail(decision, result)
    est, lo, hi = mean_interval(values, level, method=method, seed=seed)
    verdict = decide(lo, hi, at_least, at_most)
    needed = None
    mean = est
    sd = math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (n - 1))
    gap = _distance(est, at_least, at_most)
    if verdict == "undecided" and gap > 0 and sd > 0:
        def settles(k: int) -> bool:
            return t_quantile(level, max(1, k - 1)) * sd / math.sqrt(k) < gap

        needed = smallest_deciding(settles, n)
        needed = None if needed is None else max(n + 1, needed)
    total = int(getattr(result, "replications", n) or n)
    left_out = (f"; {total - n} of {total} replications have no value of {metric} and are "
                "left out: assert how often it is missing separately") if total > n else ""
    decision = Decision(claim, verdict, est, lo, hi, n, confidence, sides, name, bound,
                        f"(sd {sd:.3g}, {n} replications{left_out})", needed)
    _fail(decision, result)
    caveat = alike_caveat(claim, values, confidence)
    if caveat is not None:
        warnings.warn(caveat, AllAlikeWarning, stacklevel=2)
    return decision


def assert_quantile(result: Any, metric: str, q: float, *, at_most: float | None = None,
                    at_least: float | None = None, confidence: float = 0.95) -> Decision:
    """Assert the ``q``-quantile of every observation of a duration metric
    (``result.observations``) with the distribution-free order-statistic interval."""
    __tracebackhide__ = True
    _require(result, "assert_quantile", "observations")
    at_least, at_most, bound, claim, level, sides = _claim(
        f"p{q * 100:g} {metric}", confidence, at_least, at_most, None)
    values = result.observations(metric)
    est, lo, hi = quantile_interval(values, q, level)
    verdict = decide(lo, hi, at_least, at_most)
    n = len(values)
    needed = None
    if verdict == "undecided" and n and (at_least is None or at_most is None):
        edge = at_most if at_most is not None else at_least
        assert edge is not None
        below = sum(1 for v in values if v <= edge) / max(1, n)
        if n and not math.isclose(below, q):
            z = normal_quantile((1 + level) / 2)
            needed = max(n + 1, math.ceil(z * z * q * (1 - q) / (below - q) ** 2))
    decision = Decision(claim, verdict, est, lo, hi, n, confidence, sides, "order-statistic",
                        bound, f"({n} observations)", needed, unit="observations")
    _fail(decision, result)
    return decision


# ---------------------------------------------------------------- sequential
@dataclass(frozen=True, slots=True)
class SequentialOutcome:
    """How a sequential assertion ended: the last look's decision, the looks taken, the
    users simulated, and the per-look confidence used."""

    decision: Decision
    looks: int
    users: int
    max_looks: int
    look_confidence: float


def assert_rate_sequential(simulate_batch: Callable[[int, int], Any],
                           metric: str | tuple[Any, Any], *, at_least: float | None = None,
                           at_most: float | None = None, confidence: float = 0.95,
                           method: str = "wilson", batch_users: int = 100,
                           max_users: int = 2000) -> SequentialOutcome:
    """Simulate batches until the rate claim is decided or ``max_users`` are simulated.

    ``simulate_batch(k, n)`` returns a :class:`~opspec.testing.simulation.SimulationResult` of
    ``n`` users, independent of every other batch (e.g. ``simulate(spec, users=n,
    seed=derive_seed(base, str(k)))``). With ``K = ceil(max_users / batch_users)`` looks, each
    look decides at ``1 - (1 - confidence)/K`` on the counts pooled so far (Bonferroni), so
    the error rate over all looks is at most ``1 - confidence``. Passing returns the outcome;
    a refutation, or no decision by the cap, raises ``AssertionError`` saying so."""
    __tracebackhide__ = True
    _check_confidence(confidence)
    at_least, at_most = _target(at_least, at_most, None)
    if batch_users < 1 or max_users < batch_users:
        raise ConfigurationError("need 1 <= batch_users <= max_users")
    max_looks = math.ceil(max_users / batch_users)
    look_conf = 1 - (1 - confidence) / max_looks
    successes = trials = users = 0
    subject = units = ""
    decision: Decision | None = None
    last: Any = None
    for look in range(1, max_looks + 1):
        size = min(batch_users, max_users - users)
        last = simulate_batch(look - 1, size)
        s, t, subject, units = _rate_counts(last, metric)
        successes, trials, users = successes + s, trials + t, users + size
        claim = (f"rate {subject} {_bound_text(at_least, at_most)} with {confidence_text(confidence)} "
                 f"confidence (sequential, {look_conf:.4%} per look, up to {max_looks} looks)")
        decision = _rate_decision(claim, successes, trials, at_least, at_most, look_conf,
                                  method, users, units)
        if decision.verdict != "undecided":
            break
    assert decision is not None
    outcome = SequentialOutcome(decision, look, users, max_looks, look_conf)
    if decision.passed:
        return outcome
    text = decision.message()
    if decision.verdict == "undecided":
        text += (f"\n  stopped at the cap: {users} users in {look} look(s) (max_users="
                 f"{max_users}) did not decide it; raise max_users")
    else:
        text += f"\n  decided after {look} of {max_looks} look(s), {users} users"
    raise AssertionError(text)
