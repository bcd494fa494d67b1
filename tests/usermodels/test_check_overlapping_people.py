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


def test_a_broken_fitted_on_table_names_the_file(tmp_path: Path, capsys) -> None:
    model = tmp_path / "m.users.toml"
    model.write_text('format = "opspec-user-model"\nversion = 1\nname = "m"\n'
                     '[activities.walk]\nduration = { kind = "constant", value = 3 }\n'
                     '[fitted_on]\npersons = "P01"\n', encoding="utf-8")
    trace = _person(tmp_path, "P01", 1)
    assert main(["model-check", str(model), str(trace), "--replicates", "19"]) == 2
    assert f"{model}:7: fitted_on.persons: must be a list" in capsys.readouterr().err
