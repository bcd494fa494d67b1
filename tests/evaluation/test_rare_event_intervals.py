"""Honest intervals for rare events (issue 19): with no missed dose among 10 users x 1 day,
the missed rate's 95 % interval still has a positive upper bound — the Wilson score bound
for 0 of n, (z²/n) / (1 + z²/n) = 8.76 % for n = 40 (Newcombe 1998) — and the count per user
the exact Poisson (Garwood) bound, 3.689 events over 10 users; never [0, 0]."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def summary(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """The metrics of `opspec evaluate --json`; the report is not drawn (these tests read the
    intervals; tests/evaluation_output reads a report's)."""
    from opspec.cli import main

    out = tmp_path_factory.mktemp("rare")
    printed = io.StringIO()
    with pytest.MonkeyPatch.context() as patch, contextlib.redirect_stdout(printed), \
            contextlib.redirect_stderr(io.StringIO()):
        patch.setattr("opspec.evaluation.report.write_report",
                      lambda store, *_args, **_kwargs: store.folder / "report.html")
        status = main(["evaluate", str(ROOT / "specs" / "medication_dispenser.xpdl"),
                       "--users", "10", "--days", "1", "--out", str(out), "--json",
                       "--workers", "1"])
    assert status == 0
    return json.loads(printed.getvalue())["metrics"]


def test_no_missed_dose_still_gives_a_positive_upper_bound(summary: dict) -> None:
    missed = summary["missed_rate"]
    assert missed["value"] == 0.0
    z = 1.959963984540054
    n = 40
    wilson_high = (z * z / n) / (1 + z * z / n)          # Wilson upper bound at 0 successes
    assert missed["ci95"] == pytest.approx([0.0, wilson_high], abs=1e-9)
    assert summary["taken_rate"]["ci95"][0] == pytest.approx(1 - wilson_high, abs=1e-9)


def test_a_count_with_no_event_gets_the_exact_poisson_bound(summary: dict) -> None:
    count = summary["doses_missed"]
    assert count["total"] == 0
    assert count["ci95"] == pytest.approx([0.0, 3.6888794541139363 / 10], abs=1e-9)


def test_common_events_keep_the_cluster_robust_interval(summary: dict) -> None:
    alarms = summary["alarms"]
    assert alarms["total"] >= 10
    assert 0 < alarms["ci95"][0] < alarms["mean"] < alarms["ci95"][1]
