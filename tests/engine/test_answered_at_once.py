"""Tasks whose performer answers at once (``activities.AnswersAtOnce``, the room world's
devices): performed without a work item (``Activities._answered``), with the same trace,
data, metrics and summary as when the same devices are offered work items and answer
through their session."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from opspec.engine.activities import AnswersAtOnce
from opspec.request import RunRequest, prepare
from opspec.worlds.room_devices import RoomDevices

SPECS = Path(__file__).resolve().parents[2] / "specs"


class _Offered:
    """The same devices behind a duck-typed performer: every task is offered a work item."""

    def __init__(self, devices: Any) -> None:
        self.devices = devices

    def attach(self, session: Any) -> None:
        """(the devices are attached by the run itself)"""

    def offer(self, item: Any) -> None:
        self.devices.offer(item)

    def withdraw(self, item: Any, reason: str) -> None:
        self.devices.withdraw(item, reason)


class _Session:
    """The devices' session, counting the answers given through it."""

    def __init__(self, session: Any) -> None:
        self.session = session
        self.answers = 0

    @property
    def now(self) -> float:
        now: float = self.session.now
        return now

    def complete(self, item: Any, data: Any = None, choice: Any = None) -> None:
        self.answers += 1
        self.session.complete(item, data)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.session, name)


def _run(spec: str, seconds: float, offered: bool) -> tuple[list[Any], dict[str, Any], int]:
    run = prepare(RunRequest(spec=str(SPECS / spec), until=seconds, no_user=True, seed=3,
                             keep_trace=True)).build(0)
    apps = run.sim.apps
    devices = {id(performer): performer for performer in apps.values()}
    assert [type(d) for d in devices.values()] == [RoomDevices]
    if offered:
        for application, performer in list(apps.items()):
            apps[application] = _Offered(performer)
    run.sim.run(until=1.0)                    # attached: now count the session's answers
    (room,) = devices.values()
    room.session = session = _Session(room.session)
    outcome = run.execute()
    trace = [(e.time, e.kind, e.process, e.instance, e.activity, e.data)
             for e in outcome.result.trace]
    return trace, outcome.result.metrics, session.answers


@pytest.mark.parametrize("spec", ["vacuum_cleaner.xpdl", "medication_cart_guidance.xpdl"])
def test_answered_at_once_as_if_offered(spec: str) -> None:
    at_once, metrics, answers = _run(spec, 120.0, offered=False)
    offered, offered_metrics, offered_answers = _run(spec, 120.0, offered=True)
    assert at_once == offered
    assert metrics == offered_metrics
    assert offered_answers > answers        # the offered path went through the session


def test_the_vacuum_cleaners_devices_answer_at_once() -> None:
    """Its range finder, bumper and motors answer without their session; the battery (an
    operation the compiled devices do not do) is the general devices' and still offered."""
    trace, _metrics, answers = _run("vacuum_cleaner.xpdl", 120.0, offered=False)
    assert answers == 0
    _trace, _metrics, offered_answers = _run("vacuum_cleaner.xpdl", 120.0, offered=True)
    drives = sum(1 for _t, kind, _p, _i, activity, _d in trace
                 if kind == "activity.completed" and activity == "arbitrate_drive")
    assert drives > 500
    assert offered_answers > 2 * drives      # the range finder, the bumper, the motors


def test_a_performer_that_does_not_answer_at_once_is_offered() -> None:
    assert not AnswersAtOnce().answers_at_once("drive")
    with pytest.raises(NotImplementedError):
        AnswersAtOnce().answer("drive", {}, 0.0)
