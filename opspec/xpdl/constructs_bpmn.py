"""The construct registry's entries for BPMN 2.0 (OMG formal/2011-01-03): for every element
and attribute of chapter 10 (process elements) and chapter 13 (execution) that has execution
semantics, whether opspec RUNS it as the standard says, WARNS (it runs differently: the text
says what opspec does instead) or REFUSES it, with the section that defines it.

Grouped by kind of construct: sequence flow, activities, loops, gateways, events, data,
participants, then correlation, services, global tasks and imports. What BPMN 2.0 defines
without execution semantics is in :mod:`opspec.xpdl.constructs_inert`; how an entry is read
is said in :mod:`opspec.xpdl.constructs`.
"""

from __future__ import annotations

from opspec.xpdl.construct_entry import BPMN, Construct, Kind
from opspec.xpdl.construct_entry import entry as _c

__all__ = ["BPMN_CONSTRUCTS"]

R, W, X = Kind.RUNS, Kind.WARNS, Kind.REFUSES

_ACTIVITIES = ("task userTask manualTask serviceTask sendTask receiveTask scriptTask "
               "businessRuleTask callActivity subProcess adHocSubProcess transaction")
_GATEWAYS = "exclusiveGateway parallelGateway inclusiveGateway complexGateway eventBasedGateway"
_EVENTS = "startEvent endEvent intermediateCatchEvent intermediateThrowEvent boundaryEvent"
_SUBS = "subProcess adHocSubProcess transaction"

BPMN_CONSTRUCTS: tuple[Construct, ...] = (
    # -- sequence flow ------------------------------------------------------------------------
    _c("bpmn-process", BPMN, "definitions process", None, R,
       "each process is a workflow; its instances run on the simulated clock", "§10.1, §13"),
    _c("bpmn-non-executable", BPMN, "process", "isExecutable", W,
       "opspec runs it all the same, as drawn, by the execution semantics of §13 (a "
       "non-executable process is modelled to document behaviour, not to be executed, and "
       "may leave out what execution needs, such as formal conditions)",
       "§10.2, Table 10.1", when="false",
       hint="set isExecutable=\"true\" when the process is meant to run as drawn; the run "
       "is the same either way"),
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
    _c("bpmn-unstarted-node", BPMN, f"{_ACTIVITIES} {_GATEWAYS} intermediateCatchEvent "
       "intermediateThrowEvent endEvent", None, W,
       "no sequence flow leads to it, and the process's instances start at start events "
       "with a trigger, each running only its own path: it never runs in those instances, "
       "only in one started without a trigger (beside a none start event, called from "
       "another process, or from the API); opspec check reports it dead when no such "
       "instance runs (BPMN 2.0: \"All Flow Objects that do not have an incoming Sequence "
       "Flow (i.e., are not a target of a Sequence Flow) SHALL be instantiated when the "
       "Process is instantiated\")", "§10.4.2", when="unstarted-beside-triggered-start",
       hint="add a sequence flow to it from the node after which it should run, or remove "
            "it"),
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
    _c("bpmn-sub-process-start-trigger", BPMN, "startEvent", None, W,
       "its trigger is ignored: it starts with the sub-process, at once, as a none start "
       "event does (BPMN 2.0 §10.4.2: \"There is only one type of Start Event for "
       "Sub-Processes in BPMN (…): None.\")", "§10.4.2",
       when="triggered-start-in-sub-level",
       hint="remove its event definition and wait for the timer or message in an "
            "intermediate catch event after it, or make the sub-process an event "
            "sub-process (triggeredByEvent=\"true\")"),
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
