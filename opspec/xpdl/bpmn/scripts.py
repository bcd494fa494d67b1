"""Script tasks and conditions as SpiffWorkflow and Camunda write them.

SpiffWorkflow runs script tasks and conditions as Python; Camunda as JUEL, JavaScript or
Groovy. opspec runs none of these languages: it reads the part they share with its own
expression grammar (:mod:`opspec.xpdl.conditions`; docs/semantics.md) and refuses the rest
at its line, naming the construct, so a simulation never silently skips what a script does.

**Scripts** are statements, one per line or separated by ``;``, each an assignment:
``x = expression``, ``x += 1`` (``-= *= /= %=``), or Python's tuple assignment
``a, b, c = 1, "text", True`` (read as ``a = 1; b = "text"; c = True``). Comments (``#``) and
blank lines are skipped; so are statements that only write output (``print(…)``,
``println …``, ``console.log(…)``), which change no data. Everything else — ``if``, loops,
``def``, ``import``, ``del``, item or attribute assignment (``x['a'] = 1``,
``record.field = 1``), dict and list literals, calls of functions opspec does not know — is
a ``bad-script`` error at the statement's own line.

**Conditions** are read by the condition grammar; Python's ``x is None`` and
``x is not None`` are read as ``x == null`` and ``x != null``. A condition the grammar
cannot read is a ``bad-condition`` error whose message names the Python construct (a
membership test ``in``, a conditional expression, a list or dict literal, item access…).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass

from lxml import etree

from opspec.errors import Diagnostic, Severity, SourceLocation, SpecError
from opspec.model.data import Assignment
from opspec.model.expressions import Expression
from opspec.xpdl.bpmn.common import Defs, is_juel
from opspec.xpdl.bpmn.dialects import from_dialects
from opspec.xpdl.bpmn.juel import from_juel, outside_strings

__all__ = ["bpmn_condition", "construct_of", "read_script"]

_OUTPUT = re.compile(r"^(print\s*\(|println\b|console\.log\s*\(|System\.out\.print)")
# First words of Python/JavaScript statements that are not assignments, and what they are.
_STATEMENTS = {
    "if": "an if statement", "elif": "an elif branch", "else": "an else branch",
    "for": "a for loop", "while": "a while loop", "def": "a function definition (def)",
    "class": "a class definition", "import": "an import", "from": "an import",
    "return": "a return statement", "try": "a try statement", "except": "an except clause",
    "finally": "a finally clause", "with": "a with statement", "del": "a del statement",
    "global": "a global statement", "nonlocal": "a nonlocal statement",
    "raise": "a raise statement", "assert": "an assert statement", "lambda": "a lambda",
    "yield": "a yield", "async": "async code", "await": "await", "switch": "a switch",
    "function": "a function definition", "throw": "a throw statement", "do": "a do loop",
}
_SCRIPT_HINT = ("opspec runs scripts made of assignments over data fields: x = expression, "
                "x += 1, a, b = 1, 2 (one per line or separated by ;); set other data with "
                "opspec:Assignment elements, or let a performer supply it (docs/bpmn.md)")
_CONDITION_HINT = ("write the condition in opspec's expression grammar (docs/semantics.md): "
                   "comparisons, and/or/not, arithmetic and whitelisted functions over data "
                   "fields, e.g. status == 'ok' and n < 3")


@dataclass(frozen=True, slots=True)
class _Statement:
    text: str
    offset: int          # where it starts in the script text


def _split(text: str) -> tuple[list[_Statement], int | None]:
    """The statements of ``text`` (newline or ``;`` outside brackets and strings end one;
    comments dropped) and, when a bracket is left open, where it was opened."""
    out: list[_Statement] = []
    depth = 0
    opened: int | None = None
    start = 0
    buffer: list[str] = []
    i = 0
    quote: str | None = None

    def flush(end: int) -> None:
        nonlocal start
        piece = "".join(buffer)
        stripped = piece.strip()
        if stripped:
            out.append(_Statement(stripped, start + (len(piece) - len(piece.lstrip()))))
        buffer.clear()
        start = end + 1

    while i < len(text):
        ch = text[i]
        if quote is not None:
            buffer.append(ch)
            if ch == "\\" and i + 1 < len(text):
                buffer.append(text[i + 1])
                i += 2
                continue
            if text.startswith(quote, i):
                buffer.extend(quote[1:])
                i += len(quote)
                quote = None
                continue
            i += 1
            continue
        if ch in "'\"":
            quote = ch * 3 if text.startswith(ch * 3, i) else ch
            buffer.append(quote)
            i += len(quote)
            continue
        if ch == "#":
            while i < len(text) and text[i] != "\n":
                i += 1
            continue
        if ch in "([{":
            if depth == 0:
                opened = i
            depth += 1
        elif ch in ")]}":
            depth = max(depth - 1, 0)
        if depth == 0 and ch in "\n;":
            flush(i)
            i += 1
            continue
        buffer.append(ch)
        i += 1
    flush(len(text))
    return out, opened if depth else None


def _top_level_characters(text: str) -> Iterator[tuple[int, str]]:
    """The characters of ``text`` (with their index) that stand outside brackets and strings,
    brackets and quotes themselves left out."""
    depth, quote = 0, None
    for i, ch in enumerate(text):
        if quote is not None:
            if ch == quote and text[i - 1] != "\\":
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif depth == 0:
            yield i, ch


def _top_level(text: str, separator: str) -> list[tuple[str, int]]:
    """``text`` split at ``separator`` characters outside brackets and strings, with the
    offset of each piece."""
    pieces: list[tuple[str, int]] = []
    begin = 0
    for i, ch in _top_level_characters(text):
        if ch == separator:
            pieces.append((text[begin:i], begin))
            begin = i + 1
    pieces.append((text[begin:], begin))
    return pieces


def _assignment_at(text: str) -> int | None:
    """Index of the ``=`` of an assignment (not ``==``, ``<=``, ``+=``…) outside brackets and
    strings, or ``None``."""
    for i, ch in _top_level_characters(text):
        if ch == "=":
            before = text[i - 1] if i else ""
            after = text[i + 1] if i + 1 < len(text) else ""
            if after != "=" and before not in "=!<>+-*/%":
                return i
    return None


_NAME = re.compile(r"^[A-Za-z_$][A-Za-z0-9_$]*$")
_STRINGS = re.compile(r"""(?:[rRbBuU]?(?:'[^'\\]*(?:\\.[^'\\]*)*'|"[^"\\]*(?:\\.[^"\\]*)*"))""")


def construct_of(text: str) -> str | None:
    """The Python (or JUEL/JavaScript) construct in ``text`` that opspec's expression grammar
    does not have, in words, or ``None`` when none is recognised."""
    if re.search(r"""(?<![A-Za-z0-9_])[fF]['"]""", text):
        return "an f-string (f'…')"
    bare = _STRINGS.sub("''", text)
    checks = (
        (r"\blambda\b", "a lambda"),
        (r"\bif\b.*\belse\b", "a conditional expression (a if c else b)"),
        (r"\bfor\b.*\bin\b", "a comprehension (… for x in …)"),
        (r"\bnot\s+in\b", "a membership test (not in)"),
        (r"\bin\b", "a membership test (x in …)"),
        (r"\?.*:", "a conditional expression (c ? a : b)"),
        (r"\*\*", "the power operator **"),
        (r"//", "floor division //"),
        (r"[A-Za-z0-9_)\]'\"]\s*\[", "item access (x[…])"),
        (r"\[", "a list literal […]"),
        (r"\{", "a dict or set literal {…}"),
        (r"\bexecution\s*\.", "Camunda's execution API (execution.…)"),
        (r"\bempty\b", "JUEL's empty operator"),
        (r"\b(datetime|timedelta|date|time)\s*[.(]", "Python's datetime module"),
        (r"\bvars\s*\(|\bglobals\s*\(", "Python's vars()/globals()"),
    )
    for pattern, what in checks:
        if re.search(pattern, bare):
            return what
    return None


def _is_rewrites(text: str) -> str:
    """Python's ``is not`` / ``is`` as ``!=`` / ``==`` outside strings, keeping columns."""
    return outside_strings(text, _STRINGS, _is_plain)


def _is_plain(text: str) -> str:
    text = re.sub(r"\bis\s+not\b", lambda m: "!=" + " " * (len(m.group(0)) - 2), text)
    return re.sub(r"\bis\b", "==", text)


def bpmn_condition(element: etree._Element | None, text: str | None, defs: Defs, what: str
                   ) -> Expression | None:
    """The tree of a BPMN condition; an unreadable one is a ``bad-condition`` error at
    ``element``'s line naming the construct (never an exception)."""
    from opspec.xpdl.conditions import parse_condition

    if text is None or not text.strip():
        return None
    source = from_dialects(from_juel(text) if is_juel(element) else text, defs.data_names)
    try:
        return parse_condition(_is_rewrites(source), location=defs.loc(element))
    except (SpecError, ValueError, RecursionError) as error:
        detail = getattr(error, "message", str(error))
        construct = construct_of(text)
        named = f"{construct} is not in opspec's expression grammar; " if construct else ""
        defs.ctx.error(element, "bad-condition",
                       f"{what} {text.strip()!r} cannot be run: {named}{detail}",
                       _CONDITION_HINT)
        return None


def read_script(element: etree._Element, defs: Defs, label: str
                ) -> tuple[tuple[Assignment, ...], bool]:
    """The assignments of a script task's ``bpmn:script`` and whether all of it could be
    read: a statement outside the subset is a ``bad-script`` error at its own line (the
    file's line of the statement; the body of a refused ``if``/``for``/``def`` is not
    looked at), statements that only print are an ``info``. The readable assignments come
    back even when some statement was refused (the file is refused then, and the names they
    set are still the process's data: no follow-up errors about them)."""
    text = "".join(element.itertext())
    base = defs.loc(element).line
    statements, unclosed = _split(text)
    out: list[Assignment] = []
    ok = True
    printed: list[int | None] = []

    def line_of(offset: int) -> int | None:
        return None if base is None else base + text.count("\n", 0, offset)

    def refuse(statement: _Statement, problem: str) -> None:
        nonlocal ok
        ok = False
        compact = " ".join(statement.text.split())
        shown = compact if len(compact) <= 80 else compact[:77] + "..."
        defs.ctx.diagnostics.append(Diagnostic(
            SourceLocation(defs.ctx.path, line_of(statement.offset)), Severity.ERROR,
            "bad-script", f"the script of {label} cannot be run: {problem} (in {shown!r})",
            _SCRIPT_HINT))

    if unclosed is not None:
        defs.ctx.diagnostics.append(Diagnostic(
            SourceLocation(defs.ctx.path, line_of(unclosed)), Severity.ERROR, "bad-script",
            f"the script of {label} cannot be run: a bracket opened here is never closed",
            _SCRIPT_HINT))
        ok = False
        statements = [s for s in statements if s.offset + len(s.text) <= unclosed]
    block_indent: int | None = None      # inside the body of a refused if/for/def…
    for statement in statements:
        body = statement.text
        line_start = text.rfind("\n", 0, statement.offset) + 1
        indent = statement.offset - line_start
        if block_indent is not None:
            if indent > block_indent and not text[line_start:statement.offset].strip():
                continue
            block_indent = None
        if _OUTPUT.match(body):
            printed.append(line_of(statement.offset))
            continue
        if body == "pass":
            continue
        first_word = re.match(r"[A-Za-z_]+", body)
        if first_word is not None and first_word.group(0) in _STATEMENTS and (
                len(body) == len(first_word.group(0))
                or not re.match(r"\s*(=[^=]|[+\-*/%]=)", body[first_word.end():])):
            refuse(statement, f"{_STATEMENTS[first_word.group(0)]} is not in the subset "
                   "opspec runs")
            if body.rstrip().endswith(":"):
                block_indent = indent
            continue
        found = _statement(statement, defs, line_of(statement.offset))
        if isinstance(found, str):
            refuse(statement, found)
        else:
            out.extend(found)
    if printed:
        defs.ctx.diagnostics.append(Diagnostic(
            SourceLocation(defs.ctx.path, printed[0]), Severity.INFO, "script-output",
            f"the script of {label} prints; output statements change no data and are "
            "skipped", ""))
    return tuple(out), ok


def _statement(statement: _Statement, defs: Defs, line: int | None
               ) -> list[Assignment] | str:
    """The assignments of one statement, or the reason it cannot be run."""
    from opspec.xpdl.conditions import ConditionSyntaxError
    from opspec.xpdl.scripts import parse_script

    body = statement.text
    location = SourceLocation(defs.ctx.path, line)
    equals = _assignment_at(body)
    if equals is not None:
        left = re.sub(r"^(var|let|const)\s+", "", body[:equals].rstrip())
        right = body[equals + 1:]
        if _assignment_at(right) is not None:
            return "a chained assignment (a = b = …) is not in the subset opspec runs"
        targets = [t.strip() for t, _ in _top_level(left, ",")]
        for target in targets:
            if not _NAME.match(target):
                if "[" in target:
                    return f"an assignment to an item ({target}) is not in the subset opspec runs"
                if "." in target:
                    return (f"an assignment to an attribute ({target}) is not in the subset "
                            "opspec runs")
                return f"{target!r} is not a name a script can assign"
        if len(targets) > 1:
            return _tuple(targets, right, location)
    try:
        return list(parse_script(body, location=location))
    except ConditionSyntaxError as error:
        construct = construct_of(body)
        if construct is not None:
            return f"{construct} is not in the subset opspec runs"
        return error.problem
    except (SpecError, ValueError, RecursionError) as error:
        return getattr(error, "message", str(error))


def _tuple(targets: list[str], right: str, location: SourceLocation) -> list[Assignment] | str:
    """``a, b = x, y``: one assignment per name, when every value is given and no value
    reads a name assigned before it in the same statement (then order does not matter)."""
    from opspec.xpdl.conditions import ConditionSyntaxError, names_used, parse_expression

    values = [(v.strip(), o) for v, o in _top_level(right, ",")]
    if values and not values[-1][0]:
        values.pop()                      # a trailing comma
    if len(values) != len(targets):
        return (f"unpacking {len(values)} value{'s' * (len(values) != 1)} into "
                f"{len(targets)} names is not in the subset opspec runs (give one value per "
                "name: a, b = 1, 2)")
    out: list[Assignment] = []
    for index, (target, (text, _offset)) in enumerate(zip(targets, values, strict=True)):
        try:
            expression = parse_expression(_is_rewrites(text), location=location)
        except ConditionSyntaxError as error:
            construct = construct_of(text)
            return (f"{construct} is not in the subset opspec runs" if construct
                    else f"the value of {target!r}: {error.problem}")
        earlier = set(targets[:index]) & names_used(expression)
        if earlier:
            return (f"the value of {target!r} reads {min(earlier)!r}, which the same "
                    "statement assigns (Python assigns all at once): write one assignment "
                    "per line")
        out.append(Assignment(target=target, text=f"{target} = {text}",
                              expression=expression, location=location))
    return out
