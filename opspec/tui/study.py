"""A walkthrough study: participants, design variants in counterbalanced orders, every
session recorded under its participant and variant (``opspec study PROTOCOL.toml``).

The protocol (TOML, paths relative to it)::

    [study]
    name = "dispenser: re-alarm after 5 or 2 minutes"
    days = 1                      # simulated days of each session (default: each spec's)
    speed = 60                    # simulated seconds per wall second at start
    seed = 0                      # every session runs the variant's spec with this seed
    recordings = "recordings"     # RECORDINGS/<participant>/<variant>.json (+ .trace.jsonl)

    [[variants]]
    id = "A"
    spec = "specs/medication_dispenser.xpdl"
    told = "The dispenser will ring when a dose is due. Take your pills as at home."

    [[variants]]
    id = "B"
    spec = "dispenser-2min.xpdl"
    told = "..."

    participants = ["P01", "P02", "P03"]     # (under [study])

Orders are counterbalanced by a Latin square: participant ``i`` (in file order) takes row
``i mod rows`` of a Williams design (Williams 1949), in which every variant comes first
equally often and, for an even number of variants, follows every other variant equally
often; for an odd number the square and its mirror image are used (2k rows).

A session is done when its run reached its end: a ``.done`` file beside the recording says
so. A session that breaks off (the participant quits early, the terminal closes) keeps its
recording as ``<variant>.partial-N.json`` and is started again the next time the participant
resumes (``opspec study PROTOCOL --participant P02`` goes on with the first session not
done). :func:`check_recordings` refuses a recordings folder whose done sessions were recorded
with another spec or in another order. The summary over the participants is
:mod:`opspec.tui.study_summary`.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from opspec.errors import ConfigurationError, SourceLocation
from opspec.toml_lines import located

# the summary, opspec.tui.study_summary, stays importable from here
from opspec.tui.study_summary import session_pairs, summary, summary_lines, variant_estimate

__all__ = ["Protocol", "Session", "Variant", "check_recordings", "keep_partial", "latin_square",
           "load_protocol", "session_pairs", "summary", "summary_lines", "variant_estimate"]


@dataclass(frozen=True)
class Variant:
    id: str
    spec: Path
    told: str = ""


@dataclass(frozen=True)
class Session:
    """One participant's session of one variant: where its files are."""

    participant: str
    variant: Variant
    position: int                # 1-based, in the participant's order
    recording: Path

    @property
    def trace(self) -> Path:
        return self.recording.with_suffix(".trace.jsonl")

    @property
    def done_marker(self) -> Path:
        return self.recording.with_suffix(".done")

    @property
    def done(self) -> bool:
        return self.done_marker.is_file()


def latin_square(k: int) -> list[list[int]]:
    """The rows of a Williams design for ``k`` conditions (each a permutation of
    ``range(k)``): first row 0, 1, k−1, 2, k−2, …, each next row that plus one mod k; for odd
    ``k`` followed by the mirror image of each row."""
    first: list[int] = [0]
    low, high = 1, k - 1
    while len(first) < k:
        first.append(low)
        low += 1
        if len(first) < k:
            first.append(high)
            high -= 1
    rows = [[(c + r) % k for c in first] for r in range(k)]
    if k % 2 == 1:
        rows += [list(reversed(row)) for row in rows]
    return rows


@dataclass(frozen=True)
class Protocol:
    name: str
    path: Path
    variants: tuple[Variant, ...]
    participants: tuple[str, ...]
    recordings: Path
    days: float | None = None
    speed: float = 60.0
    seed: int = 0

    def order(self, participant: str) -> list[Variant]:
        """The variants ``participant`` performs, in their counterbalanced order."""
        if participant not in self.participants:
            raise ConfigurationError(
                f"participant {participant!r} is not in the protocol",
                location=located(str(self.path), "study.participants"),
                hint="the protocol's participants: " + ", ".join(self.participants))
        rows = latin_square(len(self.variants))
        row = rows[self.participants.index(participant) % len(rows)]
        return [self.variants[i] for i in row]

    def sessions(self, participant: str) -> list[Session]:
        safe = _file_safe(participant)
        return [Session(participant, v, i + 1, self.recordings / safe / f"{v.id}.json")
                for i, v in enumerate(self.order(participant))]

    def pending(self, participant: str) -> list[Session]:
        return [s for s in self.sessions(participant) if not s.done]


def check_recordings(protocol: Protocol) -> None:
    """Every session marked done was recorded with its variant's spec (compared by file
    name, so that a study folder can move): a recordings folder left by another study, or
    a protocol whose variant now names another spec, would otherwise count those sessions
    as done and replay their traces with the wrong spec's metrics."""
    for participant in protocol.participants:
        for session in protocol.sessions(participant):
            if not session.done:
                continue
            marker = session.done_marker
            try:
                written = json.loads(marker.read_text(encoding="utf-8"))
                recorded, position = written.get("spec"), written.get("position")
            except (OSError, ValueError, AttributeError):
                recorded = position = None
            if not isinstance(recorded, str):
                raise ConfigurationError(
                    "this session's done marker does not say which spec it was recorded "
                    "with", location=SourceLocation(str(marker)),
                    hint="delete the marker to run the session again")
            if Path(recorded).name != session.variant.spec.name:
                raise ConfigurationError(
                    f"session {session.variant.id} of {participant} was recorded with "
                    f"{Path(recorded).name}, but variant {session.variant.id} is now "
                    f"{session.variant.spec.name}",
                    location=SourceLocation(str(marker)),
                    hint="the protocol changed after the session, or its recordings folder "
                    "holds another study's: give this study a folder of its own "
                    "(recordings = \"...\" under [study]), or move those sessions aside")
            if isinstance(position, int) and position != session.position:
                # a participant put before others in the list moves them to other rows of
                # the Latin square: their remaining sessions would run out of balance
                raise ConfigurationError(
                    f"{participant} did variant {session.variant.id} as session {position}, "
                    f"but the protocol now puts it at {session.position}: the participants' "
                    "order changed", location=SourceLocation(str(marker)),
                    hint="each participant's order is their place in the list: keep the "
                    "list's order and add new participants at its end")


def _file_safe(text: str) -> str:
    import re

    return re.sub(r"[^A-Za-z0-9_-]", "_", text)


def load_protocol(path: str | Path) -> Protocol:
    """Read and check a protocol; every problem names ``file`` and the key."""
    source = Path(path)
    where = str(source)

    def bad(key: str, message: str, hint: str = "") -> ConfigurationError:
        # at the line the key (or its table) is written on, as every TOML input's errors
        return ConfigurationError(message, location=located(where, key), hint=hint)

    from opspec.toml_files import read_toml

    # the one reader of TOML people write: a pipe never blocks, nesting is bounded
    data = read_toml(source, what="the protocol")
    study = data.get("study", {})
    if not isinstance(study, dict):
        raise bad("study", "must be a table")
    unknown = sorted(set(study) - {"name", "days", "speed", "seed", "recordings",
                                   "participants"})
    if unknown:
        raise bad(f"study.{unknown[0]}", f"unknown key {unknown[0]!r}",
                  "keys of [study]: name, days, speed, seed, recordings, participants")
    people = study.get("participants")
    if (not isinstance(people, list) or not people
            or not all(isinstance(p, str) and p.strip() and p.isprintable() for p in people)):
        raise bad("study.participants", "must list the participants' identifiers",
                  'for example participants = ["P01", "P02", "P03"]')
    if len(set(people)) != len(people):
        raise bad("study.participants", "lists a participant twice")
    variants = data.get("variants")
    if not isinstance(variants, list) or len(variants) < 1:
        raise bad("variants", "needs at least one [[variants]] table with id and spec")
    out: list[Variant] = []
    for i, v in enumerate(variants):
        key = f"variants[{i}]"
        if not isinstance(v, dict) or not isinstance(v.get("id"), str) or not v["id"]:
            raise bad(f"{key}.id", "each variant needs an id (text)")
        if not isinstance(v.get("spec"), str):
            raise bad(f"{key}.spec", "each variant needs the path of its spec")
        spec = (source.parent / v["spec"]).resolve()
        if not spec.is_file():
            raise bad(f"{key}.spec", f"no spec at {spec}",
                      "paths in a protocol are relative to the protocol's file")
        told = v.get("told", "")
        if not isinstance(told, str):
            raise bad(f"{key}.told", "must be the text the participant reads before")
        out.append(Variant(v["id"], spec, told))
    if len({v.id for v in out}) != len(out):
        raise bad("variants", "two variants share an id")
    days = study.get("days")
    if days is not None and (isinstance(days, bool) or not isinstance(days, (int, float))
                             or not (days > 0 and math.isfinite(days))):
        raise bad("study.days", f"must be a positive number of days, not {days!r}")
    speed = study.get("speed", 60.0)
    if isinstance(speed, bool) or not isinstance(speed, (int, float)) or not speed > 0:
        raise bad("study.speed", f"must be a positive number, not {speed!r}")
    seed = study.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise bad("study.seed", f"must be a whole number >= 0, not {seed!r}")
    recordings = source.parent / str(study.get("recordings", "recordings"))
    return Protocol(str(study.get("name", source.stem)), source, tuple(out), tuple(people),
                    recordings, None if days is None else float(days), float(speed), seed)


# ------------------------------------------------------------------ one session


def _briefing_app(base: Any) -> Any:
    """The walkthrough app with the variant's briefing shown first (the clock waits)."""
    from textual.app import ComposeResult
    from textual.binding import Binding
    from textual.containers import Vertical
    from textual.screen import ModalScreen
    from textual.widgets import Static

    class Briefing(ModalScreen[None]):
        """What the participant is told before the session; Enter starts it."""

        BINDINGS = [Binding("enter", "start", "start")]
        DEFAULT_CSS = """Briefing { align: center middle; }
        #brief { width: 70; height: auto; border: heavy $accent; padding: 1 2;
                 background: $panel; }"""

        def __init__(self, title: str, text: str) -> None:
            super().__init__()
            self.title_text, self.text = title, text

        def compose(self) -> ComposeResult:
            with Vertical(id="brief"):
                yield Static(self.title_text, id="brief-title")
                yield Static(self.text or "(nothing to read for this session)",
                             id="brief-text")
                yield Static("Press Enter to begin.", id="brief-go")

        def action_start(self) -> None:
            self.dismiss(None)

    class StudySessionApp(base):  # type: ignore[misc, valid-type]
        def __init__(self, session: Any, *, briefing: tuple[str, str], **kwargs: Any
                     ) -> None:
            super().__init__(session, **kwargs)
            self.briefing = briefing

        def on_mount(self) -> None:
            super().on_mount()
            self.session.paused = True

            def begin(_result: None) -> None:
                self.session.paused = False

            self.push_screen(Briefing(*self.briefing), begin)

    return StudySessionApp


def session_app(protocol: Protocol, session: Session) -> tuple[Any, Any]:
    """The app of ``session`` and its :class:`~opspec.tui.session.WalkSession` (recording to
    the session's place; a broken-off earlier attempt moved aside first)."""
    from opspec.request import RunRequest, prepare
    from opspec.tui.app import WalkthroughApp
    from opspec.tui.session import WalkSession

    _move_partial(session)
    # the front hall decides the session as every door does: the spec through validate's
    # gate, and the model a hand-over goes to (the companion SPEC.users.toml, if any)
    prepared = prepare(RunRequest(session.variant.spec, seed=protocol.seed, days=protocol.days))
    package, compiled = prepared.package, prepared.compiled
    model = prepared.user.source if prepared.user.kind == "model" else None
    factory = None
    if model is not None:
        factory = lambda: model.performer_for(protocol.seed, 0)  # noqa: E731
    walk = WalkSession(compiled, seed=protocol.seed, days=protocol.days,
                       record=session.recording, model_factory=factory,
                       spec_path=str(session.variant.spec), person=session.participant)
    walk.speed = protocol.speed
    total = len(protocol.variants)
    title = (f"{protocol.name}: session {session.position} of {total} "
             f"(participant {session.participant})")
    app = _briefing_app(WalkthroughApp)(walk, title=package.name or package.id,
                                        briefing=(title, session.variant.told))
    return app, walk


def _move_partial(session: Session) -> None:
    keep_partial(session)


def keep_partial(session: Session) -> Path | None:
    """A broken-off attempt's recording and trace, kept as ``VARIANT.partial-N.*`` (the
    recording's new path; None when the session is done or recorded nothing). Done as soon
    as the session breaks off, so that what is under ``VARIANT.json`` is a whole session,
    and again before the session is started anew (a terminal closed gives no chance)."""
    if session.done or not (session.recording.exists() or session.trace.exists()):
        return None
    n = 1
    while session.recording.with_name(f"{session.variant.id}.partial-{n}.json").exists() or \
            session.recording.with_name(f"{session.variant.id}.partial-{n}.trace.jsonl"
                                        ).exists():
        n += 1
    for old, suffix in ((session.recording, ".json"), (session.trace, ".trace.jsonl")):
        if old.exists():
            old.replace(old.with_name(f"{session.variant.id}.partial-{n}{suffix}"))
    return session.recording.with_name(f"{session.variant.id}.partial-{n}.json")


def finish_session(session: Session, walk: Any) -> bool:
    """After the app closed: mark the session done when its run reached the end."""
    if not walk.ended or walk.failure is not None:
        return False
    session.done_marker.write_text(json.dumps({
        "participant": session.participant, "variant": session.variant.id,
        "position": session.position, "spec": str(session.variant.spec),
        "recording": session.recording.name, "trace": session.trace.name}, indent=1) + "\n",
        encoding="utf-8")
    return True

