"""A fitted model's parameter uncertainty: redraws of its parameters, kept in the model file.

``opspec fit`` writes, next to the point estimates, ``B`` bootstrap redraws of every fitted
parameter (:mod:`opspec.usermodels.bootstrap` says how they are made) as the
``[uncertainty]`` table of the model file::

    [uncertainty]
    method = "bootstrap"
    resampled = "persons"
    draws = 200
    persons = 40
    sessions = 80
    seed = 0
    source = "..."

    [uncertainty.parameters."activities.walk.duration.median"]
    estimate = 61.9
    draws = [58.2, 66.0, ...]

Each parameter is named by the dotted path of :func:`opspec.usermodels.population.set_parameter`
(the same names ``[vary]`` uses). Draw ``b`` (1-based) of the file is the model with every
listed parameter set to the ``b``-th value of its ``draws``: the values of one draw come from
one bootstrap resample, so their correlations (a median and a sigma estimated from the same
data) are kept. ``opspec evaluate --input-uncertainty B`` runs draws 1..B
(:mod:`opspec.evaluation.input_uncertainty`).

A parameter that the file also draws per person (``[vary]``) is the centre of that per-person
distribution (a lognormal's median, a beta's or normal's mean): the draw moves the centre and
keeps the between-person spread.
"""

from __future__ import annotations

import json
import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from opspec.errors import UserModelError
from opspec.toml_lines import located
from opspec.usermodels.distributions import ParameterError

__all__ = ["TABLE", "ParameterDraws", "drawn_model", "parse_path", "read_parameter_draws"]

TABLE = "uncertainty"
_KEYS = ("method", "resampled", "draws", "persons", "sessions", "seed", "source",
         "parameters")


def parse_path(text: str) -> tuple[str, ...]:
    """A dotted parameter name as written (parts may be quoted, as TOML keys) -> its parts."""
    tree: Any = tomllib.loads(f"{text} = 0")
    parts: list[str] = []
    while isinstance(tree, Mapping):
        (name, tree), = tree.items()
        parts.append(name)
    return tuple(parts)


@dataclass(frozen=True)
class ParameterDraws:
    """``draws[b][i]``: the value of ``parameters[i]`` in draw ``b + 1``."""

    parameters: tuple[str, ...]
    estimates: tuple[float, ...]
    draws: tuple[tuple[float, ...], ...]
    method: str = "bootstrap"
    resampled: str = "persons"
    persons: int = 0
    sessions: int = 0
    seed: int = 0
    source: str = ""
    path: str = "<python>"
    paths: tuple[tuple[str, ...], ...] = field(default=(), repr=False)

    def __post_init__(self) -> None:
        if not self.paths:
            object.__setattr__(self, "paths", tuple(parse_path(p) for p in self.parameters))

    @property
    def count(self) -> int:
        return len(self.draws)

    def values(self, draw: int) -> dict[str, float]:
        """Draw ``draw`` (1-based): parameter -> value."""
        if not 1 <= draw <= self.count:
            raise UserModelError(f"no parameter draw {draw}: the file holds {self.count}",
                                 location=located(self.path, TABLE))
        return dict(zip(self.parameters, self.draws[draw - 1], strict=True))

    def to_toml(self) -> dict[str, Any]:
        """The ``[uncertainty]`` table."""
        return {"method": self.method, "resampled": self.resampled, "draws": self.count,
                "persons": self.persons, "sessions": self.sessions, "seed": self.seed,
                "source": self.source,
                "parameters": {name: {"estimate": self.estimates[i],
                                      "draws": [float(f"{row[i]:.10g}") for row in self.draws]}
                               for i, name in enumerate(self.parameters)}}

    def to_text(self, per_line: int = 6) -> str:
        """The ``[uncertainty]`` table as TOML text, each parameter's draws a few to a line
        (tomli_w would write one number a line)."""
        import tomli_w

        head = {k: v for k, v in self.to_toml().items() if k != "parameters"}
        parts = [tomli_w.dumps({TABLE: head})]
        for i, name in enumerate(self.parameters):
            values = [f"{row[i]:.10g}" for row in self.draws]
            values = [v if any(c in v for c in ".en") else v + ".0" for v in values]
            lines = [", ".join(values[j:j + per_line]) for j in range(0, len(values),
                                                                        per_line)]
            key = json.dumps(name)          # a TOML basic string is a JSON string
            parts.append(f"[{TABLE}.parameters.{key}]\nestimate = {self.estimates[i]!r}\n"
                         "draws = [\n    " + ",\n    ".join(lines) + ",\n]\n")
        return "\n".join(parts)

    def summary(self) -> dict[str, dict[str, float]]:
        """Per parameter: the estimate, the draws' sd and their 2.5 % and 97.5 % points."""
        import numpy as np

        out = {}
        for i, name in enumerate(self.parameters):
            column = np.array([row[i] for row in self.draws])
            out[name] = {"estimate": self.estimates[i], "sd": float(column.std(ddof=1))
                         if column.size > 1 else 0.0,
                         "p2.5": float(np.percentile(column, 2.5)),
                         "p97.5": float(np.percentile(column, 97.5))}
        return out

    @classmethod
    def from_table(cls, table: Any, path: str) -> ParameterDraws:
        """The ``[uncertainty]`` table of the file ``path``, checked (errors name the key)."""
        def bad(key: str, message: str, hint: str = "") -> UserModelError:
            return UserModelError(message, location=located(path, key),
                                  hint=hint or "write it again with `opspec fit`")

        if not isinstance(table, Mapping):
            raise bad(TABLE, "must be a table")
        for key in table:
            if key not in _KEYS:
                raise bad(f"{TABLE}.{key}", "unknown key", "expected one of: "
                          + ", ".join(_KEYS))
        params = table.get("parameters")
        if not isinstance(params, Mapping) or not params:
            raise bad(f"{TABLE}.parameters", "must hold one table per redrawn parameter")
        names, estimates, columns = [], [], []
        size = None
        for name, entry in params.items():
            key = f"{TABLE}.parameters.{name}"
            if not isinstance(entry, Mapping) or "draws" not in entry:
                raise bad(key, "must be a table with estimate and draws")
            values = entry["draws"]
            if not isinstance(values, list) or not values or not all(
                    isinstance(v, (int, float)) and not isinstance(v, bool)
                    and math.isfinite(v) for v in values):
                raise bad(f"{key}.draws", "must be a list of finite numbers")
            if size is not None and len(values) != size:
                raise bad(f"{key}.draws", f"has {len(values)} values, the parameters before "
                          f"it {size}", "every parameter has one value per draw")
            size = len(values)
            estimate = entry.get("estimate", values[0])
            if isinstance(estimate, bool) or not isinstance(estimate, (int, float)):
                raise bad(f"{key}.estimate", f"must be a number, got {estimate!r}")
            try:
                parse_path(name)
            except tomllib.TOMLDecodeError:
                raise bad(key, f"{name!r} is not a dotted parameter name") from None
            names.append(str(name))
            estimates.append(float(estimate))
            columns.append([float(v) for v in values])
        assert size is not None
        declared = table.get("draws", size)
        if declared != size:
            raise bad(f"{TABLE}.draws", f"says {declared} draws, the parameters hold {size}")
        rows = tuple(tuple(col[b] for col in columns) for b in range(size))

        def whole(key: str) -> int:
            value = table.get(key, 0)
            if isinstance(value, bool) or not isinstance(value, int):
                raise bad(f"{TABLE}.{key}", f"must be a whole number, got {value!r}")
            return value

        return cls(tuple(names), tuple(estimates), rows,
                   method=str(table.get("method", "bootstrap")),
                   resampled=str(table.get("resampled", "")), persons=whole("persons"),
                   sessions=whole("sessions"), seed=whole("seed"),
                   source=str(table.get("source", "")), path=path)

    # ------------------------------------------------------------------- a drawn model

    def apply(self, model: Any, draw: int) -> Any:
        """``model`` (the file's own model, as loaded) with draw ``draw``'s values."""
        values = self.values(draw)
        try:
            return _apply(model, [(p, values[n]) for p, n in zip(self.paths, self.parameters,
                                                                   strict=True)])
        except ParameterError as error:
            raise UserModelError(f"parameter draw {draw}: {error.param} {error.detail}",
                                 location=located(self.path,
                                                         f"{TABLE}.parameters"),
                                 hint=error.hint or "fit the model again") from None


def _recentred(dist: Any, value: float) -> Any:
    """A per-person distribution with its centre moved to ``value`` (its spread kept)."""
    from opspec.usermodels.population_distributions import make_per_user

    params = dict(dist.params)
    for centre in ("median", "mean", "mu"):
        if centre in params:
            if dist.kind == "beta":
                value = min(max(value, 1e-9), 1 - 1e-9)
                most = math.sqrt(value * (1 - value))
                if params.get("sd", 0) >= most:        # keep the beta valid near 0 and 1
                    params["sd"] = 0.999 * most
            params[centre] = value
            return make_per_user({"kind": dist.kind, **params})
    raise ParameterError("kind", f"a {dist.kind} per-person distribution has no centre "
                         "(median or mean) to move", hint="vary it by a lognormal, beta or "
                         "normal with a median or mean")


def _respread(dist: Any, name: str, value: float) -> Any:
    """A per-person distribution with its spread ``name`` (a lognormal's sigma, a beta's
    sd) set to ``value`` (its centre kept; a beta's sd kept valid)."""
    from opspec.usermodels.population_distributions import make_per_user

    params = dict(dist.params)
    if name not in params:
        raise ParameterError(name, f"a {dist.kind} per-person distribution has no {name}",
                             hint="fit the model again")
    value = max(float(value), 1e-6)
    if dist.kind == "beta":
        centre = float(params.get("mean", 0.5))
        value = min(value, 0.999 * math.sqrt(centre * (1 - centre)))
    params[name] = value
    return make_per_user({"kind": dist.kind, **params})


def _apply(model: Any, changes: Sequence[tuple[tuple[str, ...], float]]) -> Any:
    from opspec.usermodels.population import set_parameter

    own = model
    for path, value in changes:
        if path[0] != "vary":
            own = set_parameter(own, path, value)
    population = model.population
    if population is None:
        if any(path[0] == "vary" for path, _ in changes):
            raise ParameterError("vary", "redraws a [vary] spread, but the model has no "
                                 "population", hint="fit the model again")
        return own
    groups = []
    for group in population.subgroups:
        sub = group.model
        varied = list(group.varied)
        for path, value in changes:
            spread = path[0] == "vary"
            target = path[1:-1] if spread else path
            hit = next((i for i, v in enumerate(varied) if v.path == target), None)
            if hit is not None:
                dist = varied[hit].distribution
                varied[hit] = replace(varied[hit], distribution=(
                    _respread(dist, path[-1], value) if spread else _recentred(dist, value)))
            elif not spread:
                sub = set_parameter(sub, path, value)
        groups.append(replace(group, model=sub, varied=tuple(varied)))
    return replace(own, population=replace(population, subgroups=tuple(groups)))


def _read_table(path: Path) -> Any:
    from opspec.usermodels.loader import _read

    return _read(path).get(TABLE)


def read_parameter_draws(ref: str | Path) -> tuple[ParameterDraws, int] | None:
    """The parameter draws of a user-model reference (a file, a preset, or ``A,B``: the
    first part whose file has them) with the index of that part; None when it has none."""
    from opspec.usermodels.loader import resolve_preset

    for index, part in enumerate(p.strip() for p in str(ref).split(",")):
        path = Path(part)
        if not path.is_file():
            if path.suffix == ".toml" or "/" in part:
                continue          # the loader says what is wrong with it
            try:
                path = resolve_preset(part)
            except UserModelError:
                continue
        table = _read_table(path)
        if table is not None:
            return ParameterDraws.from_table(table, str(path)), index
    return None


#: the models loaded up to the fitted part, by reference and the parts' file states (a
#: worker runs many draws of one file: it is read once, not once per draw)
_LOADED: dict[tuple[Any, ...], Any] = {}


def _state(part: str) -> tuple[str, int, int]:
    try:
        found = Path(part).stat()
    except OSError:
        return part, 0, 0
    return part, found.st_mtime_ns, found.st_size


def drawn_model(ref: str, draws: ParameterDraws, index: int, draw: int) -> Any:
    """The model ``ref`` names with draw ``draw`` applied to its part ``index`` (the fitted
    file), before the parts composed on top of it (their modifiers then apply as usual)."""
    from opspec.usermodels.loader import load_user_model

    parts = [p.strip() for p in ref.split(",")]
    key = tuple(_state(p) for p in parts[:index + 1])
    model = _LOADED.get(key)
    if model is None:
        for part in parts[:index + 1]:
            model = load_user_model(part, base=model)
        if len(_LOADED) > 16:
            _LOADED.clear()
        _LOADED[key] = model
    model = draws.apply(model, draw)
    for part in parts[index + 1:]:
        model = load_user_model(part, base=model)
    return model
