"""A held-out set that overlaps the fitted one: `opspec fit` writes whom it fitted on
([fitted_on]), and `opspec model-check` says which of the people it checks are among them
(a check on them is no check on new people)."""

from __future__ import annotations

import json
import random
from pathlib import Path

from opspec.cli import main
from opspec.usermodels.fitted_on import fitted_persons
from opspec.usermodels.loader import load_user_model


def _person(folder: Path, person: str, seed: int) -> Path:
    rng = random.Random(seed)
    lines = [{"format": "opspec-trace", "version": 1, "person": person},
             {"time": 0.0, "kind": "run.started"}]
    for i in range(1, 13):
        lines.append({"time": 200.0 * i, "kind": "activity.offered", "activity": "walk",
                      "lane": "user", "instance": i})
        lines.append({"time": 200.0 * i + rng.lognormvariate(3.4, 0.3),
                      "kind": "activity.completed", "activity": "walk", "lane": "user",
                      "instance": i})
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{person}.jsonl"
    path.write_text("".join(json.dumps(x) + "\n" for x in lines), encoding="utf-8")
    return path


def test_people_the_model_was_fitted_on_are_named(tmp_path: Path, capsys) -> None:
    fit = [_person(tmp_path / "fit", f"P{i:02d}", i) for i in range(6)]
    held = [_person(tmp_path / "held", f"P{i:02d}", i) for i in range(6, 9)]
    model = tmp_path / "people.users.toml"
    assert main(["fit", str(tmp_path / "fit"), "-o", str(model), "--draws", "20"]) == 0
    assert fitted_persons(str(model)) == tuple(f"P{i:02d}" for i in range(6))
    load_user_model(model)                      # the table reads back
    capsys.readouterr()

    main(["model-check", str(model), *map(str, held), "--replicates", "19", "--json"])
    notes = json.loads(capsys.readouterr().out)["notes"]
    assert not [n for n in notes if "fitted on" in n]

    main(["model-check", str(model), *map(str, held), str(fit[0]), str(fit[3]),
          "--replicates", "19"])
    out = capsys.readouterr().out
    assert ("note: 2 of the 5 person(s) checked are among the 6 the model was fitted on "
            "(P00, P03; its [fitted_on] table)") in out


def test_a_check_on_only_the_people_fitted_on_claims_no_fit_of_people(tmp_path: Path,
                                                                     capsys) -> None:
    """Every person checked was in the fit: the verdict line itself says that the check
    shows only that the model reproduces them (it said "the model fits these 6 person(s)",
    the caveat only in a note above it), and the report's title calls them no held-out
    people."""
    fit = [_person(tmp_path / "fit", f"P{i:02d}", i) for i in range(6)]
    model = tmp_path / "people.users.toml"
    assert main(["fit", str(tmp_path / "fit"), "-o", str(model), "--draws", "20"]) == 0
    capsys.readouterr()

    status = main(["model-check", str(model), *map(str, fit), "--replicates", "19",
                   "--report", str(tmp_path / "report")])
    verdict = capsys.readouterr().out.splitlines()[-2]      # the last line names the report
    assert status == 0
    assert verdict.startswith("verdict: none of ") and "the model fits" not in verdict
    assert ("but all 6 person(s) checked are among those the model was fitted on: it "
            "reproduces the people it was fitted on, which says nothing of how it predicts "
            "new people") in verdict
    html = (tmp_path / "report" / "model-check.html").read_text(encoding="utf-8")
    assert "held-out" not in html and "says nothing of how it predicts new people" in html

    main(["model-check", str(model), *map(str, fit), "--replicates", "19", "--json"])
    assert json.loads(capsys.readouterr().out)["persons_fitted_on"] == 6


def test_a_check_with_some_people_fitted_on_says_how_many(tmp_path: Path, capsys) -> None:
    fit = [_person(tmp_path / "fit", f"P{i:02d}", i) for i in range(6)]
    held = [_person(tmp_path / "held", f"P{i:02d}", i) for i in range(6, 9)]
    model = tmp_path / "people.users.toml"
    assert main(["fit", str(tmp_path / "fit"), "-o", str(model), "--draws", "20"]) == 0
    capsys.readouterr()
    assert main(["model-check", str(model), *map(str, held), str(fit[0]),
                 "--replicates", "19"]) == 0
    verdict = capsys.readouterr().out.splitlines()[-1]
    assert verdict.startswith("verdict: the model fits these 4 person(s), 1 of them among "
                              "those it was fitted on: none of ")
    assert main(["model-check", str(model), *map(str, held), "--replicates", "19"]) == 0
    assert capsys.readouterr().out.splitlines()[-1].startswith(
        "verdict: the model fits these 3 person(s): none of ")


def test_a_broken_fitted_on_table_names_the_file(tmp_path: Path, capsys) -> None:
    model = tmp_path / "m.users.toml"
    model.write_text('format = "opspec-user-model"\nversion = 1\nname = "m"\n'
                     '[activities.walk]\nduration = { kind = "constant", value = 3 }\n'
                     '[fitted_on]\npersons = "P01"\n', encoding="utf-8")
    trace = _person(tmp_path, "P01", 1)
    assert main(["model-check", str(model), str(trace), "--replicates", "19"]) == 2
    assert f"{model}:7: fitted_on.persons: must be a list" in capsys.readouterr().err
