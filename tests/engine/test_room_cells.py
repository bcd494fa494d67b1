"""The room world's cell arithmetic (``opspec.worlds.stepping``): a coordinate's cell found by
multiplying by ``1 / cell`` where the cell is a power of two metres (``cells_of``) is float
floor division's, bit for bit; ``cover`` with one membership test a cell gives what covering
first and then filtering the range's cells gave."""

from __future__ import annotations

import math
import random

import pytest

from opspec.worlds.stepping import RoomState, cells_of, cover


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


def test_cover_is_what_it_was() -> None:
    draw = random.Random(3)
    for _ in range(500):
        cell, reach = draw.choice((0.25, 0.2)), draw.choice((0.15, 0.3))
        cells = tuple((cx, cy) for cx in range(draw.randint(0, 3), 5)
                      for cy in range(draw.randint(0, 3), 5))
        before = {c for c in cells if draw.random() < 0.3} | {(9, 9)}
        x, y = draw.uniform(0.0, 1.3), draw.uniform(0.0, 1.3)
        mine, theirs = set(before), set(before)
        assert cover(cells, x, y, cell, reach, mine) == _cover_before(
            cells, x, y, cell, reach, theirs)
        assert mine == theirs
