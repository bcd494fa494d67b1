"""What a workflow instance's expressions read and where its assignments land, when the
package and the workflow both declare fields (the robot specs' ``bump``, ``escaping``,
``level`` are package fields read by every periodic instance).

XPDL 2.1 (WfMC-TC-1025), Relevant Data Field: "Workflow Relevant Data can be defined in a
Workflow Process (the Workflow Process Relevant Data) and in a Package (the Package Relevant
Data). The scopes differ in that the former may only be accessed by entities defined inside
that process, while the latter may be accessed by entities inside any process defined within
that model." A process's own field of a package field's name is the one its activities see.
The engine's :class:`opspec.engine.scope.Scope` gives that reading; it must behave as
``collections.ChainMap(instance fields, package fields)``, which it replaced for speed.
"""

from __future__ import annotations

import copy
import pickle
from collections import ChainMap
from pathlib import Path

import pytest
from spec_text import Recorder, assign, compiled, field, process, task

from opspec.engine.scope import Scope
from opspec.engine.simulation import Simulation

PACKAGE_FIELDS = [field("level", "INTEGER", "1"), field("count", "INTEGER", "0")]


def _recorded(tmp_path: Path, proc: str, app: str, until: float = 3.5) -> list[object]:
    model = compiled(tmp_path, [proc], fields=PACKAGE_FIELDS, applications=[app])
    recorder = Recorder([app], "seen")
    Simulation(model, performers={"probe": recorder}).run(until=until)
    return [value for _time, value in recorder.seen]


def test_an_instance_reads_its_own_field_before_the_package_field_of_that_name(
        tmp_path: Path) -> None:
    # each instance starts from its own field's initial value: its increment of ``level``
    # lands in its own field, neither in the package nor in the next instance
    own = process("own", [assign("look", ("seen", "level")),
                          assign("bump", ("level", "level + 1")),
                          assign("again", ("seen", "seen * 10 + level")),
                          task("report", "report")], Period="1s",
                  fields=[field("level", "INTEGER", "5"), field("seen", "INTEGER", "0")])
    assert _recorded(tmp_path, own, "report") == [56, 56, 56, 56]


def test_an_instance_without_the_field_reads_and_writes_the_package_field(
        tmp_path: Path) -> None:
    # ``count`` is the package's: each instance's increment is seen by the next one
    shared = process("shared", [assign("add", ("count", "count + 1")),
                                assign("look", ("seen", "count * 10 + level")),
                                task("report", "report")], Period="1s",
                     fields=[field("seen", "INTEGER", "0")])
    assert _recorded(tmp_path, shared, "report") == [11, 21, 31, 41]


def test_a_missing_field_is_named_with_the_fields_that_exist(tmp_path: Path) -> None:
    lost = process("lost", [assign("look", ("seen", "nowhere + 1")),
                            task("report", "report")], Period="1s",
                   fields=[field("seen", "INTEGER", "0")])
    model = compiled(tmp_path, [lost], fields=PACKAGE_FIELDS, applications=["report"])
    result = Simulation(model, performers={"probe": Recorder(["report"], "seen")},
                        keep_trace=True).run(until=0.5)
    aborted = [e.data["reason"] for e in result.trace if e.kind == "process.aborted"]
    assert len(aborted) == 1
    assert "data field 'nowhere' does not exist (fields: count, level, seen)" in aborted[0]


@pytest.mark.parametrize("key", ["own", "both", "package", "absent"])
def test_scope_behaves_as_the_chainmap_it_replaced(key: str) -> None:
    def pair() -> tuple[Scope, ChainMap[str, object]]:
        fields = {"own": 1, "both": 2}
        package = {"package": 3, "both": 4, "z": 5}
        return Scope(fields, package), ChainMap(dict(fields), dict(package))

    scope, chain = pair()
    assert (key in scope) == (key in chain)
    assert scope.get(key, "default") == chain.get(key, "default")
    assert list(scope) == list(chain) and len(scope) == len(chain)
    assert dict(scope.items()) == dict(chain.items()) and bool(scope) == bool(chain)
    if key in chain:
        assert scope[key] == chain[key]
    else:
        with pytest.raises(KeyError):
            scope[key]
    scope[key] = chain[key] = 9                     # writes go to the first mapping
    assert scope.maps == chain.maps
    for target in (scope, chain):                   # deletes too, and only from there
        if key in ("package", "absent"):
            del target[key]
            with pytest.raises(KeyError):
                del target[key]
        else:
            del target[key]
    assert scope.maps == chain.maps


def test_scope_copies_and_pickles_as_the_chainmap_it_replaced() -> None:
    package = {"level": 1}
    scope = Scope({"seen": 2}, package)
    shallow = copy.copy(scope)
    shallow["seen"] = 3                             # its own instance fields, as ChainMap's
    assert scope["seen"] == 2 and shallow.package is package
    for twin in (copy.deepcopy(scope), pickle.loads(pickle.dumps(scope))):
        assert twin.maps == scope.maps and twin.maps[0] is not scope.maps[0]
