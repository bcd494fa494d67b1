"""The names a run reads and writes data fields by are one string object per text
(``conditions.field_name``): the compiled data dictionaries' keys, the assignments' targets,
the names the conditions read and a coordination built-in's inputs, output and channel. A
dictionary finds such a key by identity; two separate strings of the same text it compares
character by character (docs/engine-performance.md, "Periodic path, fourth pass"). And a
constant's function is, compiled, a :class:`~opspec.engine.conditions.Constant` whose value
the engine reads without calling it."""

from __future__ import annotations

import sys
from pathlib import Path

from opspec.engine import coordinating
from opspec.engine.compiled import K_COORD, compile_package
from opspec.engine.conditions import COMPILED, Constant, compile_expression, field_name
from opspec.model.expressions import Literal
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]


def _interned(name: str) -> bool:
    return sys.intern(name) is name


def test_the_vacuum_cleaners_names_are_interned() -> None:
    compiled = compile_package(open_spec(ROOT / "specs" / "vacuum_cleaner.xpdl"))
    assert compiled.data and all(_interned(name) for name in compiled.data)
    targets = 0
    coords = 0
    for proc in compiled.processes.values():
        assert all(_interned(name) for name in proc.data)
        for act in proc.graph.activities:
            for name, _fn in (*act.start_assign, *act.end_assign):
                assert _interned(name)
                targets += 1
            for trans in act.out:
                assert all(_interned(name) for name, _fn in trans.assignments)
            if act.kind == K_COORD and act.coordination is not None:
                built = coordinating.coord_of(act, act.coordination)
                assert all(_interned(name) for name in built.inputs)
                assert built.output is None or _interned(built.output)
                assert _interned(built.channel)
                assert coordinating.coord_of(act, act.coordination) is built   # kept
                coords += 1
    assert targets >= 5 and coords >= 3


def test_field_name_keeps_the_text() -> None:
    text = b"level".decode()                    # a string of its own, not the literal
    assert field_name(text) == "level" and field_name(text) is field_name("level")


def test_a_constant_gives_its_value_called_or_read() -> None:
    fn = compile_expression(Literal("turn_left"))
    assert fn({}, 0.0) == "turn_left"
    assert isinstance(fn, Constant) == COMPILED
    if COMPILED:
        assert fn.value == "turn_left"          # type: ignore[attr-defined]
