"""The room world's cell arithmetic (``opspec.worlds.stepping``): a coordinate's cell found by
multiplying by ``1 / cell`` where the cell is a power of two metres (``cells_of``) is float
floor division's, bit for bit; ``cover`` with one membership test a cell gives what covering
first and then filtering the range's cells gave; ``cover_within``, what the room's compiled
loop covers with (its bound fixed with the geometry, the membership tests spared for cells
known uncovered, a cell surely too far not measured, the range's cells handed back as they
are when none was covered), gives what ``cover`` gives."""

from __future__ import annotations

import math
import random
from collections.abc import Iterator

import pytest

from opspec.worlds.stepping import (
    RoomState,
    cells_of,
    cover,
    cover_limit,
    cover_within,
    far_from,
)


def _inv(cell: float) -> float:
    state = RoomState()
    state.place((0.15, 4.85, 0.15, 3.85), [], 0.15, cell, (), {}, set(), 20, 16)
    return state.inv


@pytest.mark.parametrize("cell", [0.25, 0.5, 1.0, 0.125, 2.0 ** -20])
def test_a_power_of_two_cell_is_floor_division(cell: float) -> None:
    inv = _inv(cell)
    assert inv == 1.0 / cell
    draw = random.Random(7)
    values = [0.0, -0.0, 5e-324, -5e-324, cell, -cell, 3 * cell, -3 * cell,
              math.nextafter(cell, 0.0), math.nextafter(-cell, 0.0), 4.85, -0.15, 1e15]
    values += [draw.uniform(-6.0, 6.0) for _ in range(20_000)]
    values += [k * cell + draw.choice((-1e-17, 0.0, 1e-17)) for k in range(-50, 50)]
    for v in values:
        assert cells_of(v, cell, inv) == int(v // cell), v


@pytest.mark.parametrize("cell", [0.3, 0.2, 3.0, 0.75, 2.0 ** -21])
def test_other_cells_are_divided(cell: float) -> None:
    assert _inv(cell) == 0.0
    for v in (0.0, 0.29, 0.3, 0.6, 0.9, -0.3, 1.7):
        assert cells_of(v, cell, 0.0) == int(v // cell)


def _cover_before(cells: tuple[tuple[int, ...], ...], x: float, y: float, cell: float,
                  reach: float, covered: set[tuple[int, ...]]
                  ) -> tuple[list[tuple[int, ...]], tuple[tuple[int, ...], ...]]:
    limit = math.pow(reach, 2.0) + math.pow(cell / 2, 2.0)
    new = []
    for c in cells:
        cx, cy = c
        if math.pow((cx + 0.5) * cell - x, 2.0) + math.pow((cy + 0.5) * cell - y, 2.0) <= limit \
                and c not in covered:
            covered.add(c)
            new.append(c)
    return new, tuple([c for c in cells if c not in covered])


Cells = tuple[tuple[int, int], ...]


def _cases(seed: int) -> Iterator[tuple[float, float, Cells, set[tuple[int, int]], float, float]]:
    """Random rooms' cell ranges: (cell, reach, a range's cells, those covered before, x, y)."""
    draw = random.Random(seed)
    for _ in range(500):
        cell, reach = draw.choice((0.25, 0.2)), draw.choice((0.15, 0.3))
        cells = tuple((cx, cy) for cx in range(draw.randint(0, 3), 5)
                      for cy in range(draw.randint(0, 3), 5))
        before = {c for c in cells if draw.random() < 0.3} | {(9, 9)}
        yield cell, reach, cells, before, draw.uniform(0.0, 1.3), draw.uniform(0.0, 1.3)


def test_cover_is_what_it_was() -> None:
    for cell, reach, cells, before, x, y in _cases(3):
        mine, theirs = set(before), set(before)
        assert cover(cells, x, y, cell, reach, mine) == _cover_before(
            cells, x, y, cell, reach, theirs)
        assert mine == theirs


def test_far_spares_only_cells_outside() -> None:
    draw = random.Random(5)
    for _ in range(200):
        reach, cell = draw.uniform(0.05, 0.5), draw.choice((0.25, 0.2, 0.1, 0.5))
        limit = cover_limit(reach, cell)
        far = far_from(limit)
        for _ in range(200):
            # around the bound, where rounding could matter
            d = math.sqrt(limit) * draw.uniform(0.999999, 1.000001)
            other = draw.uniform(-1e-9, 1e-9)
            if abs(d) > far:
                assert math.pow(d, 2.0) + math.pow(other, 2.0) > limit
                assert math.pow(other, 2.0) + math.pow(d, 2.0) > limit


def test_cover_within_is_cover_whichever_way() -> None:
    draw = random.Random(11)
    for cell, reach, cells, before, x, y in _cases(11):
        mine, theirs = set(before), set(before)
        limit = cover_limit(reach, cell)
        new, left = cover_within(cells, x, y, cell, limit, far_from(limit), mine, True)
        assert (new, left) == cover(cells, x, y, cell, reach, theirs)
        assert mine == theirs
        if len(left) == len(cells):
            assert left is cells and not new
        # the cells left are uncovered: tested again without the membership tests, as
        # with them
        x2, y2 = x + draw.uniform(-0.2, 0.2), y + draw.uniform(-0.2, 0.2)
        spared, tested = set(mine), set(mine)
        assert (cover_within(left, x2, y2, cell, limit, far_from(limit), spared, False)
                == cover(left, x2, y2, cell, reach, tested))
        assert spared == tested
