"""docs/evaluation.md defines every interval method in the words the program uses.

The report, ``--json`` and the terminal take their method descriptions from
:mod:`opspec.statistics.methods`; the documentation's table must say the same, so that what a
reader of the docs is told about an interval is what the program computed."""

from __future__ import annotations

from pathlib import Path

from opspec.statistics.methods import METHODS

DOC = Path(__file__).resolve().parents[2] / "docs" / "evaluation.md"


def test_every_method_has_its_row_in_docs_evaluation():
    rows = {line.split("|")[1].strip().strip("`"): line for line in DOC.read_text(
        encoding="utf-8").splitlines() if line.startswith("| `")}
    for method in METHODS.values():
        row = rows.get(method.id)
        assert row is not None, f"docs/evaluation.md has no row for {method.id}"
        assert method.definition in row and method.name in row
        assert all(reference in row for reference in method.references)
