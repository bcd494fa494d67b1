"""Simulated worlds that specs declare for their devices (robots in rooms and rings).

A package names its world with ``<ExtendedAttribute Name="opspec:World" Value="vacuum-room"/>``
and may give parameters in a TOML file next to the spec
(``<ExtendedAttribute Name="opspec:WorldFile" Value="vacuum_cleaner.world.toml"/>``) and/or
inline, as children of the ``opspec:World`` attribute, which win over the file::

    <ExtendedAttribute Name="opspec:World" Value="vacuum-room">
      <opspec:Parameter Name="drain_per_s" Value="1.0"/>
      <opspec:Parameter Name="obstacles" Value="[[1.5, 1.5, 2.1, 2.3]]"/>
    </ExtendedAttribute>

Keys are the world's constructor parameters (``width``, ``obstacles``…; see
:class:`~opspec.worlds.room.RoomWorld` and :class:`~opspec.worlds.sumo.SumoWorld`);
an inline ``Value`` is read as a TOML value (a bare word is a string). :func:`world_performers`
gives the performers ``opspec run``, ``opspec evaluate``, the walkthrough and the test helpers
bind: one per world, serving the world's applications by Application id. Each simulated user
gets a world of their own, drawing from a stream derived from ``(seed, user)``.
:func:`check_world` builds it once, so that every door refuses a world it cannot build
before any run (:func:`opspec.request.prepare`).

Worlds are registered here by name; spec text never names Python code.
"""

from __future__ import annotations

import functools
import inspect
import tomllib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any
from xml.etree import ElementTree

from opspec.errors import ConfigurationError, SourceLocation
from opspec.files import toml_loads
from opspec.toml_lines import located
from opspec.worlds.base import World
from opspec.worlds.room import RoomWorld
from opspec.worlds.sumo import SumoWorld

if TYPE_CHECKING:
    from opspec.engine.compiled import CompiledPackage
    from opspec.engine.performers import Performer
    from opspec.model import ExtendedAttribute

__all__ = ["WORLDS", "check_world", "world_parameters", "world_performers"]

#: the ward: a 20 x 3 m corridor with two carts in the way and the patient near its far end
WARD: dict[str, Any] = {"width": 20.0, "height": 3.0, "start": (0.6, 1.5, 0.0),
                        "obstacles": ((6.0, 0.0, 6.6, 1.0), (11.0, 2.0, 11.6, 3.0)),
                        "tag": (17.0, 2.4), "drain_per_s": 0.0}

#: world name -> factory(rng, **parameters); a class or a partial of one, so its parameters
#: (and their defaults) can be listed and checked before the world is built
WORLDS: dict[str, Callable[..., World]] = {
    "vacuum-room": RoomWorld,
    "ward": functools.partial(RoomWorld, **WARD),
    "sumo-ring": SumoWorld,
}

_NS = "{urn:opspec:sisarl:1}"


def _attribute(compiled: CompiledPackage, name: str) -> ExtendedAttribute | None:
    for attribute in compiled.package.extended_attributes:
        if attribute.name == name:
            return attribute
    return None


def _file_parameters(compiled: CompiledPackage, world_attr: ExtendedAttribute
                     ) -> tuple[dict[str, Any], str | None]:
    attribute = _attribute(compiled, "opspec:WorldFile")
    if attribute is None or not attribute.value:
        return {}, None
    from opspec.files import companion_outside

    spec = compiled.package.source
    path = Path(spec or ".").parent / attribute.value
    where = attribute.location or world_attr.location
    outside = companion_outside(spec, attribute.value, "opspec:WorldFile")
    if outside is not None:           # refused before the file is even looked at
        message, hint = outside
        raise ConfigurationError(message, location=where, hint=hint)
    from opspec.toml_files import read_toml

    return read_toml(path, what=f"the world file {path}", location=where,
                     hint="opspec:WorldFile is relative to the spec"), str(path)


def _inline_parameters(attribute: ExtendedAttribute) -> dict[str, Any]:
    """``<opspec:Parameter Name=… Value=…/>`` children of the opspec:World attribute."""
    if not attribute.raw_xml:
        return {}
    # raw_xml is what the hardened reader already parsed and re-serialised: no DTDs, no
    # entities left, so the standard library parser is safe here
    root = ElementTree.fromstring(f'<root xmlns:opspec="urn:opspec:sisarl:1">'
                                  f"{attribute.raw_xml}</root>")
    params: dict[str, Any] = {}
    for element in root:
        if element.tag != f"{_NS}Parameter" or not element.get("Name"):
            raise ConfigurationError(
                f"opspec:World holds <{element.tag.replace(_NS, 'opspec:')}>; only "
                f"<opspec:Parameter Name=\"...\" Value=\"...\"/> is allowed there",
                location=attribute.location)
        text = element.get("Value", "")
        try:
            params[element.get("Name", "")] = toml_loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:
            params[element.get("Name", "")] = text          # a bare word: a string
    return params


def world_parameters(factory: Callable[..., World]) -> dict[str, Any]:
    """The parameters a world factory takes, with their defaults (``rng`` left out)."""
    signature = inspect.signature(factory)
    return {name: p.default for name, p in signature.parameters.items()
            if name != "rng" and p.kind is inspect.Parameter.KEYWORD_ONLY}


def _build(name: str, factory: Callable[..., World], rng: Any, params: Mapping[str, Any],
           attribute: ExtendedAttribute, file: str | None, inline: Mapping[str, Any]) -> World:
    known = world_parameters(factory)
    for key in params:
        if key not in known:
            where = (attribute.location if key in inline or file is None
                     else located(file, key))
            raise ConfigurationError(
                f"world {name!r} has no parameter {key!r}", location=where,
                hint=f"its parameters: {', '.join(sorted(known))}")
    try:
        return factory(rng, **params)
    except (TypeError, ValueError) as error:
        refused = _named_parameter(str(error), params)
        if refused is not None and refused.split("[")[0] in inline:
            where = attribute.location
        elif refused is not None and file is not None:
            where = located(file, refused)      # the line of the value the world refuses
        else:
            where = SourceLocation(file) if file and not inline else attribute.location
        raise ConfigurationError(f"world {name!r}: {error}", location=where,
                                 hint="check the world's parameters "
                                      "(docs/behaviour-specs.md, 'The worlds')") from None


def _named_parameter(message: str, params: Mapping[str, Any]) -> str | None:
    """The given parameter a world's refusal ``message`` names first (``start must be
    [x, y, heading]``), the entry of a list it shows (``obstacle [1, 2, 1, 3] needs x0 < x1``:
    ``obstacles[0]``), or None."""
    import re

    first: tuple[int, str] | None = None
    for key in params:
        # a parameter named in the singular ("obstacle" of obstacles), and not as a part of
        # another name (the "radius" of "ring_radius")
        found = re.search(rf"(?<![\w-]){re.escape(key.removesuffix('s'))}s?(?![\w-])",
                          message)
        if found is not None and (first is None or found.start() < first[0]):
            first = (found.start(), key)
    if first is None:
        return None
    key = first[1]
    value = params[key]
    if isinstance(value, list):         # the entry the message shows: obstacles[1]
        for index, entry in enumerate(value):
            if isinstance(entry, list) and str(entry) in message:
                return f"{key}[{index}]"
    return key


def world_performers(compiled: CompiledPackage, *, seed: int, user: int
                     ) -> dict[str, Performer]:
    """The performers of the world ``compiled`` declares ({} when it declares none).

    Raises :class:`ConfigurationError` for an unknown world (naming the known ones), an
    unreadable world file, an unknown parameter or an impossible value."""
    world = _world(compiled, seed=seed, user=user)
    if world is None:
        return {}
    from opspec.worlds.device import devices_of

    return {"world": devices_of(world)}


def check_world(compiled: CompiledPackage, *, seed: int = 0) -> None:
    """Build the world ``compiled`` declares once and drop it: the refusals of
    :func:`world_performers` (its file, its parameters) before any run, not in every one
    (an evaluation's replications each failing with the same message)."""
    _world(compiled, seed=seed, user=0)


def _world(compiled: CompiledPackage, *, seed: int, user: int) -> World | None:
    attribute = _attribute(compiled, "opspec:World")
    if attribute is None:
        return None
    name = (attribute.value or "").strip()
    factory = WORLDS.get(name)
    if factory is None:
        raise ConfigurationError(
            f"unknown world {name!r}", location=attribute.location or SourceLocation(
                compiled.package.source or "<spec>"),
            hint=f"known worlds: {', '.join(sorted(WORLDS))}")
    from opspec.engine.random import named_stream

    from_file, file = _file_parameters(compiled, attribute)
    inline = _inline_parameters(attribute)
    return _build(name, factory, named_stream(seed, f"world/{name}", (user,)),
                  {**from_file, **inline}, attribute, file, inline)
