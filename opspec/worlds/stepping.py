"""The room world's inner loop: the robot driving straight (or standing) between two device
operations, step by step.

Plain float arithmetic over plain fields, so that the compiled build (``opspec._native``)
compiles it with the engine: the same IEEE operations in the same order as from source, so
the same floats and the same traces either way (tests/engine/test_native_every_spec.py).
The loop stops and hands back to :class:`~opspec.worlds.room.RoomWorld` at the few steps that
need the world itself: one that covers new cells (``COVER``) and the first step of a
contact (``COLLISION``), both traced there; it is then run again to go on.
"""

from __future__ import annotations

import math
from typing import Any, Final

from opspec.worlds.robot import COMMANDS, pose_after

__all__ = ["ARC", "COLLISION", "COVER", "DONE", "STEP_S", "Grown", "Normals", "RayBox",
           "RoomState", "Sides", "cells_of", "cover", "cover_limit", "cover_within",
           "cover_step", "distance_ahead", "far_from", "round4", "rounded"]

#: integration step: 5 cm at 1 m/s, well under the robot's size
STEP_S: Final = 0.05

DONE: Final = 0          # reached the time asked for
COVER: Final = 1         # this step covered new cells (``new_cells``), to be traced
COLLISION: Final = 2     # a contact began at this step
ARC: Final = 3           # a command that drives and turns at once: the room steps it

#: Robot.velocity() of a command it does not know, as one Python object: compiled, a
#: ``tuple[float, float]`` constant is two C doubles, boxed anew (a tuple and two floats)
#: wherever it is used as an object, and mypyc 2.4 inverts the check of its read where it
#: is assigned (it raised "value for final name was not set")
STILL: Final[tuple[float, ...]] = (0.0, 0.0)
#: robot.COMMANDS as a static of this module: compiled, a name imported from a module that
#: is not compiled is looked up in this module's globals at each use (once a device use)
_COMMANDS: Final = COMMANDS
#: math.atan2 likewise: mypyc has no native atan2 (it was looked up in the module a call)
_atan2: Final = math.atan2

Key = tuple[int, int, int, int]
#: a floor cell (x, y), typed as a tuple of any length so that compiled code keeps it one
#: Python object: a ``tuple[int, int]`` is read into two C integers and boxed anew each
#: time it goes into a set or a list (four times a cell ``cover`` looks at)
Cell = tuple[int, ...]
Cells = tuple[Cell, ...]
#: a box as the range finder meets it: its sides, then the 1e-9 tolerance
#: ``ray_to_box_along`` puts around them (y0 - 1e-9, y1 + 1e-9, x0 - 1e-9, x1 + 1e-9)
RayBox = tuple[float, float, float, float, float, float, float, float]


# The fixed geometry that each step (``RoomState.resume``) or each range reading
# (``distance_ahead``) reads, as objects of compiled floats: compiled, a tuple of floats is
# unboxed float by float at each unpacking (eight reads of an obstacle's four sides a step
# in a room of two obstacles, 24 a reading of three boxes), a field of these is read as it is
class Grown:
    """An obstacle grown by the robot's radius: the box its centre may not enter."""

    def __init__(self, x0: float, x1: float, y0: float, y1: float) -> None:
        self.x0 = x0
        self.x1 = x1
        self.y0 = y0
        self.y1 = y1


class Sides:
    """A :data:`RayBox`: a box's sides as the range finder meets them, then those sides
    with the 1e-9 tolerance around them."""

    def __init__(self, box: RayBox) -> None:
        self.x0 = box[0]
        self.y0 = box[1]
        self.x1 = box[2]
        self.y1 = box[3]
        self.y0_lo = box[4]
        self.y1_hi = box[5]
        self.x0_lo = box[6]
        self.x1_hi = box[7]


class RoomState:
    """The room world's moving state in compiled fields: the world's ``time``, the robot's
    ``x``, ``y``, ``heading`` and motor ``command`` (this object is the room's ``robot``),
    the bumper latch ``bumped`` and ``in_contact``, with what the device operations do to
    them between two of the room's traced facts. The room (:class:`~opspec.worlds.room.
    RoomWorld`) reads and writes them through properties, so the glue around each device
    operation runs compiled too.

    :meth:`advance` moves the world to a time: driving straight (or standing) step by step,
    turning on the spot, or ``ARC`` for the room to step through ``_step``. It stops at a
    step that covers new cells (``COVER``: the room's ``covered`` has them already,
    ``new_cells`` lists them in the order the room traces them) or starts a contact
    (``COLLISION``), both traced by the room; :meth:`resume` then goes on. During such a
    stop ``time`` is the time at that step's start (the world's time while it is handled),
    ``key`` the cell range of the robot's reach; ``t`` is the loop's time after the step. ``after`` is
    ``wrap_angle(heading)``, which the next step sets the heading to, and ``settled`` says
    it equals ``heading`` bit for bit (wrapping no longer changes it)."""

    def __init__(self) -> None:
        self.x_lo = 0.0
        self.x_hi = 0.0
        self.y_lo = 0.0
        self.y_hi = 0.0
        self.grown: list[Grown] = []
        self.reach = 0.0
        self.cell = 0.0
        self.inv = 0.0          # 1 / cell where cells_of may multiply by it (see place)
        self.radius = 0.0
        self.boxes: tuple[Sides, ...] = ()
        self.uncovered: dict[Key, Cells] = {}
        self.covered: set[Cell] = set()
        self.cells_x = 0
        self.cells_y = 0
        self.new_cells: list[Cell] = []
        self.time = 0.0
        self.x = 0.0
        self.y = 0.0
        self.heading = 0.0
        self.command = "stop"
        # the speeds of the command object last looked up (advance's, in the constant table)
        self.moved_by: str | None = None
        self.mv = self.mw = 0.0
        self.bumped = False
        self.in_contact = False
        # the room's ``range_noise``, here where the compiled performer reads it natively
        self.range_noise = 0.0
        self.t = 0.0
        self.after = 0.0
        self.settled = False
        self.v = 0.0
        self.stop = False
        self.key: Key = (0, 0, 0, 0)
        # the cell range of the last step and its cells still uncovered (``uncovered[key]``
        # then): a straight drive stays in one range for several steps, and a range all
        # covered needs no look at all (``near`` says whether there is a last range)
        self.near = False
        self.near_key: Key = (0, 0, 0, 0)
        # its bounds as whole floats: ``floor(a) == k`` exactly when ``k <= a < k + 1`` (a NaN
        # fails), so resume tests a step's four products against them, without floors
        self.ax0 = self.bx0 = self.ax1 = self.bx1 = self.ay0 = self.by0 = self.ay1 = self.by1 = 0.0
        self.near_cells: Cells = ()
        # whether none of ``near_cells`` was in ``covered`` when it had ``near_count`` cells
        # (then, the set no larger, none is now: cells are only ever added, and ``cover``
        # need not test them)
        self.near_clean = False
        self.near_count = 0
        # ``cover``'s bound and the distance past which a cell is surely outside it (fixed
        # with the geometry: see place)
        self.limit = 0.0
        self.far = 0.0
        # a heading known to wrap to itself bit for bit (``wrapped``, when ``known``):
        # wrapping is a function of the heading, so advance need not compute it again
        self.known = False
        self.wrapped = 0.0
        # cos and sin of the heading ``trig_of`` (NaN: none yet), left by resume: functions
        # of it, so a straight drive's steps need not compute them again
        self.trig_of = math.nan
        self.cos_h = 1.0
        self.sin_h = 0.0

    def place(self, inside: tuple[float, float, float, float],
              grown: list[tuple[float, float, float, float]], reach: float, cell: float,
              boxes: tuple[RayBox, ...], uncovered: dict[Key, Cells],
              covered: set[Cell], cells_x: int, cells_y: int) -> None:
        """The fixed geometry: the box the robot's centre may be in, each obstacle grown by
        the robot's radius (``reach``), the coverage cell, the range finder's boxes and the
        room's cells not yet covered per cell range (ranges not in it not looked at yet),
        the room's covered cells and its size in cells."""
        self.x_lo = inside[0]
        self.x_hi = inside[1]
        self.y_lo = inside[2]
        self.y_hi = inside[3]
        self.grown = [Grown(g[0], g[1], g[2], g[3]) for g in grown]
        self.reach = reach
        self.radius = reach
        self.cell = cell
        # a cell of a power of two metres: ``v // cell`` is then ``floor(v * (1 / cell))``
        # bit for bit (both exact), without float floor division's fmod; bounded so that
        # the product neither overflows nor rounds a subnormal (see cells_of)
        bound = max(abs(inside[0]), abs(inside[1]), abs(inside[2]), abs(inside[3])) + reach
        self.inv = (1.0 / cell if math.frexp(cell)[0] == 0.5 and 2.0 ** -20 <= cell <= 1.0
                    and bound < 1e290 else 0.0)
        self.boxes = tuple([Sides(box) for box in boxes])
        self.uncovered = uncovered
        self.near = False
        self.near_clean = False
        self.limit = cover_limit(reach, cell)
        self.far = far_from(self.limit)
        self.covered = covered
        self.cells_x = cells_x
        self.cells_y = cells_y

    # the robot's interface (opspec.worlds.robot.Robot), for _step and the worlds' tests
    def velocity(self) -> tuple[float, float]:
        return COMMANDS.get(self.command, (0.0, 0.0))     # (Robot.velocity's)

    def pose_after(self, dt: float) -> tuple[float, float, float]:
        return pose_after(self.x, self.y, self.heading, self.command, dt)

    def advance(self, now: float) -> int:
        """World.advance's steps to ``now`` (nothing when the world is there already)."""
        if not self.time < now - 1e-12:
            return DONE
        command = self.command
        if command is self.moved_by:        # (the same command object as last time)
            v = self.mv
            w = self.mw
        else:
            found: tuple[float, ...] | None = _COMMANDS.get(command)
            motion = STILL if found is None else found  # (no default to the get: see STILL)
            v, w = motion
            self.moved_by = command
            self.mv = v
            self.mw = w
        if abs(w) >= 1e-12:
            if v != 0.0:
                return ARC
            self._turn_in_place(now, w)
            return DONE
        heading = self.heading
        if self.known and heading == self.wrapped and (
                math.copysign(1.0, heading) == math.copysign(1.0, self.wrapped)):
            self.after = heading                # wrap_angle(heading) is heading itself
            self.settled = True
        else:
            after = _atan2(math.sin(heading), math.cos(heading))       # wrap_angle
            self.after = after
            self.settled = after == heading and (
                math.copysign(1.0, after) == math.copysign(1.0, heading))
            if self.settled:
                self.known = True
                self.wrapped = heading
        self.t = self.time
        self.v = v
        self.stop = self.command == "stop"
        return self.resume(now)

    def _turn_in_place(self, now: float, w: float) -> None:
        """Steps of a command that turns without driving (``turn_left``…): ``_step`` with
        the position, the contact and the coverage left as they are."""
        limit = now - 1e-12
        t = self.time
        heading = self.heading
        while t < limit:
            rest = now - t
            dt = STEP_S if rest > STEP_S else rest
            heading = heading + w * dt
            heading = _atan2(math.sin(heading), math.cos(heading))   # wrap_angle
            t += dt
        if self.command == "stop":
            self.in_contact = False
        self.heading = heading
        self.time = t

    def resume(self, now: float) -> int:
        """Steps at the speed of the drive :meth:`advance` began until ``now`` (``DONE``)
        or a step the world must see."""
        limit = now - 1e-12
        v = self.v
        stop = self.stop
        uncovered = self.uncovered
        t = self.t
        x = self.x
        y = self.y
        heading = self.heading
        after = self.after
        settled = self.settled
        in_contact = self.in_contact
        reach = self.reach
        cell = self.cell
        inv = self.inv
        # (equal floats other than zero are the same float; -0.0 and 0.0 have sines of
        # two signs, so zero is computed; a NaN is never equal)
        if heading == self.trig_of and heading != 0.0:
            cos_h = self.cos_h
            sin_h = self.sin_h
        else:
            cos_h = math.cos(heading)
            sin_h = math.sin(heading)
        code = DONE
        t_step = 0.0
        while t < limit:
            rest = now - t
            dt = STEP_S if rest > STEP_S else rest      # min(STEP_S, now - t)
            nx = x + v * dt * cos_h
            ny = y + v * dt * sin_h
            if not settled:
                heading = after
                cos_h = math.cos(heading)
                sin_h = math.sin(heading)
                after = _atan2(math.sin(heading), math.cos(heading))    # wrap_angle
                settled = after == heading and (
                    math.copysign(1.0, after) == math.copysign(1.0, heading))
            if nx == x and ny == y:
                if stop:
                    in_contact = False
                t += dt
                continue
            free = self.x_lo <= nx <= self.x_hi and self.y_lo <= ny <= self.y_hi
            if free:
                for g in self.grown:
                    if g.x0 <= nx <= g.x1 and g.y0 <= ny <= g.y1:
                        free = False
                        break
            if free:
                x = nx
                y = ny
                in_contact = False
                if inv > 0.0:
                    ax0 = (x - reach) * inv                 # cells_of, in line
                    ax1 = (x + reach) * inv
                    ay0 = (y - reach) * inv
                    ay1 = (y + reach) * inv
                    if (self.near and self.ax0 <= ax0 < self.bx0 and self.ax1 <= ax1 < self.bx1
                            and self.ay0 <= ay0 < self.by0 and self.ay1 <= ay1 < self.by1):
                        cells = self.near_cells         # uncovered[key], as left
                    else:
                        cells = self._enter((math.floor(ax0), math.floor(ax1),
                                             math.floor(ay0), math.floor(ay1)))
                else:
                    key = (int((x - reach) // cell), int((x + reach) // cell),
                           int((y - reach) // cell), int((y + reach) // cell))
                    cells = (self.near_cells if self.near and key == self.near_key
                             else self._enter(key))     # (near_cells: uncovered[key], as left)
                if len(cells) > 0:
                    # RoomWorld._cover at this step, over the range's cells still uncovered
                    # (cells are only ever added, so the others cannot be covered again)
                    covered = self.covered
                    check = not (self.near_clean and len(covered) == self.near_count)
                    new, left = cover_step(cells, x, y, cell, self.limit, self.far,
                                           covered, check)
                    if left is not cells:               # (else uncovered[key] is cells)
                        uncovered[self.near_key] = left
                        self.near_cells = left
                    self.near_clean = True
                    self.near_count = len(covered)
                    if new:
                        self.key = self.near_key
                        self.new_cells = new
                        code = COVER
            else:
                self.bumped = True
                if not in_contact:
                    in_contact = True
                    code = COLLISION
            if code != DONE:
                t_step = t
                t += dt
                break
            t += dt
        self.t = t
        self.x = x
        self.y = y
        self.heading = heading
        self.trig_of = heading
        self.cos_h = cos_h
        self.sin_h = sin_h
        self.after = after
        self.settled = settled
        self.in_contact = in_contact
        self.time = t if code == DONE else t_step
        return code

    def _enter(self, key: Key) -> Cells:
        """The cell range ``key`` made the last range (``near``): its cells still uncovered,
        found or listed (the room's in it, in ``RoomWorld._cover``'s order)."""
        kx0, kx1, ky0, ky1 = key
        cells = self.uncovered.get(key)
        if cells is None:
            found: list[Cell] = []
            for cx in range(max(kx0, 0), min(kx1 + 1, self.cells_x)):
                for cy in range(max(ky0, 0), min(ky1 + 1, self.cells_y)):
                    found.append((cx, cy))
            cells = tuple(found)
            self.uncovered[key] = cells             # (near_cells is uncovered[key])
        self.near = True
        self.near_key = key
        self.ax0, self.bx0 = float(kx0), float(kx0 + 1)
        self.ax1, self.bx1 = float(kx1), float(kx1 + 1)
        self.ay0, self.by0 = float(ky0), float(ky0 + 1)
        self.ay1, self.by1 = float(ky1), float(ky1 + 1)
        self.near_cells = cells
        self.near_clean = False
        return cells

    def read_range(self, noise: float) -> float:
        """The range finder's reading with this ``noise`` drawn: the distance from the
        robot's edge to the nearest wall or obstacle face ahead, 0 at the least, to 0.1 mm."""
        best = distance_ahead(self.x, self.y, self.heading, self.boxes)
        distance = best - self.radius + noise
        return rounded(distance if distance > 0.0 else 0.0, 4, 10000.0)  # (round4, max(0, d))

    def read_bump(self) -> dict[str, Any]:
        """The bumper: whether it was pressed since it was last read (and clear it)."""
        bumped = self.bumped
        self.bumped = False
        # (compiled, a dict copied clones one key table; a dict built is filled key by key)
        return (_BUMPED if bumped else _NOT_BUMPED).copy()     # a room has no ring edge


_BUMPED: Final[dict[str, Any]] = {"bump": True, "edge": False}
_NOT_BUMPED: Final[dict[str, Any]] = {"bump": False, "edge": False}


#: how many standard normal draws :class:`Normals` takes at once
BATCH: Final = 64


class Normals:
    """A world's standard normal draws (the range finder's noise) from its generator
    ``rng``, taken :data:`BATCH` at a time: compiled, ``Generator.standard_normal()`` is a
    call through Python's protocol of about 3.3k instructions, once a period on a robot;
    an array of them costs that once and little more a draw. They are the generator's own
    draws in its order: numpy fills an array with the same ziggurat draws, one after
    another, that its scalar calls make.

    The generator has then gone ahead of the draws handed out. :meth:`settle` puts it back
    where they leave it (its state before the batch, then as many draws again), as anything
    else drawing from it must find it: the world's ``rng`` settles first
    (:attr:`~opspec.worlds.base.World.rng`)."""

    def __init__(self, rng: Any) -> None:
        self.rng = rng
        self.drawn: list[float] = []
        self.used = 0
        self.before: Any = None         # the generator's state before the batch

    def draw(self) -> float:
        """The next standard normal draw of the generator, as ``rng.standard_normal()``."""
        used = self.used
        drawn = self.drawn
        if used >= len(drawn):          # (all handed out: the generator is where they leave it)
            rng = self.rng
            self.before = rng.bit_generator.state
            drawn = rng.standard_normal(BATCH).tolist()
            self.drawn = drawn
            used = 0
        self.used = used + 1
        return drawn[used]

    def settle(self) -> None:
        """Put the generator where the draws handed out leave it; the rest dropped."""
        used = self.used
        if used < len(self.drawn):
            rng = self.rng
            rng.bit_generator.state = self.before
            if used:
                rng.standard_normal(used)
        self.drawn = []
        self.used = 0
        self.before = None


def distance_ahead(x: float, y: float, heading: float, boxes: tuple[Sides, ...]) -> float:
    """``ray_to_box_along`` to the room's walls from inside (``boxes[0]``), then to each
    obstacle's faces from outside, the nearest of them: the same arithmetic in one loop (the
    range finder of :class:`~opspec.worlds.room.RoomWorld`)."""
    dx = math.cos(heading)
    dy = math.sin(heading)
    along_x = abs(dx) > 1e-12
    along_y = abs(dy) > 1e-12
    best = math.inf
    inside = True
    for box in boxes:
        x0 = box.x0
        y0 = box.y0
        x1 = box.x1
        y1 = box.y1
        if not inside and x0 <= x <= x1 and y0 <= y <= y1:
            best = 0.0 if 0.0 < best else best      # min(best, 0.0): touching an obstacle
            continue
        nearest = math.inf
        if along_x:
            t = (x0 - x) / dx
            if t > 1e-9 and box.y0_lo <= y + t * dy <= box.y1_hi and t < nearest:
                nearest = t
            t = (x1 - x) / dx
            if t > 1e-9 and box.y0_lo <= y + t * dy <= box.y1_hi and t < nearest:
                nearest = t
        if along_y:
            t = (y0 - y) / dy
            if t > 1e-9 and box.x0_lo <= x + t * dx <= box.x1_hi and t < nearest:
                nearest = t
            t = (y1 - y) / dy
            if t > 1e-9 and box.x0_lo <= x + t * dx <= box.x1_hi and t < nearest:
                nearest = t
        if inside:
            best = nearest
            inside = False
        elif nearest < best:
            best = nearest
    return best


def cover(cells: Cells, x: float, y: float, cell: float, reach: float,
          covered: set[Cell]) -> tuple[list[Cell], Cells]:
    """The robot at ``x``, ``y`` covers those of ``cells`` whose centre is within ``reach``
    plus half a cell: they are added to ``covered``; returned are the newly covered ones, in
    the order of ``cells`` (the room traces them in that order), and the ``cells`` still not
    covered."""
    limit = cover_limit(reach, cell)
    return cover_within(cells, x, y, cell, limit, far_from(limit), covered, True)


def cover_limit(reach: float, cell: float) -> float:
    """The squared distance within which a cell's centre is covered (``RoomWorld._cover``'s
    ``reach ** 2 + (cell / 2) ** 2``)."""
    # math.pow(a, 2.0) is ``a ** 2``: both are the C library's pow(a, 2.0) (CPython's float
    # power takes the sign off first, which pow of an even power does too), but compiled
    # math.pow is that call itself, ``**`` a boxed number protocol call
    return math.pow(reach, 2.0) + math.pow(cell / 2, 2.0)


def far_from(limit: float) -> float:
    """A distance along one axis past which a centre is surely not within ``limit``: the
    square of anything above it exceeds ``limit`` by far more than pow's and the sum's
    rounding (under an ulp each), so the test it spares could only have failed."""
    return math.sqrt(limit) * (1.0 + 2.0 ** -20)


def cover_within(cells: Cells, x: float, y: float, cell: float, limit: float, far: float,
                 covered: set[Cell], check: bool) -> tuple[list[Cell], Cells]:
    """:func:`cover` with its bound ``limit`` (and ``far_from(limit)``) given; ``check``
    false when none of ``cells`` is in ``covered`` (the membership tests then spared). The
    cells still not covered are ``cells`` itself when they are all of them."""
    new, left = cover_step(cells, x, y, cell, limit, far, covered, check)
    return ([] if new is None else new), left


def cover_step(cells: Cells, x: float, y: float, cell: float, limit: float, far: float,
               covered: set[Cell], check: bool) -> tuple[list[Cell] | None, Cells]:
    """:func:`cover_within` for :meth:`RoomState.resume`'s steps: ``None`` for no cell newly
    covered, no list made when no cell is covered or dropped (most steps)."""
    new: list[Cell] | None = None
    left: list[Cell] | None = None          # (made at the first cell that is not left)
    i = 0
    # one membership test a cell: ``cells`` has no cell twice, so one covered here is in
    # no later test, and those still not covered afterwards are the ones tested here
    for c in cells:
        if check and c in covered:
            gone = True             # (cells of other ranges overlap these: covered there)
        else:
            cx, cy = c
            dx = (cx + 0.5) * cell - x
            dy = (cy + 0.5) * cell - y
            gone = (abs(dx) <= far and abs(dy) <= far
                    and math.pow(dx, 2.0) + math.pow(dy, 2.0) <= limit)
            if gone:
                covered.add(c)
                if new is None:
                    new = [c]
                else:
                    new.append(c)
        if gone:
            if left is None:
                left = list(cells[:i])
        elif left is not None:
            left.append(c)
        i += 1
    if left is None:
        return new, cells           # (the same cells, in order: no copy)
    return new, tuple(left)


def cells_of(v: float, cell: float, inv: float) -> int:
    """``int(v // cell)``, the cell index of the coordinate ``v``, as
    :meth:`RoomState.resume` computes it: with ``inv`` (``1 / cell`` of a cell of a power of
    two metres, :meth:`RoomState.place`; else 0.0) as ``floor(v * inv)``. Float floor
    division is fmod, a subtraction and a division (CPython's ``float_floor_div``); by a
    power of two each step is exact, as the product is, so both are the exact floor."""
    if inv > 0.0:
        return math.floor(v * inv)
    return int(v // cell)


def round4(x: float) -> float:
    """``round(x, 4)``, the same float, without its decimal conversion (:func:`rounded`)."""
    return rounded(x, 4, 10000.0)


def rounded(x: float, places: int, scale: float) -> float:
    """``round(x, places)``, the same float, ``scale`` being ``10.0 ** places`` (3 or 4
    places), without its decimal conversion for the usual case.

    ``round`` gives the double nearest to the decimal ``n / scale``, ``n`` the integer
    nearest to the exact ``x * scale`` (half to even); ``n / scale`` is that double too (a
    correctly rounded division of two exact numbers). ``y = x * scale`` is within half an
    ulp (under 1e-8 below 10 km) of the exact product, so ``n`` is the integer nearest to
    ``y`` unless ``y`` is within 1e-6 of a half: those, zero and negative numbers
    (``-0.0``), large and non-finite ones go to ``round`` itself."""
    if not 0.0 < x < 1e4:
        return round(x, places)
    y = x * scale
    whole = math.floor(y)
    part = y - whole                      # exact: y and its floor are close doubles
    if abs(part - 0.5) < 1e-6:
        return round(x, places)
    n = whole + 1 if part > 0.5 else whole
    return n / scale
