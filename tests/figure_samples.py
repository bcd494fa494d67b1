"""A few figures of the report drawn from fixed numbers, for the tests that compare figures
drawn in the report's drawing processes with those drawn one after another in the test's own
process (tests/evaluation_output/test_drawing_processes.py, the processes started as the
replications end; tests/evaluation/test_drawing_processes_forked.py, the first forked before
the spec is loaded, the others by it). Importable from every folder of tests/ (the root conftest's
folder is on sys.path)."""

from __future__ import annotations

from pathlib import Path

from opspec.evaluation import plots

RATES = [("doses missed", 0.0034, 0.001, 0.008), ("doses taken", 0.95, 0.93, 0.97)]
DAYS = {"doses_taken": [4, 3, 4, 4, 2], "doses_missed": [0, 1, 0, 0, 2]}
LATENCIES = [30.0 + (i * 37 % 101) for i in range(300)]


def figures(folder: Path) -> list[Path]:
    """Three figures of different kinds (rates, over days, latency) drawn into ``folder``."""
    return [plots.rates_figure(RATES, folder / "rates.svg"),
            plots.over_days_figure(DAYS, folder / "days.svg"),
            plots.latency_figure("report_latency_s", LATENCIES, folder / "latency.svg",
                                 marks={"mean": 80.0, "median": 79.0, "p95": 126.0})]
