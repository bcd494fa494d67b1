"""Every real-world XPDL file of the shared corpus either loads, with its processes, activities
and transitions counted exactly as in the file, or is rejected with one clean error naming
file:line.

The counts are checked against an independent walk of the raw XML (local names in any XPDL
namespace, outside ExtendedAttribute contents), so the front end cannot agree with itself.
Files not listed in ``EXPECTED`` (for instance added later) get the default rule: well-formed
files load, the others are rejected.

"Clean" here means: the reader builds the package without an error diagnostic. It says nothing
about the structural checks ``opspec validate`` adds (dangling transitions, undefined
participants, …); which corpus files those reject, and why, is recorded in
tests/validate/test_corpus_validate.py. Nor does loading mean a file follows its own XPDL
schema: opspec reads many files the official schemas reject, and ``FAILS_ITS_SCHEMA`` lists
them (checked below against the schemas in the corpus).
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import pytest
from lxml import etree

from opspec.errors import Severity
from opspec.xpdl import load_package
from opspec.xpdl.namespaces import is_xpdl_namespace

CORPUS = Path("/work/shared/corpus/xpdl")
if not CORPUS.is_dir():  # pragma: no cover - the corpus lives beside the repository
    CORPUS = Path(__file__).resolve().parents[3] / "shared" / "corpus" / "xpdl"
FILES = sorted(CORPUS.glob("*.xpdl")) if CORPUS.is_dir() else []


class Expect(NamedTuple):
    loads: bool           # a package is built
    clean: bool           # no error diagnostic from the reader (validate's checks may add some)
    why: str


LOADS = Expect(True, True, "well-formed XPDL the reader builds without an error")

SCHEMAS = Path(CORPUS).parent / "schemas"
# Namespace -> the official schema in the corpus. The XPDL 2.0 schema there does not compile
# (a dangling ref to StartMode), and there is none for XPDL 2.2 or for files without a
# namespace: such files are not schema-checked.
SCHEMA_FILES = {
    "http://www.wfmc.org/2002/XPDL1.0": "TC-1025_schema_10_xpdl.xsd",
    "http://www.wfmc.org/2008/XPDL2.1": "bpmnxpdl_31.localimport.xsd",
}
# Files that load although their own schema rejects them, with the first thing it rejects.
FAILS_ITS_SCHEMA: dict[str, str] = {
    "bonita-simprocess__Example6.xpdl": "text inside an empty Join element (line 124)",
    "g360__Subprocess.xpdl": "ConformanceClass before PackageHeader (line 3)",
    "g360__Subprocess4_with_exception.xpdl": "ActivitySets after Activities (line 104)",
    "jawe21__Business_Example.xpdl": "SubFlow into an external package (line 448)",
    "tibcofrg___GM0bEEeyEd-eq-1NLZ2xQg.frg.xpdl": "a fragment: Package without Id (line 2)",
    "tibcofrg___GPkNEEeyEd-eq-1NLZ2xQg.frg.xpdl": "TriggerTimer without a time (line 115)",
    "tibcofrg___GPn3cEeyEd-eq-1NLZ2xQg__es_AR.frg.xpdl": "TIBCO element out of place (line 86)",
    "tibcofrg___GQAR8EeyEd-eq-1NLZ2xQg.frg.xpdl": "WebServiceOperation without OperationName "
                                                  "(line 166)",
    "wfmc__deadline.xpdl": "NodeGraphicsInfo naming a lane no pool declares (line 89)",
}
EXPECTED: dict[str, Expect] = {
    # Bizagi 2.1/2.2 exports: gateways without GatewayType, nested lanes, BPMN events.
    "bizagi21__Test_multiple_workflow_processes.xpdl": LOADS,
    "bizagi22__Diagram_1.xpdl": LOADS,
    "bizagi22__diagram1.xpdl": LOADS,
    "bizagi22__diagram3.xpdl": LOADS,
    # Bonita (XPDL 1.0): Tool, StartMode elements, AND/XOR restrictions, subflows.
    "bonita-bull__splits_joins_complex.xpdl": LOADS,
    "bonita-nova__suspendResume.xpdl": LOADS,
    "bonita-simprocess__Example6.xpdl": LOADS,
    "bonita__ApprovalWorkflow.xpdl": LOADS,
    "bonita__Habilitation.xpdl": LOADS,
    "bonita__InputOutputConnector.xpdl": LOADS,
    "bonita__activityHook-v4.xpdl": LOADS,
    "bonita__arbitraryCycle.xpdl": LOADS,
    "bonita__carpool.xpdl": LOADS,
    "bonita__mainSubflowJoinXor.xpdl": LOADS,
    "bonita__subflowParams-sub.xpdl": LOADS,
    "bonita__subflowParams.xpdl": LOADS,
    # Bonita's own negative test: </Version> closed by </RedefinableHeader> at line 28.
    "bonita__testManagementAPIWithParsingError.xpdl": Expect(
        False, False, "not well-formed (tag mismatch at line 28): rejected with file:28"),
    # A schema-walk test artefact with placeholder values ("Id", "Value") everywhere and no
    # namespace: it loads (read with 2.x names) but reports duplicate lane ids, unresolvable
    # ExternalPackage href="Href", and <Transactions> used for <Transitions> (read, warned).
    "bpmve__PackageBasic.xpdl": Expect(True, False, "placeholder values: loads with errors"),
    # XPDL 2.0 sample with deprecated 1.0-namespace SubFlow elements and "3 days" deadlines.
    "bpmxpdl20__sample.xpdl": LOADS,
    # Global 360 exports (2.1): lanes whose ParentLane is the pool, attached events.
    "g360__Subprocess.xpdl": LOADS,
    "g360__Subprocess4_with_exception.xpdl": LOADS,
    "g360__Three_tasks_and_event_gateway.xpdl": LOADS,
    "g360__complex.xpdl": LOADS,
    "g360__dfs.xpdl": LOADS,
    # JaWE 1.0 examples ("Invalid" ones break conformance classes, not the syntax we read).
    "jawe10__LoopBlocked.xpdl": LOADS,
    "jawe10__document_approval.xpdl": LOADS,
    "jawe10__leave_request.xpdl": LOADS,
    "jawe10__sample_workflow_process.xpdl": LOADS,
    "jawe10__workflow_patterns.xpdl": LOADS,
    # JaWE 2.1: repositories with no processes, and ExternalPackage hrefs to renamed files that
    # are found beside them by Package Id.
    "jawe21__Application_Repository.xpdl": LOADS,
    "jawe21__Business_Example.xpdl": LOADS,
    "jawe21__Participant_Repository.xpdl": LOADS,
    "jawe21__Process_Repository.xpdl": LOADS,
    "jawe21__leave_request.xpdl": LOADS,
    "jawe21__nested_lanes.xpdl": LOADS,
    # TIBCO Business Studio: its conditions here are German prose ("Individualteile
    # benötigt"), which no engine can evaluate: loads with bad-condition errors.
    "tibco-af__Fallstudie_4-09_e-Car_Produktion.xpdl": Expect(
        True, False, "prose in transition conditions: bad-condition errors"),
    "tibco-af__Test_loop_2.xpdl": LOADS,
    "tibco-af__Test_multiple_pools_processes_and_lanes.xpdl": LOADS,
    "tibco__InsuranceClaimHandling.xpdl": LOADS,
    # TIBCO fragments: one without a Package Id (file name used), one declared ASCII.
    "tibcofrg___GM0bEEeyEd-eq-1NLZ2xQg.frg.xpdl": LOADS,
    "tibcofrg___GPkNEEeyEd-eq-1NLZ2xQg.frg.xpdl": LOADS,
    "tibcofrg___GPn3cEeyEd-eq-1NLZ2xQg__es_AR.frg.xpdl": LOADS,
    "tibcofrg___GQAR8EeyEd-eq-1NLZ2xQg.frg.xpdl": LOADS,
    # shoobx.wfmc: Python-expression deadlines (warned, kept as text), 1.0 publication sample.
    "wfmc__deadline.xpdl": LOADS,
    "wfmc__publication-1.0.xpdl": LOADS,
    "wfmc__subflow.xpdl": LOADS,
}


def _well_formed(path: Path) -> bool:
    try:
        etree.parse(str(path), etree.XMLParser(resolve_entities=False, no_network=True,
                                               load_dtd=False))
    except etree.XMLSyntaxError:
        return False
    return True


def _expected(path: Path) -> Expect:
    if path.name in EXPECTED:
        return EXPECTED[path.name]
    if _well_formed(path):
        return Expect(True, False, "unlisted well-formed file: must load")
    return Expect(False, False, "unlisted file that is not well-formed: rejected")


def _xpdl(element: etree._Element, local: str) -> bool:
    if not isinstance(element.tag, str):
        return False
    name = etree.QName(element)
    return name.localname == local and is_xpdl_namespace(name.namespace)


def _walk(element: etree._Element) -> list[etree._Element]:
    """XPDL elements below ``element``, not entering ExtendedAttribute contents."""
    out: list[etree._Element] = []
    stack = list(element)
    while stack:
        node = stack.pop()
        if not isinstance(node.tag, str):
            continue
        out.append(node)
        if not _xpdl(node, "ExtendedAttribute"):
            stack.extend(node)
    return out


def _raw_counts(path: Path) -> tuple[int, int, int]:
    root = etree.parse(str(path), etree.XMLParser(resolve_entities=False, no_network=True,
                                                  load_dtd=False)).getroot()
    processes = [e for e in _walk(root) if _xpdl(e, "WorkflowProcess")]
    inside = [e for p in processes for e in _walk(p)]
    return (len(processes), sum(_xpdl(e, "Activity") for e in inside),
            sum(_xpdl(e, "Transition") for e in inside))


@pytest.mark.skipif(not FILES, reason="shared corpus not present")
@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_corpus_file_loads_with_exact_counts_or_is_cleanly_rejected(path: Path) -> None:
    expect = _expected(path)
    result = load_package(path)
    codes = [d.code for d in result.diagnostics]
    assert "internal-error" not in codes, result.diagnostics
    if not expect.loads:
        assert result.package is None, expect.why
        assert result.diagnostics and result.diagnostics[0].severity is Severity.ERROR
        first = result.diagnostics[0]
        assert first.location.path == str(path) and first.location.line is not None
        return
    package = result.package
    assert package is not None, (expect.why, [str(d) for d in result.diagnostics])
    processes, activities, transitions = _raw_counts(path)
    assert len(package.processes) == processes
    assert sum(len(p.all_activities()) for p in package.processes) == activities
    assert sum(len(p.transitions) + sum(len(s.transitions) for s in p.activity_sets)
               for p in package.processes) == transitions
    if expect.clean:
        assert result.ok, [str(d) for d in result.errors]
    for diagnostic in result.diagnostics:  # every diagnostic names a file
        assert diagnostic.location.path


@pytest.fixture(scope="module")
def schemas() -> dict[str, etree.XMLSchema]:
    if not all((SCHEMAS / name).is_file() for name in SCHEMA_FILES.values()):
        pytest.skip("corpus schemas not present")
    return {ns: etree.XMLSchema(etree.parse(str(SCHEMAS / name)))
            for ns, name in SCHEMA_FILES.items()}


@pytest.mark.skipif(not FILES, reason="shared corpus not present")
@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_corpus_schema_claims_are_true(path: Path, schemas: dict[str, etree.XMLSchema]) -> None:
    if not _well_formed(path):
        pytest.skip("not well-formed: no schema applies")
    root = etree.parse(str(path), etree.XMLParser(resolve_entities=False, no_network=True,
                                                  load_dtd=False))
    schema = schemas.get(etree.QName(root.getroot()).namespace or "")
    if schema is None:
        assert path.name not in FAILS_ITS_SCHEMA, "no schema to fail"
        pytest.skip("no schema for its namespace in the corpus")
    valid = schema.validate(root)
    assert valid == (path.name not in FAILS_ITS_SCHEMA), (
        FAILS_ITS_SCHEMA.get(path.name), str(schema.error_log.last_error))


def test_corpus_has_the_documented_files() -> None:
    if not FILES:
        pytest.skip("shared corpus not present")
    assert {p.name for p in FILES} >= set(EXPECTED)
