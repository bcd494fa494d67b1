"""Every shipped spec runs the same, event for event, on the compiled engine and from source.

This is what lets scripts/test.sh re-run only the engine's own folders from source: the long,
statistical tests of specs/tests (robots at 5 Hz with their worlds, the dispenser with its
users) exercise the compiled modules along the same paths as one run of each spec,
and two engines that write byte-identical traces for that run -- every activity start and end,
every work item, every world reading, at the same simulated instant, drawing the same random
numbers -- cannot disagree on a statistic computed from such runs. Each spec of specs/ is
found by its suffix, so a spec added there is compared too.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from opspec import _native

ROOT = Path(__file__).resolve().parents[2]
SPECS = sorted([*ROOT.glob("specs/*.xpdl"), *ROOT.glob("specs/*.bpmn")])
# The shortest runs whose traces hold every kind of event (each activity started and
# completed, each data change, each world event) that the longer runs this test used to make
# (a spec with a world 300 s, a day-scale spec 200 days) hold: a periodic spec 120 s at seed 3
# (about 2,500 instances at 5, 2 and 1 Hz; its robot still engages, backs up, turns away,
# confirms the patient, loses a bout), a day-scale spec 30 days with its own users at seed 2
# (120 doses, one of them missed: the caregiver is notified, the rare path of the
# dispenser). Checked when these were chosen: the set of (kind, process, activity, lane,
# data fields) of each trace equals that of the longer run.
ROBOT_HORIZON = ["--until", "120", "--seed", "3"]
DAY_HORIZON = ["--days", "30", "--seed", "2"]


def _run(spec: Path, trace: Path, pure: bool) -> dict[str, object]:
    env = {k: v for k, v in os.environ.items() if k != _native.ENV}
    if pure:
        env[_native.ENV] = "1"
    horizon = ROBOT_HORIZON if "opspec:World" in spec.read_text(encoding="utf-8") \
        else DAY_HORIZON
    done = subprocess.run(
        [sys.executable, "-c", "import sys; from opspec.cli import main; sys.exit(main())",
         "run", str(spec), *horizon, "--json", "--timeline", "none",
         "--trace", str(trace)],
        capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    assert done.returncode in (0, 1), done.stderr
    result = json.loads(done.stdout)
    assert isinstance(result, dict)
    result.pop("trace")
    return result


@pytest.mark.skipif(os.environ.get(_native.ENV) == "1",
                    reason="the pass from source has nothing compiled to compare with; the "
                    "compiled pass runs this comparison")
@pytest.mark.parametrize("spec", SPECS, ids=[s.name for s in SPECS])
def test_compiled_and_source_engines_write_the_same_trace(spec: Path, tmp_path: Path) -> None:
    if not _native.COMPILED:
        pytest.skip(f"this installation runs from source: {_native.STATUS}")
    source_trace, compiled_trace = tmp_path / "source.jsonl", tmp_path / "compiled.jsonl"
    source = _run(spec, source_trace, pure=True)
    compiled = _run(spec, compiled_trace, pure=False)
    assert source["events"] and source["instances"], source   # the run did something
    assert compiled == source
    source_lines = source_trace.read_text(encoding="utf-8").splitlines()
    compiled_lines = compiled_trace.read_text(encoding="utf-8").splitlines()
    assert len(source_lines) > 100
    if "notify_caregiver" in spec.read_text(encoding="utf-8"):     # the dispenser's rare path
        assert any('"notify_caregiver"' in line for line in source_lines), spec.name
    for number, (a, b) in enumerate(zip(compiled_lines, source_lines, strict=True), start=1):
        assert a == b, f"{spec.name}: the traces part at line {number}"
