"""What a file given as the spec looks like when it is not XML at all: a TOML user model, a
world file, a device profile, a script, JSON, plain text or a binary file.

libxml2 would call each "not well-formed XML at column 1", which is true and no help: the
user gave the wrong file, not a broken one. Every door reads its spec through
:func:`opspec.xpdl.safe_xml.parse_safely`, which asks :func:`not_a_spec` only once the XML
could not be read, so a spec is never read twice.
"""

from __future__ import annotations

import contextlib
from typing import Any

from opspec.errors import SourceLocation

__all__ = ["WANTED", "not_a_spec"]

#: what every command that reads a spec wants instead
WANTED = "an XPDL (.xpdl) or BPMN 2.0 (.bpmn) specification, or one compiled to .wfs"

#: keys only the worlds' parameter files use (opspec/worlds: the room, the ward, the ring)
_WORLD_KEYS = frozenset({"obstacles", "drain_per_s", "range_noise", "ring_radius",
                         "opponent_speed", "bout_limit_s", "edge_band", "tag_range"})


def _starts_with_markup(text: str) -> bool:
    return text.lstrip("\ufeff \t\r\n").startswith("<")


def _kind(data: bytes, path: str) -> tuple[str, str] | None:
    """(what the file is, where it goes instead), or None when it may be XML after all."""
    from opspec.files import json_loads, toml_loads

    if data.lstrip(b" \t\r\n").startswith((b"\xff\xfe", b"\xfe\xff", b"<\x00", b"\x00<",
                                            b"\x00\x00\xfe\xff")):
        return None             # UTF-16 or UTF-32 (with or without a BOM): libxml2's to judge
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        # 8-bit text in another encoding (Latin-1, or one its declaration names wrongly) is
        # still XML when it starts with markup: broken XML, the reader's message says where
        if _starts_with_markup(data[:512].decode("latin-1")) and b"\x00" not in data[:512]:
            return None
        text = None
    if text is None or "\x00" in text:
        return "a binary file (not text)", ""
    if _starts_with_markup(text):
        return None                     # XML that is broken: the reader's message says where
    document: Any = None
    body = text.lstrip("\ufeff \t\r\n")
    if body.startswith(("{", "[")):
        with contextlib.suppress(ValueError, RecursionError):
            document = json_loads(body)
        if document is not None:
            if isinstance(document, dict) and "steps" in document:
                return "a script (JSON)", "give it to --script"
            return "JSON", ""
    with contextlib.suppress(ValueError, RecursionError):
        document = toml_loads(text)
    if not isinstance(document, dict) or not document:
        first = next((line.strip() for line in text.splitlines() if line.strip()), "")
        shown = first if len(first) <= 40 else first[:37] + "..."
        return f"text that is not XML (it starts {shown!r})", ""
    if document.get("format") == "opspec-user-model":
        return ("a user model (TOML)",
                ("give it to --user-model (opspec run, evaluate, walkthrough); "
                 "as SPEC.users.toml beside the spec, every door uses it"))
    if "steps" in document:
        return "a script (TOML)", "give it to --script"
    if "operations" in document or ("port" in document and "serial" in document):
        return ("a device profile (TOML)",
                ("put it in the folder --devices names (default devices/) and --bind its "
                 "participant"))
    if path.endswith(".world.toml") or _WORLD_KEYS & set(document):
        return ("a world file (TOML)",
                ('the spec names it with <ExtendedAttribute Name="opspec:WorldFile" '
                 'Value="..."/>'))
    return "a TOML file", ""


def not_a_spec(data: bytes, path: str) -> tuple[str, SourceLocation, str] | None:
    """The message, place and hint refusing ``data`` (read from ``path``) as a spec when it
    is plainly some other kind of file; None when it may be XML (the reader's own message
    then says what is wrong with it)."""
    found = _kind(data, path)
    if found is None:
        return None
    what, goes = found
    hint = f"give {WANTED}" + (f"; {what.split(' (')[0]}: {goes}" if goes else "")
    return f"this is {what}, not a specification", SourceLocation(path, 1), hint
