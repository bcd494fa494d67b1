"""`opspec evaluate --workers 2` starts the report's drawing processes before it loads the spec
(they import matplotlib on the core its start-up leaves idle). A bad spec or user model must
still stop the command before any simulation, with its message naming the file (and line), no
traceback and nothing created - and that error must not wait for the drawing processes, which
are ended at once: none outlives the command, none finishes its import, and no thread of
theirs is left for the interpreter's exit (Python 3.11 wakes each such thread there without a
lock: one closing its pipe at that moment printed a traceback after the error)."""

from __future__ import annotations

import multiprocessing
import threading
import time
from concurrent.futures import process as pool_internals
from pathlib import Path

import pytest
from evaluation_inputs import SPEC

from opspec.evaluation import drawing_pools, plots

BAD_SPEC = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p" Name="p">
  <WorkflowProcesses><WorkflowProcess Id="w"><Transitions>
    <Transition Id="t" From="nowhere" To="elsewhere"/>
  </Transitions></WorkflowProcess></WorkflowProcesses>
</Package>
"""


@pytest.fixture
def slow_drawing(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> tuple[Path, list[int]]:
    """Drawing processes whose matplotlib import takes 30 s and then leaves a file behind
    (forked, they run the function patched here); and the numbers of drawing processes asked
    for, so that the test knows they were started."""
    done = tmp_path / "a drawing process finished its import"
    asked: list[int] = []

    def slow_import() -> None:
        time.sleep(30)
        done.touch()

    started = plots.drawing_processes

    def counted(workers: int, **options: object):  # type: ignore[no-untyped-def]
        asked.append(workers)
        return started(workers, **options)

    monkeypatch.setattr(drawing_pools, "_import_matplotlib", slow_import)
    monkeypatch.setattr(plots, "drawing_processes", counted)
    return done, asked


def _pool_threads_alive() -> list[threading.Thread]:
    """The process pools' managing threads still running (each one's wake-up pipe is
    written to at the interpreter's exit), and the threads that send the drawing processes
    their figures."""
    return [t for t in threading.enumerate()
            if (isinstance(t, pool_internals._ExecutorManagerThread)
                or t.name == "opspec-drawing") and t.is_alive()]


def _two_cores(monkeypatch: pytest.MonkeyPatch) -> None:
    # the drawing processes are as many as the workers, up to the cores
    import opspec.commands.evaluate as command

    monkeypatch.setattr(command, "_local_cores", lambda: 2)


def test_bad_spec_fails_at_once_and_ends_the_drawing_processes(
        evaluate, slow_drawing, monkeypatch, tmp_path):
    _two_cores(monkeypatch)
    spec = tmp_path / "bad.xpdl"
    spec.write_text(BAD_SPEC, encoding="utf-8")
    out = tmp_path / "never"
    status, doc, err = evaluate(str(spec), "--users", "4", "--days", "1", "--workers", "2",
                                "--out", str(out))
    done, asked = slow_drawing
    assert status == 1 and doc is None
    assert f"{spec}:4:" in err and "nowhere" in err and "Traceback" not in err
    assert not out.exists()
    assert asked == [2]                         # they were started, before the spec was read
    assert multiprocessing.active_children() == []
    assert _pool_threads_alive() == []
    assert not done.exists()


def test_bad_user_model_fails_at_once_and_ends_the_drawing_processes(
        evaluate, slow_drawing, monkeypatch, tmp_path):
    _two_cores(monkeypatch)
    model = tmp_path / "bad.users.toml"
    model.write_text('[activities.hear_alarm]\nduration = { kind = "zipf", a = 2 }\n',
                     encoding="utf-8")
    out = tmp_path / "never"
    status, doc, err = evaluate(str(SPEC), "--user-model", str(model), "--users", "4",
                                "--days", "1", "--workers", "2", "--out", str(out))
    done, asked = slow_drawing
    assert status == 2 and doc is None
    assert str(model) in err and "zipf" in err and "Traceback" not in err
    assert not out.exists()
    assert asked == [2]
    assert multiprocessing.active_children() == []
    assert _pool_threads_alive() == []
    assert not done.exists()
