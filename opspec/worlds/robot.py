"""A differential-drive robot moved by motor commands, and the command vocabulary."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["COMMANDS", "Robot", "pose_after"]

# command -> (forward speed m/s, turn rate rad/s)
COMMANDS: dict[str, tuple[float, float]] = {
    "stop": (0.0, 0.0),
    "forward": (0.3, 0.0),
    "back": (-0.2, 0.0),
    "turn_left": (0.0, 1.5),
    "turn_right": (0.0, -1.5),
    "charge": (0.6, 0.0),
    "turn_random": (0.0, 0.0),      # a random new heading, chosen by the world (one shot)
}


@dataclass(slots=True)
class Robot:
    """Position (m), heading (rad) and the motor command it is executing."""

    x: float
    y: float
    heading: float
    command: str = "stop"

    def velocity(self) -> tuple[float, float]:
        return COMMANDS.get(self.command, (0.0, 0.0))

    def pose_after(self, dt: float) -> tuple[float, float, float]:
        """Where the current command takes the robot in ``dt`` seconds (exact arc)."""
        return pose_after(self.x, self.y, self.heading, self.command, dt)


def pose_after(x: float, y: float, heading: float, command: str,
               dt: float) -> tuple[float, float, float]:
    """Where ``command`` takes a robot at ``x``, ``y``, ``heading`` in ``dt`` seconds (exact
    arc); also the room's compiled robot's (:class:`~opspec.worlds.stepping.RoomState`)."""
    v, w = COMMANDS.get(command, (0.0, 0.0))
    if abs(w) < 1e-12:
        return x + v * dt * math.cos(heading), y + v * dt * math.sin(heading), heading
    after = heading + w * dt
    if v == 0.0:
        return x, y, after
    r = v / w
    return (x + r * (math.sin(after) - math.sin(heading)),
            y - r * (math.cos(after) - math.cos(heading)), after)
