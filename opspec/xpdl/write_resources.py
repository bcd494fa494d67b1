"""Writing who performs the work as XPDL 2.1: participants, applications (their type when
XPDL 2.1 has one without required content, and their formal parameters), and pools with their
lanes (flat, nesting stated by ``NestedLane`` references) and the lanes' performers.
"""

from __future__ import annotations

from lxml import etree

from opspec.model import Application, Lane, Participant, Pool
from opspec.xpdl.write_data import write_formal_parameters
from opspec.xpdl.write_elements import each, sub, write_extended, xml_bool

__all__ = [
    "write_applications",
    "write_participants",
    "write_pools",
]


def write_participants(parent: etree._Element, participants: tuple[Participant, ...]) -> None:
    for container, participant in each(parent, "Participants", participants):
        element = sub(container, "Participant", Id=participant.id, Name=participant.name)
        sub(element, "ParticipantType", Type=participant.type.value)
        if participant.description is not None:
            sub(element, "Description", participant.description)
        write_extended(element, participant.extended_attributes)


_APPLICATION_TYPES = {"Script", "Xslt", "Form"}  # the XPDL 2.1 types with no required content


def write_applications(parent: etree._Element, applications: tuple[Application, ...]) -> None:
    for container, application in each(parent, "Applications", applications):
        element = sub(container, "Application", Id=application.id, Name=application.name)
        if application.description is not None:
            sub(element, "Description", application.description)
        if application.kind in _APPLICATION_TYPES:
            sub(sub(element, "Type"), application.kind)
        write_formal_parameters(element, application.formal_parameters)
        if not application.formal_parameters:
            sub(element, "FormalParameters")
        write_extended(element, application.extended_attributes)


def _flatten_lanes(lanes: tuple[Lane, ...]) -> list[Lane]:
    out: list[Lane] = []
    for lane in lanes:
        out.append(lane)
        out.extend(_flatten_lanes(lane.lanes))
    return out


def write_pools(parent: etree._Element, pools: tuple[Pool, ...]) -> None:
    for container, pool in each(parent, "Pools", pools):
        element = sub(container, "Pool", Id=pool.id, Name=pool.name, Process=pool.process,
                      Participant=pool.participant, BoundaryVisible=xml_bool(pool.boundary_visible))
        if pool.lanes:
            lanes = sub(element, "Lanes")
            # XPDL 2.1 lanes are flat; nesting is stated by NestedLane references.
            for lane in _flatten_lanes(pool.lanes):
                lane_element = sub(lanes, "Lane", Id=lane.id, Name=lane.name,
                                   ParentPool=lane.parent_pool)
                if lane.performers:
                    performers = sub(lane_element, "Performers")
                    for performer in lane.performers:
                        sub(performers, "Performer", performer)
                for nested in lane.lanes:
                    sub(lane_element, "NestedLane", LaneId=nested.id)
