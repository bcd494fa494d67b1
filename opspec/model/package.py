"""The package: the root of a specification, and the XPDL versions opspec reads."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from opspec.model.activities import Activity, ActivityBody, NoImplementation
from opspec.model.common import Element, find_by_id
from opspec.model.data import DataField, TypeDeclaration
from opspec.model.process import WorkflowProcess
from opspec.model.resources import Application, Participant, ParticipantType, Pool
from opspec.model.sisarl import MetricDefinition, WorkflowMode

__all__ = ["ExternalPackage", "Package", "PackageHeader", "XpdlVersion"]


class XpdlVersion(enum.Enum):
    """The XPDL version, taken from the root element's namespace (never from XPDLVersion)."""

    V1_0 = "1.0"
    V2_0 = "2.0"
    V2_1 = "2.1"
    V2_2 = "2.2"
    NONE = "none"      # no namespace: read with 2.x element names

    @property
    def is_1_0(self) -> bool:
        return self is XpdlVersion.V1_0


# participants whose work without an implementation is manual (XPDL 2.1 §7.6.5.1, §7.7)
_PERSONS = frozenset({ParticipantType.HUMAN, ParticipantType.ROLE})


@dataclass(frozen=True, slots=True, kw_only=True)
class PackageHeader:
    """The package's header. ``source_format`` names what the file was written in when it
    is not XPDL (``"BPMN 2.0"``: the model is then XPDL 2.1's reading of it, and
    :attr:`Package.version` stays 2.1); ``None`` for XPDL, whose version is
    :attr:`Package.version`."""

    xpdl_version: str | None = None
    vendor: str | None = None
    created: str | None = None
    modified: str | None = None
    description: str | None = None
    documentation: str | None = None
    cost_unit: str | None = None
    priority_unit: str | None = None
    source_format: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class ExternalPackage(Element):
    """``ExternalPackage``: ``href`` as written; resolution happens in the front end."""

    href: str = ""


@dataclass(frozen=True, slots=True, kw_only=True)
class Package(Element):
    version: XpdlVersion = XpdlVersion.V2_1
    source: str | None = None
    header: PackageHeader = PackageHeader()
    conformance_class: str | None = None       # NON_BLOCKED / LOOP_BLOCKED / FULL_BLOCKED
    script_language: str | None = None
    type_declarations: tuple[TypeDeclaration, ...] = ()
    participants: tuple[Participant, ...] = ()
    applications: tuple[Application, ...] = ()
    data_fields: tuple[DataField, ...] = ()
    pools: tuple[Pool, ...] = ()
    processes: tuple[WorkflowProcess, ...] = ()
    external_packages: tuple[ExternalPackage, ...] = ()
    metrics: tuple[MetricDefinition, ...] = ()
    modes: tuple[WorkflowMode, ...] = ()
    run_length: float | None = None            # opspec:RunLength: one run's natural length, s
    # opspec:MessageTTL: how long a message nobody waits for is kept (s); None: until caught
    message_ttl: float | None = None

    def __repr__(self) -> str:
        # the whole spec, field by field, is no one's reading: a failing test showed 240
        # characters of it for its ``spec`` argument
        where = f" from {self.source}" if self.source else ""
        return f"<Package {self.id!r}{where}: {len(self.processes)} process(es)>"

    @property
    def source_format(self) -> str:
        """What the file was written in: ``"XPDL 2.1"``, ``"BPMN 2.0"``…"""
        return self.header.source_format or f"XPDL {self.version.value}"

    def process(self, process_id: str) -> WorkflowProcess | None:
        return find_by_id(self.processes, process_id)

    def participant(self, participant_id: str) -> Participant | None:
        return find_by_id(self.participants, participant_id)

    def is_manual_work(self, activity: Activity, process: WorkflowProcess | None = None,
                       body: ActivityBody | None = None) -> bool:
        """Whether ``activity`` waits for its performer rather than running by itself.

        Beside what :attr:`Activity.is_manual` says (a manual start mode, a manual or user
        task, opspec:AutoRun), XPDL 2.1 §7.6.5.1 says an activity with no implementation is
        "implemented by manual procedures": performed by a person (a HUMAN or ROLE
        participant) it is manual work. A BPMN abstract task, read into the same model as no
        implementation, is not (BPMN 2.0 §10.2.3), nor is one opspec:AutoRun makes automatic.
        ``body`` is the body that runs when it is not the activity's own (a Reference's).
        """
        if activity.is_manual:
            return True
        body = activity.body if body is None else body
        if (not isinstance(body, NoImplementation) or activity.directives.auto_run is not None
                or not activity.performers or self.source_format.upper().startswith("BPMN")):
            return False
        name = activity.performers[0]
        participant = next((p for p in (process.participants if process else ())
                            if p.id == name), None) or self.participant(name)
        return participant is not None and participant.type in _PERSONS

    def application(self, application_id: str) -> Application | None:
        return find_by_id(self.applications, application_id)
