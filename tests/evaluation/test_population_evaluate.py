"""`opspec evaluate` with a population user model: between-user variation that matches its
closed form, subgroup shares realised, the same people whatever the number of workers, each
person stored with their replication, metrics and per-user distributions per subgroup (table,
JSON, report) — and a model without variation gives exactly what it gave before."""

from __future__ import annotations

import math
import re
import sqlite3
from pathlib import Path

import pytest
from evaluation_inputs import SPEC, USERS_TOML
from evaluate_without_report import without_report
from scipy import stats

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
POPULATION = ROOT / "specs" / "medication_dispenser.population.toml"


def one_alarm_spec(tmp_path: Path, omission: str) -> Path:
    """The `opspec new` pill reminder cut to ONE beep per dose, its user quick and sure-footed:
    a dose is missed exactly when the beep goes unheard, so a user whose chance of not hearing
    is p misses Binomial(n, p) of n doses."""
    from opspec.commands.new import render

    files = render("pill")
    text = files["pill.xpdl"]
    assert "beeps &lt; 2" in text
    spec = tmp_path / "pill.xpdl"
    spec.write_text(text.replace("beeps &lt; 2", "beeps &lt; 1"), encoding="utf-8")
    (tmp_path / "pill.users.toml").write_text(f'''
name = "pill-population"
[busy]
engaged = ["walk_to_box", "take_pill", "press_taken"]
ignore = ["hear_beep"]
[activities.hear_beep]
duration = 0.0
omission = {{ probability = 0.25, reason = "not heard" }}
[activities.walk_to_box]
duration = 10.0
[activities.take_pill]
duration = 5.0
[activities.press_taken]
duration = 1.0
{omission}
''', encoding="utf-8")
    return spec


def test_beta_distributed_omission_gives_the_beta_binomial_between_user_variance(
        evaluate, tmp_path):
    """p ~ Beta(a, b) per user, n doses: the missed count is beta-binomial, with variance
    n a b (a + b + n) / ((a + b)^2 (a + b + 1)) — 40 here, against n p (1 - p) = 7.5 if
    every user had the mean p. The sample variance over N users has standard error
    sigma^2 sqrt(2 / (N - 1) + excess kurtosis / N); we allow 4 of them (seed fixed)."""
    a, b, days, users = 2.0, 6.0, 20, 400
    spec = one_alarm_spec(tmp_path, f'''
[vary.activities.hear_beep.omission]
probability = {{ kind = "beta", a = {a}, b = {b} }}
''')
    status, doc, _ = evaluate(str(spec), "--users", str(users), "--days", str(days),
                              "--seed", "19", "--workers", "1", "--out", str(tmp_path / "o"),
                              report=False)    # a population's report: the subgroups test
    assert status == 0
    n = 2 * days
    assert doc["metrics"]["doses_due"]["total"] == n * users
    law = stats.betabinom(n, a, b)
    variance, kurtosis = float(law.var()), float(law.stats(moments="k"))
    assert variance == pytest.approx(n * a * b * (a + b + n) / ((a + b) ** 2 * (a + b + 1)))
    missed = doc["metrics"]["doses_missed"]
    se = variance * math.sqrt(2 / (users - 1) + kurtosis / users)
    assert abs(missed["sd"] ** 2 - variance) < 4 * se
    assert missed["sd"] ** 2 > n * 0.25 * 0.75 + 4 * se     # far from "everyone the same"
    assert abs(missed["mean"] - n * a / (a + b)) < 4 * math.sqrt(variance / users)
    # the between-user sd of the taken rate estimates the sd of 1 - p: sqrt(Var Beta)
    sd_p = math.sqrt(a * b / ((a + b) ** 2 * (a + b + 1)))
    between = doc["metrics"]["taken_rate"]["per_user"]["between_user_sd"]
    assert abs(between**2 - sd_p**2) < 4 * se / n**2
    # each user's drawn probability is stored with their replication
    db = sqlite3.connect(tmp_path / "o" / "results.sqlite")
    drawn = [v for (v,) in db.execute("SELECT value FROM person_parameter WHERE parameter = "
                                      "'activities.hear_beep.omission.probability'")]
    assert len(drawn) == users
    assert stats.kstest(drawn, stats.beta(a, b).cdf).pvalue > 0.001


def test_without_variation_the_between_user_sd_is_about_zero(evaluate, tmp_path):
    spec = one_alarm_spec(tmp_path, "")
    status, doc, _ = evaluate(str(spec), "--users", "200", "--days", "20", "--seed", "19",
                              "--workers", "1", "--out", str(tmp_path / "o"), report=False)
    assert status == 0 and doc["population"] is None
    missed = doc["metrics"]["doses_missed"]
    # binomial: variance n p (1 - p) = 7.5 within sampling error, sd of rates ~ 0
    assert missed["sd"] ** 2 == pytest.approx(7.5, rel=0.35)
    assert doc["metrics"]["taken_rate"]["per_user"]["between_user_sd"] < 0.04


def test_a_population_run_reports_subgroups_everywhere(evaluate, tmp_path, capsys):
    out = tmp_path / "pop"
    status, doc, _ = evaluate(str(SPEC), "--user-model", str(POPULATION), "--users", "240",
                              "--days", "2", "--seed", "8", "--workers", "1",
                              "--out", str(out))
    assert status == 0
    population = doc["population"]
    groups = population["subgroups"]
    assert list(groups) == ["independent", "MCI", "frail"]
    # shares realised: the counts fit the multinomial of the shares asked for
    assert sum(g["users"] for g in groups.values()) == 240
    assert population["shares_test"]["p_value"] > 0.001
    for g in groups.values():
        low, high = g["share_ci95"]
        assert low <= g["expected_share"] <= high
    # every metric per subgroup: the subgroups' totals add up to the whole
    for name in ("doses_due", "doses_missed", "alarms"):
        assert sum(g["metrics"][name]["total"] for g in groups.values()) == \
            doc["metrics"][name]["total"]
    # per-user distributions: users with at least one missed dose, with an exact interval
    missed = doc["metrics"]["doses_missed"]
    low, high = missed["share_with_any_ci95"]
    assert low <= missed["share_with_any"] <= high
    check = stats.binomtest(missed["users_with_any"], 240).proportion_ci(method="exact")
    assert (low, high) == (pytest.approx(check.low), pytest.approx(check.high))
    rate = doc["metrics"]["missed_rate"]["per_user"]
    assert rate["median"] <= rate["p90"] <= rate["p99"]
    # the drawn parameters, overall and per subgroup: MCI misses more alarms by design
    omission = "activities.hear_alarm.omission.probability"
    assert groups["MCI"]["parameters"][omission]["mean"] > \
        groups["independent"]["parameters"][omission]["mean"]
    # stored with the replication
    db = sqlite3.connect(out / "results.sqlite")
    assert db.execute("SELECT COUNT(*) FROM person WHERE design = 'A'").fetchone()[0] == 240
    assert db.execute("SELECT COUNT(DISTINCT parameter) FROM person_parameter").fetchone()[0] \
        == 3
    # the report shows who the users are and the per-subgroup results
    report = (out / "report.md").read_text(encoding="utf-8")
    for words in ("Parameters that differ by person", "Users drawn per subgroup",
                  "## By subgroup", "Per-user distributions, overall and by subgroup",
                  "missed_rate-by-subgroup.svg", "population-parameters.svg"):
        assert words.replace("_", r"\_") in report or words in report
    # metrics named in words there, as in their figures (missed rate, not missed_rate)
    assert re.search(r"Subgroup MCI \([\d,]+ users, [\d.]+ %\): [^\n]*missed rate [\d.]+ %",
                     report), report
    assert "Each user's own missed rate, over the users of each subgroup" in report
    # and the terminal table too (the resume's report, drawn a second time from the same
    # store, is not read: tests/evaluation_output/test_report_content.py reads resumed ones)
    with without_report():
        assert main(["evaluate", "--resume", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "users by subgroup" in text and "metrics by subgroup" in text
    assert "how users differ" in text and "parameters drawn per user" in text


def test_the_same_seed_gives_the_same_people_with_one_or_two_workers(evaluate, tmp_path):
    args = [str(SPEC), "--user-model", str(POPULATION), "--users", "16", "--days", "1",
            "--seed", "4"]
    _, one, _ = evaluate(*args, "--workers", "1", "--out", str(tmp_path / "w1"), report=False)
    _, two, _ = evaluate(*args, "--workers", "2", "--out", str(tmp_path / "w2"),
                         report=False)

    def people(folder: str) -> list[tuple]:
        db = sqlite3.connect(tmp_path / folder / "results.sqlite")
        return (db.execute("SELECT design, user, subgroup FROM person ORDER BY user")
                .fetchall() + db.execute("SELECT user, parameter, value FROM "
                                         "person_parameter ORDER BY user, parameter")
                .fetchall())

    assert people("w1") == people("w2") and len(people("w1")) == 16 + 16 * 3
    assert one["population"] == two["population"]
    assert one["metrics"] == two["metrics"]


def test_a_comparison_runs_the_same_people_in_both_designs(evaluate, tmp_path):
    status, doc, _ = evaluate(str(SPEC), "--compare", str(SPEC), "--user-model",
                              str(POPULATION), "--users", "12", "--days", "1", "--seed", "2",
                              "--workers", "1", "--out", str(tmp_path / "cmp"))
    assert status == 0
    db = sqlite3.connect(tmp_path / "cmp" / "results.sqlite")
    a = db.execute("SELECT user, parameter, value FROM person_parameter WHERE design = 'A' "
                   "ORDER BY user, parameter").fetchall()
    b = db.execute("SELECT user, parameter, value FROM person_parameter WHERE design = 'B' "
                   "ORDER BY user, parameter").fetchall()
    assert a == b and a
    # the same design on the same people: no difference in any subgroup
    for group in doc["population"]["subgroups"].values():
        for difference in group["difference"].values():
            assert difference["difference"] in (0, 0.0, None)


def test_a_model_without_variation_runs_exactly_as_before(evaluate, tmp_path):
    """Each user's stored metrics equal those of a run whose performer is made the way every
    run made it before populations existed: StochasticUser(model, user_stream(seed, u))."""
    from opspec.engine.lanes import user_lane
    from opspec.engine.random import user_stream
    from opspec.runs import build, load
    from opspec.usermodels import load_user_model
    from opspec.usermodels.performer import StochasticUser

    seed, days, users = 11, 2, 6
    status, doc, _ = evaluate(str(SPEC), "--users", str(users), "--days", str(days),
                              "--seed", str(seed), "--workers", "1",
                              "--out", str(tmp_path / "o"), report=False)
    assert status == 0 and doc["population"] is None
    db = sqlite3.connect(tmp_path / "o" / "results.sqlite")
    assert db.execute("SELECT COUNT(*) FROM person").fetchone()[0] == 0
    stored = dict(db.execute("SELECT user, metrics FROM replication ORDER BY user"))
    import json

    spec = load(SPEC)
    model = load_user_model(USERS_TOML)
    names = user_lane(spec.compiled).bind_names
    for user in range(users):
        performer = StochasticUser(model, user_stream(seed, user))
        outcome = build(spec, seed=seed, user_index=user, days=days,
                        performers=dict.fromkeys(names, performer)).execute()
        assert json.loads(stored[user]) == json.loads(json.dumps(outcome.metrics))
