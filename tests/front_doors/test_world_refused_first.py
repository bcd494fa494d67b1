"""A world file that cannot be read, or a parameter its world refuses, is an input error that
every door refuses before any run, with ``opspec run``'s located message and exit status 2:
``opspec evaluate`` once ran every replication into it (each failing with the same message),
wrote a report and said to run again with ``--resume``."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.errors import ConfigurationError
from opspec.request import RunRequest, prepare
from opspec.testing import simulate

ROOT = Path(__file__).resolve().parents[2]

BROKEN = {
    "negative-drain": ("drain_per_s = 0.02", "drain_per_s = -1.0",
                       "drain_per_s: world 'vacuum-room': drain_per_s must be 0 or more"),
    "duplicate-key": ("width = 5.0", "width = 5.0\nwidth = 6.0", "not valid TOML"),
}


def _broken_copy(tmp_path: Path, case: str) -> tuple[Path, str]:
    """The vacuum cleaner beside a world file broken as ``case`` says, and the start of the
    message that places it (``file:line: …``)."""
    old, new, says = BROKEN[case]
    for path in ROOT.glob("specs/vacuum_cleaner.*"):
        shutil.copy(path, tmp_path / path.name)
    world = tmp_path / "vacuum_cleaner.world.toml"
    text = world.read_text(encoding="utf-8")
    assert old in text
    world.write_text(text.replace(old, new, 1), encoding="utf-8")
    (line,) = [n for n, row in enumerate(world.read_text(encoding="utf-8").splitlines(), 1)
               if row.startswith(new.splitlines()[-1])]
    return tmp_path / "vacuum_cleaner.xpdl", f"{world}:{line}: {says}"


@pytest.mark.parametrize("case", sorted(BROKEN))
def test_evaluate_refuses_the_world_before_any_replication(
        tmp_path: Path, case: str, capsys: pytest.CaptureFixture[str]) -> None:
    spec, says = _broken_copy(tmp_path, case)
    out = tmp_path / "out"
    status = main(["evaluate", str(spec), "--users", "3", "--days", "0.001", "--workers", "1",
                   "-o", str(out)])
    err = capsys.readouterr().err
    assert status == 2
    assert f"opspec evaluate: {says}" in err
    assert "--resume" not in err and "FAILED" not in err
    assert not (out / "results.sqlite").exists() and not (out / "report.html").exists()


@pytest.mark.parametrize("case", sorted(BROKEN))
def test_run_says_the_same(tmp_path: Path, case: str,
                           capsys: pytest.CaptureFixture[str]) -> None:
    spec, says = _broken_copy(tmp_path, case)
    assert main(["run", str(spec)]) == 2
    captured = capsys.readouterr()
    assert f"opspec run: {says}" in captured.err
    assert "seed 0, for" not in captured.out         # refused before the run's header


@pytest.mark.parametrize("case", sorted(BROKEN))
def test_prepare_refuses_it_before_building_a_run(tmp_path: Path, case: str) -> None:
    spec, says = _broken_copy(tmp_path, case)
    with pytest.raises(ConfigurationError) as refused:
        prepare(RunRequest(spec))
    assert str(refused.value).startswith(says)


def test_simulate_refuses_it_before_any_user(tmp_path: Path) -> None:
    spec, says = _broken_copy(tmp_path, "negative-drain")
    started: list[int] = []
    with pytest.raises(ConfigurationError) as refused:
        simulate(spec, users=3, days=0.001, progress=started.append)
    assert str(refused.value).startswith(says)
    assert started == []
