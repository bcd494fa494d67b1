"""Handlers for resources: participants, applications, pools and (nested) lanes."""

from __future__ import annotations

import dataclasses
from typing import Any

from lxml import etree

from opspec.errors import Diagnostic, Severity
from opspec.model.data import Assignment
from opspec.model.resources import Application, Lane, Participant, ParticipantType, Pool
from opspec.xpdl.handlers.common import (
    BuildContext,
    attr,
    base_fields,
    child,
    children,
    grandchildren,
    local_name,
    parse_bool,
    text_of,
)
from opspec.xpdl.handlers.data import build_formal_parameter

__all__ = ["build_application", "build_participant", "build_pool", "performers_of"]


def performers_of(element: etree._Element) -> tuple[str, ...]:
    """``element/Performers/Performer`` texts (1.0 ``Performer`` is normalised into this)."""
    out: list[str] = []
    for performer in grandchildren(element, "Performers", "Performer"):
        text = text_of(performer)
        if text:
            out.append(text)
    return tuple(out)


def build_participant(element: etree._Element, ctx: BuildContext) -> Participant:
    fields = base_fields(element, ctx, kind="Participant")
    type_element = child(element, "ParticipantType")
    raw = (attr(type_element, "Type") if type_element is not None else None) or "ROLE"
    try:
        kind = ParticipantType(raw.upper())
    except ValueError:
        allowed = ", ".join(t.value for t in ParticipantType)
        ctx.warning(type_element, "unknown-participant-type",
                    f"unknown ParticipantType {raw!r} of Participant {fields['id']!r}; ROLE assumed",
                    f"use one of {allowed}")
        kind = ParticipantType.ROLE
    return Participant(type=kind, **fields)


def build_application(element: etree._Element, ctx: BuildContext) -> Application:
    fields = base_fields(element, ctx, kind="Application")
    kind = None
    type_element = child(element, "Type")
    if type_element is not None:
        kind = next((local_name(sub) for sub in type_element if isinstance(sub.tag, str)), None)
    parameters = ctx.each(grandchildren(element, "FormalParameters", "FormalParameter"),
                          build_formal_parameter)
    return Application(formal_parameters=parameters, kind=kind,
                       script=_script(fields, ctx), **fields)


def _script(fields: dict[str, Any], ctx: BuildContext) -> tuple[Assignment, ...]:
    """The statements of a JaWE/Shark script tool agent (``ToolAgentClass`` + ``Script``
    extended attributes); a script opspec cannot run is a ``bad-script`` error at its line."""
    from opspec.xpdl.conditions import ConditionSyntaxError
    from opspec.xpdl.scripts import SCRIPT_HINT, is_script_tool_agent, parse_script

    attributes = {a.name: a for a in fields["extended_attributes"]}
    agent = attributes.get("ToolAgentClass")
    script = attributes.get("Script")
    if agent is None or not is_script_tool_agent(agent.value or agent.text):
        return ()
    if script is None or not (script.value or script.text or "").strip():
        ctx.diagnostics.append(Diagnostic(
            agent.location or ctx.loc(None), Severity.ERROR, "bad-script",
            f"Application {fields['id']!r} uses the script tool agent {agent.value!r} but has no "
            "Script extended attribute", 'add <ExtendedAttribute Name="Script" Value="x = 1;"/>'))
        return ()
    location = script.location or fields["location"]
    try:
        return parse_script(script.value or script.text or "", location=location)
    except ConditionSyntaxError as error:
        if "JavaScript" in (agent.value or agent.text or ""):
            ctx.diagnostics.append(Diagnostic(
                location, Severity.ERROR, "bad-script",
                f"Script of Application {fields['id']!r}: {error.message}", SCRIPT_HINT))
        else:  # BeanShell scripts are Java calling into the Shark API: integrations
            ctx.diagnostics.append(Diagnostic(
                location, Severity.WARNING, "script-not-run",
                f"the BeanShell Script of Application {fields['id']!r} is not run by opspec "
                f"({error.problem}); a task calling it changes no data unless a performer "
                "is bound to the application id", SCRIPT_HINT))
        return ()


def _nest(lanes: dict[str, Lane], parents: dict[str, str], order: list[str],
          pool: etree._Element, ctx: BuildContext) -> tuple[Lane, ...]:
    """Build the lane tree from flat lanes and child -> parent links (cycles are broken)."""
    kids: dict[str, list[str]] = {}
    roots: list[str] = []
    for lane_id in order:
        parent = parents.get(lane_id)
        if parent is not None and parent in lanes and parent != lane_id:
            kids.setdefault(parent, []).append(lane_id)
        else:
            if parent is not None and parent not in lanes:
                ctx.warning(pool, "unknown-parent-lane",
                            f"lane {lane_id!r} names parent lane {parent!r}, which is not in the pool",
                            "fix ParentLane / NestedLane, or remove it")
            roots.append(lane_id)

    placed: set[str] = set()

    def make(lane_id: str, trail: frozenset[str]) -> Lane:
        placed.add(lane_id)
        nested = tuple(make(k, trail | {k}) for k in kids.get(lane_id, ()) if k not in trail)
        return dataclasses.replace(lanes[lane_id], lanes=nested)

    tree = [make(lane_id, frozenset({lane_id})) for lane_id in roots]
    for lane_id in order:  # lanes only reachable through a parent cycle
        if lane_id not in placed:
            ctx.warning(pool, "lane-cycle", f"lane {lane_id!r} is its own ancestor",
                        "fix the ParentLane / NestedLane links")
            tree.append(make(lane_id, frozenset({lane_id})))
    return tuple(tree)


def build_pool(element: etree._Element, ctx: BuildContext) -> Pool:
    fields = base_fields(element, ctx, kind="Pool")
    lanes: dict[str, Lane] = {}
    parents: dict[str, str] = {}
    order: list[str] = []
    for lane_element in grandchildren(element, "Lanes", "Lane"):
        lane_fields = base_fields(lane_element, ctx, kind="Lane")
        lane = Lane(performers=performers_of(lane_element),
                    parent_pool=attr(lane_element, "ParentPool"), **lane_fields)
        if lane.id in lanes:
            ctx.error(lane_element, "duplicate-id", f"lane id {lane.id!r} is used twice in pool "
                      f"{fields['id']!r}", "give every lane its own Id")
            continue
        lanes[lane.id] = lane
        order.append(lane.id)
        parent = attr(lane_element, "ParentLane")
        # Some exporters (Global 360, XPDL 2.0 samples) name the pool itself as the parent.
        if parent is not None and parent != fields["id"]:
            parents[lane.id] = parent
        for nested in children(lane_element, "NestedLane"):
            nested_id = attr(nested, "LaneId")
            if nested_id is not None:
                parents.setdefault(nested_id, lane.id)
    return Pool(
        process=attr(element, "Process"),
        participant=attr(element, "Participant"),
        lanes=_nest(lanes, parents, order, element, ctx),
        boundary_visible=parse_bool(attr(element, "BoundaryVisible")) is not False,
        **fields,
    )
