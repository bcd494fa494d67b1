"""Reading a population from a user-model file: ``[vary]``, ``[[correlations]]``,
``[subgroups]`` (the format is in ``docs/user-models.md``, section "Populations").

Everything is checked before any simulation, and every error names the file, the line and
the TOML key (``people.toml:40: subgroups: shares add up to 0.95, not 1 (...)``):

* a varied parameter must name a number of the (subgroup's) model, and its per-user
  distribution must only draw values that number allows: a probability drawn from a
  lognormal is refused (its support runs past 1), as is a median drawn from an untruncated
  normal (it can draw negative values);
* correlations must join two parameters varied in the same subgroup, at most once, and
  together form a positive semi-definite correlation matrix for the Gaussian copula;
* shares are numbers in (0, 1] adding up to 1.
"""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from opspec.usermodels.distributions import ParameterError
from opspec.usermodels.loader import POPULATION_KEYS, _Ctx, load_named, parse_user_model
from opspec.usermodels.model import Modifier, UserModel
from opspec.usermodels.population import (
    Correlation,
    Population,
    Subgroup,
    VariedParameter,
    dotted,
    set_parameter,
)
from opspec.usermodels.population_distributions import (
    CORRELATION_KINDS,
    PerUserDistribution,
    copula_correlation,
    make_per_user,
    smallest_eigenvalue,
)

__all__ = ["compose", "parse_population"]

#: a subgroup's table: its own keys, then the model keys it may change
_SUBGROUP_KEYS = ("share", "description", "source", "extends", "apply", "vary",
                  "correlations", "activities", "defaults", "busy", "routine", "modifier")
_MODEL_KEYS = ("activities", "defaults", "busy", "routine", "modifier")
_MODIFIER_FIELDS = ("duration_factor", "notice_factor", "tail_fraction")
_SHARE_TOLERANCE = 1e-6
#: how far out an unbounded support is probed for values the parameter refuses
_FAR = 1e9

Varied = dict[tuple[str, ...], tuple[VariedParameter, str]]      # path -> (parameter, key)
Stated = dict[frozenset[str], tuple[Correlation, str]]            # pair -> (correlation, key)


def _is_distribution(value: Any) -> bool:
    return isinstance(value, Mapping) and "kind" in value


def _vary(ctx: _Ctx, value: Any, key: str) -> Varied:
    """The ``[vary]`` table: nested tables down to per-user distribution tables."""
    out: Varied = {}
    if not isinstance(value, Mapping):
        raise ctx.error(key, f"must be a table, got {type(value).__name__}",
                        hint="for example [vary.activities.hear_alarm.omission] probability = "
                        '{ kind = "beta", mean = 0.15, sd = 0.08 }')

    def walk(table: Mapping[str, Any], path: tuple[str, ...]) -> None:
        for name, entry in table.items():
            here = (*path, name)
            where = f"{key}.{dotted(here)}"
            if _is_distribution(entry):
                try:
                    dist = make_per_user(entry)
                except ParameterError as error:
                    raise ctx.wrap(where, error) from None
                source = entry.get("source")
                if source is not None and not isinstance(source, str):
                    raise ctx.error(f"{where}.source", f"must be a string, got {source!r}")
                out[here] = (VariedParameter(here, dist, source), where)
            elif isinstance(entry, Mapping):
                walk(entry, here)
            else:
                raise ctx.error(where, f"must be a per-user distribution, got {entry!r}",
                                hint='for example { kind = "beta", mean = 0.15, sd = 0.08 }; '
                                "a value the same for everyone belongs in the model itself")

    walk(value, ())
    return out


def _parameter_path(ctx: _Ctx, text: Any, key: str) -> tuple[str, ...]:
    """A dotted parameter name (``activities.walk.duration.median``) as a path, read as a
    TOML key (so quoted parts work as in the file)."""
    if not isinstance(text, str) or not text.strip():
        raise ctx.error(key, f"must name a varied parameter, got {text!r}",
                        hint='for example "activities.hear_alarm.omission.probability"')
    try:
        tree: Any = tomllib.loads(f"{text} = 0")
    except tomllib.TOMLDecodeError:
        raise ctx.error(key, f"{text!r} is not a dotted parameter name",
                        hint='for example "activities.hear_alarm.omission.probability"'
                        ) from None
    path: list[str] = []
    while isinstance(tree, Mapping):
        (name, tree), = tree.items()
        path.append(name)
    return tuple(path)


def _correlations(ctx: _Ctx, value: Any, key: str) -> Stated:
    if not isinstance(value, list):
        raise ctx.error(key, "must be an array of tables ([[correlations]])",
                        hint='[[correlations]] parameters = ["A", "B"] spearman = 0.4')
    out: Stated = {}
    for i, raw in enumerate(value):
        where = f"{key}[{i}]"
        table = ctx.table(raw, where, ("parameters", *CORRELATION_KINDS, "source"))
        names = table.get("parameters")
        if not isinstance(names, list) or len(names) != 2:
            raise ctx.error(f"{where}.parameters", "must list two varied parameters",
                            hint='parameters = ["activities.hear_alarm.omission.probability", '
                            '"modifier.duration_factor"]')
        first, second = (dotted(_parameter_path(ctx, n, f"{where}.parameters")) for n in names)
        if first == second:
            raise ctx.error(f"{where}.parameters", f"names {first} twice",
                            hint="a correlation joins two different parameters")
        kinds = [k for k in CORRELATION_KINDS if k in table]
        if len(kinds) != 1:
            raise ctx.error(where, "needs exactly one of: " + ", ".join(CORRELATION_KINDS),
                            hint="spearman = 0.4 (a rank correlation) is the usual choice")
        kind = kinds[0]
        rho = table[kind]
        if isinstance(rho, bool) or not isinstance(rho, (int, float)) or not -1 <= rho <= 1:
            raise ctx.error(f"{where}.{kind}", f"must be a correlation in [-1, 1], got {rho!r}")
        source = table.get("source")
        if source is not None and not isinstance(source, str):
            raise ctx.error(f"{where}.source", f"must be a string, got {source!r}")
        pair = frozenset((first, second))
        if pair in out:
            raise ctx.error(where, f"repeats the correlation of {first} and {second} "
                            f"(already at {out[pair][1]})")
        out[pair] = (Correlation(first, second, kind, float(rho),
                                 copula_correlation(kind, float(rho)), source), where)
    return out


# ------------------------------------------------------------------------- checking


def _apply(model: UserModel, path: tuple[str, ...], value: float) -> None:
    """Raise :class:`ParameterError` when ``value`` is not allowed at ``path``."""
    if path[0] == "modifier":
        if len(path) != 2 or path[1] not in _MODIFIER_FIELDS:
            raise ParameterError(dotted(path), "is not a field of a per-user modifier",
                                 hint="vary modifier.duration_factor, modifier.notice_factor "
                                 "or modifier.tail_fraction")
        field: dict[str, Any] = {path[1]: value}
        try:
            Modifier(**field)
        except ParameterError as error:
            raise ParameterError(dotted(path), error.detail, hint=error.hint) from None
        return
    set_parameter(model, path, value)


def _hint(detail: str, dist: PerUserDistribution) -> str:
    if "probabilit" in detail or "[0, 1]" in detail:
        return ("draw a probability from a beta distribution, or from a normal with low = 0 "
                "and high = 1")
    if dist.kind == "normal":
        return "truncate the normal (low = 0 for a positive parameter), or use a lognormal"
    return "use a lognormal or gamma for a positive parameter, a beta for a probability"


def _check(ctx: _Ctx, model: UserModel, varied: VariedParameter, key: str, group: str
           ) -> None:
    """The path names a number of ``model`` and the distribution draws only values it
    allows (the median, and points just inside each end of the support)."""
    dist = varied.distribution
    in_group = f" (subgroup {group})" if group else ""
    try:
        _apply(model, varied.path, dist.quantile(0.5))
    except ParameterError as error:
        raise ctx.error(key, f"{error.detail}{in_group}", error.hint) from None
    if varied.path[:2] == ("routine", "windows") and varied.path[-1] in ("start", "end"):
        return                                  # a drawn time of day wraps around midnight
    low, high = dist.support
    probes = []
    if math.isfinite(low):
        probes.append((low, low + 1e-9 * max(1.0, abs(low)), "down to"))
    else:
        probes.append((low, -_FAR, "down to"))
    if math.isfinite(high):
        probes.append((high, high - 1e-9 * max(1.0, abs(high)), "up to"))
    else:
        probes.append((high, _FAR, "up to"))
    for end, probe, words in probes:
        try:
            _apply(model, varied.path, probe)
        except ParameterError as error:
            allowed = re.sub(r",? got [^,]*$", "", error.detail)   # the probe, not the user's
            raise ctx.error(
                key, f"{dist.describe()} draws values {words} {end:g} (its support runs "
                f"from {low:g} to {high:g}), but the parameter {allowed}{in_group}",
                _hint(error.detail, dist)) from None


def _subgroup(ctx: _Ctx, name: str | None, share: float, model: UserModel, varied: Varied,
              stated: Stated, key: str, *, description: str = "",
              source: str | None = None) -> Subgroup:
    """A checked subgroup: every varied parameter against ``model``, the correlations
    against the varied parameters, the copula matrix positive semi-definite."""
    group = name or ""
    for parameter, where in varied.values():
        _check(ctx, model, parameter, where, group)
    order = [p.name for p, _ in varied.values()]
    index = {n: i for i, n in enumerate(order)}
    matrix = np.eye(len(order))
    for correlation, where in stated.values():
        for n in (correlation.first, correlation.second):
            if n not in index:
                raise ctx.error(f"{where}.parameters", f"{n} is not varied"
                                + (f" in subgroup {group}" if group else ""),
                                hint="correlate parameters drawn per user (in [vary]): "
                                + (", ".join(order) or "none are"))
        i, j = index[correlation.first], index[correlation.second]
        matrix[i, j] = matrix[j, i] = correlation.r
    if stated and smallest_eigenvalue(matrix) < -1e-9:
        listed = "; ".join(f"{c.first} ~ {c.second} {c.kind} {c.value:g}"
                           for c, _ in stated.values())
        raise ctx.error(
            key, "the correlations cannot hold together: their matrix is not positive "
            f"semi-definite (smallest eigenvalue {smallest_eigenvalue(matrix):.3g}"
            + (", after Spearman/Kendall were converted to the Gaussian copula's r"
               if any(c.kind != "gaussian" for c, _ in stated.values()) else "")
            + f"){' in subgroup ' + group if group else ''}: {listed}",
            hint="weaken them: if A goes with B and B with C, A cannot go strongly against C")
    return Subgroup(name, share, model, tuple(p for p, _ in varied.values()),
                    tuple(c for c, _ in stated.values()), matrix, description, source)


# --------------------------------------------------------------------------- reading


def _subgroup_model(ctx: _Ctx, table: Mapping[str, Any], key: str, name: str,
                    top: UserModel, path: str) -> UserModel:
    """The subgroup's model: ``extends`` (default: the file's own model), then each of
    ``apply`` loaded on top, then the subgroup's own model tables."""
    model = top
    if "extends" in table:
        ref = table["extends"]
        if not isinstance(ref, str):
            raise ctx.error(f"{key}.extends", f"must be a model file or preset, got {ref!r}")
        model = load_named(ctx, ref, path, f"{key}.extends")
    refs = table.get("apply", [])
    if isinstance(refs, str):
        refs = [refs]
    if not isinstance(refs, list) or not all(isinstance(r, str) for r in refs):
        raise ctx.error(f"{key}.apply", "must be a list of model files or presets",
                        hint='for example apply = ["mci"]')
    for ref in refs:
        model = load_named(ctx, ref, path, f"{key}.apply", base=model)
    if model.population is not None:
        raise ctx.error(key, f"subgroup {name} is built on a population model "
                        f"({model.path})", hint="a subgroup is one kind of person: extend "
                        "or apply plain models and modifiers")
    body = {k: table[k] for k in _MODEL_KEYS if k in table}
    if body:
        body["name"] = name
        model = parse_user_model(body, path, base=model, key_prefix=f"{key}.")
    from dataclasses import replace

    return replace(model, name=f"{top.name}/{name}", description=str(
        table.get("description", model.description)), path=path)


def parse_population(ctx: _Ctx, doc: Mapping[str, Any], model: UserModel,
                     base: UserModel | None) -> Population:
    """The population a file declares; ``model`` is the file's own model (the typical
    person, and the base of subgroups that do not ``extends`` another)."""
    if base is not None and base.population is not None:
        raise ctx.error(next(k for k in POPULATION_KEYS if k in doc),
                        f"this file declares a population on top of the population of "
                        f"{base.path}", hint="compose one population with plain models and "
                        "modifiers, not two populations")
    path = ctx.path
    varied = _vary(ctx, doc["vary"], "vary") if "vary" in doc else {}
    stated = (_correlations(ctx, doc["correlations"], "correlations")
              if "correlations" in doc else {})
    if "subgroups" not in doc:
        group = _subgroup(ctx, None, 1.0, model, varied, stated, "correlations")
        return Population((group,), path)
    raw = doc["subgroups"]
    if not isinstance(raw, Mapping) or not raw:
        raise ctx.error("subgroups", "must be tables of named subgroups",
                        hint="[subgroups.independent] share = 0.7 ... [subgroups.mci] "
                        "share = 0.3")
    groups = []
    shares: list[tuple[str, float]] = []
    for name, table in raw.items():
        key = f"subgroups.{dotted((name,))}"
        t = ctx.table(table, key, _SUBGROUP_KEYS)
        if "share" not in t:            # said as missing, not as "got None"
            raise ctx.error(f"{key}.share", "is required: the share of the users in this "
                            "subgroup", hint="write a fraction: 70 % is share = 0.7")
        share = t["share"]
        if isinstance(share, bool) or not isinstance(share, (int, float)) or not (
                0 < share <= 1):
            raise ctx.error(f"{key}.share", f"must be a share in (0, 1], got {share!r}",
                            hint="write a fraction: 70 % is 0.7")
        shares.append((name, float(share)))
        own = _vary(ctx, t["vary"], f"{key}.vary") if "vary" in t else {}
        own_stated = (_correlations(ctx, t["correlations"], f"{key}.correlations")
                      if "correlations" in t else {})
        source = t.get("source")
        if source is not None and not isinstance(source, str):
            raise ctx.error(f"{key}.source", f"must be a string, got {source!r}")
        sub_model = _subgroup_model(ctx, t, key, name, model, path)
        groups.append(_subgroup(ctx, name, float(share), sub_model, {**varied, **own},
                                {**stated, **own_stated}, f"{key}.correlations",
                                description=str(t.get("description", "")), source=source))
    total = math.fsum(s for _, s in shares)
    if abs(total - 1.0) > _SHARE_TOLERANCE:
        listed = ", ".join(f"{n} {s:g}" for n, s in shares)
        raise ctx.error("subgroups", f"shares add up to {total:g}, not 1 ({listed})",
                        hint="every simulated user belongs to exactly one subgroup: make "
                        "the shares add up to 1")
    return Population(tuple(groups), path)


def compose(ctx: _Ctx, doc: Mapping[str, Any], population: Population,
            modifier: Modifier | None) -> Population:
    """A plain file composed on top of a population (``people.toml,older-adults``): its
    model tables change every subgroup's model (the varied parameters are checked again),
    its modifier applies to each person after the draw."""
    body = {k: v for k, v in doc.items() if k in _MODEL_KEYS and k != "modifier"}
    if body:
        body["name"] = str(doc.get("name", Path(ctx.path).stem))
        changed = []
        for group in population.subgroups:
            model = parse_user_model(body, ctx.path, base=group.model)
            varied = {p.path: (p, f"vary.{p.name}") for p in group.varied}
            stated = {frozenset((c.first, c.second)): (c, "correlations")
                      for c in group.correlations}
            changed.append(_subgroup(ctx, group.name, group.share, model, varied, stated,
                                     "correlations", description=group.description,
                                     source=group.source))
        population = Population(tuple(changed), population.path, population.after)
    return population.then(modifier) if modifier is not None else population
