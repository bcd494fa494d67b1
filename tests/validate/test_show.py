"""``opspec show``: the text description and the Graphviz output (which must parse as DOT)."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest
from validate_builders import act, end, package, process, start, tr

from opspec.cli import main
from opspec.model import (
    ActivitySet,
    BlockActivity,
    ConditionKind,
    GatewayType,
    Route,
    Split,
    SubFlow,
)
from opspec.xpdl.dot import package_to_dot, quote

pydot = pytest.importorskip("pydot")
# pydot's parser still calls pyparsing's camelCase names
pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"
DATA = Path(__file__).parent / "data"
CORPUS = Path(__file__).resolve().parents[3] / "shared" / "corpus" / "xpdl"


def _graphs(text: str) -> list[object]:
    graphs = pydot.graph_from_dot_data(text)
    assert graphs, "not valid DOT"
    return list(graphs)


def _unquote(value: str) -> str:
    assert value.startswith('"') and value.endswith('"')
    return value[1:-1]


def test_text_lists_participants_lanes_processes_activities_and_transitions(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(DISPENSER)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("Package 'medication_dispenser' 'Smart medication dispenser and its "
                          "user'  (XPDL 2.1, ")
    assert re.search(r"^  user +human +User$", out, re.MULTILINE)
    assert re.search(r"^  clock +system +Clock$", out, re.MULTILINE)
    assert "    lane user_lane User [user]" in out
    assert "Process 'notify_workflow' 'Notify workflow'" in out
    assert "  directives: priority 2, lane device" in out
    assert "deadline PT300S -> no_report (SYNCHR)" in out
    assert re.search(r"^    hear_alarm +.Hear the alarm., .*by user \(human\), manual", out,
                     re.MULTILINE)
    assert re.search(r"R -> sound_alarm  \[if alarms < 3\]$", out, re.MULTILINE)
    assert "[exception no_report]" in out and "[otherwise]" in out


def test_text_of_one_process(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(DISPENSER), "--process", "user_workflow"]) == 0
    out = capsys.readouterr().out
    assert "Process 'user_workflow'" in out
    assert "Process 'notify_workflow'" not in out


def test_an_unknown_process_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(DISPENSER), "--process", "nope"]) == 2
    assert "has no process 'nope' (processes: 'timer_workflow'" in capsys.readouterr().err


def test_show_of_a_missing_or_broken_file(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(DATA / "missing.xpdl")]) == 2
    assert "cannot read the file" in capsys.readouterr().err
    assert main(["show", str(DATA / "not_well_formed.xpdl")]) == 1
    assert "not well-formed XML" in capsys.readouterr().err


def test_show_of_a_spec_with_errors_still_shows_it_lists_them_and_exits_1(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(DATA / "bad_condition.xpdl")]) == 1
    captured = capsys.readouterr()
    assert "Process 'Pump'" in captured.out
    assert f"{DATA / 'bad_condition.xpdl'}:24: error: transition condition 'n >>> ('" in (
        captured.err)
    assert "has 1 error (listed above" in captured.err


def test_show_lists_the_structural_errors_validate_finds(
        capsys: pytest.CaptureFixture[str]) -> None:
    spec = CORPUS / "g360__Subprocess4_with_exception.xpdl"
    if not spec.is_file():
        pytest.skip("corpus not available")
    assert main(["validate", str(spec)]) == 1
    expected = [line for line in capsys.readouterr().out.splitlines() if ": error: " in line]
    assert main(["show", str(spec)]) == 1
    listed = [line for line in capsys.readouterr().err.splitlines() if ": error: " in line]
    assert listed == expected and len(listed) == 6


def test_dot_has_one_digraph_per_process_that_parses(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(DISPENSER), "--format", "dot"]) == 0
    graphs = _graphs(capsys.readouterr().out)
    names = [_unquote(g.get_name()) for g in graphs]
    assert names == ["timer_workflow", "schedule_workflow", "notify_workflow", "user_workflow"]


def _all_nodes(graph: object) -> dict[str, object]:
    nodes = {_unquote(n.get_name()): n for n in graph.get_nodes() if n.get_name() not in
             ("node", "edge", "graph")}
    for sub in graph.get_subgraphs():
        nodes.update(_all_nodes(sub))
    return nodes


def _all_edges(graph: object) -> list[object]:
    edges = list(graph.get_edges())
    for sub in graph.get_subgraphs():
        edges.extend(_all_edges(sub))
    return edges


def test_dot_nodes_edges_shapes_and_labels_of_the_dispenser() -> None:
    from opspec.xpdl.loader import load_package

    result = load_package(DISPENSER)
    assert result.package is not None
    (graph,) = _graphs(package_to_dot(result.package, process="notify_workflow"))
    nodes = _all_nodes(graph)
    assert {"notify_start", "schedule", "sound_alarm", "wait_report", "R", "end_missed"} <= set(
        nodes)
    assert nodes["R"].get_shape() == "diamond"
    assert _unquote(nodes["R"].get_label()).startswith("XOR")
    assert nodes["notify_start"].get_shape() == "circle"
    assert nodes["wait_report"].get_shape() == "doublecircle"
    assert nodes["schedule"].get("peripheries") == "2"
    edges = {(_unquote(e.get_source()), _unquote(e.get_destination())): e
             for e in _all_edges(graph)}
    assert _unquote(edges[("R", "sound_alarm")].get_label()) == "alarms < 3"
    exception = edges[("wait_report", "R")]
    assert exception.get_color() == "red" and exception.get_style() == "dashed"
    clusters = [_unquote(s.get_name()) for s in graph.get_subgraphs()]
    assert "cluster_lane:device_lane" in clusters


def test_dot_highlights_manual_activities() -> None:
    from opspec.xpdl.loader import load_package

    result = load_package(DISPENSER)
    assert result.package is not None
    (graph,) = _graphs(package_to_dot(result.package, process="user_workflow"))
    nodes = _all_nodes(graph)
    assert "filled" in nodes["hear_alarm"].get_style()
    assert "filled" not in (nodes["user_done"].get_style() or "")


def test_dot_escapes_quotes_backslashes_and_newlines() -> None:
    nasty = 'say "hi" \\ then\nleave'
    split = act("work", 11, name=nasty, split=Split(type=GatewayType.XOR))
    model = package(process('P"1', activities=(start(), split, end(), end("e2", 13)),
                            transitions=(tr("t1", "start", "work"),
                                         tr("t2", "work", "end", kind=ConditionKind.CONDITION,
                                            text='x == "a\\b"'),
                                         tr("t3", "work", "e2", kind=ConditionKind.OTHERWISE))))
    text = package_to_dot(model)
    (graph,) = _graphs(text)
    assert graph.get_name() == quote('P"1')
    node = _all_nodes(graph)["work"]
    assert node.get_label() == '"say \\"hi\\" \\\\ then leave"'      # labels are one line
    labels = [e.get_label() for e in _all_edges(graph)]
    assert '"x == \\"a\\\\b\\""' in labels


def test_dot_draws_activity_sets_as_clusters_with_the_block_pointing_in() -> None:
    aset = ActivitySet(id="S", activities=(start("in", 50), act("inner", 51), end("out", 52)),
                       transitions=(tr("s1", "in", "inner"), tr("s2", "inner", "out")))
    block = act("block", 12, body=BlockActivity(activity_set="S"))
    call = act("call", 13, body=SubFlow(process="Other"))
    gate = act("gate", 14, body=Route(gateway=GatewayType.AND))
    model = package(process(activities=(start(), block, call, gate, end()),
                            transitions=(tr("t1", "start", "block"), tr("t2", "block", "call"),
                                         tr("t3", "call", "gate"), tr("t4", "gate", "end")),
                            activity_sets=(aset,)),
                    process("Other"))
    graphs = _graphs(package_to_dot(model))
    assert len(graphs) == 2
    graph = graphs[0]
    clusters = {_unquote(s.get_name()): s for s in graph.get_subgraphs()}
    assert "cluster_set_S" in clusters
    inner = _all_nodes(clusters["cluster_set_S"])
    assert {"S::in", "S::inner", "S::out"} <= set(inner)
    edges = {(_unquote(e.get_source()), _unquote(e.get_destination())): e
             for e in _all_edges(graph)}
    assert edges[("block", "S::in")].get_style() == "dashed"
    nodes = _all_nodes(graph)
    assert _unquote(nodes["gate"].get_label()) == "AND"
    assert nodes["block"].get_shape() == "box3d"


def test_quote_escapes_every_character_dot_treats_specially() -> None:
    assert quote('a"b\\c\nd\r\ne') == '"a\\"b\\\\c\\nd\\ne"'
    tail, head = quote('a"b'), quote("c\\")
    (graph,) = _graphs(f"digraph g {{ {tail} -> {head}; }}")
    assert [(e.get_source(), e.get_destination()) for e in graph.get_edges()] == [(tail, head)]


def test_dot_of_one_missing_process_raises_key_error() -> None:
    with pytest.raises(KeyError):
        package_to_dot(package(), process="nope")



def test_timer_start_triggers_show_clock_times_and_period(capsys):
    assert main(["show", str(DISPENSER)]) == 0
    assert "starts on timer at 08:00, 12:00, 18:00, 22:00 every 1 day" in capsys.readouterr().out


def _compile(spec: Path, script: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``opspec compile spec -o script``, its output discarded."""
    assert main(["compile", str(spec), "-o", str(script)]) == 0
    capsys.readouterr()


def test_show_reads_a_compiled_script_like_its_source(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = tmp_path / "dispenser.wfs"
    _compile(DISPENSER, script, capsys)
    assert main(["show", str(DISPENSER)]) == 0
    from_source = capsys.readouterr().out
    assert main(["show", str(script)]) == 0
    assert capsys.readouterr().out == from_source


def test_show_of_an_edited_script_says_its_errors_as_check_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A script is compiled from a spec without errors, but may be edited since: show checks
    it as validate checks a spec (it showed a transition to nowhere with exit status 0;
    only run refused it)."""
    import json

    script = tmp_path / "dispenser.wfs"
    _compile(DISPENSER, script, capsys)
    doc = json.loads(script.read_text(encoding="utf-8"))
    doc["package"]["processes"][0]["transitions"][0]["target"] = "nowhere"
    edited = tmp_path / "edited.wfs"
    edited.write_text(json.dumps(doc), encoding="utf-8")
    assert main(["show", str(edited)]) == 1
    shown = capsys.readouterr()
    assert "timer_workflow" in shown.out                   # still shown
    assert ":93: error: Transition 't_tick' points to activity 'nowhere'" in shown.err
    assert shown.err.splitlines()[-1] == (
        f"opspec show: {edited} has 1 error (listed above, as 'opspec check {edited}' counts "
        "them; fix the script or compile its spec again); it cannot run")
    assert main(["show", str(script)]) == 0                # as compiled: nothing to say
    assert capsys.readouterr().err == ""


def test_validate_of_a_compiled_script_says_it_takes_xpdl(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = tmp_path / "sumo.wfs"
    _compile(ROOT / "specs" / "toy_sumo.xpdl", script, capsys)
    assert main(["validate", str(script)]) == 1
    out = capsys.readouterr().out
    assert f"{script}:1: error: this is a compiled workflow script (.wfs), not an XPDL" in out
    assert "Start tag expected" not in out


def test_show_of_a_broken_script_is_one_located_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = tmp_path / "cut.wfs"
    script.write_text('{"format": "opspec-wfs", "version": 1, "pack')
    assert main(["show", str(script)]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"{script}:1: error: ") and "\n" not in err


@pytest.mark.parametrize("name", ["missing.xpdl", "missing.bpmn", "folder"])
def test_show_of_a_path_that_is_no_file_does_not_call_it_xpdl(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    # It said "give the path of an XPDL file", also of a BPMN spec.
    path = tmp_path / name
    if name == "folder":
        path.mkdir()
    assert main(["show", str(path)]) == 2
    err = capsys.readouterr().err
    why = "it is a folder" if name == "folder" else "it does not exist"
    assert err == (f"{path}: error: cannot read the file: {why} (give the path of an XPDL or "
                   "BPMN spec, or of a compiled .wfs script; specs are not read from folders, "
                   "pipes or devices)\n")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes")
def test_validate_of_a_pipe_does_not_call_a_spec_xpdl_only(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # validate reads through read_bytes.read_file, whose hint said "an XPDL file"
    pipe = tmp_path / "spec.bpmn"
    os.mkfifo(pipe)
    assert main(["validate", str(pipe)]) != 0
    err = capsys.readouterr()
    text = err.out + err.err
    assert "give the path of a spec file (XPDL or BPMN)" in text
