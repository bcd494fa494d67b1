"""`opspec check` within its budget: memory bounded by --max-states (the explored-state store
never grows past it, a state costs memory for its tokens only), a big chain checked without
anything quadratic, and running out of the budget (states or memory) reported as an
inconclusive verdict with exit status 1, never as an internal error. No timings here: speed is
measured by benchmarks/parse_compile.py."""

from __future__ import annotations

import json
import sys
import tracemalloc
from pathlib import Path

from opspec.cli import main
from opspec.model import GatewayType, Route
from opspec.model.activities import Join, Split
from opspec.model.graph import FlowGraph
from opspec.model.soundness import check_level, check_process
from opspec.model.soundness_net import TokenNet

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "validate"))
from validate_builders import act, end, process, start, tr


def chain_xpdl(n: int) -> str:
    """One process: a0 -> a1 -> ... -> a(n-1)."""
    return ("<?xml version='1.0' encoding='UTF-8'?>\n"
            '<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="chain" Name="chain">'
            "<PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor>"
            "<Created>2026-01-01</Created></PackageHeader><WorkflowProcesses>"
            '<WorkflowProcess Id="chain"><ProcessHeader/><Activities>\n'
            + "".join(f'<Activity Id="a{i}"/>\n' for i in range(n))
            + "</Activities><Transitions>\n"
            + "".join(f'<Transition Id="t{i}" From="a{i}" To="a{i + 1}"/>\n'
                      for i in range(n - 1))
            + "</Transitions></WorkflowProcess></WorkflowProcesses></Package>\n")


def wide(branches: int):
    """start -> S(AND) -> w0..wn -> J(AND) -> end: 2**n markings."""
    return process(activities=(
        start(), act("S", 11, body=Route(gateway=GatewayType.AND),
                     split=Split(type=GatewayType.AND)),
        *(act(f"w{n}", 20 + n) for n in range(branches)),
        act("J", 90, body=Route(gateway=GatewayType.AND), join=Join(type=GatewayType.AND)),
        end(line=91)),
        transitions=(tr("t0", "start", "S"), *(tr(f"a{n}", "S", f"w{n}") for n in range(branches)),
                     *(tr(f"b{n}", f"w{n}", "J") for n in range(branches)), tr("te", "J", "end")))


def test_the_explored_states_never_exceed_max_states():
    for limit in (1, 10, 500):
        report = check_process(wide(14), max_states=limit)[0]
        assert report.states <= limit
        assert not report.complete and report.stopped == "states" and not report.sound


def test_a_marking_holds_its_marked_places_only():
    proc = wide(40)
    net = TokenNet(FlowGraph.of(proc.activities, proc.transitions), ("start",))
    assert net.initial() == ((0, 1),)
    (_, after, _), = net.firings(net.initial())
    (_, split, _), = net.firings(after)
    assert len(split) == 40                  # one entry per token, not one per place
    assert len(net.places) > 80


def test_a_long_chain_is_checked_within_a_small_memory(tmp_path, capsys):
    # 2,000 activities: before, every state was a tuple over every place and every activity
    # kept the set of all it could reach (836 MB at 5,000; it grows with the square, so about
    # 130 MB at 2,000); now a state is one (place, 1) pair (2 MiB at 2,000, 6 MiB at 5,000)
    n = 2000
    proc = process(activities=tuple(act(f"a{i}", 10 + i) for i in range(n)),
                   transitions=tuple(tr(f"t{i}", f"a{i}", f"a{i + 1}") for i in range(n - 1)))
    tracemalloc.start()
    try:
        report = check_process(proc)[0]
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert report.sound and report.states == n + 1
    assert peak < 30 * 2**20, f"{peak / 2**20:.0f} MiB"
    spec = tmp_path / "chain.xpdl"
    spec.write_text(chain_xpdl(n), encoding="utf-8")
    assert main(["check", str(spec)]) == 0
    assert f"chain: sound ({n + 1} states)" in capsys.readouterr().out


def test_running_out_of_memory_is_an_inconclusive_level(monkeypatch):
    def exhausted(*_args, **_kwargs):
        raise MemoryError
    monkeypatch.setattr(TokenNet, "firings", exhausted)
    proc = wide(3)
    report = check_level("Pump", FlowGraph.of(proc.activities, proc.transitions), ("start",))
    assert not report.complete and report.stopped == "memory" and not report.sound


def test_cli_out_of_memory_is_inconclusive_and_exits_1(monkeypatch, tmp_path, capsys):
    def exhausted(*_args, **_kwargs):
        raise MemoryError
    monkeypatch.setattr(TokenNet, "firings", exhausted)
    spec = tmp_path / "chain.xpdl"
    spec.write_text(chain_xpdl(20), encoding="utf-8")
    assert main(["check", str(spec)]) == 1
    out = capsys.readouterr().out
    assert "chain: out of memory after 0 states: inconclusive" in out
    assert "internal error" not in out and "bug" not in out
    assert main(["check", "--json", str(spec)]) == 1
    doc = json.loads(capsys.readouterr().out)
    assert doc["sound"] is False and doc["inconclusive"] is True
    assert doc["processes"][0]["stopped"] == "memory"


def test_cli_memory_error_outside_the_exploration_is_inconclusive_too(monkeypatch, tmp_path,
                                                                       capsys):
    from opspec.model import soundness

    def exhausted(*_args, **_kwargs):
        raise MemoryError
    monkeypatch.setattr(soundness, "conformance_violations", exhausted)
    spec = tmp_path / "chain.xpdl"
    spec.write_text(chain_xpdl(5), encoding="utf-8")
    assert main(["check", str(spec)]) == 1
    assert "inconclusive" in capsys.readouterr().out
