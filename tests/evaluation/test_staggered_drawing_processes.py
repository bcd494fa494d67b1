"""`opspec evaluate --workers 2` forks one drawing process before it loads the spec (on the
core its start-up leaves idle) and the other as the replications start, inheriting what the
start-up loaded (``plots.staggered_start``). The figures those processes draw must be the
bytes drawn one after another, whichever process draws each, and the processes not forked at
first must be forked when asked, or at the first figure."""

from __future__ import annotations

import multiprocessing
from pathlib import Path

from opspec.evaluation import plots

from figure_samples import RATES, figures


def _figures(folder: Path) -> list[Path]:
    """The three sample figures and a fourth: a rates figure of one row."""
    return [*figures(folder), plots.rates_figure(RATES[:1], folder / "rates-1.svg")]


def _drawing_children() -> int:
    return len(multiprocessing.active_children())


def test_one_forked_first_the_other_when_asked_and_the_same_figures(tmp_path: Path) -> None:
    alone = _figures(tmp_path / "alone")
    before = _drawing_children()
    with plots.staggered_start(1), plots.drawing_processes(2):
        assert _drawing_children() == before + 1
        plots.warm_up_the_rest()
        assert _drawing_children() == before + 2
        plots.warm_up_the_rest()                # once only
        assert _drawing_children() == before + 2
        with plots.drawn_by(2):
            together = _figures(tmp_path / "together")
        assert all(p.is_file() for p in together)
    assert [p.read_bytes() for p in together] == [p.read_bytes() for p in alone]
    assert _drawing_children() == before


def test_the_rest_are_forked_at_the_first_figure_when_not_asked_before(tmp_path: Path) -> None:
    alone = _figures(tmp_path / "alone")
    before = _drawing_children()
    with plots.staggered_start(1), plots.drawing_processes(2):
        assert _drawing_children() == before + 1
        with plots.drawn_by(2):
            together = _figures(tmp_path / "together")
            assert _drawing_children() == before + 2
    assert [p.read_bytes() for p in together] == [p.read_bytes() for p in alone]


def test_a_drawing_process_that_cannot_be_forked_leaves_the_figures_to_this_process(
        tmp_path: Path, monkeypatch) -> None:
    """When the machine refuses a fork part way (too many processes), the processes already
    forked are ended at once and every figure is drawn here, the same bytes."""
    alone = _figures(tmp_path / "alone")
    fork = multiprocessing.get_context("fork")
    forked: list[object] = []

    class SecondRefused(type(fork).Process):  # type: ignore[misc]
        def start(self) -> None:
            if forked:
                raise OSError(11, "Resource temporarily unavailable")
            forked.append(self)
            super().start()

    class Refusing(type(fork)):  # type: ignore[misc]
        Process = SecondRefused

    monkeypatch.setattr(multiprocessing, "get_context", lambda method=None: Refusing())
    before = _drawing_children()
    with plots.drawing_processes(2):
        assert forked and _drawing_children() == before    # the one forked is gone already
        with plots.drawn_by(2):
            here = _figures(tmp_path / "here")
    assert [p.read_bytes() for p in here] == [p.read_bytes() for p in alone]
