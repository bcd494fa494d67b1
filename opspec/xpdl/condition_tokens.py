"""The tokenizer of the condition language (:mod:`opspec.xpdl.conditions` holds the grammar).

Splits condition text into numbers, texts, words and operators, each with its 0-based start
offset so errors can name a column. Characters that are not part of the language get a specific
message (``&`` suggests ``&&``, ``?`` explains that ``?:`` is not supported).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["Token", "Tokenizer", "unwrap"]


@dataclass(frozen=True, slots=True)
class Token:
    """One token: ``kind`` is ``num``, ``str``, ``word``, ``op`` or ``end``."""

    kind: str  # "num", "str", "word", "op", "end"
    text: str  # as written (for messages)
    start: int
    value: str | int | float | None = None


_OPERATORS = (
    "===", "!==", "==", "!=", "<>", "<=", ">=", "&&", "||",
    "=", "<", ">", "!", "+", "-", "*", "/", "%", "(", ")", ",", ".", ";", "≤", "≥", "≠",
)
_NOT_SUPPORTED = {
    "&": "'&' is not an operator here; write '&&' (and)",
    "|": "'|' is not an operator here; write '||' (or)",
    "?": "the ?: operator is not supported; use two transitions with opposite conditions",
    "[": "indexing with [...] is not supported; name record members with dots (order.total)",
    "{": "blocks {...} are scripts, not conditions",
    "^": "'^' is not supported",
}
_SIMPLE_ESCAPES = {
    "n": "\n", "t": "\t", "r": "\r", "b": "\b", "f": "\f", "v": "\v", "0": "\0",
}
_CDATA_OPEN, _CDATA_CLOSE = "<![CDATA[", "]]>"


def unwrap(text: str) -> str:
    """Replace a CDATA wrapper by spaces (keeping columns)."""
    stripped = text.strip()
    if stripped.startswith(_CDATA_OPEN) and stripped.endswith(_CDATA_CLOSE):
        start = text.index(_CDATA_OPEN)
        end = text.rindex(_CDATA_CLOSE)
        return (
            text[:start] + " " * len(_CDATA_OPEN) + text[start + len(_CDATA_OPEN) : end]
            + " " * len(_CDATA_CLOSE) + text[end + len(_CDATA_CLOSE) :]
        )
    return text


class Tokenizer:
    """``Tokenizer(text, fail).tokens()``: the tokens of ``text``, ending with an ``end`` token;
    ``fail(offset, problem)`` builds the exception raised for unreadable text."""

    def __init__(self, text: str, fail: Callable[[int, str], Exception]) -> None:
        self.text = text
        self.fail = fail

    def tokens(self) -> list[Token]:
        text, i = self.text, 0
        out: list[Token] = []
        while i < len(text):
            ch = text[i]
            if ch.isspace():
                i += 1
            elif _digit(ch) or (
                ch == "." and _digit(text[i + 1 : i + 2])
                and not (out and out[-1].kind in ("word", "num", "str") or _closes(out))
            ):
                token = self._number(i)
                out.append(token)
                i = token.start + len(token.text)
            elif ch in "'\"":
                token, i = self._string(i)
                out.append(token)
            elif ch.isalpha() or ch in "_$":
                j = i + 1
                while j < len(text) and (text[j].isalnum() or text[j] in "_$"):
                    j += 1
                out.append(Token("word", text[i:j], i))
                i = j
            else:
                for op in _OPERATORS:
                    if text.startswith(op, i):
                        out.append(Token("op", op, i))
                        i += len(op)
                        break
                else:
                    problem = _NOT_SUPPORTED.get(ch, f"unexpected character {ch!r}")
                    raise self.fail(i, problem)
        out.append(Token("end", "", len(text)))
        return out

    def _number(self, start: int) -> Token:
        text, i = self.text, start
        if text.startswith(("0x", "0X"), i):
            j = i + 2
            while j < len(text) and text[j] in "0123456789abcdefABCDEF":
                j += 1
            if j == i + 2:
                raise self.fail(i, "a hexadecimal number needs digits after '0x'")
            return self._finish_number(start, j, int(text[i + 2 : j], 16), "Ll")
        j = i
        while j < len(text) and _digit(text[j]):
            j += 1
        is_float = False
        if j < len(text) and text[j] == "." and _digit(text[j + 1 : j + 2]):
            is_float = True
            j += 1
            while j < len(text) and _digit(text[j]):
                j += 1
        if j < len(text) and text[j] in "eE":
            k = j + 1
            if k < len(text) and text[k] in "+-":
                k += 1
            if k < len(text) and _digit(text[k]):
                is_float = True
                j = k
                while j < len(text) and _digit(text[j]):
                    j += 1
        digits = text[i:j]
        if len(digits) > 400:
            raise self.fail(i, "number has too many digits")
        if not all("0" <= c <= "9" or c in ".eE+-" for c in digits):
            raise self.fail(i, f"cannot read number {digits!r}")
        if is_float:
            return self._finish_number(start, j, float(digits), "fFdD")
        return self._finish_number(start, j, int(digits), "LlfFdD")

    def _finish_number(self, start: int, end: int, value: float, suffixes: str) -> Token:
        text = self.text
        following = text[end + 1 : end + 2]
        if end < len(text) and text[end] in suffixes and not (
            following.isalnum() or following in ("_", "$")
        ):
            if text[end] in "fFdD":
                value = float(value)
            end += 1
        if end < len(text) and (text[end].isalnum() or text[end] in "_$"):
            raise self.fail(
                end,
                f"unexpected {text[end]!r} right after the number {text[start:end]} "
                "(names cannot start with a digit; durations belong in Deadline elements)",
            )
        return Token("num", text[start:end], start, value)

    def _string(self, start: int) -> tuple[Token, int]:
        text, quote, i = self.text, self.text[start], start + 1
        out: list[str] = []
        while i < len(text):
            ch = text[i]
            if ch == quote:
                return Token("str", text[start : i + 1], start, "".join(out)), i + 1
            if ch == "\\" and i + 1 < len(text):
                code = text[i + 1]
                if code in "uUxX":
                    out.append(self._code_point(i))
                    i += 6 if code in "uU" else 4
                    continue
                out.append(_SIMPLE_ESCAPES.get(code, code))
                i += 2
                continue
            out.append(ch)
            i += 1
        raise self.fail(start, f"the text starting with {quote} is never closed")

    def _code_point(self, i: int) -> str:
        width = 4 if self.text[i + 1] in "uU" else 2
        digits = self.text[i + 2 : i + 2 + width]
        if len(digits) != width or any(c not in "0123456789abcdefABCDEF" for c in digits):
            raise self.fail(i, f"escape {self.text[i : i + 2]} needs {width} hex digits")
        value = int(digits, 16)
        if 0xD800 <= value <= 0xDFFF:
            raise self.fail(i, "escape names a lone surrogate, which is not a character")
        return chr(value)


def _digit(ch: str) -> bool:
    return len(ch) == 1 and "0" <= ch <= "9"


def _closes(tokens: list[Token]) -> bool:
    return bool(tokens) and tokens[-1].kind == "op" and tokens[-1].text == ")"
