"""The default XES case notion is one a process-mining tool discovers a model from, with the
cases named after the spec's own workflows — for the medication dispenser and for a device
of another shape (the stove guard `opspec new --template stove` writes).

The process-mining reading checked (van der Aalst, Process Mining, 2nd ed., 2016, §2.2 and
§6.4): "a case [...] is the process instance being handled; each event refers to one case",
and a discovery algorithm learns a model from many cases that repeat the process. pm4py's
inductive miner (Leemans et al., 2013) discovers a Petri net from one seed's export, and that
net must replay another seed's export (token-based replay fitness, the share of its behaviour
the model allows): a model of the device's process, not of one user's whole history.
Skipped without pm4py (``pip install opspec[xes]``).
"""

from __future__ import annotations

import json
import re
import warnings
from collections import Counter
from pathlib import Path
from typing import Any

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"

pytestmark = [pytest.mark.filterwarnings("ignore::UserWarning"),
              pytest.mark.filterwarnings("ignore::DeprecationWarning"),
              pytest.mark.filterwarnings("ignore::FutureWarning")]


def export(spec: Path, out: Path, seed: int, users: int, days: int) -> tuple[Any, dict]:
    """Evaluate with ``--export xes`` (the default case notion) and read the log back."""
    import contextlib
    import io

    pm4py = pytest.importorskip("pm4py", reason="pip install opspec[xes] to run this test")
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(io.StringIO()):
        assert main(["evaluate", str(spec), "--users", str(users), "--days", str(days),
                     "--seed", str(seed), "--workers", "1", "--out", str(out),
                     "--export", "xes", "--json"]) == 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        log = pm4py.read_xes(str(out / "traces.xes"))
    return log, json.loads(stdout.getvalue())


def completed(log: Any) -> Any:
    return log[log["lifecycle:transition"] == "complete"]


def discovered_model_replays_another_seed(first: Any, second: Any) -> float:
    import pm4py

    net, initial, final = pm4py.discover_petri_net_inductive(completed(first))
    return float(pm4py.fitness_token_based_replay(completed(second), net, initial,
                                                  final)["log_fitness"])


def roots(log: Any) -> Counter[str]:
    """The workflow each case is named after (``A/3/timer_workflow#14`` → timer_workflow)."""
    names = log["case:concept:name"].unique()
    assert all(re.fullmatch(r"A/\d+/\w+#\d+", n) for n in names), names[:5]
    return Counter(n.split("/")[2].split("#")[0] for n in names)


def test_dispenser_cases_are_its_doses_and_a_model_is_discovered(tmp_path: Path) -> None:
    first, doc = export(DISPENSER, tmp_path / "a", seed=1, users=2, days=2)
    second, _ = export(DISPENSER, tmp_path / "b", seed=2, users=2, days=2)
    # a case per dose: named after the workflow whose timer starts a dose, as many as the
    # spec's own doses_due metric counted
    assert roots(first) == {"timer_workflow": doc["metrics"]["doses_due"]["total"]}
    # many cases repeat a few ways a dose goes (alarm heard at once, after 2 or 3 alarms,
    # missed): the material a discovery algorithm needs, not one long trace per user
    variants = completed(first).groupby("case:concept:name")["concept:name"].agg(tuple)
    assert variants.nunique() <= len(variants) / 2
    assert discovered_model_replays_another_seed(first, second) >= 0.95


def test_stove_guard_cases_are_its_sessions_and_a_model_is_discovered(tmp_path: Path) -> None:
    assert main(["new", str(tmp_path / "stove"), "--template", "stove"]) == 0
    spec = tmp_path / "stove" / "stove.xpdl"
    first, _ = export(spec, tmp_path / "a", seed=1, users=4, days=2)
    second, _ = export(spec, tmp_path / "b", seed=2, users=4, days=2)
    # named after the stove guard's own workflow, one case per cooking session, not "dose"
    found = roots(first)
    assert set(found) == {"guard_workflow"} and found["guard_workflow"] == 4 * 2
    names = set(completed(first)["concept:name"])
    assert any(n.startswith("guard_workflow/") for n in names)
    assert any(n.startswith("user_workflow/") for n in names)   # the user's part is in it
    assert discovered_model_replays_another_seed(first, second) >= 0.95
