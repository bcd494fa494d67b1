"""The reference tables of the user documentation name what the program has, no more, no less.

``test_docs_commands`` checks what the docs' commands print; these tests check the tables a
reader looks things up in against the code they describe: the columns of each table of
``results.sqlite`` (docs/evaluation.md), the trace's event kinds (docs/trace-format.md), the
XES lifecycle mapping (docs/xes-export.md), the distribution kinds of a user model
(docs/user-models.md) and the ``given`` keys of a scenario file (docs/spec-testing.md). A
table that drifts from the code fails here, naming the row.
"""

from __future__ import annotations

import re
import sqlite3
from pathlib import Path

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _rows(page: str, first_cell: str) -> list[list[str]]:
    """The rows of ``page``'s tables whose first cell matches ``first_cell``, as lists of
    their cells (stripped)."""
    rows = []
    for line in (DOCS / page).read_text(encoding="utf-8").splitlines():
        if line.startswith("|"):
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]
            if cells and re.fullmatch(first_cell, cells[0]):
                rows.append(cells)
    return rows


def test_results_sqlite_tables_are_those_evaluation_md_lists(tmp_path: Path) -> None:
    from opspec.evaluation.store import _SCHEMA

    db = sqlite3.connect(tmp_path / "results.sqlite")
    db.executescript(_SCHEMA)
    stored = {name: [col[1] for col in db.execute(f"PRAGMA table_info({name})")]
              for (name,) in db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
    documented = {}
    for cells in _rows("evaluation.md", r"`\w+\([\w, ]+\)`"):
        name, columns = re.fullmatch(r"`(\w+)\(([\w, ]+)\)`", cells[0]).groups()
        documented[name] = [c.strip() for c in columns.split(",")]
    assert documented == stored


def test_every_event_kind_the_engine_emits_is_in_trace_format_md() -> None:
    from opspec.engine.trace import EventKind

    kinds = {value for name, value in vars(EventKind).items()
             if name.isupper() and isinstance(value, str)}
    # defined for the XES mapping and performers' own events; the engine emits none
    kinds.discard("activity.aborted")
    documented = {cells[0].strip("`") for cells in _rows("trace-format.md", r"`[a-z_.]+`")
                  if cells[0].strip("`") not in {"seq", "time", "kind", "process",
                                                 "instance", "activity", "lane",
                                                 "participant", "package", "data"}}
    documented |= {"process.suspended", "process.resumed"}   # one row for the pair
    assert kinds <= documented, f"not in docs/trace-format.md: {sorted(kinds - documented)}"


def test_xes_lifecycle_table_is_the_exporters_mapping() -> None:
    from opspec.evaluation.exporters import LIFECYCLE_TRANSITIONS

    documented = {cells[0].strip("`"): cells[1].strip("`")
                  for cells in _rows("xes-export.md", r"`[a-z_]+\.[a-z_.]+`|`fault`")
                  if len(cells) == 3 and cells[1].startswith("`")}
    assert documented == {str(k): v for k, v in LIFECYCLE_TRANSITIONS.items()}


def test_user_models_md_lists_every_distribution_kind() -> None:
    from opspec.distributions.factory import _BUILDERS

    rows = _rows("user-models.md", r"`[a-z_]+`")
    documented = set()
    for cells in rows:
        if len(cells) == 3 and cells[0] in {f"`{k}`" for k in _BUILDERS}:
            documented.add(cells[0].strip("`"))
            documented.update(re.findall(r"`([a-z_]+)` is the same", cells[2]))
    assert documented == set(_BUILDERS), sorted(set(_BUILDERS) ^ documented)


def test_spec_testing_md_names_every_given_key_of_a_scenario() -> None:
    from opspec.testing.scenario import _GIVEN

    text = (DOCS / "spec-testing.md").read_text(encoding="utf-8")
    sentence = text[text.index("`given` keys:"):text.index("`then` is a list")]
    named = set(re.findall(r"`(\w+)`\s+\(", sentence)) | set(re.findall(r"`(\w+)` or `", sentence))
    assert named == set(_GIVEN), sorted(named ^ set(_GIVEN))
