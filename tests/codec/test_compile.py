"""`opspec compile`: every loadable spec compiles to a .wfs that loads back to an equal model;
a spec with errors is refused; I/O problems are one-line messages with exit status 2."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.errors import SpecError
from opspec.model.codec import dumps, loads, read_wfs
from opspec.xpdl.compile import compile_spec, default_output
from opspec.xpdl.loader import load_package

CORPUS = Path("/work/shared/corpus/xpdl")
SPECS = Path(__file__).resolve().parents[2] / "specs"
FILES = sorted(CORPUS.glob("*.xpdl")) + sorted(SPECS.glob("*.xpdl"))


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_every_loaded_spec_round_trips_through_the_json_form_unchanged(path: Path) -> None:
    loaded = load_package(path)
    if loaded.package is None:
        pytest.skip(f"{path.name} does not load (the reader tests say why)")
    # Locations, extended attributes and expression trees included: plain equality.
    assert loads(dumps(loaded.package)) == loaded.package


def test_compile_writes_a_script_that_loads_to_the_same_package(tmp_path: Path) -> None:
    source = SPECS / "medication_dispenser.xpdl"
    result = compile_spec(source, tmp_path / "dispenser.wfs")
    assert result.output == tmp_path / "dispenser.wfs"
    assert read_wfs(result.output) == load_package(source).package
    document = json.loads(result.output.read_text())
    assert (document["format"], document["version"]) == ("opspec-wfs", 1)
    assert document["source"] == str(source)


def test_the_default_output_is_the_input_with_the_wfs_suffix() -> None:
    assert default_output("specs/a.xpdl") == Path("specs/a.wfs")


def test_cli_compile_prints_where_it_wrote_and_exits_0(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source = tmp_path / "dispenser.xpdl"
    source.write_bytes((SPECS / "medication_dispenser.xpdl").read_bytes())
    assert main(["compile", str(source)]) == 0
    assert (tmp_path / "dispenser.wfs").is_file()
    assert "dispenser.wfs: compiled from" in capsys.readouterr().out


def test_a_spec_with_errors_is_refused_with_every_diagnostic_and_nothing_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source = tmp_path / "bad.xpdl"
    text = (SPECS / "medication_dispenser.xpdl").read_text()
    text = text.replace('Name="opspec:Priority" Value="2"', 'Name="opspec:Priority" Value="high"')
    text = text.replace('Name="opspec:Lane" Value="user"', 'Name="opspec:Lane" Value="robot"')
    source.write_text(text)
    out = tmp_path / "bad.wfs"
    assert main(["compile", str(source), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    error_lines = [line for line in err.splitlines() if ": error: " in line]
    assert len(error_lines) == 2
    assert all(line.startswith(f"{source}:") for line in error_lines)
    assert not out.exists()
    with pytest.raises(SpecError, match="opspec:Priority"):
        compile_spec(source, out)


def test_strict_refuses_warnings_too(tmp_path: Path) -> None:
    source = tmp_path / "warn.xpdl"
    text = (SPECS / "medication_dispenser.xpdl").read_text()
    source.write_text(text.replace('Name="opspec:Lane" Value="user"',
                                   'Name="opspec:Lane" Value="user"/>'
                                   '<ExtendedAttribute Name="opspec:Colour" Value="red"'))
    assert compile_spec(source, tmp_path / "ok.wfs").diagnostics  # a warning, still written
    with pytest.raises(SpecError, match="unknown directive"):
        compile_spec(source, tmp_path / "strict.wfs", strict=True)


@pytest.mark.parametrize("which", ["missing-input", "folder-input", "unwritable-output"])
def test_compile_io_problems_are_one_line_with_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], which: str
) -> None:
    source = {"missing-input": tmp_path / "none.xpdl", "folder-input": tmp_path,
              "unwritable-output": SPECS / "medication_dispenser.xpdl"}[which]
    out = tmp_path / "no-such-dir" / "x.wfs"
    assert main(["compile", str(source), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and err.startswith("opspec compile: ")


# Errors only the structural checks find (the file itself reads fine): `opspec validate`
# rejects these, so compile must too (it used to write the script anyway).
STRUCTURAL_ERRORS = {
    "dangling-transition": ('From="start_notify" To="timer_done"', 'From="start_notify" To="nowhere"'),
    "undefined-performer": ('<Performer>user</Performer>', '<Performer>ghost</Performer>'),
}


def _broken_dispenser(tmp_path: Path, case: str) -> Path:
    old, new = STRUCTURAL_ERRORS[case]
    text = (SPECS / "medication_dispenser.xpdl").read_text()
    assert old in text
    source = tmp_path / f"{case}.xpdl"
    source.write_text(text.replace(old, new, 1))
    return source


@pytest.mark.parametrize("case", sorted(STRUCTURAL_ERRORS))
def test_compile_refuses_a_spec_that_validate_rejects(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], case: str
) -> None:
    source = _broken_dispenser(tmp_path, case)
    assert main(["validate", str(source)]) == 1
    capsys.readouterr()
    out = tmp_path / "out.wfs"
    assert main(["compile", str(source), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    errors = [line for line in err.splitlines() if ": error: " in line]
    assert errors and all(line.startswith(f"{source}:") for line in errors)
    assert all(line.split(":")[1].isdigit() for line in errors)   # path:line
    assert "nothing written" in err
    assert not out.exists()


@pytest.mark.parametrize("path", sorted(SPECS.glob("*.xpdl")), ids=lambda p: p.name)
def test_every_bundled_spec_compiles(tmp_path: Path, path: Path) -> None:
    assert main(["compile", str(path), "-o", str(tmp_path / "out.wfs")]) == 0


@pytest.mark.parametrize("command", ["compile", "preprocess"])
def test_written_files_respect_the_umask(tmp_path: Path, command: str) -> None:
    import os
    import stat

    out = tmp_path / ("out.wfs" if command == "compile" else "out.xpdl")
    old = os.umask(0o022)
    try:
        assert main([command, str(SPECS / "toy_sumo.xpdl"), "-o", str(out)]) == 0
        assert stat.S_IMODE(out.stat().st_mode) == 0o644
        os.umask(0o027)
        other = out.with_name("other" + out.suffix)
        assert main([command, str(SPECS / "toy_sumo.xpdl"), "-o", str(other)]) == 0
        assert stat.S_IMODE(other.stat().st_mode) == 0o640
        out.chmod(0o664)                       # rewriting keeps the mode the file has
        assert main([command, str(SPECS / "toy_sumo.xpdl"), "-o", str(out)]) == 0
        assert stat.S_IMODE(out.stat().st_mode) == 0o664
    finally:
        os.umask(old)
