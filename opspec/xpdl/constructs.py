"""The construct registry: for every element and attribute of BPMN 2.0 and XPDL 2.x that has
execution semantics, whether opspec RUNS it as its standard says, WARNS (it runs, but as
something else: the text says what opspec does instead) or REFUSES it.

This is the one place that says so. ``opspec validate`` (and so every front door) reports each
WARNS and REFUSES entry whose condition holds at the element's line (:mod:`opspec.xpdl.gate`),
docs/semantics.md's table is generated from it (``python -m opspec.xpdl.constructs``), and
tests/semantics_gate/ walks the bundled XSDs and fails on an element or attribute that is
neither here nor in :data:`INERT`.

To record that opspec now runs a construct as its standard says, change its entry's ``kind`` to
``Kind.RUNS`` and its ``text`` to what it does (one place), then regenerate the table.

An entry's ``when`` names a condition of :data:`opspec.xpdl.gate.CONDITIONS` (``None``: the
element or attribute is present); conditions take the value into account, so a value that
changes behaviour (a quantity other than 1, a completionCondition, a cycle) is never read as
its default in silence. ``reported_by`` lists the reader's own diagnostic codes that already
say the same thing at the same line (the gate then adds nothing there).
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

__all__ = [
    "BPMN",
    "BPMNDI_NAMESPACES",
    "CONSTRUCTS",
    "INERT",
    "NOT_RUN",
    "REPORTED",
    "RUNS_DIFFERENTLY",
    "XPDL",
    "Construct",
    "Inert",
    "Kind",
    "constructs_for",
    "is_inert",
    "markdown_table",
]

BPMN = "http://www.omg.org/spec/BPMN/20100524/MODEL"
#: Every XPDL namespace (1.0, 2.0, 2.1, 2.2, none): entries are keyed by the local name.
XPDL = "xpdl"
#: Diagram interchange: layout only.
BPMNDI_NAMESPACES = (
    "http://www.omg.org/spec/BPMN/20100524/DI",
    "http://www.omg.org/spec/DD/20100524/DC",
    "http://www.omg.org/spec/DD/20100524/DI",
)


#: The codes of the gate's diagnostics: a construct run differently (warning), refused (error).
RUNS_DIFFERENTLY = "runs-differently"
NOT_RUN = "not-run"


class Kind(enum.Enum):
    """What opspec does with a construct."""

    RUNS = "runs"          # as its standard says
    WARNS = "warns"        # it runs, differently: validate warns at its line
    REFUSES = "refuses"    # validate (and so every front door) refuses the file at its line


@dataclass(frozen=True, slots=True)
class Construct:
    """One row of the registry: ``elements`` (local names in ``namespace``) and, for an
    attribute, its name; ``text`` is what opspec does (for RUNS, the standard's behaviour it
    follows); ``section`` the part of the standard that defines it."""

    key: str
    namespace: str
    elements: tuple[str, ...]
    attribute: str | None
    kind: Kind
    text: str
    section: str
    when: str | None = None
    reported_by: tuple[str, ...] = ()
    hint: str = ""

    @property
    def code(self) -> str:
        """The diagnostic code validate reports it under."""
        return NOT_RUN if self.kind is Kind.REFUSES else RUNS_DIFFERENTLY


@dataclass(frozen=True, slots=True)
class Inert:
    """Elements and attributes judged to have no execution semantics, with the reason.
    ``elements`` ``("*",)`` means every element of the namespace; ``attributes`` lists the
    attributes covered (``"*"`` all), ``include_elements`` whether the elements themselves
    are covered too (not only their attributes)."""

    namespace: str
    elements: tuple[str, ...]
    attributes: tuple[str, ...]
    reason: str
    include_elements: bool = True


def _c(key: str, namespace: str, elements: str, attribute: str | None, kind: Kind, text: str,
       section: str, when: str | None = None, reported_by: tuple[str, ...] = (),
       hint: str = "") -> Construct:
    return Construct(key, namespace, tuple(elements.split()), attribute, kind, text, section,
                     when, reported_by, hint)


R, W, X = Kind.RUNS, Kind.WARNS, Kind.REFUSES

_TTL_HINT = ("to keep messages until caught, set message_ttl = inf in the engine settings "
             "(an evaluation plan's [engine] table, opspec.run(config=...))")

_ACTIVITIES = ("task userTask manualTask serviceTask sendTask receiveTask scriptTask "
               "businessRuleTask callActivity subProcess adHocSubProcess transaction")
_GATEWAYS = "exclusiveGateway parallelGateway inclusiveGateway complexGateway eventBasedGateway"
_EVENTS = "startEvent endEvent intermediateCatchEvent intermediateThrowEvent boundaryEvent"
_SUBS = "subProcess adHocSubProcess transaction"

# BPMN 2.0 (OMG formal/2011-01-03): chapter 10 (process elements) and chapter 13 (execution).
_BPMN: tuple[Construct, ...] = (
    # -- sequence flow ------------------------------------------------------------------------
    _c("bpmn-process", BPMN, "definitions process", None, R,
       "each process is a workflow; its instances run on the simulated clock", "§10.1, §13"),
    _c("bpmn-sequence-flow", BPMN, "sequenceFlow", None, R,
       "a token moves along it when its source completes", "§13.2"),
    _c("bpmn-flow-ends", BPMN, "sequenceFlow", "sourceRef", R,
       "the flow's source node", "§10.5"),
    _c("bpmn-flow-ends-target", BPMN, "sequenceFlow", "targetRef", R,
       "the flow's target node", "§10.5"),
    _c("bpmn-condition", BPMN, "conditionExpression", None, R,
       "the flow is taken when the condition holds (opspec's expression grammar; what it "
       "cannot read is a bad-condition error)", "§13.2.1"),
    _c("bpmn-default", BPMN, f"{_ACTIVITIES} exclusiveGateway inclusiveGateway complexGateway",
       "default", R, "the default flow is taken when no other condition holds", "§13.2.1"),
    _c("bpmn-outgoing-order", BPMN, "incoming outgoing", None, R,
       "outgoing gives the order an exclusive gateway tests its flows in; the flows' "
       "sourceRef and targetRef decide the graph", "§10.5"),
    # -- activities ---------------------------------------------------------------------------
    _c("bpmn-tasks", BPMN, "task userTask manualTask serviceTask scriptTask businessRuleTask",
       None, R, "an activity: user and manual tasks wait for their performer, the others run "
       "by themselves (or for their opspec:Duration, or are offered to a bound device)",
       "§10.2.3, §13.3.2"),
    _c("bpmn-task-implementation", BPMN,
       "userTask serviceTask sendTask receiveTask businessRuleTask", "implementation", R,
       "the service is simulated: the task completes when its bound device or performer does, "
       "else by itself", "§10.2.3"),
    _c("bpmn-operation", BPMN, "serviceTask sendTask receiveTask", "operationRef", R,
       "the operation is simulated as for implementation", "§10.2.3"),
    _c("bpmn-send-receive", BPMN, "sendTask receiveTask", None, R,
       "a send task raises its message when it completes; a receive task waits for its "
       "message", "§10.2.3, §13.3.2"),
    _c("bpmn-message-ref", BPMN, "sendTask receiveTask messageEventDefinition messageFlow",
       "messageRef", R, "the message thrown or awaited", "§10.4.5"),
    _c("bpmn-receive-instantiate", BPMN, "receiveTask", "instantiate", W,
       "ignored: the receive task waits for its message inside a running instance; the "
       "message does not start a new instance (BPMN §10.2.3: an instantiating receive task "
       "starts the process)", "§10.2.3", when="true",
       hint="start the process with a message start event"),
    _c("bpmn-script", BPMN, "script", None, R,
       "the script runs as assignments (opspec's subset; anything else is a bad-script error)",
       "§10.2.3"),
    _c("bpmn-languages", BPMN, "scriptTask", "scriptFormat", R,
       "opspec reads scripts in its own subset whatever language is named", "§10.2.3"),
    _c("bpmn-expression-language", BPMN,
       "condition formalExpression transformation messagePath dataPath", "language", R,
       "opspec reads expressions in its own grammar whatever language is named; one it "
       "cannot read is a bad-condition error", "§10.3.1"),
    _c("bpmn-expression-language-default", BPMN, "definitions", "expressionLanguage", R,
       "as language", "§10.3.1"),
    _c("bpmn-call-activity", BPMN, "callActivity", None, R,
       "a synchronous subflow of the called process", "§10.2.5, §13.3.4"),
    _c("bpmn-called-element", BPMN, "callActivity", "calledElement", R,
       "the process called", "§10.2.5"),
    _c("bpmn-sub-process", BPMN, "subProcess", None, R,
       "an embedded sub-process: its flow runs in the instance of its parent",
       "§10.2.5, §13.3.4"),
    _c("bpmn-event-sub-process-runs", BPMN, "subProcess", "triggeredByEvent", R,
       "an event sub-process with one timer or message start event starts each time its "
       "trigger occurs while its parent is active; an interrupting one cancels the parent's "
       "other work first, a non-interrupting one runs beside it (as a boundary event on the "
       "parent's contents)", "§10.2.5, §13.5.4", when="true"),
    _c("bpmn-event-sub-process", BPMN, _SUBS, "triggeredByEvent", X,
       "opspec runs only event sub-processes with one timer or message start event, in a "
       "level whose own start events are none start events; not this one (it would ignore it "
       "and everything in it while the rest runs)", "§10.2.5, §13.5.4",
       when="refused-event-sub-process", reported_by=("unsupported-element",),
       hint="give it one timer or message start event, or model it as a boundary event on a "
       "sub-process, or as a workflow with a message or signal start event"),
    _c("bpmn-event-sub-process-start", BPMN, "startEvent", "isInterrupting", X,
       "only the start event of an event sub-process has it, and opspec does not run this "
       "event sub-process", "§10.4.2, §13.5.4", when="in-refused-event-sub-process"),
    _c("bpmn-transaction", BPMN, "transaction", None, W,
       "runs as a plain sub-process: no compensation, no cancel", "§10.2.5, §13.3.4",
       reported_by=("transaction",)),
    _c("bpmn-transaction-method", BPMN, "transaction", "method", W,
       "ignored with the transaction's protocol", "§10.2.5"),
    _c("bpmn-ad-hoc", BPMN, "adHocSubProcess", None, R,
       "its activities run in any order until completionCondition holds", "§10.2.5, §13.3.5"),
    _c("bpmn-ad-hoc-ordering", BPMN, "adHocSubProcess", "ordering", R,
       "Parallel: all at once; Sequential: one at a time, in declared order", "§10.2.5"),
    _c("bpmn-ad-hoc-cancel", BPMN, "adHocSubProcess", "cancelRemainingInstances", W,
       "opspec cancels the running activities when the completion condition holds, also when "
       "cancelRemainingInstances is false (BPMN: they complete first)", "§10.2.5", when="false"),
    _c("bpmn-completion-condition", BPMN, "completionCondition", None, R,
       "ad-hoc sub-process: it completes when the condition holds", "§10.2.5, §13.3.5"),
    _c("bpmn-mi-completion-condition", BPMN, "completionCondition", None, R,
       "once the condition holds the token moves on and the remaining instances are cancelled",
       "§10.2.8, §13.3.7", when="in-multi-instance"),
    _c("bpmn-quantities", BPMN, _ACTIVITIES, "startQuantity", R,
       "the activity waits for startQuantity tokens (thread merge, WCP-41)", "§10.2.1, §13.3.2",
       when="not-one"),
    _c("bpmn-completion-quantity", BPMN, _ACTIVITIES, "completionQuantity", R,
       "completionQuantity tokens leave on each outgoing flow (thread split, WCP-42)",
       "§10.2.1, §13.3.2", when="not-one"),
    _c("bpmn-orphaned-node", BPMN, f"{_ACTIVITIES} {_GATEWAYS} intermediateCatchEvent "
       "intermediateThrowEvent endEvent", None, R,
       "a node whose every incoming flow comes from a boundary event that never fires "
       "(compensation, cancel) waits for a token, so never starts", "§13.2, §13.5.3",
       when="fed-only-by-ignored"),
    _c("bpmn-compensation-activity", BPMN, _ACTIVITIES, "isForCompensation", W,
       "opspec has no compensation: this is an ordinary activity (one no sequence flow leads "
       "to starts with the instance)", "§10.2.1, §13.5.5", when="true"),
    # -- loops --------------------------------------------------------------------------------
    _c("bpmn-standard-loop", BPMN, "standardLoopCharacteristics loopCondition", None, R,
       "repeats while loopCondition holds", "§10.2.8, §13.3.6"),
    _c("bpmn-loop-maximum", BPMN, "standardLoopCharacteristics", "loopMaximum", R,
       "at most loopMaximum iterations", "§10.2.8"),
    _c("bpmn-loop-test-before", BPMN, "standardLoopCharacteristics", "testBefore", R,
       "the condition is tested before (true) or after each iteration", "§10.2.8"),
    _c("bpmn-multi-instance", BPMN, "multiInstanceLoopCharacteristics loopCardinality", None, R,
       "loopCardinality instances", "§10.2.8, §13.3.7"),
    _c("bpmn-mi-sequential", BPMN, "multiInstanceLoopCharacteristics", "isSequential", R,
       "one instance after another (true), else all at once", "§10.2.8"),
    _c("bpmn-mi-collection", BPMN, "loopDataInputRef inputDataItem", None, W,
       "one instance per item of the collection, but no instance is handed its item",
       "§10.2.8, §13.3.7", reported_by=("multi-instance-collection",),
       hint="on a task, camunda:collection with camunda:elementVariable hands each instance "
            "its own item (docs/bpmn.md, Multi-instance over a collection)"),
    _c("bpmn-mi-output", BPMN, "loopDataOutputRef outputDataItem", None, W,
       "ignored: the instances' outputs are not collected", "§10.2.8"),
    _c("bpmn-mi-behavior", BPMN, "multiInstanceLoopCharacteristics", "behavior", W,
       "ignored: no event is thrown when instances complete (behavior All)", "§10.2.8",
       when="not-all"),
    _c("bpmn-mi-behavior-events", BPMN, "complexBehaviorDefinition", None, W,
       "ignored: no event is thrown when instances complete", "§10.2.8"),
    _c("bpmn-mi-behavior-refs", BPMN, "multiInstanceLoopCharacteristics", "noneBehaviorEventRef",
       W, "ignored: no event is thrown when instances complete", "§10.2.8"),
    _c("bpmn-mi-behavior-refs-one", BPMN, "multiInstanceLoopCharacteristics",
       "oneBehaviorEventRef", W, "ignored: no event is thrown when instances complete",
       "§10.2.8"),
    # -- gateways -----------------------------------------------------------------------------
    _c("bpmn-gateways", BPMN, "exclusiveGateway parallelGateway complexGateway "
       "eventBasedGateway inclusiveGateway", None, R,
       "exclusive: the first flow whose condition holds; parallel: all flows / waits for all; "
       "complex: activationCondition; event-based: the first event wins; inclusive split: "
       "every flow whose condition holds", "§10.5, §13.4"),
    _c("bpmn-or-join", BPMN, "inclusiveGateway", None, R,
       "the inclusive join fires per activation: one token from each incoming flow that has "
       "one (left-over tokens are the next activation), held back only by a token whose every "
       "path leads to an incoming flow without one", "§13.4.3, Table 13.3", when="join"),
    _c("bpmn-activation-condition", BPMN, "activationCondition", None, R,
       "the complex join fires when it holds", "§13.4.4"),
    _c("bpmn-event-gateway-instantiate", BPMN, "eventBasedGateway", "instantiate", W,
       "ignored: the gateway does not start new instances; it waits like a non-instantiating "
       "one", "§10.5.6, §13.4.5", when="true"),
    _c("bpmn-event-gateway-type", BPMN, "eventBasedGateway", "eventGatewayType", W,
       "run as Exclusive: the first event wins and the others are withdrawn", "§10.5.6",
       when="parallel"),
    # -- events -------------------------------------------------------------------------------
    _c("bpmn-events", BPMN, _EVENTS, None, R,
       "start, end, catching and throwing events with the trigger of their definition",
       "§10.4, §13.5"),
    _c("bpmn-several-starts", BPMN, "startEvent", None, R,
       "several start events are independent: each timer, message or signal start starts its "
       "own instance in which only its own path runs; an instance started without a trigger "
       "(auto-started like a process with only a none start event, from the API, or called) "
       "begins at the none start events only", "§10.4.2, §13.3.4", when="several-starts"),
    _c("bpmn-several-none-starts", BPMN, "startEvent", None, W,
       "the none start events of a process all start together, in one instance, whenever it "
       "is instantiated (BPMN 2.0 §10.4.2 instantiates \"all Flow Objects that do not have an "
       "incoming Sequence Flow\" but also says each start event is independent and that a "
       "called process triggers only one of several none start events; SpiffWorkflow runs "
       "the first only)", "§10.4.2, §13.3.4", when="several-none-starts",
       hint="draw one none start event and a parallel gateway after it, or one process per "
       "start event"),
    _c("bpmn-several-definitions", BPMN, "startEvent intermediateCatchEvent boundaryEvent",
       None, W, "only the first event definition counts (BPMN: any one of them triggers it)",
       "§10.4.5", when="several-definitions", reported_by=("multiple-event-definitions",)),
    _c("bpmn-parallel-multiple", BPMN, "startEvent intermediateCatchEvent boundaryEvent",
       "parallelMultiple", W,
       "only the first event definition counts (BPMN: all of them must occur)", "§10.4.5",
       when="true"),
    _c("bpmn-boundary", BPMN, "boundaryEvent", "attachedToRef", R,
       "the activity the boundary event waits on", "§10.4.5, §13.5.3"),
    _c("bpmn-cancel-activity", BPMN, "boundaryEvent", "cancelActivity", R,
       "true: the activity is interrupted; false: the boundary path starts beside it",
       "§10.4.5, §13.5.3"),
    _c("bpmn-mi-boundary-timer", BPMN, "boundaryEvent", None, R,
       "a boundary timer on a multi-instance activity fires once for the whole activity",
       "§13.3.7", when="timer-on-multi-instance"),
    _c("bpmn-message", BPMN, "messageEventDefinition message messageFlow", None, R,
       "a message goes to one receiver; a message flow's source raises it, its target waits "
       "for it", "§8.4.2, §10.4.5"),
    _c("bpmn-message-ttl", BPMN, "message", None, R,
       "a message nobody waits for yet is kept for its catcher (up to 100 per name, then a "
       "trigger.lost event; a time to live only from opspec:MessageTTL)", "§10.4.5"),
    _c("bpmn-signal", BPMN, "signal signalEventDefinition", None, R,
       "broadcast to every catcher waiting at that instant", "§10.4.5"),
    _c("bpmn-signal-ref", BPMN, "signalEventDefinition", "signalRef", R,
       "the signal thrown or awaited", "§10.4.5"),
    _c("bpmn-timer", BPMN, "timerEventDefinition timeDate timeDuration timeCycle", None, R,
       "a timer: a date, a duration, or a repeating cycle (ISO 8601)", "§10.4.5"),
    _c("bpmn-boundary-cycle", BPMN, "timeCycle", None, R,
       "a non-interrupting boundary timer with a timeCycle fires at every cycle while its "
       "activity runs (Rn/ bounds the firings); an interrupting one fires once", "§10.4.5, "
       "§13.5.3", when="non-interrupting-boundary"),
    _c("bpmn-conditional", BPMN, "conditionalEventDefinition condition", None, R,
       "fires when its condition becomes true", "§10.4.5"),
    _c("bpmn-error", BPMN, "error errorEventDefinition", None, R,
       "a boundary error event catches its activity's failures (errorCode, or every one)",
       "§10.4.5, §13.5.3"),
    _c("bpmn-error-ref", BPMN, "errorEventDefinition", "errorRef", R, "the error caught",
       "§10.4.5"),
    _c("bpmn-error-code", BPMN, "error", "errorCode", R, "the failure's exception name",
       "§10.4.5"),
    _c("bpmn-error-end", BPMN, "errorEventDefinition", None, R,
       "the error is caught by the nearest enclosing sub-process or call activity with a "
       "boundary error event for it (its errorCode, else a catch-all), which is cancelled and "
       "takes its exception flow; uncaught, the instance is aborted with a located fault",
       "§10.4.3, §13.5.3", when="in-end-event"),
    _c("bpmn-escalation-end", BPMN, "escalationEventDefinition", None, R,
       "the escalation is caught by the nearest enclosing sub-process or call activity with a "
       "boundary escalation event for it (its escalationCode, else one without escalationRef): "
       "an interrupting one cancels that activity and takes its flow, a non-interrupting one "
       "starts its flow while the activity goes on; the end event ends its path, and an "
       "escalation nothing catches changes nothing else", "§10.4.3, §13.5.3",
       when="in-end-event"),
    _c("bpmn-cancel-end", BPMN, "cancelEventDefinition compensateEventDefinition", None, W,
       "the end event ends its path; the cancellation (compensation) is not handed "
       "to a boundary event of an enclosing sub-process or call activity (BPMN §13.5.3: the "
       "nearest enclosing boundary event catches it)", "§10.4.3, §13.5.3", when="in-end-event",
       reported_by=("unsupported-event",)),
    _c("bpmn-error-start", BPMN, "errorEventDefinition escalationEventDefinition "
       "compensateEventDefinition", None, W,
       "a start event of this kind only an event sub-process can catch; opspec waits for a "
       "message of that name", "§10.4.2", when="in-start-event",
       reported_by=("unsupported-event",)),
    _c("bpmn-escalation-throw", BPMN, "escalationEventDefinition", None, R,
       "the escalation is handed to the nearest enclosing boundary escalation event for it, as "
       "from an escalation end event, and the token goes on along the throw event's flow",
       "§10.4.4, §13.5.3", when="in-throw-event"),
    _c("bpmn-error-throw", BPMN, "compensateEventDefinition errorEventDefinition", None, W,
       "raised as a message of that name (a boundary event waiting for it catches it)",
       "§10.4.4", when="in-throw-event", reported_by=("unsupported-event",)),
    _c("bpmn-escalation", BPMN, "escalation escalationEventDefinition", None, R,
       "a boundary escalation event catches the escalations of that code thrown inside its "
       "activity (without escalationRef: every one)", "§10.4.5, §13.5.3"),
    _c("bpmn-escalation-ref", BPMN, "escalationEventDefinition", "escalationRef", R,
       "the escalation", "§10.4.5"),
    _c("bpmn-escalation-code", BPMN, "escalation", "escalationCode", R, "its name",
       "§10.4.5"),
    _c("bpmn-compensation", BPMN, "compensateEventDefinition cancelEventDefinition", None, W,
       "boundary compensation and cancel events are ignored with their outgoing flows",
       "§10.4.5, §13.5.5", when="in-boundary-event", reported_by=("unsupported-element",)),
    _c("bpmn-compensation-refs", BPMN, "compensateEventDefinition", "activityRef", W,
       "ignored: opspec has no compensation", "§10.4.5"),
    _c("bpmn-compensation-wait", BPMN, "compensateEventDefinition", "waitForCompletion", W,
       "ignored: opspec has no compensation", "§10.4.5"),
    _c("bpmn-terminate", BPMN, "terminateEventDefinition", None, R,
       "the process instance ends: every activity of it stops", "§10.4.3, §13.5.6"),
    _c("bpmn-terminate-sub-process", BPMN, "terminateEventDefinition", None, R,
       "a terminate end event inside an embedded sub-process ends that sub-process only: "
       "everything in it stops and the parent goes on", "§13.5.6, §13.3.4",
       when="in-sub-process"),
    _c("bpmn-link", BPMN, "linkEventDefinition", None, R,
       "a throwing link event continues at the catching one of the same name", "§10.4.5"),
    _c("bpmn-link-name", BPMN, "linkEventDefinition", "name", R, "pairs throw and catch",
       "§10.4.5"),
    _c("bpmn-event-definition-ref", BPMN, "eventDefinitionRef", None, R,
       "the event's definition, declared at the top level", "§10.4.5"),
    # -- data ---------------------------------------------------------------------------------
    _c("bpmn-data", BPMN, "dataObject dataObjectReference property ioSpecification dataInput "
       "dataOutput dataInputAssociation dataOutputAssociation sourceRef targetRef "
       "transformation assignment from to itemDefinition", None, R,
       "data fields of the process, set when an activity starts (inputs) or ends (outputs)",
       "§10.3, §13.3.2"),
    _c("bpmn-data-refs", BPMN, "dataObjectReference", "dataObjectRef", R, "its data object",
       "§10.3.1"),
    _c("bpmn-item-subject", BPMN, "dataObject dataObjectReference property dataInput dataOutput "
       "inputDataItem outputDataItem dataStore dataStoreReference", "itemSubjectRef", R,
       "the field's type (a simple XML Schema type, else a string)", "§10.3.1"),
    _c("bpmn-structure", BPMN, "itemDefinition", "structureRef", R, "the type", "§10.3.1"),
    _c("bpmn-item-kind", BPMN, "itemDefinition", "itemKind", R,
       "Information (a data value); a Physical item is a value too", "§8.3.8"),
    _c("bpmn-collection", BPMN, "dataObject dataInput dataOutput itemDefinition inputDataItem "
       "outputDataItem", "isCollection", R, "an array field", "§10.3.1"),
    _c("bpmn-sets", BPMN, "inputSet outputSet dataInputRefs dataOutputRefs optionalInputRefs "
       "optionalOutputRefs whileExecutingInputRefs whileExecutingOutputRefs inputSetRefs "
       "outputSetRefs", None, R,
       "every data field exists in its process, so an activity's input set is always "
       "available when it starts", "§10.3.1, §13.3.2"),
    _c("bpmn-data-store", BPMN, "dataStore dataStoreReference", None, W,
       "no data moves to or from a data store", "§10.3.2", reported_by=("data-store",)),
    _c("bpmn-data-store-attrs", BPMN, "dataStore", "capacity", W,
       "ignored with the data store", "§10.3.2"),
    _c("bpmn-data-store-unlimited", BPMN, "dataStore", "isUnlimited", W,
       "ignored with the data store", "§10.3.2"),
    _c("bpmn-data-store-ref", BPMN, "dataStoreReference", "dataStoreRef", W,
       "ignored with the data store", "§10.3.2"),
    # -- participants -------------------------------------------------------------------------
    _c("bpmn-lanes", BPMN, "laneSet lane childLaneSet flowNodeRef", None, R,
       "a lane's flow nodes are performed by its participant", "§10.7"),
    _c("bpmn-pools", BPMN, "collaboration participant", None, R,
       "a pool's process is performed by its participant", "§9.2"),
    _c("bpmn-process-ref", BPMN, "participant", "processRef", R, "the pool's process", "§9.2"),
    _c("bpmn-message-flow-source", BPMN, "messageFlow", "sourceRef", R,
       "the node or pool that raises the message", "§9.3"),
    _c("bpmn-message-flow-target", BPMN, "messageFlow", "targetRef", R,
       "the node or pool that waits for it", "§9.3"),
    _c("bpmn-resources", BPMN, "resource resourceRole performer humanPerformer potentialOwner "
       "resourceRef", None, R, "the activity's performer", "§10.6"),
    _c("bpmn-resource-expressions", BPMN, "resourceAssignmentExpression resourceParameter "
       "resourceParameterBinding", None, W,
       "not evaluated: the activity's lane or pool performs it", "§10.6",
       reported_by=("performer-expression",)),
    _c("bpmn-resource-parameter-attrs", BPMN, "resourceParameter", "isRequired", W,
       "not evaluated", "§10.6"),
    _c("bpmn-resource-parameter-type", BPMN, "resourceParameter", "type", W, "not evaluated",
       "§10.6"),
    _c("bpmn-resource-parameter-ref", BPMN, "resourceParameterBinding", "parameterRef", W,
       "not evaluated", "§10.6"),
    # -- correlation, services, global tasks, imports ----------------------------------------
    _c("bpmn-correlation", BPMN, "correlationKey correlationProperty correlationPropertyBinding "
       "correlationPropertyRetrievalExpression correlationSubscription correlationPropertyRef "
       "messagePath dataPath", None, W,
       "ignored: opspec correlates a reply with the instance its message started "
       "(docs/semantics.md, Messages and signals)", "§8.3.2", when=None),
    _c("bpmn-correlation-refs", BPMN, "correlationPropertyRetrievalExpression", "messageRef", W,
       "ignored with the correlation", "§8.3.2"),
    _c("bpmn-correlation-key-ref", BPMN, "correlationSubscription", "correlationKeyRef", W,
       "ignored with the correlation", "§8.3.2"),
    _c("bpmn-correlation-binding-ref", BPMN, "correlationPropertyBinding",
       "correlationPropertyRef", W, "ignored with the correlation", "§8.3.2"),
    _c("bpmn-correlation-type", BPMN, "correlationProperty", "type", W,
       "ignored with the correlation", "§8.3.2"),
    _c("bpmn-global-tasks", BPMN, "globalTask globalUserTask globalManualTask globalScriptTask "
       "globalBusinessRuleTask", None, W,
       "ignored: a call activity cannot call a global task (only a process of the file)",
       "§10.2.5", reported_by=("unsupported-element",)),
    _c("bpmn-global-task-implementation", BPMN, "globalUserTask globalBusinessRuleTask",
       "implementation", W, "ignored with the global task", "§10.2.5"),
    _c("bpmn-global-script-language", BPMN, "globalScriptTask", "scriptLanguage", W,
       "ignored with the global task", "§10.2.5"),
    _c("bpmn-import", BPMN, "import", None, W,
       "not read: definitions in other files are not loaded", "§8.3.1"),
    _c("bpmn-import-attrs", BPMN, "import", "location", W, "not read", "§8.3.1"),
)


# XPDL 2.1 (WfMC-TC-1025, 2008) and 2.2: section numbers of XPDL 2.1.
_XPDL: tuple[Construct, ...] = (
    _c("xpdl-package", XPDL, "Package WorkflowProcesses WorkflowProcess Activities Activity "
       "Transitions Transition", None, R, "processes, activities and transitions",
       "§7.5, §7.6"),
    _c("xpdl-transition-ends", XPDL, "Transition", "From", R, "the source activity", "§7.6.9"),
    _c("xpdl-transition-to", XPDL, "Transition", "To", R, "the target activity", "§7.6.9"),
    _c("xpdl-transition-quantity", XPDL, "Transition", "Quantity", R,
       "Quantity tokens pass", "§7.6.9", when="not-one"),
    _c("xpdl-conditions", XPDL, "Condition Expression", None, R,
       "CONDITION, OTHERWISE, EXCEPTION, DEFAULTEXCEPTION transitions", "§7.6.9.1"),
    _c("xpdl-condition-type", XPDL, "Condition", "Type", R, "the kind of condition",
       "§7.6.9.1"),
    _c("xpdl-routes", XPDL, "Route Join Split TransitionRefs TransitionRef TransitionRestrictions "
       "TransitionRestriction", None, R,
       "gateways: exclusive, parallel, inclusive, complex, event-based", "§7.6.4, §7.6.9.2"),
    _c("xpdl-gateway-type", XPDL, "Route", "GatewayType", R, "the gateway",
       "§7.6.4"),
    _c("xpdl-join-type", XPDL, "Join Split", "Type", R, "the gateway", "§7.6.9.2"),
    _c("xpdl-exclusive-type", XPDL, "Route Join Split", "ExclusiveType", R,
       "Data: conditions decide; Event: the first event wins", "§7.6.4"),
    _c("xpdl-xor-type", XPDL, "Route", "XORType", R, "as ExclusiveType", "§7.6.4"),
    _c("xpdl-incoming-condition", XPDL, "Route", "IncomingCondition", R,
       "the complex join fires when it holds", "§7.6.4"),
    _c("xpdl-outgoing-condition", XPDL, "Route Split", "OutgoingCondition", W,
       "ignored: a complex split takes every transition whose condition holds", "§7.6.4"),
    _c("xpdl-route-instantiate", XPDL, "Route TaskReceive", "Instantiate", W,
       "ignored: the event does not start new instances", "§7.6.4", when="true"),
    _c("xpdl-or-join", XPDL, "Join Route", None, R,
       "the inclusive join fires per activation as BPMN Table 13.3 defines (XPDL is silent): "
       "one token from each incoming transition that has one", "§7.6.9.2; BPMN Table 13.3",
       when="inclusive-join"),
    _c("xpdl-implementations", XPDL, "Implementation No Task TaskManual TaskUser TaskService "
       "TaskScript Script TaskApplication TaskBusinessRule SubFlow Reference BlockActivity "
       "ActivitySets ActivitySet", None, R,
       "the activity's implementation: none, a task, a subflow, a block of an activity set",
       "§7.6.5, §7.6.6"),
    _c("xpdl-task-send", XPDL, "TaskSend", None, W,
       "runs as an automatic task: its message is not sent (use an end or intermediate "
       "message event, or opspec:Raises)", "§7.6.5.2"),
    _c("xpdl-task-receive", XPDL, "TaskReceive", None, W,
       "runs as an automatic task: it does not wait for its message (use an intermediate "
       "message event, or opspec:StartTrigger)", "§7.6.5.2"),
    _c("xpdl-task-reference", XPDL, "TaskReference", None, W,
       "runs as a manual task waiting for its performer; the referenced task is not run",
       "§7.6.5.2"),
    _c("xpdl-task-implementation", XPDL, "TaskUser TaskService TaskSend TaskReceive",
       "Implementation", R, "the service is simulated (a bound device or performer)",
       "§7.6.5.2"),
    _c("xpdl-tools", XPDL, "Tool", None, R, "every Tool of the activity runs, in order",
       "XPDL 1.0 §7.6.5.1"),
    _c("xpdl-reference", XPDL, "Reference", "ActivityId", R,
       "the activity runs the implementation of the activity it references", "§7.6.5"),
    _c("xpdl-event-implementation", XPDL, "StartEvent IntermediateEvent EndEvent",
       "Implementation", R, "the message service is simulated (messages go by name)",
       "§7.6.2"),
    _c("xpdl-required-parameter", XPDL, "FormalParameter", "Required", R,
       "a call must pass it", "§7.9"),
    _c("xpdl-task-application", XPDL, "TaskApplication", "Id", R, "the application called",
       "§7.6.5.2"),
    _c("xpdl-subflow", XPDL, "SubFlow", "Execution", R,
       "SYNCHR waits for the called process, ASYNCHR starts it beside the caller", "§7.6.5.3"),
    _c("xpdl-subflow-package", XPDL, "SubFlow TaskApplication", "PackageRef", R,
       "the external package of the process called", "§7.6.5.3"),
    _c("xpdl-block", XPDL, "BlockActivity", "ActivitySetId", R, "the activity set run",
       "§7.6.5.4"),
    _c("xpdl-block-start", XPDL, "BlockActivity SubFlow", "StartActivityId", R,
       "the activity the set starts at", "§7.6.5.4"),
    _c("xpdl-ad-hoc", XPDL, "ActivitySet WorkflowProcess", "AdHoc", R,
       "its activities run in any order until AdHocCompletionCondition holds", "§7.5.7"),
    _c("xpdl-ad-hoc-ordering", XPDL, "ActivitySet WorkflowProcess", "AdHocOrdering", R,
       "Parallel or Sequential", "§7.5.7"),
    _c("xpdl-ad-hoc-completion", XPDL, "ActivitySet WorkflowProcess", "AdHocCompletionCondition",
       R, "the set completes when it holds", "§7.5.7"),
    _c("xpdl-start-mode", XPDL, "Activity", "StartMode", R,
       "Manual: the activity waits for its performer", "§7.6"),
    _c("xpdl-finish-mode", XPDL, "Activity", "FinishMode", R,
       "Manual: the activity waits for its performer", "§7.6"),
    _c("xpdl-quantities", XPDL, "Activity", "StartQuantity", R,
       "the activity waits for StartQuantity tokens (thread merge, WCP-41)", "§7.6",
       when="not-one"),
    _c("xpdl-completion-quantity", XPDL, "Activity", "CompletionQuantity", R,
       "CompletionQuantity tokens leave on each outgoing transition (thread split, WCP-42)",
       "§7.6", when="not-one"),
    _c("xpdl-compensation", XPDL, "Activity", "IsForCompensation", W,
       "opspec has no compensation: this is an ordinary activity", "§7.6", when="true"),
    _c("xpdl-transaction", XPDL, "Activity", "IsATransaction", W,
       "runs as a plain activity: no compensation, no cancel", "§7.6", when="true"),
    _c("xpdl-transaction-element", XPDL, "Transaction", None, W,
       "ignored: no compensation, no cancel", "§7.6"),
    _c("xpdl-transaction-attrs", XPDL, "Transaction", "TransactionId", W, "ignored", "§7.6"),
    _c("xpdl-transaction-method", XPDL, "Transaction", "TransactionMethod", W, "ignored",
       "§7.6"),
    _c("xpdl-transaction-protocol", XPDL, "Transaction", "TransactionProtocol", W, "ignored",
       "§7.6"),
    _c("xpdl-manual-without-implementation", XPDL, "Activity", None, R,
       "an activity with no implementation (\"implemented by manual procedures\") performed "
       "by a HUMAN or ROLE participant is manual work: it is offered to its participant's or "
       "lane's performer (a HUMAN one's to the user lane), and waits, reported as waiting "
       "work, while none is bound; opspec:AutoRun=\"true\" makes it automatic",
       "§7.6.5.1, §7.7", when="role-without-implementation"),
    _c("xpdl-loops", XPDL, "Loop LoopStandard LoopMultiInstance LoopCondition MI_Condition "
       "ComplexMI_FlowCondition", None, R, "standard and multi-instance loops", "§7.6.3"),
    _c("xpdl-loop-type", XPDL, "Loop", "LoopType", R, "Standard or MultiInstance", "§7.6.3"),
    _c("xpdl-loop-standard", XPDL, "LoopStandard", "LoopCondition", R, "repeats while it holds",
       "§7.6.3"),
    _c("xpdl-loop-maximum", XPDL, "LoopStandard", "LoopMaximum", R, "at most this many",
       "§7.6.3"),
    _c("xpdl-loop-test", XPDL, "LoopStandard", "TestTime", R, "Before or After", "§7.6.3"),
    _c("xpdl-mi-condition", XPDL, "LoopMultiInstance", "MI_Condition", R, "the number of "
       "instances", "§7.6.3"),
    _c("xpdl-mi-ordering", XPDL, "LoopMultiInstance", "MI_Ordering", R, "Sequential or "
       "Parallel", "§7.6.3"),
    _c("xpdl-mi-flow", XPDL, "LoopMultiInstance", "MI_FlowCondition", R,
       "All, One, None, Complex: when the token moves on", "§7.6.3"),
    _c("xpdl-mi-complex", XPDL, "LoopMultiInstance", "ComplexMI_FlowCondition", W,
       "once it holds the token moves on, but the remaining instances run on to their end "
       "(BPMN §13.3.7: a completion condition cancels them)", "§7.6.3", when="present"),
    _c("xpdl-loop-counter", XPDL, "LoopStandard LoopMultiInstance", "LoopCounter", W,
       "ignored: the loop counter is not written to a data field", "§7.6.3"),
    _c("xpdl-events", XPDL, "Event StartEvent EndEvent IntermediateEvent", None, R,
       "start, end and intermediate events with their trigger or result", "§7.6.2"),
    _c("xpdl-several-starts", XPDL, "StartEvent", None, R,
       "several start events are independent: each triggered start starts its own instance, "
       "and only its own path runs; an instance started without a trigger begins at the "
       "StartEvents with Trigger None, all of them (as XPDL 1.0 engines start every activity "
       "without incoming transitions)", "§7.6.2", when="several-starts"),
    _c("xpdl-event-trigger", XPDL, "StartEvent IntermediateEvent", "Trigger", R, "its trigger",
       "§7.6.2"),
    _c("xpdl-event-result", XPDL, "EndEvent", "Result", R,
       "None, Message, Signal, Terminate, Error…", "§7.6.2"),
    _c("xpdl-terminate-block", XPDL, "EndEvent", "Result", R,
       "a terminate end event inside an activity set ends that block only; the parent goes on "
       "(XPDL is silent: BPMN §13.5.6 followed)", "§7.6.2; BPMN §13.5.6",
       when="terminate-in-activity-set"),
    _c("xpdl-error-end", XPDL, "ResultError", None, R,
       "the error is caught by the nearest enclosing block or subflow activity's exception "
       "transition for it (else a catch-all); uncaught, the instance is aborted with a "
       "located fault", "§7.6.2; BPMN §13.5.3", when="in-end-event"),
    _c("xpdl-error-code", XPDL, "ResultError", "ErrorCode", R, "the error caught", "§7.6.2"),
    _c("xpdl-boundary-target", XPDL, "IntermediateEvent", "Target", R,
       "the activity the event is attached to", "§7.6.2"),
    _c("xpdl-triggers", XPDL, "TriggerTimer TimeDate TimeCycle TriggerConditional TriggerRule "
       "TriggerResultMessage Message TriggerResultSignal TriggerResultLink TriggerEscalation",
       None, R, "message, timer, conditional, signal, link triggers", "§7.6.2"),
    _c("xpdl-timer-attrs", XPDL, "TriggerTimer", "TimeDate", R, "a date", "§7.6.2"),
    _c("xpdl-time-date-expression", XPDL, "TimeDate", None, W,
       "a TimeDate that is no date but a data field or expression is read as a number of "
       "seconds to wait, not as a date: a field holding an ISO date stops the run with an "
       "error (BPMN §10.4.5: a timeDate is a date and time)", "§7.6.2; BPMN §10.4.5",
       when="not-a-date", hint="write the date itself (2026-01-01T08:00:00), or a "
       "TimeCycle with the delay in seconds"),
    _c("xpdl-time-date-expression-attr", XPDL, "TriggerTimer", "TimeDate", W,
       "a TimeDate that is no date but a data field or expression is read as a number of "
       "seconds to wait, not as a date (BPMN §10.4.5: a timeDate is a date and time)",
       "§7.6.2; BPMN §10.4.5", when="not-a-date"),
    _c("xpdl-timer-cycle-attr", XPDL, "TriggerTimer", "TimeCycle", R, "a repeating cycle",
       "§7.6.2"),
    _c("xpdl-boundary-cycle", XPDL, "TimeCycle", None, R,
       "a non-interrupting timer with a cycle attached to an activity fires at every cycle "
       "while the activity runs", "§7.6.2", when="attached-timer"),
    _c("xpdl-catch-throw", XPDL, "TriggerResultMessage TriggerResultSignal TriggerResultLink",
       "CatchThrow", R, "whether the event waits or raises", "§7.6.2"),
    _c("xpdl-signal-name", XPDL, "TriggerResultSignal TriggerResultLink", "Name", R,
       "the signal or link", "§7.6.2"),
    _c("xpdl-conditional-name", XPDL, "TriggerConditional", "ConditionName", R,
       "the condition", "§7.6.2"),
    _c("xpdl-rule-name", XPDL, "TriggerRule", "RuleName", R, "the rule", "§7.6.2"),
    _c("xpdl-message-ttl", XPDL, "TriggerResultMessage", None, R,
       "a message nobody waits for yet is kept for its catcher (up to 100 per name, then a "
       "trigger.lost event; a time to live only from opspec:MessageTTL)", "§7.6.2; BPMN §10.4.5",
       when="throws"),
    _c("xpdl-multiple-triggers", XPDL, "TriggerMultiple TriggerIntermediateMultiple "
       "ResultMultiple", None, W, "only the first trigger counts", "§7.6.2"),
    _c("xpdl-compensation-trigger", XPDL, "TriggerResultCompensation TriggerResultCancel",
       None, W, "opspec has no compensation or cancel: the event ends its path or passes on",
       "§7.6.2"),
    _c("xpdl-compensation-activity", XPDL, "TriggerResultCompensation", "ActivityId", W,
       "ignored: no compensation", "§7.6.2"),
    _c("xpdl-deadlines", XPDL, "Deadline DeadlineDuration ExceptionName", None, R,
       "when the duration has passed, the activity is interrupted (SYNCHR) or the exception "
       "path starts beside it (ASYNCHR)", "§7.6.8"),
    _c("xpdl-deadline-execution", XPDL, "Deadline", "Execution", R, "SYNCHR or ASYNCHR",
       "§7.6.8"),
    _c("xpdl-mi-deadline", XPDL, "Deadline", None, R,
       "a deadline of a multi-instance activity belongs to the activity as a whole (armed once)",
       "§7.6.8; BPMN §13.5.3", when="on-multi-instance"),
    _c("xpdl-data", XPDL, "DataFields DataField FormalParameters FormalParameter "
       "ActualParameters ActualParameter InitialValue Assignments Assignment Target "
       "DataType BasicType DeclaredType SchemaType ExternalReference RecordType UnionType "
       "EnumerationType EnumerationValue ArrayType ListType Member TypeDeclarations "
       "TypeDeclaration Length Precision Scale", None, R,
       "data fields, parameters and assignments", "§7.8, §7.9, §7.11"),
    _c("xpdl-data-attrs", XPDL, "DataField FormalParameter", "IsArray", R, "an array field",
       "§7.11"),
    _c("xpdl-parameter-mode", XPDL, "FormalParameter", "Mode", R, "IN, OUT, INOUT", "§7.9"),
    _c("xpdl-assign-time", XPDL, "Assignment", "AssignTime", R, "Start or End", "§7.6.11"),
    _c("xpdl-read-only", XPDL, "DataField FormalParameter", "ReadOnly", W,
       "not enforced: an assignment to it is carried out", "§7.11"),
    _c("xpdl-correlation", XPDL, "DataField", "Correlation", W,
       "ignored: opspec correlates a reply with the instance its message started", "§7.11"),
    _c("xpdl-data-mappings", XPDL, "DataMappings DataMapping Actual", None, W,
       "ignored: no data moves with the mapping", "§7.6.5"),
    _c("xpdl-applications", XPDL, "Applications Application", None, R,
       "applications the tasks call (devices, when bound)", "§7.10"),
    _c("xpdl-participants", XPDL, "Participants Participant ParticipantType Performers "
       "Performer Pools Pool Lanes Lane NestedLane", None, R,
       "who performs each activity (a lane's, a pool's participant)", "§7.7, §7.4"),
    _c("xpdl-participant-type", XPDL, "ParticipantType", "Type", R,
       "HUMAN / ROLE / SYSTEM…", "§7.7"),
    _c("xpdl-pool-process", XPDL, "Pool", "Process", R, "the pool's process", "§7.4"),
    _c("xpdl-pool-participant", XPDL, "Pool", "Participant", R, "the pool's participant",
       "§7.4"),
    _c("xpdl-lane-parent", XPDL, "Lane", "ParentLane", R, "the enclosing lane", "§7.4"),
    _c("xpdl-lane-parent-pool", XPDL, "Lane", "ParentPool", R, "its pool", "§7.4"),
    _c("xpdl-lane-id", XPDL, "NestedLane", "LaneId", R, "the nested lane", "§7.4"),
    _c("xpdl-external", XPDL, "ExternalPackages ExternalPackage", None, R,
       "other packages, loaded from their href", "§7.3"),
    _c("xpdl-external-href", XPDL, "ExternalPackage", "href", R, "the file loaded", "§7.3"),
    _c("xpdl-message-flows", XPDL, "MessageFlows MessageFlow", None, W,
       "ignored: messages go by name (a thrown message is caught by a waiting event of that "
       "name)", "§7.4.2"),
    _c("xpdl-message-flow-ends", XPDL, "MessageFlow", "Source", W, "ignored", "§7.4.2"),
    _c("xpdl-message-flow-target", XPDL, "MessageFlow", "Target", W, "ignored", "§7.4.2"),
    _c("xpdl-simulation", XPDL, "SimulationInformation TimeEstimation Duration WaitingTime "
       "WorkingTime Cost", None, W,
       "ignored: an activity's duration is its opspec:Duration (docs/sisarl-xpdl.md)",
       "§7.6.7"),
    _c("xpdl-limit", XPDL, "Limit", None, W, "ignored: no time limit is enforced (use a "
       "Deadline)", "§7.6"),
    _c("xpdl-priority", XPDL, "Priority", None, R, "the activity's or process's priority",
       "§7.6"),
    _c("xpdl-web-services", XPDL, "WebServiceOperation WebServiceFaultCatch Service EndPoint "
       "Partner PartnerLink PartnerLinkType PartnerLinkTypes PartnerLinks Role MyRole "
       "PartnerRole MessageIn MessageOut WebService", None, R,
       "the service is simulated: the task completes when its bound device or performer does, "
       "else by itself", "§7.6.5.2"),
    _c("xpdl-process-start", XPDL, "WorkflowProcess", "DefaultStartActivityId", W,
       "ignored: every activity without incoming transitions starts", "§7.5"),
    _c("xpdl-set-start", XPDL, "ActivitySet", "DefaultStartActivityId", W,
       "ignored: every activity of the set without incoming transitions starts", "§7.5.7"),
    _c("xpdl-process-set-start", XPDL, "WorkflowProcess", "DefaultStartActivitySetId", W,
       "ignored", "§7.5"),
    _c("xpdl-subflow-start-set", XPDL, "SubFlow", "StartActivitySetId", W, "ignored",
       "§7.6.5.3"),
    _c("xpdl-instance-data", XPDL, "SubFlow", "InstanceDataField", W,
       "ignored: the called instance's id is not stored", "§7.6.5.3"),
    _c("xpdl-compensation-process", XPDL, "WorkflowProcess", "EnableInstanceCompensation", W,
       "ignored: no compensation", "§7.5", when="true"),
    _c("xpdl-suppress-join-failure", XPDL, "WorkflowProcess", "SuppressJoinFailure", W,
       "ignored (a BPEL notion)", "§7.5", when="true"),
    _c("xpdl-artifact-inputs", XPDL, "InputSets InputSet Input OutputSets OutputSet Output "
       "ArtifactInput PropertyInput DataObject", None, W,
       "ignored: an activity does not wait for its inputs, and data objects move no data "
       "(use data fields)", "§7.6.10"),
    _c("xpdl-artifact-attrs", XPDL, "ArtifactInput", "RequiredForStart", W, "ignored",
       "§7.6.10"),
    _c("xpdl-artifact-ids", XPDL, "ArtifactInput Input Output", "ArtifactId", W, "ignored",
       "§7.6.10"),
    _c("xpdl-property-input", XPDL, "PropertyInput", "PropertyId", W, "ignored", "§7.6.10"),
    _c("xpdl-data-object-start", XPDL, "DataObject", "RequiredForStart", W, "ignored",
       "§7.6.10"),
    _c("xpdl-data-object-end", XPDL, "DataObject", "ProducedAtCompletion", W, "ignored",
       "§7.6.10"),
    _c("xpdl-rules", XPDL, "BusinessRule Rule RuleName", None, W,
       "not evaluated: a business rule task runs by itself", "§7.6.5.2"),
    _c("xpdl-extended-attribute-value", XPDL, "ExtendedAttribute", "Value", R,
       "a SISARL directive's value (docs/sisarl-xpdl.md)", "§7.13"),
    _c("xpdl-join-incoming-condition", XPDL, "Join", "IncomingCondtion", R,
       "as IncomingCondition (the XSD's spelling)", "§7.6.4"),
    _c("xpdl-extended-attributes", XPDL, "ExtendedAttributes ExtendedAttribute", None, R,
       "opspec's SISARL directives run (docs/sisarl-xpdl.md); other vendors' are kept and "
       "not run (unknown-directive)", "§7.13"),
)

CONSTRUCTS: tuple[Construct, ...] = _BPMN + _XPDL

_LAYOUT = "layout, display and naming: nothing runs differently whatever they say"
_META = "documentation, authoring and version metadata"

INERT: tuple[Inert, ...] = (
    Inert(BPMN, ("*",), ("id", "name"), "identifiers and names (references resolve by id)",
          include_elements=False),
    Inert(BPMNDI_NAMESPACES[0], ("*",), ("*",), "diagram interchange: " + _LAYOUT),
    Inert(BPMNDI_NAMESPACES[1], ("*",), ("*",), "diagram interchange: " + _LAYOUT),
    Inert(BPMNDI_NAMESPACES[2], ("*",), ("*",), "diagram interchange: " + _LAYOUT),
    Inert(BPMN, ("documentation", "textAnnotation", "text", "association", "group", "category",
                 "categoryValue", "categoryValueRef", "artifact"), ("*",),
          "artifacts and documentation: BPMN §7.2 (they do not affect the flow)"),
    Inert(BPMN, ("definitions",), ("exporter", "exporterVersion", "targetNamespace",
                                   "typeLanguage"), _META, include_elements=False),
    Inert(BPMN, ("process",), ("isExecutable", "isClosed", "processType",
                               "definitionalCollaborationRef"),
          "process metadata: every process of the file runs", include_elements=False),
    Inert(BPMN, ("extensionElements", "extension"), ("*",),
          "extensions: opspec's own are directives (docs/bpmn.md), others kept and reported "
          "by the reader (vendor-extension)"),
    Inert(BPMN, ("lane",), ("partitionElementRef",),
          "a lane's partition element: descriptive (flowNodeRef decides), BPMN §10.7",
          include_elements=False),
    Inert(BPMN, ("sequenceFlow",), ("isImmediate",),
          "whether other participants may act between: a choreography notion (BPMN §8.3.13)",
          include_elements=False),
    Inert(BPMN, ("supportedInterfaceRef",), ("*",),
          "service interfaces: opspec simulates services, BPMN §8.3.10"),
    Inert(BPMN, ("auditing", "monitoring", "rendering", "relationship", "source", "target",
                 "supports", "dataState", "partitionElement", "ioBinding"), ("*",),
          "tool, audit and rendering hooks, BPMN §8.3 (no effect on the token flow)"),
    Inert(BPMN, ("activity", "event", "flowElement", "flowNode", "gateway", "rootElement",
                 "baseElement", "baseElementWithMixedContent", "catchEvent", "throwEvent",
                 "callableElement", "eventDefinition", "loopCharacteristics", "dataAssociation",
                 "expression", "formalExpression", "implicitThrowEvent", "artifact"), (),
          "abstract or substitution heads: written only as their concrete elements (or as "
          "xsi:type of an expression), which are classified with their attributes"),
    Inert(BPMN, ("inclusiveGateway", "exclusiveGateway", "parallelGateway", "complexGateway",
                 "eventBasedGateway", "gateway"), ("gatewayDirection",),
          "a constraint on the number of flows (BPMN §10.5.1); the flows decide",
          include_elements=False),
    Inert(BPMN, ("message", "error", "escalation", "signal", "condition", "formalExpression",
                 "transformation", "messagePath", "dataPath"),
          ("itemRef", "structureRef", "evaluatesToTypeRef"),
          "payload and result types: opspec's data is dynamically typed",
          include_elements=False),
    Inert(BPMN, ("interface", "operation", "operationRef", "inMessageRef", "outMessageRef",
                 "errorRef", "endPoint", "endPointRef", "interfaceRef", "partnerEntity",
                 "partnerRole",
                 "participantRef"), ("*",),
          "service interfaces and partners: opspec simulates services (bound devices, "
          "performers), BPMN §8.3.10"),
    Inert(BPMN, ("choreography", "choreographyTask", "callChoreography", "subChoreography",
                 "globalChoreographyTask", "choreographyActivity", "choreographyRef",
                 "conversation", "subConversation", "callConversation", "globalConversation",
                 "conversationNode", "conversationLink", "conversationAssociation",
                 "participantAssociation", "innerParticipantRef", "outerParticipantRef",
                 "messageFlowAssociation", "messageFlowRef", "participantMultiplicity",
                 "collaboration"), ("isClosed",),
          "choreographies and conversations describe exchanges between participants; they are "
          "outside BPMN's Process Execution Conformance (§2.2) — the reader reports them",
          include_elements=False),
    Inert(BPMN, ("choreography", "choreographyTask", "callChoreography", "subChoreography",
                 "globalChoreographyTask", "choreographyActivity", "choreographyRef",
                 "conversation", "subConversation", "callConversation", "globalConversation",
                 "conversationNode", "conversationLink", "conversationAssociation",
                 "participantAssociation", "innerParticipantRef", "outerParticipantRef",
                 "messageFlowAssociation", "messageFlowRef", "participantMultiplicity"), ("*",),
          "choreographies and conversations: outside Process Execution Conformance (§2.2)"),
    Inert(BPMN, ("documentation", "textAnnotation"), ("textFormat",), _META,
          include_elements=False),
    Inert(BPMN, ("import",), ("namespace", "importType"), "with import", include_elements=False),
    # XPDL
    Inert(XPDL, ("*",), ("Id", "Name"), "identifiers and names", include_elements=False),
    Inert(XPDL, ("PackageHeader", "RedefinableHeader", "ProcessHeader", "XPDLVersion", "Vendor",
                 "Created", "ModificationDate", "Description", "Documentation", "Author",
                 "Version", "Codepage", "Countrykey", "Responsibles", "Responsible",
                 "ValidFrom", "ValidTo", "ConformanceClass", "Script", "Icon",
                 "CostUnit", "PriorityUnit", "Categories", "Category", "Object",
                 "Extensions", "VendorExtensions", "VendorExtension", "LayoutInfo",
                 "Class", "Ejb", "Pojo", "Xslt", "Form", "FormLayout", "JndiName", "HomeClass",
                 "Method", "Location", "Type", "CostStructure", "FixedCost", "ResourceCosts",
                 "ResourceCost", "ResourceCostName", "CostUnitOfTime", "Event", "Page", "Pages",
                 "Properties", "IORules", "TestValue", "TaskReference", "RuleName", "Member"),
          ("*",), _META + "; application type descriptions (the application is simulated); "
          "the package header's script and units", include_elements=False),
    Inert(XPDL, ("PackageHeader", "RedefinableHeader", "ProcessHeader", "XPDLVersion", "Vendor",
                 "Created", "ModificationDate", "Description", "Documentation", "Author",
                 "Version", "Codepage", "Countrykey", "Responsibles", "Responsible",
                 "ValidFrom", "ValidTo", "ConformanceClass", "Icon", "CostUnit", "PriorityUnit",
                 "Categories", "Category", "Object", "Extensions", "VendorExtensions",
                 "VendorExtension", "LayoutInfo", "Class", "Ejb", "Pojo", "Xslt", "Form",
                 "FormLayout", "JndiName", "HomeClass", "Method", "Location", "Type", "Page",
                 "Pages", "Properties", "IORules", "CostStructure", "FixedCost",
                 "ResourceCosts", "ResourceCost", "ResourceCostName", "CostUnitOfTime",
                 "TestValue"),
          ("*",), _META + "; application type descriptions (the application is simulated)"),
    Inert(XPDL, ("NodeGraphicsInfos", "NodeGraphicsInfo", "ConnectorGraphicsInfos",
                 "ConnectorGraphicsInfo", "Coordinates", "Associations", "Association",
                 "Artifacts", "Artifact", "Icon"), ("*",), "diagram: " + _LAYOUT),
    Inert(XPDL, ("*",), ("ScriptGrammar", "ScriptType", "ScriptVersion", "Grammar", "Version",
                         "Language", "QueryLanguage"),
          "the expression language: opspec reads its own grammar whatever is named, and "
          "refuses what it cannot read (bad-condition)", include_elements=False),
    Inert(XPDL, ("Activity", "WorkflowProcess", "Package", "ActivitySet", "BlockActivity",
                 "SubFlow", "Route", "Pool", "ProcessHeader", "RedefinableHeader", "Lane",
                 "MessageFlow", "Transition", "TransitionRef", "Application"),
          ("Status", "StartActivity", "AccessLevel", "ProcessType", "View", "MarkerVisible",
           "BoundaryVisible", "MainPool", "Orientation", "DurationUnit", "PublicationStatus",
           "Instantiation"),
          "display, access and status flags: " + _LAYOUT, include_elements=False),
    Inert(XPDL, ("Message", "MessageIn", "MessageOut"), ("From", "To", "FaultName"),
          "message addressing: messages go by name", include_elements=False),
    Inert(XPDL, ("ExternalReference", "Xslt", "VendorExtension"),
          ("location", "namespace", "xref", "ToolId", "extensionDescription", "schemaLocation"),
          "type and vendor references", include_elements=False),
    Inert(XPDL, ("ArrayType",), ("LowerIndex", "UpperIndex"), "array bounds: not enforced "
          "(opspec's arrays grow)", include_elements=False),
    Inert(XPDL, ("EnumerationValue",), ("Name",), "the enumeration's values",
          include_elements=False),
    Inert(XPDL, ("Role", "PartnerLink", "PartnerLinkType", "Partner", "PartnerRole", "MyRole",
                 "Service", "EndPoint", "WebService", "WebServiceOperation",
                 "WebServiceFaultCatch", "Message", "MessageIn", "MessageOut"),
          ("portType", "name", "PartnerLinkId", "RoleType", "RoleName", "PortName",
           "ServiceName", "EndPointType", "InputMsgName", "OutputMsgName", "OperationName",
           "FaultName", "PartnerLinkTypeId"),
          "service addressing: the service is simulated", include_elements=False),
    Inert(XPDL, ("DataMapping",), ("Direction", "Formal"), "with DataMapping",
          include_elements=False),
    Inert(XPDL, ("Script", "BasicType"), ("Type",),
          "the package's script language / a basic type's name: read as the expression "
          "grammar and the field's type", include_elements=False),
    Inert(XPDL, ("Group",), ("*",), "artifact grouping: " + _LAYOUT),
    Inert(XPDL, ("SimulationInformation",), ("Instantiation",), "with SimulationInformation",
          include_elements=False),
    Inert(XPDL, ("DataObject",), ("State",), "a data object's state label",
          include_elements=False),
)


def _index() -> Mapping[tuple[str, str, str | None], tuple[Construct, ...]]:
    out: dict[tuple[str, str, str | None], list[Construct]] = {}
    for construct in CONSTRUCTS:
        for element in construct.elements:
            out.setdefault((construct.namespace, element, construct.attribute), []).append(
                construct)
    return MappingProxyType({key: tuple(found) for key, found in out.items()})


_BY_KEY = _index()
_EMPTY: tuple[Construct, ...] = ()


def _reported() -> Mapping[tuple[str, str], tuple[tuple[str | None, Construct], ...]]:
    """What the gate looks at: per (namespace, element), its WARNS and REFUSES entries, of the
    element (attribute ``None``) and of its attributes."""
    out: dict[tuple[str, str], list[tuple[str | None, Construct]]] = {}
    for construct in CONSTRUCTS:
        if construct.kind is Kind.RUNS:
            continue
        for element in construct.elements:
            out.setdefault((construct.namespace, element), []).append(
                (construct.attribute, construct))
    # the element's own entries first: an attribute ignored with its element is then quiet
    return MappingProxyType({key: tuple(sorted(found, key=lambda f: f[0] is not None))
                             for key, found in out.items()})


#: (namespace, element) -> ((attribute or None, entry), ...) for WARNS and REFUSES entries.
REPORTED = _reported()


def constructs_for(namespace: str, element: str, attribute: str | None = None
                   ) -> tuple[Construct, ...]:
    """The registry's entries for an element (``attribute`` None) or one of its attributes."""
    return _BY_KEY.get((namespace, element, attribute), _EMPTY)


def is_inert(namespace: str, element: str, attribute: str | None = None) -> str | None:
    """The reason an element or attribute has no execution semantics, or ``None``."""
    for group in INERT:
        if group.namespace != namespace:
            continue
        if "*" not in group.elements and element not in group.elements:
            continue
        if attribute is None:
            if group.include_elements and group.reason:
                return group.reason
        elif ("*" in group.attributes or attribute in group.attributes) and group.reason:
            return group.reason
    return None


def _names(construct: Construct) -> str:
    prefix = "bpmn:" if construct.namespace == BPMN else ""
    names = ", ".join(f"`{prefix}{e}`" for e in construct.elements)
    return f"{names} `@{construct.attribute}`" if construct.attribute else names


_WHEN_TEXT = {
    None: "",
    "true": "when true",
    "false": "when false",
    "not-one": "when not 1",
    "not-all": "when not All",
    "parallel": "when Parallel",
    "present": "when given",
    "join": "as a join (several incoming flows)",
    "inclusive-join": "an inclusive join",
    "in-event-sub-process": "in an event sub-process",
    "refused-event-sub-process": "true, with a start event other than one timer or message",
    "in-refused-event-sub-process": "in an event sub-process opspec does not run",
    "in-multi-instance": "of a multi-instance loop",
    "in-sub-process": "in an embedded sub-process",
    "in-end-event": "in an end event",
    "in-start-event": "in a start event",
    "in-throw-event": "in an intermediate throw event",
    "in-boundary-event": "in a boundary event",
    "several-starts": "several in one process",
    "several-none-starts": "several without an event definition in one process",
    "several-definitions": "with several event definitions",
    "timer-on-multi-instance": "a timer on a multi-instance activity",
    "non-interrupting-boundary": "of a non-interrupting boundary timer",
    "attached-timer": "of a non-interrupting timer attached to an activity",
    "terminate-in-activity-set": "Terminate, in an activity set",
    "throws": "thrown",
    "not-a-date": "a data field or expression, not a date",
    "on-multi-instance": "of a multi-instance activity",
    "fed-only-by-ignored": "all its incoming flows come from ignored elements",
    "role-without-implementation": "no implementation, performed by a ROLE participant",
}


def markdown_table() -> str:
    """docs/semantics.md's table of what opspec does not run as its standard says (WARNS,
    REFUSES), generated from the registry: tests/semantics_gate/ fails when they differ."""
    lines = ["| standard | construct | when | opspec | what opspec does | section |",
             "|---|---|---|---|---|---|"]
    for construct in CONSTRUCTS:
        if construct.kind is Kind.RUNS:
            continue
        standard = "BPMN 2.0" if construct.namespace == BPMN else "XPDL 2.1"
        when = _WHEN_TEXT.get(construct.when, construct.when)
        text = construct.text.replace("|", "/")
        lines.append(f"| {standard} | {_names(construct)} | {when} | {construct.kind.value} "
                     f"| {text} | {construct.section} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":          # python -m opspec.xpdl.constructs: the docs table
    print(markdown_table(), end="")
