"""One module builds every run: a decided request in, one :class:`RunOutcome` out.

Every front door fills an :class:`opspec.request.RunRequest`; :func:`opspec.request.prepare`
decides it (the spec gate, the user, the seed, the length) and builds its runs here, so the
same spec, seed and user give the same run through every door. The public face is
:func:`opspec.run` (:func:`opspec.request.run`)::

    import opspec

    outcome = opspec.run("specs/medication_dispenser.xpdl", seed=1, days=7,
                         user_model="specs/medication_dispenser.users.toml")
    outcome.metrics["doses_taken"]          # {"kind": "count", "total": 28}
    outcome.trace                           # every event (kept by default)

What a run is made of, and the one rule for each (``docs/architecture.md``):

* **the spec** (:func:`load`): a path (XPDL or ``.wfs``), a ``Package`` or a
  ``CompiledPackage``, compiled (the gate that refuses what ``opspec validate`` refuses is
  :func:`opspec.request.prepare`'s); the specs its modes name (``<opspec:Mode Source="dock.xpdl">``) are
  loaded relative to the spec's file when a mode change first enters them;
* **the seed and the scope**: user ``u`` of a run seeded ``S`` draws from streams keyed
  ``(S, u)`` only: the engine's random scope is ``(u,)``, the user model's stream is
  ``user_stream(S, u)`` and the world's is ``named_stream(S, "world/NAME", (u,))``. A single
  run (``opspec run``, ``opspec.run``, the walkthrough) is user 0, so ``opspec run --seed S``
  draws the same numbers as user 0 of ``opspec evaluate --seed S``. A seed is a whole number
  from 0 to 2**63 - 1 (:func:`opspec.run_rules.check_seed`);
* **the run length** (:func:`opspec.run_rules.run_length`): ``days`` or ``until`` when given,
  else the spec's ``opspec:RunLength``, else one simulated day;
* **the user lane** (:class:`User`): a script, a stochastic user model, a person (the
  walkthrough) or nobody;
* **the world** the spec declares (``opspec:World``), **devices** bound to real or emulated
  hardware (an attached set from :func:`opspec.bindings.attach.attach_devices`), and the
  **monitors** it declares (``opspec:Monitor``), watched in every run.

:func:`build` assembles a :class:`Run` without starting it (the walkthrough steps it itself;
devices are installed on it); :meth:`Run.execute` runs it to its length and returns the
:class:`RunOutcome`.
"""

from __future__ import annotations

import operator
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from opspec.engine.compiled import CompiledPackage, compile_package
from opspec.engine.config import EngineConfig
from opspec.engine.simulation import RunResult, Simulation
from opspec.errors import ConfigurationError
from opspec.model import Package
from opspec.run_rules import DAY, MAX_SEED, check_seed, run_length

if TYPE_CHECKING:
    from opspec.engine.performers import Performer
    from opspec.engine.trace import TraceEvent, TraceListener
    from opspec.properties.language import MonitorResult, MonitorRun
    from opspec.properties.monitors import Monitor

__all__ = [
    "DAY",
    "MAX_SEED",
    "LoadedSpec",
    "Run",
    "RunOutcome",
    "User",
    "build",
    "check_seed",
    "gate",
    "load",
    "open_gated",
    "run_length",
    "run_problem",
]

# the rules of a run's numbers (the seed, the run length) are opspec.run_rules'; named here too
# because a run is made of them


# ---------------------------------------------------------------------------- the spec


@dataclass(frozen=True, eq=False)
class LoadedSpec:
    """A spec through the gate and ready to run many times: compiled once, its mode loader,
    its declared monitors and validate's warnings on it with it."""

    compiled: CompiledPackage
    mode_loader: Callable[[str], Package]
    monitors: tuple[Monitor, ...]
    #: validate's warnings on the spec's file (``path:line: warning: …``)
    warnings: tuple[Any, ...] = ()

    @property
    def package(self) -> Package:
        return self.compiled.package


#: packages through the gate (by identity, held so that an id is never reused): a spec
#: fixture's package simulated by every test of a module is checked once
_PASSED: dict[int, Any] = {}
_PASSED_MAX = 64


def _passed(package: Any) -> None:
    if len(_PASSED) >= _PASSED_MAX:
        _PASSED.pop(next(iter(_PASSED)))
    _PASSED[id(package)] = package


def gate(package: Package) -> None:
    """Refuse an in-memory package with the structural errors ``opspec validate`` reports
    (a :class:`~opspec.errors.SpecError` listing them with their places)."""
    if _PASSED.get(id(package)) is package:
        return
    from opspec.errors import Severity, SpecError
    from opspec.model.checks import check_package

    errors = [d for d in check_package(package) if d.severity is Severity.ERROR]
    if errors:
        raise SpecError.from_diagnostics(errors)
    _passed(package)


def open_gated(path: str | Path) -> tuple[Package, tuple[Any, ...]]:
    """The package in ``path`` and validate's warnings on it, refused with every error
    ``opspec validate`` reports. ``.wfs`` scripts (compiled from specs that passed) and
    paths that are not files open as :func:`opspec.xpdl.open_spec.open_spec` does (a file
    that cannot be read at all is a ConfigurationError: exit status 2)."""
    from opspec.files import not_a_file
    from opspec.xpdl.open_spec import open_spec, refuse_unreadable

    target = Path(path)
    if target.suffix == ".wfs" or not_a_file(target) is not None:
        try:
            package = open_spec(path)
        except ConfigurationError as error:
            raise _not_here(target, error) from None
        _passed(package)
        _not_too_deep(package)
        return package, ()
    from opspec.errors import Severity, SpecError
    from opspec.xpdl.validate import validate_spec

    valid, report = validate_spec(target)       # monitors and the world: checked as built
    refuse_unreadable(report.diagnostics)       # an unreadable file: exit status 2, not 1
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    if errors or valid is None:
        raise SpecError.from_diagnostics(errors or report.diagnostics)
    _passed(valid)
    _not_too_deep(valid)
    return valid, tuple(d for d in report.diagnostics if d.severity is Severity.WARNING)


def where_to_look(target: str | Path) -> str | None:
    """For a relative spec path that does not exist, the folder it was looked for in and
    where the bundled specs are (``opspec run specs/medication_dispenser.xpdl`` outside the
    clone); None for any other path."""
    target = Path(target)
    if target.is_absolute() or target.exists() or target.is_symlink():
        return None
    bundled = Path(__file__).resolve().parents[1] / "specs"
    return (f"a relative path starts in the current folder, {Path.cwd()}"
            + (f"; the bundled specs are in {bundled}" if bundled.is_dir() else ""))


def _not_here(target: Path, error: ConfigurationError) -> ConfigurationError:
    """``error`` (the spec cannot be opened) with :func:`where_to_look`'s hint: it was told
    to give "e.g. specs/medication_dispenser.xpdl", the very path it had given."""
    hint = where_to_look(target)
    if hint is None:
        return error
    return ConfigurationError(error.message, location=error.location, hint=hint)


def _not_too_deep(package: Package) -> None:
    """Blocks nested past :data:`~opspec.model.nesting.MAX_BLOCK_NESTING` are refused at
    their line before anything follows them recursively (the compiler, the soundness check)."""
    from opspec.model.nesting import nesting_problem

    deep = nesting_problem(package)
    if deep is not None:
        raise deep


def load(spec: str | Path | Package | CompiledPackage | LoadedSpec) -> LoadedSpec:
    """The spec through the gate and ready to run: no run is built from a spec ``opspec
    validate`` refuses, whoever asks. A path opens whatever its form (XPDL, BPMN, ``.wfs``:
    :func:`open_gated`, refused with validate's errors, ``path:line``); a package or a
    compiled package given in memory is refused with the errors of the same structural checks
    (:func:`gate`). The monitors it declares are read here (a located ConfigurationError
    when one is bad)."""
    if isinstance(spec, LoadedSpec):
        return spec
    from opspec.properties.monitors import declared_monitors
    from opspec.xpdl.open_spec import mode_loader_for

    warnings: tuple[Any, ...] = ()
    if isinstance(spec, (str, os.PathLike)):
        spec, warnings = open_gated(Path(spec))
    else:
        gate(spec.package if isinstance(spec, CompiledPackage) else spec)
    compiled = spec if isinstance(spec, CompiledPackage) else compile_package(spec)
    return LoadedSpec(compiled, mode_loader_for(compiled.package),
                      tuple(declared_monitors(compiled)), warnings)


# ---------------------------------------------------------------------------- the user lane


class _Script(Protocol):
    """A script (:class:`opspec.usermodels.scripts.Script`): makes a fresh scripted user."""

    def performer(self) -> Any: ...


@dataclass(frozen=True, eq=False)
class User:
    """Who performs the user lane: ``kind`` is ``"script"``, ``"model"``, ``"person"`` or
    ``"none"``; ``describe`` says so in words (``opspec run`` prints it)."""

    kind: str
    source: Any = None
    describe: str = "nobody"

    @classmethod
    def nobody(cls, describe: str = "nobody") -> User:
        return cls("none", None, describe)

    @classmethod
    def script(cls, script: _Script | Any, describe: str = "a script") -> User:
        """A scripted user: a :class:`~opspec.usermodels.scripts.Script` (a fresh performer per
        run) or a scripted performer made for one run (a walkthrough's replay)."""
        return cls("script", script, describe)

    @classmethod
    def model(cls, model: Any, describe: str | None = None) -> User:
        """A stochastic user: a :class:`~opspec.usermodels.UserModel`, a preset name or the
        path of a TOML file. User ``u`` of seed ``S`` draws from ``user_stream(S, u)``."""
        from opspec.usermodels import UserModel, load_user_model

        loaded = model if isinstance(model, UserModel) else load_user_model(model)
        return cls("model", loaded, describe or (
            "a user model" if isinstance(model, UserModel) else f"the user model {model}"))

    @classmethod
    def person(cls, performer: Performer, describe: str = "a person") -> User:
        """Someone performing the lane through ``performer`` (the walkthrough's lane)."""
        return cls("person", performer, describe)

    def make(self, user: int, seed: int) -> tuple[Performer | None, list[TraceListener]]:
        """The performer of user ``user`` in a run seeded ``seed``, and the trace listeners
        it needs (a scripted user listens to the trace to anchor its steps)."""
        if self.kind == "model":
            # user u's own model (a population draws their parameters from a stream of its
            # own), drawing from user_stream(seed, u)
            return self.source.performer_for(seed, user), []
        if self.kind == "script":
            performer = (self.source if hasattr(self.source, "offer")
                         else self.source.performer())
            return performer, [performer]
        if self.kind == "person":
            return self.source, []
        return None, []


# ---------------------------------------------------------------------------- the result


@dataclass(frozen=True, slots=True, eq=False)
class RunOutcome:
    """What one run produced.

    ``result`` is the engine's :class:`~opspec.engine.simulation.RunResult` (``trace`` when
    kept, ``metrics``, ``summary``); ``monitors`` what each monitor saw; ``samples`` every
    observation of each duration metric, and (``keep_times``) the simulated time of each
    observation (``sample_times``) and of each counted event (``count_times``); ``warnings``
    what the front hall found doubtful in the request (validate's warnings on the spec, the
    user model's against the spec's user lane: ``path:line: warning: …``), for the door to
    show; ``problem`` the run-time fault or deadlock that cut the run short, if any.
    """

    result: RunResult
    seed: int
    user: int
    horizon: float
    monitors: tuple[MonitorResult, ...] = ()
    samples: Mapping[str, Sequence[float]] = field(default_factory=dict)
    sample_times: Mapping[str, Sequence[float]] = field(default_factory=dict)
    count_times: Mapping[str, Sequence[float]] = field(default_factory=dict)
    warnings: tuple[Any, ...] = ()

    @property
    def problem(self) -> str | None:
        """The run-time fault or deadlock of this run (``fault: file:line: …``, the first one
        and how many more), or None: such a run's metrics are not the spec's
        (:func:`run_problem`)."""
        return run_problem(self.result.summary)

    @property
    def trace(self) -> tuple[TraceEvent, ...] | None:
        return self.result.trace

    @property
    def metrics(self) -> dict[str, dict[str, Any]]:
        return self.result.metrics

    @property
    def summary(self) -> dict[str, Any]:
        return self.result.summary

    @property
    def medians(self) -> dict[str, float]:
        """The median of each duration metric with observations."""
        from statistics import median

        return {name: median(values) for name, values in self.samples.items() if values}

    @property
    def problems(self) -> bool:
        """Whether the run found a problem: a deadlock, a fault or an aborted instance."""
        summary = self.result.summary
        return bool(summary.get("deadlocks") or summary.get("faults")
                    or summary.get("instances", {}).get("aborted", 0))

    def __repr__(self) -> str:
        return (f"<RunOutcome {self.summary.get('instances')} seed {self.seed} "
                f"user {self.user}>")


# ---------------------------------------------------------------------------- the run


class Run:
    """A run built by :func:`build` and not started yet: :attr:`sim` is its simulation
    (step it, or install devices on it), :meth:`execute` runs it to :attr:`horizon`."""

    def __init__(self, sim: Simulation, *, horizon: float, seed: int, user: int,
                 watches: Sequence[MonitorRun], performer: Performer | None,
                 warnings: tuple[Any, ...] = ()) -> None:
        self.sim = sim
        #: what the front hall found doubtful in the request (RunOutcome.warnings)
        self.warnings = warnings
        self.horizon = horizon
        self.seed = seed
        self.user = user
        self.watches = list(watches)
        #: the user lane's performer (None: nobody)
        self.performer = performer

    def execute(self) -> RunOutcome:
        """Run to the horizon and return what happened."""
        return self.outcome(self.sim.run(until=self.horizon))

    def outcome(self, result: RunResult | None = None) -> RunOutcome:
        """The outcome of the run as it ended (``result``: the simulation's, or its result
        so far): the monitors judge what is still pending at the end."""
        result = result if result is not None else self.sim.result()
        end = float(result.summary.get("time", self.horizon))
        for watch in self.watches:
            watch.finish(end)
        metrics = self.sim.metrics
        samples = {k: tuple(v) for k, v in metrics.samples.items()} if metrics else {}
        keep = metrics is not None and metrics.keep_times
        return RunOutcome(
            result, self.seed, self.user, self.horizon,
            tuple(w.result() for w in self.watches), samples,
            {k: tuple(v) for k, v in metrics.sample_times.items()} if keep and metrics else {},
            {k: tuple(v) for k, v in metrics.count_times.items()} if keep and metrics else {},
            self.warnings)


def _world(compiled: CompiledPackage, seed: int, user: int) -> dict[str, Performer]:
    """The simulated devices of the world the spec declares (``opspec:World``), if any."""
    from opspec.worlds import world_performers

    return dict(world_performers(compiled, seed=seed, user=user))


def _config(config: EngineConfig | Mapping[str, Any] | None) -> EngineConfig | None:
    if config is None or isinstance(config, EngineConfig):
        return config
    return EngineConfig.from_mapping(config)


def build(spec: str | Path | Package | CompiledPackage | LoadedSpec, *, seed: int = 0,
          user: User | None = None, user_index: int = 0, days: float | None = None,
          until: float | None = None, config: EngineConfig | Mapping[str, Any] | None = None,
          performers: Mapping[str, Performer] | None = None,
          listeners: Iterable[TraceListener] = (), params: Mapping[str, Any] | None = None,
          keep_trace: bool = False, keep_times: bool = False, devices: Any = None,
          monitors: Sequence[Monitor] | None = None,
          warnings: tuple[Any, ...] | None = None) -> Run:
    """Assemble run ``user_index`` of ``spec`` seeded ``seed`` (see the module docstring for
    the rules), not started.

    Performers: the world's, then the user lane's (``user``, default nobody), then the
    ``devices`` (attached devices: their performers are bound and they are installed on the
    simulation), then ``performers`` (by participant or lane; the last word). ``monitors``
    replaces the spec's declared monitors when given (pass them along with extra ones).
    ``listeners`` receive the trace after the user's and the monitors'. ``warnings`` (default:
    validate's on the spec) go to the outcome.
    """
    loaded = load(spec)
    compiled = loaded.compiled
    seed = check_seed(seed)
    user_index = operator.index(user_index)
    horizon = run_length(compiled, days=days, until=until)
    who = user if user is not None else User.nobody()
    performer, user_listeners = who.make(user_index, seed)
    bound: dict[str, Performer] = _world(compiled, seed, user_index)
    if performer is not None:
        from opspec.engine.lanes import user_lane

        bound.update(dict.fromkeys(user_lane(compiled).bind_names, performer))
    if devices is not None:
        bound.update(devices.performers)
    bound.update(performers or {})
    watches = [m.start(user_index) for m in (loaded.monitors if monitors is None
                                             else monitors)]
    sim = Simulation(compiled, _config(config), performers=bound, seed=seed,
                     scope=(user_index,), listeners=[*user_listeners, *watches, *listeners],
                     params=params, keep_trace=keep_trace, mode_loader=loaded.mode_loader)
    if keep_times and sim.metrics is not None:
        sim.metrics.keep_times = True
    if devices is not None:
        devices.install(sim)
    return Run(sim, horizon=horizon, seed=seed, user=user_index, watches=watches,
               performer=performer,
               warnings=loaded.warnings if warnings is None else tuple(warnings))


# ---------------------------------------------------------------------------- a run's problem


def run_problem(summary: Mapping[str, Any]) -> str | None:
    """The problem of a run whose summary lists run-time faults or deadlocks: the first one's
    located message (``fault: file:line: …``) and how many more, or None for a sound run.
    Such a run was cut short, so its metrics are not the spec's: ``opspec evaluate`` fails the
    replication, ``simulate()`` names it and judges no statistic over it."""
    for kind, key in (("fault", "faults"), ("deadlock", "deadlocks")):
        found: Sequence[Mapping[str, Any]] = summary.get(key) or []
        if found:
            more = len(found) - 1
            text = f"{kind}: {found[0].get('message')}"
            if more:
                text += f" (and {more} more {kind}{'s' if more > 1 else ''} in this run)"
            return text
    return None
