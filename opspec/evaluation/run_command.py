"""The ``opspec evaluate`` command line that runs a stored evaluation again, from its plan:
the report prints it under "What was run" so that a reader of a paper can reproduce the
numbers (the same seed gives the same results with any number of workers, so ``--workers``
is not part of it).

Only options a command line carries exactly are written; a run whose plan holds more (an
engine configuration stored as its settings, run inputs drawn per user or read from a data
file, a sweep, parameter draws of a fitted model) has no command here: the plan stored in
``results.sqlite`` (table ``run``, key ``plan``) is then what describes it.
"""

from __future__ import annotations

import shlex
from collections.abc import Mapping
from typing import Any

__all__ = ["rerun_command"]


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value) if isinstance(value, float) else str(value)


def rerun_command(plan: Mapping[str, Any], *, swept: bool = False) -> str | None:
    """The command that gives the results of the run with ``plan`` (the stored JSON) again,
    or None when a command line cannot say all of it (``swept``: the run was a sweep)."""
    designs = list(plan.get("designs") or [])
    labels = [d.get("label") for d in designs]
    if (swept or plan.get("engine") or plan.get("run_inputs")
            or plan.get("input_uncertainty") or labels not in (["A"], ["A", "B"])):
        return None
    # --param values: the same for every design, and of the spec (not a swept user.…)
    parameters = [tuple(p) for p in designs[0].get("parameters") or ()]
    if (any([tuple(p) for p in d.get("parameters") or ()] != parameters for d in designs)
            or any(not str(name).startswith("spec.") for name, _value in parameters)):
        return None
    days = float(plan["days"])
    words = ["opspec", "evaluate", designs[0]["spec"]]
    if len(designs) > 1:
        words += ["--compare", designs[1]["spec"]]
    words += ["--users", str(plan["users"]),
              "--days", f"{days:g}" if float(f"{days:g}") == days else repr(days),
              "--seed", str(plan["seed"])]
    if plan.get("user_model"):
        words += ["--user-model", str(plan["user_model"])]
    for name, value in parameters:
        words += ["--param", f"{str(name).removeprefix('spec.')}={_value(value)}"]
    for gateway, flows in (plan.get("branches") or {}).items():
        words += ["--branch", f"{gateway}=" + ",".join(f"{flow}:{_value(float(p))}"
                                                       for flow, p in flows.items())]
    if plan.get("export"):
        words += ["--export", ",".join(plan["export"]), "--case", str(plan.get("case"))]
    return shlex.join(words)
