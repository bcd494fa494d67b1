"""``opspec validate --strict`` over every BPMN and XPDL file of tests/ and specs/: a file that
uses a construct opspec runs differently from its standard never passes it silently."""

from __future__ import annotations

from pathlib import Path

import pytest
from lxml import etree

from opspec.errors import Severity
from opspec.xpdl.constructs import BPMN, CONSTRUCTS, XPDL, Kind, constructs_for
from opspec.xpdl.namespaces import is_xpdl_namespace
from opspec.xpdl.validate import validate_file

ROOT = Path(__file__).resolve().parents[2]
FILES = sorted(p for folder in ("tests", "specs") for p in (ROOT / folder).rglob("*")
               if p.suffix in (".bpmn", ".xpdl") and p.is_file())

# values with which an attribute entry's condition holds, judged here from the value alone
_HOLDS = {None: lambda v: True, "true": lambda v: v.strip().lower() == "true",
          "false": lambda v: v.strip().lower() == "false",
          "not-one": lambda v: v.strip() not in ("", "1"),
          "parallel": lambda v: v.strip().lower() == "parallel",
          "not-all": lambda v: v.strip() != "All"}


def _unconditional_uses(path: Path) -> list[str]:
    """Elements and attributes of the file the registry marks WARNS/REFUSES whose condition
    is their presence or their own value (read here with lxml, apart from the gate)."""
    try:
        root = etree.parse(str(path), etree.XMLParser(resolve_entities=False,
                                                      no_network=True)).getroot()
    except etree.XMLSyntaxError:
        return []
    space = etree.QName(root).namespace or ""
    key = BPMN if space == BPMN else XPDL if is_xpdl_namespace(space) else None
    if key is None:
        return []
    found = []
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        qname = etree.QName(element)
        if (qname.namespace or "") != (space or None) and (qname.namespace or "") != space:
            continue
        if any(etree.QName(a).localname in ("ExtendedAttribute", "extensionElements")
               for a in element.iterancestors()):
            continue
        entries = [(c, None) for c in constructs_for(key, qname.localname)]
        entries += [(c, a) for a in element.attrib if "}" not in a
                    for c in constructs_for(key, qname.localname, a)]
        for construct, attribute in entries:
            if construct.kind is Kind.RUNS or construct.when not in _HOLDS:
                continue
            if _HOLDS[construct.when](element.get(attribute) or "" if attribute else ""):
                found.append(f"{path.name}:{element.sourceline} {construct.key}")
    return found


def test_the_corpus_is_there():
    """The walk finds the corpus, and the corpus uses constructs run differently (so the
    test below checks something)."""
    assert len(FILES) > 50
    assert sum(1 for path in FILES if _unconditional_uses(path)) >= 3


@pytest.mark.parametrize("path", FILES, ids=[str(p.relative_to(ROOT)) for p in FILES])
def test_no_file_that_runs_differently_passes_strict(path: Path):
    """BPMN 2.0 §2.2.1: "Conformant implementations MUST fully support and interpret the
    underlying metamodel." What opspec does not run as written must make --strict fail: every
    runs-differently warning becomes an error, and a file using a construct the registry
    marks WARNS or REFUSES is never ok under --strict."""
    plain = validate_file(path)
    strict = validate_file(path, strict=True)
    # the gate's own codes, and the reader's codes the registry says already report a
    # construct (a transaction's "runs as a plain sub-process", for one)
    codes = {"runs-differently", "not-run"} | {c for k in CONSTRUCTS for c in k.reported_by}
    differently = [d for d in plain.diagnostics if d.code in codes]
    uses = _unconditional_uses(path)
    if uses:
        assert differently, f"{uses} used but not reported"
    if differently:
        assert not strict.ok
        promoted = [d for d in strict.diagnostics if d.code in ("runs-differently", "not-run")]
        assert all(d.severity is Severity.ERROR for d in promoted)
        assert all(d.location.line is not None for d in promoted)
