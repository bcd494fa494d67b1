"""The Package handler: the root of a specification file."""

from __future__ import annotations

from pathlib import PurePath

from lxml import etree

from opspec.model.package import ExternalPackage, Package, PackageHeader
from opspec.xpdl.handlers.common import (
    BuildContext,
    attr,
    base_fields,
    child,
    child_text,
    grandchildren,
    indexed_children,
)
from opspec.xpdl.handlers.data import build_data_field, build_type_declaration
from opspec.xpdl.handlers.field_names import resolve_field_names
from opspec.xpdl.handlers.process import build_process
from opspec.xpdl.handlers.resources import build_application, build_participant, build_pool
from opspec.xpdl.sisarl import package_extensions

__all__ = ["build_package"]


def _header(element: etree._Element | None) -> PackageHeader:
    if element is None:
        return PackageHeader()
    return PackageHeader(
        xpdl_version=child_text(element, "XPDLVersion"),
        vendor=child_text(element, "Vendor"),
        created=child_text(element, "Created"),
        modified=child_text(element, "ModificationDate"),
        description=child_text(element, "Description"),
        documentation=child_text(element, "Documentation"),
        cost_unit=child_text(element, "CostUnit"),
        priority_unit=child_text(element, "PriorityUnit"),
    )


def _external(element: etree._Element, ctx: BuildContext) -> ExternalPackage:
    href = attr(element, "href")
    if href is None:
        ctx.error(element, "missing-href", "ExternalPackage has no href",
                  "set href to the path of the package file, relative to this file")
    fields = base_fields(element, ctx, kind="ExternalPackage", id_default=href or "")
    return ExternalPackage(href=href or "", **fields)


def build_package(element: etree._Element, ctx: BuildContext) -> Package:
    """The :class:`Package` of a normalised ``Package`` element (the tree is only read)."""
    with indexed_children():
        return _package(element, ctx)


def _package(element: etree._Element, ctx: BuildContext) -> Package:
    stem = PurePath(ctx.path).stem
    if attr(element, "Id") is None:
        ctx.warning(element, "missing-id", f"Package has no Id; the file name {stem!r} is used",
                    "add an Id attribute to <Package>")
    fields = base_fields(element, ctx, kind="Package", id_default=stem)
    conformance = child(element, "ConformanceClass")
    script = child(element, "Script")
    package = Package(
        version=ctx.version,
        source=ctx.path,
        header=_header(child(element, "PackageHeader")),
        conformance_class=attr(conformance, "GraphConformance") if conformance is not None else None,
        script_language=attr(script, "Type") if script is not None else None,
        type_declarations=ctx.each(grandchildren(element, "TypeDeclarations", "TypeDeclaration"),
                                   build_type_declaration),
        participants=ctx.each(grandchildren(element, "Participants", "Participant"),
                              build_participant),
        applications=ctx.each(grandchildren(element, "Applications", "Application"),
                              build_application),
        data_fields=ctx.each(grandchildren(element, "DataFields", "DataField"), build_data_field),
        pools=ctx.each(grandchildren(element, "Pools", "Pool"), build_pool),
        processes=ctx.each(grandchildren(element, "WorkflowProcesses", "WorkflowProcess"),
                           build_process),
        external_packages=ctx.each(grandchildren(element, "ExternalPackages", "ExternalPackage"),
                                   _external),
        **package_extensions(element, ctx),
        **fields,
    )
    # TIBCO-style conditions name fields by Name: read as their Ids, with a warning
    return resolve_field_names(package, ctx.diagnostics)
