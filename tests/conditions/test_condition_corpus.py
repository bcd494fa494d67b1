"""Every condition and deadline text of the shared real-world XPDL corpus reads as expected.

The texts are listed literally (so the test runs without the corpus); a second test walks the
corpus with lxml and checks that the lists are complete and current.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.model.expressions import Literal
from opspec.xpdl.conditions import ConditionSyntaxError, parse_condition
from opspec.xpdl.durations import parse_duration_expression

CORPUS = Path("/work/shared/corpus/xpdl")
if not CORPUS.is_dir():  # pragma: no cover - the corpus lives beside the repository
    CORPUS = Path(__file__).resolve().parents[3] / "shared" / "corpus" / "xpdl"

# Text of every <Condition> with text in the corpus (XPDL 1.0 text, 2.x <Expression> child).
READABLE_CONDITIONS = [
    '!cont.equals("un")', '!cont2.equals("un")', '!decision.equals("oui")',
    "0 <= Entity.Cost <= 5000", "0.7", "C_SKIP", 'Credit_Status == "OK"', "Field==true;",
    "LOOP", "NO_LOOP", 'Partial_Ship_Status == "OK"', "SKIP_INNER_LOOPS",
    'Stock_Status == "ALL"', 'Stock_Status == "PARTIAL"', "a<5", "accepted_by_system",
    'answerFound.compareTo("no") == 0 && answerTimeout.compareTo("no") == 0',
    'answerFound.compareTo("yes") == 0', 'answerTimeout.compareTo("yes") == 0',
    "approvedByPublisher", "approvedByReviewer", "approved_by_personnel",
    "approved_by_supervisor", "availableBranchesToAccessE>0", "c2", "c3",
    'cont.equals("un")', 'cont2.equals("un")', 'decision.equals("oui")', "ed_changes",
    "firedBranchesBeforeE == 0", "firedBranchesBeforeE > 0",
    'isGranted.compareTo(Boolean.valueOf("false")) == 0',
    'isGranted.compareTo(Boolean.valueOf("true")) == 0', "not publish", "notifyException",
    'offerTimeout.compareTo("yes") == 0', "openedBranchesAfterA == 0",
    "openedBranchesAfterA==0", "openedBranchesFromA == 0", 'orderType == "Credit"',
    'orderType == "PO"',
    'requestFound.compareTo("no") == 0 && offerTimeout.compareTo("no") == 0',
    'requestFound.compareTo("yes") == 0', 'status == "Accept"', 'status == "BadCredit"',
    'status == "Invalid Data"', 'status == "OverLimit"', 'status == "Valid Claim"',
    'status == "Valid Data"', 'staus == "Accept"', 'staus == "OverLimit"', "tech_changes",
    "timeout", "timeoutException", "whereToGo.indexOf('B') != -1",
    "whereToGo.indexOf('C') != -1", "whereToGo.indexOf('D') != -1", 'whereToGo=="B"',
    'whereToGo=="C"', 'whereToGo=="D"', 'whereToGo=="E"',
]
# Prose, not an expression: TIBCO writes it with ScriptGrammar="Text" (a label for people).
PROSE_CONDITIONS = {"Individualteile benötigt": 17}

# Text of every <DeadlineDuration>/<DeadlineCondition> in the corpus -> seconds, or None when
# it is an expression (not a plain duration), or an error fragment when it cannot be read.
DEADLINES: dict[str, float | str | None] = {
    "3 days": 3 * 86400.0,
    "5 days": 5 * 86400.0,
    "5000": 5000.0,  # Bonita means milliseconds here; plain numbers are seconds in opspec
    "None": None,  # Python's None: a null expression, the engine decides what it means
    "timedelta(seconds=3)": "unknown function 'timedelta'",  # Python code, not XPDL
    "var d=new java.util.Date();\nd.setTime(shark_activity_created_time.getTime()+60000);\nd;":
        "script statement",  # Shark/JaWE script computing a date
    "var d=new java.util.Date();\nd.setTime(shark_activity_created_time.getTime()"
    "+default_deadline_time);\nd;": "script statement",
}


@pytest.mark.parametrize("text", READABLE_CONDITIONS)
def test_every_real_world_condition_parses(text: str) -> None:
    assert parse_condition(text) is not None


@pytest.mark.parametrize(("text", "column"), PROSE_CONDITIONS.items())
def test_prose_conditions_are_clean_syntax_errors(text: str, column: int) -> None:
    with pytest.raises(ConditionSyntaxError, match="two values with no operator") as caught:
        parse_condition(text)
    assert caught.value.column == column


@pytest.mark.parametrize(("text", "expected"), DEADLINES.items(), ids=list(range(len(DEADLINES))))
def test_real_world_deadline_texts_read_as_expected(
    text: str, expected: float | str | None
) -> None:
    if isinstance(expected, str):
        with pytest.raises(ConditionSyntaxError, match=expected):
            parse_duration_expression(text)
    elif expected is None:
        assert parse_duration_expression(text) == Literal(None)
    else:
        result = parse_duration_expression(text)
        assert isinstance(result, Literal) and result.value == expected


def _corpus_texts(local_names: set[str]) -> set[str]:
    etree = pytest.importorskip("lxml.etree")
    parser = etree.XMLParser(resolve_entities=False, load_dtd=False, no_network=True)
    found: set[str] = set()
    for path in sorted(CORPUS.glob("*.xpdl")):
        try:
            tree = etree.parse(str(path), parser)
        except etree.XMLSyntaxError:
            continue  # the one malformed corpus file belongs to the reader's tests
        for element in tree.iter():
            if isinstance(element.tag, str) and etree.QName(element).localname in local_names:
                text = "".join(element.itertext()).strip()
                if text:
                    found.add(text)
    return found


@pytest.mark.skipif(not CORPUS.is_dir(), reason="shared corpus not present")
def test_condition_lists_cover_every_condition_in_the_corpus() -> None:
    assert _corpus_texts({"Condition"}) == set(READABLE_CONDITIONS) | set(PROSE_CONDITIONS)


@pytest.mark.skipif(not CORPUS.is_dir(), reason="shared corpus not present")
def test_deadline_list_covers_every_deadline_in_the_corpus() -> None:
    assert _corpus_texts({"DeadlineDuration", "DeadlineCondition"}) == set(DEADLINES)
