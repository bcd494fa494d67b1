"""The report's figures of a stored evaluation, drawn again in one process: CPU per figure and
per part (the layout, the drawing and writing of the SVG), least of ``--repeat``.

    python benchmarks/report_figures.py RUN_FOLDER [--repeat 5] [--format svg]

``RUN_FOLDER`` is the ``--out`` of a finished ``opspec evaluate`` (for example of
``opspec evaluate specs/medication_dispenser.xpdl --users 1000 --days 30 --out runs/d``).
The report is written again once (``evaluate --resume``: the summaries and the report, no
replication) with the figure functions' arguments recorded, then each figure is drawn
``--repeat`` times into a temporary folder; the first line gives the CPU of importing
matplotlib (once per drawing process), each figure's line the least CPU of its repetitions
(every repetition after the first is warm: fonts loaded, text measures cached per figure
only). What the evaluate process pays is about the import plus the first (cold) drawing,
0.1-0.2 CPU-s above the least. The machine's load average is printed with them: measure
before and after a change alternately, or count instructions (``valgrind --tool=callgrind``
on this script with ``--repeat 1``).
"""

from __future__ import annotations

import argparse
import contextlib
import inspect
import io
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

cpu = time.process_time


def record(run: Path) -> list[tuple[str, tuple[Any, ...], dict[str, Any]]]:
    """The figure calls of the report of ``run`` (``evaluate --resume``), in order."""
    from opspec.cli import main
    from opspec.evaluation import plots

    calls: list[tuple[str, tuple[Any, ...], dict[str, Any]]] = []
    saved = {name: getattr(plots, name) for name in plots._FIGURES}

    def recorder(name: str) -> Any:
        def figure(*args: Any, **kwargs: Any) -> Any:
            calls.append((name, args, kwargs))
            return saved[name](*args, **kwargs)
        return figure

    for name in saved:
        setattr(plots, name, recorder(name))
    try:
        with contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(io.StringIO()):
            status = main(["evaluate", "--resume", "--out", str(run), "--workers", "1",
                           "--quiet"])
    finally:
        for name, figure in saved.items():
            setattr(plots, name, figure)
    if status not in (0, 1) or not calls:
        sys.exit(f"{run}: `opspec evaluate --resume --out {run}` drew no figure")
    return calls


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="the --out folder of a finished evaluation")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--format", default="svg", choices=("svg", "pdf", "png"))
    args = parser.parse_args()
    calls = record(args.run)

    # what a drawing process pays first, in a fresh interpreter (numpy loaded, as it is)
    import subprocess

    from matplotlib.figure import Figure

    from opspec.evaluation import plots

    code = ("import time, numpy\nfrom opspec.evaluation.plots import _import_matplotlib as i"
            "\nt = time.process_time(); i()\nprint(time.process_time() - t)")
    imported = float(subprocess.run([sys.executable, "-c", code], capture_output=True,
                                    text=True, check=True).stdout)
    parts: dict[str, float] = {}

    def timed(name: str, work: Any) -> Any:
        def run(*a: Any, **k: Any) -> Any:
            begin = cpu()
            try:
                return work(*a, **k)
            finally:
                parts[name] = parts.get(name, 0.0) + cpu() - begin
        return run

    try:                                # where saving a figure calls the layout
        from opspec.evaluation import figure_files as saving
    except ImportError:                 # a tree before plots.py was split: plots' own
        saving = plots
    if hasattr(saving, "_lay_out"):     # a tree before the measured layout: "all" only
        saving._lay_out = timed("layout", saving._lay_out)
    Figure.savefig = timed("drawing and writing", Figure.savefig)  # type: ignore[method-assign]
    least: dict[str, dict[str, float]] = {}
    with tempfile.TemporaryDirectory() as folder:
        for _ in range(args.repeat):
            for name, given, kwargs in calls:
                bound = inspect.signature(plots._FIGURES[name]).bind(*given, **kwargs)
                bound.arguments["path"] = Path(folder) / Path(bound.arguments["path"]).name
                parts.clear()
                begin = cpu()
                with plots.figure_format(args.format):
                    getattr(plots, name)(*bound.args, **bound.kwargs)
                parts["all"] = cpu() - begin
                mine = least.setdefault(name, {})
                for part, spent in parts.items():
                    mine[part] = min(mine.get(part, spent), spent)
    load = os.getloadavg()
    print(f"{args.run}: {len(calls)} figures, {args.format}, least of {args.repeat}; "
          f"load {load[0]:.1f} on {os.cpu_count()} cores")
    print(f"  importing matplotlib (once per process)  {imported:6.3f} CPU-s")
    columns = ("all", "layout", "drawing and writing")
    print(f"  {'figure':<26}" + "".join(f"{c:>22}" for c in columns))
    totals = dict.fromkeys(columns, 0.0)
    for name, spent in least.items():
        print(f"  {name:<26}" + "".join(f"{spent.get(c, 0.0):22.3f}" for c in columns))
        for c in columns:
            totals[c] += spent.get(c, 0.0)
    print(f"  {'all figures':<26}" + "".join(f"{totals[c]:22.3f}" for c in columns))


if __name__ == "__main__":
    main()
