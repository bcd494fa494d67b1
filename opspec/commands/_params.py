"""``--param NAME=VALUE``: values for a spec's package data fields, given on the command line.

A BPMN diagram's run inputs (variables its conditions read that nothing in it sets: the
application would set them; docs/bpmn.md, Run inputs) and any package-wide data field of an
XPDL spec take their value for one run or evaluation this way; the value is read as the
field's declared type.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable
from typing import Any

from opspec.errors import ConfigurationError
from opspec.model import Package
from opspec.model.data import BasicKind, BasicType

__all__ = ["parse_params"]

_TRUE = {"true", "yes", "1", "on"}
_FALSE = {"false", "no", "0", "off"}


def parse_params(texts: Iterable[str], package: Package) -> dict[str, Any]:
    """``NAME=VALUE`` texts as typed values of ``package``'s package-wide data fields."""
    fields = {f.id: f for f in package.data_fields}
    out: dict[str, Any] = {}
    for text in texts:
        name, sep, raw = text.partition("=")
        name = name.strip()
        if not sep or not name:
            raise ConfigurationError(f"--param {text!r} is not NAME=VALUE",
                                     hint="for example --param score=70")
        field = fields.get(name)
        if field is None:
            inputs = [f.id for f in package.data_fields
                      if any(e.name == "opspec:RunInput" for e in f.extended_attributes)]
            close = difflib.get_close_matches(name, list(fields), n=1)
            known = (f"its run inputs: {', '.join(inputs)}" if inputs else
                     f"its package data fields: {', '.join(fields)}" if fields else
                     "it has no package data fields")
            raise ConfigurationError(
                f"--param {name}: the spec has no package data field {name!r}"
                + (f" (did you mean {close[0]!r}?)" if close else ""),
                hint=f"{known}; opspec validate lists the run inputs")
        out[name] = _typed(name, raw.strip(), field.type)
    return out


def _typed(name: str, raw: str, data_type: object) -> Any:
    kind = data_type.kind if isinstance(data_type, BasicType) else BasicKind.STRING
    try:
        if kind is BasicKind.INTEGER:
            return int(raw)
        if kind is BasicKind.FLOAT:
            value = float(raw)
            if not math.isfinite(value):
                raise ValueError(raw)
            return value
    except ValueError:
        what = "an integer" if kind is BasicKind.INTEGER else "a number"
        raise ConfigurationError(f"--param {name}={raw}: {name} is {what}, and {raw!r} is "
                                 "not one",
                                 hint=f"for example --param {name}=70") from None
    if kind is BasicKind.BOOLEAN:
        if raw.lower() in _TRUE:
            return True
        if raw.lower() in _FALSE:
            return False
        raise ConfigurationError(f"--param {name}={raw}: {name} is a boolean",
                                 hint=f"write --param {name}=true or --param {name}=false")
    return raw
