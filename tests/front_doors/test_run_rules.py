"""The rules of :mod:`opspec.runs`, one for every front door: the run length, the seed, the
random scope of a single run (user 0) and who performs the user lane."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.cli import main
from opspec.errors import ConfigurationError
from opspec.runs import DAY, User, build, check_seed, load, run_length

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"
VACUUM = ROOT / "specs" / "vacuum_cleaner.xpdl"


def test_the_run_length_is_days_or_until_else_the_specs_run_length_else_one_day() -> None:
    dispenser, vacuum = load(DISPENSER), load(VACUUM)
    assert run_length(dispenser.compiled) == DAY
    assert run_length(vacuum.compiled) == 4500.0              # opspec:RunLength PT75M
    assert run_length(vacuum.compiled, days=0.5) == DAY / 2
    assert run_length(dispenser.compiled, until=90.0) == 90.0
    for bad in ({"days": 0}, {"days": -1.0}, {"until": float("inf")}, {"days": 1, "until": 5}):
        with pytest.raises(ConfigurationError):
            run_length(dispenser.compiled, **bad)


def test_fractional_days_end_at_the_second_the_decimal_says(capsys) -> None:
    """0.7 days is 16:48:00, not the float product 0.7 * 86400 = 60479.99999999999 s, which
    a clock of whole seconds shows as 16:47:59 — the same end for every door."""
    dispenser = load(DISPENSER)
    assert run_length(dispenser.compiled, days=0.7) == 60_480.0
    assert run_length(dispenser.compiled, days=2.3) == 198_720.0
    assert main(["run", str(DISPENSER), "--days", "0.7", "--json"]) == 0
    assert '"until": 60480.0' in capsys.readouterr().out
    from opspec.evaluation.plan import EvaluationPlan

    plan = EvaluationPlan(designs=(), users=2, days=0.7, seed=0)
    assert plan.horizon == 60_480.0


def test_every_front_door_defaults_to_the_same_length(tmp_path: Path, capsys) -> None:
    from opspec.testing import simulate
    from opspec.tui.session import WalkSession

    assert build(DISPENSER).horizon == DAY
    assert simulate(DISPENSER, script=[]).horizon == DAY
    assert WalkSession(load(DISPENSER).compiled).horizon == DAY
    assert main(["run", str(DISPENSER), "--json", "--no-user"]) in (0, 1)
    assert '"until": 86400.0' in capsys.readouterr().out
    out = tmp_path / "evaluation"
    assert main(["evaluate", str(DISPENSER), "--users", "2", "--workers", "1",
                 "--out", str(out), "--json"]) == 0
    assert '"days": 1.0' in capsys.readouterr().out


@pytest.mark.parametrize("seed", [-1, 2**63, 1.5, "3", True])
def test_a_seed_is_a_whole_number_from_0_to_2_63_minus_1(seed: object) -> None:
    with pytest.raises(ConfigurationError):
        check_seed(seed)
    with pytest.raises(ConfigurationError):
        opspec.run(DISPENSER, seed=seed, until=60)  # type: ignore[arg-type]


def test_the_walkthrough_refuses_a_bad_seed_as_a_usage_error(capsys) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["walkthrough", str(DISPENSER), "--seed", "-4"])
    assert exit_.value.code == 2
    assert "seed" in capsys.readouterr().err


def test_a_single_run_is_user_0_of_an_evaluation() -> None:
    import numpy as np

    run = build(DISPENSER, seed=11, user=User.model(DISPENSER.with_suffix(".users.toml")))
    assert run.sim.streams.scope == (0,) and run.user == 0
    later = build(DISPENSER, seed=11, user_index=3)
    assert later.sim.streams.scope == (3,)
    a, b = run.sim.streams.stream("x"), build(DISPENSER, seed=11).sim.streams.stream("x")
    assert np.array_equal(a.random(4), b.random(4))


def test_opspec_run_uses_the_companion_user_model_like_the_command() -> None:
    outcome = opspec.run(DISPENSER, seed=2, until=9 * 3600)
    taken = outcome.metrics["doses_taken"]["total"]
    assert taken == 1                                 # the 08:00 dose, by the companion model
    nobody = opspec.run(DISPENSER, seed=2, until=9 * 3600, user=User.nobody())
    assert nobody.metrics["doses_taken"]["total"] == 0
    with pytest.raises(ConfigurationError, match="give script or user_model, not both"):
        opspec.run(DISPENSER, user_model="x", script=object())  # type: ignore[arg-type]
