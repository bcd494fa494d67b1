"""`opspec check`: soundness of control flow with a witness for every problem, on constructed
nets, on every corpus file (with the reason for each verdict) and on the bundled specs."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.model import GatewayType, Route
from opspec.model.activities import Join, Split
from opspec.model.soundness import check_process

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

# Each corpus file's verdict and why. "unloadable" files are rejected by the reader (the
# check reports their errors and exits 1).
CORPUS_VERDICTS = {
    "jawe10__LoopBlocked.xpdl": (
        ["conformance"], ("declares LOOP_BLOCKED but Act4 -> Act3 -> Act5 -> Act4 is a cycle "
        "(JaWE files it under 'Invalid')")),
    "jawe21__Business_Example.xpdl": (
        ["improper-completion"], ("the AND-join Act13 waits for Act11 and Act101, which lie on "
        "different branches of an exclusive split: only correlated data could make both come")),
    "g360__Subprocess4_with_exception.xpdl": (
        ["dead"], ("the block's activity set starts at '232' (StartActivityId), and the "
        "transitions 235 -> 438 -> 233 that would lead through Task E are written in the "
        "wrong process (validate reports them), so Task E '438' has no way in")),
    "bonita__testManagementAPIWithParsingError.xpdl": ("unloadable", "not well-formed XML"),
    "bpmve__PackageBasic.xpdl": ("unloadable", "its ExternalPackage file is not in the corpus"),
    "tibco-af__Fallstudie_4-09_e-Car_Produktion.xpdl": (
        "unloadable", "transitions reference activities that do not exist"),
}
CORPUS_FILES = sorted(p.name for p in CORPUS.glob("*.xpdl")) if CORPUS.is_dir() else []


@pytest.mark.skipif(not CORPUS_FILES, reason="shared corpus not present")
@pytest.mark.parametrize("name", CORPUS_FILES)
def test_corpus_file_verdict(name, capsys):
    status = main(["check", "--json", "--max-states", "20000", str(CORPUS / name)])
    out = capsys.readouterr().out
    expected, _why = CORPUS_VERDICTS.get(name, ([], "sound: every process completes properly"))
    if expected == "unloadable":
        assert status == 1
        return
    doc = json.loads(out.splitlines()[-1])
    assert sorted({p["kind"] for p in doc["problems"]}) == expected
    assert status == (1 if expected else 0)
    assert doc["sound"] is (not expected)


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


def test_cli_state_space_exceeded_exits_2(capsys):
    status = main(["check", "--max-states", "3", str(ROOT / "specs" /
                                                    "medication_dispenser.xpdl")])
    assert status == 2
    assert "soundness undecided" in capsys.readouterr().out


def test_cli_missing_file_is_a_usage_error(capsys):
    assert main(["check", "/nonexistent/spec.xpdl"]) == 2
