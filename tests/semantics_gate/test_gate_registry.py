"""The construct registry is complete: every element and attribute the bundled XSDs declare
(XPDL 2.1, WfMC-TC-1025; OMG BPMN 2.0 Semantic.xsd and its diagram interchange schemas) is
either classified (RUNS / WARNS / REFUSES) or judged to have no execution semantics, with a
reason; and docs/semantics.md's table is the registry's."""

from __future__ import annotations

from pathlib import Path

import pytest
from xsd_walk import Schema

from opspec.xpdl.constructs import (
    BPMN,
    CONSTRUCTS,
    INERT,
    XPDL,
    Kind,
    constructs_for,
    is_inert,
)
from opspec.xpdl.constructs_table import markdown_table
from opspec.xpdl.gate import CONDITIONS

SCHEMAS = Path(__file__).resolve().parents[2] / "opspec" / "xpdl" / "schemas"
BPMN20 = SCHEMAS / "bpmn20"
DOCS = Path(__file__).resolve().parents[2] / "docs" / "semantics.md"

# XPDL 2.2 elements the reader reads (no 2.2 schema is bundled)
XPDL_22_ONLY = ("TaskBusinessRule", "TriggerEscalation")

# (files of one target namespace, the registry's namespace for them)
SETS = {
    "bpmn": ((BPMN20 / "Semantic.xsd", BPMN20 / "BPMN20.xsd"), BPMN),
    "bpmndi": ((BPMN20 / "BPMNDI.xsd",), None),
    "dc": ((BPMN20 / "DC.xsd",), None),
    "di": ((BPMN20 / "DI.xsd",), None),
    "xpdl21": ((SCHEMAS / "bpmnxpdl_31.xsd",), XPDL),
}


def _pairs(name: str) -> tuple[str, set[tuple[str, str | None]]]:
    files, namespace = SETS[name]
    schema = Schema(*files)
    return namespace or schema.namespace, schema.pairs()


@pytest.mark.parametrize("name", sorted(SETS))
def test_every_element_and_attribute_is_classified(name: str) -> None:
    """BPMN 2.0 §2.2.1 (Process Execution Conformance): "Conformant implementations MUST fully
    support and interpret the underlying metamodel." — so every element and attribute of the
    schema is either run (as the standard says, or differently, said at its line) or has no
    execution semantics, for a stated reason ("The tool claiming Process Execution
    Conformance type is not expected to support and interpret Choreography models.")."""
    namespace, pairs = _pairs(name)
    assert len(pairs) > (300 if name in ("bpmn", "xpdl21") else 1)   # the walk found them
    missing = sorted((element, attribute or "") for element, attribute in pairs
                     if not constructs_for(namespace, element, attribute)
                     and is_inert(namespace, element, attribute) is None)
    assert not missing, (f"{len(missing)} elements/attributes of {name} are neither in "
                         f"the registry's CONSTRUCTS (opspec/xpdl/constructs_bpmn.py, "
                         f"constructs_xpdl.py) nor in INERT (constructs_inert.py): {missing}")


@pytest.mark.parametrize("name", ["bpmn", "xpdl21"])
def test_nothing_is_both_classified_and_inert(name: str) -> None:
    """A construct with execution semantics cannot also be judged to have none (an INERT group
    that names the element explicitly and a registry entry for the same pair contradict)."""
    namespace, pairs = _pairs(name)
    both = []
    for element, attribute in pairs:
        if not constructs_for(namespace, element, attribute):
            continue
        for group in INERT:
            if group.namespace != namespace or element not in group.elements:
                continue
            covers = (group.include_elements if attribute is None
                      else attribute in group.attributes or "*" in group.attributes)
            if covers:
                both.append((element, attribute, group.reason))
    assert not both


def test_registry_names_exist_in_the_schemas() -> None:
    """A registry entry names elements and attributes the standards declare (a misspelt one
    would never match a file): BPMN's in Semantic.xsd, XPDL's in the 2.1 or 1.0 schema."""
    known = {BPMN: _pairs("bpmn")[1]}
    xpdl = set(_pairs("xpdl21")[1])
    xpdl |= Schema(SCHEMAS / "TC-1025_schema_10_xpdl.xsd").pairs()
    known[XPDL] = xpdl | {(name, None) for name in XPDL_22_ONLY}
    elements = {ns: {e for e, _a in pairs} for ns, pairs in known.items()}
    wrong = []
    for construct in CONSTRUCTS:
        for element in construct.elements:
            if construct.attribute is None:
                if element not in elements[construct.namespace]:
                    wrong.append((construct.key, element))
            elif (element, construct.attribute) not in known[construct.namespace]:
                wrong.append((construct.key, element, construct.attribute))
    assert not wrong


def test_entries_are_well_formed() -> None:
    """Each entry has a unique key, a condition the gate knows, a text and a section; the
    docs table lists exactly the entries opspec does not run as the standard says."""
    keys = [c.key for c in CONSTRUCTS]
    assert len(keys) == len(set(keys))
    for construct in CONSTRUCTS:
        assert construct.when is None or construct.when in CONDITIONS, construct.key
        assert construct.text and construct.section, construct.key
    rows = markdown_table().splitlines()[2:]
    assert len(rows) == sum(1 for c in CONSTRUCTS if c.kind is not Kind.RUNS)
    for group in INERT:
        assert group.reason


def test_docs_table_is_the_registry() -> None:
    """docs/semantics.md's table of what opspec runs differently is generated from the
    registry (`python -m opspec.xpdl.constructs`): the two never differ."""
    text = DOCS.read_text(encoding="utf-8")
    start = text.index("<!-- constructs table: begin")
    start = text.index("\n", start) + 1
    end = text.index("<!-- constructs table: end -->")
    assert text[start:end] == markdown_table(), (
        "docs/semantics.md is out of date: paste `python -m opspec.xpdl.constructs` between "
        "the constructs table markers")
