"""`opspec evaluate` without drawing its report, for the tests that read what else it writes
(the result store, ``--json``, the exports) and never the report.

A small evaluation's cost is almost all its report (4 users x 2 days: 1.2 of 1.23 CPU-s,
matplotlib's six figures), so a test that checks an export or a count but draws a report
nobody reads spends most of its time on it. Inside ``without_report()`` the command stores,
summarises and exports as always; ``write_report`` returns the report's path unwritten, and
with ``--workers 2`` no process is started to draw. The report itself is checked where it is
the point (tests/evaluation_output/test_report_content.py, test_figure_numbers.py,
test_report_browser.py and others). Importable from every folder of tests/ (the root
conftest's folder is on sys.path); the ``no_report`` fixture of tests/conftest.py is the
same for one test.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest


@contextmanager
def without_report() -> Iterator[None]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("opspec.evaluation.report.write_report", _report_not_drawn)
        # nor start the processes that would draw it (--workers 2)
        patch.setattr("opspec.evaluation.plots.drawing_processes", _no_drawing)
        yield


@contextmanager
def _no_drawing(_workers: int) -> Iterator[None]:
    yield


def _report_not_drawn(store, summaries=None, **_options) -> Path:
    return Path(store.folder) / "report.html"
