"""A metric check (--spec) over a recording cut short (a crash: no run.ended) compares its
part of a run with whole runs: fewer doses due, a correct model called a misfit of
doses_due. The note names the trace and where it ends; it said nothing."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.evaluation.predictive import write_person_traces

HERE = Path(__file__).resolve().parent
SPEC = HERE.parents[1] / "specs" / "medication_dispenser.xpdl"


@pytest.fixture(scope="module", autouse=True)
def _specs_may_be_extended() -> Iterator[None]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("OPSPEC_EXTERNAL_PATH", str(SPEC.parent))
        yield


def _check(capsys, folder: Path) -> dict:
    main(["model-check", str(HERE / "truth.population.toml"), str(folder), "--spec",
          str(SPEC), "--days", "2", "--runs", "20", "--replicates", "19", "--json"])
    return json.loads(capsys.readouterr().out)


def test_a_recording_cut_short_is_named_in_a_metric_check(tmp_path, capsys) -> None:
    traces = write_person_traces(SPEC, HERE / "truth.population.toml", tmp_path / "p",
                                 people=range(3), seed=5, days=2)
    whole = _check(capsys, tmp_path / "p")
    assert not any("do not last" in n for n in whole["notes"])
    lines = traces[0].read_text(encoding="utf-8").splitlines(keepends=True)
    traces[0].write_text("".join(lines[:len(lines) // 2]), encoding="utf-8")
    cut = _check(capsys, tmp_path / "p")
    [note] = [n for n in cut["notes"] if "do not last" in n]
    assert note.startswith("1 of 3 trace file(s) do not last the 2 day(s)")
    assert f"{traces[0]} (cut short at " in note and "no run.ended" in note


def test_sessions_longer_than_the_predicted_runs_are_named(tmp_path, capsys) -> None:
    """Two-day sessions checked without --days (the spec's run is one day): every count
    metric doubles against the prediction; the note says why and what to give."""
    write_person_traces(SPEC, HERE / "truth.population.toml", tmp_path / "p",
                        people=range(2), seed=5, days=2)
    main(["model-check", str(HERE / "truth.population.toml"), str(tmp_path / "p"),
          "--spec", str(SPEC), "--runs", "20", "--replicates", "19", "--json"])
    doc = json.loads(capsys.readouterr().out)
    [note] = [n for n in doc["notes"] if "do not last" in n]
    assert note.startswith("2 of 2 trace file(s) do not last the 1 day(s)")
    assert "(runs to 2.00 day(s))" in note and "give --days as long as the sessions" in note
