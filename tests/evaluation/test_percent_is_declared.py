"""A ratio is shown in percent where the spec declares it a proportion (``Proportion="true"``),
everywhere `opspec evaluate` shows it, as `opspec run` does: never because its name ends in
``rate`` or ``share`` and its value lies in [0, 1] (an undeclared ``missed_rate`` was 0.83 %
in `opspec evaluate` and 0.0083 in `opspec run`; a declared proportion ``cut_sessions`` was
a plain number). A store written before the declaration was kept shows plain numbers."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from evaluate_without_report import without_report

from opspec.cli import main
from opspec.evaluation import summary, sweep
from opspec.evaluation.describe import describe_metric
from opspec.evaluation.replication import ReplicationRecord
from opspec.evaluation.report_findings import key_findings, population_findings
from opspec.evaluation.store import ResultStore
from opspec.evaluation.tables import (
    comparison_rows,
    distribution_rows,
    metric_rows,
    per_user_rows,
)

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"

#: a number in percent or percentage points ("95 % confidence interval" is neither)
PERCENT = re.compile(r"\d %(?! confidence)| pp\b")

COUNTS = [{"name": "missed", "kind": "count"}, {"name": "due", "kind": "count"}]


def _definitions(declared: dict) -> list[dict]:
    """``missed_rate`` (named like a rate) and ``cut_sessions`` (not), both missed of due, with
    the declaration ``declared`` gives each (an empty dict: a store from before it)."""
    return [*COUNTS, *({"name": name, "kind": "ratio", "numerator": "missed",
                        "denominator": "due", **declared.get(name, {})}
                       for name in ("missed_rate", "cut_sessions"))]


def _store(folder: Path, definitions: list[dict]) -> ResultStore:
    store = ResultStore(folder, create=True)
    store.put("metrics", definitions)
    records = []
    for design, pairs in (("A", [(1, 4), (0, 4), (2, 4)]), ("B", [(0, 4), (0, 4), (1, 4)])):
        for user, (y, n) in enumerate(pairs):
            records.append(ReplicationRecord(design, user, "done", metrics={
                "missed": {"kind": "count", "total": y}, "due": {"kind": "count", "total": n},
                **{name: {"kind": "ratio", "value": y / n}
                   for name in ("missed_rate", "cut_sessions")}}))
    store.add_many(records)
    return store


def _shown(tmp_path: Path, declared: dict) -> dict[str, list[str]]:
    """Each ratio's cells in every table and sentence that shows it."""
    store = _store(tmp_path / "r", _definitions(declared))
    try:
        metrics = summary.summarise_design(store, "A", 1.0)
        difference = summary.compare_designs(store)
    finally:
        store.close()
    definitions = _definitions(declared)
    findings = key_findings(3, 1.0, metrics, definitions, {}, "A")
    spread = population_findings(metrics, None)
    out: dict[str, list[str]] = {}
    for name in ("missed_rate", "cut_sessions"):
        rows = [r[2:] for r in metric_rows(metrics) + per_user_rows(metrics)
                if r[0].split(" ")[0] == name]
        # (the share of users with any is a share of users: in percent whatever the metric)
        rows += [r[4:] for r in distribution_rows(metrics) if r[0].split(" ")[0] == name]
        cells = [c for r in rows for c in r]
        cells += list(comparison_rows({name: difference[name]})[0][1:5])
        cells += [s for s in findings + spread if s.lower().startswith(name.replace("_", " "))
                  or s.startswith(name)]
        cells += list(sweep._cells(name, metrics[name]))
        cells.append(describe_metric(next(d for d in definitions if d["name"] == name)))
        out[name] = cells
    return out


def test_a_declared_proportion_is_in_percent_whatever_its_name(tmp_path):
    shown = _shown(tmp_path, {"missed_rate": {"proportion": False},
                              "cut_sessions": {"proportion": True}})
    cut, missed = shown["cut_sessions"], shown["missed_rate"]
    # the estimate 3 of 12, its interval, the users' own values, the difference in points
    assert "25.00 %" in cut and any(c.startswith("[") and c.endswith(" %]") for c in cut)
    assert "-16.67 pp" in cut
    assert any("Shown as a percentage." in c for c in cut)
    # named like a rate, not declared one: a ratio, in no cell a percentage
    assert "0.25" in missed
    assert not [c for c in missed if PERCENT.search(c)], missed
    assert not any("Shown as a percentage." in c for c in missed)


def test_a_store_from_before_the_declaration_shows_plain_numbers(tmp_path):
    # no "proportion" in the stored definitions: every ratio is a ratio (its interval is the
    # ratio's, docs/evaluation.md), and so is what the tables show, whatever its name
    shown = _shown(tmp_path, {})
    for name in ("missed_rate", "cut_sessions"):
        assert "0.25" in shown[name]
        assert not [c for c in shown[name] if PERCENT.search(c)], shown[name]


def test_the_terminal_table_reads_the_declaration(tmp_path, capsys):
    text = SPEC.read_text(encoding="utf-8")
    missed = ('<opspec:Ratio Name="missed_rate" Numerator="doses_missed" '
              'Denominator="doses_due" Proportion="true"')
    assert text.count(missed) == 1
    cut = ('<opspec:Ratio Name="cut_sessions" Numerator="doses_missed" '
           'Denominator="doses_due" Proportion="true"/>\n      ')
    spec = tmp_path / "renamed.xpdl"
    spec.write_text(text.replace(missed, cut + missed.removesuffix(' Proportion="true"')),
                    encoding="utf-8")
    with without_report():
        status = main(["evaluate", str(spec), "--users", "3", "--days", "1", "--seed", "0",
                       "--workers", "1", "--user-model", str(USERS), "--quiet",
                       "--out", str(tmp_path / "o")])
    out = capsys.readouterr().out
    assert status == 0
    rows = {line.split()[0]: line for line in out.splitlines() if " ratio " in line}
    assert " %" in rows["cut_sessions"] and " %" in rows["taken_rate"]
    assert "%" not in rows["missed_rate"], rows["missed_rate"]


@pytest.mark.parametrize("declared", [True, False])
def test_a_sweeps_target_table_reads_the_declaration(declared):
    first = {"kind": "ratio", "value": 0.25, "ci95": [0.1, 0.4], "proportion": declared}
    summary_ = {"values": [{"metrics": {"cut_sessions": first}}]}
    answer = {"metric": "cut_sessions", "kind": "ratio", "users_share": None,
              "values": [{"text": "1", "estimate": 0.25, "ci95": [0.1, 0.4],
                          "verdict": "meets"}]}
    _, rows = sweep.target_table(answer, summary_)
    assert rows[0][1] == ("25.00 %" if declared else "0.25")
