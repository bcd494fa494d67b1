"""Fuzzing the front doors: mutated copies of files from specs/ and tests/ (specs, user
models, scripts) go through ``opspec validate``, ``check``, ``run`` (with ``--trace`` into an
output folder) and ``run --user-model`` / ``--script``. Whatever the mutation, no command may
end in a traceback or an internal error (exit status 70), hang, or write a file outside its
output folder. Bounded: a fixed number of examples, derandomized (the same inputs on every
run), each command stopped after a few seconds."""

from __future__ import annotations

import contextlib
import io
import os
import signal
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
SPECS = [SPEC, ROOT / "specs" / "medication_cart_guidance.xpdl",
         *sorted((ROOT / "tests" / "patterns" / "specs").glob("*.xpdl"))[:6]]
MODELS = [ROOT / "specs" / "medication_dispenser.users.toml",
          ROOT / "specs" / "medication_dispenser.population.toml"]
SCRIPT = ('steps = [["after trg_1 30s", "press_report"], ["after trg_2 10s", "take_pill"]]\n'
          'otherwise = "complete"\n').encode()

#: what mutations splice in: the shapes that broke readers before (deep nesting, huge
#: numbers, paths out of the folder, entities, control bytes)
TOKENS = [b"[" * 3000, b"{a = " * 500, b"9" * 5000, b"1e999999", b"../../../../tmp/x",
          b"/etc/passwd", b'<!DOCTYPE x [<!ENTITY a "aaaa">]>', b"&a;", b"\x00\xff\xfe",
          b"NaN", b"-0", b"\"\"\"", b"<Activity Id=\"", b"</Package>", b"PT0.00000000000000001S"]

SECONDS = 20           # a command that takes longer is a hang


class Hang(Exception):
    pass


def _alarm(_signum: int, _frame: object) -> None:
    raise Hang


@st.composite
def mutated(draw: st.DrawFn, sources: list[bytes]) -> bytes:
    data = bytearray(draw(st.sampled_from(sources)))
    for _ in range(draw(st.integers(1, 4))):
        at = draw(st.integers(0, len(data)))
        action = draw(st.sampled_from(["token", "delete", "duplicate", "flip"]))
        if action == "token":
            data[at:at] = draw(st.sampled_from(TOKENS))
        elif action == "delete":
            del data[at:at + draw(st.integers(1, 200))]
        elif action == "duplicate":
            data[at:at] = data[at:at + draw(st.integers(1, 400))]
        elif data:
            data[min(at, len(data) - 1)] ^= draw(st.integers(1, 255))
    return bytes(data)


def _files(folder: Path) -> set[Path]:
    return {p for p in folder.rglob("*") if p.is_file()}


def _run(folder: Path, argv: list[str]) -> None:
    """Run ``opspec argv`` in ``folder``: no traceback, no exit 70, no hang, and nothing
    written outside ``folder/out`` (the input files aside)."""
    before = _files(folder)
    out, err = io.StringIO(), io.StringIO()
    cwd = Path.cwd()
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(SECONDS)
    try:
        os.chdir(folder)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = main(argv)
    except Hang:
        pytest.fail(f"opspec {' '.join(argv)} ran longer than {SECONDS} s")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
        os.chdir(cwd)
    text = out.getvalue() + err.getvalue()
    assert status != 70 and "internal error" not in text, (argv, text[-2000:])
    assert "Traceback" not in text, (argv, text[-2000:])
    stray = {p for p in _files(folder) - before if folder / "out" not in p.parents}
    assert not stray, f"opspec {' '.join(argv)} wrote outside its output folder: {stray}"


_SETTINGS = settings(max_examples=25, derandomize=True, deadline=None, database=None,
                     suppress_health_check=list(HealthCheck))


@pytest.mark.skipif(not hasattr(signal, "SIGALRM"), reason="needs SIGALRM for the hang bound")
@_SETTINGS
@given(data=mutated([p.read_bytes() for p in SPECS]))
def test_mutated_specs_never_crash_hang_or_write_outside(data: bytes) -> None:
    with tempfile.TemporaryDirectory(prefix="opspec-fuzz-") as scratch:
        folder = Path(scratch)
        spec = folder / "spec.xpdl"
        spec.write_bytes(data)
        (folder / "out").mkdir()
        _run(folder, ["validate", str(spec)])
        _run(folder, ["check", str(spec), "--max-states", "2000"])
        _run(folder, ["run", str(spec), "--until", "600", "--timeline", "none", "--no-user",
                      "--trace", str(folder / "out" / "trace.jsonl")])


@pytest.mark.skipif(not hasattr(signal, "SIGALRM"), reason="needs SIGALRM for the hang bound")
@_SETTINGS
@given(data=mutated([*(p.read_bytes() for p in MODELS), SCRIPT]),
       option=st.sampled_from(["--user-model", "--script"]))
def test_mutated_user_models_and_scripts_never_crash_or_hang(data: bytes, option: str) -> None:
    with tempfile.TemporaryDirectory(prefix="opspec-fuzz-") as scratch:
        folder = Path(scratch)
        given_file = folder / ("model.toml" if option == "--user-model" else "script.toml")
        given_file.write_bytes(data)
        (folder / "out").mkdir()
        _run(folder, ["run", str(SPEC), option, str(given_file), "--until", "30000",
                      "--timeline", "none", "--trace", str(folder / "out" / "trace.jsonl")])
