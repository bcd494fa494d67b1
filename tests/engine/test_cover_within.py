"""``stepping.cover_within``, what the room's compiled loop covers with: its bound fixed with
the geometry, the membership tests spared for cells known uncovered, a cell surely too far
not measured, the range's cells handed back as they are when none was covered; each the
same as ``cover``."""

from __future__ import annotations

import math
import random

from opspec.worlds.stepping import cover, cover_limit, cover_within, far_from


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


def test_as_cover_whichever_way() -> None:
    draw = random.Random(11)
    for _ in range(500):
        cell, reach = draw.choice((0.25, 0.2)), draw.choice((0.15, 0.3))
        cells = tuple((cx, cy) for cx in range(draw.randint(0, 3), 5)
                      for cy in range(draw.randint(0, 3), 5))
        before = {c for c in cells if draw.random() < 0.3} | {(9, 9)}
        x, y = draw.uniform(0.0, 1.3), draw.uniform(0.0, 1.3)
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
