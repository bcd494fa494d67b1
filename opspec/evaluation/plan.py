"""What an evaluation run is: designs (specs), users, days, seed, user model, engine options.

The plan is stored with the results (``run`` table of the store) so that ``--resume`` finishes
exactly the run that was started, and is sent to workers as plain JSON.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from opspec.errors import EvaluationError

__all__ = ["DAY", "Design", "EvaluationPlan", "file_digest", "span"]

DAY = 86_400.0


def span(days: float) -> str:
    """A run length for people: ``30 days``, ``1 day``, ``1.5 days``, ``12 h``, ``75 min``;
    a length that is no number of days with at most two decimals is written as
    :func:`opspec.clock.span` writes it, in parts to the millisecond when no one unit
    writes it exactly (``2 h 57 min 46.598 s`` for 0.123456 days, never a rounded
    ``2.963 h``; ``29 h 37 min 46.666 s`` for 1.23456789 days, not ``1.23457 days``)."""
    from opspec.clock import span as clock_span

    if days >= 1 and round(days, 2) == days:
        return f"{days:g} day{'s' if days != 1 else ''}"
    return clock_span(days * DAY)


def file_digest(path: str | Path) -> str:
    """SHA-256 of a file's bytes (the spec a stored run was made with)."""
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError as error:
        raise EvaluationError(f"cannot read {path}: {error.strerror or error}") from None


@dataclass(frozen=True, slots=True)
class Design:
    """One device design under evaluation: ``A`` is the spec, ``B`` the ``--compare`` spec."""

    label: str
    spec: str
    sha256: str
    #: parameter values this design runs with (``--sweep``: ``spec.…`` / ``user.…`` name,
    #: value; opspec.evaluation.parameters applies them to the spec and the user model)
    parameters: tuple[tuple[str, Any], ...] = ()


@dataclass(frozen=True, slots=True)
class EvaluationPlan:
    """Everything that determines an evaluation's results (and nothing that doesn't, such as
    the number of workers: results are the same whatever it is)."""

    designs: tuple[Design, ...]
    users: int
    days: float
    seed: int
    user_model: str | None = None
    engine: Mapping[str, Any] = field(default_factory=dict)
    export: tuple[str, ...] = ()
    #: what one case of the XES and JSON Lines exports is (opspec.evaluation.cases)
    case: str = "chain"
    #: ``--input-uncertainty B``: parameter draws of the fitted user model to run, each on
    #: ``users_per_draw`` users of its own (opspec.evaluation.input_uncertainty); 0: none
    input_uncertainty: int = 0
    users_per_draw: int = 0
    #: run inputs drawn per simulated user or read from a data file's rows
    #: (:class:`opspec.run_inputs.RunInputs` as JSON; fixed values are design parameters)
    run_inputs: Mapping[str, Any] = field(default_factory=dict)
    #: ``--branch``: branch probabilities of undecided gateways, gateway -> flow -> P
    #: (:mod:`opspec.branch_choices`), applied to every design before it is compiled
    branches: Mapping[str, Mapping[str, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if isinstance(self.users, bool) or not isinstance(self.users, int) or self.users < 1:
            raise EvaluationError(f"--users must be a whole number >= 1, not {self.users!r}")
        from opspec.errors import ConfigurationError
        from opspec.run_rules import check_days

        try:                                # a stored plan too: the one rule of days
            check_days(self.days, name="--days")
        except ConfigurationError as error:
            raise EvaluationError(error.message) from None

    @property
    def horizon(self) -> float:
        from opspec.run_rules import seconds_of_days

        return seconds_of_days(float(self.days))

    def design(self, label: str) -> Design:
        for design in self.designs:
            if design.label == label:
                return design
        raise EvaluationError(f"no design {label!r} in this run")

    def to_json(self) -> dict[str, Any]:
        doc = asdict(self)
        # a design's parameters only when it has some: plans of runs without them read as
        # they always did
        doc["designs"] = [{k: v for k, v in asdict(d).items() if k != "parameters"
                           or d.parameters} for d in self.designs]
        doc["engine"] = dict(self.engine)
        doc["export"] = list(self.export)
        if not self.input_uncertainty:      # plans without draws read as they always did
            del doc["input_uncertainty"], doc["users_per_draw"]
        if not self.run_inputs:             # plans without them read as they always did
            del doc["run_inputs"]
        else:
            doc["run_inputs"] = dict(self.run_inputs)
        if not self.branches:               # plans without them read as they always did
            del doc["branches"]
        else:
            doc["branches"] = {g: dict(f) for g, f in self.branches.items()}
        return doc

    @classmethod
    def from_json(cls, doc: Mapping[str, Any]) -> EvaluationPlan:
        designs = tuple(Design(d["label"], d["spec"], d["sha256"],
                               tuple((str(n), v) for n, v in d.get("parameters") or ()))
                        for d in doc["designs"])
        return cls(designs=designs, users=int(doc["users"]),
                   days=float(doc["days"]), seed=int(doc["seed"]),
                   user_model=doc.get("user_model"), engine=dict(doc.get("engine") or {}),
                   export=tuple(doc.get("export") or ()), case=str(doc.get("case") or "user"),
                   input_uncertainty=int(doc.get("input_uncertainty") or 0),
                   users_per_draw=int(doc.get("users_per_draw") or 0),
                   run_inputs=dict(doc.get("run_inputs") or {}),
                   branches={str(g): {str(k): float(v) for k, v in f.items()}
                             for g, f in (doc.get("branches") or {}).items()})

    def same_results_as(self, other: EvaluationPlan) -> list[str]:
        """What differs between two plans in ways that change results (for ``--resume``)."""
        mine, theirs = self.to_json(), other.to_json()
        return [key for key in ("designs", "users", "days", "seed", "user_model", "engine",
                                "input_uncertainty", "users_per_draw", "run_inputs",
                                "branches")
                if json.dumps(mine.get(key), sort_keys=True) != json.dumps(theirs.get(key),
                                                                            sort_keys=True)]
