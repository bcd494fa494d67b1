"""Validation against the official WfMC XPDL schemas, bundled in ``opspec/xpdl/schemas/``.

opspec reads many files the schemas reject (every editor writes some), so schema validity is
not part of ``opspec validate``'s verdict unless asked for (``opspec validate --schema``).
The schema is chosen by the root element's namespace:

============================================  =========================================
namespace                                     bundled schema
============================================  =========================================
``http://www.wfmc.org/2002/XPDL1.0``          ``TC-1025_schema_10_xpdl.xsd`` (XPDL 1.0)
``http://www.wfmc.org/2008/XPDL2.1``          ``bpmnxpdl_31.xsd`` (XPDL 2.1)
``http://www.wfmc.org/2004/XPDL2.0alpha``     none: the official 2005-09-07 schema is not
                                              deterministic (it breaks XML Schema's unique
                                              particle attribution rule) and libxml2
                                              refuses to compile it
``http://www.wfmc.org/2009/XPDL2.2``          none bundled (``bpmnxpdl_40a.xsd``)
no namespace                                  none (no XPDL schema applies)
============================================  =========================================

The schemas are compiled with lxml's :class:`~lxml.etree.XMLSchema`, never fetched: the 2.1
schema imports the 1.0 one from ``http://www.wfmc.org/...``, and a resolver maps every
``schemaLocation`` to the bundled file of the same name (anything else is refused, and the
parser has ``no_network=True``). The schemas are copyright the Workflow Management Coalition,
reproduced with the notice the WfMC asks copies to carry (at the top of each file).
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Final

from lxml import etree

from opspec.errors import Diagnostic, Severity, SourceLocation
from opspec.model.package import Package
from opspec.xpdl.namespaces import NO_NAMESPACE, XPDL_1_0, XPDL_2_0, XPDL_2_1, XPDL_2_2
from opspec.xpdl.reader import XmlReadError, read_file

if TYPE_CHECKING:
    from opspec.xpdl.validate import FileReport

__all__ = [
    "SCHEMA_DIR",
    "SCHEMA_FILES",
    "SchemaUnavailable",
    "add_schema",
    "output_schema_warnings",
    "schema_diagnostics",
    "schema_errors",
    "schema_for",
    "unexplained",
    "with_schema",
]

#: Where the bundled XSDs are.
SCHEMA_DIR: Final = Path(__file__).with_name("schemas")

#: Namespace -> bundled XSD.
SCHEMA_FILES: Final[dict[str, str]] = {
    XPDL_1_0: "TC-1025_schema_10_xpdl.xsd",
    XPDL_2_1: "bpmnxpdl_31.xsd",
}

#: Namespace -> why no schema is bundled for it.
_NO_SCHEMA: Final[dict[str, str]] = {
    XPDL_2_0: ("no XSD for XPDL 2.0 is bundled: the official 2005-09-07 schema is not "
               "deterministic (it breaks XML Schema's unique particle attribution rule) and "
               "libxml2 refuses to compile it"),
    XPDL_2_2: "no XSD for XPDL 2.2 (bpmnxpdl_40a.xsd) is bundled with opspec",
    NO_NAMESPACE: "the Package has no namespace, so no XPDL schema applies",
}

#: At most this many schema errors are listed per file (then "and N more").
MAX_ERRORS: Final = 20


class SchemaUnavailable(Exception):
    """No bundled schema for a namespace (the message says why)."""


class _LocalOnly(etree.Resolver):  # type: ignore[misc, unused-ignore]
    """Resolve every schema import to the bundled file of the same name; nothing else."""

    def resolve(self, system_url: str | None, public_id: str | None,
                context: object) -> object:
        name = (system_url or "").replace("\\", "/").rsplit("/", 1)[-1]
        local = SCHEMA_DIR / name
        if name and local.is_file():
            return self.resolve_filename(str(local), context)
        raise SchemaUnavailable(f"the schema imports {system_url!r}, which is not bundled")


@functools.cache
def _compiled(name: str) -> etree.XMLSchema:
    parser = etree.XMLParser(no_network=True, resolve_entities=False, load_dtd=False)
    parser.resolvers.add(_LocalOnly())
    return etree.XMLSchema(etree.parse(str(SCHEMA_DIR / name), parser))


def schema_for(namespace: str | None) -> etree.XMLSchema:
    """The compiled bundled schema for an XPDL root namespace; :class:`SchemaUnavailable`
    saying why when there is none."""
    name = SCHEMA_FILES.get(namespace or NO_NAMESPACE)
    if name is None:
        raise SchemaUnavailable(_NO_SCHEMA.get(namespace or NO_NAMESPACE,
                                               f"no XPDL schema for namespace {namespace!r}"))
    return _compiled(name)


def _one_line(text: str) -> str:
    return " ".join(text.split())


def _readable(message: str, namespace: str | None) -> str:
    """libxml2's schema ``message`` as a sentence of opspec's: the file's own namespace left
    out of element names (``'{http://www.wfmc.org/2008/XPDL2.1}Bogus'`` is ``'Bogus'``; other
    namespaces stay), without the full stop that the hint's ``;`` would follow."""
    if namespace:
        message = message.replace("{" + namespace + "}", "")
    return message.rstrip().removesuffix(".")


def schema_errors(root: etree._Element) -> list[tuple[int | None, str]]:
    """``(line, message)`` of every schema error of the document of ``root`` (empty: valid).
    Raises :class:`SchemaUnavailable` when no schema is bundled for its namespace."""
    schema = schema_for(etree.QName(root).namespace)
    if schema.validate(root.getroottree()):
        return []
    return [(error.line or None, _one_line(error.message)) for error in schema.error_log]


def schema_diagnostics(path: str | Path, *, strict: bool = False) -> list[Diagnostic]:
    """``opspec validate --schema``: the schema errors of the file at ``path`` as diagnostics
    (code ``schema-invalid``, errors; at most :data:`MAX_ERRORS`, the last one saying how
    many more), or one ``no-schema`` warning when none is bundled for its namespace. A file
    the reader cannot read gives nothing here (validate reports it already)."""
    from opspec.xpdl.bpmn import is_bpmn
    from opspec.xpdl.reader import parse_safely, xpdl_outcome

    shown = str(path)
    try:
        parsed = parse_safely(read_file(path), path=shown)
        if is_bpmn(parsed.root):
            return [Diagnostic(SourceLocation(shown, 1), Severity.ERROR if strict else
                               Severity.WARNING, "no-schema",
                               "not schema-validated: this is a BPMN 2.0 file, and opspec "
                               "bundles only the WfMC XPDL schemas",
                               "validate it against the OMG BPMN 2.0 XSD in an XML tool or "
                               "your modeller (docs/bpmn.md)")]
        root = xpdl_outcome(parsed, path=shown).root
    except XmlReadError:
        return []
    try:
        errors = schema_errors(root)
    except SchemaUnavailable as missing:
        return [Diagnostic(SourceLocation(shown, 1), Severity.ERROR if strict else
                           Severity.WARNING, "no-schema",
                           f"not schema-validated: {missing}",
                           "validate it with the schema of its version in an XML tool")]
    except etree.XMLSchemaParseError as error:   # pragma: no cover - the bundled files compile
        return [Diagnostic(SourceLocation(shown, 1), Severity.ERROR, "no-schema",
                           f"the bundled schema does not compile: {_one_line(str(error))}",
                           "this is a bug in opspec; please report it")]
    namespace = etree.QName(root).namespace
    name = SCHEMA_FILES.get(namespace or NO_NAMESPACE, "")
    out = [Diagnostic(SourceLocation(shown, line), Severity.ERROR, "schema-invalid",
                      f"the WfMC schema {name} rejects this: {_readable(message, namespace)}",
                      "fix the element named (opspec itself reads many files the schema "
                      "rejects; --schema asks for the schema's verdict)")
           for line, message in errors[:MAX_ERRORS]]
    if len(errors) > MAX_ERRORS:
        last = out[-1]
        out[-1] = dataclasses.replace(
            last, message=f"{last.message} (and {len(errors) - MAX_ERRORS} more schema errors)")
    return out


def with_schema(diagnostics: Iterable[Diagnostic], path: str | Path, *, strict: bool = False
                ) -> tuple[Diagnostic, ...]:
    """``diagnostics`` (of ``opspec validate``) with the schema's added, sorted by line."""
    merged: list[Diagnostic] = [*diagnostics, *schema_diagnostics(path, strict=strict)]
    order = {p: n for n, p in enumerate(dict.fromkeys(d.location.path for d in merged))}
    merged.sort(key=lambda d: (order[d.location.path], d.location.line or 0))
    return tuple(merged)


def add_schema(report: FileReport, path: str | Path, *, strict: bool = False) -> FileReport:
    """A :class:`~opspec.xpdl.validate.FileReport` with the schema's diagnostics added
    (``opspec validate --schema``)."""
    return dataclasses.replace(report, diagnostics=with_schema(report.diagnostics, path,
                                                               strict=strict))


def unexplained(errors: Sequence[tuple[int | None, str]], explained: Iterable[str]
                ) -> list[tuple[int | None, str]]:
    """The schema errors whose message names none of the identity constraints in
    ``explained`` (e.g. ``SubFlowIdRef.Package``)."""
    names = tuple(explained)
    return [(line, message) for line, message in errors
            if not any(name in message for name in names)]


# The identity constraints of bpmnxpdl_31.xsd that opspec.xpdl.schema_limits explains in words.
_EXPLAINED: Final = {
    "used more than once in the package": "ActivityIds.Package",
    "one id space": "ProcessIds.Package",
    "SubFlow targets in the same package": "SubFlowIdRef.Package",
}


def output_schema_warnings(package: Package, data: bytes) -> list[Diagnostic]:
    """``opspec preprocess``: the ``not-schema-valid`` warnings of an output ``data`` written
    from ``package``: the rules :func:`~opspec.xpdl.schema_limits.schema_warnings` words
    (activity ids, process ids, external subflows), then, when the bundled XPDL 2.1 XSD
    rejects the output for anything else, one more naming its first such error."""
    from opspec.xpdl.schema_limits import schema_warnings

    worded = list(schema_warnings(package))
    explained = [name for d in worded for phrase, name in _EXPLAINED.items()
                 if phrase in d.message]
    root = etree.fromstring(data, etree.XMLParser(resolve_entities=False, no_network=True,
                                                  load_dtd=False, huge_tree=True))
    rest = unexplained(schema_errors(root), explained)
    if rest:
        line, message = rest[0]
        more = f" (and {len(rest) - 1} more)" if len(rest) > 1 else ""
        where = SourceLocation(package.source or "<package>",
                               package.location.line if package.location else None)
        worded.append(Diagnostic(
            where, Severity.WARNING, "not-schema-valid",
            f"the output will not be valid XPDL 2.1: bpmnxpdl_31.xsd rejects its line "
            f"{line}: {message}{more}",
            "opspec reads the output all the same; fix the input if it must pass the schema"))
    return worded
