"""Line templates: the one small language device profiles use for commands, replies and events.

A template is literal text with ``{name}`` placeholders, optionally typed: ``{slot:int}``,
``{distance:float}``, ``{bump:bool}`` (``1``/``0``, ``true``/``false``, ``on``/``off``,
``yes``/``no`` in any case; sent as ``1``/``0``), ``{reason:str}`` (``str`` is the default). ``{{`` and ``}}`` stand for
literal braces. The same template works both ways:

* :meth:`LineTemplate.fill` formats an outgoing line from values (``DISPENSE {slot:int}`` with
  ``{"slot": 3}`` gives ``DISPENSE 3``);
* :meth:`LineTemplate.match` parses an incoming line into typed values (``RANGE {distance:int}``
  matches ``RANGE 123`` and gives ``{"distance": 123}``), or returns ``None``.

Matching is on the whole line (after the framing layer strips the terminator and trailing
whitespace). A ``str`` placeholder matches one or more characters, as few as possible.
No ``str.format`` is used, so a profile can never reach attributes or indexes of values.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

__all__ = ["PLACEHOLDER_TYPES", "LineTemplate", "TemplateError"]

_TRUE, _FALSE = frozenset({"1", "true", "on", "yes"}), frozenset({"0", "false", "off", "no"})


def _to_bool(value: Any) -> bool:
    """A boolean from a device word or an engine value; anything else raises ValueError."""
    if isinstance(value, bool | int) and value in (0, 1):
        return bool(value)
    if isinstance(value, str) and value.strip().lower() in _TRUE | _FALSE:
        return value.strip().lower() in _TRUE
    raise ValueError(f"not a boolean: {value!r}")


# type name -> (regex for matching, converter)
PLACEHOLDER_TYPES: dict[str, tuple[str, Callable[[Any], Any]]] = {
    "str": (r".+?", str),
    "int": (r"[-+]?\d+", int),
    "float": (r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", float),
    "bool": (r"(?i:1|0|true|false|on|off|yes|no)", _to_bool),
}

_TOKEN = re.compile(r"\{\{|\}\}|\{([^{}]*)\}|[{}]")
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


class TemplateError(ValueError):
    """A template is malformed, or values needed to fill it are missing or of the wrong type.

    The profile loader turns this into a :class:`~opspec.errors.BindingError` naming the
    file and key; the binding turns a fill failure into a named fault.
    """


@dataclass(frozen=True, slots=True)
class LineTemplate:
    """A parsed template. Build it with :meth:`parse`."""

    text: str
    # literal text and (name, type) placeholders, in order
    parts: tuple[str | tuple[str, str], ...]
    _regex: re.Pattern[str] = field(repr=False, compare=False)

    @classmethod
    def parse(cls, text: str) -> LineTemplate:
        """Parse ``text``; raise :class:`TemplateError` saying what is wrong and how to fix it."""
        parts: list[str | tuple[str, str]] = []
        pattern: list[str] = []
        seen: set[str] = set()
        pos = 0
        literal = ""
        for token in _TOKEN.finditer(text):
            literal += text[pos:token.start()]
            pos = token.end()
            raw = token.group(0)
            if raw in ("{{", "}}"):
                literal += raw[0]
                continue
            if raw in ("{", "}"):
                raise TemplateError(
                    f"unbalanced {raw!r} at column {token.start() + 1} in {text!r} "
                    "(write {{ or }} for a literal brace)"
                )
            inner = token.group(1) or ""
            name, _, kind = inner.partition(":")
            name, kind = name.strip(), (kind.strip() or "str")
            if not _NAME.match(name):
                raise TemplateError(
                    f"placeholder {raw!r} in {text!r} needs a name made of letters, digits "
                    "and underscores, like {slot} or {slot:int}"
                )
            if kind not in PLACEHOLDER_TYPES:
                known = ", ".join(PLACEHOLDER_TYPES)
                raise TemplateError(
                    f"placeholder {raw!r} in {text!r} has unknown type {kind!r} "
                    f"(use one of: {known})"
                )
            if name in seen:
                raise TemplateError(f"placeholder {{{name}}} appears twice in {text!r}")
            seen.add(name)
            if literal:
                parts.append(literal)
                pattern.append(re.escape(literal))
                literal = ""
            parts.append((name, kind))
            pattern.append(f"(?P<{name}>{PLACEHOLDER_TYPES[kind][0]})")
        literal += text[pos:]
        if literal:
            parts.append(literal)
            pattern.append(re.escape(literal))
        return cls(text, tuple(parts), re.compile("".join(pattern)))

    @property
    def names(self) -> tuple[str, ...]:
        """The placeholder names, in order."""
        return tuple(p[0] for p in self.parts if isinstance(p, tuple))

    def fill(self, values: Mapping[str, Any]) -> str:
        """Format the line; a missing value or one that does not fit its type raises."""
        out: list[str] = []
        for part in self.parts:
            if isinstance(part, str):
                out.append(part)
                continue
            name, kind = part
            if name not in values:
                raise TemplateError(f"{self.text!r} needs a value for {{{name}}}")
            value = values[name]
            if kind != "str":
                try:
                    value = PLACEHOLDER_TYPES[kind][1](value)
                except (TypeError, ValueError):
                    raise TemplateError(
                        f"{self.text!r}: {{{name}:{kind}}} got {value!r}, which is not {kind}"
                    ) from None
            text = ("1" if value else "0") if kind == "bool" else str(value)
            if "\n" in text or "\r" in text:
                raise TemplateError(f"{self.text!r}: {{{name}}} value contains a line break")
            out.append(text)
        return "".join(out)

    def match(self, line: str) -> dict[str, Any] | None:
        """Typed values of the placeholders if ``line`` matches the whole template."""
        found = self._regex.fullmatch(line)
        if found is None:
            return None
        values: dict[str, Any] = {}
        for name, kind in (p for p in self.parts if isinstance(p, tuple)):
            values[name] = PLACEHOLDER_TYPES[kind][1](found.group(name))
        return values

    def __str__(self) -> str:
        return self.text
