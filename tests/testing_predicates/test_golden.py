"""Golden traces: stable files, readable diffs, regeneration through the plugin flag."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from opspec.engine.compiled import CompiledPackage
from opspec.testing.golden import compare, normalise
from opspec.testing.simulation import SimulationResult, simulate

from .conftest import DISPENSER, NINE


def test_the_same_seed_gives_the_same_golden_lines(dispenser: CompiledPackage) -> None:
    def run() -> list[str]:
        return normalise(simulate(dispenser, users=2, until=NINE, seed=4,
                                  user_model="dispenser-reference"))

    first = run()
    assert first == run()
    header = json.loads(first[0])
    assert header == {"format": "opspec-golden-trace", "version": 1,
                      "package": "medication_dispenser", "replications": 2}
    event = json.loads(first[1])
    assert event["replication"] == 0 and "seq" not in event and "package" not in event


def test_a_matching_run_passes_and_regen_writes_the_file(tmp_path: Path,
                                                         prompt_user: SimulationResult) -> None:
    path = tmp_path / "golden" / "prompt.jsonl"
    assert compare(prompt_user, path, regen=True) == path
    assert compare(prompt_user, path) is None
    assert compare(list(prompt_user.trace), path) is None       # a plain list of events too
    assert len(path.read_text(encoding="utf-8").splitlines()) == len(prompt_user.trace) + 1


def test_a_missing_golden_file_says_how_to_create_it(tmp_path: Path,
                                                     prompt_user: SimulationResult) -> None:
    with pytest.raises(AssertionError, match="no golden trace at .*--opspec-regen-golden"):
        compare(prompt_user, tmp_path / "nothing.jsonl")


def test_a_different_run_fails_with_counts_and_a_short_unified_diff(
        tmp_path: Path, prompt_user: SimulationResult, absent_user: SimulationResult) -> None:
    path = tmp_path / "prompt.jsonl"
    compare(prompt_user, path, regen=True)
    with pytest.raises(AssertionError) as info:
        compare(absent_user, path, max_diff_lines=30)
    text = str(info.value)
    lines = text.splitlines()
    assert lines[0].startswith(f"the run differs from the golden trace {path}: 64 event(s) "
                               "stored, ")
    assert "line(s) missing from this run" in lines[0] and "first difference at event" in lines[0]
    assert lines[1] == f"--- {path} (golden)" and lines[2] == "+++ this run"
    assert any(line.startswith("-") and '"press_report"' in line for line in lines)
    assert any(line.startswith("+") and '"deadline.expired"' in line for line in lines)
    assert "more diff line(s)" in text and len(lines) < 40
    assert lines[-1].startswith("if the change is intended, rerun with --opspec-regen-golden")


def test_one_changed_event_shows_as_one_changed_line(tmp_path: Path,
                                                     prompt_user: SimulationResult) -> None:
    path = tmp_path / "prompt.jsonl"
    compare(prompt_user, path, regen=True)
    trace = list(prompt_user.trace)
    trace[40] = replace(trace[40], time=trace[40].time + 1.0)
    with pytest.raises(AssertionError, match=r"1 line\(s\) missing from this run, 1 extra; "
                                             r"first difference at event 41") as info:
        compare(trace, path)
    diff = [line for line in str(info.value).splitlines()
            if line[:1] in "+-" and not line.startswith(("---", "+++"))]
    assert len(diff) == 2


def test_ignored_fields_do_not_count(tmp_path: Path, prompt_user: SimulationResult) -> None:
    path = tmp_path / "prompt.jsonl"
    compare(prompt_user, path, regen=True, ignore=("seq", "package", "wall", "lane"))
    trace = [replace(e, lane="elsewhere") for e in prompt_user.trace]
    assert compare(trace, path, ignore=("seq", "package", "wall", "lane")) is None
    with pytest.raises(AssertionError):
        compare(trace, path)


TEST_FILE = f'''
from opspec.testing.simulation import simulate

def test_day(golden):
    result = simulate({str(DISPENSER)!r}, script=[("after trg_2 90s", "press_report")],
                      until=9 * 3600, seed=1)
    golden(result, "golden/day.jsonl")
'''


def test_the_golden_fixture_fails_then_regenerates_then_passes(
        pytester: pytest.Pytester) -> None:
    pytester.makepyfile(test_golden_day=TEST_FILE)
    first = pytester.runpytest()
    first.assert_outcomes(failed=1)
    first.stdout.fnmatch_lines(["*no golden trace at *golden/day.jsonl*--opspec-regen-golden*"])
    pytester.runpytest("--opspec-regen-golden").assert_outcomes(passed=1)
    assert (pytester.path / "golden" / "day.jsonl").exists()
    pytester.runpytest().assert_outcomes(passed=1)
    pytester.makepyfile(test_golden_day=TEST_FILE.replace("90s", "120s"))
    changed = pytester.runpytest()
    changed.assert_outcomes(failed=1)
    changed.stdout.fnmatch_lines(["*the run differs from the golden trace*",
                                  "*--- *day.jsonl (golden)*", "*+++ this run*"])
