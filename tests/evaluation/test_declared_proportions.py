"""`opspec evaluate` gives a ratio the interval its declaration in the spec calls for, whatever
one run's numbers: a ratio declared a proportion (``Proportion="true"``) Wilson's on the
effective trials, any other ratio the ratio's, even when every user's numerator happens to be
at most its denominator (three users of one day of the dispenser: one alarm for every dose,
once reported as a proportion, [0.758, 1]); a run that contradicts a declaration stops the
summary with an error naming it."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.evaluation import summary
from opspec.evaluation.replication import ReplicationRecord
from opspec.evaluation.store import ResultStore

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
# seed 1, 3 users x 1 day: 12 alarms for 12 doses due, one per dose in every user's run
SMALL = ("--users", "3", "--days", "1", "--seed", "1", "--workers", "1",
         "--user-model", str(USERS))


@pytest.mark.parametrize("spec", ["medication_dispenser.xpdl", "medication_dispenser.bpmn"])
def test_alarms_per_dose_is_a_ratio_even_when_every_dose_had_one_alarm(evaluate, tmp_path,
                                                                        spec):
    status, doc, err = evaluate(str(ROOT / "specs" / spec), *SMALL, "--out",
                                str(tmp_path / "o"), report=False)
    assert status == 0, err
    metrics = doc["metrics"]
    alarms = metrics["alarms_per_dose"]
    assert alarms["numerator_total"] == alarms["denominator_total"] == 12
    assert alarms["ci95_method"] == "t" and alarms["proportion"] is False
    assert alarms["per_user"]["between_user_sd"] is None
    for name in ("taken_rate", "missed_rate"):
        assert metrics[name]["ci95_method"] == "wilson-neff" and metrics[name]["proportion"]
    assert "t" in doc["interval_methods"]


def test_a_run_that_contradicts_a_declared_proportion_is_an_error_naming_it(evaluate,
                                                                             tmp_path):
    text = SPEC.read_text(encoding="utf-8")
    old = '<opspec:Ratio Name="alarms_per_dose" Numerator="alarms" Denominator="doses_due"'
    assert text.count(old) == 1
    spec = tmp_path / "declared.xpdl"
    spec.write_text(text.replace(old, old + ' Proportion="true"'), encoding="utf-8")
    # seed 0: 16 alarms for 12 doses
    args = [a if a != "1" or i != 5 else "0" for i, a in enumerate(SMALL)]
    status, doc, err = evaluate(str(spec), *args, "--out", str(tmp_path / "o"), report=False)
    assert status != 0 and doc is None
    assert "alarms_per_dose is declared a proportion" in err
    assert "more alarms than doses_due" in err and 'Proportion="true"' in err


def _store(folder: Path, pairs: list[tuple[int, int]], definitions: list[dict]) -> ResultStore:
    store = ResultStore(folder, create=True)
    store.put("metrics", definitions)
    store.add_many([ReplicationRecord("A", user, "done", metrics={
        "alarms": {"kind": "count", "total": y}, "due": {"kind": "count", "total": n},
        "per_dose": {"kind": "ratio", "value": y / n}}) for user, (y, n) in enumerate(pairs)])
    return store


COUNTS = [{"name": "alarms", "kind": "count"}, {"name": "due", "kind": "count"}]


@pytest.mark.parametrize("declared", [{"proportion": False}, {}], ids=["undeclared", "old-store"])
def test_an_undeclared_ratio_is_not_capped_at_1(tmp_path, declared):
    # every user's numerator at most its denominator, the ratio near 1: the guess gave Wilson's
    # interval, whose upper end is 1; the ratio's t interval goes above 1, as the ratio may
    pairs = [(3, 4), (4, 4), (4, 4), (2, 4), (4, 4)]
    store = _store(tmp_path / "r", pairs, [*COUNTS, {
        "name": "per_dose", "kind": "ratio", "numerator": "alarms", "denominator": "due",
        **declared}])
    got = summary.summarise_design(store, "A", 1.0)["per_dose"]
    store.close()
    assert got["ci95_method"] == "t" and got["ci95"][1] > 1.0
    assert got["proportion"] is False


def test_a_declared_proportion_with_few_events_keeps_wilson(tmp_path):
    store = _store(tmp_path / "p", [(0, 4), (1, 4), (0, 4)], [*COUNTS, {
        "name": "per_dose", "kind": "ratio", "numerator": "alarms", "denominator": "due",
        "proportion": True}])
    got = summary.summarise_design(store, "A", 1.0)["per_dose"]
    store.close()
    assert got["ci95_method"] == "wilson-neff" and got["ci95"][1] < 1.0
    assert got["per_user"]["between_user_sd"] is not None
