"""`opspec check` on a path it cannot read (a device, a pipe) says so in one line, exit status
2: it added 'not checked: the file could not be read as a spec (XPDL or BPMN); fix the errors
listed above', which is no spec error to fix. A corrupt compiled script's line says it is one."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from opspec.cli import main


def test_a_device_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", os.devnull]) == 2
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 1 and out[0].startswith(
        f"{os.devnull}: error: cannot read the file: it is a character device")


def test_a_pipe_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pipe = tmp_path / "spec.xpdl"
    os.mkfifo(pipe)
    assert main(["check", str(pipe)]) == 2
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 1 and "it is a named pipe (FIFO)" in out[0]


def test_a_corrupt_script_is_said_to_be_one(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    script = tmp_path / "x.wfs"
    script.write_text("{", encoding="utf-8")
    assert main(["check", str(script)]) == 1
    assert capsys.readouterr().out.splitlines()[-1] == (
        f"{script}: not checked: the file could not be read as a compiled workflow script; "
        "fix or recompile it as the error above says")
