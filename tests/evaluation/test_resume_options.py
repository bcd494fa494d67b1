"""`opspec evaluate --resume` refuses options that differ from the stored run, naming each
with both values (issue 20: `--users` was silently ignored), and a Dask cluster without
workers is an error after a timeout, never a hang."""

from __future__ import annotations

import contextlib
import io
import json
import shutil
import sqlite3
import threading
import time

import pytest
from evaluation_inputs import SPEC, USERS_TOML, metrics_of
from evaluate_without_report import without_report

from opspec.cli import main


@pytest.fixture(scope="module")
def stored_once(tmp_path_factory):
    """A finished run of 3 users x 1 day, seed 5, the companion user model: evaluated once
    for the module and copied for each test. These tests are about what a resume accepts:
    no report is drawn (tests/evaluate_without_report.py)."""
    out = tmp_path_factory.mktemp("stored") / "run"
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr), \
            without_report():
        status = main(["evaluate", str(SPEC), "--users", "3", "--days", "1", "--seed", "5",
                       "--out", str(out), "--workers", "1", "--json"])
    assert status == 0, stderr.getvalue()
    return out, json.loads(stdout.getvalue())


@pytest.fixture
def stored(stored_once, tmp_path):
    """A test's own copy of the finished run (a test may resume or change it)."""
    original, doc = stored_once
    out = tmp_path / "run"
    shutil.copytree(original, out)
    return out, doc


def replications(out) -> int:
    with sqlite3.connect(out / "results.sqlite") as conn:
        return conn.execute("SELECT COUNT(*) FROM replication").fetchone()[0]


@pytest.mark.parametrize(("given", "named"), [
    (["--users", "8"], "--users 8 (stored: 3)"),
    (["--days", "2"], "--days 2 (stored: 1)"),
    (["--seed", "6"], "--seed 6 (stored: 5)"),
    (["--user-model", "average"], f"--user-model average (stored: {USERS_TOML})"),
    (["--export", "jsonl"], "--export jsonl (stored: none)"),
], ids=["users", "days", "seed", "user-model", "export"])
@pytest.mark.parametrize("with_spec", [False, True], ids=["no-spec", "spec"])
def test_a_differing_option_is_refused_naming_both_values(stored, evaluate, given, named,
                                                          with_spec):
    out, _ = stored
    spec = [str(SPEC)] if with_spec else []
    status, doc, err = evaluate(*spec, "--resume", "--out", str(out), *given)
    assert status == 2 and doc is None
    assert named in err, err
    assert err.count("(stored:") == 1, "only the option that differs is named"
    assert f"opspec evaluate --resume --out {out}" in err
    assert replications(out) == 3                      # nothing was run or changed


def test_several_differences_are_all_named(stored, evaluate):
    out, _ = stored
    status, _, err = evaluate("--resume", "--out", str(out), "--users", "4", "--seed", "1")
    assert status == 2
    assert "--users 4 (stored: 3)" in err and "--seed 1 (stored: 5)" in err


def test_another_spec_is_refused(stored, evaluate, tmp_path):
    out, _ = stored
    other = tmp_path / "other.xpdl"
    shutil.copy(SPEC, other)
    status, _, err = evaluate(str(other), "--resume", "--out", str(out))
    assert status == 2 and f"SPEC {other} (stored: {SPEC})" in err


def test_the_same_options_spelled_out_resume(stored, evaluate, monkeypatch):
    out, doc = stored
    monkeypatch.chdir(SPEC.parents[1])
    status, again, err = evaluate(f"./specs/{SPEC.name}", "--resume", "--out", str(out),
                                  "--users", "3", "--days", "1", "--seed", "5",
                                  "--user-model", str(USERS_TOML), report=False)
    assert status == 0, err
    assert metrics_of(again) == metrics_of(doc)


def test_a_changed_user_model_file_is_refused_with_both_digests(tmp_path, evaluate):
    model = tmp_path / "users.toml"
    shutil.copy(USERS_TOML, model)
    out = tmp_path / "run"
    assert evaluate(str(SPEC), "--users", "2", "--days", "1", "--user-model", str(model),
                    "--out", str(out), report=False)[0] == 0
    model.write_text(USERS_TOML.read_text(encoding="utf-8") + "\n# edited\n",
                     encoding="utf-8")
    status, _, err = evaluate("--resume", "--out", str(out))
    assert status == 2
    assert f"{model} changed since the run started" in err
    assert "SHA-256 is now" in err and "the stored run's" in err


def _bounded(args: list[str], seconds: float) -> tuple[int | None, float]:
    """Run ``main(args)`` in a thread; (status or None if still running, seconds taken)."""
    result: list[int] = []
    thread = threading.Thread(target=lambda: result.append(main(args)), daemon=True)
    start = time.monotonic()
    thread.start()
    thread.join(seconds)
    return (result[0] if result else None), time.monotonic() - start


def test_a_cluster_without_workers_fails_after_the_timeout(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    out = tmp_path / "dask"
    with distributed.LocalCluster(n_workers=0, processes=False,
                                  dashboard_address=None) as cluster:
        status, took = _bounded(["evaluate", str(SPEC), "--users", "2", "--days", "1",
                                 "--scheduler", cluster.scheduler_address,
                                 "--scheduler-timeout", "2", "--out", str(out), "--quiet"],
                                seconds=90)
    assert status is not None, "evaluate hung on a cluster without workers"
    err = capsys.readouterr().err
    assert status == 2, err
    assert "has no workers: none joined in 2 s" in err and "dask worker" in err
    assert took < 60
    assert not out.exists(), "nothing is created before the cluster can run anything"


class _Cluster:
    """A stand-in Dask client whose workers are all gone."""

    def nthreads(self) -> dict[str, int]:
        return {}


def test_a_cluster_whose_workers_all_left_stops_the_run(monkeypatch):
    from opspec.errors import EvaluationError
    from opspec.evaluation import runner

    now = [100.0]
    monkeypatch.setattr(runner.time, "monotonic", lambda: now[0])
    watch = runner._ClusterWatch(_Cluster(), "tcp://cluster:8786", timeout=30)
    watch()                                   # first look: no workers since now
    now[0] += 29
    watch()                                   # still within the timeout
    now[0] += 2
    with pytest.raises(EvaluationError, match=r"tcp://cluster:8786 has no workers: none "
                       r"came back in 30 s"):
        watch()
