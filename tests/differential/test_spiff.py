"""Differential test against SpiffWorkflow, the maintained Python BPMN engine (issue 32, part 3).

Every BPMN file of SpiffWorkflow's own test suite (``data/spiff/``, README.md there says from
which commit) runs through both engines with the same data — the data fields the file
declares, with their initial values (``declared_data``) — the same performer and the same
virtual clock (one day, no real sleeping). The performer completes every user and manual
task, one at a time and setting no data, at once or an hour after it is offered (``MODES``:
the second lets boundary timers on user tasks fire). Each run gives the same facts: the flow
nodes it completed (by id, as a multiset: BPMN 2.0 orders nothing between parallel paths at
one instant) and how it ended (``completed``, ``waiting`` — an opspec deadlock included, as
SpiffWorkflow leaves such an instance waiting —, ``error``, ``hang``).

SpiffWorkflow runs in its own test-only venv, ``.spiff-venv`` (``scripts/spiff-venv.sh``; never
a dependency of opspec), through ``spiff_driver.py``, one subprocess for every file and mode. When the
venv is absent this module creates it (set ``OPSPEC_NO_ORACLE=1`` to skip instead); when it
cannot be made the comparisons are skipped saying why.

Each file is classified: both engines run it and **agree**; both run it and **disagree**; only
one runs it (the other refuses the file or stops with an error); neither does.
``known_disagreements.toml`` lists every file that does not agree, with the reason and, for a
disagreement, the section of BPMN 2.0 (OMG formal/2011-01-03) that decides it. A file whose
classification differs from that list fails: a new disagreement, and a known one that went
away (the list stays true). docs/semantics.md ("Differential check against SpiffWorkflow")
states the agreement count and every disagreement; a test keeps it in step with the list.
"""

from __future__ import annotations

import functools
import json
import os
import re
import subprocess
import tomllib
import xml.etree.ElementTree as ET
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

import opspec
from opspec.errors import OpspecError, Severity
from opspec.runs import User
from opspec.xpdl.validate import validate_spec

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
DATA = HERE / "data" / "spiff"
KNOWN = HERE / "known_disagreements.toml"
SEMANTICS = ROOT / "docs" / "semantics.md"
VENV = ROOT / ".spiff-venv"
PYTHON = VENV / "bin" / "python"
FILES = sorted(p.relative_to(DATA).as_posix() for p in DATA.rglob("*")
               if p.name.endswith((".bpmn", ".bpmn20.xml")))

HORIZON = 86_400.0        # one day of virtual time (spiff_driver.HORIZON)
# how long the performer takes for each user or manual task: at once, and an hour (longer than
# every timer of the files but one, so that boundary timers on user tasks fire)
MODES = {"at_once": 0.0, "patient": 3_600.0}
MAX_COMPLETIONS = 120     # more flow-node completions is a livelock (spiff_driver too)
BPMN_NS = {"http://www.omg.org/spec/BPMN/20100524/MODEL", "http://schema.omg.org/spec/BPMN/2.0"}
PEOPLE = frozenset({"userTask", "manualTask"})   # the tasks a person performs
FLOW_NODES = frozenset({
    "task", "userTask", "manualTask", "serviceTask", "scriptTask", "sendTask", "receiveTask",
    "businessRuleTask", "callActivity", "subProcess", "transaction", "adHocSubProcess",
    "startEvent", "endEvent", "intermediateCatchEvent", "intermediateThrowEvent",
    "boundaryEvent", "exclusiveGateway", "parallelGateway", "inclusiveGateway",
    "complexGateway", "eventBasedGateway"})
CLASSES = ("disagree", "only_spiff", "only_opspec", "neither")
#: What SpiffWorkflow's own tests of these files hand the engine, handed to both engines: the
#: run inputs (names only a condition reads, which the file never sets; opspec would draw their
#: gateways at random, SpiffWorkflow read them as null) and what SpiffWorkflow's payload
#: expressions read (``payload``; opspec does not run them, so only SpiffWorkflow reads it).
#: ``approved``: the approver's answer, which SpiffWorkflow's message carries into
#: ``ApprovalResult`` (camunda:resultVariable, which opspec does not read).
GIVEN: dict[str, dict[str, Any]] = {
    "camunda/message_test.bpmn": {"ApprovalResult": "Yes", "approved": "Yes"},
    "spiff/error_event_payload.bpmn": {"error": True, "payload": "ERROR!"},
    "spiff/escalation_event_payload.bpmn": {"escalation": True, "payload": "ERROR!"},
}


@dataclass(frozen=True)
class Facts:
    """What one engine did with one file."""

    loaded: bool                 # the engine read the file and started a run
    state: str                   # completed | waiting | error | hang | refused
    completed: tuple[str, ...]   # flow node ids, in completion order
    error: str | None = None

    @property
    def ran(self) -> bool:
        return self.loaded and self.state not in ("error", "refused")


@dataclass(frozen=True)
class Verdict:
    kind: str                    # agree | one of CLASSES
    spiff: Facts
    ours: Facts
    missing: dict[str, int] = field(default_factory=dict)   # completed by SpiffWorkflow only
    extra: dict[str, int] = field(default_factory=dict)     # completed by opspec only

    def explain(self) -> str:
        return (f"{self.kind}: SpiffWorkflow {self.spiff.state} ({self.spiff.error or ''}), "
                f"opspec {self.ours.state} ({self.ours.error or ''}); completed by "
                f"SpiffWorkflow only {self.missing}, by opspec only {self.extra}")


def parser_of(name: str) -> str:
    """SpiffWorkflow's parser for a file: its tests read ``camunda/`` and ``spiff/`` (copies of
    ``tests/SpiffWorkflow/camunda/data`` and ``spiff/data``) with the parser of those
    extensions, the rest (``bpmn/data``) with the plain BPMN parser."""
    first = name.split("/", 1)[0]
    return first if first in ("camunda", "spiff") and "/" in name else "bpmn"


@functools.cache
def validated(path: Path) -> tuple[Any, Any]:
    return validate_spec(path)


def declared_data(path: Path) -> dict[str, Any]:
    """The data fields opspec reads from the file (of the package and of every process), with
    their initial values, null when they have none: the same data both engines start with.
    SpiffWorkflow puts no form field's default (nor a data object without value) into the
    data, so without this it would stop at the first condition over a form field."""
    package, _report = validated(path)
    if package is None:
        return {}
    fields = [*package.data_fields, *(f for p in package.processes for f in p.data_fields)]
    return {f.id: f.initial for f in fields
            if isinstance(f.initial, (str, int, float, bool, type(None)))}


def flow_node_ids(path: Path, kinds: frozenset[str] = FLOW_NODES) -> set[str]:
    """The ids of the file's flow nodes: what both engines' completions are compared on (each
    engine's own bookkeeping nodes, opspec's routes and SpiffWorkflow's participant tasks, are
    not in the file)."""
    ids = set()
    for element in ET.parse(path).iter():
        if not isinstance(element.tag, str) or "}" not in element.tag:
            continue
        namespace, _, local = element.tag[1:].partition("}")
        if namespace in BPMN_NS and local in kinds and element.get("id"):
            ids.add(element.get("id"))
    return ids


class _Person:
    """The performer of every participant: completes each user or manual task (``people``)
    ``delay`` seconds after it is offered, any other offer (a task in a lane bound to it) at
    once; the first alternative of a choice; no data. SpiffWorkflow's driver does the same
    (``task.run()``), whatever the lane."""

    def __init__(self, delay: float, people: frozenset[str]) -> None:
        self.delay = delay
        self.people = people

    def attach(self, session: Any) -> None:
        self.session = session

    def offer(self, item: Any) -> None:
        session = self.session
        session.call_later(self.delay if item.activity in self.people else 0.0,
                           lambda: session.complete(
                               item, choice=item.choices[0] if item.choices else None))

    def withdraw(self, item: Any, reason: str) -> None:
        pass


class _Livelock(Exception):
    pass


def given(path: Path) -> dict[str, Any]:
    """The values of :data:`GIVEN` that opspec's ``params`` can set for the file: its package
    data fields (its run inputs). A process's own field is set by the process (and hides a
    package value of that name), so ``params`` refuses it, as ``--param`` does."""
    values = GIVEN.get(path.relative_to(DATA).as_posix(), {})
    package, _report = validated(path)
    settable = {f.id for f in package.data_fields} if package is not None else set()
    return {name: value for name, value in values.items() if name in settable}


def opspec_facts(path: Path, delay: float = 0.0) -> Facts:
    """opspec's run of the file through its public API: validate, then ``opspec.run`` with the
    performer for the user lane and every participant, and the values :data:`GIVEN` for it,
    for ``HORIZON``."""
    package, report = validated(path)
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    if errors or package is None:
        first = errors[0] if errors else None
        return Facts(False, "refused", (), f"{first.code}: {first.message}" if first else "?")
    completed: list[str] = []
    tops: dict[int, str] = {}
    reasons: list[str] = []

    def listen(event: Any) -> None:
        if event.kind == "activity.completed" and event.activity is not None:
            completed.append(event.activity)
            if len(completed) > MAX_COMPLETIONS:
                raise _Livelock(f"more than {MAX_COMPLETIONS} flow-node completions")
        elif event.kind == "process.started":
            data = event.data or {}
            if data.get("parent") is None and not str(data.get("trigger")).startswith("subflow:"):
                tops[event.instance] = "waiting"
        elif event.kind in ("process.completed", "process.terminated", "process.aborted"):
            if event.instance in tops:
                tops[event.instance] = "completed"
                if event.kind == "process.aborted":
                    # a deadlock is no failure of the engine: the instance can no longer
                    # move, which SpiffWorkflow reports as waiting (it detects no deadlock)
                    reason = str((event.data or {}).get("reason", ""))
                    tops[event.instance] = "waiting" if reason.startswith("deadlock") else "error"
                    reasons.append(reason)

    people = frozenset(flow_node_ids(path, PEOPLE))
    performers = {p.id: _Person(delay, people) for p in package.participants}
    try:
        opspec.run(path, user=User.person(_Person(delay, people)), performers=performers,
                   until=HORIZON, params=given(path) or None,
                   listeners=[listen], keep_trace=False)
    except _Livelock as exc:
        return Facts(True, "hang", tuple(completed), str(exc))
    except OpspecError as exc:
        return Facts(True, "error", tuple(completed), str(exc).splitlines()[0][:300])
    states = set(tops.values())
    state = ("error" if "error" in states else "waiting" if "waiting" in states or not states
             else "completed")
    return Facts(True, state, tuple(completed), reasons[0][:300] if reasons else None)


def verdict(path: Path, spiff: Facts, ours: Facts) -> Verdict:
    nodes = flow_node_ids(path)
    theirs = Counter(i for i in spiff.completed if i in nodes)
    mine = Counter(i for i in ours.completed if i in nodes)
    missing, extra = dict(theirs - mine), dict(mine - theirs)
    if spiff.ran and ours.ran:
        same = spiff.state == ours.state and not missing and not extra
        if spiff.state == ours.state == "hang":
            # both cut a livelock off after MAX_COMPLETIONS: the same nodes loop
            same = set(theirs) == set(mine)
        return Verdict("agree" if same else "disagree", spiff, ours, missing, extra)
    kind = "only_spiff" if spiff.ran else "only_opspec" if ours.ran else "neither"
    return Verdict(kind, spiff, ours, missing, extra)


@functools.cache
def known(mode: str = "at_once") -> dict[str, tuple[str, dict[str, str]]]:
    """``{file: (class, entry)}`` from known_disagreements.toml for one performer ``mode``: the
    top-level tables are the at-once performer's; ``[patient.CLASS."FILE"]`` lists where the
    patient performer's class differs from it."""
    table = tomllib.loads(KNOWN.read_text(encoding="utf-8"))
    assert set(table) <= {*CLASSES, "patient"}, f"unknown sections {set(table)}"
    assert set(table.get("patient", {})) <= set(CLASSES)
    found = {name: (kind, entry) for kind in CLASSES
             for name, entry in table.get(kind, {}).items()}
    if mode == "patient":
        patient = table.get("patient", {})
        found.update({name: (kind, entry) for kind in CLASSES
                      for name, entry in patient.get(kind, {}).items()})
    return found


@pytest.fixture(scope="module")
def spiff() -> dict[tuple[str, str], Facts]:
    """SpiffWorkflow's facts for every file and performer mode: one subprocess of the driver."""
    if not PYTHON.exists() and os.environ.get("OPSPEC_NO_ORACLE"):
        pytest.skip("no .spiff-venv and OPSPEC_NO_ORACLE is set (bash scripts/spiff-venv.sh "
                    "makes it)")
    # idempotent: a fraction of a second when the venv imports SpiffWorkflow, and it repairs
    # a venv left half made (no PyPI the first time)
    made = subprocess.run(["bash", str(ROOT / "scripts" / "spiff-venv.sh")],
                          capture_output=True, text=True, timeout=600, check=False)
    if made.returncode != 0:
        pytest.skip("the SpiffWorkflow venv could not be made (no PyPI?): "
                    + (made.stderr.strip().splitlines() or ["?"])[-1])
    runs = [{"file": str(DATA / name), "data": {**declared_data(DATA / name),
                                                 **GIVEN.get(name, {})}, "delay": delay,
             "parser": parser_of(name)} for delay in MODES.values() for name in FILES]
    done = subprocess.run([str(PYTHON), str(HERE / "spiff_driver.py")], input=json.dumps(runs),
                          capture_output=True, text=True, timeout=300, check=False,
                          env={**os.environ, "TZ": "UTC"})
    assert done.returncode == 0, f"the SpiffWorkflow driver failed:\n{done.stderr[-3000:]}"
    modes = {delay: mode for mode, delay in MODES.items()}
    facts = {}
    for line in done.stdout.splitlines():
        row = json.loads(line)
        name = Path(row["file"]).relative_to(DATA).as_posix()
        facts[modes[row["delay"]], name] = Facts(
            row["loaded"], row["state"] if row["loaded"] else "refused",
            tuple(row["completed"]), row["error"])
    assert set(facts) == {(mode, name) for mode in MODES for name in FILES}
    return facts


def test_the_data_is_every_bpmn_file_of_spiffworkflows_suite_and_says_where_it_is_from() -> None:
    readme = (DATA / "README.md").read_text(encoding="utf-8")
    assert len(FILES) == 147   # bpmn/data 106, camunda/data 18, spiff/data 23
    for name in ("sartography/SpiffWorkflow", "LGPL", "8c6e00f6e2d85d93a1022341f4c479f23fbb0f41"):
        assert name in readme


def test_every_known_entry_names_a_file_and_says_why() -> None:
    for mode in MODES:
        for name, (kind, entry) in known(mode).items():
            assert name in FILES, f"{name} in known_disagreements.toml is no file of data/spiff"
            assert entry.get("reason"), f"{name}: no reason"
            if kind == "disagree":
                assert re.search(r"§\d+(\.\d+)*", entry.get("section", "")), \
                    f"{name}: a disagreement names the BPMN 2.0 section that decides it"
                assert entry.get("right") in ("opspec", "SpiffWorkflow", "both", "neither"), name


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("name", FILES)
def test_file_runs_as_in_spiffworkflow_or_as_the_known_list_says(
        spiff: dict[tuple[str, str], Facts], name: str, mode: str) -> None:
    """Two engines that both run the file by BPMN 2.0 chapter 13 (BPMN Execution Semantics)
    complete the same flow nodes and end the same way — or the file is listed, with why and,
    where both run it, the section of the standard that decides between them."""
    path = DATA / name
    found = verdict(path, spiff[mode, name], opspec_facts(path, MODES[mode]))
    listed = known(mode).get(name)
    if listed is None:
        assert found.kind == "agree", f"new ({mode}): {found.explain()}"
    else:
        assert found.kind == listed[0], (f"{name} ({mode}) is listed as {listed[0]} "
                                        f"({listed[1]['reason']}) but is now {found.explain()}")


def test_docs_state_the_agreement_count_and_every_disagreement() -> None:
    text = SEMANTICS.read_text(encoding="utf-8")
    heading = "## Differential check against SpiffWorkflow"
    assert heading in text
    section = text.split(heading, 1)[1]
    for mode in MODES:
        listed = known(mode)
        agree = len(FILES) - len(listed)
        count = {kind: sum(1 for k, _ in listed.values() if k == kind) for kind in CLASSES}
        line = next((ln for ln in section.splitlines() if ln.startswith(f"| {mode} |")), "")
        assert line, f"the counts of the {mode} performer are not in the section"
        cells = [cell.strip(" *") for cell in line.split("|")[2:-1]]
        assert cells == [str(agree)] + [str(count[kind]) for kind in CLASSES], (mode, cells)
        for name, (kind, _entry) in listed.items():
            if kind == "disagree":
                assert f"`{name}`" in section, f"{name} is not in docs/semantics.md's section"
