"""Estimating a user model from recorded traces (``opspec fit TRACE... -o model.toml``).

Input: JSON Lines trace files (``docs/trace-format.md``): a header line
``{"format": "opspec-trace", "version": 1, ...}`` then one ``TraceEvent.to_json()`` object per
line. For the lane being fitted (``lane`` or ``participant`` equal to ``lane``, default
``user``) the events ``activity.offered`` and ``activity.completed`` / ``activity.omitted`` /
``activity.withdrawn`` are paired per (run, instance, activity), first offered first answered.
A ``run.started`` event starts a new run, so one file may hold many replications.

Estimated, per activity:

* duration (offer to completion): lognormal by maximum likelihood and ex-Gaussian by maximum
  likelihood (scipy, started from the method-of-moments estimate); the one with the lower AIC
  is written, and the comparison is written as a comment above the activity's table;
* omission rate (omissions / answered offers, omissions with reason ``busy`` excluded) with
  a Wilson 95 % interval;
* choices (``data.choice`` of the completion, or the next activity offered in the instance
  when the offer listed ``data.choices``): an intended alternative with a commission rate
  when every instance ends on the same alternative, fixed probabilities otherwise;
* busy: activities in progress in another instance when a prompt was omitted as ``busy``.
"""

from __future__ import annotations

import io
import json
import math
import warnings
from collections import Counter, defaultdict, deque
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats  # type: ignore[import-untyped]

from opspec.engine.trace import TRACE_FORMAT, TRACE_FORMAT_VERSION, EventKind, TraceEvent
from opspec.errors import SourceLocation, UserModelError
from opspec.statistics import rate_interval
from opspec.usermodels.distributions import Constant, Distribution, ExGaussian, LogNormal
from opspec.usermodels.errors import Busy, Commission, Omission
from opspec.usermodels.model import ActivityModel, UserModel

__all__ = [
    "ActivityFit",
    "FitResult",
    "Observations",
    "collect",
    "fit_duration",
    "fit_traces",
    "read_trace",
]

_ANSWERS = (EventKind.ACTIVITY_COMPLETED, EventKind.ACTIVITY_OMITTED,
            EventKind.ACTIVITY_WITHDRAWN)


def read_trace(path: str | Path) -> Iterator[TraceEvent]:
    """The events of one JSON Lines trace file, streamed; :class:`UserModelError` naming
    ``path:line`` for an unreadable file, a missing/foreign header or a malformed line."""
    from opspec.files import open_regular, reason

    name = str(path)
    try:
        # a pipe or device is refused, never read (it would block); closed in the finally
        handle = io.TextIOWrapper(open_regular(path), encoding="utf-8")
    except OSError as error:
        raise UserModelError(f"cannot read trace: {reason(error)}",
                             location=SourceLocation(name)) from None
    try:
        header_seen = False
        for number, line in enumerate(handle, start=1):
            if not line.strip():
                continue
            try:
                obj = json.loads(line)
            except json.JSONDecodeError as error:
                raise UserModelError(f"not valid JSON: {error.msg}",
                                     location=SourceLocation(name, number),
                                     hint="each line of a trace is one JSON object") from None
            if not header_seen:
                if not isinstance(obj, dict) or obj.get("format") != TRACE_FORMAT:
                    raise UserModelError(
                        "not an opspec trace: the first line must be a header "
                        f'{{"format": "{TRACE_FORMAT}", "version": {TRACE_FORMAT_VERSION}, ...}}',
                        location=SourceLocation(name, number),
                        hint="record traces with `opspec run --trace FILE` or "
                        "`opspec evaluate --export jsonl`")
                if obj.get("version") != TRACE_FORMAT_VERSION:
                    raise UserModelError(
                        f"unsupported trace version {obj.get('version')!r}",
                        location=SourceLocation(name, number),
                        hint=f"this opspec reads version {TRACE_FORMAT_VERSION}")
                header_seen = True
                continue
            try:
                yield TraceEvent.from_json(obj)
            except (KeyError, TypeError, ValueError) as error:
                raise UserModelError(f"not a trace event ({error})",
                                     location=SourceLocation(name, number),
                                     hint='an event needs at least "time" and "kind"') from None
        if not header_seen:
            raise UserModelError("empty trace: no header and no events",
                                 location=SourceLocation(name),
                                 hint="record the trace again; the run may have been killed "
                                 "before it started")
    except UnicodeDecodeError:
        raise UserModelError("not a text trace (it is not UTF-8)",
                             location=SourceLocation(name)) from None
    finally:
        handle.close()


@dataclass
class Observations:
    """What the traces say about one lane, per activity."""

    durations: dict[str, list[float]] = field(default_factory=lambda: defaultdict(list))
    omitted: Counter[str] = field(default_factory=Counter)
    busy_omitted: Counter[str] = field(default_factory=Counter)
    picks: dict[str, list[list[str]]] = field(default_factory=lambda: defaultdict(list))
    engaged: set[str] = field(default_factory=set)
    events: int = 0
    runs: int = 0
    files: int = 0
    lanes_seen: set[str] = field(default_factory=set)

    @property
    def activities(self) -> list[str]:
        names = set(self.durations) | set(self.omitted) | set(self.busy_omitted)
        return sorted(names)


def collect(paths: Sequence[str | Path], lane: str = "user") -> Observations:
    """Pair offers with answers in ``paths`` for ``lane`` (see the module docstring)."""
    obs = Observations()
    for path in paths:
        obs.files += 1
        run = 0
        outstanding: dict[tuple[int, Any, str], deque[tuple[float, str]]] = {}
        in_progress: dict[tuple[int, Any, str], int] = Counter()
        pending_choice: dict[tuple[int, Any], tuple[str, tuple[str, ...]]] = {}
        picks_of: dict[tuple[int, Any], dict[str, list[str]]] = {}
        for event in read_trace(path):
            obs.events += 1
            if event.kind == EventKind.RUN_STARTED:
                run += 1
                obs.runs += 1
                continue
            if event.lane:
                obs.lanes_seen.add(event.lane)
            if event.activity is None or (event.lane != lane and event.participant != lane):
                continue
            inst = (run, event.instance)
            key = (run, event.instance, event.activity)
            if event.kind == EventKind.ACTIVITY_OFFERED:
                waiting = pending_choice.pop(inst, None)
                if waiting is not None and event.activity in waiting[1]:
                    picks_of.setdefault(inst, {}).setdefault(waiting[0], []).append(
                        event.activity)
                outstanding.setdefault(key, deque()).append((event.time, event.activity))
                in_progress[key] += 1
                choices = event.data.get("choices")
                if isinstance(choices, (list, tuple)) and choices:
                    pending_choice[inst] = (event.activity, tuple(map(str, choices)))
                continue
            if event.kind not in _ANSWERS:
                continue
            queue = outstanding.get(key)
            if not queue:
                continue  # an answer without its offer (trace cut at the start)
            offered_at, _ = queue.popleft()
            in_progress[key] -= 1
            reason = str(event.data.get("reason", ""))
            if event.kind == EventKind.ACTIVITY_COMPLETED:
                obs.durations[event.activity].append(max(0.0, event.time - offered_at))
                choice = event.data.get("choice")
                if isinstance(choice, str):
                    pending_choice.pop(inst, None)
                    picks_of.setdefault(inst, {}).setdefault(event.activity, []).append(choice)
            elif event.kind == EventKind.ACTIVITY_OMITTED:
                if reason == "busy":
                    obs.busy_omitted[event.activity] += 1
                    obs.engaged.update(a for (r, i, a), n in in_progress.items()
                                       if n > 0 and r == run and i != event.instance)
                else:
                    obs.omitted[event.activity] += 1
        for per_instance in picks_of.values():
            for activity, sequence in per_instance.items():
                obs.picks[activity].append(sequence)
    if not obs.durations and not obs.omitted and not obs.busy_omitted:
        seen = ", ".join(sorted(obs.lanes_seen)) or "none"
        raise UserModelError(
            f"no activity of lane {lane!r} in {len(paths)} trace file(s) "
            f"({obs.events} events; lanes seen: {seen})",
            location=SourceLocation(str(paths[0])) if paths else None,
            hint="record traces of the user lane (for instance a TUI walkthrough), or pick "
            "the lane with --lane")
    return obs


@dataclass(frozen=True)
class ActivityFit:
    """The outcome for one activity: the chosen distribution and why."""

    activity: str
    n: int
    distribution: Distribution
    chosen: str
    aic: dict[str, float]
    omission: tuple[int, int, tuple[float, float]] | None = None  # omitted, answered, CI
    note: str = ""

    def comment(self) -> str:
        lines = [f"{self.activity}: {self.n} observed duration(s); {self.note}".rstrip("; ")]
        if self.aic:
            scores = ", ".join(f"{k} AIC = {v:.2f}" for k, v in sorted(self.aic.items(),
                                                                        key=lambda kv: kv[1]))
            lines.append(f"duration: {self.chosen} chosen by AIC ({scores})")
        if self.omission is not None:
            k, n, (lo, hi) = self.omission
            lines.append(f"omission: {k}/{n} = {k / n:.4f}, Wilson 95 % interval "
                         f"[{lo:.4f}, {hi:.4f}]")
        return "\n".join(lines)


def _exgauss_mle(x: np.ndarray) -> tuple[ExGaussian, float] | None:
    m, s = float(x.mean()), float(x.std())
    skew = float(stats.skew(x))
    tau0 = s * (max(skew, 0.05) / 2) ** (1 / 3)          # method of moments, kept positive
    sigma0 = math.sqrt(max(s * s - tau0 * tau0, (0.1 * s) ** 2))
    mu0 = m - tau0
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        try:
            k, loc, scale = stats.exponnorm.fit(x, tau0 / sigma0, loc=mu0, scale=sigma0)
        except (ValueError, RuntimeError, FloatingPointError):
            return None
        ll = float(np.sum(stats.exponnorm.logpdf(x, k, loc=loc, scale=scale)))
    if not (math.isfinite(ll) and scale > 0 and k > 0):
        return None
    return ExGaussian(float(loc), float(scale), float(k * scale)), ll


def fit_duration(values: Sequence[float]) -> tuple[Distribution, str, dict[str, float], str]:
    """Best of lognormal (MLE) and ex-Gaussian (MLE) by AIC for ``values`` (seconds).

    Returns ``(distribution, chosen_name, {name: AIC}, note)``. All-equal data give a
    constant; fewer than 3 values give a lognormal (an ex-Gaussian needs more)."""
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        return Constant(0.0), "constant", {}, "no completed performance: duration 0"
    if x.size == 1 or float(np.ptp(x)) < 1e-9:
        return Constant(float(x[0])), "constant", {}, "all durations equal"
    aic: dict[str, float] = {}
    candidates: dict[str, Distribution] = {}
    if np.all(x > 0):
        logs = np.log(x)
        mu, sigma = float(logs.mean()), float(logs.std())
        if sigma > 0:
            ll = float(np.sum(stats.norm.logpdf(logs, mu, sigma) - logs))
            candidates["lognormal"] = LogNormal(mu, sigma)
            aic["lognormal"] = 2 * 2 - 2 * ll
    if x.size >= 3:
        fitted = _exgauss_mle(x)
        if fitted is not None:
            candidates["exgauss"] = fitted[0]
            aic["exgauss"] = 2 * 3 - 2 * fitted[1]
    if not candidates:
        return (Constant(float(x.mean())), "constant", {},
                "neither lognormal nor ex-Gaussian could be fitted: the mean is used")
    chosen = min(aic, key=aic.__getitem__)
    note = "" if np.all(x > 0) else "zero durations present: lognormal not possible"
    return candidates[chosen], chosen, aic, note


@dataclass(frozen=True)
class FitResult:
    """A fitted model plus the per-activity explanation written as TOML comments."""

    model: UserModel
    fits: tuple[ActivityFit, ...]
    observations: Observations

    def comments(self) -> dict[str, str]:
        return {f"activities.{f.activity}": f.comment() for f in self.fits}


def _choice_model(picks: list[list[str]]) -> dict[str, Any]:
    finals = Counter(seq[-1] for seq in picks if seq)
    if len(finals) == 1:
        intended = next(iter(finals))
        wrong_counts = [sum(1 for c in seq if c != intended) for seq in picks]
        cap = max(wrong_counts)
        if cap == 0:
            return {"intended": intended}
        # Offers at which a wrong pick was still possible: the first `cap` of each instance.
        eligible = sum(min(len(seq), cap) for seq in picks)
        wrong = sum(min(w, cap) for w in wrong_counts)
        alternatives = sorted({c for seq in picks for c in seq if c != intended})
        return {"intended": intended, "commission": Commission(
            wrong / eligible, alternatives=tuple(alternatives), max_per_instance=cap,
            source=f"fitted: {wrong} wrong pick(s) in {eligible} eligible offers")}
    everything = Counter(c for seq in picks for c in seq)
    total = sum(everything.values())
    pairs = [(name, n / total) for name, n in sorted(everything.items())]
    # Make the rounded shares add up to exactly 1 for the loader's check.
    head = [(name, round(p, 6)) for name, p in pairs[:-1]]
    return {"probabilities": (*head, (pairs[-1][0], 1.0 - sum(p for _, p in head)))}


def fit_traces(paths: Sequence[str | Path], *, lane: str = "user",
               name: str = "fitted") -> FitResult:
    """Fit a :class:`UserModel` for ``lane`` from the trace files ``paths``."""
    if not paths:
        raise UserModelError("no trace files given", hint="opspec fit TRACE... -o model.toml")
    obs = collect(paths, lane)
    origin = f"{len(paths)} trace file(s), {obs.events} events"
    activities: dict[str, ActivityModel] = {}
    fits = []
    for activity in obs.activities:
        values = obs.durations.get(activity, [])
        dist, chosen, aic, note = fit_duration(values)
        omitted = obs.omitted.get(activity, 0)
        answered = omitted + len(values)
        omission_stats = None
        kwargs: dict[str, Any] = {"duration": dist}
        if omitted:
            _, low, high = rate_interval(omitted, answered)
            lo_hi = (low, high)
            omission_stats = (omitted, answered, lo_hi)
            kwargs["omission"] = Omission(
                omitted / answered, source=f"fitted: {omitted}/{answered} omitted, Wilson 95 % "
                f"interval [{lo_hi[0]:.4f}, {lo_hi[1]:.4f}]")
        if obs.picks.get(activity):
            kwargs.update(_choice_model(obs.picks[activity]))
        aic_text = ", ".join(f"{k} AIC {v:.2f}" for k, v in sorted(aic.items()))
        kwargs["source"] = (f"fitted by opspec fit from {origin}: n = {len(values)}, "
                            f"{chosen}" + (f" by AIC ({aic_text})" if aic else ""))
        activities[activity] = ActivityModel(**kwargs)
        fits.append(ActivityFit(activity, len(values), dist, chosen, aic, omission_stats, note))
    busy = None
    if obs.busy_omitted:
        engaged = obs.engaged or set(obs.durations) - set(obs.busy_omitted)
        busy = Busy(frozenset(engaged), ignore=frozenset(obs.busy_omitted),
                    source=f"fitted: {sum(obs.busy_omitted.values())} prompt(s) ignored "
                    "while busy in another instance")
    model = UserModel(name=name, activities=activities, busy=busy,
                      description=f"Fitted from {origin} (lane {lane!r}).",
                      source=f"opspec fit on {', '.join(str(p) for p in paths[:5])}"
                      + (" ..." if len(paths) > 5 else ""))
    return FitResult(model, tuple(fits), obs)


def iter_paths(values: Iterable[str]) -> list[Path]:
    """Expand directories given on the command line to the ``*.jsonl`` files inside."""
    out: list[Path] = []
    for value in values:
        path = Path(value)
        out.extend(sorted(path.glob("*.jsonl")) if path.is_dir() else [path])
    return out
