"""A BPMN pool is not a device: the walkthrough of ``medication_dispenser.bpmn`` listed
``timer_pool``, ``schedule_pool`` and ``dispenser_pool`` as device rows beside the clock, the
schedule, the alarm and the drawer that perform their work (the pools only "performed" the
events and gateways drawn in them), seven rows where the XPDL version of the same spec has
four. A lane holding the resident's work (``kitchen_lanes.bpmn``) was a device row too. A
pool or lane that is a device row is called by its name in the diagram, not its id."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.engine.compiled import compile_package
from opspec.tui.app import WalkthroughApp
from opspec.tui.devices import DeviceBoard
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]
BPMN = ROOT / "specs" / "medication_dispenser.bpmn"
KITCHEN = Path(__file__).parent / "data" / "kitchen_lanes.bpmn"


def test_the_bpmn_dispenser_lists_the_devices_of_its_xpdl_twin(compiled):
    bpmn = DeviceBoard(compile_package(open_spec(BPMN))).rows()
    assert [r.id for r in bpmn] == [r.id for r in DeviceBoard(compiled).rows()] == [
        "clock", "sched", "alarm", "dispenser"]


def test_a_lane_of_the_residents_work_is_no_device_but_a_working_lane_is():
    rows = DeviceBoard(compile_package(open_spec(KITCHEN))).rows()
    assert [(r.id, r.name) for r in rows] == [("guard_lane", "Stove guard appliance")]


@pytest.mark.asyncio
async def test_a_lane_s_row_is_called_by_the_name_the_diagram_shows():
    """It read "guard_lane: …", an id no BPMN modeller shows; a participant of an XPDL spec
    (or a BPMN resource) keeps its id, as before."""
    session = WalkSession(compile_package(open_spec(KITCHEN)))
    session.paused = True
    app = WalkthroughApp(session, title="Kitchen watch")
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        panel = str(app.query_one("#device").render())
        assert " *  Stove guard appliance: " in panel and "guard_lane" not in panel
        await pilot.press("q")


def test_a_pool_that_is_all_there_is_keeps_its_row(tmp_path):
    """A pool whose workflow nobody else performs in is what the diagram shows: kept."""
    pool = tmp_path / "beeper.bpmn"
    pool.write_text("""<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d"
                  targetNamespace="http://example.org/beeper">
  <bpmn:collaboration id="c"><bpmn:participant id="beeper_pool" name="Beeper"
    processRef="beep"/></bpmn:collaboration>
  <bpmn:process id="beep" isExecutable="true">
    <bpmn:startEvent id="start"/><bpmn:endEvent id="done"/>
    <bpmn:sequenceFlow id="f" sourceRef="start" targetRef="done"/>
  </bpmn:process>
</bpmn:definitions>
""", encoding="utf-8")
    rows = DeviceBoard(compile_package(open_spec(pool))).rows()
    assert [(r.id, r.name) for r in rows] == [("beeper_pool", "Beeper")]


@pytest.mark.asyncio
async def test_the_device_panel_shows_no_pool_and_the_alarm_rings():
    session = WalkSession(compile_package(open_spec(BPMN)))
    session.paused = True
    app = WalkthroughApp(session, title="Smart medication dispenser and its user")
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.press("u")
        for _ in range(200):
            if session.offers:
                break
            await pilot.pause(0.02)
        await pilot.pause()
        panel = str(app.query_one("#device").render())
        assert "_pool" not in panel
        assert "(!) alarm: ((( RINGING ))) since 08:00" in panel
        await pilot.press("q")
