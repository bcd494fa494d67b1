"""Reference checks: every id or name an element uses must be defined somewhere it can see.

Participants (performers, lane performers), applications, data fields (names read by
conditions, assignments, actual parameters, loops, deadlines, triggers, coordination built-ins),
subflow targets, activity sets, parameter counts, lanes, and the SISARL-XPDL directives,
metrics and modes. Internal to :mod:`opspec.model.checks`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from opspec.errors import SourceLocation
from opspec.model.activities import Activity, BlockActivity, Event, SubFlow, Task
from opspec.model.checks_support import Reporter, names_read, quote_list, where
from opspec.model.data import ActualParameter, Assignment, BasicKind, BasicType
from opspec.model.expressions import Expression
from opspec.model.package import Package
from opspec.model.process import ActivitySet, Transition, WorkflowProcess
from opspec.model.resources import Application
from opspec.model.sisarl import CoordinationKind, EventSelector, TriggerRef

__all__ = ["RefChecks"]


class RefChecks:
    """Reference checks of one package; ``packages`` are the other packages loaded with it."""

    def __init__(self, package: Package, packages: Mapping[str, Package],
                 report: Reporter) -> None:
        self.package = package
        self.packages = packages
        self.report = report
        others = [p for p in packages.values() if p is not package]
        self.participants = {p.id for pkg in (package, *others) for p in pkg.participants}
        self.applications = {a.id for pkg in (package, *others) for a in pkg.applications}
        self.package_fields = {f.id for f in package.data_fields}
        self.performer_fields = {f.id for f in package.data_fields if _is_performer(f.type)}
        self.lanes = {lane.id for pool in package.pools for lane in pool.all_lanes()}
        self.modes = {m.id for m in package.modes}
        # the performers known in the process last asked about (one set per process, not
        # one per activity)
        self._performers_of: tuple[WorkflowProcess, set[str]] | None = None
        self._fields_of: tuple[WorkflowProcess, set[str]] | None = None

    # -- package level -----------------------------------------------------------------
    def pools(self) -> None:
        processes = {p.id: p for p in self.package.processes}
        for pool in self.package.pools:
            if pool.process and pool.process not in processes:
                self.report.warning(
                    pool, "undefined-process",
                    f"pool {pool.id!r} belongs to process {pool.process!r}, which is not in "
                    f"package {self.package.id!r}", "fix the pool's Process attribute")
            # a lane may name a participant (or performer field) of its pool's own process
            own = processes.get(pool.process or "")
            local = set() if own is None else {p.id for p in own.participants} | {
                f.id for f in own.data_fields if _is_performer(f.type)}
            known = self.participants | self.performer_fields | local
            for lane in pool.all_lanes():
                for performer in lane.performers:
                    if performer not in known:
                        inside = f"process {own.id!r}, " if own is not None else ""
                        self.report.error(
                            lane, "undefined-participant",
                            f"lane {lane.id!r} of pool {pool.id!r} names performer "
                            f"{performer!r}, which is not a participant of {inside}package "
                            f"{self.package.id!r} or its external packages",
                            f"declare a Participant {performer!r} or fix the lane's Performer")

    def sisarl(self) -> None:
        """Metrics and modes declared on the package."""
        package = self.package
        processes = {p.id: p for p in package.processes}
        metric_names = {m.name for m in package.metrics}
        for metric in package.metrics:
            for selector in (metric.select, metric.start, metric.end):
                if selector is not None:
                    self._selector(metric.name, metric.location, selector, processes)
            for ref in (metric.numerator, metric.denominator):
                if ref is not None and ref not in metric_names:
                    self.report.error(
                        metric.location or package, "undefined-metric",
                        f"ratio metric {metric.name!r} divides by or into metric {ref!r}, "
                        "which is not declared", f"declare a metric {ref!r} or fix the name")
        for mode in package.modes:
            for workflow in mode.workflows:
                if workflow not in processes:
                    self.report.error(
                        package, "undefined-mode-workflow",
                        f"mode {mode.id!r} names workflow {workflow!r}, which is not a process "
                        f"of package {package.id!r}",
                        f"fix the mode's Workflows (known: {quote_list(sorted(processes))})")

    def _selector(self, metric: str, location: SourceLocation | None, selector: EventSelector,
                  processes: Mapping[str, WorkflowProcess]) -> None:
        owner = location or self.package
        if selector.process is not None and selector.process not in processes:
            self.report.error(
                owner, "undefined-metric-target",
                f"metric {metric!r} selects process {selector.process!r}, which is not in "
                f"package {self.package.id!r}, so it never counts anything",
                "fix the selector's Process")
            return
        if selector.activity is None:
            return
        scope = [processes[selector.process]] if selector.process else list(processes.values())
        if not any(any(a.id == selector.activity for a in p.all_activities()) for p in scope):
            inside = (f"process {selector.process!r}" if selector.process
                      else f"any process of package {self.package.id!r}")
            self.report.error(
                owner, "undefined-metric-target",
                f"metric {metric!r} selects activity {selector.activity!r}, which is not in "
                f"{inside}, so it never counts anything", "fix the selector's Activity")

    # -- process level -----------------------------------------------------------------
    def fields_of(self, process: WorkflowProcess) -> set[str]:
        """The data fields and formal parameters an expression of ``process`` may read (the
        same set for every call about one process; not to be changed by the caller)."""
        if self._fields_of is None or self._fields_of[0] is not process:
            self._fields_of = (process, self.package_fields | {f.id for f in process.data_fields}
                               | {p.id for p in process.formal_parameters})
        return self._fields_of[1]

    def process(self, process: WorkflowProcess) -> None:
        directives = process.directives
        scope = where(process, None)
        if directives.period is not None and directives.period <= 0:
            self.report.error(process, "bad-period",
                              f"{scope} has period {directives.period:g} s; it must be longer "
                              "than zero", "write e.g. opspec:Period=\"PT0.1S\"")
        if directives.deadline is not None and directives.deadline <= 0:
            self.report.error(process, "bad-process-deadline",
                              f"{scope} has latency bound {directives.deadline:g} s; it must be "
                              "longer than zero", "write e.g. opspec:Deadline=\"PT0.05S\"")
        if directives.mode is not None and directives.mode not in self.modes:
            self.report.error(process, "undefined-mode",
                              f"{scope} belongs to mode {directives.mode!r}, which the package "
                              "does not declare", "declare it in opspec:Modes or fix the name")
        for trigger in (directives.start_trigger, directives.end_trigger):
            self._trigger(process, None, process, trigger, f"a trigger of {scope}")
        for assignment in process.assignments:
            self._assignment(process, None, assignment, f"an assignment of {scope}")

    def activity(self, process: WorkflowProcess, aset: ActivitySet | None,
                 activity: Activity) -> None:
        scope = where(process, aset)
        what = f"activity {activity.id!r} in {scope}"
        performers = self._performers(process) if activity.performers else set()
        for performer in activity.performers:
            if performer and performer not in performers:
                self.report.error(
                    activity, "undefined-participant",
                    f"{what} is performed by {performer!r}, which is not a participant of "
                    f"{scope}, of package {self.package.id!r} or of its external packages",
                    f"declare a Participant {performer!r} or fix the Performer")
        if activity.lane and self.lanes and activity.lane not in self.lanes:
            self.report.warning(activity, "undefined-lane",
                                f"{what} is placed in lane {activity.lane!r}, which no pool "
                                "of the package declares", "fix the activity's LaneId")
        body = activity.body
        if isinstance(body, Task):
            self._task(process, aset, activity, body, what)
        elif isinstance(body, SubFlow):
            self._subflow(process, aset, activity, body, what)
        elif isinstance(body, BlockActivity):
            if body.activity_set and process.activity_set(body.activity_set) is None:
                self.report.error(
                    activity, "undefined-activity-set",
                    f"BlockActivity {activity.id!r} in {scope} runs activity set "
                    f"{body.activity_set!r}, which process {process.id!r} does not declare",
                    "set ActivitySetId to an ActivitySet of the same process")
        elif isinstance(body, Event):
            self._names(process, aset, activity, body.trigger.condition,
                        f"the trigger condition of {what}")
            self._names(process, aset, activity, body.trigger.duration,
                        f"the timer of {what}")
        if activity.loop is not None:
            self._names(process, aset, activity, activity.loop.condition,
                        f"the loop condition of {what}")
        for deadline in activity.deadlines:
            self._names(process, aset, deadline.location or activity, deadline.duration,
                        f"a deadline of {what}")
        for assignment in activity.assignments:
            self._assignment(process, aset, assignment, f"an assignment of {what}", activity)
        self._directives(process, aset, activity, what)

    def _performers(self, process: WorkflowProcess) -> set[str]:
        """Participants and performer fields an activity of ``process`` may name."""
        if self._performers_of is None or self._performers_of[0] is not process:
            self._performers_of = (process, self.participants | self.performer_fields | {
                p.id for p in process.participants} | {
                f.id for f in process.data_fields if _is_performer(f.type)})
        return self._performers_of[1]

    def _directives(self, process: WorkflowProcess, aset: ActivitySet | None,
                    activity: Activity, what: str) -> None:
        directives = activity.directives
        if directives.priority_increment < 0:
            self.report.warning(
                activity, "negative-priority-increment",
                f"{what} has priority increment {directives.priority_increment}; a negative "
                "increment runs it below its workflow's priority",
                "use an increment of 0 or more (raise the other activities instead)")
        if directives.cpu_demand is not None and directives.cpu_demand < 0:
            self.report.error(activity, "bad-cpu-demand",
                              f"{what} has a negative CPU demand ({directives.cpu_demand:g} s)",
                              "write a duration of zero or more, e.g. PT0.002S")
        for trigger in (directives.start_trigger, directives.end_trigger, directives.raises):
            if trigger is not None:
                self._trigger(process, aset, activity, trigger, f"a trigger of {what}")
        coordination = activity.coordination
        if coordination is None:
            return
        fields = self.fields_of(process)
        used = [*coordination.inputs, *([coordination.output] if coordination.output else [])]
        for name in dict.fromkeys(used):
            if name not in fields:
                self._undefined(process, activity, f"the {coordination.kind.value} built-in "
                                f"of {what}", name)
        if (coordination.kind is CoordinationKind.MODE_CHANGE and coordination.target_mode
                and coordination.target_mode not in self.modes):
            self.report.error(
                activity, "undefined-mode",
                f"the mode change of {what} switches to mode {coordination.target_mode!r}, "
                "which the package does not declare",
                "declare it in opspec:Modes or fix the target mode")

    def _trigger(self, process: WorkflowProcess, aset: ActivitySet | None,
                 owner: Activity | WorkflowProcess, trigger: TriggerRef | None,
                 what: str) -> None:
        if trigger is None:
            return
        if trigger.every is not None and trigger.every <= 0:
            self.report.error(trigger.location or owner, "bad-period",
                              f"{what} repeats every {trigger.every:g} s; the period must be "
                              "longer than zero", "write e.g. period:PT1S")
        self._names(process, aset, trigger.location or owner, trigger.condition, what)

    def _task(self, process: WorkflowProcess, aset: ActivitySet | None, activity: Activity,
              body: Task, what: str) -> None:
        local = {a.id: a for a in process.applications}
        for use in body.applications:
            if not use.application:
                continue          # reported by the reader
            app = local.get(use.application) or self._application(use.application,
                                                                  use.package_ref)
            if app is None and use.application not in self.applications:
                self.report.error(
                    activity, "undefined-application",
                    f"{what} calls application {use.application!r}, which is not declared in "
                    f"{where(process, None)}, package {self.package.id!r} or its external "
                    "packages", f"declare an Application {use.application!r} or fix the Id")
            self._actuals(process, aset, activity, use.actual_parameters,
                          f"the call of application {use.application!r} by {what}")
            formals = app.formal_parameters if app is not None else ()
            if formals and len(formals) != len(use.actual_parameters):
                self._count(activity, what, len(use.actual_parameters),
                            f"application {use.application!r}", len(formals))

    def _application(self, app_id: str, package_ref: str | None) -> Application | None:
        if package_ref is not None and package_ref in self.packages:
            candidates = [self.packages[package_ref]]
        else:
            candidates = [self.package, *self.packages.values()]
        for package in candidates:
            app = package.application(app_id)
            if app is not None:
                return app
        return None

    def _subflow(self, process: WorkflowProcess, aset: ActivitySet | None, activity: Activity,
                 body: SubFlow, what: str) -> None:
        self._actuals(process, aset, activity, body.actual_parameters, f"the SubFlow of {what}")
        if not body.process:
            return                # reported by the reader
        if body.package_ref and body.package_ref in self.packages:
            candidates = [self.packages[body.package_ref]]
        else:
            candidates = [self.package, *self.packages.values()]
        owner = next((p for p in candidates if p.process(body.process) is not None), None)
        called = owner.process(body.process) if owner is not None else None
        if owner is None or called is None:
            self.report.error(
                activity, "undefined-subflow",
                f"{what} calls process {body.process!r}, which is neither in package "
                f"{self.package.id!r} nor in a package loaded with it",
                "set the SubFlow Id to a WorkflowProcess Id (declare its package as an "
                "ExternalPackage if it lives in another file)")
            return
        if owner is not self.package and self.package.process(body.process) is None:
            # the engine runs the processes of one package: it would refuse the call
            self.report.error(
                activity, "external-subflow",
                f"{what} calls process {body.process!r} of external package {owner.id!r} "
                f"({owner.source or 'another file'}): opspec runs a SubFlow only into a "
                f"process of its own package {self.package.id!r}; calls into other packages "
                "are not supported", f"copy process {body.process!r} into this package (or "
                "run it on its own)")
            return
        formals = called.formal_parameters
        if formals and len(formals) != len(body.actual_parameters):
            self._count(activity, what, len(body.actual_parameters),
                        f"process {body.process!r}", len(formals))

    def _count(self, activity: Activity, what: str, actual: int, callee: str,
               formal: int) -> None:
        self.report.error(
            activity, "parameter-count-mismatch",
            f"{what} passes {actual} actual parameter{'s' * (actual != 1)} to {callee}, which "
            f"declares {formal} formal parameter{'s' * (formal != 1)}",
            "give one ActualParameter per FormalParameter, in order")

    def _actuals(self, process: WorkflowProcess, aset: ActivitySet | None, activity: Activity,
                 actuals: Iterable[ActualParameter], what: str) -> None:
        for actual in actuals:
            self._names(process, aset, actual.location or activity, actual.expression,
                        f"an actual parameter of {what}")

    # -- transitions, assignments, names --------------------------------------------------
    def transition(self, process: WorkflowProcess, aset: ActivitySet | None,
                   transition: Transition) -> None:
        if transition.condition.expression is None and not transition.assignments:
            return      # nothing it reads
        what = f"the condition of transition {transition.id!r} in {where(process, aset)}"
        self._names(process, aset, transition, transition.condition.expression, what)
        for assignment in transition.assignments:
            self._assignment(process, aset, assignment,
                             f"an assignment of transition {transition.id!r} in "
                             f"{where(process, aset)}", transition)

    def _assignment(self, process: WorkflowProcess, aset: ActivitySet | None,
                    assignment: Assignment, what: str,
                    owner: Activity | Transition | None = None) -> None:
        place = assignment.location or owner or process
        target = assignment.target.split(".", 1)[0]
        if target and target not in self.fields_of(process):
            self.report.error(
                place, "undefined-data-field",
                f"{what} sets {target!r}, which is not a data field or formal parameter of "
                f"{where(process, None)} nor a data field of package {self.package.id!r}",
                self._declare_hint(target, "or fix the assignment's target"))
        self._names(process, aset, place, assignment.expression, what)

    def _names(self, process: WorkflowProcess, aset: ActivitySet | None,
               place: object, expression: Expression | None, what: str) -> None:
        fields = self.fields_of(process)
        for name in names_read(expression):
            if name not in fields:
                self._undefined(process, place, what, name)

    def _undefined(self, process: WorkflowProcess, place: object, what: str, name: str) -> None:
        location = place if isinstance(place, SourceLocation) else getattr(place, "location",
                                                                              None)
        named = [f.id for f in (*self.package.data_fields, *process.data_fields,
                                *process.formal_parameters) if f.name == name]
        if named:
            hint = (f"{name!r} is the Name of data field {named[0]!r}; expressions use Ids: "
                    f"write {named[0]!r} (or give the field the Id {name!r})")
        else:
            hint = self._declare_hint(name, "or fix the name")
        self.report.error(
            location or process.location, "undefined-data-field",
            f"{what} reads {name!r}, which is not a data field or formal parameter of "
            f"{where(process, None)} nor a data field of package {self.package.id!r}", hint)

    def _declare_hint(self, name: str, tail: str) -> str:
        """How to declare ``name`` in the notation the spec was written in."""
        if (self.package.header.source_format or "").startswith("BPMN"):
            return (f"declare it: a bpmn:dataObject or bpmn:property with id {name!r}, a "
                    "camunda:formField of a user task or start event, a camunda:inputOutput "
                    f"parameter, or an opspec:DataField; or set it in a script task, {tail} "
                    "(docs/bpmn.md, Data)")
        return f"declare a DataField {name!r} {tail}"


def _is_performer(data_type: object) -> bool:
    return isinstance(data_type, BasicType) and data_type.kind is BasicKind.PERFORMER
