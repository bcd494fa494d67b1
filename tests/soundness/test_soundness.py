"""`opspec check`: soundness of control flow with a witness for every problem, on constructed
nets, on every corpus file (with the reason for each verdict) and on the bundled specs."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.model import ConditionKind, Event, EventPosition, GatewayType, Route
from opspec.model.activities import BlockActivity, Join, Split, Trigger, TriggerKind
from opspec.model.process import ActivitySet
from opspec.model.soundness import TOKEN_BOUND, check_process

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "validate"))
from validate_builders import act, end, process, start, tr

CORPUS = Path("/work/shared/corpus/xpdl")
if not CORPUS.is_dir():
    CORPUS = ROOT.parent / "shared" / "corpus" / "xpdl"


def gateway(activity_id: str, line: int, *, split: GatewayType | None = None,
            join: GatewayType | None = None):
    return act(activity_id, line, body=Route(gateway=split or join or GatewayType.XOR),
               split=Split(type=split) if split else None, join=Join(type=join) if join else None)


def problems(proc, **kw):
    return [p for r in check_process(proc, **kw) for p in r.problems]


def kinds(proc, **kw):
    return sorted({p.kind for p in problems(proc, **kw)})


def test_a_simple_sequence_is_sound():
    assert problems(process()) == []


def test_xor_split_into_and_join_deadlocks_with_a_witness():
    proc = process(activities=(
        start(), gateway("X", 11, split=GatewayType.XOR), act("a", 12), act("b", 13),
        gateway("J", 14, join=GatewayType.AND), end(line=15)), transitions=(
        tr("t0", "start", "X"), tr("ta", "X", "a"), tr("tb", "X", "b"),
        tr("ja", "a", "J"), tr("jb", "b", "J"), tr("te", "J", "end")))
    found = problems(proc)
    assert {p.kind for p in found} == {"deadlock", "and-join-never-fires", "dead"}
    deadlock = next(p for p in found if p.kind == "deadlock")
    assert deadlock.witness[:2] == ("start", "X") and deadlock.witness[-1] in ("a", "b")
    assert deadlock.activity == "J" and deadlock.line == 14
    join = next(p for p in found if p.kind == "and-join-never-fires")
    assert join.activity == "J"


def test_and_split_into_and_join_is_sound():
    proc = process(activities=(
        start(), gateway("S", 11, split=GatewayType.AND), act("a", 12), act("b", 13),
        gateway("J", 14, join=GatewayType.AND), end(line=15)), transitions=(
        tr("t0", "start", "S"), tr("ta", "S", "a"), tr("tb", "S", "b"),
        tr("ja", "a", "J"), tr("jb", "b", "J"), tr("te", "J", "end")))
    assert problems(proc) == []


def test_loop_without_exit_is_a_livelock():
    proc = process(activities=(start(), act("a", 11), act("b", 12), end(line=13)),
                   transitions=(tr("t0", "start", "a"), tr("t1", "a", "b"),
                                tr("t2", "b", "a")))
    found = problems(proc)
    assert "livelock" in {p.kind for p in found}


def test_loop_with_an_exit_is_sound():
    proc = process(activities=(start(), act("a", 11), gateway("again", 12,
                                                               split=GatewayType.XOR),
                               end(line=13)),
                   transitions=(tr("t0", "start", "a"), tr("t1", "a", "again"),
                                tr("t2", "again", "a"), tr("t3", "again", "end")))
    assert problems(proc) == []


def test_end_reached_with_a_token_stuck_is_improper_completion():
    proc = process(activities=(
        start(), gateway("S", 11, split=GatewayType.AND), act("a", 12),
        gateway("X", 13, split=GatewayType.XOR), act("b", 14),
        gateway("J", 15, join=GatewayType.AND), end(line=16), end("end2", 17)),
        transitions=(tr("t0", "start", "S"), tr("t1", "S", "a"), tr("t2", "S", "X"),
                     tr("t3", "X", "b"), tr("t4", "X", "end2"), tr("t5", "a", "J"),
                     tr("t6", "b", "J"), tr("t7", "J", "end")))
    found = problems(proc)
    improper = next(p for p in found if p.kind == "improper-completion")
    assert improper.activity == "J" and "end2" in improper.witness


def test_an_unreachable_activity_is_dead():
    proc = process(activities=(start(), act("work", 11), act("orphan", 12), end(line=13)),
                   transitions=(tr("t0", "start", "work"), tr("t1", "work", "end"),
                                tr("t2", "orphan", "end")))
    # 'orphan' has no incoming transition, so it is a start: make it unreachable instead
    proc = process(activities=(start(), act("work", 11), act("orphan", 12), end(line=13),
                               gateway("J", 14, join=GatewayType.AND)),
                   transitions=(tr("t0", "start", "work"), tr("t1", "work", "end"),
                                tr("t2", "J", "orphan"), tr("t3", "orphan", "J")))
    assert {p.activity for p in problems(proc) if p.kind in ("dead", "and-join-never-fires")
            } == {"orphan", "J"}


def test_tokens_multiplying_in_a_loop_are_unbounded():
    proc = process(activities=(start(), gateway("S", 11, split=GatewayType.AND),
                               act("a", 12), end(line=13)),
                   transitions=(tr("t0", "start", "S"), tr("t1", "S", "S"),
                                tr("t2", "S", "a"), tr("t3", "a", "end")))
    assert "unbounded" in kinds(proc)


def test_state_space_limit_is_reported_not_called_sound():
    branches = [act(f"w{n}", 20 + n) for n in range(12)]
    proc = process(activities=(start(), gateway("S", 11, split=GatewayType.AND), *branches,
                               gateway("J", 40, join=GatewayType.AND), end(line=41)),
                   transitions=(tr("t0", "start", "S"),
                                *[tr(f"a{n}", "S", f"w{n}") for n in range(12)],
                                *[tr(f"b{n}", f"w{n}", "J") for n in range(12)],
                                tr("te", "J", "end")))
    reports = check_process(proc, max_states=100)
    assert not reports[0].complete and not reports[0].sound
    assert check_process(proc)[0].sound


def test_loop_blocked_conformance_forbids_cycles():
    proc = process(activities=(start(), act("a", 11), gateway("again", 12,
                                                               split=GatewayType.XOR),
                               end(line=13)),
                   transitions=(tr("t0", "start", "a"), tr("t1", "a", "again"),
                                tr("t2", "again", "a"), tr("t3", "again", "end")))
    found = problems(proc, conformance="LOOP_BLOCKED")
    assert [p.kind for p in found] == ["conformance"]
    assert found[0].witness[0] == found[0].witness[-1]
    assert problems(proc, conformance="NON_BLOCKED") == []


def test_full_blocked_wants_every_split_closed_by_a_join_of_its_kind():
    proc = process(activities=(
        start(), gateway("S", 11, split=GatewayType.AND), act("a", 12), act("b", 13),
        gateway("J", 14, join=GatewayType.XOR), end(line=15)), transitions=(
        tr("t0", "start", "S"), tr("ta", "S", "a"), tr("tb", "S", "b"),
        tr("ja", "a", "J"), tr("jb", "b", "J"), tr("te", "J", "end")))
    assert "conformance" in kinds(proc, conformance="FULL_BLOCKED")


# ----------------------------------------------------------------------------- corpus

SOUND = "sound"
UNREADABLE = "unreadable"

# Every corpus file, its verdict and why. A verdict is SOUND, UNREADABLE (not XPDL at all:
# exit 1, nothing checked) or the sorted problem kinds found; ``errors`` marks files whose
# reader errors make the status 1 although their control flow is checked.
CORPUS_VERDICTS: dict[str, tuple[str | list[str], bool, str]] = {
    "bizagi21__Test_multiple_workflow_processes.xpdl": (SOUND, False,
        "an empty pool process and two straight start -> task -> end sequences"),
    "bizagi22__Diagram_1.xpdl": (SOUND, False,
        ("two processes whose parallel (AND route) branches each run to their own end: "
        "implicit termination, no join to wait at")),
    "bizagi22__diagram1.xpdl": (SOUND, False,
        ("a task with two unconditional flows runs both branches (no split declared), each "
        "branch ends on its own")),
    "bizagi22__diagram3.xpdl": (SOUND, False,
        ("a long sequence with one exclusive gateway whose two paths each reach their own "
        "end")),
    "bonita-bull__splits_joins_complex.xpdl": (SOUND, False,
        ("two AND splits closed by three AND joins: every join gets a token from each of its "
        "branches in every run (50 markings)")),
    "bonita-nova__suspendResume.xpdl": (SOUND, False, "a three-activity sequence"),
    "bonita-simprocess__Example6.xpdl": (SOUND, False,
        "a subflow call (one move) and a process whose XOR split is closed by an XOR join"),
    "bonita__ApprovalWorkflow.xpdl": (SOUND, False,
        ("Approval's conditions lead to Reject or Accept, both to the XOR-joined end; its AND "
        "joins have one incoming transition each, so they never wait")),
    "bonita__Habilitation.xpdl": (SOUND, False, "a five-activity sequence"),
    "bonita__InputOutputConnector.xpdl": (SOUND, False, "a three-activity sequence"),
    "bonita__activityHook-v4.xpdl": (SOUND, False, "a three-activity sequence"),
    "bonita__arbitraryCycle.xpdl": (SOUND, False,
        ("two interleaved loops (a1..a4 and a2..a6) left by conditions on a2 and a6; the AND "
        "joins have one incoming transition each, so they never wait")),
    "bonita__carpool.xpdl": (SOUND, False,
        ("WaitRequest and WaitAnswer choose by condition between going on, cancelling and a "
        "deadline activity that loops back; a way out always remains (no livelock)")),
    "bonita__mainSubflowJoinXor.xpdl": (SOUND, False,
        ("the start runs two subflows in parallel (two unconditional flows) and an XOR join "
        "lets each token through to the end: no token is stuck")),
    "bonita__subflowParams-sub.xpdl": (SOUND, False, "a three-activity sequence"),
    "bonita__subflowParams.xpdl": (SOUND, False, "a subflow call between start and end"),
    "bonita__testManagementAPIWithParsingError.xpdl": (UNREADABLE, True,
        "not well-formed XML (a mismatched tag at line 28): nothing to check"),
    "bpmve__PackageBasic.xpdl": (SOUND, True,
        ("a template with placeholder ids: duplicate lane ids and a missing ExternalPackage are "
        "reader errors (status 1), but its processes are empty and therefore sound")),
    "bpmxpdl20__sample.xpdl": (SOUND, False,
        ("the order process's XOR splits all end at the rejection or acceptance path, its AND "
        "split 30 is closed by the AND join 31; Fill Order's AND split with two conditions "
        "runs to two ends")),
    "g360__Subprocess.xpdl": (SOUND, False,
        ("an embedded subprocess (a BlockActivity, its activity set checked on its own) "
        "beside a task; 'NON-BLOCKED' is no conformance class, so nothing is restricted")),
    "g360__Subprocess4_with_exception.xpdl": (["dead"], False,
        ("the block's activity set starts at '232' (StartActivityId), and the transitions "
        "235 -> 438 -> 233 that would lead through Task E are written in the wrong process "
        "(validate reports them), so Task E '438' has no way in")),
    "g360__Three_tasks_and_event_gateway.xpdl": (SOUND, False,
        ("an exclusive gateway before a message and a timer event: either is taken, both "
        "branches reach the end")),
    "g360__complex.xpdl": (SOUND, False,
        ("an AND split whose branches meet at a4 without a join: a4 and the rest run twice "
        "(a multi-merge), which completes properly under implicit termination")),
    "g360__dfs.xpdl": (SOUND, False,
        "AND splits into branches that end separately, one of them an embedded subprocess"),
    "jawe10__LoopBlocked.xpdl": (["conformance"], False,
        ("declares LOOP_BLOCKED but Act4 -> Act3 -> Act5 -> Act4 is a cycle (JaWE files it "
        "under 'Invalid'); its second process has no cycle")),
    "jawe10__document_approval.xpdl": (SOUND, False,
        ("review loops go back to Update Document and leave by Publish Document; the review's "
        "EXCEPTION path rejoins through an XOR join")),
    "jawe10__leave_request.xpdl": (SOUND, False,
        "five XOR splits and two EXCEPTION paths, all reaching an end; no AND join"),
    "jawe10__sample_workflow_process.xpdl": (SOUND, False,
        ("XOR splits closed by XOR joins, the AND split closed by an AND join on parallel "
        "branches, and an EXCEPTION path to its own end. JaWE files it under 'Invalid': "
        "activity 36's deadline exceptions have no EXCEPTION transition (its transitions 49 "
        "and 50 test 'notifyException' as plain conditions), so an expired deadline aborts "
        "the instance; an abort is not a token move (docs/soundness.md, Limits), and "
        "`opspec validate` reports it")),
    "jawe10__workflow_patterns.xpdl": (SOUND, False,
        ("the 15 WfMC pattern processes: Multiple Choice and Multiple Merge use AND splits "
        "with conditions (any subset of branches), Discriminator and N-out-of-M merge them "
        "with XOR joins (tokens run on, 504 markings), Synchronization closes AND with AND")),
    "jawe21__Application_Repository.xpdl": (SOUND, False, "a repository: no process"),
    "jawe21__Business_Example.xpdl": (["improper-completion"], False,
        ("the AND-join Act13 waits for Act11 and Act101, which lie on different branches of an "
        "exclusive split: only correlated data could make both come")),
    "jawe21__Participant_Repository.xpdl": (SOUND, False, "a repository: no process"),
    "jawe21__Process_Repository.xpdl": (SOUND, False, "two three-activity sequences"),
    "jawe21__leave_request.xpdl": (SOUND, False,
        "as the XPDL 1.0 leave request: XOR splits and EXCEPTION paths, all reaching an end"),
    "jawe21__nested_lanes.xpdl": (SOUND, False,
        "one AND split whose branches end separately"),
    "tibco-af__Fallstudie_4-09_e-Car_Produktion.xpdl": (["deadlock", "improper-completion"],
        True,
        ("its conditions are German prose (reader errors, status 1), but its control flow is "
        "checked: 'Individualteile benötigt' is decided twice by separate XOR splits, and "
        "when they disagree the AND joins waiting for 'Individualteile erhalten' keep a "
        "token: sound only if the data correlates. Its three message start events each start "
        "an instance running only their path (as run starts them), so an instance stuck at "
        "such a join has reached no end: a deadlock (played together, another start's path "
        "reached an end and it read as improper completion only)")),
    "tibco-af__Test_loop_2.xpdl": (SOUND, False,
        "two nested loops built from XOR gateways, each with an OTHERWISE way out"),
    "tibco-af__Test_multiple_pools_processes_and_lanes.xpdl": (SOUND, False,
        ("two start events in one process (both run), an AND split closed by an AND join; "
        "the second process's XOR split is closed by an XOR join")),
    "tibco__InsuranceClaimHandling.xpdl": (SOUND, False,
        ("XOR gateways with OTHERWISE paths meet at one XOR join; the AND split for advice "
        "and payment is closed by an AND join")),
    "tibcofrg___GM0bEEeyEd-eq-1NLZ2xQg.frg.xpdl": (SOUND, False,
        ("an embedded subprocess (a transaction) whose XOR split leads to End (OTHERWISE) or "
        "Abort")),
    "tibcofrg___GPkNEEeyEd-eq-1NLZ2xQg.frg.xpdl": (SOUND, False,
        ("a subflow call with three boundary events (cancel, error, timeout), each leading "
        "to its handler task: any of them may interrupt the call, every path ends")),
    "tibcofrg___GPn3cEeyEd-eq-1NLZ2xQg__es_AR.frg.xpdl": (SOUND, False,
        "a plain sequence of five activities"),
    "tibcofrg___GQAR8EeyEd-eq-1NLZ2xQg.frg.xpdl": (SOUND, False,
        "two sequences, one around a subflow call"),
    "wfmc__deadline.xpdl": (SOUND, False,
        ("Step 1's deadline takes the DEFAULTEXCEPTION path instead of Step 2; both meet at "
        "Step 3's XOR join")),
    "wfmc__publication-1.0.xpdl": (SOUND, False,
        "a review loop left by an XOR split, and an AND split closed by an AND join"),
    "wfmc__subflow.xpdl": (SOUND, False, ("main flow, subflow and inner flow: sequences of "
        "subflow calls (one move each)")),
}
CORPUS_FILES = sorted(p.name for p in CORPUS.glob("*.xpdl")) if CORPUS.is_dir() else []


@pytest.mark.skipif(not CORPUS_FILES, reason="shared corpus not present")
def test_every_corpus_file_has_a_verdict_with_a_reason():
    assert sorted(CORPUS_VERDICTS) == CORPUS_FILES
    assert all(len(why) > 10 for _verdict, _errors, why in CORPUS_VERDICTS.values())


@pytest.mark.skipif(not CORPUS_FILES, reason="shared corpus not present")
@pytest.mark.parametrize("name", CORPUS_FILES)
def test_corpus_file_verdict(name, capsys):
    status = main(["check", "--json", "--max-states", "20000", str(CORPUS / name)])
    doc = json.loads(capsys.readouterr().out.splitlines()[-1])
    expected, _reader_errors, why = CORPUS_VERDICTS[name]
    # check refuses exactly the specs validate refuses (issue 17): never "sound" with errors
    from opspec.commands.validate import engine_checks
    from opspec.xpdl.validate import validate_file

    errors = not validate_file(CORPUS / name, extra=engine_checks).ok
    assert bool(doc["errors"]) is errors, why
    if expected == UNREADABLE:
        assert status == 1 and doc["loaded"] is False, why
        return
    kinds_found = sorted({p["kind"] for p in doc["problems"]})
    assert kinds_found == ([] if expected == SOUND else expected), why
    assert all(process["complete"] for process in doc["processes"]), why
    assert status == (0 if expected == SOUND and not errors else 1), why
    assert doc["sound"] is (expected == SOUND and not errors), why


@pytest.mark.skipif(not CORPUS_FILES, reason="shared corpus not present")
def test_loop_blocked_corpus_file_names_its_cycle(capsys):
    assert main(["check", str(CORPUS / "jawe10__LoopBlocked.xpdl")]) == 1
    out = capsys.readouterr().out
    assert "jawe10__LoopBlocked.xpdl:" in out and "LOOP_BLOCKED" in out
    assert ("cycle: LOOP_BLOCKED_Test_Wor1_Act4 -> LOOP_BLOCKED_Test_Wor1_Act3 -> "
            "LOOP_BLOCKED_Test_Wor1_Act5 -> LOOP_BLOCKED_Test_Wor1_Act4") in out


@pytest.mark.parametrize("spec", sorted((ROOT / "specs").glob("*.xpdl")),
                         ids=lambda p: p.name)
def test_bundled_specs_are_sound(spec, capsys):
    assert main(["check", str(spec)]) == 0, capsys.readouterr().out


def test_cli_prints_path_line_and_witness_and_exits_1(tmp_path, capsys):
    spec = tmp_path / "deadlock.xpdl"
    spec.write_text((ROOT / "tests" / "validate" / "data" / "and_join_deadlock.xpdl")
                    .read_text(encoding="utf-8"), encoding="utf-8")
    assert main(["check", str(spec)]) == 1
    out = capsys.readouterr().out
    assert f"{spec}:" in out and "deadlock" in out and "witness: start -> X ->" in out


def test_cli_state_space_exceeded_is_inconclusive_and_exits_1(capsys):
    status = main(["check", "--max-states", "3", str(ROOT / "specs" /
                                                    "medication_dispenser.xpdl")])
    assert status == 1
    out = capsys.readouterr().out
    assert "more than 3 states: inconclusive" in out and ": inconclusive (" in out


def test_cli_missing_file_is_a_usage_error(capsys):
    assert main(["check", "/nonexistent/spec.xpdl"]) == 2


# ------------------------------------------------------------------ engine rules in the game

def cond(text: str) -> dict:
    from opspec.xpdl.conditions import parse_condition
    return {"kind": ConditionKind.CONDITION, "text": text, "expression": parse_condition(text)}


def fork_join(split: GatewayType, join: GatewayType, *, conditional: bool = False,
              otherwise_to: str | None = None):
    """start -> S(split) -> a, b -> J(join) -> end, optionally with conditions on S's flows
    and an OTHERWISE transition from S."""
    extra = (tr("tw", "S", otherwise_to, kind=ConditionKind.OTHERWISE),) if otherwise_to else ()
    other = (end("other", 16),) if otherwise_to else ()
    flow_a = cond("x > 1") if conditional else {}
    flow_b = cond("y > 1") if conditional else {}
    return process(activities=(
        start(), act("S", 11, split=Split(type=split)), act("a", 12), act("b", 13),
        gateway("J", 14, join=join), end(line=15), *other), transitions=(
        tr("t0", "start", "S"), tr("ta", "S", "a", **flow_a), tr("tb", "S", "b", **flow_b),
        *extra, tr("ja", "a", "J"), tr("jb", "b", "J"), tr("te", "J", "end")))


def test_and_split_with_conditions_may_take_any_subset_so_an_and_join_can_deadlock():
    # JaWE writes a multiple choice as an AND split with conditions; the engine takes the
    # conditions that hold, so one branch alone may run
    found = problems(fork_join(GatewayType.AND, GatewayType.AND, conditional=True,
                               otherwise_to="other"))
    deadlock = next(p for p in found if p.kind == "deadlock")
    assert deadlock.activity == "J" and deadlock.witness[:2] == ("start", "S")


def test_and_split_takes_otherwise_only_when_no_condition_holds():
    proc = fork_join(GatewayType.AND, GatewayType.OR, conditional=True, otherwise_to="other")
    assert problems(proc) == []         # 'other' is reachable: no dead activity
    proc = fork_join(GatewayType.AND, GatewayType.AND, otherwise_to="other")
    assert [p.activity for p in problems(proc) if p.kind == "dead"] == ["other"]


def test_or_split_closed_by_or_join_is_sound_but_by_and_join_deadlocks():
    assert problems(fork_join(GatewayType.OR, GatewayType.OR, conditional=True)) == []
    assert "deadlock" in kinds(fork_join(GatewayType.OR, GatewayType.AND, conditional=True))
    # unconditional flows of an OR split are always taken, as in the engine
    assert problems(fork_join(GatewayType.OR, GatewayType.AND)) == []


def test_terminate_end_event_removes_the_tokens_left_behind():
    def build(result: str | None):
        return process(activities=(
            start(), act("S", 11, split=Split(type=GatewayType.AND)), act("a", 12),
            gateway("w", 13, join=GatewayType.AND), act("never", 14),
            act("stop", 15, body=Event(position=EventPosition.END, result=result))),
            transitions=(tr("t0", "start", "S"), tr("t1", "S", "a"), tr("t2", "S", "w"),
                         tr("t3", "never", "w"), tr("t4", "w", "never"),
                         tr("t5", "a", "stop")))
    assert "improper-completion" in kinds(build(None))
    assert "improper-completion" not in kinds(build("Terminate"))


def test_interrupting_boundary_event_replaces_its_host_and_non_interrupting_adds_a_token():
    def build(interrupting: bool):
        timer = Event(position=EventPosition.INTERMEDIATE,
                      trigger=Trigger(kind=TriggerKind.TIMER, attached_to="h",
                                      interrupting=interrupting))
        return process(activities=(
            start(), act("h", 11), act("e", 12, body=timer), act("after", 13),
            act("handler", 14), gateway("J", 15, join=GatewayType.AND), end(line=16),
            end("end2", 17)), transitions=(
            tr("t0", "start", "h"), tr("t1", "h", "after"), tr("t2", "e", "handler"),
            tr("t3", "after", "J"), tr("t4", "handler", "J"), tr("t5", "J", "end")))
    assert "and-join-never-fires" in kinds(build(True))
    assert "and-join-never-fires" not in kinds(build(False))


def test_activity_set_starts_where_its_block_activity_says():
    inner = ActivitySet(id="set", activities=(act("first", 21), act("second", 22)))
    proc = process(activities=(
        start(), act("blk", 11, body=BlockActivity(activity_set="set", start_activity="first")),
        end()), transitions=(tr("t0", "start", "blk"), tr("t1", "blk", "end")),
        activity_sets=(inner,))
    found = problems(proc)
    assert [(p.process, p.kind, p.activity, p.line) for p in found] == [
        ("Pump/set", "dead", "second", 22)]


def test_livelock_witness_leads_into_the_loop():
    proc = process(activities=(start(), act("a", 11), act("b", 12)),
                   transitions=(tr("t0", "start", "a"), tr("t1", "a", "b"),
                                tr("t2", "b", "a")))
    livelock = next(p for p in problems(proc) if p.kind == "livelock")
    # from the start on, completion is impossible: the witness runs once round the loop,
    # and the problem is placed where the tokens enter the loop (line 11, "a"), not at the
    # start event, which has nothing to change
    assert livelock.witness == ("start", "a", "b", "a")
    assert livelock.activity == "a" and livelock.line == 11
    assert "never complete" in livelock.message and "through a, b" in livelock.message
    assert [p.kind for p in problems(proc)] == ["livelock"]


def test_unbounded_witness_ends_where_the_bound_is_passed():
    proc = process(activities=(start(), gateway("S", 11, split=GatewayType.AND),
                               act("a", 12), end(line=13)),
                   transitions=(tr("t0", "start", "S"), tr("t1", "S", "S"),
                                tr("t2", "S", "a"), tr("t3", "a", "end")))
    unbounded = next(p for p in problems(proc) if p.kind == "unbounded")
    assert unbounded.witness[0] == "start" and set(unbounded.witness[1:]) <= {"S", "a", "end"}
    assert f"more than {TOKEN_BOUND}" in unbounded.message


# ---------------------------------------------------------------------- FULL_BLOCKED blocks

def test_full_blocked_accepts_a_proper_block():
    proc = fork_join(GatewayType.AND, GatewayType.AND)
    assert problems(proc, conformance="FULL_BLOCKED") == []


def test_full_blocked_reports_branches_that_never_meet():
    proc = process(activities=(start(), gateway("S", 11, split=GatewayType.AND),
                               end("e1", 12), end("e2", 13)),
                   transitions=(tr("t0", "start", "S"), tr("t1", "S", "e1"),
                                tr("t2", "S", "e2")))
    found = problems(proc, conformance="FULL_BLOCKED")
    assert [(p.kind, p.activity) for p in found] == [("conformance", "S")]
    assert "never meet" in found[0].message
    assert problems(proc, conformance="LOOP_BLOCKED") == []


def test_full_blocked_reports_a_block_entered_from_outside():
    proc = process(activities=(
        start(), gateway("X", 11, split=GatewayType.XOR), gateway("S", 12,
                                                                  split=GatewayType.AND),
        act("a", 13), act("b", 14), gateway("J", 15, join=GatewayType.AND),
        gateway("M", 16, join=GatewayType.XOR), end(line=17)), transitions=(
        tr("t0", "start", "X"), tr("t1", "X", "S"), tr("t2", "X", "b"), tr("t3", "S", "a"),
        tr("t4", "S", "b"), tr("t5", "a", "J"), tr("t6", "b", "J"), tr("t7", "J", "M"),
        tr("t8", "M", "end")))
    messages = [p.message for p in problems(proc, conformance="FULL_BLOCKED")
                if p.kind == "conformance"]
    assert any("entered from outside, by 'X' -> 'b'" in m for m in messages)


# ------------------------------------------------------------------------------------ CLI

def test_cli_json_has_one_object_per_file_with_processes_problems_and_witnesses(capsys):
    data = ROOT / "tests" / "validate" / "data" / "and_join_deadlock.xpdl"
    spec = ROOT / "specs" / "medication_dispenser.xpdl"
    assert main(["check", "--json", str(data), str(spec)]) == 1
    docs = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [d["path"] for d in docs] == [str(data), str(spec)]
    bad, good = docs
    assert set(bad) == {"path", "sound", "loaded", "max_states", "inconclusive", "processes",
                        "problems", "errors"}
    assert bad["sound"] is False and good["sound"] is True and good["problems"] == []
    deadlock = next(p for p in bad["problems"] if p["kind"] == "deadlock")
    assert set(deadlock) == {"kind", "severity", "process", "activity", "line", "message",
                             "witness"}
    assert deadlock["witness"][:2] == ["start", "X"] and deadlock["line"] == 21
    assert {p["process"] for p in good["processes"]} >= {"notify_workflow", "user_workflow"}
    assert all(p["complete"] and p["sound"] for p in good["processes"])


def test_cli_prints_a_verdict_per_process_level(capsys):
    spec = ROOT / "specs" / "medication_dispenser.xpdl"
    assert main(["check", "--process", "notify_workflow", str(spec)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith(f"{spec}: notify_workflow: sound (")
    assert lines[-1] == f"{spec}: 1 of 1 process level(s) sound, 0 problem(s)"


def test_cli_unknown_process_is_a_usage_error_listing_the_processes(capsys):
    spec = ROOT / "specs" / "medication_dispenser.xpdl"
    assert main(["check", "--process", "nope", str(spec)]) == 2
    err = capsys.readouterr().err
    assert "no process 'nope'" in err and "notify_workflow" in err


def test_cli_rejects_a_max_states_below_one(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["check", "--max-states", "0", str(ROOT / "specs" / "medication_dispenser.xpdl")])
    assert exit_info.value.code == 2
    assert "--max-states: 0 must be at least 1" in capsys.readouterr().err


def test_cli_state_space_message_names_the_level_and_the_limit(capsys):
    spec = ROOT / "specs" / "medication_dispenser.xpdl"
    assert main(["check", "--json", "--max-states", "3", str(spec)]) == 1
    doc = json.loads(capsys.readouterr().out)
    assert doc["sound"] is False and doc["max_states"] == 3 and doc["inconclusive"] is True
    assert any(not p["complete"] and p["stopped"] == "states" for p in doc["processes"])
    assert main(["check", "--max-states", "3", str(spec)]) == 1
    out = capsys.readouterr().out
    assert "warning: notify_workflow: more than 3 states: inconclusive" in out


def test_cli_checks_the_control_flow_of_a_spec_with_reader_errors(tmp_path, capsys):
    text = (ROOT / "tests" / "validate" / "data" / "and_join_deadlock.xpdl").read_text(
        encoding="utf-8")
    spec = tmp_path / "prose.xpdl"
    spec.write_text(text.replace("<Expression>n &gt; 0</Expression>",
                                 "<Expression>parts needed</Expression>"), encoding="utf-8")
    assert main(["check", "--json", str(spec)]) == 1
    doc = json.loads(capsys.readouterr().out)
    # every error validate reports: the reader's and the structural checks'
    assert [e["code"] for e in doc["errors"]] == ["and-join-deadlock", "bad-condition"]
    assert "deadlock" in {p["kind"] for p in doc["problems"]}
    assert doc["loaded"] is True and doc["sound"] is False


def test_cli_unreadable_xml_is_reported_not_checked(tmp_path, capsys):
    spec = tmp_path / "bad.xpdl"
    spec.write_text("<Package><oops></Package>", encoding="utf-8")
    assert main(["check", str(spec)]) == 1
    out = capsys.readouterr().out
    assert f"{spec}:1: error: not well-formed XML" in out and "not checked" in out


def test_cli_unreadable_bpmn_is_not_called_xpdl(tmp_path, capsys):
    # It said "not checked: the file could not be read as XPDL" of a BPMN file too.
    spec = tmp_path / "broken.bpmn"
    spec.write_text('<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL">'
                    "<bpmn:process", encoding="utf-8")
    assert main(["check", str(spec)]) == 1
    out = capsys.readouterr().out
    assert f"{spec}:1: error: the file ends inside a tag" in out      # cut after <bpmn:process
    assert out.endswith(f"{spec}: not checked: the file could not be read as a spec (XPDL or "
                        "BPMN); fix the errors listed above\n")
    assert "as XPDL" not in out
