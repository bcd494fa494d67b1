"""The .wfs codec: every model value round-trips to an equal model; bad files are clean errors."""

from __future__ import annotations

import dataclasses
import enum
import json
import math
import sys
import types
import typing
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from opspec.errors import SourceLocation, SpecError
from opspec.model import (
    Activity,
    ActivityDirectives,
    ActivitySet,
    ActualParameter,
    Assignment,
    BasicKind,
    BasicType,
    Binary,
    BlockActivity,
    Call,
    Condition,
    ConditionKind,
    CoordinationBuiltIn,
    CoordinationKind,
    DataField,
    Deadline,
    DeclaredDistribution,
    Event,
    EventPosition,
    EventSelector,
    ExtendedAttribute,
    GatewayType,
    Join,
    Literal,
    MetricDefinition,
    MetricKind,
    Name,
    Package,
    ProcessDirectives,
    Route,
    Split,
    SubFlow,
    Task,
    TaskApplication,
    TaskKind,
    Transition,
    Trigger,
    TriggerKind,
    TriggerRef,
    Unary,
    WorkflowMode,
    WorkflowProcess,
    codec,
)
from opspec.model import Mode as ActivityMode


def _reachable_dataclasses() -> set[type]:
    """Every dataclass a Package can contain, found by walking the type hints."""
    seen: set[type] = set()
    stack: list[Any] = [Package]
    while stack:
        hint = stack.pop()
        origin = typing.get_origin(hint)
        if origin is not None:
            stack.extend(a for a in typing.get_args(hint) if a is not Ellipsis)
            continue
        if not (isinstance(hint, type) and dataclasses.is_dataclass(hint)) or hint in seen:
            continue
        seen.add(hint)
        # dataclass(slots=True) replaces each class; only the module-level one is real.
        stack.extend(
            sub for sub in hint.__subclasses__()
            if getattr(sys.modules[sub.__module__], sub.__name__, None) is sub
        )
        hints = typing.get_type_hints(hint)
        stack.extend(hints[f.name] for f in dataclasses.fields(hint))
    return seen


ABSTRACT_BASES = {"ActivityBody", "DataType", "Expression", "Element"}


def test_every_model_class_a_package_can_hold_has_a_type_tag() -> None:
    concrete = {cls for cls in _reachable_dataclasses() if cls.__name__ not in ABSTRACT_BASES}
    missing = sorted(cls.__qualname__ for cls in concrete - set(codec.TAGS.values()))
    assert missing == [], f"add these to opspec.model.codec.TAGS: {missing}"


# --------------------------------------------------------------------------- random models

# Text as XML can carry it (no lone surrogates), short to keep examples small.
_text = st.text(st.characters(blacklist_categories=("Cs",)), max_size=8)
_floats = st.floats(allow_nan=False, width=64)


def _concrete(base: type) -> list[type]:
    return [cls for cls in codec.TAGS.values() if issubclass(cls, base)]


def _strategy(hint: Any, depth: int) -> st.SearchStrategy[Any]:
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        return st.one_of(*[_strategy(a, depth) for a in typing.get_args(hint)])
    if origin is tuple:
        args = typing.get_args(hint)
        if len(args) == 2 and args[1] is Ellipsis:
            return st.lists(_strategy(args[0], depth + 1), max_size=2 if depth < 4 else 0).map(
                tuple
            )
        return st.tuples(*[_strategy(a, depth) for a in args])
    if hint is type(None):
        return st.none()
    if hint is str:
        return _text
    if hint is bool:
        return st.booleans()
    if hint is int:
        return st.integers(-(2**40), 2**40)
    if hint is float:
        return _floats
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        return st.sampled_from(list(hint))
    if isinstance(hint, type) and dataclasses.is_dataclass(hint):
        options = _concrete(hint)
        if depth > 5:  # keep trees small: prefer leaves deep down
            leaves = [c for c in options if c in (Literal, Name)] or options
            options = leaves
        return st.one_of(*[st.deferred(lambda c=c: _build(c, depth + 1)) for c in options])
    raise AssertionError(f"no strategy for {hint!r}")


def _build(cls: type, depth: int) -> st.SearchStrategy[Any]:
    hints = typing.get_type_hints(cls)
    kwargs = {}
    for f in dataclasses.fields(cls):
        strategy = _strategy(hints[f.name], depth)
        if f.default is not dataclasses.MISSING and depth > 2:
            strategy = st.one_of(st.just(f.default), strategy)
        kwargs[f.name] = strategy
    return st.builds(cls, **kwargs)


packages = _build(Package, 0)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(packages)
def test_any_model_round_trips_through_the_json_form_to_an_equal_model(package: Package) -> None:
    assert codec.loads(codec.dumps(package)) == package


# --------------------------------------------------------------------------- a hand-built model


def _rich_package() -> Package:
    here = SourceLocation("specs/demo.xpdl", 12)
    condition = Binary(
        "and",
        Binary("<", Name(("n",)), Literal(3)),
        Unary("not", Call("len", (Name(("order", "items")), Literal("x")))),
    )
    arbiter = Activity(
        id="arbitrate",
        body=Route(gateway=GatewayType.XOR),
        coordination=CoordinationBuiltIn(
            kind=CoordinationKind.ARBITER, inputs=("avoid", "wander"), output="motor"
        ),
        directives=ActivityDirectives(
            auto_run=False,
            priority_increment=2,
            duration=DeclaredDistribution(kind="LogNormalDistribution",
                                  parameters=(("mean", 2.0), ("standardDeviation", 0.5))),
            raises=TriggerRef(kind="message", name="trg_1"),
        ),
        split=Split(type=GatewayType.XOR, transition_refs=("t1",)),
        join=Join(type=GatewayType.AND),
        deadlines=(Deadline(duration_text="PT300S", duration=Literal(300.0),
                            exception_name="late", location=here),),
        extended_attributes=(
            ExtendedAttribute(name="vendor:xy", value="1", text=" t ",
                              raw_xml='<v:x xmlns:v="urn:v">1</v:x>', location=here),
        ),
        location=here,
    )
    process = WorkflowProcess(
        id="w",
        activities=(
            Activity(id="start", body=Event(position=EventPosition.START,
                                            trigger=Trigger(kind=TriggerKind.TIMER,
                                                            time_cycle="PT1S",
                                                            duration=Literal(1.0)))),
            arbiter,
            Activity(id="call", body=SubFlow(process="other", actual_parameters=(
                ActualParameter(text="n", expression=Name(("n",))),))),
            Activity(id="app", body=Task(kind=TaskKind.APPLICATION, applications=(
                TaskApplication(application="beep"),))),
            Activity(id="block", body=BlockActivity(activity_set="S"),
                     start_mode=ActivityMode.MANUAL),
        ),
        transitions=(
            Transition(id="t1", source="start", target="arbitrate",
                       condition=Condition(kind=ConditionKind.CONDITION, text="n < 3",
                                           expression=condition),
                       assignments=(Assignment(target="n", text="n + 1",
                                               expression=Binary("+", Name(("n",)),
                                                                 Literal(1))),)),
        ),
        activity_sets=(ActivitySet(id="S", activities=(Activity(id="inner"),)),),
        directives=ProcessDirectives(
            period=0.1, priority=3,
            start_trigger=TriggerRef(kind="timer", at=(28800.0, 43200.0), every=86400.0),
        ),
    )
    return Package(
        id="demo",
        source="specs/demo.xpdl",
        data_fields=(DataField(id="n", type=BasicType(kind=BasicKind.INTEGER),
                               initial_value="0", initial=0),
                     DataField(id="f", type=BasicType(kind=BasicKind.FLOAT), initial=1.0),
                     DataField(id="b", type=BasicType(kind=BasicKind.BOOLEAN), initial=True)),
        processes=(process,),
        metrics=(MetricDefinition(name="m", kind=MetricKind.DURATION,
                                  start=EventSelector(event="activity.started"),
                                  end=EventSelector(event="activity.completed", which="last")),),
        modes=(WorkflowMode(id="search", workflows=("w",), initial=True),),
        location=SourceLocation("specs/demo.xpdl", 1),
    )


def test_a_rich_model_round_trips_equal_with_types_of_values_kept() -> None:
    package = _rich_package()
    back = codec.loads(codec.dumps(package))
    assert back == package
    # 1 == 1.0 == True in Python, so check the JSON kept each value's own type.
    initials = [type(field.initial) for field in back.data_fields]
    assert initials == [int, float, bool]


def test_fields_equal_to_their_default_are_left_out_of_the_file() -> None:
    document = codec.dump(Package(id="p", processes=(WorkflowProcess(id="w"),)))
    assert document["package"] == {
        "$": "Package", "id": "p", "processes": [{"$": "WorkflowProcess", "id": "w"}]
    }
    assert document["format"] == "opspec-wfs" and document["version"] == codec.VERSION


def test_write_wfs_then_read_wfs_gives_the_same_package_and_leaves_no_temp_file(
    tmp_path: Path,
) -> None:
    package = _rich_package()
    target = tmp_path / "demo.wfs"
    codec.write_wfs(package, target)
    assert codec.read_wfs(target) == package
    assert [p.name for p in tmp_path.iterdir()] == ["demo.wfs"]


def test_write_wfs_replaces_an_existing_file(tmp_path: Path) -> None:
    target = tmp_path / "x.wfs"
    target.write_text("old")
    codec.write_wfs(Package(id="new"), target)
    assert codec.read_wfs(target).id == "new"


def test_write_wfs_into_a_missing_folder_raises_oserror(tmp_path: Path) -> None:
    with pytest.raises(OSError):
        codec.write_wfs(Package(id="p"), tmp_path / "nope" / "x.wfs")


# --------------------------------------------------------------------------- bad files


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.wfs"
    path.write_text(text)
    return path


def test_a_script_from_a_newer_opspec_is_refused_with_upgrade_advice(tmp_path: Path) -> None:
    document = codec.dump(Package(id="p"))
    document["version"] = codec.VERSION + 1
    path = _write(tmp_path, json.dumps(document))
    with pytest.raises(SpecError, match=r"bad\.wfs: .*format version 2.*upgrade opspec"):
        codec.read_wfs(path)


@pytest.mark.parametrize("version", [0, -1, "1", None, 1.5], ids=repr)
def test_an_unknown_format_version_is_refused(tmp_path: Path, version: object) -> None:
    document = codec.dump(Package(id="p"))
    document["version"] = version
    with pytest.raises(SpecError, match="unknown format version"):
        codec.read_wfs(_write(tmp_path, json.dumps(document)))


def test_older_versions_are_upgraded_through_the_migrations_table(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Pretend there was a format version 0 that called the package id "ident".
    def upgrade_0_to_1(document: dict[str, Any]) -> dict[str, Any]:
        package = dict(document["package"])
        package["id"] = package.pop("ident")
        return {**document, "package": package}

    monkeypatch.setitem(codec.MIGRATIONS, 0, upgrade_0_to_1)
    old = {"format": "opspec-wfs", "version": 0, "package": {"$": "Package", "ident": "p"}}
    assert codec.load(old) == Package(id="p")


def test_a_missing_migration_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(codec, "VERSION", 3)
    document = codec.dump(Package(id="p"))
    document["version"] = 1
    with pytest.raises(SpecError, match="format version 1 is no longer supported"):
        codec.load(document)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        pytest.param('{"format": "opspec-wfs", "vers', r"bad\.wfs:1: corrupt workflow script "
                     r"\(invalid JSON: Unterminated string starting at column 26\)",
                     id="truncated-json"),
        pytest.param('{"format": "opspec-wfs",\n "x": [1,,2]}', r"bad\.wfs:2: corrupt workflow "
                     r"script \(invalid JSON: Expecting value at column 10\)",
                     id="json-syntax-on-line-2"),
        pytest.param('{"some": "json"}', "not an opspec workflow script", id="other-json"),
        pytest.param("[1, 2]", "not an opspec workflow script", id="json-list"),
        pytest.param('<?xml version="1.0"?><Package/>', "this is XML", id="xpdl-given"),
        pytest.param('{"format":"opspec-wfs","version":1,"package":{"$":"os.system"}}',
                     "unknown type tag 'os.system'", id="unknown-tag"),
        pytest.param('{"format":"opspec-wfs","version":1,"package":{"$":"Activity","id":"a"}}',
                     "a Activity cannot stand here", id="wrong-class-at-root"),
        pytest.param('{"format":"opspec-wfs","version":1,"package":{"$":"Package"}}',
                     "missing 1 required keyword-only argument: 'id'", id="missing-field"),
        pytest.param('{"format":"opspec-wfs","version":1,"package":{"$":"Package","id":"p",'
                     '"bogus":1}}', "Package has no field 'bogus'", id="unknown-field"),
        pytest.param('{"format":"opspec-wfs","version":1,"package":{"$":"Package","id":"p",'
                     '"version":"9.9"}}', "'9.9' is not a XpdlVersion", id="bad-enum"),
        pytest.param('{"format":"opspec-wfs","version":1,"package":{"$":"Package","id":7}}',
                     "expected str, got 7", id="wrong-scalar-type"),
    ],
)
def test_a_file_that_is_not_a_valid_script_is_a_spec_error_naming_the_file(
    tmp_path: Path, text: str, message: str
) -> None:
    with pytest.raises(SpecError, match=message) as caught:
        codec.read_wfs(_write(tmp_path, text))
    assert "bad.wfs" in str(caught.value)


def test_binary_garbage_is_a_spec_error(tmp_path: Path) -> None:
    path = tmp_path / "bad.wfs"
    path.write_bytes(bytes(range(256)))
    with pytest.raises(SpecError, match="bad.wfs"):
        codec.read_wfs(path)


def test_a_missing_file_is_a_spec_error_naming_it(tmp_path: Path) -> None:
    with pytest.raises(SpecError, match=r"nothing\.wfs: cannot read"):
        codec.read_wfs(tmp_path / "nothing.wfs")


def test_infinite_floats_survive_the_round_trip() -> None:
    package = Package(id="p", processes=(WorkflowProcess(
        id="w", directives=ProcessDirectives(deadline=math.inf)),))
    assert codec.loads(codec.dumps(package)) == package
