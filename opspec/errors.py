"""One exception tree for opspec, plus the source locations and diagnostics every layer reports.

Every message a user sees says *what* went wrong, *where* (``path:line`` for specifications,
``path: key`` for TOML files) and *how to fix it*. Non-fatal problems are collected as
:class:`Diagnostic` values; only fatal ones are raised.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

__all__ = [
    "BindingError",
    "ConfigurationError",
    "Diagnostic",
    "EvaluationError",
    "ExecutionError",
    "OpspecError",
    "Severity",
    "SourceLocation",
    "SpecError",
    "UserModelError",
    "ZeroTimeCycleError",
]


@dataclass(frozen=True, slots=True)
class SourceLocation:
    """Where something came from: a file and, when known, a 1-based line.

    ``line`` is ``None`` when lxml cannot tell (for instance past line 65,535 for empty
    elements, where ``sourceline`` is unreliable) or when the thing was built in Python.
    ``key`` names a dotted key inside a TOML/JSON file (``users.walk.sigma``).
    """

    path: str
    line: int | None = None
    key: str | None = None

    def __str__(self) -> str:
        text = self.path
        if self.line is not None:
            text = f"{text}:{self.line}"
        if self.key:
            text = f"{text}: {self.key}"
        return text


class Severity(enum.Enum):
    """How bad a diagnostic is. Strict mode promotes warnings to errors."""

    ERROR = "error"
    WARNING = "warning"
    INFO = "info"


def with_hint(text: str, hint: str) -> str:
    """A message and what to do about it: the hint in parentheses after the message, or,
    when the hint has parentheses of its own, after a semicolon (a parenthesis inside a
    parenthesis reads as a slip: "(e.g. --days 1 (or leave it out))")."""
    if not hint:
        return text
    if "(" in hint:
        return f"{text}; {hint}"
    return f"{text} ({hint})"


@dataclass(frozen=True, slots=True)
class Diagnostic:
    """One problem found in an input, reported without stopping the load.

    ``code`` is a stable, kebab-case identifier (``dangling-transition``) that tests and
    ``--json`` consumers can match on; ``hint`` tells the user what to do about it.
    """

    location: SourceLocation
    severity: Severity
    code: str
    message: str
    hint: str = ""

    def __str__(self) -> str:
        return with_hint(f"{self.location}: {self.severity.value}: {self.message}", self.hint)

    def to_json(self) -> dict[str, object]:
        return {
            "path": self.location.path,
            "line": self.location.line,
            "severity": self.severity.value,
            "code": self.code,
            "message": self.message,
            "hint": self.hint,
        }


class OpspecError(Exception):
    """Root of every error opspec raises on purpose.

    The CLI catches this class, prints ``str(error)`` and exits non-zero; anything else
    that escapes is a bug in opspec.
    """

    def __init__(
        self, message: str, *, location: SourceLocation | None = None, hint: str = ""
    ) -> None:
        self.message = message
        self.location = location
        self.hint = hint
        super().__init__(self._render())

    def _render(self) -> str:
        text = self.message
        if self.location is not None:
            text = f"{self.location}: {text}"
        return with_hint(text, self.hint)


class SpecError(OpspecError):
    """A specification cannot be read, understood or resolved.

    ``diagnostics`` holds every problem found in the same pass, so a user fixes them all at
    once instead of one per run.
    """

    def __init__(
        self,
        message: str,
        *,
        location: SourceLocation | None = None,
        hint: str = "",
        diagnostics: Sequence[Diagnostic] = (),
    ) -> None:
        self.diagnostics: tuple[Diagnostic, ...] = tuple(diagnostics)
        super().__init__(message, location=location, hint=hint)

    @classmethod
    def from_diagnostics(cls, diagnostics: Iterable[Diagnostic]) -> SpecError:
        """Raise-ready error summarising the errors among ``diagnostics``."""
        diags = tuple(diagnostics)
        errors = [d for d in diags if d.severity is Severity.ERROR] or list(diags)
        first = errors[0]
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        return cls(
            f"{first.message}{more}",
            location=first.location,
            hint=first.hint,
            diagnostics=diags,
        )


class ExecutionError(OpspecError):
    """Running a specification failed: a deadlock, an activity that raised, a bad binding of
    data at run time. Carries the simulated time when known."""

    def __init__(
        self,
        message: str,
        *,
        location: SourceLocation | None = None,
        hint: str = "",
        sim_time: float | None = None,
    ) -> None:
        self.sim_time = sim_time
        super().__init__(message, location=location, hint=hint)


class ZeroTimeCycleError(ExecutionError):
    """The simulated clock stopped advancing: work keeps running at one instant (a cycle of
    instantaneous activities, a workflow that starts itself with no delay)."""


class BindingError(OpspecError):
    """A device binding or device profile is unusable (port missing, profile malformed)."""


class UserModelError(OpspecError):
    """A user-model file or preset is invalid (unknown distribution, bad parameter)."""


class ConfigurationError(OpspecError):
    """Engine or run configuration is invalid (bad TOML, unknown option, impossible value)."""


class EvaluationError(OpspecError):
    """An evaluation run cannot start, continue or be stored (unwritable output, bad resume)."""
