"""``opspec show --format svg|html``: the whole package in one picture - one cluster per
process (with its lanes inside), one dashed edge per message with its name - laid out by
Graphviz's dot; without dot, one line with the install hint and exit status 2."""

from __future__ import annotations

import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.commands.show import _validated
from opspec.xpdl.picture import messages, package_picture_dot

pydot = pytest.importorskip("pydot")
pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"
SVG = "{http://www.w3.org/2000/svg}"
needs_dot = pytest.mark.skipif(shutil.which("dot") is None,
                               reason="Graphviz's dot is not installed (scripts/system-deps.sh)")


@pytest.fixture(scope="module")
def dispenser():  # type: ignore[no-untyped-def]
    return _validated(str(DISPENSER)).package


def test_the_dispensers_messages_go_from_sender_to_receiver(dispenser) -> None:  # type: ignore[no-untyped-def]
    found = {(m.name, m.sender, m.receiver) for m in messages(dispenser)}
    assert found == {
        ("trg_2", '"notify_workflow::sound_alarm"', '"user_workflow::alarm_heard"'),
        ("trg_1", '"user_workflow::press_report"', '"notify_workflow::wait_report"'),
    }


def test_the_dot_text_parses_with_a_cluster_per_process(dispenser) -> None:  # type: ignore[no-untyped-def]
    (graph,) = pydot.graph_from_dot_data(package_picture_dot(dispenser))
    names = [s.get_name().strip('"') for s in graph.get_subgraphs()]
    assert names == [f"cluster_process_{p.id}" for p in dispenser.processes]


def _svg(capsys: pytest.CaptureFixture[str], *args: str) -> ET.Element:
    assert main(["show", str(DISPENSER), "--format", "svg", *args]) == 0
    return ET.fromstring(capsys.readouterr().out)


def _titles(root: ET.Element, css: str) -> list[ET.Element]:
    return [g for g in root.iter(f"{SVG}g") if g.get("class") == css]


@needs_dot
def test_the_svg_has_one_cluster_per_process_with_its_lanes_inside(
        capsys: pytest.CaptureFixture[str], dispenser) -> None:  # type: ignore[no-untyped-def]
    root = _svg(capsys)
    clusters = [g.findtext(f"{SVG}title") for g in _titles(root, "cluster")]
    processes = [c for c in clusters if c and c.startswith("cluster_process_")]
    assert processes == [f"cluster_process_{p.id}" for p in dispenser.processes]
    lanes = [c for c in clusters if c and "lane:" in c]
    assert "cluster_user_workflow::lane:user_lane" in lanes
    assert "cluster_notify_workflow::lane:device_lane" in lanes
    text = " ".join(t.text or "" for t in root.iter(f"{SVG}text"))
    assert "Notify workflow (notify_workflow)" in text and "Press \"report\"" in text


@needs_dot
def test_the_svg_has_an_edge_per_message_with_its_name(capsys: pytest.CaptureFixture[str]
                                                       ) -> None:
    root = _svg(capsys)
    edges = {g.findtext(f"{SVG}title"): " ".join(t.text or "" for t in g.iter(f"{SVG}text"))
             for g in _titles(root, "edge")}
    assert edges["notify_workflow::sound_alarm->user_workflow::alarm_heard"] == "trg_2"
    assert edges["user_workflow::press_report->notify_workflow::wait_report"] == "trg_1"
    # and the subflows: the timer starts notify_workflow, which calls schedule_workflow
    assert edges["timer_workflow::start_notify->notify_workflow::notify_start"] == "starts"
    assert edges["notify_workflow::schedule->schedule_workflow::lookup"] == "calls"


@needs_dot
def test_one_process_only(capsys: pytest.CaptureFixture[str]) -> None:
    root = _svg(capsys, "--process", "user_workflow")
    clusters = [g.findtext(f"{SVG}title") for g in _titles(root, "cluster")]
    assert [c for c in clusters if c and c.startswith("cluster_process_")] == [
        "cluster_process_user_workflow"]


@needs_dot
def test_the_html_page_holds_the_svg_and_a_legend(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(DISPENSER), "--format", "html"]) == 0
    page = capsys.readouterr().out
    assert page.startswith("<!DOCTYPE html>") and "<svg" in page and "How to read it" in page
    assert "<?xml" not in page


def test_without_dot_one_line_with_the_install_hint_and_status_2(
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PATH", "/nonexistent")
    for fmt in ("svg", "html"):
        assert main(["show", str(DISPENSER), "--format", fmt]) == 2
        captured = capsys.readouterr()
        assert captured.out == ""
        assert captured.err.count("\n") == 1
        assert "Graphviz" in captured.err and "apt-get install graphviz" in captured.err
