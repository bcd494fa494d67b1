"""A picture of the whole package: every process, its lanes, and the messages between them.

:func:`package_picture_dot` writes one Graphviz ``digraph`` in which

* each process is a ``cluster`` (titled with its name, id, lane role and how it starts), with
  its lanes as clusters inside it, drawn as :mod:`opspec.xpdl.dot` draws one process (same
  shapes, manual activities filled, exception edges dashed red);
* each message or signal is a dashed blue edge labelled with its name, from the activity that
  sends it (``opspec:Raises``, a throwing intermediate or end event) to every activity that
  receives it (a message start event, a catching intermediate event, an activity's
  ``opspec:StartTrigger``; a process started on it by ``opspec:StartTrigger``: its start);
* each subflow is a dotted edge from the calling activity to the start of the called process
  (``starts`` for ASYNCHR, ``calls`` for SYNCHR).

:func:`render_svg` lays it out with Graphviz's ``dot`` program (no layout is done here) and
:func:`picture_html` wraps the SVG in a self-contained page with a legend.
"""

from __future__ import annotations

import html
import shutil
import subprocess
from dataclasses import dataclass

from opspec.errors import ConfigurationError
from opspec.model.activities import (
    Activity,
    BlockActivity,
    Event,
    EventPosition,
    SubFlow,
    TriggerKind,
)
from opspec.model.graph import FlowGraph
from opspec.model.package import Package
from opspec.model.process import ActivitySet, WorkflowProcess
from opspec.model.sisarl import TriggerRef
from opspec.xpdl.dot import MANUAL_FILL, _attributes, _Clusters, _level, _node, _short, quote

__all__ = ["MESSAGE_COLOR", "Message", "messages", "package_picture_dot", "picture_html",
           "render_svg"]

MESSAGE_COLOR = "#1f5fbf"
_CALL_COLOR = "gray35"
INSTALL_HINT = ("install Graphviz: 'apt-get install graphviz' (Debian/Ubuntu; the project's "
                "scripts/system-deps.sh does it), 'brew install graphviz' (macOS), or see "
                "https://graphviz.org/download/")


@dataclass(frozen=True, slots=True)
class Message:
    """One message (or signal) edge: ``sender`` and ``receiver`` are DOT node names."""

    kind: str                 # "message" or "signal"
    name: str
    sender: str
    receiver: str


def _scope(process: WorkflowProcess) -> str:
    return process.id + "::"


def _where(process: WorkflowProcess) -> list[tuple[ActivitySet | None, Activity]]:
    """Every activity of ``process`` with the activity set it belongs to."""
    found: list[tuple[ActivitySet | None, Activity]] = [(None, a) for a in process.activities]
    for aset in process.activity_sets:
        found.extend((aset, a) for a in aset.activities)
    return found


def _signal(trigger: TriggerRef | None) -> tuple[str, str] | None:
    if trigger is None or trigger.kind not in ("message", "signal") or not trigger.name:
        return None
    return trigger.kind, trigger.name


def _event_signal(body: Event) -> tuple[str, str] | None:
    kind = body.trigger.kind
    if kind not in (TriggerKind.MESSAGE, TriggerKind.SIGNAL) or not body.trigger.name:
        return None
    return kind.value, body.trigger.name


def _starts(process: WorkflowProcess) -> list[str]:
    """The DOT nodes where an instance of ``process`` begins."""
    graph = FlowGraph.of(process.activities, process.transitions)
    return [_node(None, start, _scope(process)) for start in graph.starts(None)]


def messages(package: Package, processes: tuple[WorkflowProcess, ...] | None = None
             ) -> list[Message]:
    """The message/signal edges among ``processes`` (default: all of the package), in the
    package's order: every sender paired with every receiver of the same kind and name."""
    chosen = package.processes if processes is None else processes
    senders: dict[tuple[str, str], list[str]] = {}
    receivers: dict[tuple[str, str], list[str]] = {}
    for process in chosen:
        scope = _scope(process)
        received = _signal(process.directives.start_trigger)
        if received is not None:
            receivers.setdefault(received, []).extend(_starts(process))
        for aset, activity in _where(process):
            node = _node(aset, activity.id, scope)
            sent = _signal(activity.directives.raises)
            if sent is not None:
                senders.setdefault(sent, []).append(node)
            waited = _signal(activity.directives.start_trigger)
            if waited is not None:
                receivers.setdefault(waited, []).append(node)
            body = activity.body
            if isinstance(body, Event):
                event = _event_signal(body)
                if event is None:
                    continue
                throws = (not body.trigger.catching and body.position is not EventPosition.START
                          ) or body.position is EventPosition.END
                (senders if throws else receivers).setdefault(event, []).append(node)
    found: list[Message] = []
    for key, sources in senders.items():
        for sender in dict.fromkeys(sources):
            for receiver in dict.fromkeys(receivers.get(key, ())):
                found.append(Message(key[0], key[1], sender, receiver))
    return found


def _start_label(process: WorkflowProcess) -> str:
    trigger = process.directives.start_trigger
    if trigger is not None:
        if trigger.kind in ("message", "signal") and trigger.name:
            return f"starts on {trigger.kind} {trigger.name}"
        if trigger.kind == "timer" and trigger.at:
            times = ", ".join(f"{int(t // 3600):02d}:{int(t % 3600 // 60):02d}"
                              for t in trigger.at[:6])
            return f"starts at {times}" + (" …" if len(trigger.at) > 6 else "")
        if trigger.every:
            return f"starts every {trigger.every:g} s"
        return f"starts on {trigger.kind}"
    if process.directives.period:
        return f"starts every {process.directives.period:g} s"
    return ""


def package_picture_dot(package: Package, *, process: str | None = None) -> str:
    """The whole package (or only ``process``; ``KeyError`` if there is none) as one digraph."""
    if process is not None:
        chosen = package.process(process)
        if chosen is None:
            raise KeyError(process)
        procs: tuple[WorkflowProcess, ...] = (chosen,)
    else:
        procs = package.processes
    title = package.name or package.id
    out = [f"digraph {quote(package.id)} {{",
           f"  label={quote(title)}; labelloc=t; fontsize=16; fontname=\"Helvetica-Bold\";",
           "  rankdir=LR; compound=true; newrank=true; nodesep=0.3; ranksep=0.45;",
           '  node [fontname="Helvetica", fontsize=10];',
           '  edge [fontname="Helvetica", fontsize=9];']
    for proc in procs:
        _process_cluster(out, proc, package)
    ids = {p.id for p in procs}
    for proc in procs:
        for aset, activity in _where(proc):
            body = activity.body
            if isinstance(body, SubFlow) and body.process in ids:
                called = package.process(body.process)
                if called is None:
                    continue
                verb = "starts" if body.execution.value == "ASYNCHR" else "calls"
                for start in _starts(called):
                    out.append(f"  {_node(aset, activity.id, _scope(proc))} -> {start} "
                               f"[label={quote(verb)}, style=dotted, color={quote(_CALL_COLOR)}, "
                               f"fontcolor={quote(_CALL_COLOR)}, arrowhead=vee, "
                               f"lhead={quote('cluster_process_' + called.id)}];")
    for message in messages(package, procs):
        out.append(f"  {message.sender} -> {message.receiver} "
                   f"[label={quote(message.name)}, style=dashed, penwidth=1.6, "
                   f"color={quote(MESSAGE_COLOR)}, fontcolor={quote(MESSAGE_COLOR)}, "
                   f"fontsize=11, arrowhead=open, constraint=false, "
                   f"tooltip={quote(f'{message.kind} {message.name}')}];")
    out.append("}")
    return "\n".join(out) + "\n"


def _left(lines: list[str]) -> str:
    """A DOT label of ``lines``, each left-justified."""
    return "".join(quote(line)[1:-1] + "\\l" for line in lines).join('""')


def _picture_attributes(activity: Activity, manual: bool | None = None) -> str:
    """As :mod:`opspec.xpdl.dot` draws an activity, but events are small circles labelled
    beside them (BPMN's look, and the picture stays compact) and deadlines are spelled out."""
    body = activity.body
    if not isinstance(body, Event):
        return _attributes(activity, manual).replace("\u23f1 ", "deadline ")
    label = _short(activity.label)
    kind = body.trigger.kind
    if kind is not TriggerKind.NONE:
        what = body.trigger.name or body.trigger.time_cycle or body.trigger.time_date or ""
        label = f"{label}\n({kind.value}{' ' + _short(what) if what else ''})"
    if activity.deadlines:
        label += "\ndeadline " + ", ".join(d.duration_text for d in activity.deadlines)
    if activity.is_manual:
        label += "\n(manual)"
    attrs = ["shape=circle", "width=0.3", "fixedsize=true", 'label=""',
             f"xlabel={quote(label)}"]
    if body.position is EventPosition.INTERMEDIATE:
        attrs[0] = "shape=doublecircle"
        attrs[1] = "width=0.26"
    elif body.position is EventPosition.END:
        attrs.append("penwidth=3")
    if kind in (TriggerKind.MESSAGE, TriggerKind.SIGNAL):
        attrs.append(f"color={quote(MESSAGE_COLOR)}")
    if activity.is_manual:
        attrs += ['style="filled"', f'fillcolor="{MANUAL_FILL}"']
    attrs.append(f"tooltip={quote(activity.id)}")
    return ", ".join(attrs)


def _process_cluster(out: list[str], process: WorkflowProcess, package: Package) -> None:
    scope = _scope(process)
    title = process.label if process.label == process.id else f"{process.label} ({process.id})"
    facts = [f"{process.directives.lane} lane" if process.directives.lane else "",
             _start_label(process)]
    label = _left([title, *(fact for fact in facts if fact)])
    out.append(f"  subgraph {quote('cluster_process_' + process.id)} {{")
    out.append(f"    label={label}; labeljust=l; fontname=\"Helvetica-Bold\"; "
               "fontsize=12; style=\"rounded,bold\"; color=gray25; margin=12;")
    clusters = _Clusters(process, package)
    _level(out, None, process.activities, process.transitions, clusters, "    ", scope,
           _picture_attributes)
    for aset in process.activity_sets:
        out.append(f"    subgraph {quote('cluster_set_' + scope + aset.id)} {{")
        out.append(f"      label={quote('activity set ' + aset.label)}; style=dashed;")
        _level(out, aset, aset.activities, aset.transitions, clusters, "      ", scope,
               _picture_attributes)
        out.append("    }")
    out.append("  }")
    for owner, activity in _where(process):
        body = activity.body
        if isinstance(body, BlockActivity):
            called = process.activity_set(body.activity_set)
            if called is None:
                continue
            graph = FlowGraph.of(called.activities, called.transitions)
            for start in graph.starts(body.start_activity):
                out.append(f"  {_node(owner, activity.id, scope)} -> "
                           f"{_node(called, start, scope)} [style=dashed, arrowhead=empty, "
                           f"lhead={quote('cluster_set_' + scope + called.id)}];")


def render_svg(dot_text: str, *, timeout: float = 120.0) -> str:
    """``dot_text`` laid out by Graphviz's ``dot`` as SVG. Raises
    :class:`~opspec.errors.ConfigurationError` (one line) when ``dot`` is not installed, fails
    or takes longer than ``timeout`` seconds."""
    program = shutil.which("dot")
    if program is None:
        raise ConfigurationError(f"drawing SVG or HTML needs Graphviz's 'dot' program, which "
                                 f"is not installed ({INSTALL_HINT}); "
                                 "'--format dot' writes the graph without it")
    try:
        done = subprocess.run([program, "-Tsvg"], input=dot_text.encode("utf-8"),
                              capture_output=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        raise ConfigurationError(f"Graphviz's dot took longer than {timeout:g} s to lay out "
                                 "the picture; draw one process with --process ID") from None
    except OSError as error:
        raise ConfigurationError(f"cannot run Graphviz's dot ({program}): "
                                 f"{error.strerror or error}") from None
    if done.returncode != 0:
        reason = " ".join(done.stderr.decode("utf-8", "replace").split())[:300]
        raise ConfigurationError(f"Graphviz's dot failed (exit {done.returncode}): "
                                 f"{reason or 'no message'}")
    return done.stdout.decode("utf-8")


_LEGEND = (
    ("circle", ("start event (a double circle: an intermediate event, which waits; a bold "
                "circle: an end event)")),
    ("rounded box", "activity; filled yellow: manual, it waits for its performer (the user)"),
    ("diamond", "gateway (a decision or a merge)"),
    ("⏱", "a deadline: when it expires, its exception leaves by the red dashed edge"),
    ("blue dashed edge", "a message or signal sent from one process to another, with its name"),
    ("grey dotted edge", "a subflow: the activity starts (ASYNCHR) or calls (SYNCHR) a process"),
)


def picture_html(package: Package, svg: str) -> str:
    """A self-contained HTML page showing ``svg`` (from :func:`render_svg`) with a legend."""
    title = html.escape(package.name or package.id)
    start = svg.find("<svg")
    body = svg[start:] if start >= 0 else svg
    legend = "\n".join(f"    <tr><th>{html.escape(shape)}</th><td>{html.escape(meaning)}</td></tr>"
                       for shape, meaning in _LEGEND)
    source = f" ({html.escape(str(package.source))})" if package.source else ""
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}: processes and messages</title>
<style>
  body {{ font-family: Helvetica, Arial, sans-serif; margin: 1.5em; color: #222; }}
  h1 {{ font-size: 1.3em; }}
  .picture {{ overflow: auto; border: 1px solid #ccc; padding: 0.5em; }}
  .picture svg {{ max-width: 100%; height: auto; }}
  table {{ border-collapse: collapse; margin-top: 1em; font-size: 0.9em; }}
  th, td {{ text-align: left; padding: 0.2em 0.8em; border-bottom: 1px solid #eee; }}
</style>
</head>
<body>
<h1>{title}{source}</h1>
<p>Every process of the package with its lanes; blue dashed edges are the messages between
them. Hover over an activity for its id.</p>
<div class="picture">
{body}
</div>
<table>
  <caption>How to read it</caption>
{legend}
</table>
</body>
</html>
"""
