"""The per-activity counts of ``opspec evaluate`` (the ``activity`` table) agree with the trace
of the same run, now that they are counted from the engine's raw event fields."""

from __future__ import annotations

from collections import Counter

from evaluation_inputs import SPEC, USERS_TOML

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


def test_events_of_other_kinds_for_a_manual_activity_are_not_counted():
    """The engine sends a raw listener every event any listener selects (a metric may select
    ``activity.started`` of the same activity): only the four counted kinds count."""
    recorder = ActivityRecorder(["take_pill"])
    recorder.raw(1.0, "activity.started", "user", 1, "take_pill")
    recorder.raw(2.0, "activity.offered", "user", 1, "take_pill")
    recorder.raw(3.0, "user.slip", "user", 1, None, {"activity": "take_pill"})
    recorder.raw(4.0, "user.omitted", "user", 1, None, {"activity": "walk"})
    recorder.raw(5.0, "user.omitted", "user", 1, None, None)
    assert recorder.counts == {"take_pill": [1, 0, 0, 1]}
