"""Executable tests of specs/vacuum_cleaner.xpdl: the robot cleans its room, backs up when it
bumps into something, and docks when the battery runs low."""

from __future__ import annotations

from typing import Any

from opspec.testing import assert_mean, check, count, event, happens_before

SPEC = "../vacuum_cleaner.xpdl"
FIVE_MINUTES = 300.0
ROOM_CELLS = 20 * 16              # the 5 m x 4 m room in 25 cm cells


def test_every_bump_is_answered_by_backing_up(spec: Any, simulate: Any) -> None:
    result = simulate(spec, until=FIVE_MINUTES)
    check(result, happens_before(event("world.collision"), "activity:back_up"),
          happens_before("activity:back_up", "activity:random_move", each=True),
          count("activity:back_up") >= 1, spec=spec)


def test_vacuums_cover_at_least_a_third_of_the_room_in_five_minutes(spec: Any,
                                                                    simulate: Any) -> None:
    # each simulated user has a room and a robot of their own (its own random stream)
    result = simulate(spec, users=6, until=FIVE_MINUTES, keep_trace=False)
    assert_mean(result, "cells_covered", at_least=ROOM_CELLS / 3, confidence=0.95)
