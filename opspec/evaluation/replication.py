"""One replication: one simulated user (with their own device) of one design over the run.

Runs in worker processes. Each user ``u`` draws from streams derived from ``(seed, u)`` only
(the engine's ``scope=(u,)`` and :func:`opspec.engine.random.user_stream`), so results do not
depend on which worker runs which user, nor on how users are chunked: common random numbers
across designs come from the same rule. A replication returns a small record (metrics, the
duration observations with their times, outcome counts by day and hour, per-activity counts,
violations of the spec's monitors)
and its trace only when the run exports traces.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from opspec.errors import OpspecError

__all__ = ["ActivityRecorder", "ReplicationRecord", "prepare", "run_users"]

DAY = 86_400.0
USER_KINDS_WRONG = ("user.wrong_choice", "user.slip")


@dataclass(slots=True)
class ReplicationRecord:
    """What one replication produced (plain data: crosses process boundaries)."""

    design: str
    user: int
    status: str                                   # "done" | "failed"
    error: str | None = None
    metrics: dict[str, dict[str, Any]] = field(default_factory=dict)
    samples: list[tuple[str, float, float]] = field(default_factory=list)  # metric, value, t
    outcomes: dict[tuple[str, int, int], int] = field(default_factory=dict)  # metric,day,hour
    # activity -> [offered, completed, omitted, wrong]
    activities: dict[str, list[int]] = field(default_factory=dict)
    # monitor -> (violations, time of the first, its message); every declared monitor, also 0
    monitors: dict[str, tuple[int, float | None, str | None]] = field(default_factory=dict)
    wall_s: float = 0.0
    trace: list[dict[str, Any]] | None = None


class ActivityRecorder:
    """Counts, per manual activity of the user lane, offers, completions, omissions and wrong
    actions (``user.wrong_choice``, ``user.slip``), selecting only the events it needs."""

    def __init__(self, manual: Sequence[str]) -> None:
        self.counts: dict[str, list[int]] = {a: [0, 0, 0, 0] for a in manual}
        selects: set[tuple[str, str | None, str | None]] = set()
        for activity in manual:
            selects.add(("activity.offered", None, activity))
            selects.add(("activity.completed", None, activity))
        for kind in ("user.omitted", *USER_KINDS_WRONG):
            selects.add((kind, None, None))
        self.selects = frozenset(selects)

    def __call__(self, event: Any) -> None:
        kind = event.kind
        activity = event.activity or (event.data or {}).get("activity")
        row = self.counts.get(activity) if activity is not None else None
        if row is None:
            return
        if kind == "activity.offered":
            row[0] += 1
        elif kind == "activity.completed":
            row[1] += 1
        elif kind == "user.omitted":
            row[2] += 1
        else:
            row[3] += 1


@dataclass(frozen=True)
class _Context:
    compiled: Any
    bind_names: tuple[str, ...]
    manual: tuple[str, ...]
    model: Any
    config: Any
    monitors: tuple[Any, ...] = ()
    warnings: tuple[Any, ...] = ()          # the user model's, against this spec


_CONTEXTS: dict[tuple[str, str, str | None, str], _Context] = {}


def prepare(spec: str, sha256: str, user_model: str | None, engine: Mapping[str, Any]
            ) -> _Context:
    """Load (once per process) the compiled spec, user model and engine configuration."""
    import json

    key = (spec, sha256, user_model, json.dumps(dict(engine), sort_keys=True))
    found = _CONTEXTS.get(key)
    if found is not None:
        return found
    from opspec.engine.compiled import compile_package
    from opspec.engine.config import EngineConfig
    from opspec.engine.lanes import user_lane
    from opspec.xpdl.open_spec import open_spec

    compiled = compile_package(open_spec(spec))
    lane = user_lane(compiled)
    model = None
    warnings: tuple[Any, ...] = ()
    if user_model is not None:
        from opspec.usermodels.loader import load_user_model

        model = load_user_model(user_model)
        if not lane.empty:
            warnings = tuple(model.validate_against(lane.manual, choices=lane.choices))
    config = EngineConfig.from_mapping(engine) if engine else EngineConfig()
    from opspec.engine.monitors import declared_monitors

    context = _Context(compiled, lane.bind_names, (*lane.manual, *lane.choices), model, config,
                       tuple(declared_monitors(compiled)), warnings)
    _CONTEXTS[key] = context
    return context


def _world_performers(compiled: Any, seed: int, user: int) -> dict[str, Any]:
    try:
        from opspec.bindings.worlds import world_performers
    except ImportError:
        return {}
    return dict(world_performers(compiled, seed=seed, user=user))


def run_user(context: _Context, design: str, user: int, *, seed: int, horizon: float,
             keep_trace: bool) -> ReplicationRecord:
    """Simulate user ``user`` of ``design``; a failure becomes a ``failed`` record."""
    from opspec.engine.random import user_stream
    from opspec.engine.simulation import Simulation
    from opspec.xpdl.open_spec import mode_loader_for

    start = time.perf_counter()
    try:
        performers: dict[str, Any] = _world_performers(context.compiled, seed, user)
        if context.model is not None:
            performer = context.model.performer(user_stream(seed, user))
            for name in context.bind_names:
                performers[name] = performer
        recorder = ActivityRecorder(context.manual)
        watches = [m.start(user) for m in context.monitors]
        sim = Simulation(context.compiled, context.config, performers=performers, seed=seed,
                         scope=(user,), listeners=[recorder, *watches], keep_trace=keep_trace,
                         mode_loader=mode_loader_for(context.compiled.package))
        if sim.metrics is not None:
            sim.metrics.keep_times = True
        result = sim.run(until=horizon)
        for watch in watches:
            watch.finish(horizon)
    except OpspecError as error:
        return ReplicationRecord(design, user, "failed", error=str(error),
                                 wall_s=time.perf_counter() - start)
    except Exception as error:  # noqa: BLE001 - recorded as this replication's failure
        return ReplicationRecord(design, user, "failed",
                                 error=f"internal error: {type(error).__name__}: {error}",
                                 wall_s=time.perf_counter() - start)
    record = ReplicationRecord(design, user, "done", metrics=result.metrics,
                               activities=recorder.counts)
    for watch in watches:
        first = watch.violations[0] if watch.violations else None
        record.monitors[watch.monitor.text] = (
            watch.count, first.time if first else None, first.message if first else None)
    metrics = sim.metrics
    if metrics is not None:
        for name, values in metrics.samples.items():
            ends = metrics.sample_times.get(name, [])
            record.samples.extend((name, v, t) for v, t in zip(values, ends, strict=True))
        for name, times in metrics.count_times.items():
            for t in times:
                key = (name, int(t // DAY), int((t % DAY) // 3600))
                record.outcomes[key] = record.outcomes.get(key, 0) + 1
    problems = (result.summary.get("deadlocks") or []) + (result.summary.get("faults") or [])
    if problems:
        record.error = "; ".join(str(p.get("message")) for p in problems[:3])
    if keep_trace and result.trace is not None:
        record.trace = [event.to_json() for event in result.trace]
    record.wall_s = time.perf_counter() - start
    return record


def run_users(plan: Mapping[str, Any], design: str, users: Sequence[int]
              ) -> list[ReplicationRecord]:
    """Worker entry point: replications ``users`` of ``design`` (``plan`` as JSON)."""
    spec = next(d for d in plan["designs"] if d["label"] == design)
    context = prepare(spec["spec"], spec["sha256"], plan.get("user_model"),
                      plan.get("engine") or {})
    horizon = float(plan["days"]) * DAY
    keep = bool(plan.get("export"))
    return [run_user(context, design, u, seed=int(plan["seed"]), horizon=horizon,
                     keep_trace=keep) for u in users]
