"""A file given as the spec that is no XML at all (a TOML user model, a world file, a device
profile, a script, JSON, plain text, a binary file) is refused saying what it is and what is
wanted, through every door: the spec reader (opspec.xpdl.safe_xml) once called each "not
well-formed XML at column 1". A broken XML file keeps the reader's own message."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.errors import SpecError
from opspec.testing import simulate

ROOT = Path(__file__).resolve().parents[2]
WANTED = "give an XPDL (.xpdl) or BPMN 2.0 (.bpmn) specification, or one compiled to .wfs"

#: name -> (content or a file of the repository to copy, what the message says it is)
FILES: dict[str, tuple[str | bytes | Path, str]] = {
    "users.toml": (ROOT / "specs" / "medication_dispenser.users.toml", "a user model (TOML)"),
    "room.world.toml": (ROOT / "specs" / "vacuum_cleaner.world.toml", "a world file (TOML)"),
    "battery.toml": (ROOT / "devices" / "battery.toml", "a device profile (TOML)"),
    "late.toml": ('steps = [["after trg_2 400s", "press_report"]]\n', "a script (TOML)"),
    "other.toml": ("a = 1\n", "a TOML file"),
    "x.json": ('{"a": 1}', "JSON"),
    "notes.txt": ("hello world\n", "text that is not XML (it starts 'hello world')"),
    "blob.xpdl": (bytes(range(256)) * 2, "a binary file (not text)"),
}


def _file(tmp_path: Path, name: str) -> tuple[Path, str]:
    content, what = FILES[name]
    path = tmp_path / name
    if isinstance(content, Path):
        shutil.copy(content, path)
    elif isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, encoding="utf-8")
    return path, f"{path}:1: this is {what}, not a specification"


@pytest.mark.parametrize("name", sorted(FILES))
def test_validate_says_what_the_file_is(tmp_path: Path, name: str,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    path, says = _file(tmp_path, name)
    assert main(["validate", str(path)]) == 1
    out = capsys.readouterr().out
    assert f"{says}; {WANTED}" in out.replace(":1: error: ", ":1: ")
    assert "well-formed" not in out
    # its own code, for a tool reading --json: it is no spec, not a broken one
    assert main(["validate", str(path), "--json"]) == 1
    codes = [d["code"] for d in json.loads(capsys.readouterr().out)["diagnostics"]]
    assert codes == ["not-a-spec"]


def test_a_user_model_is_told_where_it_goes(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    path, _says = _file(tmp_path, "users.toml")
    assert main(["validate", str(path)]) == 1
    assert "a user model: give it to --user-model" in capsys.readouterr().out


@pytest.mark.parametrize("command", [
    ["run"], ["evaluate", "--users", "1", "--days", "0.01"], ["walkthrough"], ["check"],
    ["show"], ["compile"]])
def test_every_door_says_it(tmp_path: Path, command: list[str],
                            capsys: pytest.CaptureFixture[str]) -> None:
    path, says = _file(tmp_path, "x.json")
    args = [command[0], str(path), *command[1:]]
    if command == ["compile"]:
        args += ["-o", str(tmp_path / "x.wfs")]
    assert main(args) != 0
    captured = capsys.readouterr()
    said = (captured.out + captured.err).replace(":1: error: ", ":1: ")   # as a diagnostic
    assert says in said
    assert "well-formed" not in said


def test_simulate_says_it(tmp_path: Path) -> None:
    path, says = _file(tmp_path, "users.toml")
    with pytest.raises(SpecError) as refused:
        simulate(path)
    assert str(refused.value).startswith(says)


def test_broken_xml_keeps_the_readers_message(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    cut = tmp_path / "cut.xpdl"
    cut.write_bytes((ROOT / "specs" / "medication_dispenser.xpdl").read_bytes()[:3000])
    assert main(["validate", str(cut)]) == 1
    out = capsys.readouterr().out
    assert "the file ends inside a tag" in out and "not a specification" not in out


@pytest.mark.parametrize("encoding", ["utf-16-le", "utf-16"], ids=["no-bom", "bom"])
def test_broken_utf16_xml_is_still_xml(tmp_path: Path, encoding: str,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    # its NUL bytes are no sign of a binary file: libxml2 reads UTF-16 with or without a BOM
    broken = tmp_path / "wide.xpdl"
    broken.write_bytes("<Package><x></Package>".encode(encoding))
    assert main(["validate", str(broken)]) == 1
    out = capsys.readouterr().out
    assert "not a specification" not in out and "binary" not in out
