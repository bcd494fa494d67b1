"""The monitors' table (terminal and report) gives the exact interval of the share of users a
monitor's violations affected, as docs/evaluation.md (Monitors: hazards) says it does: "0 of
50 users" is not nobody but at most 7.11 %. Only ``--json`` had it
(``share_affected_ci95``); the legend under the terminal's tables names its method."""

from __future__ import annotations

import io
from types import SimpleNamespace

from opspec.evaluation.tables import MONITOR_HEADERS, monitor_rows, print_summary

MONITORS = {
    "min_gap dispense 3.75h": {
        "violations": 0, "users": 50, "users_affected": 0, "share_affected": 0.0,
        "share_affected_ci95": [0.0, 0.07112173646419764],
        "share_affected_ci95_method": "clopper-pearson", "per_user_day": 0.0,
        "ci95": [0.0, 0.01475551781645574], "ci95_method": "garwood+t", "first": None}}


def test_the_share_affected_has_its_exact_interval() -> None:
    (row,) = monitor_rows(MONITORS)
    cells = dict(zip(MONITOR_HEADERS, row, strict=True))
    assert cells["users affected"] == "0 of 50 (0.00 %)"
    assert cells["95 % CI (exact)"] == "[0.00 %, 7.11 %]"


def test_the_terminal_legend_names_the_share_s_method() -> None:
    out = io.StringIO()
    plan = SimpleNamespace(design=lambda label: SimpleNamespace(spec="d.xpdl"), users=50,
                           days=5.0, seed=0, user_model=None, run_inputs=None)
    outcome = SimpleNamespace(done=50, failed=0, wall_s=1.0, skipped=0)
    print_summary(out, plan, {}, None, outcome, [], 1, monitors=MONITORS)
    text = out.getvalue()
    assert "[0.00 %, 7.11 %]" in text
    assert "\n  Clopper–Pearson: a share of users" in text
