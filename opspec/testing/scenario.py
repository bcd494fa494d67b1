"""Scenario files (``*.scenario.toml``): spec tests for people who do not write Python.

::

    spec = "../medication_dispenser.xpdl"        # relative to this file (or the rootdir)

    [given]                                      # defaults for every scenario (optional)
    days = 1

    [[scenario]]
    name = "a user who reports 90 s after the first alarm takes the dose"
    given = { script = [["after trg_2 90s", "press_report"]], until = "09:00" }
    then = ["doses_taken == 1", "report_latency_s.mean == 90"]

``given`` keys: ``script`` (a list of ``[when, action]`` pairs, see
:mod:`opspec.testing.script`, or the path of a script file), ``user_model`` (a preset name or
a TOML path), ``users`` (independent simulated users, default 1), ``days`` or ``until``
(seconds or a duration such as ``"9h"`` / ``"09:00"``; with neither, the spec's
``opspec:RunLength``, else 1 day), ``seed`` (default: the
test's seed), ``engine`` (engine options, as in ``[engine]`` of a config file), ``params``
(package data overrides: each name a package data field of the spec), ``branches``
(``{ GATEWAY = { FLOW = P } }``: branch probabilities of undecided gateways, as
``--branch``). ``then`` lines are :mod:`opspec.testing.expectations`.

Every mistake is reported when the file is collected, as ``path:line: key: what (how to
fix)``, at the line the key or its table is written on (a name the spec lacks too: a
``params`` field, a ``branches`` gateway or flow, ``scenario[0].given.branches."Pill
taken?".Yess``); so is every failure of a scenario run (``path:line: scenario[N].then[M]:
…``, the file read for lines only then).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from opspec.errors import ConfigurationError, OpspecError, SourceLocation
from opspec.testing.expectations import Expectation, parse_expectation
from opspec.toml_lines import located
from opspec.usermodels.scripts import Script, load_script, parse_script

__all__ = ["Scenario", "ScenarioDocument", "load_scenarios", "run_scenario"]

_TOP = ("spec", "given", "scenario", "description")
_SCENARIO = ("name", "given", "then", "description")
_GIVEN = ("script", "user_model", "users", "days", "until", "seed", "engine", "params",
          "branches")
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
#: a quoted part of a key (``branches."Pill taken?"``), as :func:`_key_below` writes it
_QUOTED_PART = re.compile(r'(?<![^.])"((?:[^"\\]|\\.)*)"(?![^.])')


@dataclass(frozen=True, slots=True)
class Scenario:
    """One ``[[scenario]]`` ready to run (``where`` is ``path: scenario[N]``; ``file`` is the
    scenario file to read the lines of a failure from, ``key`` is ``scenario[N]``)."""

    name: str
    where: str
    spec_path: Path
    expectations: tuple[Expectation, ...]
    script: Script | None = None
    user_model: Any = None
    users: int = 1
    days: float | None = None
    until: float | None = None
    seed: int | None = None
    engine: Mapping[str, Any] = field(default_factory=dict)
    params: Mapping[str, Any] = field(default_factory=dict)
    #: branch probabilities of undecided gateways (:mod:`opspec.branch_choices`)
    branches: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    description: str = ""
    file: Path | None = None
    key: str = ""

    def line(self) -> int | None:
        """The line its ``[[scenario]]`` table starts on (read now), or None when unknown."""
        if self.file is None or not self.key:
            return None
        return located(str(self.file), self.key).line

    def place(self, key: str = "") -> str:
        """``path:line: scenario[N]`` followed by ``key`` (``.then[1]``): where that is written
        in the scenario file, which is read now (call it for a failure only); ``where`` and
        ``key`` when the file or the line is unknown."""
        if self.file is None or not self.key:
            return f"{self.where}{key}"
        at = located(str(self.file), self.key + key)
        return str(replace(at, path=self.where.removesuffix(f": {self.key}")))


@dataclass(frozen=True, slots=True)
class ScenarioDocument:
    path: Path
    spec_path: Path
    scenarios: tuple[Scenario, ...]


def _error(path: Path, key: str | None, message: str, hint: str = "") -> ConfigurationError:
    return ConfigurationError(message, location=SourceLocation(str(path), key=key), hint=hint)


def _find(path: Path, ref: str, rootdir: Path | None) -> Path | None:
    candidate = Path(ref)
    if candidate.is_absolute():
        return candidate if candidate.exists() else None
    here = path.parent if path.is_absolute() or rootdir is None else rootdir / path.parent
    for base in (here, rootdir):
        if base is not None and (base / candidate).exists():
            return (base / candidate).resolve()
    return None


def _unknown(path: Path, key: str, table: Mapping[str, Any], allowed: Sequence[str]) -> None:
    for name in table:
        if name not in allowed:
            where = f"{key}.{name}" if key else name
            raise _error(path, where, f"unknown key {name!r}",
                         "allowed keys: " + ", ".join(allowed))


def _given(path: Path, key: str, table: Any, rootdir: Path | None) -> dict[str, Any]:
    if not isinstance(table, Mapping):
        raise _error(path, key, "'given' is a table",
                     'write given = { script = [["after trg_2 90s", "press_report"]] }')
    _unknown(path, key, table, _GIVEN)
    out: dict[str, Any] = {}
    if "script" in table:
        value = table["script"]
        if isinstance(value, str):
            found = _find(path, value, rootdir)
            if found is None:
                raise _error(path, f"{key}.script", f"script file {value!r} not found",
                             "give a path relative to this file, or a list of [when, action]")
            out["script"] = load_script(found)
        else:
            out["script"] = _inline_script(path, f"{key}.script", value)
    if "user_model" in table:
        ref = table["user_model"]
        if not isinstance(ref, str):
            raise _error(path, f"{key}.user_model", "a user model is a preset name or a path")
        from opspec.usermodels import load_user_model

        found = _find(path, ref, rootdir) if ref.endswith(".toml") else None
        try:
            out["user_model"] = load_user_model(found or ref)
        except OpspecError as error:
            raise _error(path, f"{key}.user_model", str(error)) from None
    if "users" in table:
        value = table["users"]
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise _error(path, f"{key}.users", f"users must be a whole number >= 1, not "
                         f"{value!r}")
        out["users"] = value
    from opspec.run_rules import check_days, check_seed

    for name, rule in (("seed", check_seed), ("days", check_days), ("until", _until)):
        if name in table:
            if name == "seed" and not isinstance(table[name], int):   # not text: TOML ints
                raise _error(path, f"{key}.seed", f"a seed is a whole number, not "
                             f"{table[name]!r}")
            try:
                out[name] = rule(table[name])
            except ConfigurationError as error:
                raise _error(path, f"{key}.{name}", error.message, error.hint or "") from None
    for name in ("engine", "params"):
        if name in table:
            if not isinstance(table[name], Mapping):
                raise _error(path, f"{key}.{name}", f"{name} is a table")
            out[name] = dict(table[name])
    if "branches" in table:
        from opspec.branch_choices import BranchRefusal, read_branch_table

        try:
            out["branches"] = read_branch_table(table["branches"])
        except BranchRefusal as refusal:
            raise _refused(path, f"{key}.branches", refusal) from None
    if "engine" in out:
        from opspec.engine.config import EngineConfig

        try:
            EngineConfig.from_mapping(out["engine"], path=str(path))
        except ConfigurationError as error:
            at = error.location     # an option's key, placed at its line as the others
            option = f".{at.key}" if at is not None and at.path == str(path) and at.key else ""
            raise _error(path, f"{key}.engine{option}", error.message,
                         error.hint or "") from None
    return out


def _refused(path: Path, key: str, refusal: Any) -> ConfigurationError:
    """A :class:`~opspec.branch_choices.BranchRefusal` of the ``branches`` table at ``key``,
    in the file's words, at the key of the gateway or flow it is about."""
    return _error(path, _key_below(key, refusal.at), refusal.in_file, refusal.file_hint)


def _check_against_spec(path: Path, key: str, given: Mapping[str, Any], package: Any) -> None:
    """The names ``given`` (the ``given`` table at ``key``) gives values to, checked against
    the spec as a run given them checks them: a ``params`` name is a package data field (a
    run writes the value into the package's data, where nothing reads an undeclared name),
    a ``branches`` gateway is one the diagram leaves undecided, with these flows."""
    from opspec.branch_choices import BranchRefusal, check_branch_table
    from opspec.run_inputs import no_such_field

    declared = {f.id for f in package.data_fields}
    for name in given.get("params", {}):
        if name not in declared:
            error = no_such_field(str(name), package, "params")
            # the key is the place: the message without the API's "params: "
            raise _error(path, _key_below(f"{key}.params", (str(name),)),
                         error.message.removeprefix("params: "), error.hint)
    if given.get("branches"):
        try:
            check_branch_table(package, given["branches"])
        except BranchRefusal as refusal:
            raise _refused(path, f"{key}.branches", refusal) from None


def _key_below(key: str, names: Sequence[str]) -> str:
    """``key`` and the ``names`` below it as TOML writes them (``branches."Pill taken?".Yes``:
    quoted unless bare)."""
    return ".".join([key, *(n if _BARE_KEY.fullmatch(n) else _quoted(n) for n in names)])


def _quoted(name: str) -> str:
    return '"' + name.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _unquoted(key: str) -> str:
    """``key`` with its quoted parts as the file's keys are looked up (:func:`located`)."""
    return _QUOTED_PART.sub(lambda m: re.sub(r"\\(.)", r"\1", m.group(1)), key)


def _inline_script(path: Path, key: str, steps: Any) -> Script:
    """The script written in the scenario file at ``key`` (a list of ``[when, action]``),
    each step placed at its entry's key (``scenario[0].given.script[2]``) so that a mistake
    in it is reported at the line the entry is written on."""
    where = f"{path}: {key}"
    try:
        script = parse_script(steps, where=where)
    except ConfigurationError as error:
        entry = _entry_key(error.location, where, key)
        if entry is None:
            raise
        raise _error(path, entry, error.message, error.hint or "") from None
    places = []
    for place in script.places:
        entry = _entry_key(place, where, key)
        places.append(place if entry is None else SourceLocation(str(path), key=entry))
    return replace(script, places=tuple(places))


def _entry_key(at: SourceLocation | None, where: str, key: str) -> str | None:
    """The scenario file's key of ``at``, a place :func:`parse_script` gives in the script
    it read with ``where`` (``where: steps[N]``, entry N, or ``where``, the whole list):
    ``key[N]`` or ``key``; None for any other place."""
    if at is None or at.line is not None or at.key:
        return None
    if at.path == where:
        return key
    entry = re.fullmatch(r"steps\[(\d+)\]", at.path.removeprefix(f"{where}: "))
    return f"{key}[{entry.group(1)}]" if entry is not None else None


def _until(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ConfigurationError(f"until is seconds or a duration, not {value!r}")
    from opspec.run_rules import parse_until

    return parse_until(value)


def load_scenarios(path: str | Path, *, rootdir: Path | None = None) -> ScenarioDocument:
    """Read and check a scenario file, including its names against its spec.

    Raises :class:`ConfigurationError` (``path:line: key: ...``, at the line the key or its
    table is written on) or the spec's own error.
    """
    path = Path(path)
    if rootdir is not None and path.is_absolute() and path.is_relative_to(rootdir):
        path = path.relative_to(rootdir)     # messages name the file as the user wrote it
    full = path if path.is_absolute() or rootdir is None else rootdir / path
    try:
        return _load(path, full.absolute(), rootdir)
    except ConfigurationError as error:
        raise _at_its_line(error, path, full) from None


def _at_its_line(error: ConfigurationError, path: Path, full: Path) -> ConfigurationError:
    """``error`` about a key of the scenario file placed at the line the key is written on
    (the checks name keys; the file is read for their lines only when one is refused)."""
    at = error.location
    if (type(error) is not ConfigurationError or at is None or at.line is not None
            or at.path != str(path) or not at.key):
        return error
    line = located(str(full), _unquoted(at.key)).line
    if line is None:
        return error
    return ConfigurationError(error.message, location=replace(at, line=line), hint=error.hint)


def _load(path: Path, full: Path, rootdir: Path | None) -> ScenarioDocument:
    from opspec.toml_files import read_toml

    document = read_toml(full, what="the scenario file", location=SourceLocation(str(path)))
    _unknown(path, "", document, _TOP)
    ref = document.get("spec")
    if not isinstance(ref, str):
        raise _error(path, "spec", "the file needs spec = \"path/to/spec.xpdl\"",
                     "a path relative to this file or the rootdir")
    spec_path = _find(path, ref, rootdir)
    if spec_path is None:
        raise _error(path, "spec", f"spec {ref!r} not found",
                     "a path relative to this file or the rootdir")
    from opspec.engine.compiled import compile_package
    from opspec.request import open_gated, scripted_user
    from opspec.testing.simulation import spec_names

    try:
        package = open_gated(spec_path)[0]
        compiled = compile_package(package)
        names = spec_names(compiled)
    except OpspecError as error:
        raise _error(path, "spec", f"the spec does not load: {error}") from None
    defaults = _given(path, "given", document.get("given", {}), rootdir)
    _check_against_spec(path, "given", defaults, package)
    entries = document.get("scenario")
    if not isinstance(entries, list) or not entries:
        raise _error(path, "scenario", "no [[scenario]] tables",
                     'add [[scenario]] with name, given and then = ["doses_taken == 1"]')
    scenarios: list[Scenario] = []
    seen: set[str] = set()
    for n, entry in enumerate(entries):
        key = f"scenario[{n}]"
        if not isinstance(entry, Mapping):
            raise _error(path, key, "each scenario is a table")
        _unknown(path, key, entry, _SCENARIO)
        name = entry.get("name")
        if not isinstance(name, str) or not name.strip():
            raise _error(path, f"{key}.name", "each scenario needs a name")
        if name in seen:
            raise _error(path, f"{key}.name", f"scenario name {name!r} is used twice")
        seen.add(name)
        own = _given(path, f"{key}.given", entry.get("given", {}), rootdir)
        _check_against_spec(path, f"{key}.given", own, package)
        inherited = {k: v for k, v in defaults.items()
                     if not ({k, *own} >= {"days", "until"})}   # own days/until win
        given = {**inherited, **own}
        #: where the script is given: this scenario's given, else the file's
        script_key = f"{key}.given.script" if "script" in own else "given.script"
        if "days" in given and "until" in given:
            raise _error(path, f"{key}.given", "give days or until, not both")
        then = entry.get("then")
        if isinstance(then, str):
            then = [then]
        if not isinstance(then, list) or not then:
            raise _error(path, f"{key}.then", "'then' lists what must hold",
                         'write then = ["doses_taken == 1"]')
        expectations = []
        for m, text in enumerate(then):
            where = f"{path}: {key}.then[{m}]"
            expectation = parse_expectation(text, where=where)
            expectation.check_names(names, where)
            expectations.append(expectation)
        script = given.get("script")
        if isinstance(script, Script):
            try:     # the names it uses, and that each step acts on an offer of the user's
                scripted_user(script, compiled)
            except ConfigurationError as error:
                at = error.location
                if at is not None and at.line is not None and at.path != str(path):
                    # a script file's step: at its own line, where it must be fixed, the
                    # file named as the scenario file is (relative to the rootdir)
                    script_file = Path(at.path)
                    if rootdir is not None and script_file.is_relative_to(rootdir):
                        at = replace(at, path=str(script_file.relative_to(rootdir)))
                    given_at = replace(located(str(full), script_key), path=str(path))
                    raise ConfigurationError(
                        f"{error.message} (scenario {name.strip()!r}, {given_at})",
                        location=at, hint=error.hint) from None
                if at is not None and at.path == str(path) and at.key:
                    # a step written in this file: at its entry's line (_at_its_line)
                    raise ConfigurationError(error.message, location=at,
                                             hint=error.hint) from None
                raise _error(path, script_key, error.message, error.hint) from None
        if script is not None and "user_model" in given:
            raise _error(path, f"{key}.given", "give a script or a user model, not both")
        scenarios.append(Scenario(
            name=name.strip(), where=f"{path}: {key}", spec_path=spec_path,
            expectations=tuple(expectations), script=script,
            user_model=given.get("user_model"), users=given.get("users", 1),
            days=given.get("days"), until=given.get("until"), seed=given.get("seed"),
            engine=given.get("engine", {}), params=given.get("params", {}),
            branches=given.get("branches", {}),
            description=str(entry.get("description", "")), file=full, key=key))
    return ScenarioDocument(path, spec_path, tuple(scenarios))


def run_scenario(scenario: Scenario, spec: Any, *, seed: int = 0,
                 seen: Callable[[Any], None] | None = None,
                 noted: Callable[[str], None] | None = None) -> list[str]:
    """Run ``scenario`` on ``spec`` (a Package, CompiledPackage or LoadedSpec); return one
    failure message per expectation that does not hold (empty when all do), each at the
    line the expectation is written on (``path:line: scenario[N].then[M]: …``). ``seen`` gets
    the simulation's result (its warnings, its failed replications); ``noted`` gets, at the
    same kind of place, what a reader must know of an expectation that held (a mean over
    replications all alike: :meth:`Expectation.caveat`). A replication a fault cut short
    fails the scenario, naming the fault's file:line."""
    from opspec.testing.simulation import simulate

    needs_trace = any(e.property is not None for e in scenario.expectations)   # trace lines
    result = simulate(spec, users=scenario.users, days=scenario.days, until=scenario.until,
                      script=scenario.script, user_model=scenario.user_model,
                      seed=scenario.seed if scenario.seed is not None else seed,
                      engine_config=scenario.engine or None, params=scenario.params or None,
                      branches=scenario.branches or None,
                      keep_trace=True if needs_trace else None)
    if seen is not None:
        seen(result)
    if result.failed:       # runs cut short by a fault: no line of them is the spec's
        from opspec.testing.simulation import failed_text

        return [f"{scenario.place()}: {failed_text(result.failed, result.replications)}",
                f"(seed {result.seed}; {result.replications} replication(s))"]
    failures = []
    for number, expectation in enumerate(scenario.expectations):
        message = expectation.check(result)
        if message is not None:
            failures.append(f"{scenario.place(f'.then[{number}]')}: {message}")
        elif noted is not None:
            caveat = expectation.caveat(result)
            if caveat is not None:
                noted(f"{scenario.place(f'.then[{number}]')}: {caveat} "
                      f"(seed {result.seed})")
    if failures:
        failures.append(f"(seed {result.seed}; {result.replications} replication(s))")
    return failures
