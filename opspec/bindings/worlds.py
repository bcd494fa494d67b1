"""Simulated worlds that specs declare for their devices (robots in rooms and rings).

A package names its world with ``<ExtendedAttribute Name="opspec:World" Value="vacuum-room"/>``
and may give parameters in a TOML file next to the spec
(``<ExtendedAttribute Name="opspec:WorldFile" Value="vacuum_cleaner.world.toml"/>``, keys as
the world's constructor takes them: ``width``, ``obstacles``…). :func:`world_performers` gives
the performers ``opspec run``, ``opspec evaluate``, the walkthrough and the test helpers bind:
one per world, serving the world's applications by Application id. Each simulated user gets a
world of their own, drawing from a stream derived from ``(seed, user)``.

Worlds are registered here by name; spec text never names Python code.
"""

from __future__ import annotations

import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from opspec.errors import ConfigurationError, SourceLocation

if TYPE_CHECKING:
    from opspec.bindings.world.base import World
    from opspec.engine.compiled import CompiledPackage
    from opspec.engine.performers import Performer

__all__ = ["WORLDS", "world_performers"]


def _room(rng: Any, **params: Any) -> World:
    from opspec.bindings.world.room import RoomWorld

    return RoomWorld(rng, **params)


def _ward(rng: Any, **params: Any) -> World:
    from opspec.bindings.world.room import RoomWorld

    defaults: dict[str, Any] = {"width": 20.0, "height": 3.0, "start": (0.6, 1.5, 0.0),
                                "obstacles": ((6.0, 0.0, 6.6, 1.0), (11.0, 2.0, 11.6, 3.0)),
                                "tag": (17.0, 2.4), "drain_per_s": 0.0}
    return RoomWorld(rng, **{**defaults, **params})


def _ring(rng: Any, **params: Any) -> World:
    from opspec.bindings.world.sumo import SumoWorld

    return SumoWorld(rng, **params)


#: world name → factory(rng, **parameters)
WORLDS: dict[str, Callable[..., World]] = {
    "vacuum-room": _room,
    "ward": _ward,
    "sumo-ring": _ring,
}


def _attribute(compiled: CompiledPackage, name: str) -> Any:
    for attribute in compiled.package.extended_attributes:
        if attribute.name == name:
            return attribute
    return None


def _parameters(compiled: CompiledPackage, world_attr: Any) -> dict[str, Any]:
    attribute = _attribute(compiled, "opspec:WorldFile")
    if attribute is None or not attribute.value:
        return {}
    base = Path(compiled.package.source or ".").parent
    path = base / attribute.value
    where = attribute.location or world_attr.location
    try:
        with open(path, "rb") as handle:
            return dict(tomllib.load(handle))
    except OSError as error:
        raise ConfigurationError(f"cannot read the world file {path}: "
                                 f"{error.strerror or error}", location=where,
                                 hint="opspec:WorldFile is relative to the spec") from None
    except tomllib.TOMLDecodeError as error:
        raise ConfigurationError(f"{path}: not valid TOML: {error}", location=where) from None


def world_performers(compiled: CompiledPackage, *, seed: int, user: int
                     ) -> dict[str, Performer]:
    """The performers of the world ``compiled`` declares ({} when it declares none)."""
    attribute = _attribute(compiled, "opspec:World")
    if attribute is None:
        return {}
    name = (attribute.value or "").strip()
    factory = WORLDS.get(name)
    if factory is None:
        raise ConfigurationError(
            f"unknown world {name!r}", location=attribute.location or SourceLocation(
                compiled.package.source or "<spec>"),
            hint=f"known worlds: {', '.join(sorted(WORLDS))}")
    from opspec.bindings.world.device import WorldDevices
    from opspec.engine.random import named_stream

    params = _parameters(compiled, attribute)
    try:
        world = factory(named_stream(seed, f"world/{name}", (user,)), **params)
    except TypeError as error:
        raise ConfigurationError(f"world {name!r}: bad parameters: {error}",
                                 location=attribute.location,
                                 hint="check the keys of the opspec:WorldFile") from None
    return {"world": WorldDevices(world)}
