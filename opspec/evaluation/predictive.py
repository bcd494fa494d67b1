"""A spec's outcome metrics for held-out people, against what the user model predicts.

The people's traces are replayed into the spec's metrics (``opspec:Metrics``, the same
listener a run uses), one value per person (the mean over their sessions): a count's total,
a duration's mean, a ratio's value. The model's prediction is the same spec run with the
model for ``runs`` simulated people (user ``u`` of the seed; under parameter redraw
``1 + u mod B`` when the model carries ``[uncertainty]``), on the same run length. What a
*group* of n people would show is the mean of n of them drawn at random: its 95 % predictive
interval, and a two-sided p-value ``min(1, 2 · min(P(mean ≤ observed), P(mean ≥
observed)))`` from 4,000 such groups (+1 correction), are compared with the observed mean of
the n people. Metrics the model predicts as one value for everyone (doses due) say nothing
and are left out, unless the people's differ from it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from opspec.usermodels.checking import CheckItem

__all__ = ["metric_items", "observed_metrics", "predicted_metrics", "write_person_traces"]

_GROUPS = 4000


def _scalar(value: Mapping[str, Any]) -> float | None:
    kind = value.get("kind")
    result = (value.get("total") if kind == "count" else value.get("mean") if
              kind == "duration" else value.get("value"))
    return None if result is None else float(result)


def observed_metrics(paths: Sequence[Path], definitions: Sequence[Any],
                     person_of: Mapping[tuple[int, int], str]
                     ) -> dict[str, dict[str, float]]:
    """Per metric, per person: the mean over that person's sessions of the metric's value
    replayed from the traces (sessions keyed as :func:`opspec.usermodels.fitting.collect`
    keys them: ``(file index, run index)``)."""
    from opspec.engine.metrics import MetricsListener
    from opspec.engine.trace import EventKind
    from opspec.usermodels.fitting import read_trace

    per: dict[str, dict[str, list[float]]] = {}

    def close(listener: MetricsListener | None, session: tuple[int, int]) -> None:
        if listener is None:
            return
        person = person_of.get(session, f"{session[0]}#{session[1]}")
        for name, value in listener.values().items():
            number = _scalar(value)
            if number is not None and math.isfinite(number):
                per.setdefault(name, {}).setdefault(person, []).append(number)

    for file_index, path in enumerate(paths):
        run = 0
        listener: MetricsListener | None = MetricsListener(definitions)
        seen = False
        for event in read_trace(path):
            if event.kind == EventKind.RUN_STARTED:
                if seen:
                    close(listener, (file_index, run))
                run += 1
                listener = MetricsListener(definitions)
                seen = True
            if listener is not None:
                listener(event)
        close(listener, (file_index, run))
    return {name: {p: float(np.mean(v)) for p, v in people.items()}
            for name, people in per.items()}


def predicted_metrics(spec: Any, model: Any, *, runs: int, seed: int, days: float | None,
                      draws: Any = None) -> dict[str, np.ndarray]:
    """Per metric: its value for each of ``runs`` simulated people of ``model``."""
    from opspec.runs import User, build, load

    loaded = load(spec)
    values: dict[str, list[float]] = {}
    for u in range(runs):
        person_model = model if draws is None else draws.apply(model, 1 + u % draws.count)
        outcome = build(loaded, seed=seed, user=User.model(person_model), user_index=u,
                        days=days).execute()
        for name, value in outcome.metrics.items():
            number = _scalar(value)
            if number is not None and math.isfinite(number):
                values.setdefault(name, []).append(number)
    return {name: np.asarray(v, float) for name, v in values.items()}


def metric_items(observed: Mapping[str, Mapping[str, float]],
                 predicted: Mapping[str, np.ndarray], *, seed: int,
                 units: Mapping[str, str] | None = None
                 ) -> tuple[list[CheckItem], list[str]]:
    """One item per metric with observed and predicted values; notes for those left out."""
    notes: list[str] = []
    items: list[CheckItem] = []
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(7,)))
    for name in sorted(set(observed) & set(predicted)):
        people = observed[name]
        sim = predicted[name]
        if not people or sim.size < 2:
            continue
        values = np.asarray(list(people.values()), float)
        n = values.size
        mean = float(values.mean())
        if float(np.ptp(sim)) == 0.0:
            constant = float(sim[0])
            if np.all(np.abs(values - constant) <= 1e-9 * max(1.0, abs(constant))):
                notes.append(f"metric {name}: the model predicts {constant:g} for everyone, "
                             "as observed (not an item)")
                continue
        groups = sim[rng.integers(0, sim.size, size=(_GROUPS, n))].mean(axis=1)
        below = int(np.sum(groups <= mean + 1e-12))
        above = int(np.sum(groups >= mean - 1e-12))
        p = min(1.0, 2 * (1 + min(below, above)) / (_GROUPS + 1))
        low, high = np.percentile(groups, [2.5, 97.5])
        person_low, person_high = np.percentile(sim, [2.5, 97.5])
        items.append(CheckItem(
            f"metric {name}", "metric", None,
            f"predictive interval of the mean of {n} ({sim.size} simulated people)",
            mean, p, n, n,
            {"value": mean, "min": float(values.min()), "max": float(values.max())},
            {"value": float(sim.mean()), "low": float(low), "high": float(high),
             "person_low": float(person_low), "person_high": float(person_high)},
            (units or {}).get(name, ""),
            {"people": values.tolist(), "groups_low": float(low),
             "groups_high": float(high), "person_low": float(person_low),
             "person_high": float(person_high), "predicted_mean": float(sim.mean())}))
    return items, notes


def write_person_traces(spec: Any, model: Any, directory: str | Path, *, people: Sequence[int],
                        seed: int, days: float | None = None, prefix: str = "P") -> list[Path]:
    """Simulated people as trace files: user ``u`` of ``model`` for each ``u`` of ``people``,
    one ``PREFIXu.jsonl`` each with ``person = "PREFIXu"`` in its header (what ``opspec fit``
    and ``opspec model-check`` group by) — synthetic participants with a known truth."""
    from opspec.engine.trace_sinks import JsonlSink
    from opspec.runs import User, build, load

    loaded = load(spec)
    user = User.model(model)
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for u in people:
        path = out / f"{prefix}{u:03d}.jsonl"
        with JsonlSink(path, {"spec": str(spec), "seed": seed,
                              "person": f"{prefix}{u:03d}"}) as sink:
            build(loaded, seed=seed, user=user, user_index=u, days=days,
                  listeners=[sink]).execute()
        written.append(path)
    return written
