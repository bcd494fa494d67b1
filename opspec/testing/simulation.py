"""Run a spec for a test: one or many simulated users, a script or a user model, one result.

::

    result = simulate(spec, users=200, days=1, user_model="dispenser-reference", seed=7)
    result.metrics["doses_taken"]          # pooled over the 200 users: {"kind": "count", ...}
    result.samples("doses_taken")          # one value per user (replication)
    result.value("report_latency_s.p95")   # a pooled scalar
    result.instances("notify_workflow")    # per-instance slices of the trace

Replication ``u`` (one simulated user and their device, a household) is run ``u`` built by
:func:`opspec.runs.build`, as every run is: the engine's random scope ``(u,)`` and, for a user
model, the user stream ``default_rng(SeedSequence(seed, spawn_key=(u,)))``. User ``u`` behaves
the same whatever the number of users, so adding users never changes the first ones, and user
0 is the run of ``opspec run --seed`` with the same seed.

``simulate`` only fills an :class:`opspec.request.RunRequest`: the spec gate, the user, the
seed and the run length follow the rules of every other door (``opspec run``, ``opspec.run``).
Who performs the user lane: the ``user_model`` (a :class:`~opspec.usermodels.UserModel`, a
preset name or a TOML path), or the ``script`` (see :mod:`opspec.usermodels.scripts`; ``[]`` is
the cooperative user: every offer completed at once, a choice takes its first alternative),
or nobody (``no_user=True``); with none of them, the spec's companion ``SPEC.users.toml`` when
its file has one, else nobody, as ``opspec run`` does. ``performers`` binds anything else
(devices, callables) by participant or lane.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.engine.compiled import CompiledPackage
from opspec.engine.config import EngineConfig
from opspec.engine.metrics import summarise_durations
from opspec.engine.names import SpecNames, spec_names
from opspec.engine.performers import Performer
from opspec.engine.simulation import RunResult
from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import ConfigurationError
from opspec.model import Package

if TYPE_CHECKING:
    from opspec.usermodels.scripts import Script

__all__ = [
    "FIELDS",
    "FailedReplication",
    "FailedReplications",
    "InstanceRun",
    "SimulationResult",
    "SpecNames",
    "derive_seed",
    "load_spec_file",
    "not_a_result",
    "require_result",
    "simulate",
    "spec_names",
]

#: fields of each metric kind, the first being the one a bare metric name means
FIELDS = {"count": ("total",), "duration": ("mean", "n", "p95", "min", "max"),
          "ratio": ("value",)}


def derive_seed(base: int, text: str) -> int:
    """A seed mixing ``base`` with ``text`` (a test id): independent per test, reproducible,
    stable across processes and Python versions (CRC-32, not ``hash``)."""
    return (int(base) * 1_000_003 + zlib.crc32(text.encode("utf-8"))) % 2**63


def not_a_result(obj: Any, who: str,
                 takes: str = "a SimulationResult (what simulate() returns)") -> TypeError:
    """The error of ``who`` (``expect``, ``check``...) given something it cannot judge: the
    spec, or the ``simulate`` fixture itself (not called), are the usual slips; say what to
    write instead of an ``AttributeError`` from inside opspec."""
    kind = type(obj).__name__
    if isinstance(obj, (Package, CompiledPackage)) or kind == "LoadedSpec":
        return TypeError(f"{who}() judges a run, not the spec ({kind}): write "
                         f"{who}(simulate(spec, ...), ...)")
    if kind == "Simulator":
        return TypeError(f"{who}() judges what simulate() returns, not the simulate fixture "
                         f"itself: call it, {who}(simulate(spec, ...), ...)")
    return TypeError(f"{who}() judges {takes}, not {kind}")


def require_result(obj: Any, who: str, needs: str) -> None:
    """Raise :func:`not_a_result` unless ``obj`` has ``needs`` (what ``who`` reads of a
    :class:`SimulationResult`)."""
    __tracebackhide__ = True
    if not hasattr(obj, needs):
        raise not_a_result(obj, who)


def load_spec_file(path: str | Path) -> Package:
    """Load a spec (XPDL, BPMN or ``.wfs``), refused as ``opspec validate`` refuses it
    (``SpecError`` with ``path:line``): :func:`opspec.request.open_gated`."""
    from opspec.request import open_gated

    return open_gated(path)[0]


@dataclass(frozen=True, slots=True)
class InstanceRun:
    """One process instance of one replication, with its slice of the trace.

    ``outcome`` is ``completed``, ``terminated``, ``aborted`` or ``open`` (still running when
    the run ended). ``events`` are the events of this instance only, in order.
    """

    replication: int
    process: str
    instance: int
    started: float
    ended: float | None
    outcome: str
    events: tuple[TraceEvent, ...]

    def completed(self, activity: str) -> bool:
        return any(e.kind == EventKind.ACTIVITY_COMPLETED and e.activity == activity
                   for e in self.events)


_ENDS = {EventKind.PROCESS_COMPLETED: "completed", EventKind.PROCESS_TERMINATED: "terminated",
         EventKind.PROCESS_ABORTED: "aborted"}


@dataclass(frozen=True, slots=True)
class FailedReplication:
    """A replication a run-time fault or a deadlock cut short: ``problem`` is the first one's
    located message (``fault: spec.xpdl:216: activity 'R': … division by zero``)."""

    replication: int
    problem: str

    def __str__(self) -> str:
        return f"replication {self.replication}: {self.problem}"


class FailedReplications(AssertionError):
    """A statistic was asked of a result whose replications include failed ones: their runs
    were cut short, so any number pooled over them would not be the spec's (an aborted dose
    is neither taken nor missed). An ``AssertionError``: the spec fails the test."""


#: failed replications named in a message, at most
_NAMED = 5


def failed_text(failed: Sequence[FailedReplication], replications: int) -> str:
    """What a result's failed replications say: how many, each with its fault's file:line,
    and what to do."""
    lines = [f"{len(failed)} of {replications} replication(s) failed: a run-time fault or a "
             "deadlock of the spec cut them short, so no statistic over them is judged"]
    lines.extend(f"  {f}" for f in failed[:_NAMED])
    if len(failed) > _NAMED:
        lines.append(f"  ... and {len(failed) - _NAMED} more")
    lines.append("fix the spec at the file:line named (result.failed lists them; "
                 "result.traces shows what happened)")
    return "\n".join(lines)


@dataclass(frozen=True, slots=True, eq=False)
class SimulationResult:
    """What :func:`simulate` produced: one :class:`RunResult` per replication, pooled metrics.

    ``metrics`` has the engine's shape (``{"doses_taken": {"kind": "count", "total": 3}}``),
    pooled over replications: counts summed, durations summarised over every sample, ratios
    recomputed from the pooled metrics. ``per_replication`` holds each replication's own.

    ``failed`` lists the replications a run-time fault or a deadlock cut short (as
    ``opspec evaluate`` fails them): while there is one, every statistic (:meth:`value`,
    :meth:`samples`, :meth:`counts`, :meth:`observations`, so every statistical assertion and
    scenario line) raises :class:`FailedReplications` naming the faults instead of computing
    over truncated runs. ``warnings`` are the front hall's on the spec and the user model
    (``path:line: warning: …``; the pytest plugin shows them).
    """

    spec: Package
    names: SpecNames
    seed: int
    horizon: float | None
    runs: tuple[RunResult, ...]
    metrics: dict[str, dict[str, Any]]
    durations: dict[str, tuple[float, ...]] = field(default_factory=dict)
    #: what each monitor saw in each replication (see :mod:`opspec.testing.monitors`)
    monitor_results: tuple[Any, ...] = ()
    #: the replications a run-time fault or a deadlock cut short
    failed: tuple[FailedReplication, ...] = ()
    #: validate's warnings on the spec and the user model's against its user lane
    warnings: tuple[Any, ...] = ()

    @property
    def complete(self) -> int:
        """How many replications ran to their end without a fault or a deadlock."""
        return len(self.runs) - len(self.failed)

    def _judgeable(self) -> None:
        __tracebackhide__ = True
        if self.failed:
            raise FailedReplications(failed_text(self.failed, self.replications)
                                     + f"\n(seed {self.seed})")

    def monitor_report(self, confidence: float = 0.95) -> Any:
        """Monitor violations, per monitor, with a hazard (violations per user-day) and its
        exact interval: :func:`opspec.testing.monitors.monitor_report`."""
        from opspec.testing.monitors import monitor_report

        return monitor_report(self, confidence=confidence)

    def __repr__(self) -> str:
        failed = f", {len(self.failed)} failed" if self.failed else ""
        return (f"<SimulationResult {self.spec.id}: {self.replications} replication(s)"
                f"{failed}, seed {self.seed}>")

    @property
    def users(self) -> int:
        return len(self.runs)

    @property
    def replications(self) -> int:
        return len(self.runs)

    @property
    def per_replication(self) -> list[dict[str, dict[str, Any]]]:
        return [run.metrics for run in self.runs]

    @property
    def metric_names(self) -> tuple[str, ...]:
        """The metrics the spec declares (what ``metric`` arguments may name)."""
        return self.names.metrics

    @property
    def traces(self) -> tuple[tuple[TraceEvent, ...], ...]:
        """Each replication's trace (only when traces were kept)."""
        out = []
        for run in self.runs:
            if run.trace is None:
                raise ConfigurationError(
                    "this result kept no trace",
                    hint="pass keep_trace=True to simulate() (traces of more than "
                         "100 users are not kept by default)")
            out.append(run.trace)
        return tuple(out)

    @property
    def trace(self) -> tuple[TraceEvent, ...]:
        """The trace of a one-user run (for many users, see :attr:`traces`)."""
        traces = self.traces
        if len(traces) != 1:
            raise ConfigurationError(
                f"this result has {len(traces)} replications, so it has no single trace",
                hint="use result.traces, result.instances(process), or simulate(users=1)")
        return traces[0]

    def _split(self, metric: str) -> tuple[str, str | None]:
        name, _, part = metric.partition(".")
        if name not in self.metrics:
            known = ", ".join(self.metric_names) or "(the spec declares no metrics)"
            raise ConfigurationError(f"the spec has no metric {name!r}",
                                     hint=f"its metrics are: {known}")
        kind = self.metrics[name]["kind"]
        if part and part not in FIELDS.get(kind, ()):
            raise ConfigurationError(
                f"metric {name!r} is a {kind}; it has no field {part!r}",
                hint="its fields are: " + ", ".join(FIELDS.get(kind, ())))
        return name, part or None

    @staticmethod
    def _scalar(values: Mapping[str, Any], part: str | None) -> float | None:
        key = part or FIELDS[values["kind"]][0]
        value = values.get(key)
        return None if value is None else float(value)

    def value(self, metric: str) -> float | None:
        """A pooled scalar: ``"doses_taken"`` (a count's total), ``"report_latency_s"`` (a
        duration's mean), ``"report_latency_s.p95"``, ``"alarms_per_dose"`` (a ratio's value).
        ``None`` when undefined (a mean of no samples)."""
        self._judgeable()
        name, part = self._split(metric)
        return self._scalar(self.metrics[name], part)

    def samples(self, metric: str) -> list[float]:
        """One value per replication (same spelling as :meth:`value`), skipping replications
        where it is undefined (a duration with no sample, a ratio over zero)."""
        self._judgeable()
        name, part = self._split(metric)
        out = []
        for run in self.runs:
            value = self._scalar(run.metrics[name], part)
            if value is not None:
                out.append(value)
        return out

    def counts(self, numerator: str, denominator: str) -> tuple[int, int]:
        """Pooled ``(successes, trials)`` of two count metrics, for rate assertions
        (``counts("doses_taken", "doses_due")``)."""
        self._judgeable()
        pair = []
        for metric in (numerator, denominator):
            name, _ = self._split(metric)
            if self.metrics[name]["kind"] != "count":
                raise ConfigurationError(f"metric {name!r} is a {self.metrics[name]['kind']}, "
                                         "not a count", hint="a rate is count / count")
            pair.append(int(self.metrics[name]["total"]))
        return pair[0], pair[1]

    def observations(self, metric: str) -> list[float]:
        """Every sample of a duration metric, pooled over replications (for quantiles)."""
        self._judgeable()
        name, _ = self._split(metric)
        if self.metrics[name]["kind"] != "duration":
            raise ConfigurationError(f"metric {name!r} is a {self.metrics[name]['kind']}, "
                                     "not a duration", hint="use samples() for it")
        return list(self.durations.get(name, ()))

    def instances(self, process: str) -> list[InstanceRun]:
        """The instances of ``process`` in every replication, each with its trace slice."""
        if process not in self.names.processes:
            raise ConfigurationError(
                f"the spec has no process {process!r}",
                hint="its processes are: " + ", ".join(self.names.processes))
        out: list[InstanceRun] = []
        for rep, trace in enumerate(self.traces):
            by_id: dict[int, list[TraceEvent]] = {}
            for event in trace:
                if event.instance is not None:
                    by_id.setdefault(event.instance, []).append(event)
            for inst, events in by_id.items():
                first = events[0]
                if first.process != process or first.kind != EventKind.PROCESS_STARTED:
                    continue
                end = next((e for e in events if e.kind in _ENDS), None)
                out.append(InstanceRun(rep, process, inst, first.time,
                                       end.time if end else None,
                                       _ENDS[end.kind] if end else "open", tuple(events)))
        return out


def _pool(runs: Sequence[RunResult], samples: Mapping[str, list[float]],
          definitions: Package) -> dict[str, dict[str, Any]]:
    if len(runs) == 1:
        return dict(runs[0].metrics)
    out: dict[str, dict[str, Any]] = {}
    ratios = []
    for metric in definitions.metrics:
        first = runs[0].metrics.get(metric.name)
        if first is None:
            continue
        if first["kind"] == "count":
            out[metric.name] = {"kind": "count",
                                "total": sum(r.metrics[metric.name]["total"] for r in runs)}
        elif first["kind"] == "duration":
            out[metric.name] = summarise_durations(list(samples.get(metric.name, [])))
        else:
            ratios.append(metric)
    for metric in ratios:
        num = _pooled_scalar(out.get(metric.numerator or ""))
        den = _pooled_scalar(out.get(metric.denominator or ""))
        out[metric.name] = {"kind": "ratio",
                            "value": num / den if num is not None and den else None}
    return out


def _pooled_scalar(values: Mapping[str, Any] | None) -> float | None:
    if values is None:
        return None
    value = values.get(FIELDS[values["kind"]][0])
    return None if value is None else float(value)


def simulate(spec: Package | CompiledPackage | str | Path, *, users: int = 1,
             days: float | None = None, until: float | None = None,
             script: Script | Sequence[Any] | str | Path | None = None,
             user_model: Any = None, seed: int = 0,
             engine_config: EngineConfig | Mapping[str, Any] | None = None,
             performers: Mapping[str, Performer] | None = None,
             keep_trace: bool | None = None,
             params: Mapping[str, Any] | None = None,
             branches: Mapping[str, Mapping[str, float]] | None = None,
             progress: Callable[[int], None] | None = None,
             monitors: Sequence[Any] | None = None,
             no_user: bool = False) -> SimulationResult:
    """Run ``spec`` for ``users`` independent users, ``days`` days or to ``until`` seconds
    (default: the spec's ``opspec:RunLength``, else one day); see the module docstring. ``keep_trace`` defaults to keeping traces of up to 100
    users. Raises :class:`~opspec.errors.OpspecError` subclasses for bad arguments (naming the
    spec's processes, activities, triggers or metrics when a name is unknown).
    ``monitors`` (monitor objects or their text form, see :mod:`opspec.testing.monitors`) are
    checked in every replication, with those the spec declares (``opspec:Monitor``)."""
    from opspec.request import RunRequest, prepare
    from opspec.testing.monitors import monitors_for

    if isinstance(users, bool) or not isinstance(users, int) or users < 1:
        raise ConfigurationError(f"users must be a whole number >= 1, not {users!r}")
    prepared = prepare(RunRequest(
        spec, seed=seed, days=days, until=until, script=script, user_model=user_model,
        no_user=no_user, config=engine_config, performers=performers or {}, params=params,
        branches=branches or None, keep_trace=users <= 100 if keep_trace is None else keep_trace))
    compiled = prepared.compiled
    names = spec_names(compiled)
    prepared = prepared.but(monitors=tuple(monitors_for(compiled, names, monitors)))
    watched: list[Any] = []
    runs: list[RunResult] = []
    failed: list[FailedReplication] = []
    pooled: dict[str, list[float]] = {}
    for u in range(users):
        outcome = prepared.build(u).execute()
        runs.append(outcome.result)
        if outcome.problem is not None:
            failed.append(FailedReplication(u, outcome.problem))
        watched.extend(outcome.monitors)
        for name, values in outcome.samples.items():
            pooled.setdefault(name, []).extend(values)
        if progress is not None:
            progress(u + 1)
    horizon = prepared.horizon
    return SimulationResult(compiled.package, names, seed, horizon, tuple(runs),
                            _pool(runs, pooled, compiled.package),
                            {k: tuple(v) for k, v in pooled.items()}, tuple(watched),
                            tuple(failed), prepared.warnings)
