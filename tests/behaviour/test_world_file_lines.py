"""A world file's mistakes are refused at the line they are on (``file:line: key``), before
anything runs: a value the world refuses (at its parameter's line, not the file's top), a
negative noise or rate (once a crash mid-run, or a battery that charged), nan, a syntax error
(at the world file's line, not the spec's)."""

from __future__ import annotations

from pathlib import Path

import pytest
from spec_text import compiled, process, task

from opspec.errors import ConfigurationError
from opspec.worlds import world_performers

ROOM = """# a room
width = 5.0
height = 4.0
obstacles = [
  [1.5, 1.5, 2.1, 2.3],
  [3.4, 0.6, 4.0, 1.2],
]
start = [0.5, 0.5, 0.3]
radius = 0.15
cell = 0.25
range_noise = 0.01
drain_per_s = 0.02
"""


def _refusal(tmp_path: Path, text: str, world: str = "vacuum-room") -> ConfigurationError:
    (tmp_path / "room.toml").write_text(text, encoding="utf-8")
    model = compiled(tmp_path, [process("look", [task("read_range", "read_range")],
                                        Period="1s")], applications=["read_range"],
                     package_attributes=(
                         f'<ExtendedAttribute Name="opspec:World" Value="{world}"/>'
                         '<ExtendedAttribute Name="opspec:WorldFile" Value="room.toml"/>'))
    with pytest.raises(ConfigurationError) as refused:
        world_performers(model, seed=0, user=0)  # type: ignore[arg-type]
    return refused.value


def _line_of(text: str, written: str) -> int:
    (line,) = [n for n, row in enumerate(text.splitlines(), start=1) if written in row]
    return line


@pytest.mark.parametrize(("old", "new", "says"), [
    ("start = [0.5, 0.5, 0.3]", "start = [1.8, 1.8, 0.3]",
     "start: world 'vacuum-room': start (1.8, 1.8) puts the robot in a wall or an obstacle"),
    ("[3.4, 0.6, 4.0, 1.2]", "[3.4, 0.6, 3.0, 1.2]",
     "obstacles[1]: world 'vacuum-room': obstacle [3.4, 0.6, 3.0, 1.2] needs x0 < x1"),
    ("width = 5.0", 'width = "5"', "width: world 'vacuum-room': width must be a number, not '5'"),
    ("cell = 0.25", "cell = -0.25", "cell: world 'vacuum-room': cell (-0.25) must be positive"),
    ("range_noise = 0.01", "range_noise = -0.01",
     "range_noise: world 'vacuum-room': range_noise must be 0 or more, not -0.01"),
    ("drain_per_s = 0.02", "drain_per_s = -0.02",
     "drain_per_s: world 'vacuum-room': drain_per_s must be 0 or more, not -0.02"),
    ("height = 4.0", "height = nan",
     "height: world 'vacuum-room': height must be a number, not nan"),
], ids=["start-in-an-obstacle", "inverted-obstacle", "text-width", "negative-cell",
        "negative-noise", "negative-drain", "nan-height"])
def test_a_value_the_world_refuses_is_placed_at_its_line(
        tmp_path: Path, old: str, new: str, says: str) -> None:
    text = ROOM.replace(old, new, 1)
    refused = _refusal(tmp_path, text)
    assert str(refused).startswith(f"{tmp_path / 'room.toml'}:{_line_of(text, new)}: {says}")


def test_the_ring_too_small_for_the_robots_is_placed_at_ring_radius(tmp_path: Path) -> None:
    text = "radius = 0.15\nring_radius = 0.2\n"
    refused = _refusal(tmp_path, text, "sumo-ring")
    assert str(refused).startswith(f"{tmp_path / 'room.toml'}:2: ring_radius: world "
                                   "'sumo-ring': the ring (ring_radius 0.2 m) must hold two")


def test_a_syntax_error_is_at_the_world_files_line(tmp_path: Path) -> None:
    refused = _refusal(tmp_path, ROOM.replace("width = 5.0", "width = 5.0.0", 1))
    assert str(refused).startswith(f"{tmp_path / 'room.toml'}:2: not valid TOML: ")
    refused = _refusal(tmp_path, ROOM.replace("width = 5.0", "width = 5.0\nwidth = 6.0", 1))
    assert str(refused).startswith(f"{tmp_path / 'room.toml'}:3: not valid TOML: Cannot "
                                   "overwrite a value")
