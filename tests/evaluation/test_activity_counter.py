"""The ``activity`` table's counts as a replication makes them (offers and completions by a
compiled metrics listener, omissions and wrong actions by the stochastic user who decides
them) are those of the recorder that hears every one of those events, for the same users."""

from __future__ import annotations

import pytest
from evaluation_inputs import ROOT, SPEC, USERS_TOML

from opspec.evaluation.plan import file_digest
from opspec.evaluation.replication import (
    ActivityCounter,
    ActivityRecorder,
    prepare,
    run_user,
)
from opspec.runs import User, build

POPULATION = ROOT / "specs" / "medication_dispenser.population.toml"
BPMN = ROOT / "specs" / "medication_dispenser.bpmn"
DAY = 86_400.0


def _recorded(context, user: int, seed: int, days: float) -> dict[str, list[int]]:
    """The counts of the recorder, listening to the same user's run."""
    who = context.user
    model = context.model
    if model.population is not None:
        who = User.model(model.individual(seed, user).model)
    recorder = ActivityRecorder(context.manual)
    build(context.spec, seed=seed, user=who, user_index=user, until=days * DAY,
          config=context.config, listeners=[recorder], keep_times=True).execute()
    return recorder.counts


@pytest.mark.parametrize(("spec", "model"), [(SPEC, USERS_TOML), (SPEC, POPULATION),
                                             (BPMN, USERS_TOML)],
                         ids=["dispenser", "population", "bpmn"])
def test_counts_are_the_recorders_for_the_same_users(spec, model):
    context = prepare(str(spec), file_digest(str(spec)), str(model), {})
    columns = [0, 0, 0, 0]
    for user in range(6):
        record = run_user(context, "A", user, seed=5, horizon=6 * DAY, keep_trace=False)
        assert record.status == "done", record.error
        expected = _recorded(context, user, 5, 6)
        assert record.activities == expected
        assert list(record.activities) == list(context.manual)      # the rows' order
        for row in expected.values():
            columns = [c + v for c, v in zip(columns, row, strict=True)]
    # every column is exercised: offers, completions, omissions, wrong buttons
    assert all(columns), columns


def test_a_performer_that_does_not_tally_gets_the_recorder(monkeypatch):
    """A user lane performed by something other than a stochastic user (which tallies its own
    decisions) is counted by the recorder: the same numbers, the ``user.*`` events heard."""
    import opspec.evaluation.replication as replication

    context = prepare(str(SPEC), file_digest(str(SPEC)), str(USERS_TOML), {})
    expected = run_user(context, "A", 2, seed=9, horizon=5 * DAY, keep_trace=False).activities

    class Wrapped:
        """The same user behind another face: offers passed through, no ``tally``."""

        def __init__(self, inner) -> None:
            self.inner = inner

        def attach(self, session) -> None:
            self.inner.attach(session)

        def offer(self, item) -> None:
            self.inner.offer(item)

        def withdraw(self, item, reason: str) -> None:
            self.inner.withdraw(item, reason)

    real_make = User.make
    monkeypatch.setattr(User, "make", lambda self, user, seed: (
        Wrapped(real_make(self, user, seed)[0]), []))
    counters: list[ActivityCounter] = []
    real_counter = replication.ActivityCounter
    monkeypatch.setattr(replication, "ActivityCounter",
                        lambda manual, *offers: counters.append(real_counter(manual, *offers))
                        or counters[-1])
    record = run_user(context, "A", 2, seed=9, horizon=5 * DAY, keep_trace=False)
    assert counters, "the counter was tried first"
    assert record.activities == expected
    assert sum(row[2] + row[3] for row in expected.values()) > 0


def test_the_tally_counts_only_offers_and_completions_of_its_activities():
    """The engine sends a metrics listener every event any listener selects (a metric may
    select ``activity.started`` of the same activity, or offers of another one)."""
    from opspec.usermodels.performer import ActivityTally

    tally = ActivityTally(("take_pill", "walk"))
    assert ("activity.offered", None, "take_pill") in tally.selects
    tally.raw(1.0, "activity.started", "user", 1, "take_pill")
    tally.raw(2.0, "activity.offered", "user", 1, "take_pill")
    tally.raw(3.0, "activity.completed", "user", 1, "take_pill")
    tally.raw(4.0, "activity.offered", "device", 2, "notify")
    tally.raw(5.0, "user.omitted", "user", 1, None, {"activity": "walk"})
    tally.raw(6.0, "activity.completed", "user", 1, "walk")
    assert tally.rows == {"take_pill": [1, 1, 0, 0], "walk": [0, 1, 0, 0]}
