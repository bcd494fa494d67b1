"""The walkthrough's replay command gives ``--until`` in days, hours, minutes and seconds
(``18h16m4.89972954505s``), and ``opspec run`` reads it back to exactly the second the
session stopped at, so that the replay runs the same events: never rounded.

It printed ``--until 65764.89972954505``: exact, but no one reads 18:16 in it.
"""

from __future__ import annotations

import random
import shlex

import pytest

from opspec.run_rules import parse_until
from opspec.tui.summary import replay_commands


def _until(seconds: float) -> str:
    _walk, run = replay_commands("pill.xpdl", "lab 3.rec", until=seconds)
    words = shlex.split(run)
    return words[words.index("--until") + 1]


@pytest.mark.parametrize(("seconds", "text"), [
    (65764.89972954505, "18h16m4.89972954505s"),
    (3600.0, "1h"),
    (90061.25, "1d1h1m1.25s"),
    (9 * 3600 + 30.5, "9h30.5s"),
])
def test_the_stop_reads_as_a_duration(seconds: float, text: str) -> None:
    assert _until(seconds) == text


def test_under_a_minute_it_stays_a_number_of_seconds() -> None:
    assert _until(42.125) == "42.125"


def test_what_is_printed_reads_back_to_the_same_second_exactly() -> None:
    chooser = random.Random(7)
    moments = [chooser.uniform(0.0, 30 * 86_400.0) for _ in range(5_000)]
    moments += [65764.89972954505, 86_400.0 * 3 + 0.1, 43_200.000000001, 1e20]
    for moment in moments:
        assert parse_until(_until(moment), name="--until") == moment, moment


def test_without_a_stop_there_is_no_until() -> None:
    _walk, run = replay_commands("pill.xpdl", "r.rec")
    assert "--until" not in run
