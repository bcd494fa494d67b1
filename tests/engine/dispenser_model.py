"""The medication dispenser of SCENARIO.md built in plain Python, with the ids of
``specs/medication_dispenser.xpdl`` (processes, activities, participants, metrics)."""

from __future__ import annotations

from builders import (
    act,
    app,
    catch,
    count,
    deadline,
    duration,
    end_event,
    field,
    formal,
    manual,
    pkg,
    proc,
    ratio,
    route,
    start_event,
    subflow,
    task,
)

from opspec.model import Package

DOSES = (8 * 3600.0, 12 * 3600.0, 18 * 3600.0, 22 * 3600.0)


def dispenser_package() -> Package:
    timer = proc(
        "timer_workflow",
        acts=[start_event("tick"), subflow("start_notify", "notify_workflow", ["hour()"],
                                           asynchronous=True, performer="clock"),
              end_event("timer_done")],
        trans=[("tick", "start_notify"), ("start_notify", "timer_done")],
        start="timer:" + ",".join(f"{t:g}" for t in DOSES), lane="device")
    schedule = proc(
        "schedule_workflow",
        acts=[route("lookup", split="XOR", performer="sched"),
              act("dose_morning", assign=[("dose", '"morning"')], performer="sched"),
              act("dose_noon", assign=[("dose", '"noon"')], performer="sched"),
              act("dose_evening", assign=[("dose", '"evening"')], performer="sched"),
              act("dose_night", assign=[("dose", '"night"')], performer="sched"),
              route("merge", join="XOR", performer="sched"), end_event("schedule_done")],
        trans=[("lookup", "dose_morning", "hour < 10"), ("lookup", "dose_noon", "hour < 15"),
               ("lookup", "dose_evening", "hour < 20"), ("lookup", "dose_night", "otherwise"),
               ("dose_morning", "merge"), ("dose_noon", "merge"), ("dose_evening", "merge"),
               ("dose_night", "merge"), ("merge", "schedule_done")],
        formals=[formal("hour", "IN"), formal("dose", "OUT")], lane="device")
    notify = proc(
        "notify_workflow",
        acts=[start_event("notify_start"),
              subflow("schedule", "schedule_workflow", ["hour", "dose"], performer="sched"),
              task("sound_alarm", "alarm_on", ["dose"], join="XOR", performer="alarm",
                   raises="message:trg_2", assign=[("alarms", "alarms + 1")], line=180),
              catch("wait_report", "message", "trg_1", performer="dispenser",
                    deadlines=[deadline(300, "no_report")]),
              route("R", split="XOR", performer="alarm"),
              task("dispense", "dispense", ["dose"], performer="dispenser"),
              act("record_taken", assign=[("outcome", '"taken"')], performer="dispenser"),
              act("record_missed", assign=[("outcome", '"missed"')], performer="dispenser"),
              task("notify_caregiver", "notify_caregiver", ["dose"], performer="dispenser"),
              end_event("end_taken"), end_event("end_missed")],
        trans=[("notify_start", "schedule"), ("schedule", "sound_alarm"),
               ("sound_alarm", "wait_report"), ("wait_report", "dispense"),
               ("wait_report", "R", "exception:no_report"),
               ("R", "sound_alarm", "alarms < 3"), ("R", "record_missed", "otherwise"),
               ("dispense", "record_taken"), ("record_taken", "end_taken"),
               ("record_missed", "notify_caregiver"), ("notify_caregiver", "end_missed")],
        formals=[formal("hour", "IN")],
        data=[field("alarms", 0), field("dose", ""), field("outcome", "pending")],
        lane="device", priority=2)
    user = proc(
        "user_workflow",
        acts=[start_event("alarm_heard", "message", "trg_2"),
              manual("hear_alarm"), manual("walk_to_dispenser"),
              route("choose_button", "EVENT", join="XOR", performer="user"),
              manual("press_report", raises="message:trg_1"), manual("press_wrong_button"),
              manual("take_pill"), end_event("user_done")],
        trans=[("alarm_heard", "hear_alarm"), ("hear_alarm", "walk_to_dispenser"),
               ("walk_to_dispenser", "choose_button"), ("choose_button", "press_report"),
               ("choose_button", "press_wrong_button"),
               ("press_wrong_button", "choose_button"), ("press_report", "take_pill"),
               ("take_pill", "user_done")],
        lane="user")
    metrics = [
        count("doses_due", "process.started", "notify_workflow"),
        count("doses_taken", "activity.completed", "notify_workflow", "record_taken"),
        count("doses_missed", "activity.completed", "notify_workflow", "record_missed"),
        count("caregiver_notified", "activity.completed", "notify_workflow",
              "notify_caregiver"),
        count("alarms", "activity.completed", "notify_workflow", "sound_alarm"),
        duration("report_latency_s", ("activity.started", "notify_workflow", "sound_alarm"),
                 ("activity.completed", "notify_workflow", "wait_report")),
        ratio("alarms_per_dose", "alarms", "doses_due"),
    ]
    return pkg(timer, schedule, notify, user, metrics=metrics,
               participants=[("user", "HUMAN"), ("caregiver", "HUMAN"), ("clock", "SYSTEM"),
                             ("sched", "SYSTEM"), ("alarm", "SYSTEM"),
                             ("dispenser", "SYSTEM")],
               applications=[app("alarm_on", ("dose", "IN")), app("dispense", ("dose", "IN")),
                             app("notify_caregiver", ("dose", "IN"))])
