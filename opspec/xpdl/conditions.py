"""Read XPDL condition and expression text into :mod:`opspec.model.expressions` trees.

Real files write conditions in JavaScript-ish or Java-ish text. This module reads all of the
forms below with a small hand-written tokenizer and a Pratt (precedence-climbing) parser, and
never passes text to ``eval``. A parsing library (lark, pyparsing) would not shorten it much:
most of the code is the Java method mapping and the error messages with columns, which we would
write by hand either way, and hand-written error positions are better than a generic
"unexpected token".

Accepted, loosest binding first:

=====================  ===================================================================
``||``  ``or``          logical or (words case-insensitive: ``OR``, ``Or``)
``&&``  ``and``         logical and
``not x``               logical not, Python-like: ``not a == b`` is ``not (a == b)``
``== === = != !== <>``  equality; a single ``=`` means equality (there is no assignment)
``< <= > >=``           ordering; ``0 <= x <= 5000`` is read as ``0 <= x && x <= 5000``
``+ -``                 addition/concatenation, subtraction
``* / %``               multiplication, division, remainder
``!x  -x  +x``          prefix not (binds tightly, as in JavaScript: ``!a == b`` is
                        ``(!a) == b``), negation, and a no-op plus
``f(x)  x.m(y)``        whitelisted calls (:data:`FUNCTIONS`) and Java-ish methods
=====================  ===================================================================

Values: ``'text'`` and ``"text"`` with backslash escapes; integers, decimals, exponents,
``0x1F``, Java suffixes ``100L``/``1.5f``/``2d``; ``true``/``false``/``null`` in any case and
Python's ``None``; dotted data-field names (``order.total``, ``$amount``, ``_x``). Java forms
are mapped: ``x.equals(y)`` and ``"y".equals(x)`` to ``==``, ``equalsIgnoreCase``,
``compareTo`` (``compare``), ``indexOf`` (``find``), ``contains``, ``startsWith``,
``endsWith``, ``toLowerCase``, ``toUpperCase``, ``trim``, ``length()``, ``isEmpty()``,
``toString()``, ``Boolean.valueOf``, ``Integer.parseInt``, ``Double.parseDouble``,
``String.valueOf``, ``Math.abs/min/max/round/floor/ceil``. A whitelisted function name can also
be called as a method (``name.lower()``). A trailing ``;`` and a ``<![CDATA[...]]>`` wrapper
are ignored.

Everything else is a :class:`ConditionSyntaxError` naming the column of the problem.
"""

from __future__ import annotations

from collections.abc import Callable

from opspec.errors import Diagnostic, Severity, SourceLocation, SpecError
from opspec.model.expression_text import PRECEDENCE, SCRIPT_WORDS, to_text
from opspec.model.expressions import Binary, Call, Expression, Literal, Name, Unary
from opspec.model.functions import FUNCTIONS, TIME_FUNCTIONS, FunctionSignature
from opspec.xpdl.condition_tokens import Token, Tokenizer, unwrap

__all__ = [
    "FUNCTIONS",
    "MAX_DEPTH",
    "MAX_LENGTH",
    "ConditionSyntaxError",
    "FunctionSignature",
    "names_used",
    "parse_condition",
    "parse_expression",
    "to_text",
]

MAX_LENGTH = 20_000
"""Longest text accepted (characters); real conditions are a few dozen."""
MAX_DEPTH = 100
"""Deepest tree accepted; keeps evaluation and printing far from Python's recursion limit."""

_HINT = 'conditions are JavaScript-like expressions over data fields, e.g. status == "ok" && n < 3'
_HINTS = {
    "condition": _HINT,
    "expression": 'expressions are JavaScript-like, over data fields, e.g. total * 2 + 1',
    "duration": "write a duration (PT5M, 300, 5 min) or an expression over data fields giving"
    " seconds (timeout * 60)",
}


class ConditionSyntaxError(SpecError):
    """Condition or expression text that opspec cannot read.

    ``text`` is the text as given, ``offset`` the 0-based index of the problem in it,
    ``line`` and ``column`` (1-based) its place within the text, ``problem`` the bare reason.
    The message quotes the text and points at the problem::

        cannot read condition 'a == ' at column 6: expected a value after '=='
    """

    def __init__(
        self,
        text: str,
        offset: int,
        problem: str,
        *,
        kind: str = "condition",
        location: SourceLocation | None = None,
        hint: str = _HINT,
    ) -> None:
        self.text = text
        self.offset = offset
        self.problem = problem
        before = text[:offset]
        self.line = before.count("\n") + 1
        self.column = offset - (before.rfind("\n") + 1) + 1
        where = f"column {self.column}"
        if "\n" in text:
            where = f"line {self.line}, column {self.column}"
        super().__init__(
            f"cannot read {kind} {_quote(text)} at {where}: {problem}",
            location=location,
            hint=hint,
        )

    def to_diagnostic(self, *, code: str = "bad-condition") -> Diagnostic:
        """This error as a load-time diagnostic (the front end collects these)."""
        return Diagnostic(
            location=self.location or SourceLocation("<condition>"),
            severity=Severity.ERROR,
            code=code,
            message=self.message,
            hint=self.hint,
        )


def _quote(text: str) -> str:
    shown = text.replace("\r", "").replace("\n", "\u23ce").replace("\t", " ")
    if len(shown) > 120:
        shown = shown[:117] + "..."
    return f"'{shown}'"


def parse_expression(
    text: str, *, location: SourceLocation | None = None, kind: str = "expression"
) -> Expression:
    """The tree for ``text``; raises :class:`ConditionSyntaxError` (``kind`` names what is
    being read in the message: ``"expression"``, ``"condition"``, ``"duration"``)."""
    return _Parser(text, kind, location).parse()


def parse_condition(
    text: str | None, *, location: SourceLocation | None = None
) -> Expression | None:
    """The tree for a transition/loop/trigger condition, or ``None`` when ``text`` is ``None``,
    empty or only white space (and CDATA padding): "no condition". Raises
    :class:`ConditionSyntaxError`."""
    if text is None or not unwrap(text).strip().rstrip(";").strip():
        return None
    return parse_expression(text, location=location, kind="condition")


def names_used(expr: Expression) -> frozenset[str]:
    """The data-field names (roots of dotted names) that ``expr`` reads."""
    found: set[str] = set()
    stack = [expr]
    while stack:
        node = stack.pop()
        if isinstance(node, Name):
            found.add(node.root)
        elif isinstance(node, Unary):
            stack.append(node.operand)
        elif isinstance(node, Binary):
            stack.extend((node.left, node.right))
        elif isinstance(node, Call):
            stack.extend(node.args)
    return frozenset(found)


# --------------------------------------------------------------------------- parser

# Binding powers (shared with the printer): or 1, and 2, `not` word 3, equality 4,
# ordering 5, + - 6, * / % 7, prefix ! - + 8, postfix .method() 9.
_NOT_WORD = 3
_PREFIX = 8
_POSTFIX = 9
_EQUALITY = {"==": "==", "===": "==", "=": "==", "!=": "!=", "!==": "!=", "<>": "!=", "≠": "!="}
_ORDERING = {"<": "<", "<=": "<=", ">": ">", ">=": ">=", "≤": "<=", "≥": ">="}
_ARITHMETIC = {"+", "-", "*", "/", "%"}
_LITERAL_WORDS: dict[str, bool | None] = {"true": True, "false": False, "null": None}

# Calls of a single name that are other spellings of a whitelisted function.
_GLOBAL_ALIASES = {
    "parseInt": "int", "parseFloat": "float", "Number": "float",
    "String": "str", "Boolean": "bool",
}
# Java static methods: (class, method) -> whitelisted function.
_STATIC: dict[tuple[str, str], str] = {
    **{("Math", f): f for f in ("abs", "min", "max", "round", "floor", "ceil")},
    ("Boolean", "valueOf"): "bool", ("Boolean", "parseBoolean"): "bool",
    ("Integer", "parseInt"): "int", ("Integer", "valueOf"): "int",
    ("Long", "parseLong"): "int", ("Long", "valueOf"): "int",
    ("Double", "parseDouble"): "float", ("Double", "valueOf"): "float",
    ("Float", "parseFloat"): "float", ("Float", "valueOf"): "float",
    ("String", "valueOf"): "str",
}
_STATIC_CLASSES = frozenset(cls for cls, _ in _STATIC)


def _lower(e: Expression) -> Expression:
    return Call("lower", (e,))


# Java/JavaScript methods: name -> (argument count, builder from receiver and arguments).
_METHODS: dict[str, tuple[int, Callable[[Expression, tuple[Expression, ...]], Expression]]] = {
    "equals": (1, lambda r, a: Binary("==", r, a[0])),
    "equalsIgnoreCase": (1, lambda r, a: Binary("==", _lower(r), _lower(a[0]))),
    "compareTo": (1, lambda r, a: Call("compare", (r, a[0]))),
    "compareToIgnoreCase": (1, lambda r, a: Call("compare", (_lower(r), _lower(a[0])))),
    "indexOf": (1, lambda r, a: Call("find", (r, a[0]))),
    "includes": (1, lambda r, a: Call("contains", (r, a[0]))),
    "startsWith": (1, lambda r, a: Call("startswith", (r, a[0]))),
    "endsWith": (1, lambda r, a: Call("endswith", (r, a[0]))),
    "toLowerCase": (0, lambda r, a: Call("lower", (r,))),
    "toUpperCase": (0, lambda r, a: Call("upper", (r,))),
    "trim": (0, lambda r, a: Call("strip", (r,))),
    "length": (0, lambda r, a: Call("len", (r,))),
    "size": (0, lambda r, a: Call("len", (r,))),
    "isEmpty": (0, lambda r, a: Binary("==", Call("len", (r,)), Literal(0))),
    "toString": (0, lambda r, a: Call("str", (r,))),
    "booleanValue": (0, lambda r, a: Call("bool", (r,))),
    "intValue": (0, lambda r, a: Call("int", (r,))),
    "longValue": (0, lambda r, a: Call("int", (r,))),
    "doubleValue": (0, lambda r, a: Call("float", (r,))),
    "floatValue": (0, lambda r, a: Call("float", (r,))),
}


class _Parser:
    def __init__(self, text: str, kind: str, location: SourceLocation | None) -> None:
        self.original = text
        self.kind = kind
        self.location = location
        self.pos = 0
        self.nesting = 0
        self.tokens: list[Token] = []

    def fail(self, offset: int, problem: str) -> ConditionSyntaxError:
        return ConditionSyntaxError(
            self.original,
            offset,
            problem,
            kind=self.kind,
            location=self.location,
            hint=_HINTS.get(self.kind, _HINT),
        )

    def parse(self) -> Expression:
        text = self.original
        if len(text) > MAX_LENGTH:
            raise self.fail(0, f"text is longer than {MAX_LENGTH} characters")
        self.tokens = Tokenizer(unwrap(text), self.fail).tokens()
        if self.peek().kind == "end" or self.peek().text == ";":
            raise self.fail(self.peek().start, f"the {self.kind} is empty")
        expr = self.expression(0)
        token = self.peek()
        if token.kind == "op" and token.text == ";":
            # A trailing ";" (JavaScript statement end) is fine; anything after it is not.
            while self.peek().kind == "op" and self.peek().text == ";":
                self.pos += 1
            if self.peek().kind != "end":
                raise self.fail(token.start, self.leftover(token))
            token = self.peek()
        if token.kind != "end":
            raise self.fail(token.start, self.leftover(token))
        if _depth(expr) > MAX_DEPTH:
            raise self.fail(0, f"nested more than {MAX_DEPTH} levels deep; split it up")
        return expr

    def leftover(self, token: Token) -> str:
        previous = self.tokens[self.pos - 1].text
        if token.kind == "op" and token.text == ";":
            return "only one expression is allowed (';' separates script statements)"
        if token.kind == "op" and token.text == ")":
            return "')' has no matching '('"
        if token.kind == "word" and token.text.lower() not in _LITERAL_WORDS:
            return (
                f"unexpected {token.text!r} after {previous!r}: two values with no operator "
                "between them (names cannot contain spaces)"
            )
        return f"unexpected {token.text!r} after {previous!r}: expected an operator or the end"

    def peek(self) -> Token:
        return self.tokens[self.pos]

    def advance(self) -> Token:
        token = self.tokens[self.pos]
        if token.kind != "end":
            self.pos += 1
        return token

    def expect(self, op: str, problem: str) -> Token:
        token = self.peek()
        if token.kind == "op" and token.text == op:
            return self.advance()
        raise self.fail(token.start, problem)

    # -- Pratt core

    def expression(self, right_power: int) -> Expression:
        self.nesting += 1
        if self.nesting > MAX_DEPTH:
            raise self.fail(self.peek().start, f"nested more than {MAX_DEPTH} levels deep")
        left = self.prefix(self.advance())
        while True:
            token = self.peek()
            power = self.infix_power(token)
            if power <= right_power:
                break
            self.advance()
            left = self.infix(left, token, power)
        self.nesting -= 1
        return left

    def infix_power(self, token: Token) -> int:
        if token.kind == "word":
            return {"or": 1, "and": 2}.get(token.text.lower(), 0)
        if token.kind != "op":
            return 0
        text = token.text
        if text in ("||", "&&"):
            return 1 if text == "||" else 2
        if text in _EQUALITY:
            return 4
        if text in _ORDERING:
            return 5
        if text in _ARITHMETIC:
            return PRECEDENCE[text]
        if text == ".":
            return _POSTFIX
        return 0

    def prefix(self, token: Token) -> Expression:
        if token.kind in ("num", "str"):
            return Literal(token.value)
        if token.kind == "word":
            return self.word(token)
        if token.kind == "end":
            return self.missing_value(token)
        text = token.text
        if text == "(":
            inner = self.expression(0)
            self.expect(")", f"expected ')' to close the '(' at column {token.start + 1}")
            return inner
        if text == "!":
            return Unary("not", self.expression(_PREFIX))
        if text == "-":
            following = self.peek()
            if following.kind == "num" and isinstance(following.value, (int, float)):
                self.advance()
                return Literal(-following.value)
            return Unary("neg", self.expression(_PREFIX))
        if text == "+":
            return self.expression(_PREFIX)
        return self.missing_value(token)

    def missing_value(self, token: Token) -> Expression:
        index = self.pos if token.kind == "end" else self.pos - 1
        previous = self.tokens[index - 1].text if index > 0 else ""
        if token.kind == "end":
            raise self.fail(token.start, f"expected a value after {previous!r}")
        if previous:
            raise self.fail(
                token.start, f"expected a value after {previous!r} but found {token.text!r}"
            )
        raise self.fail(token.start, f"expected a value but found {token.text!r}")

    def word(self, token: Token) -> Expression:
        lowered = token.text.lower()
        if lowered in _LITERAL_WORDS:
            return Literal(_LITERAL_WORDS[lowered])
        if token.text == "None":
            return Literal(None)
        if lowered == "not":
            return Unary("not", self.expression(_NOT_WORD))
        if lowered in ("and", "or"):
            raise self.fail(token.start, f"expected a value before {token.text!r}")
        if token.text in SCRIPT_WORDS:
            raise self.fail(
                token.start,
                f"{token.text!r} starts a script statement; opspec reads single expressions "
                "over data fields",
            )
        path = [token.text]
        while self.peek().text == "." and self.peek().kind == "op":
            dot = self.advance()
            part = self.peek()
            if part.kind != "word":
                raise self.fail(part.start, f"expected a name after '.' at column {dot.start + 1}")
            path.append(self.advance().text)
        if self.peek().kind == "op" and self.peek().text == "(":
            return self.call(tuple(path), token.start)
        return Name(tuple(path))

    def arguments(self) -> tuple[Expression, ...]:
        opening = self.expect("(", "expected '('")
        args: list[Expression] = []
        if self.peek().text == ")" and self.peek().kind == "op":
            self.advance()
            return ()
        while True:
            args.append(self.expression(0))
            token = self.advance()
            if token.kind == "op" and token.text == ")":
                return tuple(args)
            if not (token.kind == "op" and token.text == ","):
                raise self.fail(
                    token.start,
                    f"expected ',' or ')' in the call opened at column {opening.start + 1}",
                )

    def call(self, path: tuple[str, ...], start: int) -> Expression:
        args = self.arguments()
        if len(path) == 1:
            name = _GLOBAL_ALIASES.get(path[0], path[0])
            signature = FUNCTIONS.get(name)
            if signature is None:
                known = ", ".join(sorted(FUNCTIONS))
                raise self.fail(start, f"unknown function {path[0]!r} (known: {known})")
            return self.checked_call(signature, args, start, path[0])
        if len(path) == 2 and path[0] in _STATIC_CLASSES:
            target = _STATIC.get((path[0], path[1]))
            if target is None:
                raise self.fail(start, f"unsupported method {'.'.join(path)}()")
            return self.checked_call(FUNCTIONS[target], args, start, ".".join(path))
        return self.method(Name(path[:-1]), path[-1], args, start)

    def checked_call(
        self, signature: FunctionSignature, args: tuple[Expression, ...], start: int, written: str
    ) -> Expression:
        if not signature.accepts(len(args)):
            raise self.fail(
                start,
                f"{written}() takes {signature.arity_text()}, not {len(args)}",
            )
        return Call(signature.name, args)

    def method(
        self, receiver: Expression, name: str, args: tuple[Expression, ...], start: int
    ) -> Expression:
        if name in _METHODS:
            count, build = _METHODS[name]
            if len(args) != count:
                plural = "" if count == 1 else "s"
                raise self.fail(start, f".{name}() takes {count} argument{plural}, not {len(args)}")
            return build(receiver, args)
        signature = FUNCTIONS.get(name)
        if signature is not None and signature.name not in TIME_FUNCTIONS:
            return self.checked_call(signature, (receiver, *args), start, name)
        raise self.fail(start, f"unsupported method .{name}()")

    def infix(self, left: Expression, token: Token, power: int) -> Expression:
        text = token.text if token.kind == "op" else token.text.lower()
        if text in ("||", "or"):
            return Binary("or", left, self.operand(token, 1))
        if text in ("&&", "and"):
            return Binary("and", left, self.operand(token, 2))
        if text in _EQUALITY:
            return Binary(_EQUALITY[text], left, self.operand(token, 4))
        if text in _ORDERING:
            return self.ordering(left, token)
        if text in _ARITHMETIC:
            return Binary(text, left, self.operand(token, power))
        # text == ".": a method on a value that is not a plain name ("y".equals(x), f(a).m())
        part = self.peek()
        if part.kind != "word":
            raise self.fail(part.start, "expected a method name after '.'")
        self.advance()
        if not (self.peek().kind == "op" and self.peek().text == "("):
            raise self.fail(
                part.start, f"'.{part.text}' without '()': only data fields have members"
            )
        return self.method(left, part.text, self.arguments(), token.start)

    def operand(self, operator: Token, power: int) -> Expression:
        following = self.peek()
        if following.kind == "end":
            raise self.fail(following.start, f"expected a value after {operator.text!r}")
        return self.expression(power)

    def ordering(self, left: Expression, token: Token) -> Expression:
        """``a < b <= c`` reads as ``a < b && b <= c`` (what people mean by a range)."""
        right = self.operand(token, 5)
        result: Expression = Binary(_ORDERING[token.text], left, right)
        while self.peek().kind == "op" and self.peek().text in _ORDERING:
            nxt = self.advance()
            third = self.operand(nxt, 5)
            result = Binary("and", result, Binary(_ORDERING[nxt.text], right, third))
            right = third
        return result


def _depth(expr: Expression) -> int:
    deepest, stack = 0, [(expr, 1)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        if isinstance(node, Unary):
            stack.append((node.operand, depth + 1))
        elif isinstance(node, Binary):
            stack.extend(((node.left, depth + 1), (node.right, depth + 1)))
        elif isinstance(node, Call):
            stack.extend((arg, depth + 1) for arg in node.args)
    return deepest

