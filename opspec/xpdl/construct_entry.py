"""What an entry of the construct registry (:mod:`opspec.xpdl.constructs`) is: the namespaces
entries are keyed by, the three things opspec does with a construct (:class:`Kind`: RUNS,
WARNS, REFUSES) and the diagnostic codes the gate reports them under, a construct's row
(:class:`Construct`) and a group judged to have no execution semantics (:class:`Inert`).

The entries themselves are in :mod:`opspec.xpdl.constructs_bpmn`,
:mod:`opspec.xpdl.constructs_xpdl` and :mod:`opspec.xpdl.constructs_inert`; they write a row
with :func:`entry`.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

__all__ = [
    "BPMN",
    "BPMNDI_NAMESPACES",
    "NOT_RUN",
    "RUNS_DIFFERENTLY",
    "XPDL",
    "Construct",
    "Inert",
    "Kind",
    "entry",
]

BPMN = "http://www.omg.org/spec/BPMN/20100524/MODEL"
#: Every XPDL namespace (1.0, 2.0, 2.1, 2.2, none): entries are keyed by the local name.
XPDL = "xpdl"
#: Diagram interchange: layout only.
BPMNDI_NAMESPACES = (
    "http://www.omg.org/spec/BPMN/20100524/DI",
    "http://www.omg.org/spec/DD/20100524/DC",
    "http://www.omg.org/spec/DD/20100524/DI",
)


#: The codes of the gate's diagnostics: a construct run differently (warning), refused (error).
RUNS_DIFFERENTLY = "runs-differently"
NOT_RUN = "not-run"


class Kind(enum.Enum):
    """What opspec does with a construct."""

    RUNS = "runs"          # as its standard says
    WARNS = "warns"        # it runs, differently: validate warns at its line
    REFUSES = "refuses"    # validate (and so every front door) refuses the file at its line


@dataclass(frozen=True, slots=True)
class Construct:
    """One row of the registry: ``elements`` (local names in ``namespace``) and, for an
    attribute, its name; ``text`` is what opspec does (for RUNS, the standard's behaviour it
    follows); ``section`` the part of the standard that defines it."""

    key: str
    namespace: str
    elements: tuple[str, ...]
    attribute: str | None
    kind: Kind
    text: str
    section: str
    when: str | None = None
    reported_by: tuple[str, ...] = ()
    hint: str = ""

    @property
    def code(self) -> str:
        """The diagnostic code validate reports it under."""
        return NOT_RUN if self.kind is Kind.REFUSES else RUNS_DIFFERENTLY


@dataclass(frozen=True, slots=True)
class Inert:
    """Elements and attributes judged to have no execution semantics, with the reason.
    ``elements`` ``("*",)`` means every element of the namespace; ``attributes`` lists the
    attributes covered (``"*"`` all), ``include_elements`` whether the elements themselves
    are covered too (not only their attributes)."""

    namespace: str
    elements: tuple[str, ...]
    attributes: tuple[str, ...]
    reason: str
    include_elements: bool = True


def entry(key: str, namespace: str, elements: str, attribute: str | None, kind: Kind, text: str,
          section: str, when: str | None = None, reported_by: tuple[str, ...] = (),
          hint: str = "") -> Construct:
    """A row of the registry, its ``elements`` written as one space-separated string."""
    return Construct(key, namespace, tuple(elements.split()), attribute, kind, text, section,
                     when, reported_by, hint)
