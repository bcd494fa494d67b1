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
from collections import Counter, defaultdict, deque
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from opspec.engine.trace import TRACE_FORMAT, TRACE_FORMAT_VERSION, EventKind, TraceEvent
from opspec.errors import SourceLocation, UserModelError
from opspec.files import json_loads
from opspec.statistics import rate_interval
from opspec.usermodels.distributions import Constant, Distribution, Gamma, LogNormal, Weibull
from opspec.usermodels.errors import Busy, Commission, Omission
from opspec.usermodels.families import CRITERIA, FamilyFit, choose, fit_families
from opspec.usermodels.model import ActivityModel, UserModel
from opspec.usermodels.persons import PersonRule
from opspec.usermodels.spread import (
    DurationSpread,
    OmissionSpread,
    duration_spread,
    omission_spread,
)

__all__ = [
    "ActivityFit",
    "FitResult",
    "Observations",
    "WrongChoiceLoss",
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
                obj = json_loads(line)
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
    #: answers a walkthrough marked as not timed in real time (their durations are left out)
    unusable: Counter[str] = field(default_factory=Counter)
    #: per activity, per user (file index, run index): durations and (omitted, answered)
    user_durations: dict[str, dict[tuple[int, int], list[float]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(list)))
    user_omissions: dict[str, dict[tuple[int, int], list[int]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(lambda: [0, 0])))
    #: per choice activity, per picked alternative: the durations of that pick
    pick_durations: dict[str, dict[str, list[float]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(list)))
    #: the same per session (file index, run index): the picks of each instance, and per
    #: picked alternative its durations (what a person-level bootstrap resamples)
    user_picks: dict[str, dict[tuple[int, int], list[list[str]]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(list)))
    user_pick_durations: dict[str, dict[str, dict[tuple[int, int], list[float]]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(lambda: defaultdict(list))))
    #: who each session (file index, run index) is (opspec.usermodels.persons)
    person_of: dict[tuple[int, int], str] = field(default_factory=dict)
    events: int = 0
    runs: int = 0
    files: int = 0
    lanes_seen: set[str] = field(default_factory=set)

    @property
    def activities(self) -> list[str]:
        names = set(self.durations) | set(self.omitted) | set(self.busy_omitted)
        return sorted(names)

    @property
    def persons(self) -> list[str]:
        """The persons the sessions belong to, in order of appearance."""
        return list(dict.fromkeys(self.person_of.values()))

    @property
    def sessions(self) -> int:
        return len(self.person_of)

    def person(self, session: tuple[int, int]) -> str:
        return self.person_of.get(session, f"{session[0]}#{session[1]}")

    def lists_by_person(self, per_session: Mapping[tuple[int, int], Sequence[Any]]
                        ) -> dict[str, list[Any]]:
        """Per-session lists (durations, pick sequences) concatenated per person."""
        out: dict[str, list[Any]] = {}
        for session, values in per_session.items():
            out.setdefault(self.person(session), []).extend(values)
        return out

    def counts_by_person(self, per_session: Mapping[tuple[int, int], Sequence[int]]
                         ) -> dict[str, tuple[int, int]]:
        """Per-session ``[omitted, answered]`` added up per person."""
        out: dict[str, tuple[int, int]] = {}
        for session, (k, n) in per_session.items():
            k0, n0 = out.get(self.person(session), (0, 0))
            out[self.person(session)] = (k0 + k, n0 + n)
        return out


def collect(paths: Sequence[str | Path], lane: str = "user",
            persons: PersonRule | None = None) -> Observations:
    """Pair offers with answers in ``paths`` for ``lane`` (see the module docstring);
    ``persons`` says whose each session is (default: the header's ``person``, else each run
    a person of its own)."""
    obs = Observations()
    rule = persons or PersonRule()
    for file_index, path in enumerate(paths):
        obs.files += 1
        whose = rule.of_file(Path(path))
        run = 0
        outstanding: dict[tuple[int, Any, str], deque[tuple[float, str]]] = {}
        in_progress: dict[tuple[int, Any, str], int] = Counter()
        pending_choice: dict[tuple[int, Any], tuple[str, tuple[str, ...]]] = {}
        unreal: set[tuple[int, Any, str]] = set()     # (run, instance, activity)
        picks_of: dict[tuple[int, Any], dict[str, list[str]]] = {}
        for event in read_trace(path):
            obs.events += 1
            if event.kind == EventKind.RUN_STARTED:
                run += 1
                obs.runs += 1
                obs.person_of[(file_index, run)] = (
                    whose if whose is not None else f"{Path(path).name}#{run}")
                continue
            if event.lane:
                obs.lanes_seen.add(event.lane)
            if event.kind == "walkthrough.action" and event.data.get("usable") is False:
                # a walkthrough's answer whose simulated duration is not the person's
                # (docs/walkthrough.md): its duration is not fitted
                unreal.add((run, event.data.get("instance"), str(event.data.get("activity"))))
                continue
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
            user = (file_index, run)
            if event.kind == EventKind.ACTIVITY_COMPLETED:
                took = max(0.0, event.time - offered_at)
                real = _real_duration(unreal, key, obs)
                if real:
                    obs.durations[event.activity].append(took)
                    obs.user_durations[event.activity][user].append(took)
                obs.user_omissions[event.activity][user][1] += 1
                choice = event.data.get("choice")
                if isinstance(choice, str):
                    if real:
                        obs.pick_durations[event.activity][choice].append(took)
                        obs.user_pick_durations[event.activity][choice][user].append(took)
                    pending_choice.pop(inst, None)
                    picks_of.setdefault(inst, {}).setdefault(event.activity, []).append(choice)
            elif event.kind == EventKind.ACTIVITY_OMITTED:
                if reason == "busy":
                    obs.busy_omitted[event.activity] += 1
                    obs.engaged.update(a for (r, i, a), n in in_progress.items()
                                       if n > 0 and r == run and i != event.instance)
                else:
                    obs.omitted[event.activity] += 1
                    counts = obs.user_omissions[event.activity][user]
                    counts[0] += 1
                    counts[1] += 1
        for (picked_in, _), per_instance in picks_of.items():
            for activity, sequence in per_instance.items():
                obs.picks[activity].append(sequence)
                obs.user_picks[activity][(file_index, picked_in)].append(sequence)
        if run == 0:                    # a trace without run.started: one session
            obs.person_of[(file_index, 0)] = (whose if whose is not None
                                              else f"{Path(path).name}#0")
    if not obs.durations and not obs.omitted and not obs.busy_omitted:
        seen = ", ".join(sorted(obs.lanes_seen)) or "none"
        unusable = sum(obs.unusable.values())
        raise UserModelError(
            f"no activity of lane {lane!r} in {len(paths)} trace file(s) "
            f"({obs.events} events; lanes seen: {seen})" + (
                f"; {unusable} walkthrough answer(s) left out: not timed in real time"
                if unusable else ""),
            location=SourceLocation(str(paths[0])) if paths else None,
            hint="record traces of the user lane (for instance a TUI walkthrough), or pick "
            "the lane with --lane")
    return obs


@dataclass(frozen=True)
class WrongChoiceLoss:
    """The time a wrong pick costs, apart from the choice's own duration: the mean of the
    wrong picks' durations minus the mean of the intended picks' (Welch 95 % interval)."""

    choice: str
    alternatives: tuple[str, ...]
    wrong: int
    right: int
    seconds: float
    ci: tuple[float, float]
    distribution: Distribution

    def comment(self) -> str:
        lo, hi = self.ci
        return (f"time lost to a wrong choice ({', '.join(self.alternatives)}): "
                f"{self.seconds:.4g} s (95 % interval [{lo:.4g}, {hi:.4g}]) = mean of "
                f"{self.wrong} wrong pick(s) - mean of {self.right} intended pick(s); written "
                "as the wrong alternative's duration")

    def to_json(self) -> dict[str, Any]:
        return {"choice": self.choice, "alternatives": list(self.alternatives),
                "wrong_picks": self.wrong, "intended_picks": self.right,
                "seconds": self.seconds, "ci95": list(self.ci),
                "distribution": self.distribution.to_params()}


def _real_duration(unreal: set[tuple[int, Any, str]], key: tuple[int, Any, str],
                   obs: Observations) -> bool:
    """Whether the answer ``key`` has a real duration. A walkthrough marks those it has not
    (``walkthrough.action`` with ``usable: false``: the clock was paused, ran faster than real
    time or jumped, or the user model answered); they are counted in ``obs.unusable``."""
    if key in unreal:
        unreal.discard(key)
        obs.unusable[key[2]] += 1
        return False
    return True


@dataclass(frozen=True)
class ActivityFit:
    """The outcome for one activity: the chosen distribution, every family's fit, and why."""

    activity: str
    n: int
    distribution: Distribution
    chosen: str
    aic: dict[str, float]
    omission: tuple[int, int, tuple[float, float]] | None = None  # omitted, answered, CI
    note: str = ""
    families: tuple[FamilyFit, ...] = ()
    criterion: str = "aic"
    duration_spread: DurationSpread | None = None
    omission_spread: OmissionSpread | None = None
    wrong_choice: WrongChoiceLoss | None = None

    def family_table(self) -> list[str]:
        """The comparison of families as aligned text lines (chosen one marked)."""
        if not self.families:
            return []
        best = {c: min(f.score(c) for f in self.families) for c in CRITERIA}
        rows = [(f"  {'family':<10} {'parameters':<36} {'log L':>11} {'AIC':>10} {'dAIC':>7} "
                f"{'BIC':>10} {'dBIC':>7}")]
        for f in sorted(self.families, key=lambda f: f.score(self.criterion)):
            mark = "  <- chosen" if f.family == self.chosen else ""
            rows.append(f"  {f.family:<10} {f.describe():<36} {f.log_likelihood:>11.2f} "
                        f"{f.aic:>10.2f} {f.aic - best['aic']:>7.2f} {f.bic:>10.2f} "
                        f"{f.bic - best['bic']:>7.2f}{mark}")
        return rows

    def comment(self) -> str:
        lines = [f"{self.activity}: {self.n} observed duration(s); {self.note}".rstrip("; ")]
        if self.families:
            lines.append(f"duration: {self.chosen} chosen by {self.criterion.upper()} (lowest "
                         "wins; a difference under 2 is no real preference)")
            lines.extend(self.family_table())
        if self.omission is not None:
            k, n, (lo, hi) = self.omission
            lines.append(f"omission: {k}/{n} = {k / n:.4f}, Wilson 95 % interval "
                         f"[{lo:.4f}, {hi:.4f}]")
        for part in (self.wrong_choice, self.duration_spread, self.omission_spread):
            if part is not None:
                lines.append(part.comment())
        return "\n".join(lines)

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "n": self.n, "chosen": self.chosen, "criterion": self.criterion,
            "distribution": self.distribution.to_params(), "note": self.note or None,
            "families": [f.to_json() for f in self.families]}
        if self.omission is not None:
            k, n, (lo, hi) = self.omission
            out["omission"] = {"omitted": k, "answered": n, "rate": k / n, "ci95": [lo, hi]}
        out["wrong_choice"] = self.wrong_choice.to_json() if self.wrong_choice else None
        out["between_users"] = {
            "duration": self.duration_spread.to_json() if self.duration_spread else None,
            "omission": self.omission_spread.to_json() if self.omission_spread else None}
        return out


def fit_duration(values: Sequence[float], criterion: str = "aic"
                 ) -> tuple[Distribution, str, dict[str, float], str]:
    """The best family of :data:`~opspec.usermodels.families.FAMILIES` by ``criterion`` for
    ``values`` (seconds). Returns ``(distribution, chosen_name, {name: AIC}, note)``.
    All-equal data give a constant."""
    dist, chosen, fits, note = _fit_duration(values, criterion)
    return dist, chosen, {f.family: f.aic for f in fits}, note


def _fit_duration(values: Sequence[float], criterion: str = "aic"
                  ) -> tuple[Distribution, str, tuple[FamilyFit, ...], str]:
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        return Constant(0.0), "constant", (), "no completed performance: duration 0"
    if x.size == 1 or float(np.ptp(x)) < 1e-9:
        return Constant(float(x[0])), "constant", (), "all durations equal"
    fits = tuple(fit_families(x))
    if not fits:
        return (Constant(float(x.mean())), "constant", (),
                "no family could be fitted: the mean is used")
    best = choose(fits, criterion)
    note = "" if np.all(x > 0) else ("zero durations present: only the ex-Gaussian can "
                                     "describe them")
    return best.distribution, best.family, fits, note


@dataclass(frozen=True)
class FitResult:
    """A fitted model plus the per-activity explanation written as TOML comments."""

    model: UserModel
    fits: tuple[ActivityFit, ...]
    observations: Observations

    def comments(self) -> dict[str, str]:
        return {f"activities.{f.activity}": f.comment() for f in self.fits}

    def to_json(self) -> dict[str, Any]:
        return {"events": self.observations.events, "runs": self.observations.runs,
                "files": self.observations.files,
                "activities": {f.activity: f.to_json() for f in self.fits}}

    def vary(self) -> dict[str, dict[str, dict[str, Any]]]:
        """The between-user variation to write as ``[vary.activities.ID.*]`` tables of the
        fitted file (``docs/user-models.md``, Populations): per activity, where the data
        show users differ (a duration spread whose 95 % interval excludes 0; omission rates
        that fail the chi-square test of one rate for all at 5 %). A lognormal's median, a
        gamma's or Weibull's scale varies lognormally with the between-user sd; the
        omission probability by a beta with the between-user mean and sd."""
        out: dict[str, dict[str, dict[str, Any]]] = {}
        for fit in self.fits:
            entry: dict[str, dict[str, Any]] = {}
            d = fit.duration_spread
            dist = fit.distribution
            if d is not None and d.between_sd_ci[0] > 0 and d.between_sd > 0:
                source = (f"fitted: between-user sd of ln(scale) {d.between_sd:.3f} (95 % "
                          f"interval [{d.between_sd_ci[0]:.3f}, {d.between_sd_ci[1]:.3f}], "
                          f"{d.users} users)")
                if isinstance(dist, LogNormal):
                    entry["duration"] = {"median": {
                        "kind": "lognormal", "median": math.exp(dist.mu),
                        "sigma": d.between_sd, "source": source}}
                elif isinstance(dist, (Gamma, Weibull)):
                    entry["duration"] = {"scale": {
                        "kind": "lognormal", "median": dist.scale, "sigma": d.between_sd,
                        "source": source}}
            o = fit.omission_spread
            if o is not None and o.varies:
                entry["omission"] = {"probability": {
                    "kind": "beta", "mean": o.mean, "sd": o.between_sd,
                    "source": f"fitted: between-user sd {o.between_sd:.4f} (95 % interval "
                    f"[{o.between_sd_ci[0]:.4f}, {o.between_sd_ci[1]:.4f}], {o.users} users; "
                    f"one rate for all: chi-square p = {o.homogeneity_p:.2g})"}}
            if entry:
                out[fit.activity] = entry
        return out


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


def _wrong_choice_loss(choice: str, intended: str, by_pick: dict[str, list[float]],
                       criterion: str) -> WrongChoiceLoss | None:
    """Separate the time a wrong pick costs from the choice's own duration."""
    right = np.asarray(by_pick.get(intended, []), dtype=float)
    wrong_names = tuple(sorted(p for p in by_pick if p != intended))
    wrong = np.asarray([v for p in wrong_names for v in by_pick[p]], dtype=float)
    if right.size == 0 or wrong.size == 0:
        return None
    seconds = float(wrong.mean() - right.mean())
    if wrong.size >= 2 and right.size >= 2 and (wrong.std() > 0 or right.std() > 0):
        from scipy import stats  # type: ignore[import-untyped]

        test = stats.ttest_ind(wrong, right, equal_var=False)
        ci = test.confidence_interval(0.95)
        interval = (float(ci.low), float(ci.high))
    else:
        interval = (seconds, seconds)
    lost = np.maximum(wrong - right.mean(), 0.0)
    dist, _, _, _ = _fit_duration(lost.tolist(), criterion)
    return WrongChoiceLoss(choice, wrong_names, int(wrong.size), int(right.size), seconds,
                           interval, dist)


def fit_traces(paths: Sequence[str | Path], *, lane: str = "user", name: str = "fitted",
               criterion: str = "aic", min_per_user: int = 10,
               persons: PersonRule | None = None) -> FitResult:
    """Fit a :class:`UserModel` for ``lane`` from the trace files ``paths``: per activity the
    best duration family by ``criterion`` (``aic`` or ``bic``), omission rates, choices with
    the time a wrong pick costs, and the between-user spread of persons with at least
    ``min_per_user`` observations (``persons`` says whose each session is: several sessions
    of one participant are one person; :mod:`opspec.usermodels.persons`)."""
    if not paths:
        raise UserModelError("no trace files given", hint="opspec fit TRACE... -o model.toml")
    if criterion not in CRITERIA:
        raise UserModelError(f"unknown selection criterion {criterion!r}",
                             hint="use --criterion aic or --criterion bic")
    if persons is not None:
        persons.check_used([Path(p) for p in paths])
    obs = collect(paths, lane, persons)
    origin = f"{len(paths)} trace file(s), {obs.events} events"
    activities: dict[str, ActivityModel] = {}
    fits = []
    losses: dict[str, WrongChoiceLoss] = {}
    for activity in obs.activities:
        values = obs.durations.get(activity, [])
        kwargs: dict[str, Any] = {}
        wrong_choice = None
        if obs.picks.get(activity):
            kwargs.update(_choice_model(obs.picks[activity]))
            intended = kwargs.get("intended")
            if intended is not None and activity in obs.pick_durations:
                wrong_choice = _wrong_choice_loss(activity, intended,
                                                  obs.pick_durations[activity], criterion)
                if wrong_choice is not None:
                    # the choice's own duration: the intended picks only
                    values = obs.pick_durations[activity][intended]
                    for alternative in wrong_choice.alternatives:
                        losses[alternative] = wrong_choice
        dist, chosen, families, note = _fit_duration(values, criterion)
        omitted = obs.omitted.get(activity, 0)
        answered = omitted + len(obs.durations.get(activity, []))
        omission_stats = None
        kwargs["duration"] = dist
        if omitted:
            _, low, high = rate_interval(omitted, answered)
            lo_hi = (low, high)
            omission_stats = (omitted, answered, lo_hi)
            kwargs["omission"] = Omission(
                omitted / answered, source=f"fitted: {omitted}/{answered} omitted, Wilson 95 % "
                f"interval [{lo_hi[0]:.4f}, {lo_hi[1]:.4f}]")
        by = criterion.upper()
        scores = ", ".join(f"{f.family} {by} {f.score(criterion):.2f}"
                           for f in sorted(families, key=lambda f: f.score(criterion)))
        kwargs["source"] = (f"fitted by opspec fit from {origin}: n = {len(values)}, "
                            f"{chosen}" + (f" by {by} ({scores})" if families else ""))
        spread_d = duration_spread(obs.lists_by_person(obs.user_durations.get(activity, {})),
                                   min_per_user=min_per_user,
                                   family=chosen if families else None)
        if (isinstance(dist, LogNormal) and spread_d is not None
                and spread_d.between_sd_ci[0] > 0 and 0 < spread_d.between_sd < dist.sigma):
            # the pooled sigma holds both within- and between-user spread; the person-level
            # median varies with between_sd (the [vary] table), so one person's own sigma is
            # the rest, and the population's spread stays what was observed
            within = math.sqrt(dist.sigma ** 2 - spread_d.between_sd ** 2)
            kwargs["duration"] = LogNormal(dist.mu, within)
            note = (note + "; " if note else "") + (
                f"sigma {within:.4g} within a user, {spread_d.between_sd:.4g} between users")
        spread_o = omission_spread(obs.counts_by_person(obs.user_omissions.get(activity, {})),
                                   min_per_user=min_per_user) if omitted else None
        if spread_o is not None and spread_o.varies:
            # people differ: the rate a person has is drawn around the mean of the people's
            # own rates, not the pooled one (a missed prompt is offered again, so the pooled
            # rate weighs the forgetful more than the population draws them)
            kwargs["omission"] = replace(
                kwargs["omission"], probability=spread_o.mean,
                source=f"fitted: mean of {spread_o.users} persons' own rates "
                f"(pooled {omitted}/{answered} = {omitted / answered:.4f})")
        activities[activity] = ActivityModel(**kwargs)
        fits.append(ActivityFit(activity, len(values), dist, chosen,
                                {f.family: f.aic for f in families}, omission_stats, note,
                                families, criterion, spread_d, spread_o, wrong_choice))
    for alternative, loss in losses.items():
        if obs.durations.get(alternative):
            continue           # performed as its own activity: its own durations stand
        old = activities.get(alternative, ActivityModel())
        activities[alternative] = replace(
            old, duration=loss.distribution,
            source=f"fitted by opspec fit: the time a wrong pick at {loss.choice} costs, "
            f"{loss.seconds:.4g} s on average ({loss.wrong} wrong picks)")
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
