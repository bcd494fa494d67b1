"""What every part of the BPMN reader shares: namespaces, tree helpers, and :class:`Defs`, the
index of one file (its ids, messages, errors, signals, resources, message flows)."""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Final

from lxml import etree

from opspec.errors import Severity, SourceLocation
from opspec.model.data import BasicKind, DataField, ParameterMode
from opspec.model.sisarl import DeclaredDistribution
from opspec.xpdl.handlers.common import BuildContext
from opspec.xpdl.namespaces import OPSPEC

__all__ = [
    "BPMN",
    "BPMN_NAMESPACES",
    "Defs",
    "bpmn_children",
    "expression_text",
    "first",
    "is_juel",
    "kids",
    "label",
    "literal_kind",
    "local",
    "namespace",
    "tag",
    "text_of",
]

#: The BPMN 2.0 model namespace (OMG, final 2011 and every modeller since).
BPMN: Final = "http://www.omg.org/spec/BPMN/20100524/MODEL"
#: The namespace of the BPMN 2.0 beta (2009) some older exports still use: read as BPMN.
BPMN_BETA: Final = "http://schema.omg.org/spec/BPMN/2.0"
BPMN_NAMESPACES: Final = frozenset({BPMN, BPMN_BETA})
BPMNDI: Final = "http://www.omg.org/spec/BPMN/20100524/DI"

_TAGS: dict[str, str] = {}


def tag(name: str) -> str:
    """``{BPMN}name``, as lxml spells a BPMN tag."""
    found = _TAGS.get(name)
    if found is None:
        found = _TAGS[name] = f"{{{BPMN}}}{name}"
    return found


def local(element: etree._Element) -> str:
    """The local name of an element (``""`` for comments and processing instructions)."""
    raw = element.tag
    return raw.rsplit("}", 1)[-1] if isinstance(raw, str) else ""


def label(element: etree._Element) -> str:
    """How a diagnostic names a flow node: ``bpmn:userTask 'take'``."""
    return f"bpmn:{local(element)} {element.get('id')!r}"


def namespace(element: etree._Element) -> str:
    raw = element.tag
    if not isinstance(raw, str) or not raw.startswith("{"):
        return ""
    return raw[1:].split("}", 1)[0]


def kids(element: etree._Element, name: str) -> list[etree._Element]:
    """The BPMN children called ``name``, in document order."""
    return list(element.iterchildren(tag(name)))


def first(element: etree._Element, name: str) -> etree._Element | None:
    return next(element.iterchildren(tag(name)), None)


def bpmn_children(element: etree._Element) -> Iterator[etree._Element]:
    """The element children of ``element`` in the BPMN namespace."""
    prefix = f"{{{BPMN}}}"
    for sub in element:
        if isinstance(sub.tag, str) and sub.tag.startswith(prefix):
            yield sub


def text_of(element: etree._Element | None) -> str | None:
    """All the text inside ``element`` (CDATA included), stripped; ``None`` when blank."""
    if element is None:
        return None
    return "".join(element.itertext()).strip() or None


# ${...} and #{...}: Camunda's JUEL wrapper around an expression.
_JUEL = re.compile(r"^[$#]\{(?P<inner>.*)\}$", re.DOTALL)
# "PT5M" or 'PT5M': SpiffWorkflow writes timer values as Python string literals.
_QUOTED = re.compile(r"""^(?P<q>["'])(?P<inner>[^"']*)(?P=q)$""")


def literal_kind(expression: object) -> BasicKind:
    """The basic type a literal's value has (STRING for anything but a number or boolean):
    what a variable a script sets, or a condition compares, is typed as."""
    from opspec.model.expressions import Literal

    if isinstance(expression, Literal):
        value = expression.value
        if isinstance(value, bool):
            return BasicKind.BOOLEAN
        if isinstance(value, int):
            return BasicKind.INTEGER
        if isinstance(value, float):
            return BasicKind.FLOAT
    return BasicKind.STRING


def is_juel(element: etree._Element | None) -> bool:
    """Whether ``element``'s expression is wrapped as Camunda's JUEL (``${…}``, ``#{…}``)."""
    text = text_of(element)
    return text is not None and _JUEL.match(text) is not None


def expression_text(element: etree._Element | None, *, unquote: bool = False) -> str | None:
    """The text of a ``tFormalExpression``: the JUEL wrapper ``${…}`` of Camunda removed, and
    with ``unquote`` the quotes of a Python string literal (SpiffWorkflow's ``"PT5M"``)."""
    text = text_of(element)
    if text is None:
        return None
    match = _JUEL.match(text)
    if match is not None:
        text = match.group("inner").strip()
    if unquote:
        quoted = _QUOTED.match(text)
        if quoted is not None:
            text = quoted.group("inner").strip()
    return text or None


@dataclass(slots=True)
class Defs:
    """One BPMN file being built: the build context and an index of what its elements name.

    ``messages``, ``signals``, ``escalations`` map ids to the name a trigger goes by (the
    ``name``, else the id); ``errors`` maps an error's id to its ``errorCode`` (else name,
    else id); ``human`` holds the ids of resources some ``humanPerformer`` or
    ``potentialOwner`` names. ``sends``/``receives`` map a flow node id to the message a
    message flow from/to it carries; ``pool_of`` maps a process id to its pool's participant.
    ``item_kinds`` maps an itemDefinition's id to the basic type of its ``structureRef``;
    ``process_io`` a process id to its ``ioSpecification``'s inputs (IN) and outputs (OUT).
    """

    ctx: BuildContext
    by_id: dict[str, etree._Element] = field(default_factory=dict)
    messages: dict[str, str] = field(default_factory=dict)
    signals: dict[str, str] = field(default_factory=dict)
    escalations: dict[str, str] = field(default_factory=dict)
    errors: dict[str, str] = field(default_factory=dict)
    resources: dict[str, etree._Element] = field(default_factory=dict)
    human: set[str] = field(default_factory=set)
    sends: dict[str, list[tuple[str, etree._Element]]] = field(default_factory=dict)
    receives: dict[str, list[tuple[str, etree._Element]]] = field(default_factory=dict)
    pool_of: dict[str, tuple[str, str | None]] = field(default_factory=dict)
    user_participant: bool = False       # some user/manual task falls back on "user"
    package_fields: set[str] = field(default_factory=set)
    package_data: dict[str, DataField] = field(default_factory=dict)     # the same, by id
    item_kinds: dict[str, BasicKind] = field(default_factory=dict)
    process_io: dict[str, list[tuple[str, ParameterMode]]] = field(default_factory=dict)
    probabilities: dict[str, float] = field(default_factory=dict)   # BPSim / QBP, by flow id
    probability_source: dict[str, str] = field(default_factory=dict)
    data_names: dict[str, str] = field(default_factory=dict)   # a data object's name -> its id
    # BPSim / QBP processing times by activity id, and arrivals by process id (:mod:`.simulation`)
    durations: dict[str, DeclaredDistribution] = field(default_factory=dict)
    duration_source: dict[str, str] = field(default_factory=dict)
    arrivals: dict[str, tuple[DeclaredDistribution, int | None, str]] = field(
        default_factory=dict)
    call_aliases: dict[str, str] = field(default_factory=dict)  # tns:proc -> proc (:mod:`.imports`)

    def info(self, element: etree._Element | None, code: str, message: str,
             hint: str = "") -> None:
        self.ctx.report(element, Severity.INFO, code, message, hint)

    def loc(self, element: etree._Element | None) -> SourceLocation:
        return self.ctx.loc(element)

    def line(self, element: etree._Element | None) -> str:
        """``" (line N)"`` for messages that name another place, else ``""``."""
        where = self.ctx.loc(element)
        return f" (line {where.line})" if where.line else ""


def is_opspec(element: etree._Element) -> bool:
    return namespace(element) == OPSPEC
