"""`opspec evaluate --input-uncertainty B`: a fitted model's parameter uncertainty carried
into the evaluation (issue 19; docs/evaluation.md, "Input uncertainty").

The evidence that the widened interval is right is by simulation against a truth nobody here
wrote - the closed form of the reference scenario (../shared/bench/analytic.py) for the TRUE
user model a person's trace was recorded from: the slow test below, and
benchmarks/input_uncertainty_coverage.py for the full table.
"""

from __future__ import annotations

import contextlib
import io
import sqlite3
from pathlib import Path

import numpy as np
import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
SHARED = ROOT.parent / "shared" / "bench" / "analytic.py"


@pytest.fixture(scope="module")
def fitted(tmp_path_factory) -> Path:
    """A model fitted to 4 days of one person following the reference user (with 30
    bootstrap redraws)."""
    folder = tmp_path_factory.mktemp("fitted")
    trace, model = folder / "person.jsonl", folder / "person.users.toml"
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["run", str(SPEC), "--user-model", "dispenser-reference", "--days", "4",
                     "--seed", "11", "--trace", str(trace), "--timeline", "none"]) in (0, 1)
        assert main(["fit", str(trace), "-o", str(model), "--draws", "30"]) == 0
    return model


def _rows(folder: Path, design: str) -> list[tuple]:
    with sqlite3.connect(folder / "results.sqlite") as db:
        return db.execute("SELECT user, status, metrics FROM replication WHERE design = ? "
                          "ORDER BY user", (design,)).fetchall()


def test_draws_leave_the_ordinary_results_as_they_were(evaluate, fitted, tmp_path) -> None:
    common = [str(SPEC), "--user-model", str(fitted), "--users", "8", "--days", "2",
              "--quiet"]
    status, plain, _ = evaluate(*common, "--out", str(tmp_path / "plain"), "--workers", "1",
                                report=False)
    assert status == 0 and plain["input_uncertainty"] is None
    status, doc, _ = evaluate(*common, "--out", str(tmp_path / "iu"), "--workers", "1",
                              "--input-uncertainty", "6", "--users-per-draw", "4")
    assert status == 0
    assert doc["metrics"] == plain["metrics"]
    assert _rows(tmp_path / "iu", "A") == _rows(tmp_path / "plain", "A")
    drawn = _rows(tmp_path / "iu", "A~draws")
    assert [u for u, _, _ in drawn] == list(range(8, 8 + 6 * 4))   # users after the 8
    summary = doc["input_uncertainty"]
    assert summary["draws"] == 6 and summary["users_per_draw"] == 4
    latency = summary["metrics"]["report_latency_s"]
    assert latency["ci95"] == plain["metrics"]["report_latency_s"]["ci95"]
    low, high = latency["ci95_with_parameters"]
    assert low <= latency["ci95"][0] and high >= latency["ci95"][1]
    assert 0 <= latency["parameter_share"] <= 1
    assert latency["variance"]["parameters"] >= 0
    rate = summary["metrics"]["taken_rate"]["ci95_with_parameters"]
    assert 0 <= rate[0] <= rate[1] <= 1
    # the widened interval contains the ordinary one, for every metric
    for name, entry in summary["metrics"].items():
        if entry["ci95"] and entry["ci95_with_parameters"]:
            (low, high), (wide_low, wide_high) = entry["ci95"], entry["ci95_with_parameters"]
            assert wide_low <= low and wide_high >= high, name


def test_only_a_declared_proportion_is_cut_at_one() -> None:
    """A count whose few users each had 0 or 1 events looks like a proportion; its ordinary
    interval ([0, 1.23] here) reaches past 1, and the widened one must contain it. Only the
    spec's declaration (Proportion="true" on a ratio) makes a metric a proportion, as in the
    ordinary summary; even then the cut never falls below the ordinary interval."""
    from opspec.evaluation.input_uncertainty import _combine, _proportion

    assert not _proportion({"kind": "count", "name": "doses_missed"})
    assert not _proportion({"kind": "ratio", "proportion": False})
    assert _proportion({"kind": "ratio", "proportion": True})
    batches = [(0.2, 0.1), (0.6, 0.1), (0.4, 0.1)]
    for proportion in (False, True):
        out = _combine(0.33, [0.0, 1.23], 0.1, 3, batches, 0.95, proportion=proportion)
        low, high = out["ci95_with_parameters"]
        assert low <= 0.0 and high >= 1.23


def test_the_same_seed_gives_the_same_draws_whatever_the_workers(evaluate, fitted,
                                                                   tmp_path) -> None:
    common = [str(SPEC), "--user-model", str(fitted), "--users", "6", "--days", "1",
              "--quiet", "--input-uncertainty", "5", "--users-per-draw", "3"]
    one = evaluate(*common, "--out", str(tmp_path / "one"), "--workers", "1", report=False)[1]
    two = evaluate(*common, "--out", str(tmp_path / "two"), "--workers", "2", report=False)[1]
    assert one["input_uncertainty"] == two["input_uncertainty"]
    assert _rows(tmp_path / "one", "A~draws") == _rows(tmp_path / "two", "A~draws")


def test_a_comparison_gets_widened_paired_differences(evaluate, fitted, tmp_path) -> None:
    four = tmp_path / "four.xpdl"
    four.write_text(SPEC.read_text(encoding="utf-8").replace(
        "<Expression>alarms &lt; 3</Expression>", "<Expression>alarms &lt; 4</Expression>"),
        encoding="utf-8")
    status, doc, _ = evaluate(str(SPEC), "--compare", str(four), "--user-model", str(fitted),
                              "--users", "6", "--days", "2", "--quiet", "--out",
                              str(tmp_path / "c"), "--input-uncertainty", "4",
                              "--users-per-draw", "3")
    assert status == 0
    diff = doc["input_uncertainty"]["difference"]["alarms_per_dose"]
    assert diff["ci95"] == doc["compare"]["difference"]["alarms_per_dose"]["ci95"]
    assert diff["ci95_with_parameters"] is not None
    # B's draws run the same users with the same draws as A's (paired)
    assert ([u for u, _, _ in _rows(tmp_path / "c", "B~draws")]
            == [u for u, _, _ in _rows(tmp_path / "c", "A~draws")])


def test_what_cannot_be_honoured_is_refused(evaluate, fitted, tmp_path) -> None:
    base = [str(SPEC), "--users", "4", "--days", "1", "--quiet"]
    status, _, err = evaluate(*base, "--user-model", "dispenser-reference",
                              "--input-uncertainty", "5", "--out", str(tmp_path / "a"))
    assert status == 2 and "holds no parameter draws" in err and "opspec fit" in err
    status, _, err = evaluate(*base, "--user-model", str(fitted), "--input-uncertainty",
                              "31", "--out", str(tmp_path / "b"))
    assert status == 2 and "holds 30 parameter draws" in err and "--draws 31" in err
    status, _, err = evaluate(*base, "--user-model", str(fitted), "--input-uncertainty", "1",
                              "--out", str(tmp_path / "c"))
    assert status == 2 and "at least 2 draws" in err
    status, _, err = evaluate(*base, "--user-model", str(fitted), "--users-per-draw", "3",
                              "--out", str(tmp_path / "d"))
    assert status == 2 and "goes with --input-uncertainty" in err
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()
    # resuming with another number of draws would mix two runs
    status, _, _ = evaluate(*base, "--user-model", str(fitted), "--input-uncertainty", "3",
                            "--users-per-draw", "2", "--out", str(tmp_path / "e"),
                            report=False)      # the resume below draws it
    assert status == 0
    status, _, err = evaluate("--resume", "--out", str(tmp_path / "e"),
                              "--input-uncertainty", "4")
    assert status == 2 and "--input-uncertainty 4 (stored: 3)" in err
    status, doc, _ = evaluate("--resume", "--out", str(tmp_path / "e"))
    assert status == 0 and doc["input_uncertainty"]["draws"] == 3


def test_the_variance_split_recovers_known_components() -> None:
    """Batches whose true values differ by N(0, 2^2) (the parameters) and whose estimates
    carry simulation noise of known variance: the random-effects split returns about 4 for
    the parameters, not 4 + the noise, and the widened interval's variance is se^2 + 4."""
    from opspec.evaluation.input_uncertainty import _combine

    rng = np.random.default_rng(3)
    noise = rng.uniform(0.5, 1.5, 2000)            # each batch's own simulation variance
    values = 10 + rng.normal(0, 2, 2000) + rng.normal(0, np.sqrt(noise))
    out = _combine(10.0, [9.9, 10.1], 0.0025, 1000, list(zip(values, noise, strict=True)),
                   0.95)
    assert out["variance"]["parameters"] == pytest.approx(4.0, rel=0.1)
    assert out["variance"]["between_draws"] == pytest.approx(5.0, rel=0.1)
    low, high = out["ci95_with_parameters"]
    assert (high - low) / 2 == pytest.approx(1.96 * np.sqrt(4.0025), rel=0.1)
    assert out["parameter_share"] == pytest.approx(4 / 4.0025, abs=0.01)



@pytest.mark.slow
@pytest.mark.skipif(not SHARED.is_file(), reason="needs ../shared/bench (the closed form)")
def test_widened_intervals_cover_the_true_models_metric(load_benchmark) -> None:
    """40 repetitions of: record 7 days of one person following the reference user (about
    28 walks and 33 alarms), fit, evaluate 40 users x 5 days with 20 parameter draws x 10
    users. The truth is the closed
    form for the reference (true) parameters. The ordinary intervals, which take the fitted
    parameters for the truth, cover it far less often than 95 %; the widened ones cover it
    about as often as they say."""
    result = load_benchmark("input_uncertainty_coverage").run(repetitions=40, trace_days=7.0, users=40, days=5.0, draws=20,
                              per_draw=10, workers=1, seed0=41_000)
    rows = {r["metric"]: r for r in result["table"]}
    for metric in ("alarms_per_dose", "report_latency_s"):
        row = rows[metric]
        assert row["ci95_with_parameters"] >= 0.85, row
        assert row["ci95"] <= 0.6, row
        assert row["mean_parameter_share"] > 0.8, row
