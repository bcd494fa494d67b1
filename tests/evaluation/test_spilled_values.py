"""The summaries read each user's values from temporary tables of the store at each pass
(opspec/evaluation/spilled.py), so that the evaluate process's memory does not grow with
the number of users: the numbers must be exactly those of the same values held in arrays,
and the per-user figure drawn from its few numbers per metric the same bytes as from every
user's value."""

from __future__ import annotations

import json
import math
import random
from pathlib import Path

import pytest

from opspec.evaluation import summary, values_per_user
from opspec.evaluation.replication import ReplicationRecord
from opspec.evaluation.runner import chunks, iter_chunks
from opspec.evaluation.spilled import spill_user_values
from opspec.evaluation.store import ResultStore

DEFINITIONS = [
    {"name": "due", "kind": "count"},
    {"name": "missed", "kind": "count"},
    {"name": "latency", "kind": "duration", "unit": "s"},
    {"name": "missed_rate", "kind": "ratio", "numerator": "missed", "denominator": "due"},
]


def _store(folder: Path, users: int, seed: int) -> ResultStore:
    """A store of ``users`` made-up users (some without any latency observation)."""
    rng = random.Random(seed)
    store = ResultStore(folder, create=True)
    store.put("metrics", DEFINITIONS)
    records = []
    for user in range(users):
        due = rng.randint(0, 30)
        missed = rng.randint(0, due)
        n = rng.randint(0, 5)
        mean = rng.lognormvariate(4.0, 0.5) if n else None
        records.append(ReplicationRecord("A", user, "done", metrics={
            "due": {"kind": "count", "total": due},
            "missed": {"kind": "count", "total": missed},
            "latency": {"kind": "duration", "n": n, "mean": mean},
            "missed_rate": {"kind": "ratio", "value": missed / due if due else None}},
            samples=[("latency", mean, 60.0 * k) for k in range(n)] if mean else [],
            activities={"hear": [due, due - missed, missed, user % 3]}))
    store.add_many(records)
    return store


@pytest.mark.parametrize(("users", "seed"), [(1, 1), (2, 2), (57, 3), (600, 4)])
def test_summaries_from_disk_are_exactly_those_of_the_arrays(tmp_path, monkeypatch, users,
                                                             seed):
    store = _store(tmp_path / "run", users, seed)
    monkeypatch.setattr(values_per_user, "HELD_USERS", 0)   # spilled however few the users
    from_disk = summary.summarise_design(store, "A", 7.0)
    activities = summary.summarise_activities(store, "A")
    # the same summaries with the values held in arrays (what a NaN falls back to)
    monkeypatch.setattr("opspec.evaluation.spilled.spill_user_values",
                        lambda *args, **kwargs: None)
    held = summary.summarise_design(store, "A", 7.0)
    assert json.dumps(from_disk, sort_keys=True) == json.dumps(held, sort_keys=True)
    assert from_disk["missed_rate"]["per_user"]["users"] >= 1 or users < 3
    if activities:
        assert activities[0]["offered"] == sum(
            r[0] for r in store.query("SELECT offered FROM activity"))
    store.close()


def test_a_spill_is_read_again_until_the_store_is_written(tmp_path):
    store = _store(tmp_path / "run", 20, 5)
    first = spill_user_values(store, "A", DEFINITIONS)
    assert first is not None and first.users == 20
    assert spill_user_values(store, "A", DEFINITIONS) is first
    assert list(first.pairs("due")) == [
        (float(json.loads(m)["due"]["total"]), 1.0)
        for (m,) in store.query("SELECT metrics FROM replication ORDER BY user")]
    ordered = first.sorted("latency", "v")
    assert list(ordered) == sorted(ordered) and ordered[len(ordered) - 1] == max(ordered)
    store.add(ReplicationRecord("A", 20, "done", metrics={
        "due": {"kind": "count", "total": 3}}))
    again = spill_user_values(store, "A", DEFINITIONS)
    assert again is not first and again is not None and again.users == 21
    store.close()


def test_a_nan_is_left_to_the_arrays(tmp_path):
    store = ResultStore(tmp_path / "run", create=True)
    store.put("metrics", [{"name": "x", "kind": "duration"}])
    store.add_many([ReplicationRecord("A", u, "done", metrics={
        "x": {"kind": "duration", "n": 1, "mean": float("nan") if u == 1 else 2.0}},
        samples=[("x", 2.0, 1.0)]) for u in range(3)])
    definitions = [{"name": "x", "kind": "duration"}]
    assert spill_user_values(store, "A", definitions) is None     # SQLite stores NaN as NULL
    held = summary.per_user_values(store, "A", definitions).pairs("x")
    assert [y for y, _ in held][0] == 2.0 and math.isnan([y for y, _ in held][1])
    store.close()


def test_chunks_made_lazily_are_those_of_the_list():
    for users, workers in ((0, 1), (7, 1), (1000, 1), (1000, 2), (333, 3)):
        assert list(iter_chunks(range(users), workers)) == chunks(list(range(users)), workers)


def _svg(draw) -> bytes:
    import io

    import matplotlib
    from matplotlib.backends.backend_svg import FigureCanvasSVG
    from matplotlib.figure import Figure

    with matplotlib.rc_context({"svg.hashsalt": "test", "svg.fonttype": "none"}):
        fig = Figure(figsize=(4, 3))
        FigureCanvasSVG(fig)
        draw(fig.add_subplot())
        out = io.BytesIO()
        fig.savefig(out, format="svg", metadata={"Date": None})
    return out.getvalue()


def test_the_per_user_histogram_from_its_numbers_is_the_histogram_of_every_value():
    """The figure draws numpy's "auto" bins of every user's value from the bins and their
    counts (plots.user_distribution): matplotlib must draw the same picture as from the
    values themselves, and a few distinct values stay a bar each."""
    import numpy as np

    from opspec.evaluation import plots

    rng = random.Random(7)
    many = [rng.lognormvariate(4.0, 0.4) for _ in range(3000)]
    shown = plots.user_distribution(many)
    assert shown is not None and shown.kind == "hist" and shown.users == 3000
    edges = list(shown.xs)
    style = {"histtype": "stepfilled", "color": "#56B4E9", "edgecolor": "#0072B2"}
    every = _svg(lambda ax: ax.hist(np.asarray(many), bins="auto", **style))
    compact = _svg(lambda ax: ax.hist(edges[:-1], bins=edges, weights=list(shown.counts),
                                      **style))
    assert every == compact
    few = plots.user_distribution([0.0, 1 / 120, 0.0, float("nan"), 2 / 120], 100.0)
    assert few is not None and few.kind == "bars" and few.counts == (2, 1, 1)
    assert few.users == 4 and few.high == pytest.approx(100.0 * 2 / 120)
