"""Never a silent hang, at every front door: `opspec run`, `opspec evaluate`, the walkthrough
(its session, and the command when the run cannot even start) and `opspec.testing.simulate`
end within seconds with one line naming the process, the cycle's activities and the simulated
time, and exit 1 — no traceback."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.errors import ZeroTimeCycleError
from opspec.tui.session import WalkSession
from opspec.xpdl.loader import load_spec

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "tests" / "engine" / "hang_specs"
#: spec -> (process named, activities of the cycle)
HANGS = {
    "cycle": ("spin", "B, C"),
    "self_start": ("again", "restart"),
    "loop": ("looping", "spin"),
    "zero_timer": ("ticking", "A, wait"),
}
START = "the simulated clock stopped advancing at t=0.000 s (d1 00:00:00): "


@pytest.fixture(autouse=True)
def small_limit(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("OPSPEC_MAX_INSTANT_STEPS", "20000")


def one_line(stderr: str, command: str, process: str, cycle: str) -> str:
    """The one line ``opspec COMMAND`` said about the cycle, begun with that command (the
    spec's load warnings, such as a cycle of subflows, are said before it)."""
    lines = [line for line in stderr.splitlines()
             if line.startswith("opspec") and ": warning: " not in line]
    assert len(lines) == 1, stderr
    [line] = lines
    # at the spec's line of the cycle (its first activity the message names)
    assert re.match(rf"opspec {command}: \S+\.xpdl:\d+: {re.escape(START)}", line), line
    assert f"process {process!r} (" in line and f"): {cycle} (" in line, line
    assert "Traceback" not in stderr
    return line


@pytest.mark.parametrize("name", list(HANGS))
def test_opspec_run_exits_1_with_one_line(name: str, capsys: pytest.CaptureFixture[str]
                                          ) -> None:
    began = time.perf_counter()
    status = main(["run", str(SPECS / f"{name}.xpdl"), "--timeline", "none",
                   "--until", "3600"])
    assert status == 1
    one_line(capsys.readouterr().err, "run", *HANGS[name])
    assert time.perf_counter() - began < 30


def test_opspec_run_in_a_process_with_the_default_limit_ends_within_seconds(
        tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k != "OPSPEC_MAX_INSTANT_STEPS"}
    began = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "opspec", "run", str(SPECS / "cycle.xpdl")],
                          capture_output=True, text=True, timeout=120, check=False, env=env,
                          cwd=tmp_path)
    assert done.returncode == 1
    line = one_line(done.stderr, "run", "spin", "B, C")
    from opspec.engine.zero_time import MAX_INSTANT_STEPS

    assert f"{MAX_INSTANT_STEPS:,} steps ran at that instant" in line
    assert time.perf_counter() - began < 60


def test_opspec_evaluate_exits_1_naming_the_cycle(tmp_path: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    began = time.perf_counter()
    status = main(["evaluate", str(SPECS / "cycle.xpdl"), "--users", "2", "--days", "1",
                   "--workers", "1", "--out", str(tmp_path / "out")])
    assert status == 1
    out = capsys.readouterr()
    assert "Traceback" not in out.out + out.err
    failed = [line for line in out.out.splitlines() if "stopped advancing" in line]
    assert len(failed) == 2
    for line in failed:
        assert "at t=0.000 s (d1 00:00:00)" in line
        assert "process 'spin' (instance 1): B, C" in line
    assert time.perf_counter() - began < 60


def test_the_walkthrough_session_ends_and_keeps_the_error() -> None:
    compiled = load_spec(SPECS / "cycle.xpdl")
    from opspec.engine.compiled import compile_package

    session = WalkSession(compile_package(compiled), days=1)
    assert session.ended
    error = session.failure
    assert isinstance(error, ZeroTimeCycleError)
    assert "process 'spin' (instance 1): B, C" in str(error)
    # the timeline shows it as an engine fault; stepping on does nothing
    assert session.events[-1].kind == "fault"
    assert session.events[-1].data["device"] == "engine"
    assert session.run_to(3600.0)
    session.advance(10.0)
    session.skip_until_user()
    assert session.now == 0.0


def test_a_cycle_met_while_walking_ends_the_session(tmp_path: Path) -> None:
    """The cycle starts after an hour: the session runs until then, then ends with it."""
    text = (SPECS / "cycle.xpdl").read_text()
    text = text.replace('<Activity Id="A"><Implementation><No/></Implementation></Activity>',
                        '<Activity Id="A"><Implementation><No/></Implementation>'
                        '<ExtendedAttributes><ExtendedAttribute Name="opspec:Duration" '
                        'Value="ConstantParameter(3600)"/></ExtendedAttributes></Activity>')
    later = tmp_path / "later.xpdl"
    later.write_text(text)
    from opspec.engine.compiled import compile_package

    session = WalkSession(compile_package(load_spec(later)), days=1)
    assert session.failure is None
    session.run_to(7200.0)
    assert isinstance(session.failure, ZeroTimeCycleError)
    assert "at t=3600.000 s (d1 01:00:00)" in str(session.failure)
    assert session.ended and session.now == 3600.0


def test_opspec_walkthrough_that_cannot_start_exits_1(capsys: pytest.CaptureFixture[str]
                                                      ) -> None:
    status = main(["walkthrough", str(SPECS / "loop.xpdl"), "--no-record"])
    assert status == 1
    one_line(capsys.readouterr().err, "walkthrough", "looping", "spin")


def test_opspec_testing_simulate_raises_it() -> None:
    from opspec.testing.simulation import simulate

    with pytest.raises(ZeroTimeCycleError, match=r"process 'again' \(.*\): restart"):
        simulate(SPECS / "self_start.xpdl", days=1)


def test_until_and_days_bound_a_run_that_never_runs_dry(tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]
                                                        ) -> None:
    """B -> C -> B forever, an hour a lap: --until and --days stop it where they say."""
    text = (SPECS / "cycle.xpdl").read_text().replace(
        '<Activity Id="C"><Implementation><No/></Implementation>',
        '<Activity Id="C"><Implementation><No/></Implementation><ExtendedAttributes>'
        '<ExtendedAttribute Name="opspec:Duration" Value="ConstantParameter(3600)"/>'
        "</ExtendedAttributes>")
    laps = tmp_path / "laps.xpdl"
    laps.write_text(text)
    for args, end in ((["--until", "PT5H"], 5 * 3600.0), (["--days", "2"], 2 * 86_400.0)):
        assert main(["run", str(laps), "--json", *args]) == 0
        assert json.loads(capsys.readouterr().out)["time"] == end


def test_a_trace_file_stops_at_its_cap_and_says_so(tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    from opspec.engine.trace_sinks import read_trace

    monkeypatch.setenv("OPSPEC_TRACE_MAX_BYTES", "20000")
    trace = tmp_path / "t.jsonl"
    status = main(["run", str(ROOT / "specs" / "medication_dispenser.xpdl"), "--days", "2",
                   "--timeline", "none", "--trace", str(trace)])
    assert status == 0
    notes = [line for line in capsys.readouterr().err.splitlines() if "cap" in line]
    assert len(notes) == 1
    assert notes[0].startswith(f"opspec run: note: the trace {trace} reached its cap of 20,000 "
                               "bytes at t=")
    assert "OPSPEC_TRACE_MAX_BYTES" in notes[0]
    events = list(read_trace(trace))
    assert events[-1].kind == "trace.truncated"
    assert trace.stat().st_size < 20_000 + 1000      # the cap plus the closing line


def test_a_trace_export_stops_at_its_cap(tmp_path: Path,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    from opspec.engine.trace import TraceEvent
    from opspec.errors import EvaluationError
    from opspec.evaluation.exporters import JsonlTraceWriter, XesWriter

    monkeypatch.setenv("OPSPEC_TRACE_MAX_BYTES", "5000")
    events = [TraceEvent(float(i), "activity.started", "p", 1, "a", "device")
              for i in range(200)]
    for writer_class in (XesWriter, JsonlTraceWriter):
        path = tmp_path / f"traces.{writer_class.__name__}"
        with (pytest.raises(EvaluationError, match="reached its cap of 5,000 bytes"),
              writer_class(path) as writer):
            writer.add_case("A/0", events)
        assert not path.exists()
