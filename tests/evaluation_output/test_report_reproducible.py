"""A reader of the report can reproduce it: "What was run" gives the SHA-256 of the spec and
of the user model (the store kept them; the report did not say them) and the command that
runs the evaluation again, which gives the same results in another folder."""

from __future__ import annotations

import hashlib
import shlex
import sqlite3
from pathlib import Path

import pytest
from lxml import html as lxml_html

from opspec.cli import main
from opspec.evaluation.run_command import rerun_command

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"


def _run_table(report: Path) -> dict[str, str]:
    """The rows of the table under the heading "What was run": parameter -> value."""
    page = lxml_html.fromstring(report.read_bytes())
    (heading,) = [h for h in page.iter("h2") if h.text_content().strip() == "What was run"]
    table = next(heading.itersiblings()).xpath("following::table[1]")[0]
    return {" ".join(tr[0].text_content().split()): " ".join(tr[1].text_content().split())
            for tr in table.find("tbody").iter("tr")}


def _results(out: Path) -> list[tuple[object, ...]]:
    with sqlite3.connect(out / "results.sqlite") as db:
        return db.execute("SELECT design, user, status, metrics FROM replication "
                          "ORDER BY design, user").fetchall()


def test_the_report_names_the_files_digests_and_a_command_that_reproduces_it(
        tmp_path: Path, capsys) -> None:
    out = tmp_path / "first"
    assert main(["evaluate", str(SPEC), "--users", "3", "--days", "0.5", "--seed", "5",
                 "--workers", "1", "--out", str(out), "--quiet"]) == 0
    rows = _run_table(out / "report.html")
    assert rows["specification SHA-256"] == hashlib.sha256(SPEC.read_bytes()).hexdigest()
    assert rows["user model SHA-256"] == hashlib.sha256(USERS.read_bytes()).hexdigest()
    command = shlex.split(rows["command (the same results with any --workers)"])
    assert command[:2] == ["opspec", "evaluate"] and "--workers" not in command
    again = tmp_path / "again"
    assert main([*command[1:], "--workers", "2", "--out", str(again), "--quiet"]) == 0
    assert _results(again) == _results(out)
    md = (again / "report.md").read_text(encoding="utf-8")
    assert "specification SHA-256" in md and "--seed 5" in md


PLAN = {"designs": [{"label": "A", "spec": "a b.xpdl", "sha256": "0"},
                    {"label": "B", "spec": "b.xpdl", "sha256": "1"}],
        "users": 7, "days": 0.25, "seed": 3, "user_model": "u.toml", "engine": {},
        "export": ["xes"], "case": "user",
        "branches": {"gw": {"yes": 0.75, "no": 0.25}}}


def test_the_command_says_every_option_of_the_plan_or_nothing() -> None:
    assert shlex.split(rerun_command(PLAN) or "") == [
        "opspec", "evaluate", "a b.xpdl", "--compare", "b.xpdl", "--users", "7",
        "--days", "0.25", "--seed", "3", "--user-model", "u.toml",
        "--branch", "gw=yes:0.75,no:0.25", "--export", "xes", "--case", "user"]
    fixed = {**PLAN, "designs": [{**d, "parameters": [["spec.score", 40]]}
                                 for d in PLAN["designs"]]}
    assert "--param score=40" in (rerun_command(fixed) or "")
    thirds = {**PLAN, "days": 1 / 3}
    assert float(shlex.split(rerun_command(thirds) or "")[8]) == 1 / 3
    for more in ({"engine": {"workers": 2}}, {"run_inputs": {"draws": [["x", {}, False]]}},
                 {"input_uncertainty": 4}):
        assert rerun_command({**PLAN, **more}) is None, more
    assert rerun_command(PLAN, swept=True) is None


@pytest.mark.parametrize("days", [2.0, 0.5, 1 / 3, 30.0])
def test_days_are_written_exactly(days: float) -> None:
    words = shlex.split(rerun_command({**PLAN, "days": days}) or "")
    assert float(words[words.index("--days") + 1]) == days


def test_json_names_the_files_digests_and_opspecs_version(tmp_path: Path, capsys) -> None:
    import json

    from opspec import __version__

    assert main(["evaluate", str(SPEC), "--compare", str(SPEC.with_suffix(".bpmn")),
                 "--users", "2", "--days", "0.25", "--workers", "1",
                 "--out", str(tmp_path / "run"), "--quiet", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["spec_sha256"] == hashlib.sha256(SPEC.read_bytes()).hexdigest()
    assert doc["user_model_sha256"] == hashlib.sha256(USERS.read_bytes()).hexdigest()
    assert doc["opspec_version"] == __version__
    assert doc["compare"]["spec_sha256"] == hashlib.sha256(
        SPEC.with_suffix(".bpmn").read_bytes()).hexdigest()


def test_the_report_names_the_numpy_its_random_numbers_came_from(tmp_path: Path) -> None:
    """NumPy may change a Generator's numbers between versions (NEP 19): reproducing a
    run's numbers needs its NumPy, which the report now names."""
    import platform

    import numpy

    out = tmp_path / "run"
    assert main(["evaluate", str(SPEC), "--users", "2", "--days", "0.25", "--workers", "1",
                 "--out", str(out), "--quiet"]) == 0
    rows = _run_table(out / "report.html")
    assert rows["Python and NumPy versions"] == (
        f"Python {platform.python_version()}, NumPy {numpy.__version__}")
