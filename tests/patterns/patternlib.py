"""Run a pattern spec and read its trace (imported by the tests of tests/patterns)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from opspec.testing.simulation import SimulationResult, simulate

SPECS = Path(__file__).resolve().parent / "specs"


def run(name: str | Path, *, script: Sequence[tuple[Any, str]] | None = None,
        until: float = 3600.0, **kwargs: Any) -> SimulationResult:
    """Run ``specs/NAME`` (or a path) for one user until ``until`` simulated seconds; the user
    lane is the script, by default the cooperative user ``[]`` (every offer at once), as the
    oracle runs every activity."""
    path = Path(name) if isinstance(name, Path) else SPECS / name
    return simulate(str(path), script=list(script) if script is not None else [],
                    until=until, seed=1, keep_trace=True, **kwargs)


def events(result: SimulationResult, kind: str | None = None, *, process: str | None = None,
           activity: str | None = None) -> list[Any]:
    return [e for e in result.trace
            if (kind is None or e.kind == kind) and (process is None or e.process == process)
            and (activity is None or e.activity == activity)]


def done(result: SimulationResult, process: str | None = None) -> list[str]:
    """Ids of completed activities, in trace order."""
    return [e.activity for e in events(result, "activity.completed", process=process)
            if e.activity is not None]


def started(result: SimulationResult, process: str | None = None) -> list[str]:
    return [e.activity for e in events(result, "activity.started", process=process)
            if e.activity is not None]


def when(result: SimulationResult, activity: str, kind: str = "activity.completed") -> list[float]:
    """Times of each ``kind`` event of ``activity``."""
    return [e.time for e in events(result, kind, activity=activity)]


def first(result: SimulationResult, activity: str, kind: str = "activity.completed") -> float:
    found = when(result, activity, kind)
    assert found, f"{activity} never {kind.split('.')[-1]}; completed: {done(result)}"
    return found[0]


def outcomes(result: SimulationResult, process: str) -> list[str]:
    return [i.outcome for i in result.instances(process)]


def dump(result: SimulationResult) -> str:
    """The trace as text, for failure messages."""
    return "\n".join(f"{e.time:9.3f} #{e.instance} {e.process} {e.kind} {e.activity or ''} "
                     f"{e.data or ''}" for e in result.trace)
