"""Property-based tests: garbage never crashes the parser, printed trees read back the same, and
the compiled evaluator agrees with the tree walker on random trees and data."""

from __future__ import annotations

import math
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from opspec.engine.conditions import compile_expression, evaluate
from opspec.errors import ExecutionError
from opspec.model.expression_text import is_reserved
from opspec.model.expressions import Binary, Call, Expression, Literal, Name, Unary
from opspec.model.functions import FUNCTIONS
from opspec.xpdl.conditions import ConditionSyntaxError, parse_condition, parse_expression, to_text

from .test_condition_parser import same

# Seeded (derandomized) so a failure reproduces on every machine; no deadline on a shared CPU.
SETTINGS = settings(derandomize=True, deadline=None, max_examples=300)

TOKENS = [
    "a", "b.c", "x1", "$y", "_z", "1", "2.5", "-", "+", "*", "/", "%", "(", ")", ",", ".",
    "==", "=", "===", "!=", "!==", "<>", "<", "<=", ">", ">=", "&&", "||", "!", "and", "or",
    "not", "true", "FALSE", "null", "'s'", '"t"', '"', "'", "\\", "abs", "max", "equals",
    "compareTo", "Math", "x.equals(", ";", "&", "|", "?", ":", "[", "]", "\n", " ", "0x",
    "1e", "<![CDATA[", "]]>", "var", "new", "ü", "\u200b", "\x00",
]


def parse_or_syntax_error(text: str) -> None:
    try:
        parse_condition(text)
    except ConditionSyntaxError as error:
        assert error.column >= 1
        assert error.message.startswith("cannot read condition '")


@SETTINGS
@given(st.text())
def test_random_unicode_never_raises_anything_but_a_syntax_error(text: str) -> None:
    parse_or_syntax_error(text)


@SETTINGS
@given(st.text(alphabet=st.characters(min_codepoint=0, max_codepoint=127)))
def test_random_ascii_never_raises_anything_but_a_syntax_error(text: str) -> None:
    parse_or_syntax_error(text)


@SETTINGS
@given(st.lists(st.sampled_from(TOKENS), max_size=30), st.sampled_from(["", " "]))
def test_random_token_soup_never_raises_anything_but_a_syntax_error(
    tokens: list[str], separator: str
) -> None:
    parse_or_syntax_error(separator.join(tokens))


@settings(derandomize=True, deadline=None, max_examples=20)
@given(st.sampled_from(["(", "!", "-", "not ", "a.equals(", "abs(", "a + ", "a && "]))
def test_very_deep_nesting_is_a_syntax_error_not_a_recursion_error(prefix: str) -> None:
    parse_or_syntax_error(prefix * 5000 + "a")


# ----------------------------------------------------------------------- random trees

identifiers = st.from_regex(r"[A-Za-z_$][A-Za-z0-9_$]{0,6}", fullmatch=True)
roots = identifiers.filter(lambda word: not is_reserved(word))
names = st.builds(
    lambda root, rest: Name((root, *rest)), roots, st.lists(identifiers, max_size=2)
)
literals = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**15), max_value=10**15),
    st.floats(allow_nan=False),
    st.text(max_size=8),
).map(Literal)
UNARY = ["not", "neg"]
BINARY = ["and", "or", "==", "!=", "<", "<=", ">", ">=", "+", "-", "*", "/", "%"]


def calls(children: st.SearchStrategy[Expression]) -> st.SearchStrategy[Expression]:
    def build(name: str) -> st.SearchStrategy[Expression]:
        signature = FUNCTIONS[name]
        most = signature.max_args if signature.max_args is not None else 3
        return st.lists(children, min_size=signature.min_args, max_size=most).map(
            lambda args: Call(name, tuple(args))
        )

    return st.sampled_from(sorted(FUNCTIONS)).flatmap(build)


def trees(leaves: st.SearchStrategy[Expression]) -> st.SearchStrategy[Expression]:
    return st.recursive(
        leaves,
        lambda children: st.one_of(
            st.builds(Unary, st.sampled_from(UNARY), children),
            st.builds(Binary, st.sampled_from(BINARY), children, children),
            calls(children),
        ),
        max_leaves=12,
    )


@SETTINGS
@given(trees(st.one_of(literals, names)))
def test_printed_trees_read_back_to_the_same_tree(expr: Expression) -> None:
    text = to_text(expr)
    assert same(parse_expression(text), expr), text


# ------------------------------------------------------------- walker == compiled

small_literals = st.one_of(
    st.none(), st.booleans(), st.integers(-3, 3), st.sampled_from([0.5, -1.5, 0.0, 2.0]),
    st.sampled_from(["", "3", "abc", "true", "FALSE", "2.5"]),
).map(Literal)
field_names = st.sampled_from(["a", "b", "c", "missing"]).map(lambda name: Name((name,)))
field_values = st.one_of(
    st.none(), st.booleans(), st.integers(-3, 3), st.floats(allow_nan=True, width=16),
    st.sampled_from(["", "0", "3", "x", "true", "False"]),
)


def outcome(run: Any) -> tuple[str, Any]:
    try:
        return "value", run()
    except ExecutionError as error:
        return "error", error.message


@SETTINGS
@given(
    trees(st.one_of(small_literals, field_names)),
    st.fixed_dictionaries({"a": field_values, "b": field_values, "c": field_values}),
    st.floats(min_value=0, max_value=10 * 86400),
)
def test_compiled_expressions_agree_with_the_tree_walker(
    expr: Expression, data: dict[str, Any], now: float
) -> None:
    walked = outcome(lambda: evaluate(expr, data, clock=lambda: now))
    fast = outcome(lambda: compile_expression(expr)(data, now))
    assert walked[0] == fast[0], (walked, fast)
    if walked[0] == "error":
        assert walked[1] == fast[1]
    else:
        a, b = walked[1], fast[1]
        assert type(a) is type(b)
        assert a == b or (isinstance(a, float) and math.isnan(a) and math.isnan(b))
