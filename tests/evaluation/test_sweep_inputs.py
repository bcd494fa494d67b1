"""`opspec evaluate --sweep`: bad parameter names, values and targets are refused before
anything runs (exit 2, nothing created) with what to do; `--sweep list` lists the names;
the report draws the sweep; `--resume` finishes and reports a sweep."""

from __future__ import annotations

import sqlite3

from evaluation_inputs import SPEC, USERS_TOML

from opspec.cli import main

ROOT = SPEC.parents[1]
POPULATION = ROOT / "specs" / "medication_dispenser.population.toml"


def refused(capsys, tmp_path, *args: str) -> str:
    out = tmp_path / "never"
    try:
        status = main(["evaluate", str(SPEC), "--users", "2", "--days", "0.5", "--out",
                       str(out), "--quiet", *args])
    except SystemExit as stop:                  # argparse's usage errors
        status = stop.code
    err = capsys.readouterr().err
    assert status == 2, err
    assert not out.exists()
    assert "Traceback" not in err
    return err


def test_a_misspelt_parameter_gets_did_you_mean_and_the_list(capsys, tmp_path):
    err = refused(capsys, tmp_path, "--sweep", "spec.notify_workflow.wait_report.dedline=3min,5min")
    assert "did you mean spec.notify_workflow.wait_report.deadline?" in err
    assert "sweepable: " in err and "user.activities.hear_alarm.omission.probability" in err
    err = refused(capsys, tmp_path, "--sweep", "activities.hear_alarm.omission.probability=0.1,0.2")
    assert "did you mean user.activities.hear_alarm.omission.probability" in err


def test_a_value_that_does_not_parse_names_the_parameter_and_the_unit(capsys, tmp_path):
    err = refused(capsys, tmp_path, "--sweep", "spec.notify_workflow.wait_report.deadline=3min,fast")
    assert "spec.notify_workflow.wait_report.deadline: cannot read 'fast'" in err
    assert "expected a duration" in err and "5 min" in err
    err = refused(capsys, tmp_path, "--sweep", "user.activities.hear_alarm.omission=0.1,1.5")
    assert "cannot read '1.5'" in err and "a probability" in err
    err = refused(capsys, tmp_path, "--sweep", "user.activities.hear_alarm.omission=0.1,10%")
    assert "same value" in err
    err = refused(capsys, tmp_path, "--sweep", "user.activities.walk_to_dispenser.duration.sigma="
                  "0.6,-1")
    assert "sigma" in err and "must be" in err                    # the model's own check
    err = refused(capsys, tmp_path, "--sweep", "user.activities.hear_alarm.omission")
    assert "PARAM=v1,v2" in err


def test_targets_are_checked_before_the_run(capsys, tmp_path):
    sweep = ("--sweep", "user.activities.hear_alarm.omission=0.1,0.2")
    err = refused(capsys, tmp_path, *sweep, "--target", "missed_rat < 1%")
    assert "did you mean missed_rate?" in err
    err = refused(capsys, tmp_path, *sweep, "--target", "report_latency_s < soon")
    assert "expected a duration" in err
    err = refused(capsys, tmp_path, *sweep, "--target", "missed_rate about 1%")
    assert "METRIC OP VALUE" in err
    err = refused(capsys, tmp_path, "--target", "missed_rate < 1%")
    assert "answer a sweep" in err
    err = refused(capsys, tmp_path, *sweep, "--compare", str(SPEC))
    assert "cannot be combined" in err


def test_a_population_parameter_drawn_per_user_is_not_swept_but_a_modifier_is(capsys,
                                                                              tmp_path):
    err = refused(capsys, tmp_path, "--user-model", str(POPULATION), "--sweep",
                  "user.activities.hear_alarm.omission=0.1,0.2")
    assert "draws this parameter per user" in err and "user.modifier.notice_factor" in err
    status = main(["evaluate", str(SPEC), "--user-model", str(POPULATION), "--users", "6",
                   "--days", "1", "--workers", "1", "--out", str(tmp_path / "pop"), "--quiet",
                   "--sweep", "user.modifier.duration_factor=1,2"])
    assert status == 0
    assert "sweep of user.modifier.duration_factor" in capsys.readouterr().out


def test_sweep_list_prints_every_parameter_with_its_unit_and_value(capsys, tmp_path):
    status = main(["evaluate", str(SPEC), "--sweep", "list", "--out", str(tmp_path / "x")])
    out = capsys.readouterr().out
    assert status == 0 and not (tmp_path / "x").exists()
    line = next(x for x in out.splitlines() if "wait_report.deadline" in x)
    assert "duration" in line and "5 min" in line
    assert "user.activities.walk_to_dispenser.duration.median" in out
    # a derived value is written as a person writes it, not as 1.19722 min
    mean = next(x for x in out.splitlines() if "walk_to_dispenser.duration.mean" in x)
    assert "1 min 11.833 s" in mean


def test_the_report_draws_the_sweep_and_resume_reports_it_again(capsys, tmp_path):
    out = tmp_path / "run"
    args = ["evaluate", str(SPEC), "--user-model", str(USERS_TOML), "--users", "4", "--days",
            "1", "--workers", "1", "--out", str(out), "--quiet", "--sweep",
            "spec.notify_workflow.wait_report.deadline=3min,5min", "--target",
            "missed_rate < 1%"]
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "target missed_rate < 1%" in printed
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "Sweep of spec.notify_workflow.wait_report.deadline" in html
    assert (out / "figures" / "sweep.svg").stat().st_size > 10_000
    with sqlite3.connect(out / "results.sqlite") as db:
        designs = [d for (d,) in db.execute("SELECT DISTINCT design FROM replication "
                                            "ORDER BY design")]
    assert designs == ["A", "S1"]
    (out / "report.html").unlink()
    assert main(["evaluate", "--resume", "--out", str(out), "--quiet"]) == 0
    assert "Sweep of spec.notify" in (out / "report.html").read_text(encoding="utf-8")
    capsys.readouterr()
    status = main(["evaluate", "--resume", "--out", str(out), "--quiet", "--sweep",
                   "spec.notify_workflow.wait_report.deadline=3min,10min"])
    assert status == 2
    assert "cannot resume it with --sweep" in capsys.readouterr().err
