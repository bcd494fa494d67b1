"""From source, the plans make activity instances, process instances, frames and work items
without calling their classes (``object.__new__`` and the fields stored in line, from the
tables beside each class): the tables must say what ``__init__`` does, and what the plans
make must be whole objects of the same class."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path
from typing import Any

import pytest

from opspec.engine import plans
from opspec.engine.compiled import compile_package
from opspec.engine.instances import (
    ACTIVITY_FIELDS,
    FRAME_FIELDS,
    IN_LINE,
    PROCESS_FIELDS,
    ActivityInstance,
    Frame,
    ProcessInstance,
    process_instance,
)
from opspec.engine.lanes import user_lane
from opspec.engine.random import user_stream
from opspec.engine.simulation import Simulation
from opspec.engine.workitem import FIELDS, WorkItem
from opspec.usermodels.loader import load_user_model
from opspec.usermodels.performer import StochasticUser
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]

#: the tables are read from source (compiled, ``__init__``'s signature is not inspectable and
#: the plans call the classes)
from_source = pytest.mark.skipif(not IN_LINE, reason="compiled, the classes are called")

TABLES = [(ActivityInstance, ACTIVITY_FIELDS), (ProcessInstance, PROCESS_FIELDS),
          (Frame, FRAME_FIELDS)]


def _slots(cls: type) -> set[str]:
    return set(cls.__slots__)  # type: ignore[attr-defined]


@from_source
@pytest.mark.parametrize(("cls", "fields"), TABLES, ids=lambda v: getattr(v, "__name__", ""))
def test_each_table_says_what_init_stores(cls: type, fields: tuple[Any, ...]) -> None:
    params = [name for name in inspect.signature(cls.__init__).parameters if name != "self"]
    given = [f for f in fields if isinstance(f, str)]
    started = dict(f for f in fields if not isinstance(f, str))
    assert set(given) <= set(params)
    assert set(given) | set(started) == _slots(cls)
    assert len(given) + len(started) == len(fields)
    # every parameter given a value of its own (defaults too, to see where each goes)
    values = {name: object() for name in params}
    made = cls(**values)
    for name in given:
        assert getattr(made, name) is values[name], name
    for name, start in started.items():
        assert getattr(made, name) == ast.literal_eval(start), name
        assert type(getattr(made, name)) is type(ast.literal_eval(start)), name


@from_source
def test_the_work_items_fields_are_its_init_in_order() -> None:
    params = [name for name in inspect.signature(WorkItem.__init__).parameters
              if name != "self"]
    assert list(FIELDS) == params
    assert set(WorkItem.__slots__) == set(FIELDS)
    values = [object() for _ in params[:10]]
    item = WorkItem(*values, (), None, None)
    assert [getattr(item, name) for name in FIELDS[:10]] == values
    assert not hasattr(item, "__dict__")


class _Checking(StochasticUser):
    """The dispenser's user, looking at what each offer is made of."""

    sim: Simulation

    def offer(self, item: WorkItem) -> None:
        ai = self.sim.offered[item.key]
        assert type(item) is WorkItem and type(ai) is ActivityInstance
        assert type(ai.frame) is Frame and type(ai.frame.inst) is ProcessInstance
        for made, cls in ((ai, ActivityInstance), (ai.frame, Frame),
                          (ai.frame.inst, ProcessInstance)):
            for name in _slots(cls):
                getattr(made, name)          # every field set (else AttributeError)
        again = WorkItem(*[getattr(item, name) for name in FIELDS])
        assert item == again and repr(item) == repr(again)
        assert not hasattr(item, "__dict__")
        self.checked += 1
        super().offer(item)


@pytest.mark.skipif(plans.COMPILED, reason="compiled, the engine makes no plans")
def test_what_the_plans_make_is_whole() -> None:
    compiled = compile_package(open_spec(ROOT / "specs" / "medication_dispenser.xpdl"))
    model = load_user_model(ROOT / "specs" / "medication_dispenser.users.toml")
    user = _Checking(model, user_stream(3, 0))
    user.checked = 0  # type: ignore[attr-defined]
    sim = Simulation(compiled, performers={n: user for n in user_lane(compiled).bind_names},
                     seed=3, scope=(0,))
    user.sim = sim
    sim.run(until=3 * 86400.0)
    assert user.checked >= 40  # type: ignore[attr-defined]


@from_source
def test_a_process_instance_made_in_line_is_the_classes() -> None:
    """``Flow.start_process``'s from-source maker stores what ``__init__`` stores."""
    values = [object() for _ in range(10)]
    made, called = process_instance(*values), ProcessInstance(*values)  # type: ignore[arg-type]
    assert type(made) is ProcessInstance
    for name in _slots(ProcessInstance):
        assert getattr(made, name) == getattr(called, name), name
        assert type(getattr(made, name)) is type(getattr(called, name)), name
    assert made.frames is not called.frames
