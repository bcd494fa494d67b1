"""`opspec evaluate --sweep`: results checked against closed forms nobody here wrote.

The spec is the `opspec new` pill reminder, its user quick and sure-footed (walk 10 s, take
5 s, press 1 s, well inside the 10-minute deadline), with the number of beeps per dose named
as a data field (`max_beeps`) and a `missed_rate` ratio: a dose is missed exactly when every
one of its k beeps goes unheard, so with a chance p of not hearing a beep the missed rate is
p^k, and a user with n doses misses Binomial(n, p^k) of them."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from scipy import stats

USER_MODEL = '''
name = "pill-sweep"
[busy]
engaged = ["walk_to_box", "take_pill", "press_taken"]
ignore = ["hear_beep"]
[activities.hear_beep]
duration = 0.0
omission = { probability = 0.25, reason = "not heard" }
[activities.walk_to_box]
duration = 10.0
[activities.take_pill]
duration = 5.0
[activities.press_taken]
duration = 1.0
'''


def pill_spec(tmp_path: Path, beeps: int = 1) -> Path:
    """The pill reminder with ``beeps`` beeps per dose in a data field and a missed rate."""
    from opspec.commands.new import render

    text = render("pill")["pill.xpdl"]
    for old, new in (
            ("beeps &lt; 2", "beeps &lt; max_beeps"),
            ('<DataField Id="beeps"',
             ('<DataField Id="max_beeps" Name="Beeps per dose"><DataType><BasicType '
             f'Type="INTEGER"/></DataType><InitialValue>{beeps}</InitialValue></DataField>'
             '\n        <DataField Id="beeps"')),
            ('<opspec:Ratio Name="taken_rate"',
             ('<opspec:Ratio Name="missed_rate" Numerator="doses_missed" Proportion="true" '
             'Denominator="doses_due" Description="Share of the doses due that were missed"/>'
             '\n      <opspec:Ratio Name="taken_rate"'))):
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    spec = tmp_path / "pill.xpdl"
    spec.write_text(text, encoding="utf-8")
    (tmp_path / "pill.users.toml").write_text(USER_MODEL, encoding="utf-8")
    return spec


def sweep_of(evaluate, tmp_path: Path, spec: Path, *args: str, users: int = 150,
             days: int = 20, workers: int = 1, out: str = "o", report: bool = False) -> dict:
    """The sweep's JSON document. No report unless asked (``report=True``): these tests read
    the numbers; test_sweep_inputs.py reads a sweep's report, and the two tests here that
    draw one (a spec parameter's sweep, a sweep with per-user targets) check it is written."""
    status, doc, err = evaluate(str(spec), "--users", str(users), "--days", str(days),
                                "--seed", "7", "--workers", str(workers),
                                "--out", str(tmp_path / out), *args, report=report)
    assert status == 0, err
    return doc


def values_of(doc: dict) -> dict[str, dict]:
    return {v["text"]: v for v in doc["sweep"]["values"]}


def test_swept_omission_gives_the_closed_form_missed_rate_at_every_value(evaluate, tmp_path):
    """One beep per dose: the missed rate is the chance p of not hearing it, at each p."""
    spec = pill_spec(tmp_path, beeps=1)
    doc = sweep_of(evaluate, tmp_path, spec,
                   "--sweep", "user.activities.hear_beep.omission=0.05,10%,0.2,0.4")
    sweep = doc["sweep"]
    assert sweep["parameter"] == "user.activities.hear_beep.omission.probability"
    assert [v["value"] for v in sweep["values"]] == [0.05, 0.1, 0.2, 0.4]
    for entry in sweep["values"]:
        rate = entry["metrics"]["missed_rate"]
        assert rate["ci95"][0] <= entry["value"] <= rate["ci95"][1], entry["text"]
        # and the paired difference against p = 0.05 covers the difference of closed forms
        if entry["difference"] is not None:
            low, high = entry["difference"]["missed_rate"]["ci95"]
            assert low <= entry["value"] - 0.05 <= high, entry["text"]
    # the first value is the run's own summary ("metrics" of the whole document)
    assert doc["metrics"]["missed_rate"] == sweep["values"][0]["metrics"]["missed_rate"]


def test_swept_number_of_beeps_gives_p_to_the_k(evaluate, tmp_path):
    """A spec parameter (a data field's initial value): k beeps, missed rate 0.25^k; a
    deadline shorter than the walk misses every dose (the spec's deadline is swept too)."""
    spec = pill_spec(tmp_path, beeps=2)
    doc = sweep_of(evaluate, tmp_path, spec, "--sweep", "spec.reminder_workflow.max_beeps=1,2,3",
                   report=True)
    assert Path(doc["report"]).is_file()
    for entry in doc["sweep"]["values"]:
        k = entry["value"]
        low, high = entry["metrics"]["missed_rate"]["ci95"]
        assert low <= 0.25**k <= high, k
        assert entry["metrics"]["doses_due"]["total"] == 150 * 20 * 2
    doc = sweep_of(evaluate, tmp_path, spec, "--sweep",
                   "spec.reminder_workflow.wait_taken.deadline=10 min,5s", users=20,
                   days=2, out="deadline")
    found = values_of(doc)
    assert found["5 s"]["metrics"]["missed_rate"]["value"] == 1.0    # the walk takes 10 s
    assert found["10 min"]["metrics"]["missed_rate"]["value"] < 0.2


def test_common_random_numbers_make_paired_differences_much_sharper(evaluate, tmp_path):
    """Each value runs on the same users with the same streams: the paired interval of a
    difference is far narrower than the one independent users for each value would give.
    The unpaired width is checked against the two values' own intervals (independent
    designs: the half-widths add in quadrature)."""
    spec = pill_spec(tmp_path, beeps=1)
    doc = sweep_of(evaluate, tmp_path, spec,
                   "--sweep", "user.activities.hear_beep.omission=0.20,0.25", users=200)
    first, second = doc["sweep"]["values"]
    diff = second["difference"]["missed_rate"]
    paired = diff["ci95"][1] - diff["ci95"][0]
    unpaired = diff["unpaired_ci95"][1] - diff["unpaired_ci95"][0]
    assert paired / unpaired < 0.5
    halves = [(v["metrics"]["missed_rate"]["ci95"][1] - v["metrics"]["missed_rate"]["ci95"][0])
              for v in (first, second)]
    assert unpaired == pytest.approx(math.hypot(*halves), rel=0.05)
    assert diff["significant"] and diff["ci95"][0] > 0      # 5 points more missed, seen


def test_the_same_seed_gives_the_same_sweep_on_one_and_two_workers(evaluate, tmp_path):
    spec = pill_spec(tmp_path, beeps=2)
    args = ("--sweep", "user.activities.walk_to_box.duration.value=10s,8 min,20min",
            "--target", "missed_rate < 10%", "--target-users", "90%")
    one = sweep_of(evaluate, tmp_path, spec, *args, users=40, days=5, out="w1", report=True)
    assert Path(one["report"]).is_file()
    two = sweep_of(evaluate, tmp_path, spec, *args, users=40, days=5, workers=2, out="w2")
    assert one["sweep"] == two["sweep"]
    # and the walk matters as it must: 20 minutes never reaches the box within two 10-minute
    # windows, 8 minutes only after the first beep
    assert values_of(one)["20 min"]["metrics"]["missed_rate"]["value"] == 1.0


def test_the_target_answer_is_the_closed_forms(evaluate, tmp_path):
    """p = 1 %, 5 %, 10 %, one beep, 40 doses per user, 200 users. On average "< 3 %" is
    met by 1 % only (its interval lies below, the others' above); for 90 % of users "<= 5 %"
    (at most 2 misses of 40) holds for binom.cdf(2, 40, p) of users: 99.3 %, 67.7 %, 22.3 %
    — met by 1 % only; "< 0.5 %" is met by none."""
    spec = pill_spec(tmp_path, beeps=1)
    doc = sweep_of(evaluate, tmp_path, spec, "--sweep", "user.activities.hear_beep.omission="
                   "1%,5%,10%", "--target", "missed_rate < 3%", "--target", "missed_rate <= 5%",
                   "--target", "missed_rate < 0.5%", "--target-users", "90%", users=200)
    mean, users, none = doc["sweep"]["targets"]
    assert mean["meets"] == ["1 %"] and mean["undecided"] == []
    assert [r["verdict"] for r in mean["values"]] == ["meets", "fails", "fails"]
    assert users["users_meets"] == ["1 %"]
    for row in users["values"]:
        expected = float(stats.binom.cdf(2, 40, row["value"]))
        low, high = row["users"]["share_ci95"]
        assert low <= expected <= high, row["text"]
    assert [r["users"]["verdict"] for r in users["values"]] == ["meets", "fails", "fails"]
    assert none["meets"] == [] and "no value" in none["answer"]
    assert doc["sweep"]["meets_every_target"] == []
