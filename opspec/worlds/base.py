"""What every simulated world shares: simulated time, a random stream, trace output, and the
device operations the specs' applications name."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from opspec.worlds.geometry import wrap_angle
from opspec.worlds.stepping import STEP_S, Normals

if TYPE_CHECKING:   # annotations only: `opspec validate` loads no NumPy
    import numpy as np

__all__ = ["STEP_S", "RobotWorld", "World", "check_parameters"]

Tracer = Callable[[str, Mapping[str, Any]], None]



def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def check_parameters(*, numbers: Mapping[str, Any] | None = None,
                     vectors: Mapping[str, tuple[Any, int | None]] | None = None,
                     boxes: Mapping[str, Any] | None = None,
                     not_negative: tuple[str, ...] = ()) -> None:
    """Raise ``ValueError`` naming the first parameter of the wrong type: ``numbers`` must be
    finite numbers (those in ``not_negative`` also >= 0: a noise's sd, a rate), ``vectors``
    (value, length or None) lists of numbers of that length (a ``None`` value is allowed),
    ``boxes`` lists of such [x0, y0, x1, y1] lists. Worlds call it first,
    so a user reads "width must be a number, not 'wide'", not a Python comparison error."""
    for name, value in (numbers or {}).items():
        if not _is_number(value) or not math.isfinite(value):   # nan, inf: no length
            raise ValueError(f"{name} must be a number, not {value!r}")
        if name in not_negative and value < 0:      # here, not as a crash mid-run
            raise ValueError(f"{name} must be 0 or more, not {value!r}")
    for name, (value, size) in (vectors or {}).items():
        if value is None:
            continue
        if (isinstance(value, str | bytes) or not hasattr(value, "__len__")
                or not all(_is_number(v) for v in value)
                or (size is not None and len(value) != size)):
            shape = f"a list of {size} numbers" if size else "a list of numbers"
            raise ValueError(f"{name} must be {shape}, not {value!r}")
    for name, value in (boxes or {}).items():
        if isinstance(value, str | bytes) or not hasattr(value, "__iter__"):
            raise ValueError(f"{name} must be a list of [x0, y0, x1, y1] boxes, not {value!r}")
        for box in value:
            check_parameters(vectors={f"each of {name}": (box, 4)})


class World:
    """A world advanced lazily to the engine's time whenever a device is used.

    Subclasses implement :meth:`_step` (move everything by ``dt``) and the sensor reads.
    Facts worth counting are traced as ``world.*`` events (``tracer(kind, data)``).
    """

    def __init__(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self._normals: Normals | None = None
        self.time = 0.0
        self.tracer: Tracer | None = None
        self._announced = False

    @property
    def rng(self) -> np.random.Generator:
        """The world's random stream, where the draws made so far leave it (the normal draws
        taken ahead, :meth:`normal_draws`, settled first)."""
        normals = self._normals
        if normals is not None:
            normals.settle()
        return self._rng

    @rng.setter
    def rng(self, rng: np.random.Generator) -> None:
        normals = self._normals
        if normals is not None:
            normals.settle()
            normals.rng = rng
        self._rng = rng

    def normal_draws(self) -> Normals:
        """The standard normal draws of :attr:`rng` taken a batch at a time (one object per
        world, drawing from its stream as ``rng.standard_normal()`` would)."""
        normals = self._normals
        if normals is None:
            normals = self._normals = Normals(self._rng)
        return normals

    def trace(self, kind: str, **data: Any) -> None:
        if self.tracer is not None:
            self.tracer(kind, data)

    def advance(self, now: float) -> None:
        """Move the world forward to simulated time ``now`` in small steps."""
        if not self._announced:
            # facts of the initial state (cells under the robot at the start) are traced at
            # the first use, once the tracer is attached, so counts from the trace are whole
            self._announced = True
            self._announce()
        if self.time < now - 1e-12:
            self._advance(now)

    def _advance(self, now: float) -> None:
        """Step from ``self.time`` to ``now``: steps of ``STEP_S``, the last one shorter.
        A subclass may take the same steps faster (with the same arithmetic, so the same
        floats: a run's trace must not depend on how the world was stepped)."""
        limit = now - 1e-12
        step = self._step
        while self.time < limit:
            dt = min(STEP_S, now - self.time)
            step(dt)
            self.time += dt

    def _step(self, dt: float) -> None:
        raise NotImplementedError

    def _announce(self) -> None:
        """Trace facts of the initial state (subclass hook; nothing by default)."""

    # device operations, by Application id: each returns the data the activity completes with
    def operation(self, application: str, data: Mapping[str, Any]) -> dict[str, Any]:
        handler = getattr(self, f"op_{application}", None)
        if handler is None:
            raise KeyError(application)
        result: dict[str, Any] = handler(data)
        return result

    def applications(self) -> list[str]:
        return [name[3:] for name in dir(self) if name.startswith("op_")]


class RobotWorld(World):
    """A world with one robot of ours (``self.robot``) and a battery draining linearly at
    ``self.drain_per_s`` % per second: the motors and the battery gauge every such world has."""

    robot: Any
    drain_per_s: float

    def op_drive(self, data: Mapping[str, Any]) -> dict[str, Any]:
        """Execute ``motor_cmd``; ``turn_random`` (the random-move manoeuvre) turns to a new
        heading a quarter to three quarters round at once, then stops."""
        command = str(data.get("motor_cmd") or "stop")
        if command == "turn_random":
            self.robot.heading = wrap_angle(
                self.robot.heading + float(self.rng.uniform(math.pi / 2, 3 * math.pi / 2)))
            command = "stop"
        self.robot.command = command
        return {}

    def op_read_battery(self, _data: Mapping[str, Any]) -> dict[str, Any]:
        return {"level": round(max(0.0, 100.0 - self.drain_per_s * self.time), 3)}
