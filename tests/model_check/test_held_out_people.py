"""Synthetic people with a known truth: fit on 30, check the model on 10 others.

The truth (``truth.population.toml``): the reference user of specs/medication_dispenser.xpdl
whose median walk varies by person (lognormal, sigma 0.25) and whose chance of missing an
alarm varies by person (beta, mean 0.15, sd 0.08). 40 such people are simulated for a week
(``opspec.evaluation.predictive.write_person_traces``, each trace with its ``person``);
the model is fitted with ``opspec fit`` on 30 of them. The 10 others are people the model has
never seen and who behave as the model says: the check passes. 10 people of
``slow.population.toml`` (walk 1.5x slower, 30 % of alarms missed) are flagged, naming those
two activities. How often the check is wrong either way is measured by
benchmarks/model_check_power.py (docs/fitting.md).
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.evaluation.predictive import write_person_traces

HERE = Path(__file__).resolve().parent
SPEC = HERE.parents[1] / "specs" / "medication_dispenser.xpdl"
DAYS = 7


@pytest.fixture(scope="module", autouse=True)
def _specs_may_be_extended() -> Iterator[None]:
    """The test populations extend the bundled dispenser model in specs/, outside their
    folder: a user model may name it only when OPSPEC_EXTERNAL_PATH allows it (issue 33)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("OPSPEC_EXTERNAL_PATH", str(SPEC.parent))
        yield


@pytest.fixture(scope="module")
def people(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    root = tmp_path_factory.mktemp("people")
    truth = write_person_traces(SPEC, HERE / "truth.population.toml", root / "truth",
                                people=range(40), seed=11, days=DAYS)
    slow = write_person_traces(SPEC, HERE / "slow.population.toml", root / "slow",
                               people=range(10), seed=12, days=DAYS, prefix="S")
    fitted = root / "fitted.users.toml"
    assert main(["fit", *map(str, truth[:30]), "-o", str(fitted), "--draws", "60",
                 "--seed", "1"]) == 0
    return {"root": root, "train": truth[:30], "held_out": truth[30:], "slow": slow,
            "fitted": fitted}


def _check(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict]:
    status = main(["model-check", *args, "--replicates", "199", "--json"])
    return status, json.loads(capsys.readouterr().out)


def test_people_the_model_was_not_fitted_on_pass(people, capsys) -> None:
    status, doc = _check(capsys, str(people["fitted"]), *map(str, people["held_out"]))
    assert status == 0, doc["misfits"]
    assert doc["fits"] is True and doc["persons"] == 10
    checked = {item["item"] for item in doc["items"]}
    # every varying part of the lane is checked: the two durations, the omission of the
    # alarm, the wrong button
    assert {"walk_to_dispenser duration", "take_pill duration", "hear_alarm omission",
            "choose_button commission"} <= checked
    assert doc["family_wise"]["method"] == "holm"
    assert doc["parameter_uncertainty"].startswith("60 redraws")


def test_slower_more_forgetful_people_are_flagged_by_name(people, capsys) -> None:
    status, doc = _check(capsys, str(people["fitted"]), *map(str, people["slow"]))
    assert status == 1
    assert {"walk_to_dispenser duration", "hear_alarm omission"} <= set(doc["misfits"])
    items = {item["item"]: item for item in doc["items"]}
    walk = items["walk_to_dispenser duration"]
    # what they did against what the model predicts: a median walk about 1.5x the model's
    assert walk["observed"]["value"] > walk["predicted"]["high"]
    assert 1.25 < walk["observed"]["value"] / walk["predicted"]["value"] < 1.8
    missed = items["hear_alarm omission"]
    assert missed["observed"]["value"] > missed["predicted"]["high"]
    assert missed["p_holm"] <= 0.05 and missed["p"] <= missed["p_holm"]
    # the rest of what they do is as the model says
    assert "take_pill duration" not in doc["misfits"]


def test_the_text_output_names_each_misfit_and_the_holm_control(people, capsys) -> None:
    status = main(["model-check", str(people["fitted"]), *map(str, people["slow"]),
                   "--replicates", "199"])
    out = capsys.readouterr().out
    assert status == 1
    line = next(x for x in out.splitlines() if x.startswith("MISFIT walk_to_dispenser"))
    assert "observed median" in line and "predicted" in line and "p = " in line
    assert "Holm" in out and "at most 0.05" in out
    assert out.splitlines()[-1].startswith("verdict: ")


def test_spec_metrics_and_the_report(people, capsys, tmp_path: Path) -> None:
    """With --spec the outcome metrics of the spec, run with the model on the same days,
    are checked too; --report writes one HTML file with a QQ plot per activity and an
    interval per metric, inline SVG."""
    status = main(["model-check", str(people["fitted"]), *map(str, people["held_out"]),
                   "--spec", str(SPEC), "--days", str(DAYS), "--runs", "60",
                   "--replicates", "199", "--report", str(tmp_path), "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert status == 0, doc["misfits"]
    metrics = {i["item"]: i for i in doc["items"] if i["kind"] == "metric"}
    assert {"metric report_latency_s", "metric doses_missed"} <= set(metrics)
    latency = metrics["metric report_latency_s"]
    assert latency["predicted"]["low"] <= latency["observed"]["value"] <= \
        latency["predicted"]["high"]
    assert any("doses_due" in n and "everyone" in n for n in doc["notes"])
    html = (tmp_path / "model-check.html").read_text(encoding="utf-8")
    assert html.count("<svg") >= 2 + len(metrics)
    assert "QQ plot" in html and "walk_to_dispenser duration" in html


def test_the_slow_people_miss_more_doses_than_the_spec_run_with_the_model(people, capsys
                                                                          ) -> None:
    status = main(["model-check", str(people["fitted"]), *map(str, people["slow"]),
                   "--spec", str(SPEC), "--days", str(DAYS), "--runs", "60",
                   "--replicates", "199", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert status == 1
    assert "metric report_latency_s" in doc["misfits"]


def test_the_fitted_redraws_carry_how_much_people_differ(people) -> None:
    """From 30 persons how much people differ is estimated about as loosely as their mean
    (Davison & Hinkley 1997, 3.8: two-stage data are resampled by their units, and every
    statistic of the resample is computed again): the redraws of the fitted population
    carry its between-person spreads too, and a redraw sets them in the model it draws."""
    from opspec.usermodels.loader import load_user_model
    from opspec.usermodels.uncertainty import read_parameter_draws

    found = read_parameter_draws(str(people["fitted"]))
    assert found is not None
    draws, _ = found
    walk = "vary.activities.walk_to_dispenser.duration.median.sigma"
    alarm = "vary.activities.hear_alarm.omission.probability.sd"
    assert {walk, alarm} <= set(draws.parameters)
    values = [draws.values(d + 1) for d in range(draws.count)]
    spreads = [v[walk] for v in values]
    assert min(spreads) < draws.estimates[draws.parameters.index(walk)] < max(spreads)
    drawn = draws.apply(load_user_model(people["fitted"]), 1)
    varied = {v.path: v.distribution.params for g in drawn.population.subgroups
              for v in g.varied}
    assert varied[("activities", "walk_to_dispenser", "duration", "median")]["sigma"] == \
        pytest.approx(values[0][walk])
    assert varied[("activities", "hear_alarm", "omission", "probability")]["sd"] == \
        pytest.approx(values[0][alarm])
