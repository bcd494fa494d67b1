"""Executable tests of specs/toy_sumo.xpdl: the move-back-and-hit manoeuvre wins bouts."""

from __future__ import annotations

from typing import Any

from opspec.testing import assert_mean, check, count, happens_before

SPEC = "../toy_sumo.xpdl"
TEN_MINUTES = 600.0


def test_contact_is_answered_by_moving_back_then_hitting(spec: Any, simulate: Any) -> None:
    result = simulate(spec, until=120.0)
    check(result, count("activity:move_back") >= 1, count("activity:hit") >= 1,
          happens_before("activity:move_back", "activity:choose_hit", each=True), spec=spec)


def test_the_sumo_wins_a_fair_share_of_its_bouts(spec: Any, simulate: Any) -> None:
    # each user is a ring and an opponent of their own; bouts are chaotic (per ring, bouts
    # won in 20 minutes vary with sd about 2.5), so eight rings for twenty minutes: at about
    # 5.5 won the claim "at least one per ten minutes" is decided for almost every seed
    result = simulate(spec, users=8, until=2 * TEN_MINUTES, keep_trace=False)
    assert_mean(result, "bouts_won", at_least=2.0, confidence=0.95)
