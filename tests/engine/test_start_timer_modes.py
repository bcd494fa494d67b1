"""A start timer tests its workflow's mode at every firing (opspec/engine/triggers.py,
``_Timer.go``, which keeps the modes its workflow belongs to instead of asking
``Triggers.is_active`` each time): a periodic workflow of a mode starts only while its mode
is the current one, one of no mode always, and a mode changed back starts it again."""

from __future__ import annotations

from builders import act, catch, coordination, pkg, proc

from engine_runs import events, run
from opspec.model import WorkflowMode


def _switch(id: str, at: float, target: str) -> object:
    return proc(id, [catch("d", "timer", seconds=at), act("switch", coordination=
                     coordination("mode-change", target_mode=target))], [("d", "switch")],
                auto_start=True)


def test_periodic_starts_follow_the_current_mode() -> None:
    model = pkg(proc("cleaning", ["sweep"], start="period:1", mode="clean"),
                proc("docking", ["park"], start="period:1", mode="dock"),
                proc("always", ["tick"], start="period:1"),
                _switch("to_dock", 3.5, "dock"), _switch("to_clean", 6.5, "clean"),
                modes=[WorkflowMode(id="clean", initial=True), WorkflowMode(id="dock")])
    result = run(model, until=9.5)
    starts = {p: [e.time for e in events(result, "process.started", process=p)]
              for p in ("cleaning", "docking", "always")}
    assert starts["cleaning"] == [0.0, 1.0, 2.0, 3.0, 7.0, 8.0, 9.0]
    assert starts["docking"] == [4.0, 5.0, 6.0]
    assert starts["always"] == [float(t) for t in range(10)]
