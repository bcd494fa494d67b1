"""The rules of a run's numbers, written once: the seed and the run length.

Every front door (``opspec run``, ``evaluate`` and its stored plans, ``walkthrough``,
:func:`opspec.run`, :func:`opspec.testing.simulate`, scenario files) and
:func:`opspec.runs.build` ask these functions, so that a seed or a length is refused with the
same words whatever door it came through. This module imports nothing heavy: the command line
checks ``--seed`` with it while parsing.
"""

from __future__ import annotations

import math
import operator
from decimal import Decimal
from typing import Any

from opspec.errors import ConfigurationError

__all__ = ["DAY", "MAX_SEED", "check_days", "check_seed", "parse_until", "run_length",
           "seconds_of_days"]

DAY = 86_400.0
#: numpy's SeedSequence takes non-negative integers; 2**63 - 1 keeps seeds in an SQLite integer
MAX_SEED = 2**63 - 1


def check_seed(seed: Any) -> int:
    """``seed`` as a plain int: a whole number from 0 to 2**63 - 1 (numpy integers too; not
    text, which the command line turns into a number first), else a
    :class:`ConfigurationError`."""
    if isinstance(seed, bool):
        raise ConfigurationError(f"a seed is a whole number, not {seed!r}")
    try:
        value = operator.index(seed)
    except TypeError:
        raise ConfigurationError(f"a seed is a whole number, not {seed!r}") from None
    if not 0 <= value <= MAX_SEED:
        raise ConfigurationError(f"{value} is out of range: a seed is a whole number "
                                 "from 0 to 2**63 - 1")
    return value


def _positive(value: Any) -> bool:
    return (not isinstance(value, bool) and isinstance(value, (int, float))
            and math.isfinite(value) and value > 0)


def check_days(days: Any, *, name: str = "days") -> float:
    """``days`` as a float: a positive, finite number of simulated days."""
    if not _positive(days):
        shown = f"{days:g}" if isinstance(days, float) else repr(days)
        raise ConfigurationError(f"{name} must be a positive number, not {shown}",
                                 hint=f"e.g. {name} 1 (or leave it out for the spec's "
                                 "opspec:RunLength)" if name.startswith("--") else "")
    return float(days)


def seconds_of_days(days: float) -> float:
    """``days`` in seconds, as the decimal number written: 0.7 days ends at 16:48:00
    (60480 s), not at the float product 60479.99999999999 s, which a clock of whole seconds
    shows as 16:47:59 (and ``--json`` as the run's end). Whole days are unchanged."""
    return float(Decimal(repr(float(days))) * Decimal(86_400))


def parse_until(until: Any, *, name: str = "until") -> float:
    """An end time in simulated seconds: a positive number, or text in the one duration
    grammar (:func:`opspec.clock.parse_duration`: ``90``, ``8h``, ``PT8H``)."""
    if isinstance(until, str):
        from opspec.clock import parse_duration

        try:
            value = parse_duration(until, error=ConfigurationError)
        except ConfigurationError as error:
            raise ConfigurationError(f"{name}: {error.message}", hint=error.hint) from None
    else:
        value = until
    if not _positive(value):
        raise ConfigurationError(f"{name} must be a positive number of seconds, not {until!r}")
    return float(value)


def run_length(spec: Any, *, days: Any = None, until: Any = None) -> float:
    """How long a run of ``spec`` (a Package or CompiledPackage) lasts, in simulated seconds:
    ``days`` or ``until`` when given, else the spec's ``opspec:RunLength``, else one day.
    Events that fall exactly at the end time are after the run."""
    if days is not None and until is not None:
        raise ConfigurationError("give days or until, not both")
    if days is not None:
        return seconds_of_days(check_days(days))
    if until is not None:
        return parse_until(until)
    package = getattr(spec, "package", spec)          # a CompiledPackage, or the Package
    declared = getattr(package, "run_length", None)
    return DAY if declared is None else float(declared)
