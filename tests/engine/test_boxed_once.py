"""The run's tables are keyed by the very objects the instances hold: a process instance's
``id`` is the key of the run's ``live`` table, an activity instance's ``key`` the key of its
frame's ``running`` table. Compiled, an ``int`` field is a C integer that each read boxes
anew (ids pass 256 within the first simulated seconds, beyond CPython's small ints): each
insertion, test and deletion then made a new int, which the table found by comparing
values. Held as objects, boxed once when the instance is made, the tables find them by
identity (docs/engine-performance.md, "Periodic path, third pass")."""

from __future__ import annotations

from pathlib import Path

from opspec.engine.compiled import compile_package
from opspec.engine.lifecycle import TERMINATED
from opspec.engine.simulation import Simulation
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]


def test_the_tables_are_keyed_by_the_objects_the_instances_hold() -> None:
    sim = Simulation(compile_package(open_spec(ROOT / "specs" / "medication_dispenser.xpdl")),
                     seed=3)
    ids = [sim.start("timer_workflow") for _ in range(300)]
    assert max(ids) > 256                       # past the small ints, both ways alike
    live = sim.live
    assert len(live) >= 300
    assert all(key is inst.id for key, inst in live.items())
    running = [(key, ai) for inst in live.values() for frame in inst.frames
               for key, ai in frame.running.items()]
    assert len(running) >= 300
    assert all(key is ai.key for key, ai in running)
    # ended instances leave both tables (found by identity, as they were put in): their
    # activity instances leave their frames (ActivityInstance.leave), they leave ``live``
    waiting = [inst for inst in live.values() if any(frame.running for frame in inst.frames)]
    assert len(waiting) >= 10
    for inst in waiting[-10:]:
        iid = inst.id
        frames = list(inst.frames)
        sim.flow.end_instance(inst, TERMINATED, "test")
        assert iid not in live
        assert all(not frame.running for frame in frames)
