"""Plane geometry for the simulated worlds: axis-aligned boxes, rays, circles."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Box", "ray_to_box", "ray_to_box_along", "ray_to_circle_inside", "wrap_angle"]


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
    return ray_to_box_along(x, y, math.cos(heading), math.sin(heading), box, inside=inside)


def ray_to_box_along(x: float, y: float, dx: float, dy: float, box: Box, *,
                     inside: bool) -> float:
    """:func:`ray_to_box` along the unit direction ``(dx, dy)`` (one ray against several
    boxes computes its direction once)."""
    x0, y0, x1, y1 = box.x0, box.y0, box.x1, box.y1
    if not inside and x0 <= x <= x1 and y0 <= y <= y1:
        return 0.0                                  # from inside an obstacle: touching it
    best = math.inf
    if abs(dx) > 1e-12:
        for edge_x in (x0, x1):
            t = (edge_x - x) / dx
            if t > 1e-9 and y0 - 1e-9 <= y + t * dy <= y1 + 1e-9 and t < best:
                best = t
    if abs(dy) > 1e-12:
        for edge_y in (y0, y1):
            t = (edge_y - y) / dy
            if t > 1e-9 and x0 - 1e-9 <= x + t * dx <= x1 + 1e-9 and t < best:
                best = t
    return best


def ray_to_circle_inside(x: float, y: float, heading: float, radius: float) -> float:
    """Distance from a point inside a circle (centred at the origin) to its edge along
    ``heading``."""
    dx, dy = math.cos(heading), math.sin(heading)
    b = x * dx + y * dy
    c = x * x + y * y - radius * radius
    disc = b * b - c
    return -b + math.sqrt(disc) if disc >= 0 else 0.0
