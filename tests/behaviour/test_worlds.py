"""The simulated worlds the robot specs run in: geometry, the robot's motion, its sensors,
the sumo's bouts, and how a spec declares and parameterises its world."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from spec_text import compiled, process, task

from opspec.engine.simulation import Simulation
from opspec.errors import ConfigurationError
from opspec.worlds import WORLDS, world_parameters, world_performers
from opspec.worlds.geometry import Box, ray_to_box, ray_to_circle_inside
from opspec.worlds.robot import Robot
from opspec.worlds.room import RoomWorld
from opspec.worlds.sumo import SumoWorld


def rng(seed: int = 0) -> np.random.Generator:
    return np.random.default_rng(seed)


def room(**kw: object) -> RoomWorld:
    params: dict[str, object] = {"obstacles": (), "range_noise": 0.0, "start": (1.0, 2.0, 0.0)}
    params.update(kw)
    return RoomWorld(rng(), **params)  # type: ignore[arg-type]


# ---------------------------------------------------------------------- geometry

@pytest.mark.parametrize(("x", "y", "heading", "inside", "distance"), [
    (1.0, 1.0, 0.0, True, 4.0), (1.0, 1.0, math.pi, True, 1.0),
    (1.0, 1.0, math.pi / 2, True, 3.0), (1.0, 1.0, math.pi / 4, True, math.sqrt(2) * 3),
    (-2.0, 2.0, 0.0, False, 2.0), (-2.0, 2.0, math.pi, False, math.inf),
    (2.0, 2.0, 0.0, False, 0.0),
], ids=["wall-east", "wall-west", "wall-north", "corner-diagonal", "box-ahead", "box-behind",
        "inside-the-box"])
def test_a_ray_meets_the_nearest_face_of_a_box(x: float, y: float, heading: float,
                                               inside: bool, distance: float) -> None:
    box = Box(0.0, 0.0, 5.0, 4.0)
    assert ray_to_box(x, y, heading, box, inside=inside) == pytest.approx(distance)


def test_a_ray_from_inside_a_circle_meets_its_edge() -> None:
    assert ray_to_circle_inside(0.0, 0.0, 1.0, 1.5) == pytest.approx(1.5)
    assert ray_to_circle_inside(0.5, 0.0, 0.0, 1.5) == pytest.approx(1.0)
    assert ray_to_circle_inside(0.5, 0.0, math.pi, 1.5) == pytest.approx(2.0)


@pytest.mark.parametrize(("command", "pose"), [
    ("forward", (0.3, 0.0, 0.0)), ("back", (-0.2, 0.0, 0.0)), ("stop", (0.0, 0.0, 0.0)),
    ("turn_left", (0.0, 0.0, 1.5)), ("turn_right", (0.0, 0.0, -1.5)),
], ids=["forward", "back", "stop", "turn-left-in-place", "turn-right-in-place"])
def test_motor_commands_move_the_robot_as_the_command_table_says(
        command: str, pose: tuple[float, float, float]) -> None:
    assert Robot(0.0, 0.0, 0.0, command).pose_after(1.0) == pytest.approx(pose)


def test_a_robot_driving_and_turning_follows_an_exact_arc(monkeypatch: pytest.MonkeyPatch
                                                          ) -> None:
    from opspec.worlds import robot

    monkeypatch.setitem(robot.COMMANDS, "arc", (1.0, 1.0))     # radius 1 m
    x, y, heading = Robot(0.0, 0.0, 0.0, "arc").pose_after(math.pi / 2)
    assert (x, y, heading) == pytest.approx((1.0, 1.0, math.pi / 2))


# ---------------------------------------------------------------------- the room

def test_driving_into_a_wall_stops_at_the_wall_and_counts_one_collision() -> None:
    world = room()
    facts: list[tuple[str, dict[str, object]]] = []
    world.tracer = lambda kind, data: facts.append((kind, dict(data)))
    world.robot.command = "forward"
    world.advance(30.0)                               # 9 m of driving in a 5 m room
    assert world.robot.x == pytest.approx(5.0 - world.radius, abs=0.3 * 0.05 + 1e-9)
    assert [k for k, _ in facts if k == "world.collision"] == ["world.collision"]
    assert world.op_read_bump({})["bump"] is True
    world.advance(30.1)
    assert world.op_read_bump({})["bump"] is True   # still pressed against the wall
    assert world.collisions == 1


def test_the_bumper_latches_a_contact_until_it_is_read() -> None:
    world = room(start=(4.6, 2.0, 0.0))
    world.robot.command = "forward"
    world.advance(2.0)
    world.op_drive({"motor_cmd": "back"})
    world.advance(3.0)                                # backed away from the wall
    assert world.op_read_bump({})["bump"] is True   # the contact is remembered...
    assert world.op_read_bump({})["bump"] is False  # ...once
    world.op_drive({"motor_cmd": "forward"})
    world.advance(10.0)
    assert world.collisions == 2                      # a new contact is a new collision


def test_the_range_finder_sees_the_nearest_wall_or_obstacle_ahead() -> None:
    assert room().op_read_range({}) == {"distance": pytest.approx(4.0 - 0.15)}
    blocked = room(obstacles=[(2.0, 1.5, 2.5, 2.5)])
    assert blocked.op_read_range({}) == {"distance": pytest.approx(1.0 - 0.15)}
    noisy = [room(range_noise=0.05).op_read_range({})["distance"] for _ in range(3)]
    assert noisy[0] == noisy[1] == noisy[2] != pytest.approx(3.85, abs=1e-6)  # seeded noise


def test_coverage_counts_each_cell_the_robot_passes_over_once() -> None:
    world = room()
    covered: list[object] = []
    world.tracer = lambda kind, data: covered.append(data["cell"]) if (
        kind == "world.covered") else None
    world.robot.command = "forward"
    world.advance(5.0)                                # 1.5 m along y = 2
    cells = {tuple(c) for c in covered}  # type: ignore[arg-type]
    assert len(cells) == len(covered)                 # each cell once
    assert {cx for cx, _ in cells} == set(range(3, 11))
    assert world.coverage == pytest.approx(len(world.covered) / (20 * 16))


def test_turn_random_turns_a_quarter_to_three_quarters_round_and_stops() -> None:
    for seed in range(20):
        world = RoomWorld(rng(seed), obstacles=(), start=(2.5, 2.0, 0.0))
        world.op_drive({"motor_cmd": "turn_random"})
        assert math.pi / 2 <= abs(world.robot.heading) <= math.pi
        assert world.robot.command == "stop"


def test_the_rfid_reader_and_bar_code_scanner_see_the_patient_only_within_range() -> None:
    world = room(tag=(3.0, 2.0), tag_range=0.8)
    assert world.op_read_rfid({}) == {"tag": ""}
    assert world.op_scan_barcode({}) == {"patient_id": ""}
    world.robot.command = "forward"
    world.advance(4.5)                                # x = 2.35: 0.65 m from the tag
    assert world.op_read_rfid({}) == {"tag": "patient-17"}
    assert world.op_scan_barcode({}) == {"patient_id": "patient-17"}


def test_the_battery_drains_linearly_with_simulated_time() -> None:
    world = room(drain_per_s=0.5)
    world.advance(60.0)
    assert world.op_read_battery({}) == {"level": 70.0}


# ---------------------------------------------------------------------- the sumo ring

def bout(command: str, seconds: float = 30.0, **kw: float
         ) -> tuple[dict[str, int], list[str]]:
    world = SumoWorld(rng(3), **kw)
    facts: list[str] = []
    world.tracer = lambda kind, data: facts.append(kind)
    world.robot.heading = 0.0                          # facing the opponent
    world.robot.command = command
    world.advance(seconds)
    return world.results, facts


def test_charging_at_the_opponent_pushes_it_out_of_the_ring() -> None:
    _, facts = bout("charge", bout_limit_s=30.0)
    assert facts[:3] == ["world.collision", "world.bout", "world.bout_won"]


def test_standing_still_gets_the_robot_pushed_out() -> None:
    results, facts = bout("stop", bout_limit_s=30.0)
    assert results["lost"] >= 1 and results["won"] == 0
    assert facts[:3] == ["world.collision", "world.bout", "world.bout_lost"]


def test_a_bout_nobody_wins_is_a_draw_at_the_time_limit() -> None:
    results, _ = bout("stop", seconds=35.0, opponent_speed=0.0, bout_limit_s=10.0)
    assert results == {"won": 0, "lost": 0, "draw": 3}


def test_the_sumo_range_finder_sees_the_opponent_ahead_else_the_ring_edge() -> None:
    world = SumoWorld(rng(0), range_noise=0.0)
    world.robot.heading = 0.0
    assert world.op_read_range({}) == {"distance": pytest.approx(1.5 - 0.3)}
    world.robot.heading = math.pi
    assert world.op_read_range({}) == {"distance": pytest.approx(1.5 - 0.75 - 0.15)}


# ---------------------------------------------------------------------- declaring a world

def spec_with_world(tmp_path: Path, attributes: str) -> object:
    return compiled(tmp_path, [process("look", [task("read_range", "read_range")],
                                       Period="1s")],
                    applications=["read_range"], package_attributes=attributes)


def test_a_spec_without_a_world_has_no_world_performers(tmp_path: Path) -> None:
    assert world_performers(spec_with_world(tmp_path, ""), seed=0, user=0) == {}  # type: ignore[arg-type]


def test_world_parameters_come_from_the_world_file_and_inline_ones_win(tmp_path: Path) -> None:
    (tmp_path / "room.toml").write_text("width = 8.0\nheight = 6.0\nrange_noise = 0.0\n",
                                        encoding="utf-8")
    model = spec_with_world(tmp_path, (
        '<ExtendedAttribute Name="opspec:World" Value="vacuum-room">'
        '<opspec:Parameter Name="height" Value="7"/>'
        '<opspec:Parameter Name="obstacles" Value="[]"/>'
        '<opspec:Parameter Name="start" Value="[1.0, 1.0, 0.0]"/></ExtendedAttribute>'
        '<ExtendedAttribute Name="opspec:WorldFile" Value="room.toml"/>'))
    world = world_performers(model, seed=0, user=0)["world"].world  # type: ignore[arg-type,attr-defined]
    assert (world.room.x1, world.room.y1, world.obstacles) == (8.0, 7.0, [])
    assert world.op_read_range({}) == {"distance": pytest.approx(8.0 - 1.0 - 0.15)}


@pytest.mark.parametrize(("attributes", "message"), [
    ('<ExtendedAttribute Name="opspec:World" Value="moon-base"/>',
     r"unknown world 'moon-base'.*known worlds: sumo-ring, vacuum-room, ward"),
    (('<ExtendedAttribute Name="opspec:World" Value="vacuum-room">'
     '<opspec:Parameter Name="widht" Value="6"/></ExtendedAttribute>'),
     r"situation.xpdl:\d+: world 'vacuum-room' has no parameter 'widht'.*width"),
    (('<ExtendedAttribute Name="opspec:World" Value="vacuum-room">'
     '<opspec:Parameter Name="start" Value="[1.8, 1.8, 0.0]"/></ExtendedAttribute>'),
     r"start \(1.8, 1.8\) puts the robot in a wall or an obstacle"),
    (('<ExtendedAttribute Name="opspec:World" Value="sumo-ring">'
     '<opspec:Parameter Name="ring_radius" Value="0.2"/></ExtendedAttribute>'),
     r"must hold two robots"),
    (('<ExtendedAttribute Name="opspec:World" Value="ward"/>'
     '<ExtendedAttribute Name="opspec:WorldFile" Value="missing.toml"/>'),
     r"cannot read the world file .*missing.toml"),
], ids=["unknown-world", "unknown-parameter", "start-in-an-obstacle", "ring-too-small",
        "missing-world-file"])
def test_world_declaration_mistakes_are_configuration_errors_saying_what_to_fix(
        tmp_path: Path, attributes: str, message: str) -> None:
    model = spec_with_world(tmp_path, attributes)
    with pytest.raises(ConfigurationError, match=message):
        world_performers(model, seed=0, user=0)  # type: ignore[arg-type]


def test_an_unknown_key_in_the_world_file_is_located_at_that_key(tmp_path: Path) -> None:
    (tmp_path / "ring.toml").write_text("ring_radius = 2.0\nopponent = 'fast'\n",
                                        encoding="utf-8")
    model = spec_with_world(tmp_path, '<ExtendedAttribute Name="opspec:World" Value="sumo-ring"/>'
                            '<ExtendedAttribute Name="opspec:WorldFile" Value="ring.toml"/>')
    with pytest.raises(ConfigurationError, match=r"ring.toml:2: opponent: world 'sumo-ring' has "
                                                 r"no parameter 'opponent'"):
        world_performers(model, seed=0, user=0)  # type: ignore[arg-type]


def test_every_registered_world_lists_its_parameters_with_defaults() -> None:
    for name, factory in WORLDS.items():
        params = world_parameters(factory)
        assert "rng" not in params and params, name
    assert world_parameters(WORLDS["ward"])["width"] == 20.0       # the ward's own defaults


def test_the_world_fails_an_activity_whose_application_it_does_not_know(tmp_path: Path) -> None:
    model = compiled(tmp_path, [process("look", [task("sniff", "read_smell")],
                                        StartTrigger="timer:after 1s")],
                     applications=["read_smell"], package_attributes=(
                         '<ExtendedAttribute Name="opspec:World" Value="vacuum-room"/>'))
    devices = world_performers(model, seed=0, user=0)
    devices["world"].applications["read_smell"] = None  # type: ignore[attr-defined]
    result = Simulation(model, performers=devices, keep_trace=True).run(until=2.0)
    failed = [e for e in result.trace if e.kind == "activity.failed"]
    assert [f.data["message"] for f in failed] == [
        "the simulated world has no device operation 'read_smell'"]
