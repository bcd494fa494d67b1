"""An activity in no lane of a user workflow (its end event, drawn with no performer) is shown
in the workflow's lane in the timeline's lane column, as the workflow's other activities are.

In a spec with Pools and Lanes (as ``opspec new`` writes), ``run --timeline all`` and the
walkthrough showed ``user    user_workflow#3  user_done completed`` among the ``User`` lines:
such an activity got the fixed word ``user``, not its workflow's lane label.
"""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace

import pytest

from opspec.cli import main
from opspec.engine.lane_labels import USER, LaneLabels

_LINE = re.compile(r"^\s+d\d+ \d\d:\d\d:\d\d(?:\.\d+)?  (?P<lane>\S*)\s+(?P<where>\S+#\d+)\s+"
                   r"(?P<what>.*)$")


def test_the_user_workflows_end_is_in_the_user_lane_by_its_name(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["new", str(tmp_path / "demo")]) == 0
    spec = tmp_path / "demo" / "demo.xpdl"
    capsys.readouterr()
    assert main(["run", str(spec), "--timeline", "all", "--seed", "0", "--until", "10h"]) == 0
    rows = [m for m in map(_LINE.match, capsys.readouterr().out.splitlines()) if m]
    user_rows = [m for m in rows if m["where"].startswith("user_workflow#")]
    ends = [m for m in user_rows if m["what"].startswith("user_done ")]
    assert ends, "the user's workflow ran to its end"
    assert {m["lane"] for m in user_rows} == {"User"}, {m["lane"] for m in user_rows}


def _event(process: str, activity: str | None) -> SimpleNamespace:
    return SimpleNamespace(lane=None, process=process, activity=activity)


def test_without_a_lane_name_the_user_lane_is_still_called_user() -> None:
    labels = LaneLabels(names={}, process_lane={"u": USER, "both": ""},
                        user_activities=frozenset({("u", "end"), ("both", "end")}),
                        user_processes=frozenset({"u"}))
    assert labels.label(_event("u", "end")) == USER
    # a workflow spanning several lanes has no lane of its own: its user work says user
    assert labels.label(_event("both", "end")) == USER


def test_a_user_workflows_own_lane_name_is_used_and_cut_to_the_column() -> None:
    labels = LaneLabels(names={}, process_lane={"u": "Resident of the flat"},
                        user_activities=frozenset({("u", "end")}),
                        user_processes=frozenset({"u"}), width=8)
    assert labels.label(_event("u", "end")) == "Residen…"
