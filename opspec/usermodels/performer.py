"""``StochasticUser``: a :class:`~opspec.engine.performers.Performer` driven by a user model.

Every random number comes from the one numpy ``Generator`` given to the constructor (the
evaluation derives it per user from the run seed:
``numpy.random.default_rng(numpy.random.SeedSequence(seed, spawn_key=(user_index,)))``), in
this fixed order for each offered work item:

0. routine: when the offer falls on a day not drawn yet, one uniform per *probabilistic*
   routine window per day (windows in file order);
1. busy: no draw - an offer from another instance while an instance is engaged is omitted;
2. omission: one uniform, if the activity has an ``omission`` or is a ``prompt``
   (noticed iff ``u < (1 - p_omission) * routine notice factor``); stops here if omitted;
3. choice (work items with ``choices``): with ``probabilities``, one uniform; with
   ``intended`` + ``commission`` under its cap, one uniform, and when wrong, one integer if
   there are several wrong alternatives, then one ``recovery`` sample; with neither, one
   integer (a uniform pick); then, when the model describes the chosen alternative (e.g.
   ``press_wrong_button``), one sample of its duration: the time to carry out the pick;
4. extra delay: one uniform if configured, plus one ``delay.duration`` sample when it occurs;
5. duration: one sample of the activity's distribution (its own documented draws);
6. repetition: one uniform if configured, plus one more duration sample when it occurs;
7. commission on a plain activity: one uniform if configured, plus one ``recovery`` sample
   when it occurs.

The same model, seed and sequence of offers therefore give the same decisions. Decisions are
recorded through ``session.trace`` with kinds ``user.omitted`` (``reason``: ``busy``, the
omission's reason, a routine window's name, or ``adherence``), ``user.wrong_choice``,
``user.slip``, ``user.repeated``, ``user.delayed`` and ``user.deferred``.
"""

from __future__ import annotations

import math
import types
from collections.abc import Callable, Mapping
from functools import partial
from typing import Any, Final

import numpy as np

from opspec.engine.metrics import MetricsListener
from opspec.engine.performers import PerformerSession, WorkItem
from opspec.errors import UserModelError
from opspec.usermodels.errors import Busy
from opspec.usermodels.model import ActivityModel, UserModel
from opspec.usermodels.parametric import Constant, LogNormal
from opspec.usermodels.routine import RoutineTracker

__all__ = ["ActivityTally", "StochasticUser"]

#: 2**-53: numpy's PCG64 ``next_double`` is ``(next64 >> 11) * (1.0 / 9007199254740992.0)``
#: (numpy/random/src/pcg64/pcg64.h), the float ``Generator.random()`` returns
_TWO_TO_MINUS_53: Final = 1.0 / 9007199254740992.0  # (Final: a constant compiled)


class StochasticUser:
    """Performs the work items of a user lane according to a :class:`UserModel`.

    Implements the Performer protocol (``attach``, ``offer``, ``withdraw``). One instance
    per simulated user; not thread-safe (the engine calls it from its one thread).
    """

    def __init__(self, model: UserModel, rng: np.random.Generator, *,
                 trace_decisions: bool = True) -> None:
        self.model = model
        self.rng = rng
        self.trace_decisions = trace_decisions
        self._session: PerformerSession | None = None
        self._routine = RoutineTracker(model.routine, rng)
        self._routine_is_trivial = model.routine.is_trivial
        self._random = rng.random     # bound once: offer draws from it several times a cycle
        # (found at the first lognormal draw: _standard_normal; most users draw one)
        self._normal: Callable[[], float] | None = None
        # With numpy's default bit generator, PCG64, a uniform is taken from the raw 64-bit
        # draw as numpy itself does (see _TWO_TO_MINUS_53): the same float from the same
        # stream position, without Generator.random's dtype and size handling (~1k
        # instructions a draw, two or more draws a dose cycle); other bit generators define
        # their doubles otherwise, and go through Generator.random
        bit_generator = rng.bit_generator
        self._raw: Callable[[], int] | None = (
            bit_generator.random_raw if type(bit_generator) is np.random.PCG64 else None)
        self._pending: dict[int, WorkItem] = {}
        self._engaged: set[int] = set()          # lane instances the person is engaged in
        self._wrong: dict[tuple[int, str], int] = {}
        self._recovery: dict[tuple[int, str], float] = {}
        self._plans: dict[str, _Plan] = {}
        self._alternatives: dict[str, ActivityModel | None] = {}
        self._handover: dict[int, int] = {}      # lane -> key of its last completed item
        self._call_with: Callable[..., None] | None = None     # (see attach)
        # (with _call_with: _finish and _end_handover bound once, not a method object made
        # and freed per work item)
        self._finishing: Callable[[WorkItem, int, str | None], None] | None = None
        self._ending: Callable[[int, int, Any], None] | None = None
        #: per activity of the lane, ``[offered, completed, omitted, wrong]`` (``opspec
        #: evaluate``'s activity rows): when set, this user adds its omissions (column 2)
        #: and wrong actions (column 3: wrong choices and slips) to it as it decides them, so
        #: that no listener has to select its ``user.*`` events for them
        #: (:mod:`opspec.evaluation.replication`); None: not counted
        self.tally: dict[str, list[int]] | None = None
        #: per activity whose offers this user counts (column 0 of the same rows), the row:
        #: set by :mod:`opspec.evaluation.replication` for the activities the engine offers
        #: to this user alone, so that no listener has to select their ``activity.offered``
        #: events (each offer of one of them is this ``offer`` call, right after the engine
        #: would have traced it); None: not counted here
        self.offers: dict[str, list[int]] | None = None
        # the busy model's sets, read once (the model's frozen dataclasses are slow to read
        # from compiled code, and _finish reads them for every work item)
        busy = model.busy
        self._busy = busy is not None
        self._release_after: frozenset[str] = busy.release_after if busy else frozenset()
        self._engaging: frozenset[str] = busy.engaged if busy else frozenset()

    # ------------------------------------------------------------------ Performer protocol

    def attach(self, session: PerformerSession) -> None:
        self._session = session
        # From source, a session that has it (the engine's) takes the callback's arguments
        # beside it: ``call_later_with(delay, fn, a, b, c)``, no partial made and called
        # per work item, and an answer at once is queued as the call itself
        self._call_with = (getattr(session, "call_later_with", None) if _FROM_SOURCE
                           else None)
        if self._call_with is not None:
            self._finishing = self._finish
            self._ending = self._end_handover

    def offer(self, item: WorkItem) -> None:
        session = self._session
        if session is None:
            session = self._require_session()
        activity = item.activity
        offers = self.offers
        if offers is not None and activity in offers:
            offers[activity][0] += 1
        plan = self._plans.get(activity)
        if plan is None:
            plan = self._plans[activity] = _Plan(activity, self.model.activity(activity),
                                                 self.model.busy)
        root = item.root_instance
        lane = root if root is not None else item.instance
        if self._routine_is_trivial:    # RoutineTracker.state's own answer, without the call
            notice, factor, window, start_at = 1.0, 1.0, None, None
            # the clock is read only for a deferred start (start_at - now); the engine reads
            # it itself when it schedules the completion (``session.now`` is a property: a
            # Python frame per offer from source)
            now = 0.0
        else:
            now = session.now
            state = self._routine.state(now)
            notice, factor = state.notice_factor, state.duration_factor
            window, start_at = state.window, state.start_at
        handover = self._handover
        if lane in handover:    # (``in``, ``del``: primitives compiled, where pop is a call)
            del handover[lane]

        if plan.ignored_when_busy and (
                len(self._engaged) > 1 or (self._engaged and lane not in self._engaged)):
            self._omit(item, lane, "busy")
            return

        if plan.noticed_or_not:
            p_miss = plan.p_miss
            raw = self._raw
            u = (raw() >> 11) * _TWO_TO_MINUS_53 if raw is not None else float(self._random())
            if u >= (1.0 - p_miss) * notice:
                if u >= 1.0 - p_miss:
                    reason = plan.miss_reason
                elif window is not None:
                    reason = window
                else:
                    reason = "adherence"
                self._omit(item, lane, reason)
                return

        delay = 0.0
        choice: str | None = None
        if item.choices:
            choice, delay = self._choose(item, plan, lane)
            alternatives = self._alternatives
            picked = (alternatives[choice] if choice in alternatives
                      else self._alternative(choice))
            if picked is not None:
                carry_out = picked.duration
                # (Constant.sample draws nothing: its value, without the call)
                delay += (carry_out.value if type(carry_out) is Constant
                          else carry_out.sample(self.rng)) * factor

        extra_delay = plan.delay
        if extra_delay is not None and self._uniform() < extra_delay.probability:
            extra = extra_delay.duration.sample(self.rng)
            delay += extra
            self._trace("user.delayed", item, seconds=extra)

        constant = plan.constant_duration
        if constant is not None:
            duration = constant * factor
        elif plan.lognormal:
            # LogNormal.sample's own expression, without its call (a Python frame in both
            # builds: the distributions are not compiled); the same one standard normal
            normal = self._normal
            if normal is None:
                normal = self._normal = _standard_normal(self.rng)
            duration = math.exp(plan.mu + plan.sigma * float(normal())) * factor
        else:
            duration = plan.duration.sample(self.rng) * factor
        repetition = plan.repetition
        if repetition is not None and self._uniform() < repetition.probability:
            duration += plan.duration.sample(self.rng) * factor
            self._trace("user.repeated", item)
        slip = plan.commission
        if (slip is not None and not item.choices
                and self._uniform() < slip.probability):
            recovery = slip.recovery.sample(self.rng)
            duration += recovery
            self._count(item, 3)
            self._trace("user.slip", item, recovery=recovery)

        lead = 0.0      # (start - now, and start is now unless the routine defers it)
        if start_at is not None:
            lead = start_at - now
            self._trace("user.deferred", item, until=start_at)

        if plan.engages is not None:
            if plan.engages:
                self._engaged.add(lane)
            else:
                self._engaged.discard(lane)

        self._pending[item.key] = item
        # (comparisons, not max(0.0, x): the same value, without a builtin call each)
        total = (lead + (delay if delay > 0.0 else 0.0)  # noqa: FURB136
                 + (duration if duration > 0.0 else 0.0))  # noqa: FURB136
        if not total > 0.0:
            total = 0.0
        call_with = self._call_with
        if call_with is not None:
            call_with(total, self._finishing, item, lane, choice)
        elif _FROM_SOURCE:
            session.call_later(total, partial(self._finish, item, lane, choice))
        else:
            session.call_later(total, _Finish(self, item, lane, choice))

    def withdraw(self, item: WorkItem, reason: str) -> None:
        pending = self._pending
        if item.key in pending:
            del pending[item.key]
            self._release(self._lane_of(item))

    # ------------------------------------------------------------------ internals

    def _uniform(self) -> float:
        """One uniform in [0, 1): ``Generator.random()``'s float and stream position (offer
        and _choose write this inline where it is drawn every dose cycle)."""
        raw = self._raw
        return (raw() >> 11) * _TWO_TO_MINUS_53 if raw is not None else float(self._random())

    def _require_session(self) -> PerformerSession:
        if self._session is None:
            raise UserModelError("StochasticUser.offer() called before attach(session)")
        return self._session

    def _alternative(self, activity: str) -> ActivityModel | None:
        """The model of a choice's alternative, if the user model describes it (cached)."""
        if activity in self._alternatives:
            return self._alternatives[activity]
        found = self.model.activity(activity) if self.model.covers(activity) else None
        self._alternatives[activity] = found
        return found

    def _choose(self, item: WorkItem, plan: _Plan, lane: int) -> tuple[str, float]:
        """Pick an alternative (draw order: see the module docstring); returns the choice and
        the recovery time owed from an earlier wrong pick of this choice."""
        choices = item.choices
        key = (lane, item.activity)
        recovery = self._recovery
        owed = 0.0
        if key in recovery:
            owed = recovery[key]
            del recovery[key]
        if plan.probabilities:
            return self._by_probability(choices, plan), owed
        intended = plan.intended
        if intended is None or intended not in choices:
            if intended is not None:
                raise UserModelError(
                    f"choice {item.activity!r}: intended alternative {intended!r} is not "
                    f"offered (offered: {', '.join(choices)})")
            return choices[int(self.rng.integers(len(choices)))], owed
        commission = plan.commission
        count = self._wrong.get(key, 0)
        slipped = False
        if commission is not None and count < commission.max_per_instance:
            raw = self._raw
            u = (raw() >> 11) * _TWO_TO_MINUS_53 if raw is not None else float(self._random())
            slipped = u < commission.probability
        if commission is not None and slipped:
            # (a loop: a comprehension would make intended and choices a closure's cells,
            # made at every call of _choose from source)
            wrong: list[str] = []
            for c in commission.alternatives or choices:
                if c != intended and c in choices:
                    wrong.append(c)
            if wrong:
                pick = wrong[0] if len(wrong) == 1 else wrong[int(self.rng.integers(len(wrong)))]
                self._wrong[key] = count + 1
                self._recovery[key] = commission.recovery.sample(self.rng)
                self._count(item, 3)
                self._trace("user.wrong_choice", item, choice=pick, intended=intended)
                return pick, owed
        if key in self._wrong:
            del self._wrong[key]
        return intended, owed

    def _by_probability(self, choices: tuple[str, ...], plan: _Plan) -> str:
        """The alternative drawn by the plan's probabilities (one uniform)."""
        weights = dict(plan.probabilities)
        offered = [(c, weights.get(c, 0.0)) for c in choices]
        total = sum(w for _, w in offered)
        u = self._uniform() * total
        for choice, weight in offered:
            if u < weight:
                return choice
            u -= weight
        return offered[-1][0]

    def _finish(self, item: WorkItem, lane: int, choice: str | None) -> None:
        pending = self._pending
        if item.key not in pending:
            return  # withdrawn meanwhile
        del pending[item.key]
        session = self._session
        if session is None:
            session = self._require_session()
        handover = False
        if self._busy and lane in self._engaged:
            if item.activity in self._release_after or item.activity not in self._engaging:
                self._engaged.discard(lane)
            else:
                handover = True
                self._handover[lane] = item.key
        complete = session.complete     # (the session's field, as a rule: read, then
        complete(item, None, choice)    # called, its load specialised from source)
        if handover and self._handover.get(lane) == item.key:
            # Stay engaged if the instance offers its next activity at this same moment;
            # release if it ended (nothing offered when this zero-delay check runs). An
            # engine that routes in several zero-delay steps may release and re-engage at
            # the same instant, which no prompt can fall into except at that exact time.
            call_with = self._call_with
            if call_with is not None:
                call_with(0.0, self._ending, lane, item.key, None)
            elif _FROM_SOURCE:
                session.call_later(0.0, partial(self._end_handover, lane, item.key))
            else:
                session.call_later(0.0, _EndHandover(self, lane, item.key))

    def _end_handover(self, lane: int, key: int, _unused: Any = None) -> None:
        if self._handover.get(lane) == key:
            del self._handover[lane]
            # (a loop, not any() over a generator of _lane_of calls: from source each is a
            # Python frame, and this runs after every handover)
            for pending in self._pending.values():
                root = pending.root_instance
                if (root if root is not None else pending.instance) == lane:
                    return
            self._engaged.discard(lane)

    @staticmethod
    def _lane_of(item: WorkItem) -> int:
        return item.root_instance if item.root_instance is not None else item.instance

    def _omit(self, item: WorkItem, lane: int, reason: str) -> None:
        if reason != "busy":
            self._release(lane)
        self._count(item, 2)
        self._trace("user.omitted", item, reason=reason)
        self._require_session().omit(item, reason)

    def _release(self, lane: int) -> None:
        self._engaged.discard(lane)
        for key in [k for k in self._wrong if k[0] == lane]:
            del self._wrong[key]
        for key in [k for k in self._recovery if k[0] == lane]:
            del self._recovery[key]

    def _count(self, item: WorkItem, column: int) -> None:
        """Count a decision in :attr:`tally`, where its ``user.*`` event is traced (the
        same activity: the one the event names in its data)."""
        tally = self.tally
        if tally is not None and self.trace_decisions:
            row = tally.get(item.activity)
            if row is not None:
                row[column] += 1

    def _trace(self, kind: str, item: WorkItem, **data: Any) -> None:
        if self.trace_decisions and self._session is not None:
            payload: Mapping[str, Any] = {"instance": item.instance, "activity": item.activity,
                                          "process": item.process, **data}
            self._session.trace(kind, payload)


#: numpy's ``random_standard_normal`` through ctypes, looked up once (None: not found)
_C_NORMAL: Final[list[Any]] = []


def _standard_normal(rng: np.random.Generator) -> Callable[[], float]:
    """``rng.standard_normal()``'s draw without its method: numpy's own ziggurat,
    ``random_standard_normal``, the C function that method calls (numpy's C API for
    distributions), called through ctypes on ``rng``'s bit generator. The same function on
    the same state gives the same float and leaves the stream where the method would; what
    is saved is the method's argument and dtype handling and its lock (about 350 ns of 750
    a draw, two a dose cycle of the dispenser). The lock guards a generator shared between
    threads; a user's is its own, on the engine's one thread. The method itself where
    numpy's extension does not export the function."""
    if not _C_NORMAL:
        _C_NORMAL.append(_c_function())
    draw = _C_NORMAL[0]
    if draw is None:
        method: Callable[[], float] = rng.standard_normal
        return method
    # (a partial: called in C, no Python frame; it keeps the pointer alive, ``rng`` keeps
    # the bit generator it points into)
    normal: Callable[[], float] = partial(draw, rng.bit_generator.ctypes.bit_generator)
    return normal


def _c_function() -> Any:
    """numpy's ``random_standard_normal(bitgen_t *)`` as a ctypes function, or None."""
    try:
        import ctypes

        from numpy.random import _generator
        draw = ctypes.CDLL(_generator.__file__).random_standard_normal
    except (ImportError, OSError, AttributeError):
        return None
    draw.restype = ctypes.c_double
    draw.argtypes = [ctypes.c_void_p]
    return draw


class _Finish:
    """The callback ending a work item (a small object, not a closure: compiled, a closure in
    ``offer`` would make every call build an environment of its variables). From source,
    ``offer`` schedules a :func:`functools.partial` of ``_finish`` instead (see
    ``_FROM_SOURCE``)."""

    __slots__ = ("choice", "item", "lane", "user")

    def __init__(self, user: StochasticUser, item: WorkItem, lane: int,
                 choice: str | None) -> None:
        self.user = user
        self.item = item
        self.lane = lane
        self.choice = choice

    def __call__(self) -> None:
        self.user._finish(self.item, self.lane, self.choice)


class _EndHandover:
    """The zero-delay check after a handover (see ``StochasticUser._finish``)."""

    __slots__ = ("key", "lane", "user")

    def __init__(self, user: StochasticUser, lane: int, key: int) -> None:
        self.user = user
        self.lane = lane
        self.key = key

    def __call__(self) -> None:
        self.user._end_handover(self.lane, self.key)


#: Whether this module runs from source (not compiled by mypyc). From source, the callbacks
#: ``offer`` and ``_finish`` schedule are partials of the bound methods: made and called in C,
#: they cost no Python frame for an ``__init__`` and a ``__call__`` (about 0.7k of 3.3k
#: instructions per work item, counted with callgrind). Compiled, the small classes are
#: native, made and called without a Python frame already, and are kept (a partial would
#: add a bound method object each).
_FROM_SOURCE: Final = isinstance(_Finish.__call__, types.FunctionType)


class _Plan:
    """What ``offer`` reads of an activity's model, read once per user and activity: the
    model's frozen dataclasses are slow to read from compiled code, and ``offer`` runs for
    every work item. Nothing here draws a random number (the draw order is unchanged)."""

    def __init__(self, activity: str, model: ActivityModel, busy: Busy | None) -> None:
        self.model = model
        omission = model.omission
        self.noticed_or_not = omission is not None or model.prompt
        self.p_miss = omission.probability if omission is not None else 0.0
        self.miss_reason = omission.reason if omission is not None else "not noticed"
        # Constant.sample draws nothing, so skipping the call leaves the stream as it was.
        # A lognormal's draw is written out in offer (LogNormal.sample's expression).
        duration = model.duration
        self.lognormal = type(duration) is LogNormal
        self.mu = duration.mu if isinstance(duration, LogNormal) else 0.0
        self.sigma = duration.sigma if isinstance(duration, LogNormal) else 0.0
        self.constant_duration = (model.duration.value if type(model.duration) is Constant
                                  else None)
        self.ignored_when_busy = busy is not None and busy.ignores(activity)
        # None: no busy model; else whether offering this activity engages the person
        self.engages = None if busy is None else activity in busy.engaged
        self.delay = model.delay
        self.repetition = model.repetition
        self.commission = model.commission
        self.duration = model.duration
        self.probabilities = model.probabilities
        self.intended = model.intended


class ActivityTally(MetricsListener):
    """Counts, per activity of the user lane, the offers and completions the engine traces
    (``activity.offered`` / ``activity.completed`` of that activity, in any process) into
    :attr:`rows` (``[offered, completed, omitted, wrong]``; a :class:`StochasticUser` given
    the same rows as its ``tally`` fills the last two as it decides).

    ``opspec evaluate``'s activity table (:mod:`opspec.evaluation.replication`). A metrics
    listener, so that the compiled engine calls it as a native method, as it calls a run's
    own metrics, where a listener in Python made it call every selected event's listeners
    through Python's protocol; and one dictionary look-up per event where a count metric per
    activity and kind compared the event with each of them."""

    def __init__(self, activities: tuple[str, ...],
                 offered_elsewhere: frozenset[str] | None = None) -> None:
        super().__init__(())
        self.rows: dict[str, list[int]] = {a: [0, 0, 0, 0] for a in activities}
        # the rows whose offers this listener counts: all, or (``offered_elsewhere``) only
        # those the stochastic user does not count itself (StochasticUser.offers)
        self._offered: dict[str, list[int]] = (
            self.rows if offered_elsewhere is None
            else {a: row for a, row in self.rows.items() if a in offered_elsewhere})
        self.selects = frozenset(
            [("activity.completed", None, a) for a in activities]
            + [("activity.offered", None, a) for a in self._offered])

    def raw(self, time: float, kind: str, process: str | None, instance: int | None,
            activity: str | None, data: Mapping[str, Any] | None = None) -> None:
        # (the engine sends every event some listener selects: the kind is checked here)
        # (an offer of an activity the user counts may still come: another listener, a
        # monitor or a kept trace, selects it)
        if kind == "activity.offered":
            if activity is not None:
                row = self._offered.get(activity)
                if row is not None:
                    row[0] += 1
        elif kind == "activity.completed":
            if activity is not None:
                row = self.rows.get(activity)
                if row is not None:
                    row[1] += 1
