"""`opspec new` and the mistakes a newcomer makes with it: a NAME that is no new folder ('.'),
a spec file's name for the folder ('pill.xpdl'), a folder with a space whose printed commands
must still run when pasted, a write that fails half-way; and the README it writes, whose
commands must all be opspec's."""

from __future__ import annotations

import errno
import shlex
from pathlib import Path

import pytest

from opspec.cli import _subparsers, build_parser, main
from opspec.commands.new import SHAPES, render


@pytest.mark.parametrize("typed", [".", "./", "..", "/"])
def test_a_name_with_no_last_part_is_refused_saying_what_was_typed(
        typed: str, capsys: pytest.CaptureFixture[str]) -> None:
    """Before, '.' was refused as "'' cannot name a spec", as if nothing had been typed."""
    assert main(["new", typed]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"{typed!r} names no new folder" in err and "''" not in err
    assert "opspec new pill_reminder" in err


@pytest.mark.parametrize("suffix", [".xpdl", ".bpmn", ".XPDL"])
def test_a_spec_files_name_is_refused_with_the_folder_to_give_instead(
        suffix: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Before, 'opspec new pill.xpdl' wrote pill.xpdl/pill.xpdl.xpdl."""
    typed = tmp_path / f"pill{suffix}"
    assert main(["new", str(typed)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"opspec new {tmp_path / 'pill'} writes {tmp_path / 'pill' / 'pill.xpdl'}" in err
    assert list(tmp_path.iterdir()) == []


def test_a_dotted_name_that_is_not_a_spec_file_is_still_a_name(tmp_path: Path) -> None:
    assert main(["new", str(tmp_path / "pill.v2")]) == 0
    assert (tmp_path / "pill.v2" / "pill.v2.xpdl").is_file()


def test_the_commands_it_prints_name_the_files_when_pasted_into_a_shell(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A folder with a space (or a quoted '~') was printed bare: pasted, the command got
    two arguments, or the home folder."""
    folder = tmp_path / "my specs" / "pill"
    assert main(["new", str(folder)]) == 0
    commands = [line.strip().removeprefix("try:").strip()
                for line in capsys.readouterr().out.splitlines()[1:]]
    assert len(commands) == 3
    for command in commands:
        words = shlex.split(command)
        target = Path(words[3] if words[0] == "python" else words[2])
        assert target.exists(), command
    assert shlex.split(commands[0]) == ["opspec", "run", str(folder / "pill.xpdl")]


def test_a_write_that_fails_half_way_leaves_nothing_so_trying_again_works(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """Before, a disk that filled up after the first file left the folder behind, and the
    next 'opspec new' with the same name was refused: 'already exists'."""
    (tmp_path / "mine.txt").write_text("kept", encoding="utf-8")
    folder = tmp_path / "new" / "parents" / "pill"
    write_text = Path.write_text
    calls: list[Path] = []

    def fill_up(self: Path, *args: object, **kwargs: object) -> int:
        calls.append(self)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        return write_text(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(Path, "write_text", fill_up)
    assert main(["new", str(folder)]) == 2
    err = capsys.readouterr().err
    assert err == f"opspec new: cannot write {folder}: No space left on device; nothing written\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.txt"]
    monkeypatch.undo()
    assert main(["new", str(folder)]) == 0


@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_the_readme_lists_each_of_opspecs_ways_to_use_the_spec(shape: str) -> None:
    """Every command of the README's block is an opspec command, and the block offers the
    walkthrough (play the user yourself), which only the spec's comment mentioned before."""
    readme = render("pb", shape)["README.md"]
    block = readme.split("```sh\n", 1)[1].split("```", 1)[0]
    commands = _subparsers(build_parser())
    used = [line.split()[1] for line in block.splitlines() if line.startswith("opspec ")]
    assert set(used) <= set(commands)
    assert {"validate", "run", "evaluate", "check", "walkthrough"} <= set(used)


def test_the_help_names_the_test_file_it_writes() -> None:
    """The help said test_NAME.py; for pill-box the file is test_pill_box.py."""
    help_text = " ".join(_subparsers(build_parser())["new"].format_help().split())
    assert "test_pill_box.py for pill-box" in help_text
    assert "test_pill_box.py" in render("pill-box")


def test_a_name_with_an_accent_is_told_which_letters_are_meant(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """'médicament' was refused with "use letters, digits, ...": é is a letter."""
    assert main(["new", str(tmp_path / "médicament")]) == 2
    assert "the letters a-z and A-Z (no accents)" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
