"""The per-activity counts of ``opspec evaluate`` (the ``activity`` table) agree with the trace
of the same run, now that they are counted from the engine's raw event fields."""

from __future__ import annotations

from collections import Counter

from conftest import SPEC, USERS_TOML

from opspec.evaluation.plan import file_digest
from opspec.evaluation.replication import ActivityRecorder, prepare, run_user


def _counts_in_trace(trace: list[dict], manual: tuple[str, ...]) -> dict[str, list[int]]:
    """offered, completed, omitted, wrong per manual activity, counted from the trace."""
    seen: Counter[tuple[str, str]] = Counter()
    for event in trace:
        activity = event.get("activity") or (event.get("data") or {}).get("activity")
        seen[(event["kind"], activity)] += 1
    return {a: [seen[("activity.offered", a)], seen[("activity.completed", a)],
                seen[("user.omitted", a)],
                seen[("user.wrong_choice", a)] + seen[("user.slip", a)]] for a in manual}


def test_activity_counts_agree_with_the_exported_trace_of_the_same_user():
    context = prepare(str(SPEC), file_digest(str(SPEC)), str(USERS_TOML), {})
    omitted = wrong = 0
    for user in range(3):
        traced = run_user(context, "A", user, seed=11, horizon=4 * 86_400.0, keep_trace=True)
        plain = run_user(context, "A", user, seed=11, horizon=4 * 86_400.0, keep_trace=False)
        assert traced.status == plain.status == "done"
        assert traced.trace is not None
        expected = _counts_in_trace(traced.trace, context.manual)
        # with a full trace listener and without one (raw fields only) alike
        assert traced.activities == expected
        assert plain.activities == expected
        omitted += sum(row[2] for row in expected.values())
        wrong += sum(row[3] for row in expected.values())
    # the users of this seed do omit and press wrong buttons: every column is exercised
    assert omitted > 0 and wrong > 0


def _send(recorder: ActivityRecorder, *event: object) -> None:
    """One event as the engine sends it: to every raw listener of the run, to one that
    declares ``raw_kinds`` only when the event is of one of them (opspec.engine.runstate)."""
    for listener in recorder.listeners:
        kinds = getattr(listener, "raw_kinds", None)
        if kinds is None or event[1] in kinds:
            listener.raw(*event)


def test_events_of_other_kinds_for_a_manual_activity_are_not_counted():
    """The engine sends a raw listener every event any listener selects (a metric may select
    ``activity.started`` of the same activity): only the four counted kinds count, a user's
    decision for the activity its data names, and each event once."""
    recorder = ActivityRecorder(["take_pill"])
    _send(recorder, 1.0, "activity.started", "user", 1, "take_pill")
    _send(recorder, 2.0, "activity.offered", "user", 1, "take_pill")
    _send(recorder, 2.5, "activity.completed", "user", 1, "walk")
    _send(recorder, 3.0, "user.slip", "user", 1, None, {"activity": "take_pill"})
    _send(recorder, 4.0, "user.omitted", "user", 1, None, {"activity": "walk"})
    _send(recorder, 5.0, "user.omitted", "user", 1, None, None)
    assert recorder.counts == {"take_pill": [1, 0, 0, 1]}


def test_the_engine_calls_the_decision_counter_only_for_decisions():
    """The user's decisions are counted in Python: the engine must not call that listener
    for the other events of a run (14 a dose cycle of the dispenser, 4 of them its own)."""
    from opspec.engine.lanes import user_lane
    from opspec.engine.simulation import Simulation
    from opspec.runs import User

    context = prepare(str(SPEC), file_digest(str(SPEC)), str(USERS_TOML), {})
    recorder = ActivityRecorder(context.manual)
    heard: Counter[str] = Counter()
    counted = recorder.raw

    def raw(*event: object) -> None:
        heard[str(event[1])] += 1
        counted(*event)

    recorder.raw = raw  # type: ignore[method-assign]
    performer, _ = User.model(context.model, None).make(0, 11)
    compiled = context.compiled
    sim = Simulation(compiled, performers=dict.fromkeys(user_lane(compiled).bind_names,
                                                        performer),
                     seed=11, scope=(0,), listeners=recorder.listeners)
    sim.run(until=4 * 86_400.0)
    assert heard, "the users of this seed omit and press wrong buttons"
    assert set(heard) <= set(recorder.raw_kinds)
    assert sum(recorder.counts["hear_alarm"][:2]) > 0
