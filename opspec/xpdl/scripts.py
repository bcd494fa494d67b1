"""Read the scripts of JaWE/Shark script tool agents into assignment statements.

Together Workflow Editor (JaWE) and the Shark engine implement small applications as scripts
run by a *tool agent*: an ``Application`` carries the extended attributes
``ToolAgentClass="org.enhydra.shark.toolagent.JavaScriptToolAgent"`` (or ``…BshToolAgent``,
BeanShell) and ``Script="counter = counter + 1;"``. The script sees the application's formal
parameters as variables; the tool agent copies IN/INOUT actual parameters in before and
OUT/INOUT formals back out after.

opspec never runs JavaScript. It reads the subset such scripts are written in: a sequence of
statements separated by ``;``, each an assignment of an expression of the condition language
(:mod:`opspec.xpdl.conditions`) to a variable::

    counter = counter + 1;
    var next = value * 2; total = total + next;
    n += 1; n -= 2; n *= 3; n /= 4; n++; n--;

``var``/``let``/``const`` before a name is allowed (the name is then a local variable of the
script). Anything else (``if``, loops, blocks, function calls as statements, assignments to a
record member) is a :class:`~opspec.xpdl.conditions.ConditionSyntaxError` that names the
statement; the front end reports it at the ``Script`` attribute's line.
"""

from __future__ import annotations

from collections.abc import Callable

from opspec.errors import SourceLocation
from opspec.model.data import Assignment
from opspec.model.expressions import Binary, Expression, Literal, Name
from opspec.xpdl.condition_tokens import Token, Tokenizer, unwrap
from opspec.xpdl.conditions import MAX_LENGTH, ConditionSyntaxError, parse_expression

__all__ = ["SCRIPT_HINT", "SCRIPT_TOOL_AGENTS", "is_script_tool_agent", "parse_script"]

SCRIPT_TOOL_AGENTS = ("JavaScriptToolAgent", "BshToolAgent")
"""Tool agent classes (last part of the Java class name) whose ``Script`` opspec runs."""

SCRIPT_HINT = ("opspec runs scripts made of assignments only: NAME = EXPRESSION; (also +=, -=, "
               "*=, /=, ++, --, and var NAME = ...), over the application's formal parameters")
_DECLARE = frozenset({"var", "let", "const"})
_COMPOUND = {"+": "+", "-": "-", "*": "*", "/": "/", "%": "%"}


def is_script_tool_agent(tool_agent_class: str | None) -> bool:
    """True for the JaWE/Shark tool agents whose ``Script`` attribute opspec runs."""
    if not tool_agent_class:
        return False
    return tool_agent_class.strip().rsplit(".", 1)[-1] in SCRIPT_TOOL_AGENTS


def parse_script(text: str, *, location: SourceLocation | None = None) -> tuple[Assignment, ...]:
    """The statements of ``text`` as assignments, in order; raises
    :class:`~opspec.xpdl.conditions.ConditionSyntaxError` for anything outside the subset."""

    def fail(offset: int, problem: str) -> ConditionSyntaxError:
        if problem.startswith("blocks {"):
            problem = "blocks {...} (if, loops, functions) are not supported"
        return ConditionSyntaxError(text, offset, problem, kind="script", location=location,
                                    hint=SCRIPT_HINT)

    if len(text) > MAX_LENGTH:
        raise fail(0, f"text is longer than {MAX_LENGTH} characters")
    source = unwrap(text)
    tokens = Tokenizer(source, fail).tokens()
    statements: list[list[Token]] = [[]]
    for token in tokens:
        if token.kind == "end":
            break
        if token.kind == "op" and token.text == ";":
            statements.append([])
        else:
            statements[-1].append(token)
    out: list[Assignment] = []
    for statement in statements:
        if statement:
            out.append(_statement(statement, source, fail, location))
    if not out:
        raise fail(0, "the script has no statement")
    return tuple(out)


def _statement(tokens: list[Token], source: str,
               raise_at: Callable[[int, str], ConditionSyntaxError],
               location: SourceLocation | None) -> Assignment:
    first = tokens[0]
    end = tokens[-1].start + len(tokens[-1].text)
    shown = source[first.start:end]
    pos = 0
    if first.kind == "word" and first.text in _DECLARE and len(tokens) > 1:
        pos = 1
    target = tokens[pos] if pos < len(tokens) else first
    if target.kind != "word":
        raise raise_at(target.start, f"statement {shown!r} does not start with the name of "
                       "the variable it assigns")
    if target.text.lower() in ("if", "for", "while", "do", "switch", "return", "function",
                               "else", "try", "throw", "new"):
        raise raise_at(target.start, f"{target.text!r} statements are not supported "
                       f"(in {shown!r})")
    rest = tokens[pos + 1:]
    name = Name((target.text,))
    ops = "".join(t.text for t in rest[:2] if t.kind == "op")
    if rest and rest[0].kind == "op" and rest[0].text == ".":
        raise raise_at(rest[0].start, f"{shown!r} assigns to a member or calls a method; "
                       "only plain variables can be assigned")
    if len(rest) == 2 and ops in ("++", "--"):
        expression: Expression = Binary(ops[0], name, Literal(1))
        return Assignment(target=target.text, text=shown, expression=expression,
                          location=location)
    if rest and rest[0].kind == "op" and rest[0].text == "=":
        value_tokens = rest[1:]
        operator = None
    elif (len(rest) >= 2 and rest[0].kind == "op" and rest[0].text in _COMPOUND
          and rest[1].kind == "op" and rest[1].text == "=" and rest[1].start == rest[0].start + 1):
        value_tokens = rest[2:]
        operator = _COMPOUND[rest[0].text]
    else:
        at = rest[0].start if rest else end
        raise raise_at(at, f"statement {shown!r} is not an assignment NAME = EXPRESSION")
    if not value_tokens:
        raise raise_at(end, f"statement {shown!r} assigns nothing")
    base = value_tokens[0].start
    value_text = source[base:end]
    try:
        value = parse_expression(value_text, location=location, kind="expression")
    except ConditionSyntaxError as error:
        raise raise_at(base + error.offset, f"in {shown!r}: {error.problem}") from None
    if operator is not None:
        value = Binary(operator, name, value)
    return Assignment(target=target.text, text=shown, expression=value, location=location)
