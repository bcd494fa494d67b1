"""A rectangular room with box obstacles: the vacuum cleaner's room and the cart's ward.

The robot (a disc of ``radius``) moves by its motor command; it cannot enter walls or
obstacles — a move that would is not made, and the contact latches the bumper and, at the
start of each contact, traces ``world.collision``. A coverage grid of ``cell`` metres records
where the robot has been (``world.covered`` per new cell). The battery drains linearly. In the
ward, an RFID tag on the patient is readable within ``tag_range`` metres, and the wristband's
bar code can be scanned there too.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from opspec.worlds.base import RobotWorld, World, check_parameters
from opspec.worlds.geometry import Box, wrap_angle
from opspec.worlds.stepping import ARC, COVER, DONE, Cell, Cells, RayBox, RoomState, rounded

if TYPE_CHECKING:   # annotations only: `opspec validate` loads no NumPy
    import numpy as np

__all__ = ["RoomWorld"]

def _box(corners: Sequence[float]) -> Box:
    if len(corners) != 4:
        raise ValueError(f"an obstacle is [x0, y0, x1, y1], not {list(corners)}")
    box = Box(*map(float, corners))
    if not (box.x0 < box.x1 and box.y0 < box.y1):
        raise ValueError(f"obstacle {list(corners)} needs x0 < x1 and y0 < y1")
    return box


class RoomWorld(RobotWorld):
    """The room (``width`` x ``height`` metres, walls on its edges, ``obstacles`` as
    ``[x0, y0, x1, y1]`` boxes) with the robot starting at ``start`` = ``[x, y, heading]``."""

    def __init__(self, rng: np.random.Generator, *, width: float = 5.0, height: float = 4.0,
                 obstacles: Sequence[Sequence[float]] = ((1.5, 1.5, 2.1, 2.3),
                                                         (3.4, 0.6, 4.0, 1.2)),
                 start: Sequence[float] = (0.5, 0.5, 0.3), radius: float = 0.15,
                 cell: float = 0.25, range_noise: float = 0.01, drain_per_s: float = 0.02,
                 tag: Sequence[float] | None = None, tag_range: float = 0.8,
                 patient_id: str = "patient-17") -> None:
        # the robot, the world's time and the bumper live in compiled fields (stepping.py),
        # read and written through the properties below; the room is their only user
        self._state = RoomState()
        super().__init__(rng)
        check_parameters(numbers={"width": width, "height": height, "radius": radius,
                                  "cell": cell, "range_noise": range_noise,
                                  "drain_per_s": drain_per_s, "tag_range": tag_range},
                         vectors={"start": (start, 3), "tag": (tag, 2)},
                         boxes={"obstacles": obstacles},
                         not_negative=("range_noise", "drain_per_s", "tag_range"))
        self.radius = float(radius)
        for name, value in (("radius", radius), ("cell", cell)):
            if not value > 0:               # the message names the one to fix first
                raise ValueError(f"{name} ({value}) must be positive")
        if not (width > 2 * self.radius and height > 2 * self.radius):
            raise ValueError(f"a {width} x {height} m room has no room for a robot of "
                             f"radius {radius} m")
        self.room = Box(0.0, 0.0, float(width), float(height))
        self.obstacles = [_box(o) for o in obstacles]
        if len(start) != 3:
            raise ValueError(f"start must be [x, y, heading], not {list(start)}")
        self.robot = robot = self._state
        robot.x, robot.y, robot.heading = float(start[0]), float(start[1]), float(start[2])
        if not self._free(self.robot.x, self.robot.y):
            raise ValueError(f"start ({start[0]}, {start[1]}) puts the robot in a wall or "
                             "an obstacle")
        if tag is not None and not (len(tag) == 2 and self.room.contains(*map(float, tag))):
            raise ValueError(f"tag must be [x, y] inside the room, not {list(tag)}")
        self.cell = float(cell)
        self.cells_x = max(1, math.ceil(width / cell))
        self.cells_y = max(1, math.ceil(height / cell))
        self.covered: set[Cell] = set()
        self.range_noise = float(range_noise)
        self.drain_per_s = float(drain_per_s)
        self.tag = tuple(map(float, tag)) if tag is not None else None
        self.tag_range = float(tag_range)
        self.patient_id = patient_id
        self.bumped = False
        self.in_contact = False
        self.collisions = 0
        # What advance needs of the fixed geometry, computed once with _free's arithmetic:
        # the box the robot's centre may be in, each obstacle grown by the robot's radius
        r = self.radius
        inside = (self.room.x0 + r, self.room.x1 - r, self.room.y0 + r, self.room.y1 - r)
        grown = [(o.x0 - r, o.x1 + r, o.y0 - r, o.y1 + r) for o in self.obstacles]
        # per cell range of _cover's loops, its cells (in the room) not yet covered, in the
        # loops' order; cells are only ever added, so the others can add nothing again
        self._uncovered: dict[tuple[int, int, int, int], Cells] = {}
        # the room and the obstacles as op_read_range's ray meets them (ray_to_box_along)
        boxes = tuple(_ray_box(box) for box in (self.room, *self.obstacles))
        self._state.place(inside, grown, self.radius, self.cell, boxes, self._uncovered,
                          self.covered, self.cells_x, self.cells_y)
        self._cover()

    # the world's state, kept in the compiled RoomState
    @property
    def time(self) -> float:
        return self._state.time

    @time.setter
    def time(self, value: float) -> None:
        self._state.time = value

    @property
    def bumped(self) -> bool:
        return self._state.bumped

    @bumped.setter
    def bumped(self, value: bool) -> None:
        self._state.bumped = value

    @property
    def range_noise(self) -> float:
        return self._state.range_noise

    @range_noise.setter
    def range_noise(self, value: float) -> None:
        self._state.range_noise = value

    @property
    def in_contact(self) -> bool:
        return self._state.in_contact

    @in_contact.setter
    def in_contact(self, value: bool) -> None:
        self._state.in_contact = value

    # ------------------------------------------------------------------ motion
    def _free(self, x: float, y: float) -> bool:
        r = self.radius
        if not (self.room.x0 + r <= x <= self.room.x1 - r and
                self.room.y0 + r <= y <= self.room.y1 - r):
            return False
        return not any(o.contains(x, y, margin=r) for o in self.obstacles)

    def advance(self, now: float) -> None:
        """World.advance's steps, the same floats as :meth:`_step` taken one by one (see
        :class:`~opspec.worlds.stepping.RoomState`): the motor command cannot change between
        two device operations, so driving straight (or standing) and turning on the spot are
        compiled loops; :meth:`_cover` looks only at cells still uncovered. Driving along an
        arc takes the steps one by one."""
        if not self._announced:
            self._announced = True
            self._announce()
        code = self._state.advance(now)
        if code != DONE:
            self.finish_advance(code, now)

    def _advance(self, now: float) -> None:
        code = self._state.advance(now)
        if code != DONE:
            self.finish_advance(code, now)

    def finish_advance(self, code: int, now: float) -> None:
        """The steps the compiled loop (``RoomState.advance``, returning ``code``) hands
        back: cells to cover, a contact to trace, an arc to step; then on to ``now``. Also
        called by the compiled performer (:mod:`opspec.worlds.room_devices`)."""
        state = self._state
        while code != DONE:
            if code == ARC:
                World._advance(self, now)       # no command of the bundled specs
                return
            if code == COVER:                   # covered (by the loop), to be traced
                for cx, cy in state.new_cells:
                    self.trace("world.covered", cell=[cx, cy])
            else:
                # (round(x, 3), the same float: round's decimal conversion is about 5k
                # instructions, rounded's shortcut compiled)
                self.collisions += 1
                self.trace("world.collision", x=rounded(state.x, 3, 1000.0),
                           y=rounded(state.y, 3, 1000.0))
            code = state.resume(now)

    def _step(self, dt: float) -> None:
        robot = self.robot
        x, y, heading = robot.pose_after(dt)
        robot.heading = wrap_angle(heading)
        if (x, y) == (robot.x, robot.y):
            self.in_contact = False if robot.command in ("stop",) else self.in_contact
            return
        if self._free(x, y):
            robot.x, robot.y = x, y
            self.in_contact = False
            self._cover()
        else:
            self.bumped = True
            if not self.in_contact:
                self.in_contact = True
                self.collisions += 1
                self.trace("world.collision", x=round(robot.x, 3), y=round(robot.y, 3))

    def _cover(self) -> None:
        robot, cell, reach = self.robot, self.cell, self.radius
        for cx in range(int((robot.x - reach) // cell), int((robot.x + reach) // cell) + 1):
            for cy in range(int((robot.y - reach) // cell), int((robot.y + reach) // cell) + 1):
                if not (0 <= cx < self.cells_x and 0 <= cy < self.cells_y):
                    continue
                centre_x, centre_y = (cx + 0.5) * cell, (cy + 0.5) * cell
                if (centre_x - robot.x) ** 2 + (centre_y - robot.y) ** 2 <= reach ** 2 + (
                        cell / 2) ** 2 and (cx, cy) not in self.covered:
                    self.covered.add((cx, cy))
                    self.trace("world.covered", cell=[cx, cy])

    def _announce(self) -> None:
        for cx, cy in sorted(self.covered):
            self.trace("world.covered", cell=[cx, cy])

    @property
    def coverage(self) -> float:
        """Share of the room's cells the robot has passed over (obstacles included)."""
        return len(self.covered) / (self.cells_x * self.cells_y)

    # ------------------------------------------------------------------ devices
    def op_read_range(self, _data: Mapping[str, Any]) -> dict[str, Any]:
        sd = self.range_noise
        # Generator.normal(0, sd) is 0.0 + sd * standard_normal() (numpy's random_normal:
        # loc + scale * z), the same draw and the same float for half its call's cost; a
        # negative (or NaN) sd still goes to normal, which refuses it as before.
        # RoomDevices.offer (room_devices.py, compiled) draws and reads the same way
        noise = (0.0 + sd * self.rng.standard_normal() if sd >= 0.0
                 else float(self.rng.normal(0.0, sd)))
        return {"distance": self._state.read_range(noise)}

    def op_read_bump(self, _data: Mapping[str, Any]) -> dict[str, Any]:
        return self._state.read_bump()

    def _near_tag(self) -> bool:
        if self.tag is None:
            return False
        return math.hypot(self.robot.x - self.tag[0], self.robot.y - self.tag[1]) <= (
            self.tag_range)

    def op_read_rfid(self, _data: Mapping[str, Any]) -> dict[str, Any]:
        return {"tag": self.patient_id if self._near_tag() else ""}

    def op_scan_barcode(self, _data: Mapping[str, Any]) -> dict[str, Any]:
        return {"patient_id": self.patient_id if self._near_tag() else ""}


def _ray_box(box: Box) -> RayBox:
    """A box's sides and the 1e-9 tolerance ray_to_box_along puts around them."""
    return (box.x0, box.y0, box.x1, box.y1,
            box.y0 - 1e-9, box.y1 + 1e-9, box.x0 - 1e-9, box.x1 + 1e-9)
