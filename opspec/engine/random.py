"""Seeded random streams, one per entity, reproducible and independent of each other.

Every stochastic thing in a run (an activity's duration, a simulated user, a device fault
model) draws from its own :class:`numpy.random.Generator`, derived from the run seed and the
entity's identity, never from a shared global stream. So adding a user, a household or an
activity to a run does not change what any other entity draws.

- ``user_stream(seed, u)`` is ``default_rng(SeedSequence(seed, spawn_key=(u,)))``, which is
  exactly ``SeedSequence(seed).spawn(n)[u]`` for any ``n > u``: user ``u`` has the same
  stream whatever the number of users (and the same as the reference baseline's user ``u``).
- ``named_stream(seed, name, scope)`` hashes ``name`` (CRC-32, stable across processes and
  Python versions, unlike ``hash``) into a spawn key of a different length, so named streams
  never collide with user streams.
"""

from __future__ import annotations

import zlib
from collections.abc import Sequence

import numpy as np

__all__ = ["Streams", "named_stream", "user_stream"]

_NAMED = 0x6F70_7370      # "opsp": marks spawn keys of named streams


def user_stream(seed: int, user: int) -> np.random.Generator:
    """The stream of user (household) ``user`` in a run seeded with ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(user,)))


def named_stream(seed: int, name: str, scope: Sequence[int] = ()) -> np.random.Generator:
    """The stream of the entity called ``name`` (within household ``scope``, if any)."""
    key = (*scope, _NAMED, zlib.crc32(name.encode("utf-8")))
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key))


class Streams:
    """The random streams of one simulation: created lazily, cached by name.

    ``scope`` is the household index path of the simulation (``(k,)`` for household ``k`` of
    an evaluation, ``()`` for a lone run); it is prepended to every named stream's key.
    """

    __slots__ = ("_cache", "scope", "seed")

    def __init__(self, seed: int, scope: Sequence[int] = ()) -> None:
        self.seed = int(seed)
        self.scope = tuple(scope)
        self._cache: dict[str, np.random.Generator] = {}

    def stream(self, name: str) -> np.random.Generator:
        """The stream of entity ``name`` (same object on every call)."""
        rng = self._cache.get(name)
        if rng is None:
            rng = self._cache[name] = named_stream(self.seed, name, self.scope)
        return rng

    def user(self, user: int | None = None) -> np.random.Generator:
        """The user stream of this household (``scope[0]``) or of user ``user``."""
        if user is None:
            user = self.scope[0] if self.scope else 0
        return user_stream(self.seed, user)
