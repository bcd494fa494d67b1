"""The one place that lists the XML namespaces opspec reads.

The XPDL version of a file is decided by the namespace of its root element only (never by the
``XPDLVersion`` header, which real files get wrong). Elements in any XPDL namespace are read
with the same handlers: the normalising pass renames them all to :data:`CANONICAL`.
"""

from __future__ import annotations

from typing import Final

from opspec.model.package import XpdlVersion

__all__ = [
    "CANONICAL",
    "NO_NAMESPACE",
    "OPSPEC",
    "OPSPEC_PREFIX",
    "XPDL_1_0",
    "XPDL_2_0",
    "XPDL_2_1",
    "XPDL_2_2",
    "XPDL_NAMESPACES",
    "is_xpdl_namespace",
    "qname",
    "version_of_namespace",
]

XPDL_1_0: Final = "http://www.wfmc.org/2002/XPDL1.0"
XPDL_2_0: Final = "http://www.wfmc.org/2004/XPDL2.0alpha"
XPDL_2_1: Final = "http://www.wfmc.org/2008/XPDL2.1"
XPDL_2_2: Final = "http://www.wfmc.org/2009/XPDL2.2"
NO_NAMESPACE: Final = ""

#: Namespace -> version. ``""`` (no namespace) is read with XPDL 2.x element names.
XPDL_NAMESPACES: Final[dict[str, XpdlVersion]] = {
    XPDL_1_0: XpdlVersion.V1_0,
    XPDL_2_0: XpdlVersion.V2_0,
    XPDL_2_1: XpdlVersion.V2_1,
    XPDL_2_2: XpdlVersion.V2_2,
    NO_NAMESPACE: XpdlVersion.NONE,
}

#: The namespace every XPDL element has after normalising (handlers are keyed by it).
CANONICAL: Final = XPDL_2_1

#: SISARL-XPDL extensions (docs/sisarl-xpdl.md).
OPSPEC: Final = "urn:opspec:sisarl:1"
OPSPEC_PREFIX: Final = "opspec:"


def version_of_namespace(namespace: str | None) -> XpdlVersion | None:
    """The XPDL version a root namespace stands for, or ``None`` if it is not XPDL."""
    return XPDL_NAMESPACES.get(namespace or NO_NAMESPACE)


def is_xpdl_namespace(namespace: str | None) -> bool:
    return (namespace or NO_NAMESPACE) in XPDL_NAMESPACES


def qname(local: str, namespace: str = CANONICAL) -> str:
    """Clark notation ``{namespace}local`` as lxml spells tags."""
    return f"{{{namespace}}}{local}" if namespace else local
