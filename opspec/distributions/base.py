"""The base of every duration distribution, its parameter error, and shared helpers.

See :mod:`opspec.distributions` for the contract and the factories.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import fields
from statistics import NormalDist
from typing import TYPE_CHECKING, Any, TypeAlias

from opspec.errors import UserModelError

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt

__all__ = ["Distribution", "FloatArray", "ParameterError"]

if TYPE_CHECKING:
    FloatArray: TypeAlias = npt.NDArray[np.float64]


def __getattr__(name: str) -> Any:
    """``FloatArray`` (numpy's array of floats), made when first read: numpy is imported
    where an array is made, not by this module, so that a user model is loaded and checked
    without it (`opspec validate SPEC` checks the companion user model: issue 31's
    start-up)."""
    if name == "FloatArray":
        import numpy as np
        import numpy.typing as npt

        return npt.NDArray[np.float64]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
_STD_NORMAL = NormalDist()
_SQRT2 = math.sqrt(2.0)


class ParameterError(UserModelError):
    """A distribution parameter is invalid; ``param`` names it (``sigma``), so a loader can
    prefix the dotted key of the table it came from."""

    def __init__(self, param: str, message: str, *, hint: str = "") -> None:
        self.param = param
        self.detail = message
        super().__init__(f"{param}: {message}", hint=hint)


def _finite(param: str, value: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(param, f"must be a number, got {value!r}")
    value = float(value)
    if math.isnan(value):
        raise ParameterError(param, "must be a number, got nan")
    return value


def _positive(param: str, value: float) -> float:
    value = _finite(param, value)
    if not value > 0 or math.isinf(value):
        raise ParameterError(param, f"must be > 0, got {value:g}")
    return value


def _non_negative(param: str, value: float) -> float:
    value = _finite(param, value)
    if value < 0 or math.isinf(value):
        raise ParameterError(param, f"must be >= 0, got {value:g}")
    return value


def _check_fields(instance: object, **checks: Callable[[str, float], float]) -> None:
    """Check (and normalise to float) each named parameter of a frozen dataclass in
    ``__post_init__``: ``_check_fields(self, shape=_positive, scale=_positive)``."""
    for name, check in checks.items():
        object.__setattr__(instance, name, check(name, getattr(instance, name)))


def _phi(z: float) -> float:
    """Standard normal density."""
    return math.exp(-0.5 * z * z) / math.sqrt(2.0 * math.pi) if math.isfinite(z) else 0.0


def _ncdf(z: float) -> float:
    """Standard normal CDF, accurate in the lower tail (erfc)."""
    return 0.5 * math.erfc(-z / _SQRT2)


def _check_q(q: float) -> float:
    if not 0.0 <= q <= 1.0:
        raise ValueError(f"quantile level must be in [0, 1], got {q}")
    return q


class Distribution(ABC):
    """Base of every duration distribution (values in seconds)."""

    kind: str = ""

    @abstractmethod
    def sample(self, rng: np.random.Generator) -> float:
        """One draw."""

    @abstractmethod
    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        """``n`` draws as a float array."""

    @property
    @abstractmethod
    def mean(self) -> float: ...

    @property
    @abstractmethod
    def var(self) -> float: ...

    @property
    def sd(self) -> float:
        return math.sqrt(self.var)

    def cdf(self, x: float) -> float:
        raise NotImplementedError(f"{self.kind}: cdf is not available")

    def quantile(self, q: float) -> float:
        raise NotImplementedError(f"{self.kind}: quantile is not available")

    @abstractmethod
    def scaled(self, factor: float) -> Distribution:
        """The distribution of ``factor * X`` (``factor`` > 0)."""

    def to_params(self) -> dict[str, Any]:
        """The TOML table form, read back by :func:`make_distribution`: the kind and each
        parameter under its field's name (a class whose TOML names differ overrides this)."""
        return {"kind": self.kind,
                **{f.name: getattr(self, f.name) for f in fields(self) if f.init}}  # type: ignore[arg-type]
