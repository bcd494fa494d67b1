"""A differential-drive robot moved by motor commands, and the command vocabulary."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["COMMANDS", "Robot"]

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
        v, w = self.velocity()
        if abs(w) < 1e-12:
            return (self.x + v * dt * math.cos(self.heading),
                    self.y + v * dt * math.sin(self.heading), self.heading)
        heading = self.heading + w * dt
        if v == 0.0:
            return self.x, self.y, heading
        r = v / w
        return (self.x + r * (math.sin(heading) - math.sin(self.heading)),
                self.y - r * (math.cos(heading) - math.cos(self.heading)), heading)
