"""The front hall: every door fills one :class:`RunRequest`, and :func:`prepare` decides it.

``opspec run``, ``opspec evaluate`` (and its workers), ``opspec walkthrough``,
``opspec check --schedulability``, :func:`opspec.run`, :func:`opspec.testing.simulate` (so the
pytest fixture and scenario files) only say what they were asked; :func:`prepare` applies the
one rule for each part of a run and hands the result to :func:`opspec.runs.build`:

* **the spec gate** — a path opens whatever its form (XPDL, BPMN 2.0, a compiled ``.wfs``)
  and is refused with every error ``opspec validate`` reports (``path:line``); a package given
  in memory is refused with the errors of the same structural checks. Its warnings come back
  in :attr:`PreparedRun.warnings` for the door to show;
* **the seed and the run length** — :mod:`opspec.run_rules`;
* **the world** the spec declares — built once (:func:`opspec.worlds.check_world`), so a
  world file that cannot be read or a parameter its world refuses is refused before any run;
* **the user lane** — ``script`` (a path, a :class:`~opspec.usermodels.scripts.Script` or its
  steps; every name it uses must be the spec's, and every activity it acts on one the user
  lane is offered), ``user_model`` (a preset, a TOML path or a
  :class:`~opspec.usermodels.UserModel`, checked against the spec's user lane), ``user`` (a
  prepared :class:`~opspec.runs.User`: a person, a replay) or ``no_user``; with none of them,
  the spec's companion ``SPEC.users.toml`` when its file has one, else nobody
  (:func:`side_files` names the files a run picks up beside the spec; ``opspec validate``
  checks them with :func:`user_model_warnings`, as a run does).

A :class:`PreparedRun` builds user ``u`` of the run as often as a door needs
(:meth:`PreparedRun.build`), so a door running many users prepares once.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from opspec.errors import ConfigurationError
from opspec.run_rules import check_seed, run_length

if TYPE_CHECKING:
    from opspec.engine.config import EngineConfig
    from opspec.engine.performers import Performer
    from opspec.engine.trace import TraceListener
    from opspec.model import Package
    from opspec.runs import LoadedSpec, Run, RunOutcome, User

__all__ = ["PreparedRun", "RunRequest", "companion_user_model", "gate", "open_gated",
           "prepare", "run", "scripted_user", "side_files", "user_model_warnings"]

_EMPTY: Mapping[str, Any] = MappingProxyType({})


def __getattr__(name: str) -> Any:
    # the spec gate lives with the spec loader (opspec.runs.load), so no load skips it;
    # named here too, loaded on first use (importing the front hall stays light)
    if name in ("gate", "open_gated"):
        import opspec.runs

        return getattr(opspec.runs, name)
    raise AttributeError(f"module 'opspec.request' has no attribute {name!r}")
#: the parts of a request that prepare() decides from (the rest goes to runs.build as it is)
_DECIDED = frozenset({"spec", "seed", "days", "until", "script", "user_model", "user",
                      "no_user", "default_metrics"})


@dataclass(frozen=True, eq=False)
class RunRequest:
    """What a door was asked for, as it was asked (nothing decided yet).

    ``spec`` is a path (XPDL, BPMN or ``.wfs``), a ``Package``, a ``CompiledPackage`` or a
    :class:`~opspec.runs.LoadedSpec` (already through the gate). ``days`` or ``until``
    (seconds, or a duration as text: ``PT8H``) give the length. At most one of ``script``,
    ``user_model``, ``user`` and ``no_user`` says who performs the user lane. The rest goes to
    :func:`opspec.runs.build` as it is.
    """

    spec: Any
    seed: Any = 0
    days: Any = None
    until: Any = None
    script: Any = None
    user_model: Any = None
    user: User | None = None
    no_user: bool = False
    config: EngineConfig | Mapping[str, Any] | None = None
    performers: Mapping[str, Performer] = field(default_factory=dict)
    listeners: tuple[TraceListener, ...] = ()
    params: Mapping[str, Any] | None = None
    #: branch probabilities given at run time (gateway -> flow -> probability,
    #: :mod:`opspec.branch_choices`), applied to the spec before it is compiled
    branches: Mapping[str, Mapping[str, float]] | None = None
    keep_trace: bool = False
    keep_times: bool = False
    #: when the spec declares no metrics, measure each process's completed instances and
    #: cycle time (:mod:`opspec.model.default_metrics`; ``opspec evaluate`` asks for it)
    default_metrics: bool = False
    monitors: tuple[Any, ...] | None = None
    devices: Any = None

    def __post_init__(self) -> None:
        # immutable all the way down: a door cannot change a request after handing it in
        object.__setattr__(self, "performers", MappingProxyType(dict(self.performers or {})))
        object.__setattr__(self, "listeners", tuple(self.listeners))
        if self.params is not None:
            object.__setattr__(self, "params", MappingProxyType(dict(self.params)))
        if self.monitors is not None:
            object.__setattr__(self, "monitors", tuple(self.monitors))

    def but(self, **changes: Any) -> RunRequest:
        """The same request with ``changes`` (a door adding its listeners)."""
        return replace(self, **changes)


@dataclass(frozen=True, eq=False)
class PreparedRun:
    """A request decided: the spec through the gate and compiled, the seed, the run length
    in seconds, who performs the user lane, and the warnings a door shows."""

    request: RunRequest
    spec: LoadedSpec
    seed: int
    horizon: float
    user: User
    #: validate's warnings on the spec (``path:line: warning: …``) and the user model's
    #: against the spec's user lane, in that order
    warnings: tuple[Any, ...] = ()
    #: the file the spec came from, when it came from one
    path: Path | None = field(default=None)
    #: the reference (a preset name or a TOML path) of the user model performing the lane,
    #: when it was named so (an evaluation stores it to resume and sends it to its workers)
    user_model: str | None = None

    @property
    def compiled(self) -> Any:
        return self.spec.compiled

    def but(self, **changes: Any) -> PreparedRun:
        """The same decided run with the request's ``changes`` that decide nothing (a door's
        listeners, its devices, the engine configuration a bound device's clock sets)."""
        decided = sorted(set(changes) & _DECIDED)
        if decided:
            raise ConfigurationError(f"prepare() decided {', '.join(decided)} already",
                                     hint="fill a new RunRequest and prepare it")
        return replace(self, request=self.request.but(**changes))

    @property
    def package(self) -> Package:
        return self.spec.package

    def build(self, user_index: int = 0, *, user: User | None = None,
              listeners: Iterable[TraceListener] = (), devices: Any = None) -> Run:
        """Run ``user_index`` of this request, built by :func:`opspec.runs.build` and not
        started; ``user`` replaces the prepared one (a population's drawn person),
        ``listeners`` and ``devices`` are added to the request's."""
        from opspec.runs import build

        request = self.request
        return build(self.spec, seed=self.seed, user=user or self.user, user_index=user_index,
                     until=self.horizon, config=request.config,
                     performers=request.performers,
                     listeners=[*request.listeners, *listeners], params=request.params,
                     keep_trace=request.keep_trace, keep_times=request.keep_times,
                     devices=devices if devices is not None else request.devices,
                     monitors=request.monitors, warnings=self.warnings)

    def execute(self, user_index: int = 0) -> RunOutcome:
        """Build run ``user_index`` and run it to its length."""
        return self.build(user_index).execute()


# ---------------------------------------------------------------------------- the spec


def companion_user_model(spec_path: str | Path | None) -> Path | None:
    """``SPEC.users.toml`` next to the spec's file, if there is one."""
    if spec_path is None:
        return None
    path = Path(spec_path)
    candidate = path.with_name(path.name.removesuffix(path.suffix) + ".users.toml")
    return candidate if candidate.is_file() else None


def side_files(spec_path: str | Path | None) -> dict[str, Path]:
    """The files beside the spec's file that a run of it picks up by their name, by what they
    are (``"user model"``: :func:`companion_user_model`); absent ones are left out.
    ``opspec validate SPEC`` checks each as a run would."""
    found = {"user model": companion_user_model(spec_path)}
    return {what: path for what, path in found.items() if path is not None}


def _spec(spec: Any) -> tuple[LoadedSpec, tuple[Any, ...], Path | None]:
    """The spec through the gate (:func:`opspec.runs.load`), validate's warnings on it and
    its file."""
    from opspec.runs import LoadedSpec, load

    if isinstance(spec, LoadedSpec):
        return spec, spec.warnings, _source(spec.package)
    loaded = load(spec)
    path = Path(spec) if isinstance(spec, (str, os.PathLike)) else _source(loaded.package)
    return loaded, loaded.warnings, path


def _with_branches(loaded: LoadedSpec, branches: Any) -> LoadedSpec:
    """``loaded`` recompiled with the run-time branch probabilities (before compile, so the
    run, its workers and its seed see one spec)."""
    from opspec.branch_choices import (
        BranchRefusal,
        CommandLineBranches,
        gateway_lines,
        with_branches,
    )
    from opspec.runs import load

    try:
        changed = load(with_branches(loaded.package, branches))
    except BranchRefusal as refusal:
        if isinstance(branches, CommandLineBranches):
            raise
        raise refusal.in_api_words() from None
    # the file's warning about the shares it would draw no longer holds for these gateways
    lines = gateway_lines(loaded.package, branches)
    kept = tuple(w for w in loaded.warnings if getattr(w, "code", None) != "undecided-gateway"
                 or getattr(getattr(w, "location", None), "line", None) not in lines)
    return replace(changed, warnings=kept)


def _with_default_metrics(loaded: LoadedSpec) -> LoadedSpec:
    """``loaded`` recompiled with opspec's default metrics (the spec declares none)."""
    from opspec.model.default_metrics import default_metrics
    from opspec.runs import load

    package = replace(loaded.package, metrics=default_metrics(loaded.package))
    return replace(load(package), warnings=loaded.warnings)


def _source(package: Any) -> Path | None:
    source = getattr(package, "source", None)
    return Path(source) if source else None


# ---------------------------------------------------------------------------- the user


def _user(request: RunRequest, loaded: LoadedSpec, path: Path | None
          ) -> tuple[User, tuple[Any, ...], str | None]:
    """Who performs the user lane, the user model's warnings against the spec, and the
    model's reference when it was named by one."""
    from opspec.engine.lanes import user_lane
    from opspec.runs import User

    given = [name for name, value in (
        ("script", request.script), ("user_model", request.user_model),
        ("user", request.user), ("no_user", request.no_user or None)) if value is not None]
    if len(given) > 1:
        raise ConfigurationError(f"give {given[0]} or {given[1]}, not both" if len(given) == 2
                                 else f"give one of {', '.join(given)}, not all of them",
                                 hint="a script plays exact actions; a model draws them")
    if request.user is not None:
        return request.user, (), None
    lane = user_lane(loaded.compiled)
    if request.script is not None:
        return scripted_user(request.script, loaded.compiled), (), None
    ref = request.user_model
    if ref is None and not request.no_user:
        ref = side_files(path).get("user model")
    if ref is None:
        why = ("--no-user" if request.no_user
               else "no --script or --user-model, and no companion .users.toml")
        return User.nobody(f"nobody ({why}): user-lane activities wait" if not lane.empty
                           else "nobody (no user lane)"), (), None
    user = User.model(ref)
    named = str(ref) if isinstance(ref, (str, os.PathLike)) else None
    return user, user_model_warnings(user.source, loaded.compiled), named


def user_model_warnings(model: Any, compiled: Any) -> tuple[Any, ...]:
    """The warnings of the user model ``model`` (a loaded
    :class:`~opspec.usermodels.UserModel`) against the user lane of the spec ``compiled``;
    refused (a :class:`~opspec.errors.UserModelError` at the file and key) when it does not
    cover the lane. Every door checks a user model so, and ``opspec validate`` the spec's
    companion."""
    from opspec.engine.lanes import user_lane

    lane = user_lane(compiled)
    if lane.empty:
        return ()
    return tuple(model.validate_against(lane.manual, choices=lane.choices))


def scripted_user(script: Any, compiled: Any) -> User:
    """A scripted user (a script file's path, a Script or its steps), every activity and
    trigger it names checked against the spec ``compiled`` (a misspelt name would never
    match an offer), and every activity a step acts on checked to be one the user lane is
    offered: ``opspec run --script``, the walkthrough's ``--replay``, ``simulate``."""
    from opspec.engine.names import spec_names
    from opspec.runs import User
    from opspec.usermodels.scripts import Script, load_script, parse_script

    if isinstance(script, (str, os.PathLike)):
        plan, describe = load_script(Path(script)), f"the script {script}"
    elif isinstance(script, Script):
        plan, describe = script, "a script"
    else:
        plan, describe = parse_script(script), "a script"
    names = spec_names(compiled)
    plan.check_names(names.activities, names.triggers)
    _check_offered(plan, compiled)
    return User.script(plan, describe)


def _check_offered(plan: Any, compiled: Any) -> None:
    """Refuse a step acting on an activity the spec's user lane is never offered (a device's
    ``dispense``): the scripted user plays that lane only, so the step would never be used
    and the run would go on as if it were not written."""
    from opspec.engine.lanes import all_activities, user_lane, user_offers

    offered = user_offers(compiled)
    lane = user_lane(compiled)
    for index, step in enumerate(plan.steps):
        alternatives = lane.choices.get(step.target)
        if step.verb in ("complete", "choose") and alternatives and step.target not in lane.manual:
            # completing the choice itself names no branch: the engine refused it mid-run
            raise ConfigurationError(
                f"the script's step '{step.verb} {step.target}' names the choice "
                f"{step.target!r}, not one of its alternatives",
                location=plan.place(index),
                hint=f"write e.g. (5, 'choose {alternatives[0]}'); its alternatives: "
                     + ", ".join(alternatives))
        if step.verb == "raise" or step.target in offered:
            continue
        act = next(a for a in all_activities(compiled) if a.id == step.target)
        who = (f"lane {act.lane!r}" if act.lane else f"participant {act.participant!r}"
               if act.participant else "the device")
        yours = ", ".join(sorted(offered)) or "(none: the spec has no user lane)"
        raise ConfigurationError(
            f"the script's step '{step.verb} {step.target}' names activity {step.target!r}, "
            f"which is never offered to the user ({who} performs it in process "
            f"{act.process!r}), so the step would never be used",
            location=plan.place(index),
            hint=f"a script plays the user lane, whose activities are: {yours}; to act "
                 f"after {step.target}, time a step from it: "
                 f"('after {step.target} 10s', 'ACTIVITY')")


# ---------------------------------------------------------------------------- prepare


def prepare(request: RunRequest) -> PreparedRun:
    """Decide ``request`` (see the module docstring): every bad input is refused here,
    before anything runs, with the same message through every door."""
    seed = check_seed(request.seed)
    loaded, spec_warnings, path = _spec(request.spec)
    if request.branches:
        loaded = _with_branches(loaded, request.branches)
        spec_warnings = loaded.warnings
    if request.default_metrics and not loaded.package.metrics:
        loaded = _with_default_metrics(loaded)
    horizon = run_length(loaded.compiled, days=request.days, until=request.until)
    _check_world(loaded.compiled, seed)
    if request.params:
        _check_params(request.params, loaded.package)
    user, user_warnings, named = _user(request, loaded, path)
    return PreparedRun(request, loaded, seed, horizon, user,
                       (*spec_warnings, *user_warnings), path, named)


def _check_world(compiled: Any, seed: int) -> None:
    """The world the spec declares is built once here: a world file that cannot be read, or
    a parameter its world refuses, is refused by every door before any run (``opspec run``
    did so as it built its one run; an evaluation ran every replication into it)."""
    from opspec.worlds import check_world

    check_world(compiled, seed=seed)


def _check_params(params: Mapping[str, Any], package: Any) -> None:
    """Every name of the API's ``params`` is a package data field, as ``--param`` checks: the
    run writes the value into the package's data, where nothing reads an undeclared name
    (and a process's own field of that name hides it), so a misspelt one would change
    nothing and say nothing."""
    from opspec.run_inputs import no_such_field

    declared = {f.id for f in package.data_fields}
    for name in params:
        if name not in declared:
            raise no_such_field(str(name), package, "params")


def run(spec: Any, *, seed: Any = 0, days: Any = None, until: Any = None,
        user_model: Any = None, script: Any = None, user: User | None = None,
        no_user: bool = False, user_index: int = 0,
        config: EngineConfig | Mapping[str, Any] | None = None,
        performers: Mapping[str, Performer] | None = None,
        listeners: Sequence[TraceListener] = (), params: Mapping[str, Any] | None = None,
        branches: Mapping[str, Mapping[str, float]] | None = None,
        keep_trace: bool = True) -> RunOutcome:
    """Run ``spec`` once, as ``opspec run`` does, and return its
    :class:`~opspec.runs.RunOutcome` (``opspec.run``): the request's rules are those of the
    module docstring; ``opspec.run(spec, seed=S)`` is user 0 of
    ``opspec evaluate spec --seed S``."""
    request = RunRequest(spec, seed=seed, days=days, until=until, script=script,
                         user_model=user_model, user=user, no_user=no_user, config=config,
                         performers=performers or _EMPTY, listeners=tuple(listeners),
                         params=params, branches=branches, keep_trace=keep_trace)
    return prepare(request).execute(user_index)
