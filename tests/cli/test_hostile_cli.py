"""Hostile and clumsy input at the command line (issue 17): each case exits with the documented
status and says so in one line, without a traceback. Exit statuses: 1 a problem in a spec, 2
usage or I/O (a path that is not a readable regular file, an output that is the input)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
CORPUS = Path("/work/shared/corpus/xpdl")
OPSPEC = [sys.executable, "-m", "opspec.cli"]

# Every command that reads a spec, with the arguments that make it quick.
SPEC_COMMANDS = {
    "validate": [],
    "show": [],
    "check": [],
    "compile": [],
    "preprocess": ["-o", "-"],
    "run": ["--until", "60"],
    "evaluate": ["--users", "1", "--days", "1"],
    "walkthrough": ["--replay", "/nonexistent.toml"],
}


def said_without_traceback(*outputs: str) -> None:
    text = "".join(outputs)
    assert "Traceback" not in text
    assert text.strip(), "nothing was said"


def opspec(*args: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([*OPSPEC, *args], check=False, capture_output=True, text=True,
                          timeout=timeout,
                          env=env, stdin=subprocess.DEVNULL)


# ---------------------------------------------------------------- pipes and devices


@pytest.mark.parametrize("command", sorted(SPEC_COMMANDS))
def test_a_fifo_given_as_a_spec_is_refused_at_once(tmp_path: Path, command: str) -> None:
    fifo = tmp_path / "spec.xpdl"
    os.mkfifo(fifo)
    try:
        done = opspec(command, str(fifo), *SPEC_COMMANDS[command], timeout=30)
    except subprocess.TimeoutExpired:  # pragma: no cover - the bug
        pytest.fail(f"opspec {command} blocked on a FIFO")
    assert done.returncode == 2, done.stderr
    said_without_traceback(done.stdout, done.stderr)
    assert "named pipe (FIFO), not a regular file" in done.stderr + done.stdout


@pytest.mark.parametrize("command", ["validate", "compile", "preprocess", "run"])
def test_a_device_given_as_a_spec_is_refused(command: str) -> None:
    done = opspec(command, "/dev/zero", *SPEC_COMMANDS[command], timeout=30)
    assert done.returncode == 2, done.stderr
    assert "character device, not a regular file" in done.stderr + done.stdout


# ---------------------------------------------------------------- unreadable files


@pytest.fixture
def unreadable(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A copy of the dispenser spec nobody may read. Root reads anything, so as root opening
    that one path fails as it would for anyone else (PermissionError)."""
    import builtins
    import errno

    spec = tmp_path / "spec.xpdl"
    shutil.copy(SPEC, spec)
    spec.chmod(0)
    if os.access(spec, os.R_OK):
        real_os_open, real_open = os.open, builtins.open

        def denied(path: object) -> bool:
            try:
                return Path(os.fsdecode(path)).resolve() == spec  # type: ignore[arg-type]
            except (TypeError, ValueError):
                return False

        def os_open(path: object, *args: object, **kwargs: object) -> int:
            if denied(path):
                raise PermissionError(errno.EACCES, "Permission denied", str(path))
            return real_os_open(path, *args, **kwargs)  # type: ignore[arg-type]

        def open_(path: object, *args: object, **kwargs: object) -> object:
            if denied(path):
                raise PermissionError(errno.EACCES, "Permission denied", str(path))
            return real_open(path, *args, **kwargs)  # type: ignore[call-overload]

        monkeypatch.setattr(os, "open", os_open)
        monkeypatch.setattr(builtins, "open", open_)
    return spec.resolve()


@pytest.mark.parametrize("command", sorted(SPEC_COMMANDS))
def test_an_unreadable_spec_exits_2_in_every_command(
        unreadable: Path, command: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    args = list(SPEC_COMMANDS[command])
    if command == "compile":
        args = ["-o", str(tmp_path / "out.wfs")]
    if command == "evaluate":
        args += ["--out", str(tmp_path / "runs")]
    status = main([command, str(unreadable), *args])
    out, err = capsys.readouterr()
    assert status == 2, (out, err)
    said_without_traceback(out, err)
    assert "Permission denied" in out + err


def test_an_unreadable_compiled_script_exits_2(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    import errno

    script = tmp_path / "spec.wfs"
    assert main(["compile", str(SPEC), "-o", str(script)]) == 0
    real_os_open = os.open

    def os_open(path: object, *args: object, **kwargs: object) -> int:
        if os.fsdecode(path) == str(script):  # type: ignore[arg-type]
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        return real_os_open(path, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(os, "open", os_open)
    capsys.readouterr()
    assert main(["run", str(script), "--until", "60"]) == 2
    assert "cannot read the file: Permission denied" in capsys.readouterr().err


# ---------------------------------------------------------------- outputs that are the input


def test_compile_never_overwrites_its_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                            ) -> None:
    spec = tmp_path / "spec.xpdl"
    shutil.copy(SPEC, spec)
    before = spec.read_bytes()
    assert main(["compile", str(spec), "-o", str(spec)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is the file this command reads as IN; refusing to overwrite it" in err
    assert spec.read_bytes() == before


def test_compile_does_not_overwrite_its_input_through_a_link(tmp_path: Path) -> None:
    spec = tmp_path / "spec.xpdl"
    shutil.copy(SPEC, spec)
    (tmp_path / "out.wfs").symlink_to(spec)
    os.link(spec, tmp_path / "hard.wfs")
    assert main(["compile", str(spec), "-o", str(tmp_path / "out.wfs")]) == 2
    assert main(["compile", str(spec), "-o", str(tmp_path / "hard.wfs")]) == 2
    assert spec.read_bytes() == SPEC.read_bytes()


def test_compile_of_a_wfs_to_its_default_output_is_refused(tmp_path: Path) -> None:
    script = tmp_path / "spec.wfs"
    assert main(["compile", str(SPEC), "-o", str(script)]) == 0
    before = script.read_bytes()
    assert main(["compile", str(script)]) == 2          # default output: spec.wfs itself
    assert script.read_bytes() == before


def test_compile_spec_refuses_to_overwrite_its_input(tmp_path: Path) -> None:
    from opspec.errors import ConfigurationError
    from opspec.xpdl.compile import compile_spec

    spec = tmp_path / "spec.xpdl"
    shutil.copy(SPEC, spec)
    with pytest.raises(ConfigurationError, match="is the input file itself"):
        compile_spec(spec, spec)


def test_preprocess_never_overwrites_its_input(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "spec.xpdl"
    shutil.copy(SPEC, spec)
    before = spec.read_bytes()
    assert main(["preprocess", str(spec), "-o", str(spec)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is the file this command reads as IN; refusing to overwrite it" in err
    assert spec.read_bytes() == before
    (tmp_path / "link.xpdl").symlink_to(spec)
    assert main(["preprocess", str(spec), "-o", str(tmp_path / "link.xpdl")]) == 2
    assert spec.read_bytes() == before


# ---------------------------------------------------------------- validate --schema


def test_validate_schema_reports_what_the_wfmc_schema_rejects(
        capsys: pytest.CaptureFixture[str]) -> None:
    path = CORPUS / "g360__Subprocess.xpdl"
    if not path.is_file():
        pytest.skip("corpus not present")
    main(["validate", str(path)])
    assert "schema-invalid" not in capsys.readouterr().out
    assert main(["validate", "--schema", "--json", str(path)]) == 1
    out = capsys.readouterr().out
    assert '"code": "schema-invalid"' in out and '"line": 3' in out
    assert "ConformanceClass" in out and "bpmnxpdl_31.xsd" in out


def test_validate_schema_accepts_the_bundled_specs(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", "--schema", str(SPEC)]) == 0
    assert "schema" not in capsys.readouterr().out.replace("0 warnings", "")


@pytest.mark.parametrize(("namespace", "says"), [
    ("http://www.wfmc.org/2009/XPDL2.2", "no XSD for XPDL 2.2"),
    ("http://www.wfmc.org/2004/XPDL2.0alpha", "no XSD for XPDL 2.0"),
    ("", "no namespace"),
])
def test_validate_schema_says_when_no_schema_is_bundled(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], namespace: str, says: str) -> None:
    spec = tmp_path / "p.xpdl"
    xmlns = f' xmlns="{namespace}"' if namespace else ""
    spec.write_text(f'<Package{xmlns} Id="p"/>')
    assert main(["validate", "--schema", str(spec)]) == 0
    out = capsys.readouterr().out
    assert f"{spec}:1: warning: not schema-validated: " in out and says in out
    assert main(["validate", "--schema", "--strict", str(spec)]) == 1


def test_schema_imports_resolve_locally_only(monkeypatch: pytest.MonkeyPatch) -> None:
    import socket

    from opspec.xpdl import schema

    def no_network(*_args: object, **_kwargs: object) -> None:
        raise AssertionError("the schema tried the network")

    monkeypatch.setattr(socket, "create_connection", no_network)
    monkeypatch.setattr(socket.socket, "connect", no_network)
    schema._compiled.cache_clear()
    compiled = schema.schema_for("http://www.wfmc.org/2008/XPDL2.1")
    assert compiled is not None
    text = (schema.SCHEMA_DIR / "bpmnxpdl_31.xsd").read_text()
    assert 'schemaLocation="http://www.wfmc.org/standards/docs/TC-1025_schema_10_xpdl.xsd"' in text
