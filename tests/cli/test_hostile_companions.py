"""Hostile and clumsy input in the files that come with a spec (issue 17): the files given on the
command line besides the spec (user models, scripts and recordings, engine configurations,
traces, device profiles, scenario files) and the files a spec names (mode Sources, world files).

Each case exits with the documented status and says so in one line, without a traceback: a pipe
or device is refused at once and never blocks, an unreadable file exits 2, and a file a spec
names outside its folder tree is refused at its line by ``validate`` and by a run alike."""

from __future__ import annotations

import builtins
import errno
import os
import re
import shutil
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
VACUUM = ROOT / "specs" / "vacuum_cleaner.xpdl"
OPSPEC = [sys.executable, "-m", "opspec.cli"]


def opspec(*args: str, cwd: Path | None = None, env: dict[str, str] | None = None,
           timeout: float = 60) -> subprocess.CompletedProcess[str]:
    environment = {**os.environ, "PYTHONPATH": str(ROOT), **(env or {})}
    try:
        return subprocess.run([*OPSPEC, *args], check=False, capture_output=True, text=True,
                              timeout=timeout, env=environment, cwd=cwd,
                              stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:  # pragma: no cover - the bug
        pytest.fail(f"opspec {' '.join(args)} blocked")


def one_line(text: str) -> str:
    """The single line ``text`` holds (no traceback, nothing else)."""
    assert "Traceback" not in text
    lines = [line for line in text.splitlines() if line.strip()]
    assert len(lines) == 1, text
    return lines[0]


def within(seconds: float, call: Callable[[], Any]) -> BaseException | None:
    """Run ``call`` in a thread and return what it raised (``None`` if nothing); fail the test
    if it is still running after ``seconds`` (it blocked)."""
    outcome: list[BaseException | None] = []

    def target() -> None:
        try:
            call()
            outcome.append(None)
        except BaseException as error:  # noqa: BLE001 - handed back to the test
            outcome.append(error)

    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():  # pragma: no cover - the bug
        pytest.fail("it blocked")
    return outcome[0]


# Every option that names a file, as (command, arguments before and after the file).
# {out} is a fresh output folder or file.
OPTIONS: dict[str, tuple[list[str], str]] = {
    "run --user-model": (["run", str(SPEC), "--until", "60", "--user-model"],
                         "cannot read user model"),
    "run --script": (["run", str(SPEC), "--until", "60", "--script"],
                     "cannot read the script"),
    "run --engine-config": (["run", str(SPEC), "--until", "60", "--engine-config"],
                            "cannot read the engine configuration"),
    "evaluate --user-model": (["evaluate", str(SPEC), "--users", "1", "--days", "1",
                               "--out", "{out}", "--user-model"], "cannot read user model"),
    "evaluate --engine-config": (["evaluate", str(SPEC), "--users", "1", "--days", "1",
                                  "--out", "{out}", "--engine-config"],
                                 "cannot read the engine configuration"),
    "walkthrough --replay": (["walkthrough", str(SPEC), "--replay"], "cannot read the script"),
    "walkthrough --user-model": (["walkthrough", str(SPEC), "--user-model"],
                                 "cannot read user model"),
    "fit TRACE": (["fit", "-o", "{out}"], "cannot read trace"),
}


def _arguments(option: str, path: Path, tmp_path: Path) -> list[str]:
    before, _ = OPTIONS[option]
    args = [a.replace("{out}", str(tmp_path / "out")) for a in before]
    return [*args, str(path)]


# ---------------------------------------------------------------- pipes and devices


@pytest.mark.parametrize("option", sorted(OPTIONS))
def test_a_fifo_given_to_an_option_is_refused_at_once(tmp_path: Path, option: str) -> None:
    fifo = tmp_path / "companion.toml"
    os.mkfifo(fifo)
    done = opspec(*_arguments(option, fifo, tmp_path), timeout=30)
    assert done.returncode == 2, done.stderr
    line = one_line(done.stderr)
    assert line.endswith(f"{OPTIONS[option][1]}: it is a named pipe (FIFO), not a regular file")
    assert str(fifo) in line


@pytest.mark.parametrize("option", ["run --user-model", "run --script", "run --engine-config",
                                    "walkthrough --replay", "fit TRACE"])
def test_a_device_given_to_an_option_is_refused(tmp_path: Path, option: str) -> None:
    done = opspec(*_arguments(option, Path("/dev/zero"), tmp_path), timeout=30)
    assert done.returncode == 2, done.stderr
    assert one_line(done.stderr).endswith("it is a character device, not a regular file")


def test_a_fifo_among_the_device_profiles_is_refused(tmp_path: Path) -> None:
    profiles = tmp_path / "devices"
    profiles.mkdir()
    shutil.copy(ROOT / "devices" / "medication_dispenser.toml", profiles)
    os.mkfifo(profiles / "evil.toml")
    for command in (["run", str(SPEC), "--until", "60"], ["walkthrough", str(SPEC)]):
        done = opspec(*command, "--bind", "dispenser=auto", "--devices", str(profiles))
        assert done.returncode == 2, done.stderr
        assert one_line(done.stderr) == (f"opspec {command[0]}: cannot read device profile "
                                         f"{profiles}/evil.toml: it is a named pipe (FIFO), "
                                         "not a regular file")


def test_a_fifo_given_as_the_device_profile_folder_is_refused(tmp_path: Path) -> None:
    fifo = tmp_path / "devices"
    os.mkfifo(fifo)
    done = opspec("run", str(SPEC), "--until", "60", "--bind", "dispenser=auto",
                  "--devices", str(fifo))
    assert done.returncode == 2, done.stderr
    assert f"device profile directory {fifo} is a named pipe (FIFO), not a folder" in one_line(
        done.stderr)


def test_a_fifo_among_the_traces_of_a_folder_is_refused(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "run.jsonl")
    done = opspec("fit", str(tmp_path), "-o", str(tmp_path / "model.toml"))
    assert done.returncode == 2, done.stderr
    assert one_line(done.stderr).endswith("cannot read trace: it is a named pipe (FIFO), "
                                          "not a regular file")


def test_the_python_api_refuses_pipes_without_blocking(tmp_path: Path) -> None:
    from opspec.bindings.profiles import load_profile
    from opspec.engine.config import EngineConfig
    from opspec.errors import BindingError, ConfigurationError, UserModelError
    from opspec.testing.scenario import load_scenarios
    from opspec.testing.script import load_script
    from opspec.usermodels.fitting import read_trace
    from opspec.usermodels.loader import load_user_model

    fifo = tmp_path / "x.scenario.toml"
    os.mkfifo(fifo)
    cases: list[tuple[Callable[[], Any], type[BaseException]]] = [
        (lambda: load_user_model(fifo), UserModelError),
        (lambda: load_script(fifo), ConfigurationError),
        (lambda: EngineConfig.load(fifo), ConfigurationError),
        (lambda: list(read_trace(fifo)), UserModelError),
        (lambda: load_profile(fifo), BindingError),
        (lambda: load_scenarios(fifo), ConfigurationError),
    ]
    for call, kind in cases:
        error = within(20, call)
        assert isinstance(error, kind), error
        assert "it is a named pipe (FIFO), not a regular file" in str(error)


def test_a_fifo_scenario_file_does_not_hang_pytest(tmp_path: Path) -> None:
    """pytest hands only regular files to the plugin; a pipe named like a scenario file is
    passed over (and load_scenarios refuses one, above)."""
    os.mkfifo(tmp_path / "hang.scenario.toml")
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           str(tmp_path)], check=False, capture_output=True, text=True,
                          timeout=120, cwd=tmp_path, stdin=subprocess.DEVNULL,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 5, done.stdout          # no tests collected, nothing blocked
    assert "Traceback" not in done.stdout + done.stderr


# ---------------------------------------------------------------- unreadable files


@pytest.fixture
def deny(monkeypatch: pytest.MonkeyPatch) -> Callable[[Path], Path]:
    """``deny(path)``: opening ``path`` fails with Permission denied from then on. Root reads
    anything, so as root opening that one path is made to fail as it would for anyone else."""
    denied: set[Path] = set()
    real_os_open, real_open = os.open, builtins.open

    def is_denied(path: object) -> bool:
        try:
            return Path(os.fsdecode(path)).resolve() in denied  # type: ignore[arg-type]
        except (TypeError, ValueError):
            return False

    def os_open(path: object, *args: object, **kwargs: object) -> int:
        if is_denied(path):
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        return real_os_open(path, *args, **kwargs)  # type: ignore[arg-type]

    def open_(path: object, *args: object, **kwargs: object) -> object:
        if is_denied(path):
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        return real_open(path, *args, **kwargs)  # type: ignore[call-overload]

    monkeypatch.setattr(os, "open", os_open)
    monkeypatch.setattr(builtins, "open", open_)

    def add(path: Path) -> Path:
        path.chmod(0)
        denied.add(path.resolve())
        return path

    return add


def _readable_companion(option: str, tmp_path: Path) -> Path:
    """A file that would be accepted for ``option`` if it could be read."""
    if "user-model" in option:
        return Path(shutil.copy(ROOT / "specs" / "medication_dispenser.users.toml",
                                tmp_path / "model.toml"))
    if "engine-config" in option:
        path = tmp_path / "engine.toml"
        path.write_text("[engine]\nworkers = 1\n", encoding="utf-8")
        return path
    if option == "fit TRACE":
        path = tmp_path / "run.jsonl"
        assert main(["run", str(SPEC), "--until", "60", "--trace", str(path)]) == 0
        return path
    path = tmp_path / "script.toml"
    path.write_text("steps = []\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("option", sorted(OPTIONS))
def test_an_unreadable_file_given_to_an_option_exits_2(
        option: str, tmp_path: Path, deny: Callable[[Path], Path],
        capsys: pytest.CaptureFixture[str]) -> None:
    path = deny(_readable_companion(option, tmp_path))
    capsys.readouterr()
    status = main(_arguments(option, path, tmp_path))
    out, err = capsys.readouterr()
    assert status == 2, (out, err)
    command = option.split()[0]
    assert one_line(err) == f"opspec {command}: {path}: {OPTIONS[option][1]}: Permission denied"


def test_an_unreadable_device_profile_exits_2(tmp_path: Path, deny: Callable[[Path], Path],
                                              capsys: pytest.CaptureFixture[str]) -> None:
    profiles = tmp_path / "devices"
    profiles.mkdir()
    profile = deny(Path(shutil.copy(ROOT / "devices" / "medication_dispenser.toml", profiles)))
    status = main(["run", str(SPEC), "--until", "60", "--bind", "dispenser=auto",
                   "--devices", str(profiles)])
    assert status == 2
    assert one_line(capsys.readouterr().err) == (
        f"opspec run: cannot read device profile {profile}: Permission denied")


def test_a_report_template_that_cannot_be_read_is_refused_before_the_runs(
        tmp_path: Path, deny: Callable[[Path], Path],
        capsys: pytest.CaptureFixture[str]) -> None:
    fifo = tmp_path / "fifo.html.j2"
    os.mkfifo(fifo)
    template = tmp_path / "report.html.j2"
    template.write_text("<html></html>\n", encoding="utf-8")
    deny(template)
    for path, why in ((fifo, "it is a named pipe (FIFO), not a regular file"),
                      (template, "Permission denied")):
        status = main(["evaluate", str(SPEC), "--users", "1", "--days", "1", "--out",
                       str(tmp_path / f"out-{path.stem}"), "--report-template", str(path)])
        _, err = capsys.readouterr()
        assert status == 2
        assert one_line(err) == (f"opspec evaluate: cannot read the report template {path}: "
                                 f"{why}")
        assert not (tmp_path / f"out-{path.stem}").exists()     # refused before any run


def test_an_unreadable_scenario_file_is_refused(tmp_path: Path,
                                                deny: Callable[[Path], Path]) -> None:
    from opspec.errors import ConfigurationError
    from opspec.testing.scenario import load_scenarios

    path = tmp_path / "x.scenario.toml"
    path.write_text('spec = "x.xpdl"\n', encoding="utf-8")
    deny(path)
    with pytest.raises(ConfigurationError, match="cannot read the scenario file: Permission denied"):
        load_scenarios(path)


# ---------------------------------------------------------------- files a spec names


def _vacuum(folder: Path, *, world: str | None = None, mode_source: str | None = None) -> Path:
    """A copy of the vacuum cleaner spec in ``folder`` whose world file and/or dock mode Source
    are the given paths."""
    folder.mkdir(parents=True, exist_ok=True)
    text = VACUUM.read_text(encoding="utf-8")
    shutil.copy(VACUUM.with_name("vacuum_cleaner.world.toml"), folder)
    if world is not None:
        text = text.replace('Value="vacuum_cleaner.world.toml"', f'Value="{world}"')
    if mode_source is not None:
        assert '<opspec:Mode Id="dock"/>' in text
        text = text.replace('<opspec:Mode Id="dock"/>',
                            f'<opspec:Mode Id="dock" Source="{mode_source}"/>')
    spec = folder / "vacuum.xpdl"
    spec.write_text(text, encoding="utf-8")
    return spec


def _line_of(spec: Path, needle: str) -> int:
    for number, line in enumerate(spec.read_text(encoding="utf-8").splitlines(), start=1):
        if needle in line:
            return number
    raise AssertionError(needle)


OUTSIDE = ["/etc/passwd", "../../outside.toml"]


@pytest.mark.parametrize("target", OUTSIDE)
def test_a_world_file_outside_the_spec_folder_is_refused_by_validate_and_run(
        tmp_path: Path, target: str) -> None:
    spec = _vacuum(tmp_path / "a" / "b", world=target)
    line = _line_of(spec, "opspec:WorldFile")
    expected = re.compile(rf"{re.escape(str(spec))}:{line}: .*opspec:WorldFile "
                          rf"{re.escape(repr(target))} leads outside the spec's folder")
    checked = opspec("validate", str(spec))
    assert checked.returncode == 1, checked.stdout
    assert expected.search(checked.stdout), checked.stdout
    assert "OPSPEC_EXTERNAL_PATH" in checked.stdout
    ran = opspec("run", str(spec), "--until", "5")
    assert ran.returncode == 2, ran.stderr
    assert expected.search(one_line(ran.stderr))


@pytest.mark.parametrize("target", ["/etc/passwd", "../../dock.xpdl"])
def test_a_mode_source_outside_the_spec_folder_is_refused_by_validate_and_run(
        tmp_path: Path, target: str) -> None:
    spec = _vacuum(tmp_path / "a" / "b", mode_source=target)
    line = _line_of(spec, "opspec:Modes")
    expected = re.compile(rf"{re.escape(str(spec))}:{line}: .*mode 'dock': Source "
                          rf"{re.escape(repr(target))} leads outside the spec's folder")
    checked = opspec("validate", str(spec))
    assert checked.returncode == 1, checked.stdout
    assert expected.search(checked.stdout), checked.stdout
    assert "error" in checked.stdout
    ran = opspec("run", str(spec), "--until", "5")
    assert ran.returncode == 1, ran.stderr
    assert expected.search(one_line(ran.stderr))


def test_a_mode_source_outside_is_refused_by_the_python_api(tmp_path: Path) -> None:
    from opspec.errors import SpecError
    from opspec.runs import load
    from opspec.xpdl.loader import load_package

    spec = _vacuum(tmp_path / "a", mode_source="../dock.xpdl")
    shutil.copy(VACUUM, tmp_path / "dock.xpdl")
    package = load_package(spec).package
    assert package is not None
    with pytest.raises(SpecError, match="mode 'dock': Source '../dock.xpdl' leads outside"):
        load(package)


def test_a_link_leading_out_of_the_tree_is_refused(tmp_path: Path) -> None:
    outside = tmp_path / "elsewhere.toml"
    shutil.copy(VACUUM.with_name("vacuum_cleaner.world.toml"), outside)
    folder = tmp_path / "spec"
    spec = _vacuum(folder, world="linked.toml")
    (folder / "linked.toml").symlink_to(outside)
    checked = opspec("validate", str(spec))
    assert checked.returncode == 1
    assert f"which is {outside}" in checked.stdout


def test_opspec_external_path_allows_the_files_a_spec_names(tmp_path: Path) -> None:
    shared = tmp_path / "shared"
    shared.mkdir()
    shutil.copy(VACUUM.with_name("vacuum_cleaner.world.toml"), shared / "world.toml")
    spec = _vacuum(tmp_path / "specs", world="../shared/world.toml")
    assert opspec("validate", str(spec)).returncode == 1
    allowed = {"OPSPEC_EXTERNAL_PATH": str(shared)}
    checked = opspec("validate", str(spec), env=allowed)
    assert checked.returncode == 0, checked.stdout
    ran = opspec("run", str(spec), "--until", "5", env=allowed)
    assert ran.returncode == 0, ran.stderr


def test_a_world_file_inside_the_tree_still_loads(tmp_path: Path) -> None:
    folder = tmp_path / "spec"
    (folder / "worlds").mkdir(parents=True)
    shutil.copy(VACUUM.with_name("vacuum_cleaner.world.toml"), folder / "worlds" / "w.toml")
    spec = _vacuum(folder, world="worlds/../worlds/w.toml")
    assert opspec("validate", str(spec)).returncode == 0


def test_a_world_file_that_is_a_fifo_is_refused_without_blocking(tmp_path: Path) -> None:
    spec = _vacuum(tmp_path, world="pipe.toml")
    os.mkfifo(tmp_path / "pipe.toml")
    checked = opspec("validate", str(spec), timeout=30)
    assert checked.returncode == 1
    assert "cannot read the world file" in checked.stdout
    assert "it is a named pipe (FIFO), not a regular file" in checked.stdout
    ran = opspec("run", str(spec), "--until", "5", timeout=30)
    assert ran.returncode == 2
    assert one_line(ran.stderr).endswith("it is a named pipe (FIFO), not a regular file "
                                         "(opspec:WorldFile is relative to the spec)")


def test_a_mode_source_that_is_a_fifo_is_refused_without_blocking(tmp_path: Path) -> None:
    spec = _vacuum(tmp_path, mode_source="dock.xpdl")
    os.mkfifo(tmp_path / "dock.xpdl")
    checked = opspec("validate", str(spec), timeout=30)
    assert checked.returncode == 1
    assert ("mode 'dock' loads 'dock.xpdl', which cannot be read: it is a named pipe (FIFO), "
            "not a regular file") in checked.stdout
