"""Condition text from real XPDL files reads into the canonical expression tree."""

from __future__ import annotations

import pytest

from opspec.errors import Severity, SourceLocation, SpecError
from opspec.model.expressions import Binary, Call, Expression, Literal, Name, Unary
from opspec.xpdl.conditions import (
    FUNCTIONS,
    ConditionSyntaxError,
    names_used,
    parse_condition,
    parse_expression,
    to_text,
)


def n(*path: str) -> Name:
    return Name(path)


def lit(value: str | float | bool | None) -> Literal:
    return Literal(value)


def same(a: Expression, b: Expression) -> bool:
    """Tree equality that also tells 1, 1.0 and True apart (dataclass == does not)."""
    if isinstance(a, Literal) and isinstance(b, Literal):
        return type(a.value) is type(b.value) and a.value == b.value
    if type(a) is not type(b):
        return False
    if isinstance(a, Name):
        return a == b
    if isinstance(a, Unary) and isinstance(b, Unary):
        return a.op == b.op and same(a.operand, b.operand)
    if isinstance(a, Binary) and isinstance(b, Binary):
        return a.op == b.op and same(a.left, b.left) and same(a.right, b.right)
    if isinstance(a, Call) and isinstance(b, Call):
        return (
            a.function == b.function
            and len(a.args) == len(b.args)
            and all(same(x, y) for x, y in zip(a.args, b.args))
        )
    return False


FORMS: list[tuple[str, str, Expression]] = [
    # (id, text, tree)
    ("js-equality", 'status=="approved"', Binary("==", n("status"), lit("approved"))),
    ("single-quotes", "decision == 'accept'", Binary("==", n("decision"), lit("accept"))),
    ("greater-than-int", "amount > 1000", Binary(">", n("amount"), lit(1000))),
    ("bang-not", "!approved", Unary("not", n("approved"))),
    ("single-equals-is-equality", "x = 'y'", Binary("==", n("x"), lit("y"))),
    ("triple-equals", "a === 1", Binary("==", n("a"), lit(1))),
    ("not-equals", "a != 1", Binary("!=", n("a"), lit(1))),
    ("strict-not-equals", "a !== 1", Binary("!=", n("a"), lit(1))),
    ("sql-not-equals", "a <> 1", Binary("!=", n("a"), lit(1))),
    ("unicode-not-equals", "a ≠ 1", Binary("!=", n("a"), lit(1))),
    ("less", "a < 1", Binary("<", n("a"), lit(1))),
    ("less-equal", "a <= 1", Binary("<=", n("a"), lit(1))),
    ("greater-equal", "a >= 1", Binary(">=", n("a"), lit(1))),
    ("unicode-less-equal", "a ≤ 1", Binary("<=", n("a"), lit(1))),
    ("and-symbol", "a && b", Binary("and", n("a"), n("b"))),
    ("or-symbol", "a || b", Binary("or", n("a"), n("b"))),
    ("and-word", "a and b", Binary("and", n("a"), n("b"))),
    ("AND-word-uppercase", "a AND b", Binary("and", n("a"), n("b"))),
    ("Or-word-mixed-case", "a Or b", Binary("or", n("a"), n("b"))),
    ("not-word", "not publish", Unary("not", n("publish"))),
    ("NOT-word-uppercase", "NOT publish", Unary("not", n("publish"))),
    ("plus", "a + 1", Binary("+", n("a"), lit(1))),
    ("minus", "a - 1", Binary("-", n("a"), lit(1))),
    ("times", "a * 2", Binary("*", n("a"), lit(2))),
    ("divide", "a / 2", Binary("/", n("a"), lit(2))),
    ("remainder", "a % 2", Binary("%", n("a"), lit(2))),
    ("unary-minus-name", "-a", Unary("neg", n("a"))),
    ("negative-literal", "-1", lit(-1)),
    ("unary-plus-dropped", "+a", n("a")),
    ("parentheses", "(a)", n("a")),
    ("escaped-double-quote", r'"say \"hi\""', lit('say "hi"')),
    ("escaped-single-quote", r"'it\'s'", lit("it's")),
    ("escape-newline-tab", r'"a\nb\tc"', lit("a\nb\tc")),
    ("escape-unicode", r'"caf\u00e9"', lit("café")),
    ("escape-backslash", r'"a\\b"', lit("a\\b")),
    ("int", "42", lit(42)),
    ("float", "2.5", lit(2.5)),
    ("float-leading-dot", ".5", lit(0.5)),
    ("float-exponent", "1e3", lit(1000.0)),
    ("hex", "0x1F", lit(31)),
    ("java-long-suffix", "100L", lit(100)),
    ("java-float-suffix", "1.5f", lit(1.5)),
    ("true", "true", lit(True)),
    ("TRUE-uppercase", "TRUE", lit(True)),
    ("False-capitalised", "False", lit(False)),
    ("null", "null", lit(None)),
    ("NULL-uppercase", "NULL", lit(None)),
    ("python-None", "None", lit(None)),
    ("dotted-name", "order.total", n("order", "total")),
    ("dollar-name", "$amount", n("$amount")),
    ("underscore-name", "_x1", n("_x1")),
    ("unicode-name", "benötigt", n("benötigt")),
    ("java-equals", 'x.equals("y")', Binary("==", n("x"), lit("y"))),
    ("java-equals-literal-first", '"y".equals(x)', Binary("==", lit("y"), n("x"))),
    ("java-not-equals", '!decision.equals("oui")',
     Unary("not", Binary("==", n("decision"), lit("oui")))),
    ("java-equals-ignore-case", 'x.equalsIgnoreCase("Y")',
     Binary("==", Call("lower", (n("x"),)), Call("lower", (lit("Y"),)))),
    ("java-compareTo", 'requestFound.compareTo("yes") == 0',
     Binary("==", Call("compare", (n("requestFound"), lit("yes"))), lit(0))),
    ("java-Boolean-valueOf", 'isGranted.compareTo(Boolean.valueOf("false")) == 0',
     Binary("==", Call("compare", (n("isGranted"), Call("bool", (lit("false"),)))), lit(0))),
    ("java-indexOf", "whereToGo.indexOf('B') != -1",
     Binary("!=", Call("find", (n("whereToGo"), lit("B"))), lit(-1))),
    ("java-chained-methods", 'x.toLowerCase().startsWith("a")',
     Call("startswith", (Call("lower", (n("x"),)), lit("a")))),
    ("java-length", "s.length() > 0", Binary(">", Call("len", (n("s"),)), lit(0))),
    ("java-isEmpty", "s.isEmpty()", Binary("==", Call("len", (n("s"),)), lit(0))),
    ("java-Math-max", "Math.max(a, 2)", Call("max", (n("a"), lit(2)))),
    ("java-Integer-parseInt", 'Integer.parseInt(s)', Call("int", (n("s"),))),
    ("js-parseFloat", "parseFloat(s)", Call("float", (n("s"),))),
    ("method-on-dotted-name", 'order.state.equals("open")',
     Binary("==", n("order", "state"), lit("open"))),
    ("whitelisted-function-as-method", "name.upper()", Call("upper", (n("name"),))),
    ("call-no-args", "hour() >= 8", Binary(">=", Call("hour", ()), lit(8))),
    ("call-min-variadic", "min(a, b, c)", Call("min", (n("a"), n("b"), n("c")))),
    ("range-chain", "0 <= Entity.Cost <= 5000",
     Binary("and", Binary("<=", lit(0), n("Entity", "Cost")),
            Binary("<=", n("Entity", "Cost"), lit(5000)))),
    ("trailing-semicolon", "Field==true;", Binary("==", n("Field"), lit(True))),
    ("newlines-and-padding", "\n   a\n  &&\n b  \n", Binary("and", n("a"), n("b"))),
    ("cdata-wrapper", "<![CDATA[ a > 1 ]]>", Binary(">", n("a"), lit(1))),
    ("no-spaces", "openedBranchesAfterA==0", Binary("==", n("openedBranchesAfterA"), lit(0))),
    ("bizagi-probability", "0.7", lit(0.7)),
]


@pytest.mark.parametrize(("text", "tree"), [f[1:] for f in FORMS], ids=[f[0] for f in FORMS])
def test_every_supported_form_reads_into_its_canonical_tree(text: str, tree: Expression) -> None:
    parsed = parse_condition(text)
    assert parsed is not None and same(parsed, tree), parsed


PRECEDENCE = [
    ("and-binds-tighter-than-or", "a || b && c",
     Binary("or", n("a"), Binary("and", n("b"), n("c")))),
    ("comparison-binds-tighter-than-and", "n < 3 && !done",
     Binary("and", Binary("<", n("n"), lit(3)), Unary("not", n("done")))),
    ("times-binds-tighter-than-plus", "a + b * c",
     Binary("+", n("a"), Binary("*", n("b"), n("c")))),
    ("minus-is-left-associative", "a - b - c",
     Binary("-", Binary("-", n("a"), n("b")), n("c"))),
    ("parentheses-override", "(a + b) * c",
     Binary("*", Binary("+", n("a"), n("b")), n("c"))),
    ("bang-binds-tightly-like-javascript", "!a == b",
     Binary("==", Unary("not", n("a")), n("b"))),
    ("not-word-binds-loosely-like-python", "not a == b",
     Unary("not", Binary("==", n("a"), n("b")))),
    ("not-word-stops-at-and", "not a and b",
     Binary("and", Unary("not", n("a")), n("b"))),
    ("ordering-binds-tighter-than-equality", "a < b == true",
     Binary("==", Binary("<", n("a"), n("b")), lit(True))),
    ("unary-minus-binds-tighter-than-times", "-a * b",
     Binary("*", Unary("neg", n("a")), n("b"))),
    ("arithmetic-binds-tighter-than-comparison", "a + 1 > b * 2",
     Binary(">", Binary("+", n("a"), lit(1)), Binary("*", n("b"), lit(2)))),
    ("equality-is-left-associative", "a == b != c",
     Binary("!=", Binary("==", n("a"), n("b")), n("c"))),
    ("or-is-left-associative", "a || b || c",
     Binary("or", Binary("or", n("a"), n("b")), n("c"))),
]


@pytest.mark.parametrize(("text", "tree"), [p[1:] for p in PRECEDENCE], ids=[p[0] for p in PRECEDENCE])
def test_operators_bind_in_the_documented_order(text: str, tree: Expression) -> None:
    assert same(parse_expression(text), tree)


@pytest.mark.parametrize("text", [None, "", "   ", "\n\t  \n", "<![CDATA[   ]]>", " ; "],
                         ids=["none", "empty", "spaces", "newlines", "empty-cdata", "semicolon"])
def test_an_empty_condition_means_no_condition(text: str | None) -> None:
    assert parse_condition(text) is None


def test_parse_expression_refuses_empty_text() -> None:
    with pytest.raises(ConditionSyntaxError, match="the expression is empty"):
        parse_expression("  ")


BAD = [
    # (id, text, column, message fragment)
    ("missing-right-operand", "a == ", 6, "expected a value after '=='"),
    ("missing-operand-after-and", "a &&", 5, "expected a value after '&&'"),
    ("two-names-no-operator", "Individualteile benötigt", 17, "two values with no operator"),
    ("single-ampersand", "a & b", 3, "write '&&'"),
    ("single-pipe", "a | b", 3, "write '||'"),
    ("unclosed-parenthesis", "(a == 1", 8, "expected ')' to close the '(' at column 1"),
    ("stray-closing-parenthesis", "a == 1)", 7, "')' has no matching '('"),
    ("unterminated-string", 'a == "abc', 6, "never closed"),
    ("unknown-function", "foo(x)", 1, "unknown function 'foo'"),
    ("wrong-arity", "abs(1, 2)", 1, "abs() takes 1 argument, not 2"),
    ("unknown-method", "x.frobnicate()", 1, "unsupported method .frobnicate()"),
    ("unknown-static-method", "Math.sqrt(x)", 1, "unsupported method Math.sqrt()"),
    ("ternary", "a ? b : c", 3, "?: operator is not supported"),
    ("indexing", "a[0]", 2, "indexing"),
    ("number-glued-to-word", "5days", 2, "right after the number 5"),
    ("two-statements", "a; b", 2, "only one expression"),
    ("script", "var d = new Date();", 1, "script statement"),
    ("leading-and", "and a", 1, "expected a value before 'and'"),
    ("dot-without-name", "a. == 1", 4, "expected a name after '.'"),
    ("member-of-literal", '"x".y', 5, "only data fields have members"),
    ("bad-unicode-escape", r'"\u12"', 2, "needs 4 hex digits"),
    ("lone-operator", "==", 1, "expected a value but found '=='"),
    ("too-deep", "(" * 150 + "a" + ")" * 150, 101, "nested more than 100 levels"),
    ("too-many-digits", "1" * 500, 1, "too many digits"),
]


@pytest.mark.parametrize(("text", "column", "fragment"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_unreadable_conditions_name_the_column_and_the_problem(
    text: str, column: int, fragment: str
) -> None:
    with pytest.raises(ConditionSyntaxError) as caught:
        parse_condition(text)
    error = caught.value
    assert error.column == column
    assert fragment in error.message
    assert error.message.startswith("cannot read condition '")
    assert f"at column {column}: " in error.message


def test_error_message_has_the_documented_shape() -> None:
    with pytest.raises(ConditionSyntaxError) as caught:
        parse_condition("a == ")
    assert caught.value.message == "cannot read condition 'a == ' at column 6: expected a value after '=='"


def test_error_in_multiline_text_names_line_and_column() -> None:
    with pytest.raises(ConditionSyntaxError, match=r"at line 2, column 5: ") as caught:
        parse_condition("a ==\n  1 1")
    assert (caught.value.line, caught.value.column) == (2, 5)


def test_syntax_error_is_a_spec_error_carrying_the_file_location() -> None:
    location = SourceLocation("specs/pump.xpdl", 212)
    with pytest.raises(SpecError, match=r"^specs/pump\.xpdl:212: cannot read condition 'a =='"):
        parse_condition("a ==", location=location)


def test_syntax_error_becomes_a_load_time_diagnostic() -> None:
    location = SourceLocation("specs/pump.xpdl", 7)
    with pytest.raises(ConditionSyntaxError) as caught:
        parse_condition("a &", location=location)
    diagnostic = caught.value.to_diagnostic()
    assert diagnostic.location == location
    assert diagnostic.severity is Severity.ERROR
    assert diagnostic.code == "bad-condition"
    assert str(diagnostic).startswith("specs/pump.xpdl:7: error: cannot read condition 'a &'")


def test_names_used_lists_root_names_only() -> None:
    expr = parse_expression('order.total > limit && lower(status) == "ok" || 1 + n.x.y > 0')
    assert names_used(expr) == frozenset({"order", "limit", "status", "n"})


def test_literals_alone_use_no_names() -> None:
    assert names_used(parse_expression('1 + 2 == 3 && "a" != "b" && now() > 0')) == frozenset()


def test_printer_writes_javascript_like_text_with_minimal_parentheses() -> None:
    expr = parse_expression("not (a or b) and x.equals('it\"s') and -(1) < -2 and (0 <= y <= 5)")
    text = to_text(expr)
    assert text == '!(a || b) && x == "it\\"s" && -(1) < -2 && (0 <= y && y <= 5)'
    assert same(parse_expression(text), expr)


@pytest.mark.parametrize(
    "expr",
    [Name(("true",)), Name(("a b",)), Literal(float("nan"))],
    ids=["reserved-root", "name-with-space", "nan"],
)
def test_printer_refuses_trees_no_text_can_express(expr: Expression) -> None:
    with pytest.raises(ValueError):
        to_text(expr)


def test_whitelist_has_the_documented_functions() -> None:
    required = {
        "abs", "min", "max", "round", "floor", "ceil", "len", "lower", "upper", "contains",
        "startswith", "endswith", "str", "int", "float", "bool", "now", "time_of_day", "hour",
        "day",
    }
    assert required <= set(FUNCTIONS)
    assert FUNCTIONS["now"].accepts(0) and not FUNCTIONS["now"].accepts(1)
    assert FUNCTIONS["max"].accepts(5)
