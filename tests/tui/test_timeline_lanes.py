"""The timelines' lane column, with and without lanes: ``opspec run``'s printed timeline and
the walkthrough's timeline box name each event's lane as the spec does (a BPMN lane by its
``name``, not its id) and keep the columns after it in one place on every line.

BPMN 2.0 (formal/2011-01-03), 10.7 Lanes: "A Lane is a sub-partition within a Process
(often within a Pool) and will extend the entire length of the Process level [...] Lanes are
used to organize and categorize Activities within a Pool"; the lane's ``name`` attribute is
what a diagram shows on the lane. The fixture ``kitchen_lanes.bpmn`` has a lane named longer
than the column ("Stove guard appliance") and a manual lane named "Resident" (the user lane),
with no opspec:Lane directive, so the names come from the diagram alone.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from walkthrough_inputs import ROOT, SPEC

from opspec.cli import main
from opspec.engine.compiled import compile_package
from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

KITCHEN = Path(__file__).parent / "data" / "kitchen_lanes.bpmn"
VACUUM = ROOT / "specs" / "vacuum_cleaner.xpdl"
# a timeline line: the time, the lane column, then process#instance
_LINE = re.compile(r"^\s+d\d+ \d\d:\d\d:\d\d  ")


def timeline(spec: Path, capsys, until: str = "PT5M") -> list[str]:
    main(["run", str(spec), "--timeline", "all", "--seed", "1", "--until", until])
    return [line for line in capsys.readouterr().out.splitlines() if _LINE.match(line)]


def where_columns(lines: list[str]) -> set[int]:
    """Where the process#instance column starts, on every line that has one."""
    found = (re.search(r"\S+#\d+", line[18:]) for line in lines)
    return {m.start() for m in found if m is not None}


@pytest.mark.parametrize(("spec", "until"), [(KITCHEN, "PT5M"), (VACUUM, "PT2M"),
                                             (SPEC, "PT8H10M")],
                         ids=["lanes", "no-lanes", "dispenser"])
def test_run_timeline_columns_line_up(spec, until, capsys):
    lines = timeline(spec, capsys, until)
    assert len(lines) > 10
    assert len(where_columns(lines)) == 1, "\n".join(lines[:20])


def test_run_timeline_names_bpmn_lanes_by_their_names(capsys):
    lines = timeline(KITCHEN, capsys)
    lanes = {line[18:35].rstrip() for line in lines}
    assert lanes == {"", "Stove guard app…", "Resident"}
    assert any("Resident " in line and "confirm offered" in line for line in lines)
    # the long name is cut to the column with an ellipsis, not left to push the columns
    assert any("Stove guard app… kitchen#1" in line for line in lines)
    # the process spans both lanes: its own events are in neither
    started = next(line for line in lines if "kitchen started" in line)
    assert "device" not in started and "Resident" not in started


def test_run_timeline_without_lanes_says_device(capsys):
    lines = timeline(VACUUM, capsys, "PT2M")
    assert all(line[18:].startswith("device ") for line in lines if "#" in line)


def timeline_box(app: WalkthroughApp) -> list[str]:
    return str(app.query_one("#timeline").render()).splitlines()


@pytest.mark.asyncio
async def test_walkthrough_timeline_names_lanes_and_filters_the_user_lane_by_its_work():
    session = WalkSession(compile_package(open_spec(KITCHEN)))
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space")                      # the test drives time with keys
        await pilot.press("u")                          # until the resident is asked
        await pilot.pause()
        assert session.offers and session.offers[0].item.activity == "confirm"
        lines = timeline_box(app)[1:]
        assert lines[0] == "00:01:00  Resident         confirm offered"
        assert "00:01:00  Stove guard app… sound_alert completed" in lines
        # one column for what happened on every line, wherever the lane's name ends
        assert all(line[26] == " " and line[27] != " " for line in lines if line)
        await pilot.press("l")                          # the device: the guard's lane
        shown = timeline_box(app)
        assert shown[0].startswith("showing: device")
        assert any("Stove guard app…" in line for line in shown)
        assert not any("Resident" in line for line in shown)
        await pilot.press("l")                          # the user: the resident's manual work
        shown = timeline_box(app)
        assert shown[0].startswith("showing: user") and len(shown) > 1
        assert all("Resident" in line for line in shown[1:])


@pytest.mark.asyncio
async def test_walkthrough_timeline_without_lanes_keeps_its_columns():
    session = WalkSession(compile_package(open_spec(VACUUM)))
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space")
        await pilot.press("n", "n", "n")
        await pilot.pause()
        lines = [line for line in timeline_box(app)[1:] if line]
        assert lines and all(line[10:18] == "device  " for line in lines)
