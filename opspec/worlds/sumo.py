"""The toy sumo's ring: our robot against an opponent, bout after bout.

The ring is a disc of ``ring_radius`` metres. The opponent drives towards our robot at
``opponent_speed`` with a seeded wobble. Robots in contact push each other: the one driving
into the other harder (speed along the line of contact) moves both. A robot whose centre
leaves the ring loses the bout (``world.bout`` plus ``world.bout_won`` / ``world.bout_lost``);
a bout lasting ``bout_limit_s`` is a draw. After each bout both robots return to their corners.
The bumper senses contact with the opponent or the ring's edge; a line sensor tells whether
the robot stands on the rim band (``edge_band`` metres wide); the range finder sees the
opponent when it is within 20 degrees of straight ahead, else the ring's edge.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from opspec.worlds.base import RobotWorld, check_parameters
from opspec.worlds.geometry import ray_to_circle_inside, wrap_angle
from opspec.worlds.robot import Robot

if TYPE_CHECKING:   # annotations only: `opspec validate` loads no NumPy
    import numpy as np

__all__ = ["SumoWorld"]


class SumoWorld(RobotWorld):
    def __init__(self, rng: np.random.Generator, *, ring_radius: float = 1.5,
                 radius: float = 0.15, opponent_speed: float = 0.25, bout_limit_s: float = 60.0,
                 range_noise: float = 0.01, drain_per_s: float = 0.02,
                 edge_band: float = 0.3) -> None:
        super().__init__(rng)
        check_parameters(numbers={"ring_radius": ring_radius, "radius": radius,
                                  "opponent_speed": opponent_speed,
                                  "bout_limit_s": bout_limit_s, "range_noise": range_noise,
                                  "drain_per_s": drain_per_s, "edge_band": edge_band},
                         not_negative=("opponent_speed", "range_noise", "drain_per_s",
                                       "edge_band"))
        if not (radius > 0 and ring_radius > 4 * radius and bout_limit_s > 0):
            raise ValueError(f"the ring (ring_radius {ring_radius} m) must hold two robots of "
                             f"radius {radius} m apart, and bout_limit_s must be positive")
        self.ring = float(ring_radius)
        self.radius = float(radius)
        self.opponent_speed = float(opponent_speed)
        self.bout_limit_s = float(bout_limit_s)
        self.range_noise = float(range_noise)
        self.drain_per_s = float(drain_per_s)
        self.edge_band = float(edge_band)
        self.robot = Robot(0.0, 0.0, 0.0)
        self.opponent = Robot(0.0, 0.0, 0.0)
        self.bumped = False
        self.in_contact = False
        self.bout_started = 0.0
        self.results = {"won": 0, "lost": 0, "draw": 0}
        self._corners()

    def _corners(self) -> None:
        offset = self.ring * 0.5
        wobble = float(self.rng.uniform(-0.4, 0.4))
        self.robot.x, self.robot.y, self.robot.heading = -offset, 0.0, wobble
        self.opponent.x, self.opponent.y, self.opponent.heading = offset, 0.0, math.pi
        self.bout_started = self.time

    def _end_bout(self, result: str) -> None:
        self.results[result] += 1
        self.trace("world.bout", result=result, seconds=round(self.time - self.bout_started, 2))
        if result != "draw":
            self.trace(f"world.bout_{result}")
        self._corners()

    def _step(self, dt: float) -> None:
        me, other = self.robot, self.opponent
        # the opponent steers towards us, with a wobble
        aim = math.atan2(me.y - other.y, me.x - other.x)
        other.heading = wrap_angle(aim + float(self.rng.normal(0.0, 0.3)))
        v_me, w_me = me.velocity()
        me.heading = wrap_angle(me.heading + w_me * dt)
        gap = math.hypot(me.x - other.x, me.y - other.y)
        if gap <= 2 * self.radius:
            if not self.in_contact:
                self.in_contact = True
                self.trace("world.collision", x=round(me.x, 3), y=round(me.y, 3))
            self.bumped = True
            # push: components of each robot's velocity along the line from us to them
            ux, uy = (other.x - me.x) / max(gap, 1e-9), (other.y - me.y) / max(gap, 1e-9)
            mine = v_me * (math.cos(me.heading) * ux + math.sin(me.heading) * uy)
            theirs = self.opponent_speed * -(math.cos(other.heading) * ux
                                             + math.sin(other.heading) * uy)
            shove = (mine - theirs) * dt        # > 0: we push them back, < 0: they push us
            for robot in (me, other):
                robot.x += shove * ux
                robot.y += shove * uy
        else:
            # a contact ends when the robots are clearly apart (2 cm), not when the wobbling
            # opponent leaves a hair's gap: one shoving match is one collision
            if gap > 2 * self.radius + 0.02:
                self.in_contact = False
            me.x += v_me * dt * math.cos(me.heading)
            me.y += v_me * dt * math.sin(me.heading)
            step = min(self.opponent_speed * dt, gap - 2 * self.radius)
            other.x += step * math.cos(other.heading)
            other.y += step * math.sin(other.heading)
        if math.hypot(other.x, other.y) > self.ring:
            self._end_bout("won")
        elif math.hypot(me.x, me.y) > self.ring:
            self._end_bout("lost")
        elif self.time - self.bout_started >= self.bout_limit_s:
            self._end_bout("draw")
        elif self.ring - math.hypot(me.x, me.y) < 0.1:
            self.bumped = True                 # the line sensor sees the ring's edge

    # ------------------------------------------------------------------ devices
    def op_read_range(self, _data: Mapping[str, Any]) -> dict[str, Any]:
        me, other = self.robot, self.opponent
        bearing = wrap_angle(math.atan2(other.y - me.y, other.x - me.x) - me.heading)
        if abs(bearing) <= math.radians(20):
            distance = math.hypot(other.x - me.x, other.y - me.y) - 2 * self.radius
        else:
            distance = ray_to_circle_inside(me.x, me.y, me.heading, self.ring) - self.radius
        noisy = distance + float(self.rng.normal(0.0, self.range_noise))
        return {"distance": round(max(0.0, noisy), 4)}

    def op_read_bump(self, _data: Mapping[str, Any]) -> dict[str, Any]:
        """The bumper (latched until read) and the line sensor: ``edge`` is whether the
        robot stands on the ring's rim band (within ``edge_band`` metres of the edge) now."""
        bumped, self.bumped = self.bumped, False
        edge = self.ring - math.hypot(self.robot.x, self.robot.y) < self.edge_band
        return {"bump": bumped, "edge": edge}


