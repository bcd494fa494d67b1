"""The time a wrong pick costs when the wrong picks were not slower than the intended ones
(walkthrough participants who pick the wrong button as fast as the right one): no time lost
is written, 0 s, and said so; a family fitted to the differences clipped at 0 wrote a cost
(its mean above 0) that the difference of means, below 0, does not show."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from opspec.usermodels.choice_estimates import wrong_choice_loss
from opspec.usermodels.distributions import Constant


def test_wrong_picks_no_slower_cost_nothing() -> None:
    rng = np.random.default_rng(3)
    right = list(rng.lognormal(np.log(2.5), 0.3, 48))
    wrong = list(rng.lognormal(np.log(2.3), 0.3, 10))
    loss = wrong_choice_loss("choose", "ok", {"ok": right, "wrong": wrong}, "aic")
    assert loss is not None
    assert loss.seconds == pytest.approx(np.mean(wrong) - np.mean(right))
    assert loss.seconds < 0
    assert loss.distribution == Constant(0.0)
    assert "the wrong picks were not slower: no time lost, written as 0 s" in loss.comment()


def test_slower_wrong_picks_still_cost_their_time() -> None:
    rng = np.random.default_rng(4)
    right = list(rng.lognormal(np.log(2.0), 0.2, 200))
    wrong = list(np.array(rng.lognormal(np.log(2.0), 0.2, 60)) + 8.0)
    loss = wrong_choice_loss("choose", "ok", {"ok": right, "wrong": wrong}, "aic")
    assert loss is not None and loss.seconds == pytest.approx(8.0, abs=0.5)
    assert loss.distribution.mean == pytest.approx(8.0, abs=0.5)
    assert "written as the wrong alternative's duration" in loss.comment()


def _choices(folder: Path, person: int) -> Path:
    """A person's session: 12 choices of "ok", every third preceded by a wrong pick."""
    rng = np.random.default_rng(person)
    lines: list[dict[str, object]] = [
        {"format": "opspec-trace", "version": 1, "person": f"P{person:02d}"},
        {"time": 0.0, "kind": "run.started"}]
    t = 0.0
    for i in range(1, 13):
        picks = ["wrong", "ok"] if i % 3 == 0 else ["ok"]
        for pick in picks:
            lines.append({"time": t, "kind": "activity.offered", "activity": "choose",
                          "lane": "user", "instance": i,
                          "data": {"choices": ["ok", "wrong"]}})
            # wrong picks faster on average, some slower than the intended ones' mean
            t += float(rng.lognormal(np.log(2.0), 0.5) if pick == "wrong"
                       else rng.lognormal(np.log(3.0), 0.1))
            lines.append({"time": t, "kind": "activity.completed", "activity": "choose",
                          "lane": "user", "instance": i, "data": {"choice": pick}})
        t += 100.0
    path = folder / f"P{person:02d}.jsonl"
    path.write_text("".join(json.dumps(x) + "\n" for x in lines), encoding="utf-8")
    return path


def test_the_redraws_of_no_loss_are_no_loss(tmp_path: Path) -> None:
    from opspec.cli import main
    from opspec.usermodels.uncertainty import read_parameter_draws

    for person in range(6):
        _choices(tmp_path, person)
    model = tmp_path / "m.users.toml"
    assert main(["fit", str(tmp_path), "-o", str(model), "--draws", "30"]) == 0
    found = read_parameter_draws(model)
    name = "activities.wrong.duration.value"
    # every resample's wrong picks are faster: no loss, in every redraw as in the estimate
    # (the clipped losses' mean put a cost in each redraw)
    assert found is None or name not in found[0].parameters
