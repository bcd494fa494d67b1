"""`opspec preprocess` output runs where it is written (issue 17): relative companion paths
follow it, the user model is copied beside it, and every output the bundled XPDL 2.1 XSD
rejects carries a not-schema-valid warning."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from lxml import etree

from opspec.cli import main
from opspec.model.package import ExternalPackage, Package
from opspec.model.sisarl import WorkflowMode
from opspec.xpdl.relocate import relocate
from opspec.xpdl.schema import schema_for

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"
CORPUS = Path("/work/shared/corpus/xpdl")
XPDL21 = "http://www.wfmc.org/2008/XPDL2.1"


def test_a_preprocessed_world_spec_validates_and_runs_from_another_folder(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "elsewhere" / "deeper" / "vacuum.xpdl"
    out.parent.mkdir(parents=True)
    assert main(["preprocess", str(SPECS / "vacuum_cleaner.xpdl"), "-o", str(out)]) == 0
    root = etree.parse(str(out)).getroot()
    (world_file,) = [e.get("Value") for e in root.iter(f"{{{XPDL21}}}ExtendedAttribute")
                     if e.get("Name") == "opspec:WorldFile"]
    # the original lies outside the output's folder tree, where opspec does not read files a
    # spec names (docs/validation.md): the world file is copied beside the output
    assert world_file == "vacuum_cleaner.world.toml"
    assert (out.parent / world_file).read_bytes() == (
        SPECS / "vacuum_cleaner.world.toml").read_bytes()
    capsys.readouterr()
    assert main(["validate", str(out)]) == 0, capsys.readouterr().out
    assert main(["run", str(out), "--until", "5"]) == 0


def test_a_preprocessed_world_spec_above_the_input_names_the_original(tmp_path: Path) -> None:
    """Written in a folder whose tree holds the input, the output names the original world
    file by a rewritten path and nothing is copied."""
    specs = tmp_path / "specs"
    specs.mkdir()
    shutil.copy(SPECS / "vacuum_cleaner.xpdl", specs)
    shutil.copy(SPECS / "vacuum_cleaner.world.toml", specs)
    above = tmp_path / "vacuum.xpdl"
    assert main(["preprocess", str(specs / "vacuum_cleaner.xpdl"), "-o", str(above)]) == 0
    assert 'Value="specs/vacuum_cleaner.world.toml"' in above.read_text(encoding="utf-8")
    assert not (tmp_path / "vacuum_cleaner.world.toml").exists()
    assert main(["validate", str(above)]) == 0


def test_output_to_stdout_keeps_paths_as_written(capsys: pytest.CaptureFixture[str],
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(SPECS)
    assert main(["preprocess", "vacuum_cleaner.xpdl", "-o", "-"]) == 0
    assert 'Value="vacuum_cleaner.world.toml"' in capsys.readouterr().out


def test_the_user_model_is_copied_beside_the_output(tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "dispenser.xpdl"
    assert main(["preprocess", str(SPECS / "medication_dispenser.xpdl"), "-o", str(out)]) == 0
    copy = tmp_path / "dispenser.users.toml"
    assert copy.read_bytes() == (SPECS / "medication_dispenser.users.toml").read_bytes()
    capsys.readouterr()
    assert main(["evaluate", str(out), "--users", "2", "--days", "1", "--workers", "1",
                 "--out", str(tmp_path / "runs")]) == 0
    assert f"user model {copy}" in capsys.readouterr().out


def test_an_existing_different_user_model_beside_the_output_is_kept(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "dispenser.xpdl"
    mine = tmp_path / "dispenser.users.toml"
    mine.write_text("# mine\n")
    assert main(["preprocess", str(SPECS / "medication_dispenser.xpdl"), "-o", str(out)]) == 0
    assert mine.read_text() == "# mine\n"
    assert f"kept {mine}" in capsys.readouterr().err


def test_relocate_rewrites_mode_sources_and_external_hrefs(tmp_path: Path) -> None:
    source = tmp_path / "specs" / "robot.xpdl"
    package = Package(id="p", modes=(WorkflowMode(id="dock", source="modes/dock.xpdl"),),
                      external_packages=(ExternalPackage(id="lib", href="lib.xpdl"),))
    above, warnings = relocate(package, source, tmp_path / "robot.xpdl")
    assert above.modes[0].source == "specs/modes/dock.xpdl"
    assert above.external_packages[0].href == "specs/lib.xpdl"
    assert warnings == []                 # inside the output's folder tree
    below, warnings = relocate(package, source, tmp_path / "specs" / "out" / "robot.xpdl")
    assert below.modes[0].source == "../modes/dock.xpdl"
    assert below.external_packages[0].href == "../lib.xpdl"
    # both now lead out of the output's folder tree: the mode Source and the package
    assert [w.code for w in warnings] == ["relocated-outside", "relocated-outside"]
    # beside the input: nothing changes; URLs and absolute paths are left alone
    same, _ = relocate(package, source, tmp_path / "specs" / "robot.std.xpdl")
    assert same == package
    remote = Package(id="p", external_packages=(
        ExternalPackage(id="a", href="http://x/lib.xpdl"), ExternalPackage(id="b", href="/abs.xpdl")))
    assert relocate(remote, source, tmp_path / "o" / "r.xpdl")[0] == remote


def test_relocate_warns_when_an_external_package_falls_outside_the_output_folder(
        tmp_path: Path) -> None:
    source = tmp_path / "specs" / "main.xpdl"
    package = Package(id="p", external_packages=(ExternalPackage(id="lib", href="lib.xpdl"),))
    moved, warnings = relocate(package, source, tmp_path / "out" / "main.xpdl")
    assert moved.external_packages[0].href == "../specs/lib.xpdl"
    (warning,) = warnings
    assert warning.code == "relocated-outside" and "OPSPEC_EXTERNAL_PATH" in warning.hint


GHOST_POOL = f"""<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="{XPDL21}" Id="p" Name="p">
  <Pools><Pool Id="pool" Name="pool" Process="ghost" BoundaryVisible="false"/></Pools>
  <WorkflowProcesses><WorkflowProcess Id="main" Name="main"><Activities>
    <Activity Id="a" Name="a"><Implementation><No/></Implementation></Activity>
  </Activities></WorkflowProcess></WorkflowProcesses>
</Package>
"""


def test_an_output_the_xsd_rejects_for_any_reason_gets_the_warning(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "ghost.xpdl"
    spec.write_text(GHOST_POOL)
    out = tmp_path / "out.xpdl"
    assert main(["preprocess", str(spec), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    (line,) = [x for x in err.splitlines() if "will not be valid XPDL 2.1" in x]
    assert line.startswith(f"{spec}:2: warning: ") and "PoolProcessIdRef.Package" in line
    assert not schema_for(XPDL21).validate(etree.parse(str(out)))
    assert main(["preprocess", str(spec), "-o", str(tmp_path / "strict.xpdl"), "--strict"]) == 1


CORPUS_FILES = sorted(CORPUS.glob("*.xpdl")) + sorted(SPECS.glob("*.xpdl"))


@pytest.mark.parametrize("path", CORPUS_FILES, ids=lambda p: p.name)
def test_every_written_output_is_xsd_valid_or_says_it_is_not(
        path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = tmp_path / path.name
    shutil.copy(path, source)
    for companion in path.parent.glob(path.name.removesuffix(".xpdl") + ".*.toml"):
        shutil.copy(companion, tmp_path / companion.name)
    out = tmp_path / "out.xpdl"
    status = main(["preprocess", str(source), "-o", str(out)])
    err = capsys.readouterr().err
    if status != 0:
        assert not out.exists()
        pytest.skip("refused (validate's errors)")
    valid = schema_for(XPDL21).validate(etree.parse(str(out)))
    assert valid == ("will not be valid XPDL 2.1" not in err), err


def test_relocate_copies_or_warns_for_companions_leading_outside(tmp_path: Path) -> None:
    from opspec.model.common import ExtendedAttribute

    world = ExtendedAttribute(name="opspec:WorldFile", value="worlds/room.toml")
    package = Package(id="p", extended_attributes=(world,),
                      modes=(WorkflowMode(id="dock", source="dock.xpdl"),))
    source, output = tmp_path / "specs" / "r.xpdl", tmp_path / "out" / "r.xpdl"
    copies: list[tuple[Path, Path]] = []
    moved, warnings = relocate(package, source, output, copies=copies)
    assert moved.extended_attributes[0].value == "room.toml"          # copied beside OUT
    assert copies == [(tmp_path / "specs" / "worlds" / "room.toml", tmp_path / "out" / "room.toml")]
    assert moved.modes[0].source == "../specs/dock.xpdl"
    (warning,) = warnings                                               # the mode: not copied
    assert warning.code == "relocated-outside" and "mode 'dock'" in warning.message
    moved, warnings = relocate(package, source, output)                 # no copies: warned
    assert moved.extended_attributes[0].value == "../specs/worlds/room.toml"
    assert sorted("world file" in w.message for w in warnings) == [False, True]


def test_mode_sources_written_verbatim_are_rewritten_too(tmp_path: Path) -> None:
    from opspec.model.common import ExtendedAttribute
    from opspec.xpdl.writer import write_xpdl

    modes = ExtendedAttribute(name="opspec:Modes",
                              raw_xml='<opspec:Mode xmlns:opspec="urn:opspec:sisarl:1" '
                                      'Id="dock" Source="dock.xpdl"/>')
    package = Package(id="p", extended_attributes=(modes,),
                      modes=(WorkflowMode(id="dock", source="dock.xpdl"),))
    moved, _ = relocate(package, tmp_path / "specs" / "r.xpdl",
                        tmp_path / "specs" / "sub" / "r.xpdl")
    assert 'Source="../dock.xpdl"' in write_xpdl(moved).decode()
