"""`opspec model-check` and `opspec fit --holdout` at the command line: verdicts, exit
statuses, bad input refused with a message (never a traceback)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.evaluation.predictive import write_person_traces

HERE = Path(__file__).resolve().parent
SPEC = HERE.parents[1] / "specs" / "medication_dispenser.xpdl"
REFERENCE = HERE.parents[1] / "specs" / "medication_dispenser.users.toml"


@pytest.fixture(scope="module")
def reference_people(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """Twelve people of the reference user (one person, no population), five days each."""
    return write_person_traces(SPEC, REFERENCE, tmp_path_factory.mktemp("ref"),
                               people=range(12), seed=21, days=5)


def test_a_hand_written_model_checks_its_own_people(reference_people, capsys) -> None:
    """The reference model is one person for everyone: its omission rate is checked by the
    exact binomial test of the pooled count, and nothing misfits."""
    status = main(["model-check", str(REFERENCE), *map(str, reference_people),
                   "--replicates", "99", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert status == 0, doc["misfits"]
    omission = next(i for i in doc["items"] if i["item"] == "hear_alarm omission")
    assert omission["test"] == "exact binomial of the pooled count"
    assert omission["predicted"]["value"] == pytest.approx(0.15)
    assert doc["parameter_uncertainty"].startswith("none in the model")


def test_the_wrong_model_exits_1(reference_people, capsys) -> None:
    """The same people against older-adults (every duration x 1.5): the walk and the pill
    misfit, named, and the exit status says so."""
    status = main(["model-check", f"{REFERENCE},older-adults", *map(str, reference_people),
                   "--replicates", "99", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert status == 1
    assert {"walk_to_dispenser duration", "take_pill duration"} <= set(doc["misfits"])
    assert "hear_alarm omission" not in doc["misfits"]


def test_holdout_cross_validates_by_person(reference_people, capsys, tmp_path) -> None:
    status = main(["fit", *map(str, reference_people), "-o", str(tmp_path / "m.toml"),
                   "--holdout", "3", "--draws", "30", "--replicates", "99", "--json"])
    doc = json.loads(capsys.readouterr().out)
    cv = doc["holdout"]
    assert status == 0, cv["misfits"]
    assert len(cv["folds"]) == 3 and cv["fits"] is True
    held = [set(f["held_out"]) for f in cv["folds"]]
    assert sum(len(h) for h in held) == 12 and set.union(*held) == {
        f"P{u:03d}" for u in range(12)}                     # each person held out once
    assert all(f["persons"] == 4 for f in cv["folds"])
    assert cv["family_wise"]["over"] == "every item of every fold"
    assert (tmp_path / "m.toml").is_file()                 # the model of all persons


@pytest.mark.parametrize(("args", "message"), [
    (["--level", "1.5"], "--level must be between 0 and 1"),
    (["--replicates", "5"], "--replicates must be at least 19"),
])
def test_bad_options_are_refused(reference_people, capsys, args, message) -> None:
    status = main(["model-check", str(REFERENCE), str(reference_people[0]), *args])
    assert status == 2
    assert message in capsys.readouterr().err


def test_a_file_that_is_not_a_trace_is_named_with_its_line(tmp_path, capsys) -> None:
    bad = tmp_path / "notes.jsonl"
    bad.write_text('{"hello": 1}\n', encoding="utf-8")
    assert main(["model-check", str(REFERENCE), str(bad)]) == 2
    err = capsys.readouterr().err
    assert f"{bad}:1" in err and "not an opspec trace" in err and "Traceback" not in err


def test_a_missing_model_is_refused(reference_people, capsys) -> None:
    assert main(["model-check", "no-such-model.toml", str(reference_people[0])]) == 2
    assert "no-such-model.toml" in capsys.readouterr().err


def test_holdout_needs_each_file_to_be_one_person(tmp_path, capsys) -> None:
    """One file with several runs, each a person: a fold cannot take a file apart."""
    both = tmp_path / "two.jsonl"
    runs = write_person_traces(SPEC, REFERENCE, tmp_path / "runs", people=range(2), seed=3,
                               days=1)
    lines = runs[0].read_text().splitlines()
    both.write_text("\n".join([json.dumps({"format": "opspec-trace", "version": 1}),
                               *lines[1:], *runs[1].read_text().splitlines()[1:]]) + "\n")
    status = main(["fit", str(both), *map(str, runs), "-o", str(tmp_path / "m.toml"),
                   "--holdout", "2", "--draws", "0"])
    assert status == 2
    assert "holds sessions of 2 persons" in capsys.readouterr().err
    assert not (tmp_path / "m.toml").exists()       # refused before anything is written


def test_holdout_with_too_few_persons_is_refused(reference_people, capsys, tmp_path) -> None:
    for folds in ("3", "1"):
        status = main(["fit", *map(str, reference_people[:3]), "-o", str(tmp_path / "m.toml"),
                       "--holdout", folds, "--draws", "0"])
        assert status == 2
        assert f"--holdout {folds} cannot split 3 person(s)" in capsys.readouterr().err
        # a refused command leaves no model behind: the user would take it for the result
        assert not (tmp_path / "m.toml").exists()


def test_holdout_with_the_model_on_standard_output_is_refused(reference_people, capsys
                                                              ) -> None:
    # the folds' checks would be skipped (they print after the model is written)
    status = main(["fit", *map(str, reference_people[:4]), "-o", "-", "--holdout", "2",
                   "--draws", "0"])
    captured = capsys.readouterr()
    assert status == 2 and captured.out == ""
    assert "--holdout and -o - both want standard output" in captured.err
