"""Inputs that ended in "internal error" (exit status 70) get a message naming the file:
TOML and JSON nested deeper than Python's parsers can recurse (scripts, user models, engine
configurations, world files, device profiles, traces) and ``.wfs`` scripts nested deeply or
holding a number past Python's limit."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from nested_blocks import nested_blocks

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


def _model(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(("files", "start", "says"), [
    ({"self.toml": 'extends = "self.toml"\n'}, "self.toml", "is this file itself"),
    ({"a.toml": 'extends = "b.toml"\n', "b.toml": 'extends = "c.toml"\n',
      "c.toml": 'extends = "a.toml"\n'}, "a.toml", "a cycle"),
    ({"m/out.toml": 'extends = "../secret.toml"\n', "secret.toml": 'name = "x"\n'},
     "m/out.toml", "leads outside the user model's folder"),
    ({"abs.toml": 'extends = "/etc/hostname"\n'}, "abs.toml", "leads outside"),
], ids=["itself", "cycle", "relative-outside", "absolute"])
def test_user_model_extends_cycles_and_escapes_are_located_errors(files, start, says,
                                                                  tmp_path, capsys) -> None:
    for name, text in files.items():
        _model(tmp_path / name, text)
    model = tmp_path / start
    err = _located(capsys, ["run", str(SPEC), "--user-model", str(model), "--until", "60"],
                   model)
    assert says in err and "extends" in err


def test_extends_inside_the_folder_and_its_allowed_roots_still_work(tmp_path, monkeypatch,
                                                                     capsys) -> None:
    from opspec.usermodels.loader import load_user_model

    users = ROOT / "specs" / "medication_dispenser.users.toml"
    shutil.copy(users, tmp_path / "base.toml")
    child = _model(tmp_path / "sub" / "child.toml", 'extends = "../base.toml"\n')
    # the folder tree of the model is its own folder: ../ leaves it
    with pytest.raises(Exception, match="leads outside"):
        load_user_model(child)
    monkeypatch.setenv("OPSPEC_EXTERNAL_PATH", str(tmp_path))
    assert load_user_model(child).activities == load_user_model(users).activities
    sibling = _model(tmp_path / "sibling.toml", 'extends = "base.toml"\n')
    assert load_user_model(sibling).activities == load_user_model(users).activities


@pytest.mark.parametrize("command", [["check"], ["validate"], ["run", "--until", "10"],
                                     ["compile"]])
@pytest.mark.parametrize("shape", ["1500-deep", "cycle"])
def test_deeply_nested_or_cyclic_blocks_are_located_errors(command, shape, tmp_path,
                                                           capsys) -> None:
    # 1,500 deep is past Python's recursion limit (1,000): a guard that recursed would crash
    # here as the unguarded compile does (an internal RecursionError), and the file is a
    # quarter of the 5,000-deep one (the loader's cost grows faster than the depth)
    spec = nested_blocks(tmp_path / "deep.xpdl", 1500 if shape == "1500-deep" else 2,
                          cycle=shape == "cycle")
    status = main([command[0], str(spec), *command[1:]])
    out = capsys.readouterr()
    text = out.out + out.err
    assert status == 1, text
    assert "internal error" not in text
    assert f"{spec}:" in text and "nested more than 100 blocks deep" in text


def test_a_few_nested_blocks_still_run(tmp_path, capsys) -> None:
    spec = nested_blocks(tmp_path / "three.xpdl", 3)
    assert main(["check", str(spec)]) == 0
    assert main(["run", str(spec), "--until", "10"]) == 0


def test_show_refuses_to_hand_graphviz_a_huge_picture(tmp_path, capsys) -> None:
    n = 3000
    acts = "".join(f'<Activity Id="a{i}"><Implementation><No/></Implementation></Activity>'
                   for i in range(n))
    trs = "".join(f'<Transition Id="t{i}" From="a{i}" To="a{i + 1}"/>' for i in range(n - 1))
    spec = tmp_path / "big.xpdl"
    spec.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="http://www.wfmc.org/2008/'
        'XPDL2.1" Id="big" Name="big"><PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t'
        "</Vendor><Created>2026-01-01</Created></PackageHeader><WorkflowProcesses>"
        f'<WorkflowProcess Id="p"><ProcessHeader/><Activities>{acts}</Activities>'
        f"<Transitions>{trs}</Transitions></WorkflowProcess></WorkflowProcesses></Package>",
        encoding="utf-8")
    for fmt in ("svg", "html"):
        assert main(["show", str(spec), "--format", fmt]) == 2
        err = capsys.readouterr().err
        assert "more than the 4,000 Graphviz is given to lay out" in err and str(spec) in err
