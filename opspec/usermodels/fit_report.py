"""What ``opspec fit`` says about what it fitted: per activity the chosen distribution, every
family's AIC/BIC, the omission rate's interval, the time a wrong pick costs and how much
people differ (:class:`ActivityFit`, written as TOML comments above the activity's table and
as JSON), and the whole fit (:class:`FitResult`) with the between-user ``[vary]`` tables the
data call for.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from opspec.usermodels.choice_estimates import WrongChoiceLoss
from opspec.usermodels.distributions import Distribution, Gamma, LogNormal, Weibull
from opspec.usermodels.families import CRITERIA, FamilyFit
from opspec.usermodels.model import UserModel
from opspec.usermodels.observations import Observations
from opspec.usermodels.spread import DurationSpread, OmissionSpread

__all__ = ["ActivityFit", "FitResult"]


@dataclass(frozen=True)
class ActivityFit:
    """The outcome for one activity: the chosen distribution, every family's fit, and why."""

    activity: str
    n: int
    distribution: Distribution
    chosen: str
    aic: dict[str, float]
    omission: tuple[int, int, tuple[float, float]] | None = None  # omitted, answered, CI
    note: str = ""
    families: tuple[FamilyFit, ...] = ()
    criterion: str = "aic"
    duration_spread: DurationSpread | None = None
    omission_spread: OmissionSpread | None = None
    wrong_choice: WrongChoiceLoss | None = None

    def family_table(self) -> list[str]:
        """The comparison of families as aligned text lines (chosen one marked)."""
        if not self.families:
            return []
        best = {c: min(f.score(c) for f in self.families) for c in CRITERIA}
        rows = [(f"  {'family':<10} {'parameters':<36} {'log L':>11} {'AIC':>10} {'dAIC':>7} "
                f"{'BIC':>10} {'dBIC':>7}")]
        for f in sorted(self.families, key=lambda f: f.score(self.criterion)):
            mark = "  <- chosen" if f.family == self.chosen else ""
            rows.append(f"  {f.family:<10} {f.describe():<36} {f.log_likelihood:>11.2f} "
                        f"{f.aic:>10.2f} {f.aic - best['aic']:>7.2f} {f.bic:>10.2f} "
                        f"{f.bic - best['bic']:>7.2f}{mark}")
        return rows

    def comment(self) -> str:
        lines = [f"{self.activity}: {self.n} observed duration(s); {self.note}".rstrip("; ")]
        if self.families:
            lines.append(f"duration: {self.chosen} chosen by {self.criterion.upper()} (lowest "
                         "wins; a difference under 2 is no real preference)")
            lines.extend(self.family_table())
        if self.omission is not None:
            k, n, (lo, hi) = self.omission
            lines.append(f"omission: {k}/{n} = {k / n:.4f}, Wilson 95 % interval "
                         f"[{lo:.4f}, {hi:.4f}]")
        for part in (self.wrong_choice, self.duration_spread, self.omission_spread):
            if part is not None:
                lines.append(part.comment())
        return "\n".join(lines)

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "n": self.n, "chosen": self.chosen, "criterion": self.criterion,
            "distribution": self.distribution.to_params(), "note": self.note or None,
            "families": [f.to_json() for f in self.families]}
        if self.omission is not None:
            k, n, (lo, hi) = self.omission
            out["omission"] = {"omitted": k, "answered": n, "rate": k / n, "ci95": [lo, hi]}
        out["wrong_choice"] = self.wrong_choice.to_json() if self.wrong_choice else None
        out["between_users"] = {
            "duration": self.duration_spread.to_json() if self.duration_spread else None,
            "omission": self.omission_spread.to_json() if self.omission_spread else None}
        return out


@dataclass(frozen=True)
class FitResult:
    """A fitted model plus the per-activity explanation written as TOML comments."""

    model: UserModel
    fits: tuple[ActivityFit, ...]
    observations: Observations

    def comments(self) -> dict[str, str]:
        return {f"activities.{f.activity}": f.comment() for f in self.fits}

    def to_json(self) -> dict[str, Any]:
        return {"events": self.observations.events, "runs": self.observations.runs,
                "files": self.observations.files,
                "activities": {f.activity: f.to_json() for f in self.fits}}

    def vary(self) -> dict[str, dict[str, dict[str, Any]]]:
        """The between-user variation to write as ``[vary.activities.ID.*]`` tables of the
        fitted file (``docs/user-models.md``, Populations): per activity, where the data
        show users differ (a duration spread whose 95 % interval excludes 0; omission rates
        that fail the chi-square test of one rate for all at 5 %). A lognormal's median, a
        gamma's or Weibull's scale varies lognormally with the between-user sd; the
        omission probability by a beta with the between-user mean and sd."""
        out: dict[str, dict[str, dict[str, Any]]] = {}
        for fit in self.fits:
            entry: dict[str, dict[str, Any]] = {}
            d = fit.duration_spread
            dist = fit.distribution
            if d is not None and d.between_sd_ci[0] > 0 and d.between_sd > 0:
                source = (f"fitted: between-user sd of ln(scale) {d.between_sd:.3f} (95 % "
                          f"interval [{d.between_sd_ci[0]:.3f}, {d.between_sd_ci[1]:.3f}], "
                          f"{d.users} users)")
                if isinstance(dist, LogNormal):
                    entry["duration"] = {"median": {
                        "kind": "lognormal", "median": math.exp(dist.mu),
                        "sigma": d.between_sd, "source": source}}
                elif isinstance(dist, (Gamma, Weibull)):
                    entry["duration"] = {"scale": {
                        "kind": "lognormal", "median": dist.scale, "sigma": d.between_sd,
                        "source": source}}
            o = fit.omission_spread
            if o is not None and o.varies:
                entry["omission"] = {"probability": {
                    "kind": "beta", "mean": o.mean, "sd": o.between_sd,
                    "source": f"fitted: between-user sd {o.between_sd:.4f} (95 % interval "
                    f"[{o.between_sd_ci[0]:.4f}, {o.between_sd_ci[1]:.4f}], {o.users} users; "
                    f"one rate for all: chi-square p = {o.homogeneity_p:.2g})"}}
            if entry:
                out[fit.activity] = entry
        return out
