"""The people a model check compares held-out people with: groups simulated from the model.

"People like them" is the model's *predictive* distribution (:mod:`opspec.usermodels.checking`):
each replicate group of simulated people uses one redraw of the model's parameters when the
model file carries ``[uncertainty]``, each simulated person is drawn from the population
(``[vary]``, subgroups), and each check draws that person's observations from their own
model. :class:`PredictivePeople` holds the groups; :func:`item_stream` is the random stream
each checked item draws from.
"""

from __future__ import annotations

import zlib
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from opspec.usermodels.model import UserModel
    from opspec.usermodels.uncertainty import ParameterDraws

__all__ = ["POOL_SIZE", "PredictivePeople", "item_stream"]


#: simulated people drawn for a population without parameter redraws (a person costs
#: milliseconds to draw); each replicate group takes its people at random from them
POOL_SIZE = 1000


class PredictivePeople:
    """``replicates`` groups of ``size`` simulated people, each group under one parameter
    redraw of ``draws`` (when given) and each person drawn from the population.

    Without redraws, people are drawn once into a pool of :data:`POOL_SIZE` (users ``0 …``
    of the population seeded ``seed``, its own stream) and each group takes ``size`` of
    them at random: the groups are as varied as the population. With redraws the people of
    one group share its redraw — that is what parameter uncertainty means for a group: all
    its people are off in the same direction — so every replicate group is drawn on its own
    (group ``b`` under redraw ``1 + b mod B``, its own people). Reusing a few groups for
    many replicates would make the replicates dependent, and the bootstrap p-value
    ``(1 + #exceed) / (B + 1)`` then too small: it would count one unusual group several
    times. ``bases[b]`` is group ``b``'s model (the redrawn one, before people are drawn).
    """

    def __init__(self, model: UserModel, size: int, replicates: int, seed: int,
                 draws: ParameterDraws | None = None) -> None:
        self.model = model
        self.size = size
        self.replicates = replicates
        self.draws = draws
        self.seed = seed
        distinct: list[list[UserModel]] = []
        self.bases: list[UserModel] = []
        if draws is None:
            if model.population is None:
                distinct = [[model] * size]
                self.groups = [distinct[0]] * replicates
            else:
                pool = [model.individual(seed, u).model
                        for u in range(min(POOL_SIZE, replicates * size))]
                distinct = [pool]
                rng = item_stream(seed, "people")
                self.groups = [[pool[i] for i in rng.choice(len(pool), size,
                                                            replace=len(pool) < size)]
                               for _ in range(replicates)]
        else:
            applied: dict[int, UserModel] = {}
            for g in range(replicates):
                index = 1 + g % draws.count
                base = applied.get(index)
                if base is None:
                    base = applied[index] = draws.apply(model, index)
                self.bases.append(base)
                if base.population is None:
                    distinct.append([base] * size)
                else:
                    distinct.append([base.individual(seed, g * size + j).model
                                     for j in range(size)])
            self.groups = distinct
        self.distinct = distinct

    def people(self) -> list[UserModel]:
        return [p for g in self.distinct for p in g]


def item_stream(seed: int, item: str) -> np.random.Generator:
    """The random stream of one checked ``item`` (``duration/ACTIVITY``, ``KIND/ACTIVITY``,
    ``people``) from the check's ``seed``: each item has its own, so what one item draws
    never shifts another's numbers."""
    return np.random.default_rng(np.random.SeedSequence(
        seed, spawn_key=(zlib.crc32(item.encode()),)))
