"""A report that cannot be written (a full disk) leaves neither a half-written report.html
nor its report.html.tmp behind: the resume hint then finds a clean folder."""

from __future__ import annotations

import errno
from pathlib import Path

import pytest

from opspec.errors import EvaluationError
from opspec.evaluation import html


def test_a_failed_report_write_removes_its_temporary_file(tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    def full_disk(src: object, dst: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(html.os, "replace", full_disk)
    with pytest.raises(EvaluationError, match="No space left on device"):
        html._write(tmp_path / "report.html", "<html>" + "x" * 10_000 + "</html>")
    assert sorted(p.name for p in tmp_path.iterdir()) == []
