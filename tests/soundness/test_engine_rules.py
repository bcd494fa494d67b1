"""`opspec check` plays the engine's rules: complex joins (discriminator, N-out-of-M, reset),
conditional flows without a split (inclusive, and a path that may end), correlated
conditions, multi-instance flows, and the compiler's classification of every corpus
activity (the token game and the engine must read each split and join alike)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from opspec.model import ConditionKind, GatewayType, Route
from opspec.model.activities import Join, Loop, LoopKind, MIFlow, Split
from opspec.model.expressions import Literal
from opspec.model.graph import levels
from opspec.model.soundness import check_process
from opspec.model.soundness_net import TokenNet, condition_subsets
from opspec.xpdl.conditions import parse_condition

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "validate"))
from validate_builders import act, end, process, start, tr

CORPUS = Path("/work/shared/corpus/xpdl")
if not CORPUS.is_dir():
    CORPUS = ROOT.parent / "shared" / "corpus" / "xpdl"


def cond(text: str) -> dict:
    return {"kind": ConditionKind.CONDITION, "text": text, "expression": parse_condition(text)}


def route(activity_id: str, line: int, *, split: GatewayType | None = None,
          join: GatewayType | None = None, incoming: str | None = None):
    return act(activity_id, line, body=Route(gateway=split or join or GatewayType.XOR),
               split=Split(type=split) if split else None,
               join=Join(type=join, condition_text=incoming,
                         condition=parse_condition(incoming)) if join else None)


def kinds(proc) -> list[str]:
    return sorted({p.kind for r in check_process(proc) for p in r.problems})


def into_complex(split: GatewayType, incoming: str, branches: int = 2, *,
                 conditional: bool = False):
    """start -> S(split) -> b0..bn -> J(complex, incoming) -> end."""
    names = [f"b{n}" for n in range(branches)]
    return process(activities=(
        start(), route("S", 11, split=split), *(act(b, 12 + n) for n, b in enumerate(names)),
        route("J", 20, join=GatewayType.COMPLEX, incoming=incoming), end(line=21)),
        transitions=(tr("t0", "start", "S"),
                     *(tr(f"s{b}", "S", b, **(cond(f"{b} > 0") if conditional else {}))
                       for b in names),
                     *(tr(f"j{b}", b, "J") for b in names), tr("te", "J", "end")))


# ------------------------------------------------------------------ complex joins

def test_a_discriminator_after_an_exclusive_choice_fires_on_the_one_token():
    # an AND-like join would deadlock here; activationCount >= 1 fires on the first arrival
    assert kinds(into_complex(GatewayType.XOR, "activationCount >= 1")) == []


def test_a_discriminator_after_a_parallel_split_ignores_the_later_tokens():
    # the second token is owed to the join and ignored: no token is left behind, J runs once
    assert kinds(into_complex(GatewayType.AND, "activationCount >= 1", 3)) == []


def test_n_out_of_m_waits_for_n_tokens():
    assert kinds(into_complex(GatewayType.AND, "activationCount >= 2", 3)) == []
    # one branch only: the join never fires, the token waits there
    found = kinds(into_complex(GatewayType.XOR, "activationCount >= 2", 3))
    assert "deadlock" in found and "dead" in found
    # an inclusive split may start one branch only, or two
    found = kinds(into_complex(GatewayType.OR, "activationCount == 2", 3, conditional=True))
    assert "deadlock" in found and "dead" not in found


def test_a_complex_join_whose_condition_can_never_hold_is_reported():
    proc = into_complex(GatewayType.AND, "activationCount >= 3")
    problems = [p for r in check_process(proc) for p in r.problems]
    dead = next(p for p in problems if p.activity == "J" and p.kind == "dead")
    assert "IncomingCondition never holds" in dead.message


def test_a_condition_reading_data_may_or_may_not_hold():
    # "ready" is data: the join may wait for ever with one token (conservative)
    found = kinds(into_complex(GatewayType.XOR, "activationCount >= 1 && ready"))
    assert "deadlock" in found


def test_a_discriminator_in_a_loop_resets_and_stays_bounded():
    proc = process(activities=(
        start(), route("S", 11, split=GatewayType.AND), act("a", 12), act("b", 13),
        route("J", 14, join=GatewayType.COMPLEX, incoming="activationCount >= 1"),
        route("again", 15, split=GatewayType.XOR), end(line=16)),
        transitions=(tr("t0", "start", "S"), tr("sa", "S", "a"), tr("sb", "S", "b"),
                     tr("ja", "a", "J"), tr("jb", "b", "J"), tr("tj", "J", "again"),
                     tr("back", "again", "S", **cond("n < 3")),
                     tr("out", "again", "end", kind=ConditionKind.OTHERWISE)))
    reports = check_process(proc)
    assert reports[0].complete and kinds(proc) == []


# ------------------------------------------------------------------ splits as the engine reads them

def test_conditional_flows_without_a_split_are_inclusive():
    # both conditions may hold (BPMN conditional flows): the AND join can fire; when one
    # holds alone, a token waits there for ever
    proc = process(activities=(
        start(), act("S", 11), act("a", 12), act("b", 13),
        route("J", 14, join=GatewayType.AND), end(line=15)),
        transitions=(tr("t0", "start", "S"), tr("sa", "S", "a", **cond("x > 1")),
                     tr("sb", "S", "b", **cond("y > 1")), tr("ja", "a", "J"),
                     tr("jb", "b", "J"), tr("te", "J", "end")))
    found = kinds(proc)
    assert "deadlock" in found and "and-join-never-fires" not in found and "dead" not in found


def test_complementary_conditions_are_never_taken_together():
    for first, second in (("x == 1", "!(x == 1)"), ('x == "yes"', 'x == "no"'),
                          ("n < 3", "n >= 3"), ('s.compareTo("a") == 0', "s != 'a'")):
        proc = process(activities=(
            start(), act("S", 11), act("a", 12), act("b", 13),
            route("J", 14, join=GatewayType.AND), end(line=15)),
            transitions=(tr("t0", "start", "S"), tr("sa", "S", "a", **cond(first)),
                         tr("sb", "S", "b", **cond(second)), tr("ja", "a", "J"),
                         tr("jb", "b", "J"), tr("te", "J", "end")))
        assert "and-join-never-fires" in kinds(proc), (first, second)


def test_condition_subsets():
    x, not_x, y = (parse_condition(t) for t in ("x", "!x", "y"))
    assert condition_subsets([x, not_x]) == [(0,), (1,)]
    assert condition_subsets([x, y]) == [(), (0,), (1,), (0, 1)]
    many = [parse_condition(f"v{n} > 0") for n in range(12)]
    assert condition_subsets(many) is None       # too many atoms: the caller enumerates


def test_a_path_ends_where_its_only_condition_fails():
    # no split, one conditional transition: the engine ends that path when it fails, so the
    # AND join after it may wait for ever
    proc = process(activities=(
        start(), route("F", 11, split=GatewayType.AND), act("p", 12), act("q", 13),
        route("J", 14, join=GatewayType.AND), end(line=15)),
        transitions=(tr("t0", "start", "F"), tr("fp", "F", "p"), tr("fq", "F", "q"),
                     tr("pj", "p", "J", **cond("ok")), tr("qj", "q", "J"),
                     tr("te", "J", "end")))
    # the path that ended counts as an end reached: the token left at J is an improper
    # completion (the engine reports the join waiting for a branch that can no longer come)
    assert "improper-completion" in kinds(proc)


def test_several_unconditional_flows_out_of_a_plain_route_run_in_parallel():
    # a Route with no split and two unconditional transitions: the engine runs both
    proc = process(activities=(
        start(), route("R", 11), act("a", 12), act("b", 13),
        route("J", 14, join=GatewayType.AND), end(line=15)),
        transitions=(tr("t0", "start", "R"), tr("ra", "R", "a"), tr("rb", "R", "b"),
                     tr("ja", "a", "J"), tr("jb", "b", "J"), tr("te", "J", "end")))
    assert kinds(proc) == []


# ------------------------------------------------------------------ multi-instance loops

def mi_into_join(flow: MIFlow, count: str | int):
    """start -> S(AND) -> M (multi-instance) and C -> J(AND) -> end."""
    loop = Loop(kind=LoopKind.MULTI_INSTANCE, flow=flow, parallel=True,
                condition=Literal(count) if isinstance(count, int) else parse_condition(count),
                condition_text=str(count))
    return process(activities=(
        start(), route("S", 11, split=GatewayType.AND), act("M", 12, loop=loop), act("C", 13),
        route("J", 14, join=GatewayType.AND), end(line=15)),
        transitions=(tr("t0", "start", "S"), tr("sm", "S", "M"), tr("sc", "S", "C"),
                     tr("mj", "M", "J"), tr("cj", "C", "J"), tr("te", "J", "end")))


def test_multi_instance_all_and_one_pass_one_token():
    assert kinds(mi_into_join(MIFlow.ALL, "n")) == []
    assert kinds(mi_into_join(MIFlow.ONE, "n")) == []


def test_multi_instance_none_passes_a_token_per_instance():
    # several instances: several tokens reach the AND join, which consumes one of them
    assert "improper-completion" in kinds(mi_into_join(MIFlow.NONE, "n"))
    assert "improper-completion" in kinds(mi_into_join(MIFlow.NONE, 3))
    assert kinds(mi_into_join(MIFlow.NONE, 1)) == []


def test_multi_instance_complex_may_pass_nothing():
    # its condition may never hold: nothing moves on, and C's token waits at J
    assert "improper-completion" in kinds(mi_into_join(MIFlow.COMPLEX, "n"))


# ------------------------------------------------------------------ the compiler's reading

def _corpus_and_specs() -> list[Path]:
    return sorted(CORPUS.glob("*.xpdl")) + sorted((ROOT / "specs").glob("*.xpdl"))


@pytest.mark.parametrize("path", _corpus_and_specs(), ids=lambda p: p.name)
def test_the_net_reads_every_split_and_join_as_the_compiler_does(path):
    from opspec.engine.compiled import (
        J_AND,
        J_COMPLEX,
        J_OR,
        J_XOR,
        S_AND,
        S_OR,
        S_XOR,
        compile_package,
    )
    from opspec.errors import OpspecError
    from opspec.xpdl.loader import load_package

    result = load_package(path)
    if result.package is None:
        pytest.skip("not loadable")
    try:
        compiled = compile_package(result.package)
    except OpspecError:
        pytest.skip("the engine refuses it")
    joins = {J_XOR: GatewayType.XOR, J_AND: GatewayType.AND, J_OR: GatewayType.OR,
             J_COMPLEX: GatewayType.COMPLEX}
    splits = {S_XOR: GatewayType.XOR, S_AND: GatewayType.AND, S_OR: GatewayType.OR}
    checked = 0
    for process_model in result.package.processes:
        proc = compiled.processes[process_model.id]
        graphs = {None: proc.graph}
        stack = [proc.graph]
        while stack:
            graph = stack.pop()
            for ca in graph.activities:
                if ca.block is not None:
                    graphs[ca.block.name.rsplit("/", 1)[-1]] = ca.block
                    stack.append(ca.block)
        for activity_set, flow in levels(process_model):
            cgraph = graphs.get(activity_set.id if activity_set is not None else None)
            if cgraph is None:
                continue
            net = TokenNet(flow, flow.starts())
            for ca in cgraph.activities:
                if ca.id not in flow.by_id:
                    continue
                assert net.join[ca.id] is joins[ca.join], (process_model.id, ca.id)
                split, may_end = net.split_rule[ca.id]
                if len(ca.out) > 1 or not ca.out:
                    assert split is splits[ca.split], (process_model.id, ca.id)
                assert may_end == ca.path_may_end, (process_model.id, ca.id)
                checked += 1
    assert checked or not any(p.activities for p in result.package.processes)


# ------------------------------------------------------------------ against the engine

NS = "http://www.wfmc.org/2008/XPDL2.1"


def _activity(aid: str, *, join: str | None = None, split: str | None = None,
              route: str | None = None, seconds: float | None = None, extra: str = "") -> str:
    body = f"<Route {route}/>" if route is not None else "<Implementation><No/></Implementation>"
    restriction = ""
    if join or split:
        restriction = ("<TransitionRestrictions><TransitionRestriction>"
                       + (f'<Join Type="{join}"/>' if join else "")
                       + (f'<Split Type="{split}"/>' if split else "")
                       + "</TransitionRestriction></TransitionRestrictions>")
    duration = ('<ExtendedAttributes><ExtendedAttribute Name="opspec:Duration" '
                f'Value="ConstantParameter({seconds})"/></ExtendedAttributes>'
                if seconds is not None else "")
    return f'<Activity Id="{aid}">{body}{extra}{restriction}{duration}</Activity>'


def _transition(source: str, target: str, condition: str | None = None) -> str:
    cond = ""
    if condition == "otherwise":
        cond = '<Condition Type="OTHERWISE"/>'
    elif condition is not None:
        cond = f'<Condition Type="CONDITION"><Expression>{condition}</Expression></Condition>'
    return f'<Transition Id="{source}_{target}" From="{source}" To="{target}">{cond}</Transition>'


def _spec(tmp_path: Path, split: str, condition: str, *, loop: bool = False) -> Path:
    acts = [_activity("A", split=split, join="Exclusive" if loop else None),
            _activity("B", seconds=1), _activity("C", seconds=2), _activity("D", seconds=3),
            _activity("J", join="Complex", route=f'GatewayType="Complex" '
                      f'IncomingCondition="{condition}"'),
            _activity("E", extra='<Assignments><Assignment><Target>n</Target>'
                      '<Expression>n + 1</Expression></Assignment></Assignments>')]
    trans = [_transition("A", "B", "n &gt; -1" if split == "Exclusive" else None),
             _transition("A", "C", "n &gt; -2" if split == "Exclusive" else None),
             _transition("A", "D"), _transition("B", "J"), _transition("C", "J"),
             _transition("D", "J"), _transition("J", "E")]
    if loop:
        acts += [_activity("S"), _activity("L", route='GatewayType="Exclusive"',
                                           split="Exclusive"), _activity("Z")]
        trans += [_transition("S", "A"), _transition("E", "L"),
                  _transition("L", "A", "n &lt; 2"), _transition("L", "Z", "otherwise")]
    fields = ('<DataFields><DataField Id="n"><DataType><BasicType Type="INTEGER"/></DataType>'
              "<InitialValue>0</InitialValue></DataField></DataFields>")
    path = tmp_path / "routing.xpdl"
    path.write_text(
        f'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="{NS}" Id="routing">'
        "<PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor>"
        "<Created>2026</Created></PackageHeader>"
        f'<WorkflowProcesses><WorkflowProcess Id="p"><ProcessHeader/>{fields}'
        f"<Activities>{''.join(acts)}</Activities>"
        f"<Transitions>{''.join(trans)}</Transitions>"
        "</WorkflowProcess></WorkflowProcesses></Package>", encoding="utf-8")
    return path


@pytest.mark.parametrize(("split", "condition", "loop", "engine_deadlocks"), [
    ("Parallel", "activationCount &gt;= 1", False, False),    # discriminator
    ("Parallel", "activationCount &gt;= 2", False, False),    # 2-out-of-3
    ("Parallel", "activationCount &gt;= 1", True, False),     # discriminator in a loop
    ("Exclusive", "activationCount &gt;= 1", False, False),   # one branch is enough
    ("Exclusive", "activationCount &gt;= 2", False, True),    # one branch never is
])
def test_check_and_engine_agree_on_complex_joins(tmp_path, split, condition, loop,
                                                 engine_deadlocks):
    from opspec.cli import main
    from opspec.engine.simulation import Simulation
    from opspec.xpdl.loader import load_spec

    path = _spec(tmp_path, split, condition, loop=loop)
    result = Simulation(load_spec(path), keep_trace=True).run(until=1000.0)
    assert bool(result.summary["deadlocks"]) is engine_deadlocks
    # the check plays every data outcome, a superset of this one run: where the engine got
    # stuck the check must say so; where it did not, the check finds it sound
    assert main(["check", str(path)]) == (1 if engine_deadlocks else 0)
