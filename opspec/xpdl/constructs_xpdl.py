"""The construct registry's entries for XPDL 2.1 (WfMC-TC-1025, 2008) and 2.2: for every
element and attribute that has execution semantics, whether opspec RUNS it as the standard
says, WARNS (it runs differently: the text says what opspec does instead) or REFUSES it, with
the section of XPDL 2.1 that defines it.

Entries are keyed by local name: they hold for every XPDL namespace (1.0, 2.0, 2.1, 2.2, none).
What XPDL defines without execution semantics is in :mod:`opspec.xpdl.constructs_inert`; how
an entry is read is said in :mod:`opspec.xpdl.constructs`.
"""

from __future__ import annotations

from opspec.xpdl.construct_entry import XPDL, Construct, Kind
from opspec.xpdl.construct_entry import entry as _c

__all__ = ["XPDL_CONSTRUCTS"]

R, W, X = Kind.RUNS, Kind.WARNS, Kind.REFUSES

XPDL_CONSTRUCTS: tuple[Construct, ...] = (
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
    _c("xpdl-start-activity", XPDL, "Activity", "StartActivity", R,
       "where every activity of the level has an incoming transition (a cycle, no start "
       "event), instances start at the activities marked true (\"Used when there is no other "
       "way to determine this\")", "§7.6 (Activity, StartActivity)"),
    _c("xpdl-start-activity-overruled", XPDL, "Activity", "StartActivity", W,
       "ignored: instances start at the level's activities without incoming transitions, "
       "not at this one, which has an incoming transition (XPDL designates it \"the first "
       "activity to be executed\" but uses it only \"when there is no other way to determine "
       "this\")", "§7.6 (Activity, StartActivity)",
       when="start-activity-overruled",
       hint="remove the incoming transitions of the activities the process does not start "
       "at, or remove StartActivity"),
    _c("xpdl-quantities", XPDL, "Activity", "StartQuantity", R,
       "the activity waits for StartQuantity tokens (thread merge, WCP-41)", "§7.6",
       when="not-one"),
    _c("xpdl-completion-quantity", XPDL, "Activity", "CompletionQuantity", R,
       "CompletionQuantity tokens leave on each outgoing transition (thread split, WCP-42)",
       "§7.6", when="not-one"),
    _c("xpdl-unstarted-activity", XPDL, "Activity", None, W,
       "no transition leads to it, and the process's instances start at start events with "
       "a trigger, each running only its own path: it never runs in those instances, only "
       "in one started without a trigger (beside a StartEvent with Trigger None, called as "
       "a subflow, or from the API); opspec check reports it dead when no such instance "
       "runs (BPMN 2.0 §10.4.2, which XPDL 2.1's events follow: \"All Flow Objects that do "
       "not have an incoming Sequence Flow (i.e., are not a target of a Sequence Flow) SHALL "
       "be instantiated when the Process is instantiated\")", "§7.6.2; BPMN §10.4.2",
       when="unstarted-beside-triggered-start",
       hint="add a transition to it from the activity after which it should run, or remove "
            "it"),
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
    _c("xpdl-activity-set-start-trigger", XPDL, "StartEvent", None, W,
       "its trigger is ignored: it starts with its activity set, at once, as a StartEvent "
       "with Trigger None does (BPMN 2.0 §10.4.2, which XPDL 2.1's events follow: \"There "
       "is only one type of Start Event for Sub-Processes in BPMN (…): "
       "None.\")", "§7.6.2; BPMN §10.4.2", when="triggered-start-in-sub-level",
       hint="give it Trigger=\"None\" and wait for the timer or message in an "
            "IntermediateEvent after it"),
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
    _c("xpdl-duration-unit", XPDL, "DeadlineDuration DeadlineCondition TimeCycle", None, W,
       "a bare number is read as seconds, not in the unit the process header's DurationUnit "
       "names (XPDL applies it to \"an integer duration value that has no unit tag\")",
       "Process Header (DurationUnit), §7.6.8", when="unitless-in-other-unit",
       hint="write the unit with the number (PT2H, 2 h, 120 min)"),
    _c("xpdl-duration-unit-attr", XPDL, "TriggerTimer", "TimeCycle", W,
       "a bare number is read as seconds, not in the unit the process header's DurationUnit "
       "names (XPDL applies it to \"an integer duration value that has no unit tag\")",
       "Process Header (DurationUnit), §7.6.2", when="unitless-in-other-unit",
       hint="write the unit with the number (PT2H, 2 h, 120 min)"),
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
