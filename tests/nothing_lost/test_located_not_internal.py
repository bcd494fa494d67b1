"""Inputs that ended in "internal error" (exit status 70) get a message naming the file:
TOML and JSON nested deeper than Python's parsers can recurse (scripts, user models, engine
configurations, world files, device profiles, traces) and ``.wfs`` scripts nested deeply or
holding a number past Python's limit."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
DEEP = 100_000


def _deep_toml(path: Path) -> Path:
    path.write_text("steps = " + "[" * DEEP + "]" * DEEP + "\n", encoding="utf-8")
    return path


def _deep_json(path: Path) -> Path:
    path.write_text("[" * DEEP + "]" * DEEP, encoding="utf-8")
    return path


def _located(capsys, argv: list[str], named: Path) -> str:
    status = main(argv)
    err = capsys.readouterr().err
    assert status in (1, 2), err
    assert "internal error" not in err and "Traceback" not in err
    assert str(named) in err
    return err


@pytest.mark.parametrize("option", ["--script", "--user-model", "--engine-config"])
def test_deeply_nested_toml_options_are_located_errors(option, tmp_path, capsys) -> None:
    deep = _deep_toml(tmp_path / "deep.toml")
    err = _located(capsys, ["run", str(SPEC), option, str(deep), "--until", "60"], deep)
    assert "nest too deeply" in err


def test_a_deeply_nested_json_script_and_trace_are_located_errors(tmp_path, capsys) -> None:
    deep = _deep_json(tmp_path / "deep.json")
    assert "nest too deeply" in _located(
        capsys, ["run", str(SPEC), "--script", str(deep), "--until", "60"], deep)
    trace = _deep_json(tmp_path / "deep.jsonl")
    _located(capsys, ["fit", str(trace), "-o", str(tmp_path / "m.toml")], trace)


def test_a_deeply_nested_world_file_is_a_located_error(tmp_path, capsys) -> None:
    for name in ("toy_sumo.xpdl", "toy_sumo.world.toml"):
        shutil.copy(ROOT / "specs" / name, tmp_path)
    world = tmp_path / "toy_sumo.world.toml"
    world.write_text("ring = " + "[" * DEEP + "]" * DEEP + "\n", encoding="utf-8")
    _located(capsys, ["run", str(tmp_path / "toy_sumo.xpdl"), "--until", "60"], world)


def test_a_deeply_nested_device_profile_is_a_located_error(tmp_path, capsys) -> None:
    profile = tmp_path / "deep.toml"
    profile.write_text("name = " + "[" * DEEP + "]" * DEEP + "\n", encoding="utf-8")
    _located(capsys, ["devices", "emulate", str(profile), "--duration", "0.1"], profile)


@pytest.mark.parametrize("value", ["[" * DEEP + "]" * DEEP, "[" * 900 + "]" * 900,
                                   "1" * 5000], ids=["deep", "nested-900", "huge-int"])
def test_a_corrupt_wfs_is_a_located_error(value, tmp_path, capsys) -> None:
    wfs = tmp_path / "spec.wfs"
    assert main(["compile", str(SPEC), "-o", str(wfs)]) == 0
    capsys.readouterr()
    text = wfs.read_text(encoding="utf-8")
    doc = json.loads(text)
    assert "version" in doc
    wfs.write_text(text.replace('"version"', f'"extra": {value}, "version"', 1),
                   encoding="utf-8")
    err = _located(capsys, ["run", str(wfs), "--until", "60"], wfs)
    assert "corrupt workflow script" in err and len(err) < 2000
