"""A disk that fills while ``opspec run --trace`` writes: the run goes on to its end, its
results are printed, the trace keeps what was written, and the failure is said (with where
the trace ends) and ends the run with exit status 1 — never an internal error (issue 33)."""

from __future__ import annotations

import errno
import io
import json
from pathlib import Path
from typing import Any

import pytest

from opspec.cli import main
from opspec.engine import trace_sinks

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"


class _FillingFile(io.StringIO):
    """A text file on a disk with room for ``room`` characters."""

    def __init__(self, path: Path, room: int) -> None:
        super().__init__()
        self.path, self.room = path, room

    def write(self, text: str) -> int:
        if self.tell() + len(text) > self.room:
            raise OSError(errno.ENOSPC, "No space left on device")
        return super().write(text)

    def close(self) -> None:
        self.path.write_text(self.getvalue(), encoding="utf-8")
        super().close()


def test_a_full_disk_ends_the_trace_not_the_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    trace = tmp_path / "t.jsonl"

    def filling_open(path: Any, *args: Any, **kwargs: Any) -> _FillingFile:
        return _FillingFile(Path(path), room=20_000)

    monkeypatch.setattr(trace_sinks, "open", filling_open, raising=False)
    status = main(["run", str(SPEC), "--days", "1", "--seed", "3", "--trace", str(trace),
                   "--timeline", "none"])
    out, err = capsys.readouterr()
    assert status == 1
    assert "instances:" in out                         # the run's results are all there
    assert "writing the trace" in err and "No space left on device" in err
    assert "internal error" not in err and "Traceback" not in err
    lines = trace.read_text(encoding="utf-8").splitlines()
    assert lines and all(json.loads(line) for line in lines)   # what was written is whole
    assert 0 < sum(len(line) + 1 for line in lines) <= 20_000
