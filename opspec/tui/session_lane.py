"""The person's lane in a walkthrough session: what waits for the person (the offers, an
older offer of the same activity lapsing), what the person does with it (act, omit), and the
lane handed over to a user model and taken back."""

from __future__ import annotations

from opspec.engine.performers import PerformerSession, WorkItem
from opspec.tui.lane import Offer
from opspec.tui.replay import tagged_action
from opspec.tui.session_state import SessionState, guarded

__all__ = ["PersonLane"]


class PersonLane(SessionState):
    """The person's offers and actions in a :class:`~opspec.tui.session.WalkSession`."""

    # ------------------------------------------------------------------ the offers
    def has_new_offers(self, since: int) -> bool:
        """Whether an offer made after the ``since``-th one is waiting for the person."""
        return any(self._seq_of.get(o.item.key, 0) > since for o in self.offers)

    # ------------------------------------------------------------------ the person
    @guarded()
    def act(self, offer: Offer) -> None:
        """The person does ``offer`` now."""
        engine = self._take(offer, offer.action, offer.label)
        if engine is not None:
            engine.complete(offer.item, None, offer.choice)
            self._follow_call()

    @guarded()
    def ignore(self, offer: Offer) -> None:
        """The person explicitly does not do ``offer`` (omission). Of a deferred choice the
        whole choice is omitted, none of its alternatives done: it is named, not the first."""
        item = offer.item
        what = offer.label if offer.choice is None else self._label_of(item.process,
                                                                       item.activity)
        engine = self._take(offer, tagged_action("omit", item.activity, item.instance),
                            f"not: {what}")
        if engine is not None:
            engine.omit(offer.item, "the person chose not to")
            self._follow_call()

    def _take(self, offer: Offer, action: str, label: str) -> PerformerSession | None:
        """The person answers ``offer`` with ``action``: recorded and the offer withdrawn;
        the lane's engine to tell, or None when the offer no longer stands (the run ended,
        the lane was handed over, or it was answered already)."""
        engine = self.lane_user.engine
        if engine is None or self.ended or self.handed_over or (
                offer.item.key not in self.lane_user.items):
            return None
        self.lane_user.items.pop(offer.item.key, None)
        self._record(action, by="person", item=offer.item, label=label)
        self._drop_offers(offer.item.key)
        return engine

    @guarded(False)
    def hand_over(self) -> bool:
        """Let the user model perform the lane from now on, starting with what the person
        is offered now (``False``: no model, or a replay performs the lane)."""
        if self.model_factory is None or self.replaying or self.handed_over:
            return False
        current = list({o.item.key: o.item for o in self.offers}.values())
        self.offers.clear()
        self.lane_user.hand_over(self.model_factory(), current)
        self._follow_call()        # a call to the person is over: the model is not slowed
        return True

    @guarded()
    def take_back(self) -> None:
        """The person performs the lane again: the model's pending work is withdrawn from
        it (a delayed action of the model does nothing) and offered to the person."""
        if not self.handed_over:
            return
        for item in self.lane_user.take_back():
            self._offered(item)
            # offered to the engine long ago: its duration is not the person's
            self.times.spoil("taken back from the user model", keys=(item.key,))
        self._follow_call()        # the device still calls: now it calls the person

    @property
    def handed_over(self) -> bool:
        return self.lane_user.model is not None

    def _label_of(self, process: str, activity: str) -> str:
        return self._names.get((process, activity), activity)

    # ------------------------------------------------------------------ engine side
    def _offered(self, item: WorkItem) -> None:
        # the same activity offered in a newer instance supersedes the older offer (three
        # ignored alarms leave one "Hear the alarm", the newest); the older one is not
        # done, it lapses as an untaken action does
        stale = {o.item.key for o in self.offers
                 if o.item.process == item.process and o.item.activity == item.activity
                 and o.item.instance != item.instance}
        if stale:
            self.lapsed += len(stale)
            lapsed = {o.item.instance for o in self.offers if o.item.key in stale}
            for key in stale:
                self.lane_user.items.pop(key, None)
            self._drop_offers(*stale)
            # an instance with nothing left for the person has lapsed: it is not running
            # any more as far as the person can tell (it waits for an answer that will not
            # come), so it leaves the Running list
            for instance in lapsed - {i.instance for i in self.lane_user.items.values()}:
                self.current.pop(instance, None)
                self.deadlines = {k: v for k, v in self.deadlines.items() if k[0] != instance}
                self.lapsed_instances.add(instance)
        self._offer_seq += 1
        self._seq_of[item.key] = self._offer_seq
        self.times.shown(item.key, self.now, paused=self._paused)
        if item.choices:
            self.offers.extend(Offer(item, choice, self._names.get((item.process, choice)))
                               for choice in item.choices)
        else:
            self.offers.append(Offer(item, None))

    def _drop_offers(self, *keys: int) -> None:
        self.offers = [o for o in self.offers if o.item.key not in keys]
        for key in keys:
            self._seq_of.pop(key, None)
            self.times.forget(key)

    def _drop_instance(self, instance: int) -> None:
        """An instance ended: what it offered the person goes."""
        gone = [k for k, i in self.lane_user.items.items() if i.instance == instance]
        for key in gone:
            self.lane_user.items.pop(key, None)
        self._drop_offers(*gone, *(o.item.key for o in self.offers
                                   if o.item.instance == instance))
