"""The behaviour-based specs: the vacuum cleaner, the toy sumo and the medication cart run in
their simulated worlds with outcomes that mean something; the vacuum and the sumo differ only
in their manoeuvre; the mode change happens when the battery says so."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any

import pytest

from opspec.cli import main
from opspec.engine.compiled import compile_package
from opspec.engine.simulation import Simulation
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"
sys.path.insert(0, str(ROOT / "tests" / "preprocess"))
from builtin_models import without_locations

from opspec.worlds import world_performers


def run_spec(path: Path, until: float, seed: int = 0, **kw: Any) -> Any:
    compiled = compile_package(open_spec(path))
    sim = Simulation(compiled, performers=world_performers(compiled, seed=seed, user=0),
                     seed=seed, **kw)
    return sim.run(until=until)


def totals(result: Any) -> dict[str, Any]:
    return {name: m.get("total", m.get("value", m.get("n"))) for name, m in result.metrics.items()}


def test_vacuum_and_sumo_differ_only_in_the_manoeuvre_graph():
    vacuum = open_spec(SPECS / "vacuum_cleaner.xpdl")
    sumo = open_spec(SPECS / "toy_sumo.xpdl")
    assert [p.id for p in vacuum.processes] == [p.id for p in sumo.processes]
    differing = [p.id for p, q in zip(vacuum.processes, sumo.processes, strict=True)
                 if without_locations(p) != without_locations(q)]
    assert differing == ["manoeuvre"]
    assert without_locations(vacuum.data_fields) == without_locations(sumo.data_fields)
    assert without_locations(vacuum.applications) == without_locations(sumo.applications)
    vac_steps = {a.id for a in vacuum.process("manoeuvre").activities}
    sumo_steps = {a.id for a in sumo.process("manoeuvre").activities}
    assert vac_steps - sumo_steps == {"back_up", "random_move"}
    assert sumo_steps - vac_steps == {
        "move_back", "opponent_ahead", "range_says_charge", "range_abstains", "range_voted",
        "on_rim", "line_says_turn", "line_says_charge", "line_voted", "choose_hit", "hit"}
    # the header may differ in its world (and world file) and metrics, nothing else
    assert (vacuum.id, vacuum.modes) == ("vacuum_cleaner", sumo.modes)
    assert without_locations(vacuum.participants) == without_locations(sumo.participants)


def test_vacuum_covers_a_good_part_of_the_room_in_five_minutes():
    result = run_spec(SPECS / "vacuum_cleaner.xpdl", until=300)
    metrics = totals(result)
    cells = 20 * 16                      # 5 m x 4 m room in 25 cm cells
    assert metrics["cells_covered"] / cells > 0.35
    assert metrics["collisions"] >= 1 and metrics["manoeuvres"] >= 1
    assert result.summary["deadlocks"] == []


def test_a_collision_is_answered_by_backing_up_first(tmp_path):
    result = run_spec(SPECS / "vacuum_cleaner.xpdl", until=120, keep_trace=True)
    trace = result.trace
    first_hit = next(e for e in trace if e.kind == "world.collision")
    back = next(e for e in trace if e.kind == "activity.started" and e.activity == "back_up"
                and e.time >= first_hit.time)
    # the manoeuvre workflow runs at 5 Hz: it reacts within one period of the bump read
    assert back.time - first_hit.time <= 0.45
    commands = [e.data.get("motor_cmd") for e in trace
                if e.kind == "data.changed" and "motor_cmd" in (e.data or {})]
    assert "back" in commands


def test_battery_low_changes_mode_to_dock_at_the_right_time(tmp_path):
    spec = tmp_path / "vacuum.xpdl"
    text = (SPECS / "vacuum_cleaner.xpdl").read_text(encoding="utf-8")
    spec.write_text(text.replace(
        '<ExtendedAttribute Name="opspec:World" Value="vacuum-room"/>',
        '<ExtendedAttribute Name="opspec:World" Value="vacuum-room"/>'
        '<ExtendedAttribute Name="opspec:WorldFile" Value="fast_drain.toml"/>'),
        encoding="utf-8")
    (tmp_path / "fast_drain.toml").write_text("drain_per_s = 1.0\n", encoding="utf-8")
    result = run_spec(spec, until=120, keep_trace=True)
    # level = 100 - t: the battery workflow (every 10 s) reads the battery after its 1 ms of
    # CPU demand, so the instance started at 80 s reads 19.999 % < 20 % at 80.001 s
    change = [e for e in result.trace if e.kind == "mode.changed"]
    assert [(e.time, e.data["to"]) for e in change] == [(pytest.approx(80.001), "dock")]
    assert result.summary["mode"] == "dock"
    after = [e for e in result.trace if e.kind == "process.started" and e.time > 80.001]
    assert after and {e.process for e in after} == {"dock"}


def test_sumo_wins_some_bouts_by_moving_back_and_hitting():
    result = run_spec(SPECS / "toy_sumo.xpdl", until=600)
    metrics = totals(result)
    assert metrics["bouts"] >= 5
    assert metrics["bouts_won"] >= 1
    assert metrics["manoeuvres"] >= 1
    assert 0.0 < metrics["win_rate"] <= 1.0


def test_medication_cart_finds_the_patient():
    result = run_spec(SPECS / "medication_cart_guidance.xpdl", until=1200)
    assert result.metrics["patients_found"]["total"] == 1
    assert 30.0 < result.metrics["time_to_find_s"]["mean"] < 600.0


def test_each_simulated_user_gets_a_world_of_their_own_and_seeds_repeat():
    compiled = compile_package(open_spec(SPECS / "vacuum_cleaner.xpdl"))

    def covered(seed: int, user: int) -> int:
        sim = Simulation(compiled, performers=world_performers(compiled, seed=seed, user=user),
                         seed=seed, scope=(user,))
        return sim.run(until=120).metrics["cells_covered"]["total"]

    assert covered(1, 0) == covered(1, 0)
    assert len({covered(1, u) for u in range(4)}) > 1


def test_unknown_world_is_an_error_naming_the_known_ones(tmp_path, capsys):
    spec = tmp_path / "bad.xpdl"
    spec.write_text((SPECS / "vacuum_cleaner.xpdl").read_text(encoding="utf-8").replace(
        'Value="vacuum-room"', 'Value="moon-base"'), encoding="utf-8")
    assert main(["run", str(spec), "--until", "10"]) == 2
    err = capsys.readouterr().err
    assert "moon-base" in err and "vacuum-room" in err and "sumo-ring" in err


def _evaluate(args: list[str], *, report: bool) -> int:
    """``opspec evaluate``; with ``report=False`` the report is not drawn (it is not engine
    code: the same from source and compiled, and these tests read the numbers)."""
    with pytest.MonkeyPatch.context() as patch:
        if not report:
            patch.setattr("opspec.evaluation.report.write_report",
                          lambda store, *_args, **_kwargs: store.folder / "report.html")
        return main(["evaluate", *args])


#: the pass from source (scripts/test.sh) draws no report: the compiled pass draws each
FROM_SOURCE = os.environ.get("OPSPEC_PURE_PYTHON") == "1"


def test_evaluate_runs_the_vacuum_with_its_own_metrics(tmp_path, capsys):
    # no report: tests/evaluation/test_evaluate.py draws the vacuum's
    status = _evaluate([str(SPECS / "vacuum_cleaner.xpdl"), "--users", "3", "--days",
                        "0.002", "--workers", "1", "--json", "--out", str(tmp_path / "ev")],
                       report=False)
    doc = json.loads(capsys.readouterr().out)
    assert status == 0
    assert doc["metrics"]["cells_covered"]["total"] > 0
    assert doc["metrics"]["collisions"]["kind"] == "count"


@pytest.mark.parametrize("spec, metrics", [
    ("toy_sumo.xpdl", {"bouts": "count", "bouts_won": "count", "win_rate": "ratio"}),
    ("medication_cart_guidance.xpdl", {"patients_found": "count", "time_to_find_s": "duration",
                                       "collisions": "count"}),
], ids=["sumo", "cart"])
def test_evaluate_runs_the_sumo_and_the_cart_with_their_own_metrics(tmp_path, capsys, spec,
                                                                   metrics):
    status = _evaluate([str(SPECS / spec), "--users", "2", "--days", "0.002",
                        "--workers", "1", "--json", "--out", str(tmp_path / "ev")],
                       report=not FROM_SOURCE)
    doc = json.loads(capsys.readouterr().out)
    assert status == 0
    assert {name: doc["metrics"][name]["kind"] for name in metrics} == metrics
    if spec == "toy_sumo.xpdl":
        assert doc["metrics"]["bouts"]["total"] >= 1
    else:
        assert doc["metrics"]["patients_found"]["total"] >= 1
