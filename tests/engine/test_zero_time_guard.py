"""Never a silent hang: a run whose simulated clock stops advancing ends with one located
line naming the workflow, the activities that keep coming back and the simulated time."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from test_routing_fidelity import NS, activity, integer_field, spec, transition

from opspec.engine.simulation import Simulation
from opspec.errors import ZeroTimeCycleError
from opspec.xpdl.loader import load_spec


@pytest.fixture(autouse=True)
def small_limit(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("OPSPEC_MAX_INSTANT_STEPS", "20000")


def cycle(tmp_path: Path) -> Path:
    """B -> C -> B while x == 0, and nothing ever changes x (zero time throughout)."""
    acts = [activity("A"), activity("B", join="Exclusive"),
            activity("C", split="Exclusive"), activity("D")]
    trans = [transition("A", "B"), transition("B", "C"), transition("C", "B", "x == 0"),
             transition("C", "D", "otherwise")]
    return spec(tmp_path, acts, trans, integer_field("x", 0))


def test_a_cycle_of_instantaneous_activities_stops_the_run_naming_it(tmp_path: Path) -> None:
    sim = Simulation(load_spec(cycle(tmp_path)))
    with pytest.raises(ZeroTimeCycleError) as caught:
        sim.run()
    message = str(caught.value)
    assert "stopped advancing at t=0.000 s" in message
    assert "process 'p' (instance 1): " in message
    assert {"B", "C"} <= set(message.split("(instance 1): ")[1].split(" (")[0].split(", "))
    assert caught.value.sim_time == 0.0


def test_a_workflow_that_starts_itself_with_no_delay_stops_the_run(tmp_path: Path) -> None:
    acts = [('<Activity Id="again"><Implementation><SubFlow Id="p" Execution="ASYNCHR"/>'
             "</Implementation></Activity>")]
    sim = Simulation(load_spec(spec(tmp_path, acts, [])))
    with pytest.raises(ZeroTimeCycleError, match="process 'p'"):
        sim.start("p")          # a subflow target: nothing starts it by itself
        sim.run(until=10)


def test_a_loop_whose_body_takes_no_time_stops_the_run(tmp_path: Path) -> None:
    loop = ('<Loop LoopType="Standard"><LoopStandard LoopCondition="x == 0" TestTime="Before"/>'
            "</Loop>")
    acts = [activity("spin", extra=loop)]
    sim = Simulation(load_spec(spec(tmp_path, acts, [], integer_field("x", 0))))
    with pytest.raises(ZeroTimeCycleError, match="spin"):
        sim.run(until=10)


def test_opspec_run_exits_1_with_one_line_and_keeps_the_trace(tmp_path: Path) -> None:
    trace = tmp_path / "trace.jsonl"
    done = subprocess.run([sys.executable, "-m", "opspec", "run", str(cycle(tmp_path)),
                           "--timeline", "none", "--trace", str(trace)],
                          capture_output=True, text=True, timeout=120, check=False,
                          env={**__import__("os").environ, "OPSPEC_MAX_INSTANT_STEPS": "20000"})
    assert done.returncode == 1
    [line] = done.stderr.strip().splitlines()
    assert re.match(r"opspec run: \S+\.xpdl:\d+: the simulated clock stopped advancing at "
                    r"t=0\.000 s", line), line
    assert "Traceback" not in done.stderr
    assert trace.read_text().count('"activity.started"') > 1000



def _loops(tmp_path: Path, **bursts: tuple[int, int]) -> Path:
    """A workflow per keyword ``name=(second, iterations)``: at that simulated second, one
    activity run that many times at once (each iteration takes no time)."""
    processes = []
    for pid, (second, count) in bursts.items():
        spin = activity("spin", extra=(f'<Loop LoopType="Standard"><LoopStandard '
                                       f'LoopMaximum="{count}" TestTime="After"/></Loop>'))
        wait = [activity("wait", seconds=second)] if second else []
        flow = [transition("wait", "spin")] if second else []
        processes.append(f'<WorkflowProcess Id="{pid}"><ProcessHeader/><Activities>'
                         f"{''.join([*wait, spin])}</Activities>"
                         f"<Transitions>{''.join(flow)}</Transitions></WorkflowProcess>")
    path = tmp_path / "loops.xpdl"
    path.write_text(f'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="{NS}" '
                    'Id="loops"><PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor>'
                    "<Created>2026</Created></PackageHeader><WorkflowProcesses>"
                    f"{''.join(processes)}</WorkflowProcesses></Package>")
    return path


def _stopped_at(path: Path) -> float | None:
    """The simulated time at which the guard stopped a run of ``path`` (None: it ran)."""
    try:
        Simulation(load_spec(path)).run(until=10)
    except ZeroTimeCycleError as error:
        assert "2,000 steps ran at that instant" in str(error)
        return error.sim_time
    return None


def test_the_count_starts_again_at_every_instant(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """docs/soundness.md: the run "counts the zero-time steps at the current simulated
    instant ... The count starts again whenever the clock moves." So what one instant may do
    before the run is stopped does not depend on what ran before: a burst just below what
    stops a run at its first instant runs at any instant, and one just above it is stopped
    at any instant, however much ran a second before. (The count used to carry across
    instants until it passed the limit: a burst could then do up to twice the limit's steps,
    while the message said it had done the limit's.)"""
    monkeypatch.setenv("OPSPEC_MAX_INSTANT_STEPS", "2000")
    low, high = 1, 5_000                # the fewest iterations stopped at the first instant
    while low < high:
        middle = (low + high) // 2
        if _stopped_at(_loops(tmp_path, p=(0, middle))) is not None:
            high = middle
        else:
            low = middle + 1
    stopped = low
    assert _stopped_at(_loops(tmp_path, p=(0, stopped))) == 0.0
    for second in (1, 2):
        assert _stopped_at(_loops(tmp_path, p=(second, stopped - 1))) is None
        assert _stopped_at(_loops(tmp_path, p=(second, stopped))) == second
    for before in (stopped // 4, stopped // 2, stopped - 10):  # ("at" starts at 0 too)
        ran = {"before": (0, before)}
        assert _stopped_at(_loops(tmp_path, **ran, at=(1, stopped - 1))) is None
        assert _stopped_at(_loops(tmp_path, **ran, at=(1, stopped))) == 1.0
