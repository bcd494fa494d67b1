"""What ``opspec evaluate`` prints when the run is over: one JSON object (``--json``), or
the tables of the metrics, the monitors, a population's subgroups, the input uncertainty and
a sweep's values, then where the results and the report are."""
from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["Results", "print_results", "replication_counts"]


@dataclass(frozen=True, slots=True)
class Results:
    """What an evaluation found: the summaries the report was drawn from (by design, plus
    ``sweep`` for a sweep), the comparison of two designs, and the run itself."""

    summaries: dict[str, dict[str, Any]]
    compare: dict[str, Any] | None
    report: Path
    outcome: Any
    failures: list[tuple[str, int, str]]
    #: replications planned, complete and failed (:func:`replication_counts`)
    counts: dict[str, Any]
    #: what the store says of the run: ``user_model_sha256``, ``opspec_version``
    stored: dict[str, Any] | None = None


def replication_counts(store: Any, plan: Any, failures: list[tuple[str, int, str]]
                       ) -> dict[str, Any]:
    """Replications planned, complete (what every number is computed from) and failed."""
    complete = {d.label: len(store.finished(d.label)) for d in plan.designs}
    return {"planned": plan.users * len(plan.designs), "complete": sum(complete.values()),
            "complete_by_design": complete,
            "failed": sum(1 for d, _, _ in failures if d in complete),
            "metrics_from": "complete replications only"}


def print_results(args: argparse.Namespace, plan: Any, store: Any, workers: int,
                  results: Results) -> None:
    """Print ``results`` as ``--json`` asks: one JSON object, else the tables."""
    from opspec.evaluation.failures import kind_of

    summaries, compare = results.summaries, results.compare
    metrics, monitors = summaries["A"]["metrics"], summaries["A"]["monitors"]
    population = summaries["A"]["population"]
    uncertainty = summaries["A"]["input_uncertainty"]
    swept = "sweep" in summaries
    if args.json:
        doc = {"spec": plan.design("A").spec, "users": plan.users, "days": plan.days,
               "seed": plan.seed, "user_model": plan.user_model,
               # which files the numbers are of, and by which opspec (as the report says)
               "spec_sha256": plan.design("A").sha256,
               "user_model_sha256": (results.stored or {}).get("user_model_sha256"),
               "opspec_version": (results.stored or {}).get("opspec_version"),
               "workers": workers,
               "scheduler": args.scheduler,
               "out": str(store.folder), "report": str(results.report), "metrics": metrics,
               "monitors": monitors, "population": population,
               "input_uncertainty": uncertainty,
               "replications": results.counts,
               "failed": [{"design": d, "user": u, "error": e, "kind": kind_of(e)}
                          for d, u, e in results.failures],
               "wall_s": round(results.outcome.wall_s, 3)}
        if compare is not None:
            doc["compare"] = {"spec": compare["spec"],
                              "spec_sha256": plan.design("B").sha256,
                              **{k: v for k, v in compare.items() if k != "spec"}}
        if swept:
            doc["sweep"] = summaries["sweep"]
        from opspec.statistics.methods import describe, methods_in

        # what every "ci95_method" above means: its recipe and references
        doc["interval_methods"] = describe(methods_in(doc))
        print(json.dumps(_finite(doc), allow_nan=False, default=str))
    else:
        from opspec.evaluation.tables import print_summary

        print_summary(sys.stdout, plan, metrics, compare, results.outcome, results.failures,
                      workers, monitors=monitors, population=population)
        from opspec.evaluation.input_uncertainty import print_input_uncertainty

        print_input_uncertainty(sys.stdout, uncertainty, metrics,
                                (compare or {}).get("difference"))
        if swept:
            from opspec.evaluation.sweep import print_sweep

            print_sweep(sys.stdout, summaries["sweep"], plan.users)
        print(f"results: {store.path}\nreport: {results.report}")


def _finite(value: Any) -> Any:
    """``value`` with NaN and infinities as ``null`` (JSON has no spelling for them)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value
