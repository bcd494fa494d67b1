"""BPMN 2.0 front end: ``.bpmn`` files drawn in bpmn.io, Camunda Modeler, Signavio or
SpiffWorkflow's editor, built into the same immutable model (:mod:`opspec.model`) as XPDL.

The file is read by the XPDL front end's hardened reader (:func:`opspec.xpdl.reader.
parse_safely`: size limit, no DOCTYPE, no entities, no network, encodings, exact lines), and
the loader (:mod:`opspec.xpdl.loader`) sends a root ``bpmn:definitions`` here instead of to
the XPDL handlers. Everything after the model (validation, checks, the engine) is shared.

How each BPMN element maps to the model, and the opspec extension elements SISARL directives
travel in, is documented in ``docs/bpmn.md``. Modules, bottom up: :mod:`.common` (namespaces,
the file's index of ids), :mod:`.extensions` (``opspec:`` extension elements),
:mod:`.events` (event definitions), :mod:`.nodes` (what each flow node is),
:mod:`.process` (processes, sub-processes, flows, boundary events, lanes) and
:mod:`.package` (definitions, pools, message flows).
"""

from __future__ import annotations

from lxml import etree

from opspec.model.package import Package, XpdlVersion
from opspec.xpdl.bpmn.common import BPMN_NAMESPACES
from opspec.xpdl.handlers.common import BuildContext

__all__ = ["BPMN_VERSION", "build_bpmn", "is_bpmn"]

#: The version a package read from BPMN carries: XPDL 2.1 is the XPDL that serialises BPMN,
#: and its reading of every construct is the one the model follows.
BPMN_VERSION = XpdlVersion.V2_1


def is_bpmn(root: etree._Element) -> bool:
    """True when ``root`` is a BPMN 2.0 ``definitions`` element."""
    if not isinstance(root.tag, str):
        return False
    name = etree.QName(root)
    return name.localname == "definitions" and name.namespace in BPMN_NAMESPACES


def build_bpmn(root: etree._Element, ctx: BuildContext) -> Package:
    """The :class:`Package` of a BPMN ``definitions`` element; problems go to ``ctx``."""
    from opspec.xpdl.bpmn.package import build_definitions

    return build_definitions(root, ctx)
