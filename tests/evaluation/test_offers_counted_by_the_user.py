"""The offers a stochastic user counts itself (``StochasticUser.offers``) are the engine's
``activity.offered`` events of those activities, also in the specs where some offers of an
activity id of the user lane go elsewhere: there the engine still traces them for the
activity table, and the table is the one a recorder hearing every event makes.

The engine traces ``activity.offered`` where it offers a work item to a performer or finds
none (XPDL 2.1, WfMC-TC-1025, 7.6: "Performers ... the resource that is requested to or
should perform the activity"): an activity with the id of one of the user lane's, performed
by a device, is offered to the device, not to the user."""

from __future__ import annotations

from pathlib import Path

import pytest
from evaluation_inputs import SPEC, USERS_TOML

from opspec.evaluation.plan import file_digest
from opspec.evaluation.replication import ActivityRecorder, prepare, run_user
from opspec.runs import build

DAY = 86_400.0


def _recorded(context, user: int, seed: int, days: float) -> dict[str, list[int]]:
    recorder = ActivityRecorder(context.manual)
    build(context.spec, seed=seed, user=context.user, user_index=user, until=days * DAY,
          config=context.config, listeners=[recorder], keep_times=True).execute()
    return recorder.counts


def _same_as_the_recorder(spec: Path, users: int = 4, days: float = 4, *,
                          status: str = "done") -> dict[str, list[int]]:
    context = prepare(str(spec), file_digest(str(spec)), str(USERS_TOML), {})
    total: dict[str, list[int]] = {}
    for user in range(users):
        record = run_user(context, "A", user, seed=11, horizon=days * DAY, keep_trace=False)
        assert record.status == status, record.error
        assert record.activities == _recorded(context, user, 11, days)
        for activity, row in record.activities.items():
            total[activity] = [a + b for a, b in zip(total.get(activity, [0] * 4), row,
                                                      strict=True)]
    return total


def test_the_dispensers_user_counts_the_offers_of_every_activity_of_its_lane():
    context = prepare(str(SPEC), file_digest(str(SPEC)), str(USERS_TOML), {})
    assert context.user_offers == frozenset(context.manual)
    total = _same_as_the_recorder(SPEC)
    assert all(row[0] > 0 for row in total.values()), total


@pytest.fixture
def shared_id(tmp_path: Path) -> Path:
    """The dispenser with a manual activity ``take_pill`` in the device's process too,
    performed by the dispenser, which nobody performs in an evaluation: once a dose is
    taken, the engine offers it to no performer (and traces that offer), and that dose's
    process waits there for good (a deadlock the run reports, failing the replication; its
    activity rows are counted all the same)."""
    text = SPEC.read_text(encoding="utf-8")
    device_step = """
      <Activity Id="take_pill" Name="The drawer's own take_pill step">
        <Implementation><No/></Implementation>
        <Performers><Performer>dispenser</Performer></Performers>
        <ExtendedAttributes>
          <ExtendedAttribute Name="opspec:AutoRun" Value="false"/>
        </ExtendedAttributes>
      </Activity>
      <Activity Id="end_taken\""""
    assert text.count('<Activity Id="end_taken"') == 1
    text = text.replace('\n      <Activity Id="end_taken"', device_step, 1)
    old = '<Transition Id="n_end_taken" From="record_taken" To="end_taken">'
    assert text.count(old) == 1
    text = text.replace(old, '<Transition Id="n_device_step" From="take_pill" To="end_taken"/>'
                        '<Transition Id="n_end_taken" From="record_taken" To="take_pill">')
    spec = tmp_path / "shared_id.xpdl"
    spec.write_text(text, encoding="utf-8")
    return spec


def test_an_activity_id_also_offered_to_a_device_is_counted_by_the_engine(shared_id):
    context = prepare(str(shared_id), file_digest(str(shared_id)), str(USERS_TOML), {})
    assert "take_pill" in context.manual
    assert "take_pill" not in context.user_offers
    assert "walk_to_dispenser" in context.user_offers
    total = _same_as_the_recorder(shared_id, status="failed")
    # the offers to nobody are in the row too: one more per pill the user took
    assert total["take_pill"][0] == 2 * total["take_pill"][1] > 0, total


def test_a_spec_whose_modes_load_other_files_leaves_every_offer_to_the_engine(tmp_path):
    """Workflows compiled during the run (a mode's Source) are not known before it: their
    activities may share an id with the user lane's, so the engine counts every offer."""
    text = SPEC.read_text(encoding="utf-8")
    (tmp_path / "away.xpdl").write_text(text, encoding="utf-8")
    modes = ('<ExtendedAttribute Name="opspec:Modes"><opspec:Mode Id="home" Initial="true" '
             'Workflows="timer_workflow notify_workflow schedule_workflow user_workflow"/>'
             '<opspec:Mode Id="away" Source="away.xpdl"/></ExtendedAttribute>\n'
             '    <ExtendedAttribute Name="opspec:MessageTTL"')
    assert text.count('<ExtendedAttribute Name="opspec:MessageTTL"') == 1
    spec = tmp_path / "modes.xpdl"
    spec.write_text(text.replace('<ExtendedAttribute Name="opspec:MessageTTL"', modes, 1),
                    encoding="utf-8")
    context = prepare(str(spec), file_digest(str(spec)), str(USERS_TOML), {})
    assert context.user_offers == frozenset()
    total = _same_as_the_recorder(spec, users=2, days=2)
    assert all(row[0] > 0 for row in total.values()), total
