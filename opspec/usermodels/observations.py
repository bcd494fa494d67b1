"""What recorded traces say about one lane: offers paired with their answers, per activity,
per session and per person (what ``opspec fit`` estimates from and ``opspec model-check``
checks against).

For the lane being fitted (``lane`` or ``participant`` equal to ``lane``, default ``user``)
the events ``activity.offered`` and ``activity.completed`` / ``activity.omitted`` /
``activity.withdrawn`` are paired per (run, instance, activity), first offered first answered.
A ``run.started`` event starts a new run, so one file may hold many replications. A choice
is the ``data.choice`` of the completion, or the next activity offered in the instance when
the offer listed ``data.choices``; an omission with reason ``busy`` records the activities in
progress in another instance. Whose each session is comes from
:mod:`opspec.usermodels.persons`.
"""

from __future__ import annotations

from collections import Counter, defaultdict, deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from opspec.engine.trace import EventKind
from opspec.errors import SourceLocation, UserModelError
from opspec.usermodels.persons import PersonRule
from opspec.usermodels.trace_reader import read_trace

__all__ = ["Observations", "collect", "without_lane_text"]

_ANSWERS = (EventKind.ACTIVITY_COMPLETED, EventKind.ACTIVITY_OMITTED,
            EventKind.ACTIVITY_WITHDRAWN)


@dataclass
class Observations:
    """What the traces say about one lane, per activity."""

    durations: dict[str, list[float]] = field(default_factory=lambda: defaultdict(list))
    omitted: Counter[str] = field(default_factory=Counter)
    busy_omitted: Counter[str] = field(default_factory=Counter)
    picks: dict[str, list[list[str]]] = field(default_factory=lambda: defaultdict(list))
    engaged: set[str] = field(default_factory=set)
    #: answers a walkthrough marked as not timed in real time (their durations are left out)
    unusable: Counter[str] = field(default_factory=Counter)
    #: per activity, per user (file index, run index): durations and (omitted, answered)
    user_durations: dict[str, dict[tuple[int, int], list[float]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(list)))
    user_omissions: dict[str, dict[tuple[int, int], list[int]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(lambda: [0, 0])))
    #: per choice activity, per picked alternative: the durations of that pick
    pick_durations: dict[str, dict[str, list[float]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(list)))
    #: the same per session (file index, run index): the picks of each instance, and per
    #: picked alternative its durations (what a person-level bootstrap resamples)
    user_picks: dict[str, dict[tuple[int, int], list[list[str]]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(list)))
    user_pick_durations: dict[str, dict[str, dict[tuple[int, int], list[float]]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(lambda: defaultdict(list))))
    #: who each session (file index, run index) is (opspec.usermodels.persons)
    person_of: dict[tuple[int, int], str] = field(default_factory=dict)
    events: int = 0
    runs: int = 0
    files: int = 0
    lanes_seen: set[str] = field(default_factory=set)
    #: files with no event of the lane (a trace of another spec, a run nobody performed the
    #: lane in) and the lanes each did show: read, but no session of them is a person
    without_lane: list[tuple[str, list[str]]] = field(default_factory=list)

    @property
    def activities(self) -> list[str]:
        names = set(self.durations) | set(self.omitted) | set(self.busy_omitted)
        return sorted(names)

    @property
    def persons(self) -> list[str]:
        """The persons the sessions belong to, in order of appearance."""
        return list(dict.fromkeys(self.person_of.values()))

    @property
    def sessions(self) -> int:
        return len(self.person_of)

    def person(self, session: tuple[int, int]) -> str:
        return self.person_of.get(session, f"{session[0]}#{session[1]}")

    def lists_by_person(self, per_session: Mapping[tuple[int, int], Sequence[Any]]
                        ) -> dict[str, list[Any]]:
        """Per-session lists (durations, pick sequences) concatenated per person."""
        out: dict[str, list[Any]] = {}
        for session, values in per_session.items():
            out.setdefault(self.person(session), []).extend(values)
        return out

    def counts_by_person(self, per_session: Mapping[tuple[int, int], Sequence[int]]
                         ) -> dict[str, tuple[int, int]]:
        """Per-session ``[omitted, answered]`` added up per person."""
        out: dict[str, tuple[int, int]] = {}
        for session, (k, n) in per_session.items():
            k0, n0 = out.get(self.person(session), (0, 0))
            out[self.person(session)] = (k0 + k, n0 + n)
        return out


def collect(paths: Sequence[str | Path], lane: str = "user",
            persons: PersonRule | None = None) -> Observations:
    """Pair offers with answers in ``paths`` for ``lane`` (see the module docstring);
    ``persons`` says whose each session is (default: the header's ``person``, else each run
    a person of its own)."""
    obs = Observations()
    rule = persons or PersonRule()
    for file_index, path in enumerate(paths):
        obs.files += 1
        whose = rule.of_file(Path(path))
        run = 0
        outstanding: dict[tuple[int, Any, str], deque[tuple[float, str]]] = {}
        in_progress: dict[tuple[int, Any, str], int] = Counter()
        pending_choice: dict[tuple[int, Any], tuple[str, tuple[str, ...]]] = {}
        unreal: set[tuple[int, Any, str]] = set()     # (run, instance, activity)
        picks_of: dict[tuple[int, Any], dict[str, list[str]]] = {}
        of_lane = 0
        file_lanes: set[str] = set()
        for event in read_trace(path):
            obs.events += 1
            if event.kind == EventKind.RUN_STARTED:
                run += 1
                obs.runs += 1
                obs.person_of[(file_index, run)] = (
                    whose if whose is not None else f"{Path(path).name}#{run}")
                continue
            if event.lane:
                obs.lanes_seen.add(event.lane)
                file_lanes.add(event.lane)
            if event.kind == "walkthrough.action" and event.data.get("usable") is False:
                # a walkthrough's answer whose simulated duration is not the person's
                # (docs/walkthrough.md): its duration is not fitted
                unreal.add((run, event.data.get("instance"), str(event.data.get("activity"))))
                continue
            if event.activity is None or (event.lane != lane and event.participant != lane):
                continue
            of_lane += 1
            inst = (run, event.instance)
            key = (run, event.instance, event.activity)
            if event.kind == EventKind.ACTIVITY_OFFERED:
                waiting = pending_choice.pop(inst, None)
                if waiting is not None and event.activity in waiting[1]:
                    picks_of.setdefault(inst, {}).setdefault(waiting[0], []).append(
                        event.activity)
                outstanding.setdefault(key, deque()).append((event.time, event.activity))
                in_progress[key] += 1
                choices = event.data.get("choices")
                if isinstance(choices, (list, tuple)) and choices:
                    pending_choice[inst] = (event.activity, tuple(map(str, choices)))
                continue
            if event.kind not in _ANSWERS:
                continue
            queue = outstanding.get(key)
            if not queue:
                continue  # an answer without its offer (trace cut at the start)
            offered_at, _ = queue.popleft()
            in_progress[key] -= 1
            reason = str(event.data.get("reason", ""))
            user = (file_index, run)
            if event.kind == EventKind.ACTIVITY_COMPLETED:
                took = max(0.0, event.time - offered_at)
                real = _real_duration(unreal, key, obs)
                if real:
                    obs.durations[event.activity].append(took)
                    obs.user_durations[event.activity][user].append(took)
                obs.user_omissions[event.activity][user][1] += 1
                choice = event.data.get("choice")
                if isinstance(choice, str):
                    if real:
                        obs.pick_durations[event.activity][choice].append(took)
                        obs.user_pick_durations[event.activity][choice][user].append(took)
                    pending_choice.pop(inst, None)
                    picks_of.setdefault(inst, {}).setdefault(event.activity, []).append(choice)
            elif event.kind == EventKind.ACTIVITY_OMITTED:
                if reason == "busy":
                    obs.busy_omitted[event.activity] += 1
                    obs.engaged.update(a for (r, i, a), n in in_progress.items()
                                       if n > 0 and r == run and i != event.instance)
                else:
                    obs.omitted[event.activity] += 1
                    counts = obs.user_omissions[event.activity][user]
                    counts[0] += 1
                    counts[1] += 1
        for (picked_in, _), per_instance in picks_of.items():
            for activity, sequence in per_instance.items():
                obs.picks[activity].append(sequence)
                obs.user_picks[activity][(file_index, picked_in)].append(sequence)
        if run == 0:                    # a trace without run.started: one session
            obs.person_of[(file_index, 0)] = (whose if whose is not None
                                              else f"{Path(path).name}#0")
        if not of_lane:
            # counted as a person it would add one with nothing observed: to the persons a
            # fit names and resamples, to a check's group size
            for session in [s for s in obs.person_of if s[0] == file_index]:
                del obs.person_of[session]
            obs.without_lane.append((str(path), sorted(file_lanes)))
    if not obs.durations and not obs.omitted and not obs.busy_omitted:
        seen = ", ".join(sorted(obs.lanes_seen)) or "none"
        unusable = sum(obs.unusable.values())
        raise UserModelError(
            f"no activity of lane {lane!r} in {len(paths)} trace file(s) "
            f"({obs.events} events; lanes seen: {seen})" + (
                f"; {unusable} walkthrough answer(s) left out: not timed in real time"
                if unusable else ""),
            location=SourceLocation(str(paths[0])) if paths else None,
            hint="record traces of the user lane (for instance a TUI walkthrough), or pick "
            "the lane with --lane")
    return obs


def without_lane_text(obs: Observations, lane: str) -> str | None:
    """What ``opspec fit`` and ``opspec model-check`` say of the files with no event of
    ``lane`` (None when there are none): read, and left out of the persons."""
    if not obs.without_lane:
        return None
    shown = "; ".join(f"{path}: lanes seen {', '.join(lanes) or 'none'}"
                      for path, lanes in obs.without_lane[:3])
    more = f"; ... {len(obs.without_lane) - 3} more" if len(obs.without_lane) > 3 else ""
    return (f"left out {len(obs.without_lane)} trace file(s) with no activity of lane "
            f"{lane!r} ({shown}{more}), not counted as persons: a trace of another spec, or "
            "a session nobody performed the lane in (pick the lane with --lane)")


def _real_duration(unreal: set[tuple[int, Any, str]], key: tuple[int, Any, str],
                   obs: Observations) -> bool:
    """Whether the answer ``key`` has a real duration. A walkthrough marks those it has not
    (``walkthrough.action`` with ``usable: false``: the clock was paused, ran faster than real
    time or jumped, or the user model answered); they are counted in ``obs.unusable``."""
    if key in unreal:
        unreal.discard(key)
        obs.unusable[key[2]] += 1
        return False
    return True
