"""Reading and writing user-model TOML files; resolving presets by name.

The format is documented in ``docs/user-models.md``. Every error names the file, the line and
the dotted key (``users.toml:12: activities.walk_to_dispenser.duration.sigma: must be > 0, got
-1``; the line is the key's, or its nearest written parent's: :mod:`opspec.toml_lines`) and
says how to fix it. ``load_user_model`` accepts a path, a preset name (``older-adults``), or a
comma-separated composition ``BASE,MODIFIER,...`` (``specs/x.users.toml,older-adults``).
"""

from __future__ import annotations

import contextvars
import math
import tomllib
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

import tomli_w

from opspec.errors import SourceLocation, UserModelError
from opspec.usermodels.distributions import Distribution, ParameterError, make_distribution
from opspec.usermodels.errors import Busy, Commission, ExtraDelay, Omission, Repetition
from opspec.usermodels.model import ActivityModel, Modifier, UserModel
from opspec.usermodels.routine import Drift, Routine, Window

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "dump_user_model",
    "emit_toml",
    "load_user_model",
    "parse_user_model",
    "preset_names",
    "resolve_preset",
    "user_model_to_toml",
]

FORMAT = "opspec-user-model"
FORMAT_VERSION = 1

_TOP_KEYS = ("format", "version", "name", "description", "source", "extends", "defaults",
             "activities", "busy", "routine", "modifier", "operators",
             "vary", "correlations", "subgroups",   # these three: a population
             "uncertainty",   # parameter redraws of a fitted model (usermodels.uncertainty)
             "fitted_on")     # whom a fitted model was fitted on (usermodels.fitted_on)
#: keys of a population (docs/user-models.md, "Populations")
POPULATION_KEYS = ("vary", "correlations", "subgroups")
_ACTIVITY_KEYS = ("duration", "omission", "prompt", "commission", "repetition", "delay",
                  "intended", "probabilities", "source")


class _Ctx:
    """The file being read, for error locations; ``prefix`` is put before every key (the
    table of a subgroup: ``subgroups.mci.``)."""

    def __init__(self, path: str, operators: Mapping[str, float] | None = None,
                 prefix: str = "") -> None:
        self.path = path
        self.operators = dict(operators or {})
        self.prefix = prefix

    def error(self, key: str, message: str, hint: str = "") -> UserModelError:
        """The error ``message`` at ``file:line: key`` (the line the key, or its nearest
        written parent, is on: an editor jumps to it)."""
        from opspec.toml_lines import located

        return UserModelError(message, location=located(
            self.path, f"{self.prefix}{key}" if key else self.prefix.rstrip(".") or None),
            hint=hint)

    def table(self, value: Any, key: str, allowed: tuple[str, ...]) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            raise self.error(key, f"must be a table, got {type(value).__name__}")
        for name in value:
            if name not in allowed:
                hint = "expected one of: " + ", ".join(allowed)
                if key and name in _TOP_KEYS:
                    # "name = ..." appended at the end of the file lands in its last table
                    hint += (f"; {name} belongs at the top of the file: a key written below "
                             "a [table] line is in that table, so move it above the first "
                             "[table] line")
                raise self.error(f"{key}.{name}" if key else name, "unknown key", hint=hint)
        return value

    def wrap(self, key: str, error: ParameterError) -> UserModelError:
        return self.error(f"{key}.{error.param}" if key else error.param, error.detail,
                          error.hint)


def _string(ctx: _Ctx, value: Any, key: str) -> str:
    if not isinstance(value, str):
        raise ctx.error(key, f"must be a string, got {value!r}")
    return value


def _distribution(ctx: _Ctx, value: Any, key: str) -> Distribution:
    try:
        if isinstance(value, Mapping) and str(value.get("kind", "")).lower() == "klm":
            return _klm(ctx, value, key)
        return make_distribution(value)
    except ParameterError as error:
        raise ctx.wrap(key, error) from None


def _klm(ctx: _Ctx, value: Mapping[str, Any], key: str) -> Distribution:
    """``{ kind = "klm", operators = "M P K" }``: the sum of keystroke-level-model operator
    times from the ``[operators]`` table (of this file, or of the ``klm`` preset)."""
    ctx.table(value, key, ("kind", "operators", "source"))
    ops = value.get("operators")
    if not isinstance(ops, str) or not ops.split():
        raise ctx.error(f"{key}.operators", "must be a string of operator letters like \"M P\"")
    table = ctx.operators or _klm_operators()
    total = 0.0
    for op in ops.split():
        if op not in table:
            raise ctx.error(f"{key}.operators", f"unknown KLM operator {op!r}",
                            hint="known operators: " + ", ".join(sorted(table)))
        total += table[op]
    return make_distribution({"kind": "constant", "value": total})


def _klm_operators() -> dict[str, float]:
    doc = tomllib.loads(resolve_preset("klm").read_text(encoding="utf-8"))
    return _operators(_Ctx(str(resolve_preset("klm"))), doc.get("operators", {}))


def _operators(ctx: _Ctx, value: Any) -> dict[str, float]:
    table = ctx.table(value, "operators", tuple(value) if isinstance(value, Mapping) else ())
    out: dict[str, float] = {}
    for name, entry in table.items():
        seconds = entry.get("seconds") if isinstance(entry, Mapping) else entry
        if isinstance(seconds, bool) or not isinstance(seconds, (int, float)) or seconds < 0:
            raise ctx.error(f"operators.{name}", f"must be seconds >= 0, got {seconds!r}")
        out[name] = float(seconds)
    return out


def _probability_table(ctx: _Ctx, value: Any, key: str, allowed: tuple[str, ...]
                       ) -> Mapping[str, Any]:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return {"probability": value}
    return ctx.table(value, key, allowed)


def _activity(ctx: _Ctx, value: Any, key: str) -> ActivityModel:
    table = ctx.table(value, key, _ACTIVITY_KEYS)
    kwargs: dict[str, Any] = {}
    try:
        if "duration" in table:
            kwargs["duration"] = _distribution(ctx, table["duration"], f"{key}.duration")
        else:
            kwargs["untimed"] = True
        if "omission" in table:
            sub = f"{key}.omission"
            t = _probability_table(ctx, table["omission"], sub,
                                   ("probability", "reason", "source"))
            try:
                kwargs["omission"] = Omission(t.get("probability", 0.0),
                                              _string(ctx, t.get("reason", "not noticed"),
                                                      f"{sub}.reason"), t.get("source"))
            except ParameterError as error:
                raise ctx.wrap(sub, error) from None
        prompt = table.get("prompt", "omission" in table)
        if not isinstance(prompt, bool):
            raise ctx.error(f"{key}.prompt", f"must be true or false, got {prompt!r}")
        kwargs["prompt"] = prompt
        if "commission" in table:
            sub = f"{key}.commission"
            t = _probability_table(ctx, table["commission"], sub, (
                "probability", "recovery", "alternatives", "max_per_instance", "source"))
            recovery = (_distribution(ctx, t["recovery"], f"{sub}.recovery")
                        if "recovery" in t else make_distribution(0.0))
            alternatives = t.get("alternatives", [])
            if not isinstance(alternatives, list) or not all(
                    isinstance(a, str) for a in alternatives):
                raise ctx.error(f"{sub}.alternatives", "must be a list of activity ids")
            try:
                kwargs["commission"] = Commission(t.get("probability", 0.0), recovery,
                                                  tuple(alternatives),
                                                  t.get("max_per_instance", 1), t.get("source"))
            except ParameterError as error:
                raise ctx.wrap(sub, error) from None
        if "repetition" in table:
            sub = f"{key}.repetition"
            t = _probability_table(ctx, table["repetition"], sub, ("probability", "source"))
            try:
                kwargs["repetition"] = Repetition(t.get("probability", 0.0), t.get("source"))
            except ParameterError as error:
                raise ctx.wrap(sub, error) from None
        if "delay" in table:
            sub = f"{key}.delay"
            t = ctx.table(table["delay"], sub, ("probability", "duration", "source"))
            if "duration" not in t:
                raise ctx.error(f"{sub}.duration", "is required",
                                hint='for example duration = { kind = "exponential", mean = 30 }')
            try:
                kwargs["delay"] = ExtraDelay(t.get("probability", 0.0),
                                             _distribution(ctx, t["duration"], f"{sub}.duration"),
                                             t.get("source"))
            except ParameterError as error:
                raise ctx.wrap(sub, error) from None
        if "intended" in table:
            kwargs["intended"] = _string(ctx, table["intended"], f"{key}.intended")
        if "probabilities" in table:
            sub = f"{key}.probabilities"
            t = ctx.table(table["probabilities"], sub, tuple(table["probabilities"])
                          if isinstance(table["probabilities"], Mapping) else ())
            pairs = []
            for name, p in t.items():
                if isinstance(p, bool) or not isinstance(p, (int, float)) or not 0 <= p <= 1:
                    raise ctx.error(f"{sub}.{name}", f"must be a probability in [0, 1], got {p!r}")
                pairs.append((name, float(p)))
            kwargs["probabilities"] = tuple(pairs)
        if "source" in table:
            kwargs["source"] = _string(ctx, table["source"], f"{key}.source")
        return ActivityModel(**kwargs)
    except ParameterError as error:
        raise ctx.wrap(key, error) from None


def _busy(ctx: _Ctx, value: Any) -> Busy:
    t = ctx.table(value, "busy", ("engaged", "ignore", "release_after", "source"))
    for name in ("engaged", "ignore", "release_after"):
        if name in t and not isinstance(t[name], list):
            raise ctx.error(f"busy.{name}", "must be a list of activity ids",
                            hint=f'for example {name} = ["walk_to_dispenser"]')
    try:
        return Busy(frozenset(t.get("engaged", [])),
                    frozenset(t["ignore"]) if "ignore" in t else None,
                    frozenset(t.get("release_after", [])), t.get("source"))
    except ParameterError as error:
        raise ctx.wrap("busy", error) from None


def _routine(ctx: _Ctx, value: Any) -> Routine:
    t = ctx.table(value, "routine", ("windows", "drift", "source"))
    windows = []
    raw_windows = t.get("windows", [])
    if not isinstance(raw_windows, list):
        raise ctx.error("routine.windows", "must be an array of tables ([[routine.windows]])")
    keys = ("name", "start", "end", "notice_factor", "duration_factor", "defer", "probability",
            "source")
    for i, raw in enumerate(raw_windows):
        key = f"routine.windows[{i}]"
        w = ctx.table(raw, key, keys)
        for required in ("name", "start", "end"):
            if required not in w:
                raise ctx.error(f"{key}.{required}", "is required")
        if not isinstance(w.get("defer", False), bool):
            raise ctx.error(f"{key}.defer", "must be true or false")
        try:
            windows.append(Window(_string(ctx, w["name"], f"{key}.name"), w["start"], w["end"],
                                  w.get("notice_factor", 1.0), w.get("duration_factor", 1.0),
                                  w.get("defer", False), w.get("probability", 1.0),
                                  w.get("source")))
        except ParameterError as error:
            raise ctx.wrap(key, error) from None
    drift = Drift()
    if "drift" in t:
        d = ctx.table(t["drift"], "routine.drift", (
            "notice_factor_per_day", "min_notice_factor", "duration_factor_per_day",
            "min_duration_factor", "source"))
        try:
            drift = Drift(**d)
        except ParameterError as error:
            raise ctx.wrap("routine.drift", error) from None
    return Routine(tuple(windows), drift)


def _modifier(ctx: _Ctx, value: Any, name: str) -> Modifier:
    t = ctx.table(value, "modifier", ("duration_factor", "tail_fraction", "notice_factor",
                                      "source"))
    try:
        return Modifier(name=name, **t)
    except ParameterError as error:
        raise ctx.wrap("modifier", error) from None


def parse_user_model(doc: Mapping[str, Any], path: str = "<toml>", *,
                     base: UserModel | None = None, key_prefix: str = "") -> UserModel:
    """Build a :class:`UserModel` from a parsed TOML document. ``base`` is the model an
    ``extends`` key or a composition names; this file's activities override the base's, and
    this file's ``[modifier]`` is then applied to the result. ``[vary]``,
    ``[[correlations]]`` and ``[subgroups]`` make it a population
    (:mod:`opspec.usermodels.population_loader`); a file composed on top of a population
    changes every subgroup's model, and its modifier applies to each person after the draw.
    ``key_prefix`` is put before every key in error messages (a subgroup's table)."""
    ctx = _Ctx(path, prefix=key_prefix)
    ctx.table(doc, "", _TOP_KEYS)
    fmt = doc.get("format", FORMAT)
    if fmt != FORMAT:
        raise ctx.error("format", f"must be {FORMAT!r}, got {fmt!r}")
    version = doc.get("version", FORMAT_VERSION)
    if version != FORMAT_VERSION:
        raise ctx.error("version", f"unsupported version {version!r}",
                        hint=f"this opspec reads version {FORMAT_VERSION}")
    name = _string(ctx, doc.get("name", Path(path).stem.removesuffix(".users")), "name")
    if "operators" in doc:
        ctx.operators = _operators(ctx, doc["operators"])
    extended = base is None and "extends" in doc
    if extended:
        base = load_named(ctx, _string(ctx, doc["extends"], "extends"), path)
    activities: dict[str, ActivityModel] = dict(base.activities) if base else {}
    raw_activities = doc.get("activities", {})
    ctx.table(raw_activities, "activities", tuple(raw_activities)
              if isinstance(raw_activities, Mapping) else ())
    for activity_id, value in raw_activities.items():
        activities[activity_id] = _activity(ctx, value, f"activities.{activity_id}")
    default = base.default if base else None
    if "defaults" in doc:
        default = _activity(ctx, doc["defaults"], "defaults")
    busy = _busy(ctx, doc["busy"]) if "busy" in doc else (base.busy if base else None)
    routine = _routine(ctx, doc["routine"]) if "routine" in doc else (
        base.routine if base else Routine())
    # a file that extends another and names itself is called so (a population extending
    # its reference user); composed on a base (SPEC.users.toml,older-adults), or unnamed,
    # it is its base with what it changes
    called = name
    if base is not None and not (extended and "name" in doc):
        called = f"{base.name}+{name}" if raw_activities else base.name
    model = UserModel(
        name=called,
        activities=activities, default=default, busy=busy, routine=routine,
        modifiers=base.modifiers if base else (),
        description=_string(ctx, doc.get("description", ""), "description"),
        source=_string(ctx, doc.get("source", ""), "source"),
        path=path)
    modifier = _modifier(ctx, doc["modifier"], name) if "modifier" in doc else None
    if modifier is not None:
        model = model.with_modifier(modifier)
    if "uncertainty" in doc:         # checked here, so a bad table names the file at load
        from opspec.usermodels.uncertainty import ParameterDraws

        ParameterDraws.from_table(doc["uncertainty"], path)
    if "fitted_on" in doc:
        from opspec.usermodels.fitted_on import check_table

        check_table(doc["fitted_on"], path)
    declares = any(key in doc for key in POPULATION_KEYS)
    if declares or (base is not None and base.population is not None):
        from dataclasses import replace

        from opspec.usermodels import population_loader

        if declares:
            population = population_loader.parse_population(ctx, doc, model, base)
        else:
            assert base is not None and base.population is not None
            population = population_loader.compose(ctx, doc, base.population, modifier)
        model = replace(model, population=population)
    return model


#: How many files an ``extends`` chain may pass through (A extends B extends C…).
MAX_EXTENDS = 32

# the files being extended, outermost first, while their bases load (a cycle comes back to
# one of them)
_EXTENDING: contextvars.ContextVar[tuple[Path, ...]] = contextvars.ContextVar(
    "opspec_user_model_extending", default=())


def load_named(ctx: _Ctx, ref: str, path: str, key: str = "extends",
              base: UserModel | None = None) -> UserModel:
    """The model ``extends = ref`` (or another ``key``: a subgroup's ``extends`` and
    ``apply``, loaded on ``base``) names in the file ``path``: a file relative to it, read
    only inside its folder tree and :data:`opspec.files.EXTERNAL_PATH_VARIABLE` (as a spec's
    ExternalPackage), or a preset; an ``extends`` that comes back to a file being extended,
    or a chain of more than :data:`MAX_EXTENDS` files, is a located error."""
    from opspec.files import EXTERNAL_PATH_VARIABLE, allowed_roots, outside_roots

    here = Path(path)
    local = here.parent / ref
    word = key.rsplit(".", 1)[-1]
    chain = _EXTENDING.get()
    own = here.resolve() if here.is_file() else None
    if own is not None and own in chain:
        shown = " -> ".join(str(p) for p in (*chain[chain.index(own):], own))
        raise ctx.error(key, f"{word} {ref!r} comes back to {path}: a cycle ({shown})",
                        hint="a user model may extend another, never itself")
    if len(chain) >= MAX_EXTENDS:
        raise ctx.error(key, f"{word} {ref!r}: more than {MAX_EXTENDS} user models extend "
                        "one another", hint="shorten the chain of extends")
    if local.is_file() or Path(ref).is_absolute() or "/" in ref or "\\" in ref:
        roots = allowed_roots(path)
        where = outside_roots(local, roots)
        if where is not None:
            raise ctx.error(key, f"{word} {ref!r} leads outside the user model's folder "
                            f"({where}); opspec reads the files a user model names "
                            f"only inside {' or '.join(str(r) for r in roots)}",
                            hint="copy the base model beside this one, or allow its folder "
                            f"with the environment variable {EXTERNAL_PATH_VARIABLE}")
        if local.resolve() == own:
            raise ctx.error(key, f"{word} {ref!r} is this file itself",
                            hint="a user model may extend another, never itself")
    token = _EXTENDING.set((*chain, own) if own is not None else chain)
    try:
        return load_user_model(str(local) if local.is_file() else ref, base=base)
    except UserModelError as error:
        at = error.location
        if at is not None and (at.line is not None or at.key is not None):
            raise                   # a mistake inside the model it names, at its own line
        # nothing by that name, or a file that cannot be read: said at this file's line
        # that names it
        raise ctx.error(key, f"{word} {ref!r}: {error.message}", error.hint) from None
    finally:
        _EXTENDING.reset(token)


def preset_names() -> list[str]:
    """Names of the bundled presets (``klm``, ``older-adults``…)."""
    folder = resources.files("opspec.usermodels") / "presets"
    return sorted(p.name.removesuffix(".toml") for p in folder.iterdir()
                  if p.name.endswith(".toml"))


def resolve_preset(name: str) -> Path:
    """The file of bundled preset ``name``; :class:`UserModelError` naming the closest
    preset and listing them all."""
    folder = resources.files("opspec.usermodels") / "presets"
    candidate = folder / f"{name}.toml"
    if not candidate.is_file():
        import difflib

        close = difflib.get_close_matches(name, preset_names(), n=1)
        meant = f"; did you mean {close[0]!r}?" if close else ""
        raise UserModelError(f"no user model file or preset called {name!r}{meant}",
                             hint="give a path to a .toml file or one of the presets: "
                             + ", ".join(preset_names()))
    return Path(str(candidate))


def _read(path: Path) -> dict[str, Any]:
    from opspec.toml_files import read_toml

    return read_toml(path, what="user model", error=UserModelError)


def load_user_model(ref: str | Path, *, base: UserModel | None = None) -> UserModel:
    """Load a user model from a path, a preset name, or a composition ``A,B,...`` (``A`` is
    loaded, then each of ``B``... is loaded on top of it: its activities override, its
    ``[modifier]`` applies). ``base`` puts the given model under ``ref`` the same way."""
    text = str(ref)
    if isinstance(ref, str) and "," in ref:
        model = base
        for part in (p.strip() for p in ref.split(",")):
            if not part:
                raise UserModelError(f"empty part in user model composition {ref!r}",
                                     hint="write BASE,MODIFIER (for example "
                                     "specs/medication_dispenser.users.toml,older-adults)")
            model = load_user_model(part, base=model)
        assert model is not None
        return model
    path = Path(text)
    if not path.is_file():
        if path.exists() and not path.is_dir():    # a pipe or device: say what it is
            _read(path)
        if path.suffix == ".toml" or "/" in text or "\\" in text:
            raise UserModelError("user model file not found",
                                 location=SourceLocation(text),
                                 hint="check the path, or name a preset: "
                                 + ", ".join(preset_names()))
        path = resolve_preset(text)
    return parse_user_model(_read(path), str(path), base=base)


# ----------------------------------------------------------------------------- writing


def _clean(value: Any) -> Any:
    """TOML has no None; drop them, and turn tuples into lists."""
    if isinstance(value, Mapping):
        return {k: _clean(v) for k, v in value.items() if v is not None}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, float) and math.isinf(value):
        return value
    return value


def _activity_table(model: ActivityModel) -> dict[str, Any]:
    out: dict[str, Any] = {"duration": model.duration.to_params()}
    if model.omission is not None:
        out["omission"] = {"probability": model.omission.probability,
                           "reason": model.omission.reason, "source": model.omission.source}
    if model.prompt != (model.omission is not None):
        out["prompt"] = model.prompt
    if model.commission is not None:
        c = model.commission
        out["commission"] = {"probability": c.probability, "recovery": c.recovery.to_params(),
                             "alternatives": list(c.alternatives),
                             "max_per_instance": c.max_per_instance, "source": c.source}
    if model.repetition is not None:
        out["repetition"] = {"probability": model.repetition.probability,
                             "source": model.repetition.source}
    if model.delay is not None:
        out["delay"] = {"probability": model.delay.probability,
                        "duration": model.delay.duration.to_params(),
                        "source": model.delay.source}
    if model.intended is not None:
        out["intended"] = model.intended
    if model.probabilities:
        out["probabilities"] = dict(model.probabilities)
    out["source"] = model.source
    return out


def user_model_to_toml(model: UserModel) -> dict[str, Any]:
    """The TOML document of ``model`` (modifiers already applied to its distributions)."""
    doc: dict[str, Any] = {"format": FORMAT, "version": FORMAT_VERSION, "name": model.name}
    if model.description:
        doc["description"] = model.description
    if model.source:
        doc["source"] = model.source
    if model.default is not None:
        doc["defaults"] = _activity_table(model.default)
    if model.busy is not None:
        b = model.busy
        doc["busy"] = {"engaged": sorted(b.engaged),
                       "ignore": sorted(b.ignore) if b.ignore is not None else None,
                       "release_after": sorted(b.release_after) or None, "source": b.source}
    if not model.routine.is_trivial:
        r = model.routine
        doc["routine"] = {"windows": [
            {"name": w.name, "start": w.start, "end": w.end, "notice_factor": w.notice_factor,
             "duration_factor": w.duration_factor, "defer": w.defer,
             "probability": w.probability, "source": w.source} for w in r.windows]}
        if not r.drift.is_identity:
            d = r.drift
            doc["routine"]["drift"] = {
                "notice_factor_per_day": d.notice_factor_per_day,
                "min_notice_factor": d.min_notice_factor,
                "duration_factor_per_day": d.duration_factor_per_day,
                "min_duration_factor": d.min_duration_factor, "source": d.source}
    doc["activities"] = {k: _activity_table(v) for k, v in model.activities.items()}
    cleaned: dict[str, Any] = _clean(doc)
    return cleaned


def _scalar(value: Any) -> str:
    """One TOML value; mappings become inline tables (distributions read best that way)."""
    if isinstance(value, Mapping):
        inner = ", ".join(f"{_key(k)} = {_scalar(v)}" for k, v in value.items())
        return "{ " + inner + " }" if inner else "{}"
    if isinstance(value, list):
        return "[" + ", ".join(_scalar(v) for v in value) + "]"
    return tomli_w.dumps({"v": value})[4:].strip()


def _key(key: str) -> str:
    return tomli_w.dumps({key: 0}).rsplit("=", 1)[0].strip()


def _section(header: str, table: Mapping[str, Any], comments: Mapping[str, str]) -> list[str]:
    lines = [f"# {line}" for line in comments.get(header, "").splitlines()]
    lines.append(f"[{header}]")
    lines.extend(f"{_key(k)} = {_scalar(v)}" for k, v in table.items())
    return [*lines, ""]


def emit_toml(doc: Mapping[str, Any], comments: Mapping[str, str] | None = None,
              header: str = "") -> str:
    """Write a user-model document as readable TOML: top-level keys, then ``[busy]``,
    ``[defaults]``, ``[routine]`` (windows as ``[[routine.windows]]``), then one
    ``[activities.<id>]`` table per activity with distributions as inline tables.
    ``comments`` maps a section header (``activities.walk``) to a comment written above it."""
    notes = dict(comments or {})
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    for key, value in doc.items():
        if not isinstance(value, Mapping):
            lines.append(f"{_key(key)} = {_scalar(value)}")
    lines.append("")
    for key, value in doc.items():
        if not isinstance(value, Mapping) or key == "activities":
            continue
        if key == "routine":
            windows = value.get("windows", [])
            rest = {k: v for k, v in value.items() if k not in ("windows", "drift")}
            if rest:
                lines += _section("routine", rest, notes)
            for window in windows:
                lines += ["[[routine.windows]]",
                          *(f"{_key(k)} = {_scalar(v)}" for k, v in window.items()), ""]
            if "drift" in value:
                lines += _section("routine.drift", value["drift"], notes)
            continue
        lines += _section(_key(key), value, notes)
    for activity_id, table in doc.get("activities", {}).items():
        lines += _section(f"activities.{_key(activity_id)}", table, notes)
    return "\n".join(lines).rstrip() + "\n"


def dump_user_model(model: UserModel, *, comments: Mapping[str, str] | None = None,
                    header: str = "") -> str:
    """``model`` as TOML text that :func:`load_user_model` reads back to an equal model."""
    return emit_toml(user_model_to_toml(model), comments, header)
