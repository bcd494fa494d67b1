"""`opspec evaluate` refuses bad input before any simulation, with a message that says what,
where and how to fix it, and leaves nothing behind."""

from __future__ import annotations

import pytest
from evaluation_inputs import SPEC, USERS_TOML


@pytest.mark.parametrize("content, message", [
    ('[activities.hear_alarm]\nduration = { kind = "zipf", a = 2 }\n', "zipf"),
    ('[activities.hear_alarm]\nduration = { kind = "lognormal", median = -60, sigma = 0.6 }\n',
     "median"),
    ('[activities.hear_alarm]\nduration = 0\nomission = { probability = 1.5 }\n',
     "probability"),
], ids=["unknown-distribution", "negative-scale", "probability-above-1"])
def test_bad_user_model_stops_before_any_simulation(content, message, evaluate, tmp_path):
    model = tmp_path / "bad.users.toml"
    model.write_text(content, encoding="utf-8")
    out = tmp_path / "never"
    status, doc, err = evaluate(str(SPEC), "--user-model", str(model), "--out", str(out))
    assert status == 2 and doc is None
    assert str(model) in err and message in err
    assert not out.exists()


def test_model_not_covering_a_manual_activity_names_it(evaluate, tmp_path):
    text = USERS_TOML.read_text(encoding="utf-8")
    start = text.index("[activities.take_pill]")
    end = text.find("\n[", start + 1)
    model = tmp_path / "partial.users.toml"
    model.write_text(text[:start] + (text[end:] if end != -1 else ""), encoding="utf-8")
    status, _, err = evaluate(str(SPEC), "--user-model", str(model), "--out",
                              str(tmp_path / "x"))
    assert status == 2
    assert "take_pill" in err and str(model) in err


def test_unwritable_output_folder_is_a_clear_error(evaluate, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder", encoding="utf-8")
    status, _, err = evaluate(str(SPEC), "--users", "2", "--days", "1", "--out",
                              str(blocker / "out"))
    assert status == 2
    # said before anything is made: a file where a folder of --out would be
    assert f"{blocker} is a file, not a folder" in err and "Traceback" not in err
    # nothing was started there: the hint is about the folder, not about resuming a run
    assert "give a new or an existing folder" in err and "--resume" not in err


def test_existing_results_need_resume_and_resume_refuses_other_options(evaluate, tmp_path):
    out = str(tmp_path / "run")
    # drawn by the resume at the end
    assert evaluate(str(SPEC), "--users", "2", "--days", "1", "--out", out, report=False)[0] == 0
    status, _, err = evaluate(str(SPEC), "--users", "2", "--days", "1", "--out", out)
    assert status == 2 and "already holds an evaluation" in err
    status, _, err = evaluate(str(SPEC), "--users", "3", "--days", "1", "--out", out,
                              "--resume")
    assert status == 2 and "users" in err
    status, doc, _ = evaluate("--resume", "--out", out)
    assert status == 0 and doc["users"] == 2


def test_unknown_export_format_and_resume_without_out(evaluate, tmp_path):
    status, _, err = evaluate(str(SPEC), "--export", "csv", "--out", str(tmp_path / "e"))
    assert status == 2 and "xes, jsonl" in err
    status, _, err = evaluate("--resume")
    assert status == 2 and "--resume needs --out" in err


@pytest.mark.parametrize("args, message", [
    (["--users", "-3"], "--users must be a whole number >= 1"),
    (["--users", "0"], "--users must be a whole number >= 1"),
    (["--days", "-1"], "--days must be a positive number"),
    (["--days", "nan"], "--days must be a positive number"),
    (["--workers", "0"], "--workers must be >= 1"),
], ids=["negative-users", "no-users", "negative-days", "nan-days", "no-workers"])
def test_impossible_run_sizes_are_refused_before_anything_runs(args, message, evaluate,
                                                              tmp_path):
    out = tmp_path / "never"
    status, doc, err = evaluate(str(SPEC), *args, "--out", str(out))
    assert status == 2 and doc is None
    assert message in err
    assert not out.exists()


def test_broken_spec_stops_with_its_location_before_anything_runs(evaluate, tmp_path):
    broken = tmp_path / "broken.xpdl"
    broken.write_text(SPEC.read_text(encoding="utf-8").replace("</Activities>", "", 1),
                      encoding="utf-8")
    out = tmp_path / "never"
    status, doc, err = evaluate(str(broken), "--user-model", str(USERS_TOML), "--out",
                                str(out))
    assert status == 1 and doc is None
    assert f"{broken}:" in err and "Traceback" not in err
    assert not out.exists()


def test_resume_refuses_a_spec_changed_since_the_run_started(evaluate, tmp_path):
    spec = tmp_path / "dispenser.xpdl"
    spec.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")
    out = str(tmp_path / "run")
    assert evaluate(str(spec), "--users", "2", "--days", "1", "--user-model",
                    str(USERS_TOML), "--out", out, report=False)[0] == 0
    spec.write_text(SPEC.read_text(encoding="utf-8").replace("PT300S", "PT600S"),
                    encoding="utf-8")
    status, _, err = evaluate("--resume", "--out", out)
    assert status == 2 and f"{spec} changed since the run started" in err


def test_unreachable_scheduler_is_a_clear_error_before_anything_is_written(evaluate, tmp_path,
                                                                          monkeypatch):
    pytest.importorskip("distributed")
    import socket

    from opspec.evaluation import runner

    monkeypatch.setattr(runner, "SCHEDULER_TIMEOUT", 1)
    with socket.socket() as sock:            # a port nobody listens on
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    out = tmp_path / "never"
    status, doc, err = evaluate(str(SPEC), "--users", "2", "--days", "1", "--scheduler",
                                f"tcp://127.0.0.1:{port}", "--out", str(out))
    assert status == 2 and doc is None
    assert f"cannot reach the Dask scheduler at tcp://127.0.0.1:{port}" in err
    assert not out.exists()


def test_a_damaged_result_store_says_so_and_how_to_go_on(evaluate, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.sqlite").write_bytes(b"this is not an SQLite database " * 40)
    status, doc, err = evaluate("--resume", "--out", str(out))
    assert status == 2 and doc is None
    assert "results.sqlite: cannot open the result database: file is not a database" in err
    assert "damaged" in err and "another --out" in err and "Traceback" not in err


def test_a_spec_with_a_user_lane_and_no_model_lists_the_presets(evaluate, tmp_path):
    spec = tmp_path / "lonely.xpdl"
    spec.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")   # no companion model
    status, _, err = evaluate(str(spec), "--users", "2", "--out", str(tmp_path / "o"))
    assert status == 2
    assert "no user model was given" in err and "dispenser-reference" in err
