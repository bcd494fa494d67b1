"""The values of simulation parameters, as BPSim and QBP write them, into opspec's
:class:`~opspec.model.DeclaredDistribution` (seconds): the model an ``opspec:Duration`` gives.

- **BPSim** (WfMC BPSim 1.0 and 2.0): a parameter (``bpsim:ProcessingTime``,
  ``bpsim:InterTriggerTimer``…) holds one parameter value: a constant
  (``FloatingParameter``/``NumericParameter value``, in the scenario's ``baseTimeUnit``;
  ``DurationParameter value`` an ISO 8601 duration) or a distribution
  (``NormalDistribution mean standardDeviation``, ``LogNormalDistribution mean
  standardDeviation`` — the moments of the variable itself —, ``UniformDistribution min max``,
  ``TriangularDistribution min mode max``, ``NegativeExponentialDistribution mean``,
  ``GammaDistribution shape scale``, ``ErlangDistribution k mean``,
  ``TruncatedNormalDistribution mean standardDeviation min max``, ``WeibullDistribution shape
  scale``).
- **QBP** (BIMP, Apromore): ``durationDistribution``/``arrivalRateDistribution`` with ``type``
  and ``mean``, ``arg1``, ``arg2``, always in seconds (the ``qbp:timeUnit`` child is only the
  unit BIMP shows), read as Prosimos's QBP reader reads them: ``FIXED`` mean; ``NORMAL`` mean,
  arg1 the standard deviation; ``EXPONENTIAL`` arg1 the mean (``mean`` when arg1 is 0);
  ``UNIFORM`` arg1 to arg2; ``TRIANGULAR`` arg1, mode ``mean``, arg2; ``LOGNORMAL`` and
  ``GAMMA`` mean, arg1 the variance.

A value opspec cannot map (a Poisson or binomial count, a user distribution, an expression) is
a located ``unread-simulation-parameter`` warning, and the element runs without it.
"""

from __future__ import annotations

import math
from typing import Final

from lxml import etree

from opspec.errors import SpecError
from opspec.model.sisarl import DeclaredDistribution
from opspec.xpdl.bpmn.common import Defs, local

__all__ = ["BPSIM_TIME_UNITS", "UNREAD", "bpsim_count", "bpsim_distribution", "bpsim_values",
           "qbp_distribution"]

#: BPSim's ``TimeUnit`` values in seconds (a year of 365 days).
BPSIM_TIME_UNITS: Final = {"ms": 0.001, "s": 1.0, "min": 60.0, "hour": 3600.0,
                           "day": 86_400.0, "year": 365 * 86_400.0}
#: The diagnostic code of a parameter opspec does not read.
UNREAD: Final = "unread-simulation-parameter"

# BPSim distribution -> (opspec kind, its parameters as (BPSim attribute, opspec name, is a
# time)); a time is scaled by the base time unit, a shape is not.
_BPSIM: Final[dict[str, tuple[str, tuple[tuple[str, str, bool], ...]]]] = {
    "NormalDistribution": ("NormalDistribution", (("mean", "mean", True),
                                                  ("standardDeviation", "standardDeviation",
                                                   True))),
    "LogNormalDistribution": ("LogNormalDistribution", (("mean", "mean", True),
                                                        ("standardDeviation",
                                                         "standardDeviation", True))),
    "UniformDistribution": ("UniformDistribution", (("min", "min", True),
                                                    ("max", "max", True))),
    "TriangularDistribution": ("TriangularDistribution", (("min", "min", True),
                                                          ("mode", "mode", True),
                                                          ("max", "max", True))),
    "NegativeExponentialDistribution": ("ExponentialDistribution", (("mean", "mean", True),)),
    "ExponentialDistribution": ("ExponentialDistribution", (("mean", "mean", True),)),
    "GammaDistribution": ("GammaDistribution", (("shape", "shape", False),
                                                ("scale", "scale", True))),
    "WeibullDistribution": ("WeibullDistribution", (("shape", "shape", False),
                                                    ("scale", "scale", True))),
    "TruncatedNormalDistribution": ("TruncatedNormalDistribution", (
        ("mean", "mean", True), ("standardDeviation", "standardDeviation", True),
        ("min", "min", True), ("max", "max", True))),
}
_BPSIM["TruncatedNormal"] = _BPSIM["TruncatedNormalDistribution"]
_CONSTANTS: Final = frozenset({"FloatingParameter", "NumericParameter"})


def _number(element: etree._Element, attribute: str, defs: Defs, what: str) -> float | None:
    raw = element.get(attribute)
    try:
        value = float(raw) if raw is not None else math.nan
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        shown = "is missing" if raw is None else f"{raw!r} is not a number"
        defs.ctx.warning(element, UNREAD, f"{what}: {attribute} of {local(element)} {shown}; "
                         "opspec runs without this parameter", f"give {attribute} a number")
        return None
    return value


def _checked(dist: DeclaredDistribution, element: etree._Element, defs: Defs,
             what: str) -> DeclaredDistribution | None:
    """``dist`` if it is a distribution of durations opspec can draw from, else a warning."""
    from opspec.distributions import ParameterError, from_model

    try:
        from_model(dist)
    except ParameterError as error:
        defs.ctx.warning(element, UNREAD, f"{what}: {local(element)} {error.param} "
                         f"{error.detail}; opspec runs without this parameter",
                         error.hint or "give parameters that describe a distribution of "
                         "durations")
        return None
    for name, value in dist.parameters:
        if value < 0 and name not in ("mean", "min"):
            defs.ctx.warning(element, UNREAD, f"{what}: {local(element)} {name} is negative; "
                             "opspec runs without this parameter", "give times of 0 or more")
            return None
    return dist


def bpsim_values(parameter: etree._Element) -> list[etree._Element]:
    """The parameter values of a BPSim parameter: its element children but the
    ``ResultRequest``s (which ask a simulator for results, and hold no value)."""
    return [v for v in parameter if isinstance(v.tag, str) and local(v) != "ResultRequest"]


def bpsim_distribution(parameter: etree._Element, unit: float, defs: Defs,
                       what: str) -> DeclaredDistribution | None:
    """The value of a BPSim parameter (``bpsim:ProcessingTime``…) in seconds, ``unit`` being
    the seconds of the scenario's base time unit; ``None`` (with a warning) when there is none
    opspec can read."""
    values = bpsim_values(parameter)
    if not values:
        defs.ctx.warning(parameter, UNREAD, f"{what}: {local(parameter)} holds no value; "
                         "opspec runs without it", "give it a FloatingParameter or a "
                         "distribution")
        return None
    value = values[0]
    if len(values) > 1:
        defs.ctx.warning(values[1], UNREAD, f"{what}: {local(parameter)} holds "
                         f"{len(values)} values (for calendars or instances); opspec reads the "
                         "first", "keep one value")
    kind = local(value)
    if kind in _CONSTANTS:
        number = _number(value, "value", defs, what)
        if number is None:
            return None
        return _checked(DeclaredDistribution(kind="ConstantParameter",
                                             parameters=(("value", number * unit),)),
                        value, defs, what)
    if kind == "DurationParameter":
        from opspec.clock import parse_duration

        try:
            seconds = parse_duration(value.get("value") or "", location=defs.loc(value))
        except SpecError as error:
            defs.ctx.warning(value, UNREAD, f"{what}: {error.message}; opspec runs without "
                             "this parameter", "write an ISO 8601 duration such as PT5M")
            return None
        return DeclaredDistribution(kind="ConstantParameter", parameters=(("value", seconds),))
    if kind == "ErlangDistribution":
        k = _number(value, "k", defs, what)
        mean = _number(value, "mean", defs, what)
        if k is None or mean is None:
            return None
        if k <= 0:
            defs.ctx.warning(value, UNREAD, f"{what}: ErlangDistribution k must be more than "
                             "0; opspec runs without this parameter", "give k = 1, 2, 3…")
            return None
        # Erlang(k, mean) is the gamma distribution of shape k and scale mean / k
        return _checked(DeclaredDistribution(kind="GammaDistribution", parameters=(
            ("shape", k), ("scale", mean * unit / k))), value, defs, what)
    known = _BPSIM.get(kind)
    if known is None:
        defs.ctx.warning(value, UNREAD, f"{what}: opspec cannot draw durations from a BPSim "
                         f"{kind}; it runs without this parameter",
                         "use a FloatingParameter, DurationParameter or a normal, lognormal, "
                         "uniform, triangular, exponential, gamma, Erlang, truncated normal "
                         "or Weibull distribution (docs/bpmn.md, Simulation parameters)")
        return None
    target, names = known
    parameters: list[tuple[str, float]] = []
    for attribute, name, is_time in names:
        number = _number(value, attribute, defs, what)
        if number is None:
            return None
        parameters.append((name, number * unit if is_time else number))
    return _checked(DeclaredDistribution(kind=target, parameters=tuple(parameters)), value,
                    defs, what)


def bpsim_count(parameter: etree._Element, defs: Defs, what: str) -> int | None:
    """A BPSim count (``bpsim:TriggerCount``): a whole number of 0 or more."""
    values = bpsim_values(parameter)
    if not values or local(values[0]) not in _CONSTANTS:
        defs.ctx.warning(parameter, UNREAD, f"{what}: {local(parameter)} is not a "
                         "NumericParameter; opspec does not read it",
                         "give <bpsim:NumericParameter value=\"100\"/>")
        return None
    number = _number(values[0], "value", defs, what)
    if number is None:
        return None
    if number < 0 or number != int(number):
        defs.ctx.warning(values[0], UNREAD, f"{what}: {local(parameter)} {number:g} is no "
                         "whole number of 0 or more; opspec does not read it",
                         "give a count such as 100")
        return None
    return int(number)


def qbp_distribution(element: etree._Element, defs: Defs, what: str
                     ) -> DeclaredDistribution | None:
    """A QBP ``durationDistribution`` or ``arrivalRateDistribution`` (seconds)."""
    kind = (element.get("type") or "").strip().upper()
    args: dict[str, float] = {}
    for attribute in ("mean", "arg1", "arg2"):
        raw = element.get(attribute)
        if raw is None:
            args[attribute] = 0.0
            continue
        number = _number(element, attribute, defs, what)
        if number is None:
            return None
        args[attribute] = number
    mean, arg1, arg2 = args["mean"], args["arg1"], args["arg2"]
    dist: DeclaredDistribution
    if kind == "FIXED":
        dist = DeclaredDistribution(kind="ConstantParameter", parameters=(("value", mean),))
    elif kind == "NORMAL":
        dist = (DeclaredDistribution(kind="ConstantParameter", parameters=(("value", mean),))
                if arg1 == 0 else DeclaredDistribution(kind="NormalDistribution", parameters=(
                    ("mean", mean), ("standardDeviation", arg1))))
    elif kind == "EXPONENTIAL":
        dist = DeclaredDistribution(kind="ExponentialDistribution",
                                    parameters=(("mean", arg1 if arg1 > 0 else mean),))
    elif kind == "UNIFORM":
        dist = DeclaredDistribution(kind="UniformDistribution",
                                    parameters=(("min", arg1), ("max", arg2)))
    elif kind == "TRIANGULAR":
        dist = DeclaredDistribution(kind="TriangularDistribution",
                                    parameters=(("min", arg1), ("mode", mean), ("max", arg2)))
    elif kind in ("LOGNORMAL", "GAMMA") and mean > 0 and arg1 > 0:
        if kind == "LOGNORMAL":
            dist = DeclaredDistribution(kind="LogNormalDistribution", parameters=(
                ("mean", mean), ("standardDeviation", math.sqrt(arg1))))
        else:                       # shape mean²/variance, scale variance/mean
            dist = DeclaredDistribution(kind="GammaDistribution", parameters=(
                ("shape", mean * mean / arg1), ("scale", arg1 / mean)))
    elif kind in ("LOGNORMAL", "GAMMA"):
        defs.ctx.warning(element, UNREAD, f"{what}: a QBP {kind} needs mean and arg1 (the "
                         "variance) above 0; opspec runs without this parameter",
                         "give mean and arg1")
        return None
    else:
        defs.ctx.warning(element, UNREAD, f"{what}: opspec cannot draw durations from a QBP "
                         f"distribution of type {kind or '(none)'!r}; it runs without this "
                         "parameter", "use FIXED, NORMAL, EXPONENTIAL, UNIFORM, TRIANGULAR, "
                         "LOGNORMAL or GAMMA (docs/bpmn.md, Simulation parameters)")
        return None
    return _checked(dist, element, defs, what)
