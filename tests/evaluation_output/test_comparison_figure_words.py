"""The comparison figure writes each difference as the report's table does, signed (a
difference B − A, not a level: the table once wrote "0.7378" beside the figure's "+0.7378"),
and names a difference it cannot draw, with the reason it has no interval (it once said
"1 non-finite value(s) left out")."""

from __future__ import annotations

import html
import re
from pathlib import Path

from opspec.evaluation import figure_files, plots
from opspec.evaluation.tables import comparison_rows

LATENCY = "report latency"
WHY = "fewer than 2 users' durations differ between the designs"


def _texts(path: Path) -> str:
    svg = path.read_text(encoding="utf-8")
    return html.unescape(" ".join(re.sub(r"<[^>]+>", " ", svg).split()))


def test_the_figure_and_the_table_write_a_difference_alike(tmp_path: Path) -> None:
    difference = {
        "alarms": {"kind": "count", "a": 14.16, "b": 14.9, "difference": 0.7378,
                   "ci95": [0.5121, 0.9635], "users": 50, "significant": True},
        "missed_rate": {"kind": "ratio", "proportion": True, "a": 0.0083, "b": 0.0056,
                        "difference": -0.0027, "ci95": [-0.0041, -0.0013], "users": 50,
                        "significant": True},
        LATENCY: {"kind": "duration", "unit": "s", "a": 117.3, "b": 117.3,
                  "difference": 0.0, "ci95": [None, None], "users": 50,
                  "significant": False}}
    [alarms, missed, latency] = comparison_rows(difference)
    # the levels A and B unsigned, the difference and its bounds signed
    assert alarms[1:5] == ("14.16", "14.9", "+0.7378", "[+0.5121, +0.9635]")
    assert missed[3:5] == ("-0.27 pp", "[-0.41 pp, -0.13 pp]")
    assert latency[3:5] == ("0 s", "–")
    with figure_files.figure_format("svg"):
        path = plots.comparison_figure(
            [(n, d["difference"], *d["ci95"]) for n, d in difference.items()],
            tmp_path / "comparison.svg", {"missed_rate": "pp", LATENCY: "s"},
            no_interval={LATENCY: WHY})
    text = _texts(path)
    assert f"{alarms[3]} {alarms[4]}" in text
    assert f"{missed[3]} {missed[4]}" in text
    assert "non-finite" not in text
    assert f"not drawn, no 95 % interval: {LATENCY} ({WHY})" in text
