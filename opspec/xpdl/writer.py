"""Model -> standard XPDL 2.1 XML.

:func:`write_xpdl` writes every model element back as XPDL 2.1
(``http://www.wfmc.org/2008/XPDL2.1``), children in the order the official schema
(``bpmnxpdl_31.xsd``) requires, so that the output of a schema-valid input validates again.

- Extended attributes are written verbatim (``Value``, text and raw child XML).
- SISARL-XPDL directives (:mod:`opspec.model.sisarl`) are written as ``ExtendedAttribute``
  elements named ``opspec:…`` (``docs/sisarl-xpdl.md``), except where a verbatim extended
  attribute of the same name is already there (the reader may keep those), so nothing is
  written twice.
- Conditions, assignments and parameters are written from their original text when the model
  has it, else printed from the expression tree (:func:`expression_text`).

Known losses (the model does not keep them, or XPDL 2.1 has no place for them): graphics,
application types other than Script/Xslt/Form, ``business-rule`` tasks (written as
``TaskService``), the ``interrupting`` flag of boundary events, source lines.

This module writes the package (:func:`build_tree`: its header, type declarations,
participants, applications, data fields, pools, processes, extended attributes) and the
document; the parts are written by :mod:`opspec.xpdl.write_processes` (a workflow process,
its activity sets and transitions), :mod:`opspec.xpdl.write_activities` (one activity),
:mod:`opspec.xpdl.write_events` (an event and its trigger), :mod:`opspec.xpdl.write_data`
(data types, fields, parameters, assignments), :mod:`opspec.xpdl.write_resources`
(participants, applications, pools and lanes) and :mod:`opspec.xpdl.write_elements` (the
namespace, the element helpers, extended attributes).
"""

from __future__ import annotations

import dataclasses

from lxml import etree

from opspec.model import Activity, NoImplementation, Package, WorkflowProcess
from opspec.xpdl.sisarl_write import (
    distribution_text,
    duration_text,
    expression_text,
    merged_attributes,
    package_directive_attributes,
    trigger_text,
)
from opspec.xpdl.write_data import write_data_fields, write_type_declaration
from opspec.xpdl.write_elements import NSMAP, XPDL21, sub, write_extended, xpdl_tag
from opspec.xpdl.write_processes import write_process
from opspec.xpdl.write_resources import write_applications, write_participants, write_pools

__all__ = [
    "XPDL21",
    "distribution_text",
    "duration_text",
    "expression_text",
    "trigger_text",
    "write_xpdl",
]


def build_tree(package: Package) -> etree._Element:
    """The ``Package`` element of ``package`` (for callers that post-process the tree)."""
    root = etree.Element(xpdl_tag("Package"), nsmap=NSMAP)
    root.set("Id", package.id)
    if package.name is not None:
        root.set("Name", package.name)
    header = package.header
    header_element = sub(root, "PackageHeader")
    sub(header_element, "XPDLVersion", "2.1")
    sub(header_element, "Vendor", header.vendor or "opspec")
    sub(header_element, "Created", header.created or "")
    description = header.description if header.description is not None else package.description
    for local, value in (("ModificationDate", header.modified), ("Description", description),
                         ("Documentation", header.documentation),
                         ("PriorityUnit", header.priority_unit),
                         ("CostUnit", header.cost_unit)):
        if value is not None:
            sub(header_element, local, value)
    if package.conformance_class is not None:
        sub(root, "ConformanceClass", GraphConformance=package.conformance_class)
    if package.script_language is not None:
        sub(root, "Script", Type=package.script_language)
    if package.external_packages:
        container = sub(root, "ExternalPackages")
        for external in package.external_packages:
            element = sub(container, "ExternalPackage", href=external.href, Id=external.id,
                          Name=external.name)
            write_extended(element, external.extended_attributes)
    if package.type_declarations:
        container = sub(root, "TypeDeclarations")
        for declaration in package.type_declarations:
            write_type_declaration(container, declaration)
    write_participants(root, package.participants)
    write_applications(root, package.applications)
    write_data_fields(root, package.data_fields)
    write_pools(root, package.pools)
    if package.processes:
        container = sub(root, "WorkflowProcesses")
        for process in package.processes:
            write_process(container, process, package)
    write_extended(root, merged_attributes(package.extended_attributes,
                                           package_directive_attributes(package)))
    return root


def write_xpdl(package: Package) -> bytes:
    """``package`` as a standard XPDL 2.1 document (UTF-8, with an XML declaration)."""
    root = build_tree(_abstract_tasks_automatic(package))
    etree.cleanup_namespaces(root, keep_ns_prefixes=["opspec"])
    data: bytes = etree.tostring(root, xml_declaration=True, encoding="UTF-8",
                                 pretty_print=True)
    return data


def _abstract_tasks_automatic(package: Package) -> Package:
    """A package read from BPMN, its abstract tasks (no implementation) automatic in writing.

    BPMN 2.0 §10.2.3: a Task "not further specified" runs by itself, while XPDL 2.1 §7.6.5.1
    reads an activity without an implementation performed by a person (a lane's ROLE
    participant) as manual work; so the XPDL written says opspec:AutoRun="true" for each such
    activity, and runs as the BPMN file did."""
    if not package.source_format.upper().startswith("BPMN"):
        return package
    # the same package, read as XPDL reads it: which activities would turn into manual work
    as_xpdl = dataclasses.replace(package, header=dataclasses.replace(
        package.header, source_format=None))

    def automatic(activities: tuple[Activity, ...], process: WorkflowProcess
                  ) -> tuple[Activity, ...]:
        return tuple(
            dataclasses.replace(a, directives=dataclasses.replace(a.directives, auto_run=True))
            if isinstance(a.body, NoImplementation) and a.directives.auto_run is None
            and not a.is_manual and as_xpdl.is_manual_work(a, process) else a
            for a in activities)

    processes = tuple(dataclasses.replace(
        process, activities=automatic(process.activities, process),
        activity_sets=tuple(dataclasses.replace(s, activities=automatic(s.activities, process))
                            for s in process.activity_sets))
        for process in package.processes)
    return dataclasses.replace(package, processes=processes)
