"""A coordination built-in's fields as the engine reads them (``coordinating.Coord``, one per
activity) and its inputs read from an instance's scope (``coordinating.inputs_of``): the same
as the model's built-in and as ``scope[name]``, for every kind and every kind of scope."""

from __future__ import annotations

from collections import ChainMap

import pytest

from opspec.engine import coordinating
from opspec.engine.compiled import CompiledActivity
from opspec.engine.scope import Scope
from opspec.model import CoordinationBuiltIn, CoordinationKind

KINDS = {
    CoordinationKind.ARBITER: coordinating.ARBITER,
    CoordinationKind.VOTER: coordinating.VOTER,
    CoordinationKind.SUPERPOSITION: coordinating.SUPERPOSITION,
    CoordinationKind.PUSH_DATA: coordinating.PUSH,
    CoordinationKind.PULL_DATA: coordinating.PULL,
    CoordinationKind.MODE_CHANGE: coordinating.OTHER,
}


def _act(ident: str) -> CompiledActivity:
    return CompiledActivity(index=0, id=ident, label=ident, process="p", location=None)


@pytest.mark.parametrize("kind", list(KINDS))
@pytest.mark.parametrize("channel", [None, "range"])
def test_the_fields_are_the_built_ins(kind: CoordinationKind, channel: str | None) -> None:
    spec = CoordinationBuiltIn(kind=kind, inputs=("a", "b"), output="out", channel=channel)
    built = coordinating.coord_of(_act("pull_it"), spec)
    assert built.kind == KINDS[kind]
    assert built.inputs == ("a", "b") and built.output == "out"
    assert built.channel == (channel or "pull_it")     # the activity's id without a channel
    assert built.waiting == f"pull from mailbox {built.channel!r}"


def test_one_per_activity_and_made_again_for_another_spec() -> None:
    act = _act("x")
    spec = CoordinationBuiltIn(kind=CoordinationKind.PUSH_DATA, inputs=("a",), channel="c")
    first = coordinating.coord_of(act, spec)
    assert coordinating.coord_of(act, spec) is first
    other = CoordinationBuiltIn(kind=CoordinationKind.PULL_DATA, output="v", channel="d")
    again = coordinating.coord_of(act, other)
    assert again is not first and again.kind == coordinating.PULL and again.channel == "d"


@pytest.mark.parametrize("scope", [
    Scope({"a": 1, "b": None}, {"b": 2, "c": "", "d": 4}),
    Scope({}, {"a": 1, "b": None, "c": "", "d": 4}),
    ChainMap({"a": 1}, {"b": None, "c": "", "d": 4}),
    {"a": 1, "b": None, "c": "", "d": 4},
])
def test_inputs_read_as_the_scope_reads_them(scope: object) -> None:
    names = ("d", "b", "a", "c")
    assert coordinating.inputs_of(scope, names) == [scope[n] for n in names]  # type: ignore[index]
    with pytest.raises(KeyError) as caught:
        coordinating.inputs_of(scope, ("a", "nothing", "b"))  # type: ignore[arg-type]
    assert caught.value.args == ("nothing",)
