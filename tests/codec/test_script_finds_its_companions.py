"""A compiled script finds its spec's companion files (the world file) from any folder.

The script stored the spec's path as `opspec compile` was given it, relative to the folder it
ran in, and a run resolved the world file from there: `opspec run specs/vacuum_cleaner.wfs`
worked from one folder only, elsewhere 'cannot read the world file ...: it does not exist'.
The path is now written relative to the script (docs/wfs-format.md)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"


def _project(tmp_path: Path) -> Path:
    """A project folder holding specs/vacuum.xpdl and its world file."""
    specs = tmp_path / "project" / "specs"
    specs.mkdir(parents=True)
    shutil.copyfile(SPECS / "vacuum_cleaner.xpdl", specs / "vacuum.xpdl")
    shutil.copyfile(SPECS / "vacuum_cleaner.world.toml", specs / "vacuum_cleaner.world.toml")
    return specs.parent


def _summary(spec: str, capsys: pytest.CaptureFixture[str]) -> dict:
    capsys.readouterr()
    status = main(["run", spec, "--until", "20", "--seed", "3", "--json"])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    summary = json.loads(captured.out)
    del summary["spec"]
    return summary


def test_a_script_runs_from_another_folder_as_its_spec(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    project = _project(tmp_path)
    monkeypatch.chdir(project)
    assert main(["compile", "specs/vacuum.xpdl"]) == 0
    expected = _summary("specs/vacuum.xpdl", capsys)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    assert _summary(str(project / "specs" / "vacuum.wfs"), capsys) == expected
    monkeypatch.chdir(project / "specs")
    assert _summary("vacuum.wfs", capsys) == expected


def test_a_script_written_to_another_folder_runs_from_there(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    project = _project(tmp_path)
    (project / "build").mkdir()
    monkeypatch.chdir(project)
    assert main(["compile", "specs/vacuum.xpdl", "-o", "build/vacuum.wfs"]) == 0
    expected = _summary("specs/vacuum.xpdl", capsys)
    document = json.loads((project / "build" / "vacuum.wfs").read_text(encoding="utf-8"))
    assert document["source"] == "../specs/vacuum.xpdl"
    monkeypatch.chdir(project / "build")
    assert _summary("vacuum.wfs", capsys) == expected
    # the script and its spec moved together still find each other
    moved = tmp_path / "moved"
    shutil.move(project, moved)
    monkeypatch.chdir(tmp_path)
    assert _summary("moved/build/vacuum.wfs", capsys) == expected


def test_a_script_that_stored_the_path_from_where_it_was_compiled_still_runs_there(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    project = _project(tmp_path)
    monkeypatch.chdir(project)
    assert main(["compile", "specs/vacuum.xpdl"]) == 0
    script = project / "specs" / "vacuum.wfs"
    document = json.loads(script.read_text(encoding="utf-8"))
    # as scripts were written before: the path as compile was given it
    document["source"] = document["package"]["source"] = "specs/vacuum.xpdl"
    script.write_text(json.dumps(document), encoding="utf-8")
    assert _summary("specs/vacuum.wfs", capsys) == _summary("specs/vacuum.xpdl", capsys)
