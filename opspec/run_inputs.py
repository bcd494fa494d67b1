"""The values a run is given for a spec's run inputs: fixed, drawn from a distribution, or one
row of a data file per run.

A BPMN diagram's run inputs (variables its conditions read that nothing in it sets,
docs/bpmn.md, Run inputs) and an XPDL spec's package data fields take their value for one run
from ``--param NAME=VALUE``, ``--param NAME~DISTRIBUTION`` or ``--params FILE``
(:mod:`opspec.commands._params` reads them into a :class:`RunInputs`). Run ``r`` of a seed —
the lone run of ``opspec run`` is run 0, simulated user ``u`` of ``opspec evaluate`` is run
``u`` — gets :meth:`RunInputs.for_run` ``(seed, r)``: the fixed values, row ``r`` of the data
file, and each distribution's draw from the stream of ``(seed, r, "run-input/NAME")``. So
the same seed gives the same values to the same user whatever the number of workers, and a
new run input changes no other draw.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from opspec.distributions import make_distribution
from opspec.engine.random import named_stream
from opspec.errors import ConfigurationError
from opspec.model import Package

__all__ = ["RunInputs", "no_such_field"]


def no_such_field(name: str, package: Package, where: str) -> ConfigurationError:
    """The error for a value given to ``name``, which is not a package data field of
    ``package`` (what ``--param``, ``--params``, the API's ``params`` and a scenario's
    ``given.params`` may set: a run's value for anything else would be set nowhere anyone
    reads it): that it is a process's formal parameter when it is one, else the closest
    name."""
    owners = [p.id for p in package.processes
              if any(f.id == name for f in p.formal_parameters)]
    if owners:
        # validate's unpassed-parameter warning sends the user here: "no package data
        # field" would leave them guessing what to change
        return ConfigurationError(
            f"{where}: {name!r} is a formal parameter of process {owners[0]!r}, not a "
            "package data field: run inputs set package data fields only (a formal "
            "parameter gets its value from the SubFlow or call activity that calls its "
            "process)",
            hint=f"to give {name!r} a value per run, declare it as a package data field "
            "instead of a formal parameter (as validate's unpassed-parameter warning says); "
            "opspec validate lists the run inputs")
    fields = [f.id for f in package.data_fields]
    inputs = [f.id for f in package.data_fields
              if any(e.name == "opspec:RunInput" for e in f.extended_attributes)]
    close = difflib.get_close_matches(name, fields, n=1)
    known = (f"its run inputs: {', '.join(inputs)}" if inputs else
             f"its package data fields: {', '.join(fields)}" if fields else
             "it has no package data fields")
    return ConfigurationError(
        f"{where}: the spec has no package data field {name!r}"
        + (f" (did you mean {close[0]!r}?)" if close else ""),
        hint=f"{known}; opspec validate lists the run inputs")


@dataclass(frozen=True, slots=True)
class RunInputs:
    """Values for run inputs (plain data: it travels in an evaluation's plan as JSON)."""

    #: name, value: the same in every run
    values: tuple[tuple[str, Any], ...] = ()
    #: name, distribution table (opspec's TOML form, :func:`make_distribution`), and whether
    #: the field is an integer (a draw is then rounded to the nearest one)
    draws: tuple[tuple[str, Mapping[str, Any], bool], ...] = ()
    #: one mapping of values per run, in order (a data file's rows)
    rows: tuple[Mapping[str, Any], ...] = ()
    #: the data file the rows come from (for messages)
    source: str = ""

    def __bool__(self) -> bool:
        return bool(self.values or self.draws or self.rows)

    def for_run(self, seed: int, run: int) -> dict[str, Any]:
        """The values of run ``run`` of a run seeded ``seed``."""
        out = dict(self.values)
        if self.rows:
            out.update(self.rows[run % len(self.rows)])
        for name, table, integer in self.draws:
            value = make_distribution(table).sample(named_stream(seed, f"run-input/{name}",
                                                                 (run,)))
            out[name] = int(round(value)) if integer else float(value)
        return out

    def describe(self) -> str:
        """One line for a run's header: ``score ~ uniform(low=0, high=100); age = 70``."""
        parts = [f"{name} = {value!r}" for name, value in self.values]
        for name, table, integer in self.draws:
            args = ", ".join(f"{k}={_number(v)}" for k, v in table.items() if k != "kind")
            parts.append(f"{name} ~ {table['kind']}({args})" + (" rounded" if integer else ""))
        if self.rows:
            names = ", ".join(dict.fromkeys(n for row in self.rows for n in row))
            parts.append(f"{names} from {self.source or 'a data file'} "
                         f"({len(self.rows)} row{'s' if len(self.rows) != 1 else ''}, "
                         "one per run)")
        return "; ".join(parts)

    def to_json(self) -> dict[str, Any]:
        return {"values": [list(v) for v in self.values],
                "draws": [[n, dict(t), i] for n, t, i in self.draws],
                "rows": [dict(r) for r in self.rows], "source": self.source}

    @classmethod
    def from_json(cls, doc: Mapping[str, Any] | None) -> RunInputs:
        if not doc:
            return cls()
        return cls(values=tuple((str(n), v) for n, v in doc.get("values") or ()),
                   draws=tuple((str(n), dict(t), bool(i)) for n, t, i in doc.get("draws") or ()),
                   rows=tuple(dict(r) for r in doc.get("rows") or ()),
                   source=str(doc.get("source") or ""))

    def names(self) -> Sequence[str]:
        """Every run input given a value."""
        found = [n for n, _ in self.values] + [n for n, _t, _i in self.draws]
        found += [n for row in self.rows for n in row]
        return tuple(dict.fromkeys(found))


def _number(value: Any) -> str:
    if isinstance(value, float) and math.isinf(value):
        return "-inf" if value < 0 else "inf"
    return f"{value:g}" if isinstance(value, float) else str(value)
