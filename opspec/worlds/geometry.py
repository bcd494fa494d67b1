"""Plane geometry for the simulated worlds: axis-aligned boxes, rays, circles."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Box", "ray_to_box", "ray_to_circle_inside", "wrap_angle"]


@dataclass(frozen=True, slots=True)
class Box:
    """An axis-aligned rectangle (an obstacle, or a room's inside)."""

    x0: float
    y0: float
    x1: float
    y1: float

    def contains(self, x: float, y: float, margin: float = 0.0) -> bool:
        return (self.x0 - margin <= x <= self.x1 + margin
                and self.y0 - margin <= y <= self.y1 + margin)


def wrap_angle(angle: float) -> float:
    """The same angle in (-pi, pi]."""
    return math.atan2(math.sin(angle), math.cos(angle))


def ray_to_box(x: float, y: float, heading: float, box: Box, *, inside: bool) -> float:
    """Distance along the ray from (x, y) at ``heading`` to the box's boundary: its walls seen
    from inside (``inside=True``, a room) or its faces seen from outside (an obstacle);
    ``inf`` when the ray misses."""
    dx, dy = math.cos(heading), math.sin(heading)
    best = math.inf
    for edge_x in (box.x0, box.x1):
        if abs(dx) > 1e-12:
            t = (edge_x - x) / dx
            if t > 1e-9 and box.y0 - 1e-9 <= y + t * dy <= box.y1 + 1e-9:
                best = min(best, t)
    for edge_y in (box.y0, box.y1):
        if abs(dy) > 1e-12:
            t = (edge_y - y) / dy
            if t > 1e-9 and box.x0 - 1e-9 <= x + t * dx <= box.x1 + 1e-9:
                best = min(best, t)
    if not inside and box.contains(x, y):
        return 0.0
    return best


def ray_to_circle_inside(x: float, y: float, heading: float, radius: float) -> float:
    """Distance from a point inside a circle (centred at the origin) to its edge along
    ``heading``."""
    dx, dy = math.cos(heading), math.sin(heading)
    b = x * dx + y * dy
    c = x * x + y * y - radius * radius
    disc = b * b - c
    return -b + math.sqrt(disc) if disc >= 0 else 0.0
