"""The evaluation's figures, one import for the report and the commands: fit for a paper and
readable by people who did not run it.

Every figure function draws one figure, writes it to ``path`` (parent folders are created)
in the format :func:`figure_format` chose, else the one ``path``'s suffix names — SVG
(vector: the report inlines it; the report's default), PDF, or PNG at :data:`DPI` — and
returns the path written (with PDF, an SVG twin beside it, which is returned: the HTML report
shows that one). Empty input never raises: the figure then says "no observations", so a
report of a run in which nothing happened still has all its pictures. Non-finite values
(NaN, ±inf) are left out and counted in the figure's note.

Where each part is:

- the figures of one design's outcomes (rates, durations, counts over days and hours, the
  user's actions per activity): :mod:`.outcome_figures`;
- who the users are and how they differ (per user, by subgroup, drawn parameters):
  :mod:`.user_figures`;
- design B against A, and a sweep: :mod:`.comparison_figures`;
- the look they share (palette, fonts, notes): :mod:`.figure_style`;
- the formats and the writing of the files: :mod:`.figure_files` (the panels' layout:
  :mod:`.figure_layout`);
- the figures drawn side by side (:func:`drawn_by`; some asked for earlier,
  :func:`asked_ahead`): :mod:`.figure_queue`, by the drawing
  processes started early (:func:`drawing_processes`): :mod:`.drawing_pools`.

The report calls the figure functions through this module (``plots.rates_figure(...)``), so
that replacing one here (a test's spy, ``benchmarks/report_figures.py``'s recorder) replaces
it for the report. matplotlib is imported inside the functions, so ``import
opspec.evaluation.plots`` stays light.
"""

from __future__ import annotations

from opspec.evaluation.comparison_figures import comparison_figure, sweep_figure
from opspec.evaluation.drawing_pools import drawing_processes
from opspec.evaluation.figure_files import (
    DPI,
    FORMATS,
    _lay_out,  # noqa: F401 - benchmarks/report_figures.py times the layout
    figure_format,
)
from opspec.evaluation.figure_queue import (
    _FIGURES,  # noqa: F401 - benchmarks/report_figures.py: the figures by name
    asked_ahead,
    drawn_by,
)
from opspec.evaluation.figure_style import NO_OBSERVATIONS, PALETTE, PERCENT
from opspec.evaluation.matplotlib_import import (
    import_matplotlib as _import_matplotlib,  # noqa: F401 - benchmarks/report_figures.py
)
from opspec.evaluation.outcome_figures import (
    activity_rates_figure,
    latency_figure,
    over_days_figure,
    rates_figure,
    time_of_day_figure,
)
from opspec.evaluation.user_figures import (
    UserDistribution,
    parameters_figure,
    per_user_figure,
    subgroups_figure,
    user_distribution,
)

__all__ = [
    "DPI",
    "FORMATS",
    "NO_OBSERVATIONS",
    "PALETTE",
    "PERCENT",
    "UserDistribution",
    "activity_rates_figure",
    "asked_ahead",
    "comparison_figure",
    "drawing_processes",
    "drawn_by",
    "figure_format",
    "latency_figure",
    "over_days_figure",
    "parameters_figure",
    "per_user_figure",
    "rates_figure",
    "subgroups_figure",
    "sweep_figure",
    "time_of_day_figure",
    "user_distribution",
]
