"""The summaries of a stored evaluation (what ``opspec evaluate --json`` prints), one import
for the commands, the report and the studies:

- per metric of a design, B − A per metric, per activity of the user's lane, per monitor:
  :mod:`.design_summary` (whose docstring lists every field);
- who the users of a population were, per subgroup: :mod:`.population_summary`;
- each finished user's ``(y, n)`` pair of every metric, held in arrays or spilled to disk:
  :mod:`.values_per_user`.
"""

from __future__ import annotations

from opspec.evaluation.design_summary import (
    PERCENTILES,
    compare_designs,
    metric_definitions,
    subgroup_users,
    summarise_activities,
    summarise_design,
    summarise_monitors,
)
from opspec.evaluation.population_summary import has_population, summarise_population
from opspec.evaluation.values_per_user import (
    Pairs,
    UserValues,
    pair_reader,
    per_user_values,
    user_pairs,
    user_pairs_by_metric,
    user_values,
)

__all__ = ["PERCENTILES", "Pairs", "UserValues", "compare_designs", "has_population",
           "metric_definitions", "pair_reader", "per_user_values", "subgroup_users",
           "summarise_activities", "summarise_design", "summarise_monitors",
           "summarise_population", "user_pairs", "user_pairs_by_metric", "user_values"]
