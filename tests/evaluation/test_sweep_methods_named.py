"""Every interval of a sweep's tables names its method, as every other table of an evaluation
does (README: every interval names its method): the paired differences' intervals were shown
with no method and, in the terminal, with no legend, so a reader of ``doses_due  +0
[-0.01844, +0.01844]`` could not tell it is the exact Poisson bound of a difference no user
had (paired t ∪ Garwood)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.fixture(scope="module")
def sweep_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, Path]:
    from evaluate_without_report import without_report

    out = tmp_path_factory.mktemp("sweep") / "run"
    printed = io.StringIO()
    with without_report(), contextlib.redirect_stdout(printed):
        assert main(["evaluate", str(SPEC), "--users", "20", "--days", "2", "--workers", "1",
                     "--quiet", "--out", str(out), "--sweep",
                     "spec.notify_workflow.wait_report.deadline=2min,5min"]) == 0
    return printed.getvalue(), out


def _table_of(text: str, metric: str) -> list[str]:
    lines = text.splitlines()
    start = lines.index(metric)
    return lines[start + 1:start + 5]


def test_each_interval_of_a_sweep_table_names_its_method(sweep_run: tuple[str, Path]) -> None:
    text, _ = sweep_run
    header, _, reference, other = _table_of(text, "doses_due (count)")
    assert "CI method" in header and "CI method (paired)" in header
    assert reference.split()[:2] == ["2", "min"] and "(reference)" in reference
    assert "paired t ∪ Garwood" in other           # no user's doses due differ
    header, _, _, other = _table_of(text, "missed_rate (ratio)")
    assert "Wilson, eff. n" in other


def test_the_paired_methods_are_explained_under_the_sweep(sweep_run: tuple[str, Path]) -> None:
    text, _ = sweep_run
    legend = text[text.index("95 % intervals of the sweep's tables"):]
    assert "\n  paired t ∪ Garwood: a difference of counts" in legend
    # not again what the run's own table above explains
    assert "\n  Wilson, eff. n:" not in legend
