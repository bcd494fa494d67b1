"""The users' values the summaries and the report's per-user figure read (and their counts
of each activity): held in arrays for a few users (a pass over values on disk reads a batch of that many rows at once, so
writing them to disk saves nothing there), on disk beyond, and read once per state of the
store either way; the numbers are the same wherever they are kept."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.evaluation import summary, values_per_user
from opspec.evaluation.replication import ReplicationRecord
from opspec.evaluation.spilled import BATCH, SpilledUsers
from opspec.evaluation.store import ResultStore

DEFINITIONS = [{"name": "due", "kind": "count"},
               {"name": "latency", "kind": "duration", "unit": "s"}]


def _store(folder: Path, users: int) -> ResultStore:
    store = ResultStore(folder, create=True)
    store.put("metrics", DEFINITIONS)
    store.add_many([ReplicationRecord("A", u, "done", metrics={
        "due": {"kind": "count", "total": 4 + u % 3},
        "latency": {"kind": "duration", "n": u % 2, "mean": 60.0 + u if u % 2 else None}},
        samples=[("latency", 60.0 + u, 3600.0)] if u % 2 else [],
        activities={"hear_alarm": [4 + u % 3, 3, 1 + u % 2, u % 3],
                    "take_pill": [4, 4 - u % 2, u % 2, 0]}) for u in range(users)])
    return store


def test_the_threshold_is_the_spills_batch() -> None:
    assert values_per_user.HELD_USERS == BATCH


@pytest.mark.parametrize(("users", "spilled"), [(6, False), (7, True)])
def test_few_users_are_held_more_are_spilled_with_the_same_numbers(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, users: int, spilled: bool) -> None:
    monkeypatch.setattr(values_per_user, "HELD_USERS", 6)
    store = _store(tmp_path / "run", users)
    values = summary.per_user_values(store, "A", DEFINITIONS)
    assert isinstance(values, SpilledUsers) is spilled
    # read again (the report's per-user figure): the same values, not read a second time
    assert summary.per_user_values(store, "A", DEFINITIONS) is values
    here = (summary.summarise_design(store, "A", 3.0),
            summary.summarise_activities(store, "A"))
    monkeypatch.setattr(values_per_user, "HELD_USERS", 0 if not spilled else 10**9)
    store.add(ReplicationRecord("B", 0, "done", metrics={}))     # a new state of the store
    there = (summary.summarise_design(store, "A", 3.0),
             summary.summarise_activities(store, "A"))
    assert [a["activity"] for a in here[1]] == ["hear_alarm", "take_pill"]
    assert json.dumps(here, sort_keys=True) == json.dumps(there, sort_keys=True)
    store.close()
