"""One replication: one simulated user (with their own device) of one design over the run.

Runs in worker processes. Each user ``u`` draws from streams derived from ``(seed, u)`` only
(:func:`opspec.runs.build`: the engine's ``scope=(u,)``, the user model's
:func:`opspec.engine.random.user_stream`, the world's), so results do not
depend on which worker runs which user, nor on how users are chunked: common random numbers
across designs come from the same rule. A replication returns a small record (metrics, the
duration observations with their times, outcome counts by day and hour, per-activity counts,
violations of the spec's monitors, and who the user is when the user model is a population:
their subgroup and drawn parameters) and its trace only when the run exports traces.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from opspec.errors import OpspecError
from opspec.evaluation.columns import Columns, outcome_columns, sample_columns
from opspec.run_rules import seconds_of_days

__all__ = ["ActivityCounter", "ActivityRecorder", "ReplicationRecord", "prepare", "run_users"]

USER_KINDS_WRONG = ("user.wrong_choice", "user.slip")


@dataclass(slots=True)
class ReplicationRecord:
    """What one replication produced (plain data: crosses process boundaries)."""

    design: str
    user: int
    # "done" | "failed": failed also when the run had a run-time fault or a deadlock
    # (opspec.evaluation.failures); its metrics are kept, its other rows are not stored
    status: str
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
    # who the user is, when the user model is a population: (subgroup or None, the
    # parameters drawn for them as dotted path -> value); None for a model without variation
    person: tuple[str | None, dict[str, float]] | None = None
    # the sample and outcome rows column by column (opspec.evaluation.columns), as
    # run_user makes them: stored after the rows of ``samples`` and ``outcomes`` above (a
    # record built by hand), which run_user leaves empty
    sample_columns: Columns | None = None
    outcome_columns: Columns | None = None


#: The column of the activity table each event kind counts in: offered, completed, omitted,
#: wrong (``user.wrong_choice``, ``user.slip``).
_COLUMN = {"activity.offered": 0, "activity.completed": 1, "user.omitted": 2,
           **dict.fromkeys(USER_KINDS_WRONG, 3)}


class ActivityRecorder:
    """Counts, per manual activity of the user lane, offers, completions, omissions and wrong
    actions (``user.wrong_choice``, ``user.slip``), selecting only the events it needs.

    A raw listener (:meth:`raw`): the engine hands it each event's fields without building a
    trace-event object for it, which the dispenser's user lane emits four of per dose."""

    def __init__(self, manual: Sequence[str]) -> None:
        self.counts: dict[str, list[int]] = {a: [0, 0, 0, 0] for a in manual}
        selects: set[tuple[str, str | None, str | None]] = set()
        for activity in manual:
            selects.add(("activity.offered", None, activity))
            selects.add(("activity.completed", None, activity))
        for kind in ("user.omitted", *USER_KINDS_WRONG):
            selects.add((kind, None, None))
        self.selects = frozenset(selects)

    def raw(self, time: float, kind: str, process: str | None, instance: int | None,
            activity: str | None, data: Mapping[str, Any] | None = None) -> None:
        """Count one event from its fields. The engine sends a raw listener every event any
        listener selects, so the kind is checked here (the activity too: the user events
        name theirs in ``data``)."""
        column = _COLUMN.get(kind)
        if column is None:
            return
        if not activity:
            activity = data.get("activity") if data else None
            if activity is None:
                return
        row = self.counts.get(activity)
        if row is not None:
            row[column] += 1

    def __call__(self, event: Any) -> None:
        self.raw(event.time, event.kind, event.process, event.instance, event.activity,
                 event.data)

    def finish(self) -> dict[str, list[int]]:
        """The rows, once the run ended."""
        return self.counts


class ActivityCounter:
    """The :class:`ActivityRecorder`'s counts, made where they are cheapest: the offers and
    completions by a compiled metrics listener (:class:`ActivityTally
    <opspec.usermodels.performer.ActivityTally>`, selecting as the recorder does), the
    omissions and wrong actions by the stochastic user who decides them
    (:attr:`StochasticUser.tally <opspec.usermodels.performer.StochasticUser.tally>`), where
    the recorder counted the ``user.*`` events that user traces.

    The numbers are the recorder's; the difference is what a run pays for them. With a raw
    listener in Python beside the metrics, the engine called every selected event's
    listeners through Python's protocol (its metrics' too), and every decision of the user
    was traced as an event: about 4.5 M instructions per user-month of the dispenser, a sixth
    of a replication. With only metrics listeners the engine calls them as native methods,
    and a decision nobody else selects is not traced at all. Used when the user lane's
    performer is a stochastic user (or nobody); any other performer gets the recorder."""

    def __init__(self, manual: Sequence[str], user_offers: frozenset[str] = frozenset()
                 ) -> None:
        from opspec.usermodels.performer import ActivityTally

        activities = tuple(dict.fromkeys(manual))
        #: the listener the run is built with; the offers of ``user_offers`` are left to
        #: the stochastic user (``StochasticUser.offers``: :attr:`user_offers`)
        self.listener = ActivityTally(
            activities, frozenset(a for a in activities if a not in user_offers))
        #: the rows, in ``manual``'s order; the stochastic user's ``tally``
        self.counts: dict[str, list[int]] = self.listener.rows
        #: the rows whose offers the stochastic user counts: its ``offers``
        self.user_offers: dict[str, list[int]] = {
            a: row for a, row in self.counts.items() if a in user_offers}

    def finish(self) -> dict[str, list[int]]:
        """The rows, once the run ended."""
        return self.counts


def offered_to_the_user_alone(compiled: Any) -> frozenset[str]:
    """The activities of the user lane whose every offer goes to the user lane's performer:
    a stochastic user counts their offers itself (``StochasticUser.offers``), so that no
    listener selects their ``activity.offered`` events and the engine traces none for them
    (about 1 M instructions per user-month of the dispenser: the event, and every raw
    listener called with it).

    The engine traces ``activity.offered`` of an activity where it offers a work item of it
    to a performer (``Offers.offer``, then ``performer.offer(item)`` with ``item.activity``
    its id) or finds no performer for it. The user's performer is bound to the participant
    or first lane of every activity of the user lane (:func:`opspec.runs.build`), so an
    activity ``X`` is counted the same by the user when every activity with the id ``X`` in
    the package is of the user lane, is not a task (a task's work goes to its
    application's performer) and, when it decides a deferred choice, every manual
    alternative it offers is of the user lane too (the choice goes to the first one's
    performer). A spec whose modes load other files (workflows compiled during the run) has
    none: their activities are not known here."""
    from opspec.engine.compiled import K_GATEWAY, K_MANUAL, K_TASK

    if any(mode.source for mode in compiled.package.modes):
        return frozenset()
    seen: dict[str, bool] = {}
    for proc in compiled.processes.values():
        stack = [proc.graph]
        while stack:
            graph = stack.pop()
            acts = graph.activities
            for act in acts:
                if act.block is not None:
                    stack.append(act.block)
                branches = act.choice or (act.out if act.kind == K_GATEWAY else ())
                alone = (act.user_lane and act.kind != K_TASK
                         and all(acts[t.target].user_lane for t in branches
                                 if acts[t.target].kind == K_MANUAL))
                seen[act.id] = seen.get(act.id, True) and alone
    return frozenset(a for a, alone in seen.items() if alone)


@dataclass(frozen=True)
class _Context:
    spec: Any                               # opspec.runs.LoadedSpec
    manual: tuple[str, ...]
    user: Any                               # opspec.runs.User of the user model, or None
    config: Any
    warnings: tuple[Any, ...] = ()          # the user model's, against this spec
    #: the activities of ``manual`` a stochastic user counts the offers of itself
    #: (:func:`offered_to_the_user_alone`)
    user_offers: frozenset[str] = frozenset()

    @property
    def compiled(self) -> Any:
        return self.spec.compiled

    @property
    def model(self) -> Any:
        return self.user.source if self.user is not None else None


_CONTEXTS: dict[tuple[str, str, str | None, str, str], _Context] = {}


def prepare(spec: str, sha256: str, user_model: str | None, engine: Mapping[str, Any],
            parameters: Sequence[Sequence[Any]] = (),
            branches: Mapping[str, Mapping[str, float]] | None = None, *,
            decided: Any = None) -> _Context:
    """Load (once per process) the spec, user model and engine configuration; with
    ``parameters`` (a design of ``--sweep``: ``(name, value)`` pairs) the spec and the user
    model changed as :mod:`opspec.evaluation.parameters` says; ``branches`` (``--branch``)
    applied to the spec before it is compiled. ``decided``: the front hall's
    :class:`~opspec.request.PreparedRun` of this spec and user model, when the caller has
    it (``opspec evaluate``'s plan): they are then not read and checked a second time."""
    import json

    key = (spec, sha256, user_model, json.dumps(dict(engine), sort_keys=True),
           json.dumps([list(p) for p in parameters]),
           json.dumps(branches or {}, sort_keys=True))
    found = _CONTEXTS.get(key)
    if found is not None:
        return found
    from opspec.engine.config import EngineConfig
    from opspec.engine.lanes import user_lane
    from opspec.request import RunRequest
    from opspec.request import prepare as decide
    from opspec.runs import User, load

    # the front hall decides the spec (validate's gate) and the user model (checked against
    # the spec's user lane), in the command and in every worker alike
    prepared = decided if decided is not None else decide(RunRequest(
        spec, user_model=user_model, no_user=user_model is None, branches=branches or None,
        default_metrics=True))
    loaded = prepared.spec
    lane = user_lane(loaded.compiled)
    user = prepared.user if prepared.user.kind == "model" else None
    warnings: tuple[Any, ...] = prepared.warnings
    if parameters:
        from opspec.evaluation.parameters import apply_parameters

        loaded, model = apply_parameters(loaded, user.source if user else None, parameters)
        loaded = load(loaded)
        if model is not None:
            user = User.model(model, user.describe if user else None)
    config = EngineConfig.from_mapping(engine) if engine else EngineConfig()
    manual = (*lane.manual, *lane.choices)
    context = _Context(loaded, manual, user, config, warnings,
                       offered_to_the_user_alone(loaded.compiled) & frozenset(manual))
    _CONTEXTS[key] = context
    return context


def run_user(context: _Context, design: str, user: int, *, seed: int, horizon: float,
             keep_trace: bool, inputs: Any = None) -> ReplicationRecord:
    """Simulate user ``user`` of ``design`` (built by :func:`opspec.runs.build`, as every
    run is: user ``user``'s streams); a failure (an error, a run-time fault, a deadlock:
    :mod:`opspec.evaluation.failures`) becomes a ``failed`` record."""
    from opspec.runs import build
    from opspec.usermodels.performer import StochasticUser

    start = time.perf_counter()
    person = None
    try:
        who = context.user
        model = context.model
        if model is not None and model.population is not None:
            # user u of a population: the person drawn for (seed, u) - the same one
            # opspec.runs.User.make would draw - run as that person's own model
            from opspec.runs import User

            drawn = model.individual(seed, user)
            person = (drawn.subgroup, dict(drawn.parameters))
            who = User.model(drawn.model, who.describe)
        params = inputs.for_run(seed, user) if inputs else None
        # a user model's performer (a stochastic user) counts the offers it alone is made
        counter = ActivityCounter(context.manual, context.user_offers
                                  if who is not None and who.kind == "model" else frozenset())
        run = build(context.spec, seed=seed, user=who, user_index=user, until=horizon,
                    config=context.config, listeners=[counter.listener],
                    keep_trace=keep_trace, keep_times=True, params=params)
        recorder: ActivityCounter | ActivityRecorder = counter
        performer = run.performer
        if isinstance(performer, StochasticUser):
            performer.tally = counter.counts
            performer.offers = counter.user_offers or None
        elif performer is None and counter.user_offers:
            # nobody to count them after all: the engine traces every offer (a fresh run)
            counter = ActivityCounter(context.manual)
            recorder = counter
            run = build(context.spec, seed=seed, user=who, user_index=user, until=horizon,
                        config=context.config, listeners=[counter.listener],
                        keep_trace=keep_trace, keep_times=True, params=params)
        elif performer is not None:
            # a performer that does not tally its decisions: the recorder hears them (a
            # fresh run: nothing of the first was started or drawn)
            recorder = ActivityRecorder(context.manual)
            run = build(context.spec, seed=seed, user=who, user_index=user, until=horizon,
                        config=context.config, listeners=[recorder],
                        keep_trace=keep_trace, keep_times=True, params=params)
        outcome = run.execute()
    except OpspecError as error:
        return ReplicationRecord(design, user, "failed", error=str(error),
                                 wall_s=time.perf_counter() - start)
    except Exception as error:  # noqa: BLE001 - recorded as this replication's failure
        return ReplicationRecord(design, user, "failed",
                                 error=f"internal error: {type(error).__name__}: {error}",
                                 wall_s=time.perf_counter() - start)
    result = outcome.result
    from opspec.evaluation.failures import run_problem

    # a run-time fault or deadlock fails the replication (its metrics are not the spec's)
    problem = run_problem(result.summary)
    record = ReplicationRecord(design, user, "done" if problem is None else "failed",
                               error=problem, metrics=result.metrics,
                               activities=recorder.finish(), person=person)
    for seen in outcome.monitors:
        first = seen.violations[0] if seen.violations else None
        record.monitors[seen.monitor] = (
            seen.count, first.time if first else None, first.message if first else None)
    # the rows as columns: counted and sent as a few arrays (opspec.evaluation.columns)
    record.sample_columns = sample_columns(outcome.samples, outcome.sample_times)
    record.outcome_columns = outcome_columns(outcome.count_times)
    if keep_trace and result.trace is not None:
        record.trace = [event.to_json() for event in result.trace]
    record.wall_s = time.perf_counter() - start
    return record


def run_users(plan: Mapping[str, Any], design: str, users: Sequence[int]
              ) -> list[ReplicationRecord]:
    """Worker entry point: replications ``users`` of ``design`` (``plan`` as JSON)."""
    if design.endswith("~draws"):       # users of the fitted model's parameter draws
        from opspec.evaluation.input_uncertainty import run_draw_users

        return run_draw_users(plan, design, users)
    spec = next(d for d in plan["designs"] if d["label"] == design)
    context = prepare(spec["spec"], spec["sha256"], plan.get("user_model"),
                      plan.get("engine") or {}, spec.get("parameters") or (),
                      plan.get("branches") or None)
    horizon = seconds_of_days(float(plan["days"]))
    keep = bool(plan.get("export"))
    from opspec.run_inputs import RunInputs

    inputs = RunInputs.from_json(plan.get("run_inputs"))     # drawn per user u, or row u
    return [run_user(context, design, u, seed=int(plan["seed"]), horizon=horizon,
                     keep_trace=keep, inputs=inputs) for u in users]
