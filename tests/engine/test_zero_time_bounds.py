"""Bounded zero time: a cycle whose activities take a duration too short to move the clock
(a Zeno cycle, 1e-17 s a round) is found by ``opspec check`` like a cycle of no time, one
of real duration is not; and the run-time guard's limit is small enough that a workflow
starting itself without delay is stopped after a bounded number of steps."""

from __future__ import annotations

from pathlib import Path

from test_routing_fidelity import activity, integer_field, spec, transition

from opspec.cli import main


def _cycle(tmp_path: Path, seconds: float) -> Path:
    """B -> C -> B while x == 0; B takes ``seconds``."""
    acts = [activity("A"), activity("B", join="Exclusive", seconds=seconds),
            activity("C", split="Exclusive"), activity("D")]
    trans = [transition("A", "B"), transition("B", "C"), transition("C", "B", "x == 0"),
             transition("C", "D", "otherwise")]
    return spec(tmp_path, acts, trans, integer_field("x", 0))


def test_check_finds_a_zeno_cycle(tmp_path: Path, capsys) -> None:
    assert main(["check", str(_cycle(tmp_path, 1e-17))]) == 0
    out = capsys.readouterr().out
    assert "zero-time cycle B -> C -> B" in out


def test_check_leaves_a_cycle_that_takes_time_alone(tmp_path: Path, capsys) -> None:
    assert main(["check", str(_cycle(tmp_path, 1.0))]) == 0
    assert "zero-time cycle" not in capsys.readouterr().out


def test_the_guards_limit_is_tens_of_thousands_of_steps() -> None:
    from opspec.engine.zero_time import MAX_INSTANT_STEPS, SAMPLE_STEPS

    # a self-starting workflow piles up an instance per step: 500,000 steps took a minute
    # and a gigabyte with the trace kept (docs in opspec/engine/zero_time.py)
    assert MAX_INSTANT_STEPS + SAMPLE_STEPS <= 60_000


def test_a_run_whose_clock_creeps_is_stopped_like_a_zero_time_cycle(tmp_path: Path,
                                                                   capsys) -> None:
    """A Zeno run (each round 1e-17 s: the clock never reaches a second) is stopped by the
    run-time guard with the cycle named, as a cycle of no time is (issue 33); one of real
    duration runs to its end."""
    assert main(["run", str(_cycle(tmp_path, 1e-17)), "--days", "1", "--timeline",
                 "none"]) == 1
    err = capsys.readouterr().err
    assert "clock stopped advancing" in err and "Traceback" not in err
    assert main(["run", str(_cycle(tmp_path, 1.0)), "--until", "PT10M", "--timeline",
                 "none"]) == 0
