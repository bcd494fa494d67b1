"""What Ctrl-C during ``opspec evaluate`` says is stored: the users of --input-uncertainty's
parameter draws (stored as ``A~draws``) count as the progress line counts them. It said
"300 of 300 replications are stored" while the progress line stood at 588/600 and 300 draws'
users were still to run; and a run stopped once everything was stored is told that only the
report is missing, whichever phase the Ctrl-C reached."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from opspec.commands.evaluate_run import _say_stopped


class _Store:
    def __init__(self, done: dict[str, int]) -> None:
        self.done = done
        self.folder = Path("runs/x")
        self.path = self.folder / "results.sqlite"

    def finished(self, label: str) -> set[int]:
        return set(range(self.done.get(label, 0)))


def _plan(draws: int = 0) -> SimpleNamespace:
    return SimpleNamespace(users=300, designs=[SimpleNamespace(label="A")],
                           input_uncertainty=draws, users_per_draw=30 if draws else 0)


def test_the_draws_users_are_counted(capsys: pytest.CaptureFixture[str]) -> None:
    _say_stopped(_Store({"A": 300, "A~draws": 120}), _plan(draws=10))
    err = capsys.readouterr().err
    assert "stopped; 420 of 600 replications are stored" in err
    assert "finish with `opspec evaluate --resume --out runs/x`" in err


def test_all_stored_says_only_the_report_is_missing(capsys: pytest.CaptureFixture[str]) -> None:
    _say_stopped(_Store({"A": 300}), _plan())
    assert ("300 of 300 replications are stored in runs/x/results.sqlite; the report is not "
            "written; write it with") in capsys.readouterr().err


def test_a_run_part_way(capsys: pytest.CaptureFixture[str]) -> None:
    _say_stopped(_Store({"A": 150}), _plan())
    assert "150 of 300 replications are stored in runs/x/results.sqlite; finish with" in (
        capsys.readouterr().err)
