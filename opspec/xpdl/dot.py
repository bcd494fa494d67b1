"""Graphviz (DOT) text for the processes of a package; no Graphviz binary needed.

One ``digraph`` per process (several graphs in one text are valid DOT: ``dot -Tsvg`` renders
the first, ``dot -Tsvg -O`` or ``ccomps`` all of them). Inside a graph:

* lanes are ``cluster`` subgraphs (the activity's lane, else the lane listing its first
  performer, else a cluster per performer); each activity set is a cluster of its own, and a
  BlockActivity points at its set's start with a dashed edge;
* shapes follow the activity kind: start events circles, intermediate events double circles,
  end events bold circles, routes diamonds labelled with their gateway, subflows double boxes,
  blocks 3-D boxes, other activities rounded boxes; manual activities (waiting for their
  performer) are filled in a highlight colour;
* edges carry their condition (``otherwise``, ``exception: name`` dashed and red).

Every id and label is written as a quoted DOT string with ``\\`` and ``"`` escaped, so any text
found in a file is safe.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from opspec.model.activities import (
    Activity,
    BlockActivity,
    Event,
    EventPosition,
    Route,
    SubFlow,
    Task,
)
from opspec.model.graph import FlowGraph
from opspec.model.package import Package
from opspec.model.process import ActivitySet, ConditionKind, Transition, WorkflowProcess

__all__ = ["package_to_dot", "process_to_dot", "quote"]

MANUAL_FILL = "#ffe08a"
_MAX_LABEL = 60


def quote(text: str) -> str:
    """``text`` as a DOT quoted string (backslashes and quotes escaped, newlines as ``\\n``)."""
    escaped = (text.replace("\\", "\\\\").replace('"', '\\"')
               .replace("\r\n", "\n").replace("\r", "\n").replace("\n", "\\n"))
    return f'"{escaped}"'


def _short(text: str) -> str:
    text = " ".join(text.split())
    return text if len(text) <= _MAX_LABEL else text[: _MAX_LABEL - 1] + "…"


def package_to_dot(package: Package, *, process: str | None = None) -> str:
    """One digraph per process of ``package`` (only ``process`` when given; ``KeyError`` if
    the package has no such process)."""
    if process is not None:
        chosen = package.process(process)
        if chosen is None:
            raise KeyError(process)
        return process_to_dot(chosen, package)
    return "".join(process_to_dot(p, package) for p in package.processes)


def process_to_dot(process: WorkflowProcess, package: Package | None = None) -> str:
    """The digraph of one process."""
    out: list[str] = [f"digraph {quote(process.id)} {{"]
    title = process.label if process.label == process.id else f"{process.label} ({process.id})"
    out.append(f"  label={quote(title)}; labelloc=t; rankdir=LR; compound=true;")
    out.append('  node [fontname="Helvetica", fontsize=10];')
    out.append('  edge [fontname="Helvetica", fontsize=9];')
    clusters = _Clusters(process, package)
    _level(out, None, process.activities, process.transitions, clusters, "  ")
    for aset in process.activity_sets:
        out.append(f"  subgraph {quote('cluster_set_' + aset.id)} {{")
        out.append(f"    label={quote('activity set ' + aset.label)}; style=dashed;")
        _level(out, aset, aset.activities, aset.transitions, clusters, "    ")
        out.append("  }")
    for activity in process.all_activities():
        body = activity.body
        if isinstance(body, BlockActivity):
            called = process.activity_set(body.activity_set)
            if called is None:
                continue
            owner = _owner(process, activity)
            graph = FlowGraph.of(called.activities, called.transitions)
            for start in graph.starts(body.start_activity):
                out.append(f"  {_node(owner, activity.id)} -> {_node(called, start)} "
                           f"[style=dashed, arrowhead=empty, "
                           f"lhead={quote('cluster_set_' + called.id)}];")
    out.append("}")
    return "\n".join(out) + "\n"


def _owner(process: WorkflowProcess, activity: Activity) -> ActivitySet | None:
    for aset in process.activity_sets:
        if any(a is activity for a in aset.activities):
            return aset
    return None


def _node(aset: ActivitySet | None, activity_id: str, scope: str = "") -> str:
    """Node names are scoped like activity ids: per activity set (and per process, ``scope``,
    when several processes share one graph)."""
    return quote(scope + (activity_id if aset is None else f"{aset.id}::{activity_id}"))


class _Clusters:
    """Which cluster an activity is drawn in: its lane; else the lane listing its first
    performer (lanes of the process's own pool first); else its first performer."""

    def __init__(self, process: WorkflowProcess, package: Package | None) -> None:
        self.labels: dict[str, str] = {}
        self.lane_of: dict[str, str] = {}
        pools = package.pools if package is not None else ()
        ordered = sorted(pools, key=lambda pool: pool.process != process.id)
        for pool in ordered:
            for lane in pool.all_lanes():
                self.labels.setdefault("lane:" + lane.id, lane.label)
                for performer in lane.performers:
                    self.lane_of.setdefault(performer, lane.id)
        participants = [*(package.participants if package is not None else ()),
                        *process.participants]
        for participant in participants:
            self.labels["by:" + participant.id] = participant.label
        # what waits for its performer, as the run does (an XPDL activity without an
        # implementation performed by a person included)
        self.manual = frozenset(
            a.id for a in process.all_activities()
            if (package.is_manual_work(a, process) if package is not None else a.is_manual))

    def key(self, activity: Activity) -> str | None:
        if activity.lane:
            return "lane:" + activity.lane
        if activity.performers:
            performer = activity.performers[0]
            lane = self.lane_of.get(performer)
            return "lane:" + lane if lane is not None else "by:" + performer
        return None

    def label(self, key: str) -> str:
        return self.labels.get(key, key.split(":", 1)[1])


def _level(out: list[str], aset: ActivitySet | None, activities: Iterable[Activity],
           transitions: Iterable[Transition], clusters: _Clusters, indent: str,
           scope: str = "", attributes: Callable[[Activity, bool], str] | None = None) -> None:
    attributes = attributes or _attributes
    acts = tuple(activities)
    groups: dict[str, list[Activity]] = {}
    loose: list[Activity] = []
    for activity in acts:
        key = clusters.key(activity)
        if key:
            groups.setdefault(key, []).append(activity)
        else:
            loose.append(activity)
    prefix = f"cluster_{scope}{aset.id}_" if aset is not None else f"cluster_{scope}"
    for key, members in groups.items():
        out.append(f"{indent}subgraph {quote(prefix + key)} {{")
        out.append(f"{indent}  label={quote(clusters.label(key))}; style=rounded; color=gray60;")
        for activity in members:
            out.append(f"{indent}  {_node(aset, activity.id, scope)} "
                       f"[{attributes(activity, activity.id in clusters.manual)}];")
        out.append(f"{indent}}}")
    for activity in loose:
        out.append(f"{indent}{_node(aset, activity.id, scope)} [{attributes(activity, activity.id in clusters.manual)}];")
    graph = FlowGraph.of(acts, transitions)
    for transition in graph.transitions:
        attrs = _edge_attributes(transition)
        tail = f" [{attrs}]" if attrs else ""
        out.append(f"{indent}{_node(aset, transition.source, scope)} -> "
                   f"{_node(aset, transition.target, scope)}{tail};")
    for host, events in graph.boundary.items():
        for event in events:
            out.append(f"{indent}{_node(aset, host, scope)} -> {_node(aset, event, scope)} "
                       "[style=dotted, arrowhead=none];")


def _attributes(activity: Activity, manual: bool | None = None) -> str:
    """``manual``: whether it waits for its performer (default: what the activity says)."""
    body = activity.body
    label = _short(activity.label)
    attrs: list[str] = []
    if isinstance(body, Event):
        shape = {EventPosition.START: "circle", EventPosition.INTERMEDIATE: "doublecircle",
                 EventPosition.END: "circle"}[body.position]
        attrs += [f"shape={shape}", "width=0.4", "fixedsize=false"]
        if body.position is EventPosition.END:
            attrs.append("penwidth=3")
        kind = body.trigger.kind.value
        if kind != "none":
            label = f"{label}\n({kind})"
    elif isinstance(body, Route):
        attrs.append("shape=diamond")
        gateway = body.gateway.value
        label = gateway if label == activity.id else f"{gateway}\n{label}"
    elif isinstance(body, SubFlow):
        attrs += ["shape=box", "peripheries=2"]
        label = f"{label}\n→ {body.process}"
    elif isinstance(body, BlockActivity):
        attrs.append("shape=box3d")
    else:
        attrs += ["shape=box", 'style="rounded"']
        if isinstance(body, Task) and body.applications:
            label = f"{label}\n[{body.applications[0].application}]"
    if activity.is_manual if manual is None else manual:
        attrs = [a for a in attrs if not a.startswith("style=")]
        style = "rounded,filled,bold" if not isinstance(body, Event | Route) else "filled,bold"
        attrs += [f'style="{style}"', f'fillcolor="{MANUAL_FILL}"']
        label = f"{label}\n(manual)"
    if activity.deadlines:
        label = f"{label}\n⏱ " + ", ".join(d.duration_text for d in activity.deadlines)
    attrs.insert(0, f"label={quote(label)}")
    attrs.append(f"tooltip={quote(activity.id)}")
    return ", ".join(attrs)


def _edge_attributes(transition: Transition) -> str:
    condition = transition.condition
    kind = condition.kind
    if kind is ConditionKind.CONDITION and condition.text:
        return f"label={quote(_short(condition.text))}"
    if kind is ConditionKind.OTHERWISE:
        return 'label="otherwise", style=bold'
    if kind is ConditionKind.EXCEPTION:
        name = condition.exception_name or (condition.text or "").strip()
        text = f"exception: {name}" if name else "exception"
        return f"label={quote(_short(text))}, style=dashed, color=red, fontcolor=red"
    if kind is ConditionKind.DEFAULTEXCEPTION:
        return 'label="default exception", style=dashed, color=red, fontcolor=red'
    return ""
