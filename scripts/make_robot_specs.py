"""Write the behaviour-based robot specs (specs/vacuum_cleaner.xpdl, specs/toy_sumo.xpdl,
specs/medication_cart_guidance.xpdl) from one shared shape, as the source design's Figures 2
and 7 share theirs: periodic sense / avoid / wander / manoeuvre / arbitrate workflows, a
fixed-priority arbiter choosing the motor command, range data passed through the supervisor
(push/pull), and a battery mode change. The vacuum cleaner and the toy sumo differ only in the
manoeuvre graph (back up and move randomly vs. move back and hit) and in their header, world
and metrics; the cart adds patient identification (RFID + bar code) instead of a manoeuvre.

    python scripts/make_robot_specs.py        # rewrites the three files

The generated files are ordinary SISARL-XPDL, meant to be read and edited; rerun this script
after changing the shared shape so the three stay consistent.
"""

from __future__ import annotations

import re
from pathlib import Path

SPECS = Path(__file__).resolve().parents[1] / "specs"


def field(fid: str, kind: str, initial: str) -> str:
    return (f'    <DataField Id="{fid}"><DataType><BasicType Type="{kind}"/></DataType>'
            f'<InitialValue>{initial}</InitialValue></DataField>')


def attrs(**values: str) -> str:
    items = "".join(f'<ExtendedAttribute Name="opspec:{k}" Value="{v}"/>'
                    for k, v in values.items())
    return f"<ExtendedAttributes>{items}</ExtendedAttributes>"


def start(aid: str = "start") -> str:
    return f'      <Activity Id="{aid}"><Event><StartEvent Trigger="None"/></Event></Activity>'


def end(aid: str = "end") -> str:
    return f'      <Activity Id="{aid}"><Event><EndEvent Result="None"/></Event></Activity>'


def task(aid: str, app: str, name: str, cpu: str = "2ms") -> str:
    return (f'      <Activity Id="{aid}" Name="{name}"><Implementation><Task><TaskApplication '
            f'Id="{app}"/></Task></Implementation><Performers><Performer>{app_owner(app)}'
            f'</Performer></Performers>{attrs(CpuDemand=cpu)}</Activity>')


def app_owner(app: str) -> str:
    return {"read_range": "range_finder", "read_bump": "bumper", "drive": "motors",
            "read_battery": "battery", "read_rfid": "rfid_reader",
            "scan_barcode": "barcode_scanner"}[app]


def assign(aid: str, name: str, *pairs: tuple[str, str], when: str = "End",
           duration: str | None = None, join: bool = False) -> str:
    body = "".join(f'<Assignment AssignTime="{when}"><Target>{t}</Target><Expression>{e}'
                   f'</Expression></Assignment>' for t, e in pairs)
    extra = attrs(Duration=f"ConstantParameter({duration})") if duration else ""
    restr = ('<TransitionRestrictions><TransitionRestriction><Join Type="Exclusive"/>'
             '</TransitionRestriction></TransitionRestrictions>') if join else ""
    return (f'      <Activity Id="{aid}" Name="{name}"><Implementation><No/></Implementation>'
            f'{restr}{extra}<Assignments>{body}</Assignments></Activity>')


def route(aid: str, name: str, *, join: bool = False) -> str:
    kind = "Join" if join else "Split"
    return (f'      <Activity Id="{aid}" Name="{name}"><Route GatewayType="Exclusive"/>'
            f'<TransitionRestrictions><TransitionRestriction><{kind} Type="Exclusive"/>'
            f'</TransitionRestriction></TransitionRestrictions></Activity>')


def builtin(aid: str, name: str, xml: str) -> str:
    return (f'      <Activity Id="{aid}" Name="{name}"><Implementation><No/></Implementation>'
            f'<ExtendedAttributes><ExtendedAttribute Name="opspec:BuiltIn">{xml}'
            f'</ExtendedAttribute></ExtendedAttributes></Activity>')


def tr(tid: str, frm: str, to: str, cond: str | None = None) -> str:
    if cond is None:
        body = ""
    elif cond == "OTHERWISE":
        body = '<Condition Type="OTHERWISE"/>'
    else:
        body = f'<Condition Type="CONDITION"><Expression>{cond}</Expression></Condition>'
    return f'      <Transition Id="{tid}" From="{frm}" To="{to}">{body}</Transition>'


def process(pid: str, name: str, activities: list[str], transitions: list[str], *,
            rate: str | None = None, period: str | None = None, priority: int,
            mode: str | None = None, data: list[str] = (), auto_start: bool = False,
            deadline: str | None = None) -> str:
    directives = {"Lane": "device", "Priority": str(priority)}
    if deadline:
        directives["Deadline"] = deadline
    if rate:
        directives["Rate"] = rate
    if period:
        directives["Period"] = period
    if mode:
        directives["Mode"] = mode
    if auto_start:
        directives["AutoStart"] = "true"
    fields = f"\n  <DataFields>\n{chr(10).join(data)}\n  </DataFields>" if data else ""
    # XPDL 2.1 wants activity ids unique in the whole package: prefix the generic ones
    generic = ("start", "end", "merge", "drive")
    pattern = re.compile(r'(Activity Id|From|To)="(' + "|".join(generic) + ')"')
    activities = [pattern.sub(lambda m: f'{m[1]}="{pid}_{m[2]}"', a) for a in activities]
    transitions = [pattern.sub(lambda m: f'{m[1]}="{pid}_{m[2]}"', t) for t in transitions]
    return (f'    <WorkflowProcess Id="{pid}" Name="{name}">\n      <ProcessHeader/>{fields}\n'
            f'      <Activities>\n{chr(10).join(activities)}\n      </Activities>\n'
            f'      <Transitions>\n{chr(10).join(transitions)}\n      </Transitions>\n'
            f'      {attrs(**directives)}\n    </WorkflowProcess>')


# ----------------------------------------------------------------------------- shared shape

def sense() -> str:
    return process("sense", "Sense: range finder and bumper", [
        start(), task("read_range", "read_range", "Read the range finder"),
        task("read_bump", "read_bump", "Read the bumper", cpu="1ms"),
        builtin("push_range", "Push the range to the supervisor",
                '<opspec:PushData Channel="range" Ref="distance"/>'), end()], [
        tr("s1", "start", "read_range"), tr("s2", "read_range", "read_bump"),
        tr("s3", "read_bump", "push_range"), tr("s4", "push_range", "end")],
        rate="5Hz", priority=3, mode="run", deadline="50ms")


def avoid() -> str:
    return process("avoid", "Avoid obstacles", [
        start(), builtin("pull_range", "Pull the range from the supervisor",
                         '<opspec:PullData Channel="range" Ref="seen"/>'),
        route("near", "Obstacle near?"),
        assign("turn_away", "Turn away", ("avoid_cmd", '"turn_left"')),
        assign("clear", "Nothing near", ("avoid_cmd", '""')),
        route("merge", "Merge", join=True), end()], [
        tr("a1", "start", "pull_range"), tr("a2", "pull_range", "near"),
        tr("a3", "near", "turn_away", "seen &lt; 0.35"), tr("a4", "near", "clear", "OTHERWISE"),
        tr("a5", "turn_away", "merge"), tr("a6", "clear", "merge"), tr("a7", "merge", "end")],
        rate="5Hz", priority=2, mode="run", deadline="100ms",
        data=[field("seen", "FLOAT", "10.0")])


def wander(stop_when_found: bool = False) -> str:
    if not stop_when_found:
        return process("wander", "Wander", [
            start(), assign("cruise", "Cruise forward", ("wander_cmd", '"forward"')), end()], [
            tr("w1", "start", "cruise"), tr("w2", "cruise", "end")],
            rate="1Hz", priority=1, mode="run")
    return process("wander", "Wander until the patient is found", [
        start(), route("done_yet", "Patient found?"),
        assign("cruise", "Cruise forward", ("wander_cmd", '"forward"')),
        assign("halt", "Stay with the patient", ("wander_cmd", '"stop"'),
               ("avoid_cmd", '""')),
        route("merge", "Merge", join=True), end()], [
        tr("w1", "start", "done_yet"), tr("w2", "done_yet", "halt", "found == true"),
        tr("w3", "done_yet", "cruise", "OTHERWISE"), tr("w4", "cruise", "merge"),
        tr("w5", "halt", "merge"), tr("w6", "merge", "end")],
        rate="1Hz", priority=1, mode="run")


def manoeuvre(kind: str) -> str:
    """The one graph in which the vacuum cleaner and the toy sumo differ."""
    if kind == "vacuum":
        steps = [assign("back_up", "Back up", ("escape_cmd", '"back"'), when="Start",
                        duration="0.6"),
                 assign("random_move", "Turn to a random heading",
                        ("escape_cmd", '"turn_random"'), when="Start", duration="0.2")]
        chain = [tr("m4", "back_up", "random_move"), tr("m5", "random_move", "done")]
        first = "back_up"
        data = []
    else:
        # after moving back, two sensors vote on how to hit: the range finder (charge if
        # something is near ahead, else it abstains) and the line sensor (turn if on the
        # ring's rim, else charge). Off the rim the sumo charges; on the rim with something
        # near ahead (the opponent, or the edge itself: the range finder cannot tell) the
        # votes tie and the tie goes to the option listed first, turn_random: in doubt, the
        # sumo does not charge out of the ring
        steps = [assign("move_back", "Move back", ("escape_cmd", '"back"'), when="Start",
                        duration="0.4"),
                 route("opponent_ahead", "Opponent ahead?"),
                 assign("range_says_charge", "Range votes: charge", ("vote_range", '"charge"')),
                 assign("range_abstains", "Range abstains", ("vote_range", '""')),
                 route("range_voted", "Range voted", join=True),
                 route("on_rim", "On the ring's rim?"),
                 assign("line_says_turn", "Line sensor votes: turn",
                        ("vote_edge", '"turn_random"')),
                 assign("line_says_charge", "Line sensor votes: charge",
                        ("vote_edge", '"charge"')),
                 route("line_voted", "Line sensor voted", join=True),
                 builtin("choose_hit", "Vote on the hit",
                         '<opspec:Voter Output="hit_cmd" Options="turn_random charge">'
                         '<opspec:Input Ref="vote_range"/>'
                         '<opspec:Input Ref="vote_edge"/></opspec:Voter>'),
                 assign("hit", "Hit: charge forward (or turn away)", ("escape_cmd", "hit_cmd"),
                        when="Start", duration="1.0")]
        chain = [tr("m4", "move_back", "opponent_ahead"),
                 tr("v1", "opponent_ahead", "range_says_charge", "distance &lt; 0.6"),
                 tr("v2", "opponent_ahead", "range_abstains", "OTHERWISE"),
                 tr("v3", "range_says_charge", "range_voted"),
                 tr("v4", "range_abstains", "range_voted"), tr("v5", "range_voted", "on_rim"),
                 tr("v6", "on_rim", "line_says_turn", "edge == true"),
                 tr("v7", "on_rim", "line_says_charge", "OTHERWISE"),
                 tr("v8", "line_says_turn", "line_voted"),
                 tr("v9", "line_says_charge", "line_voted"),
                 tr("v10", "line_voted", "choose_hit"), tr("v11", "choose_hit", "hit"),
                 tr("m5", "hit", "done")]
        first = "move_back"
        data = [field("vote_range", "STRING", '""'), field("vote_edge", "STRING", '""'),
                field("hit_cmd", "STRING", '"charge"')]
    return process("manoeuvre", "Manoeuvre on contact", [
        start(), route("contact", "Bumped?"),
        assign("engage", "Start the manoeuvre", ("escaping", "true")), *steps,
        assign("done", "Manoeuvre done", ("escape_cmd", '""'), ("escaping", "false")),
        assign("calm", "No contact", ("escape_cmd", '""')),
        route("merge", "Merge", join=True), end()], [
        tr("m1", "start", "contact"),
        tr("m2", "contact", "engage", "bump == true &amp;&amp; escaping == false"),
        tr("m2b", "contact", "merge", "escaping == true"),
        tr("m3", "contact", "calm", "OTHERWISE"), tr("m3b", "engage", first), *chain,
        tr("m6", "done", "merge"), tr("m7", "calm", "merge"), tr("m8", "merge", "end")],
        rate="5Hz", priority=4, mode="run", data=data)


def arbitrate() -> str:
    return process("arbitrate", "Arbitrate and drive", [
        start(), builtin("arbiter", "Fixed-priority arbiter",
                         '<opspec:Arbiter Output="motor_cmd"><opspec:Input Ref="escape_cmd"/>'
                         '<opspec:Input Ref="avoid_cmd"/><opspec:Input Ref="wander_cmd"/>'
                         '</opspec:Arbiter>'),
        task("drive", "drive", "Drive the motors"), end()], [
        tr("d1", "start", "arbiter"), tr("d2", "arbiter", "drive"), tr("d3", "drive", "end")],
        rate="5Hz", priority=5, mode="run", deadline="50ms",
        data=[field("motor_cmd", "STRING", '"stop"')])


def battery() -> str:
    return process("battery", "Battery watch", [
        start(), task("read_battery", "read_battery", "Read the battery", cpu="1ms"),
        route("low", "Battery low?"),
        builtin("go_dock", "Change mode: dock", '<opspec:ModeChange To="dock"/>'),
        route("merge", "Merge", join=True), end()], [
        tr("b1", "start", "read_battery"), tr("b2", "read_battery", "low"),
        tr("b3", "low", "go_dock", "level &lt; 20"), tr("b4", "low", "merge", "OTHERWISE"),
        tr("b5", "go_dock", "merge"), tr("b6", "merge", "end")],
        period="10", priority=2, mode="run")


def dock() -> str:
    return process("dock", "Dock: stop and wait", [
        start(), assign("park", "Park", ("motor_cmd", '"stop"')),
        task("drive", "drive", "Drive the motors"), end()], [
        tr("k1", "start", "park"), tr("k2", "park", "drive"), tr("k3", "drive", "end")],
        rate="1Hz", priority=5, mode="dock", data=[field("motor_cmd", "STRING", '"stop"')])


def identify() -> str:
    return process("identify", "Identify the patient (RFID, bar code)", [
        start(), task("read_rfid", "read_rfid", "Read RFID tags in range"),
        route("tag_seen", "Tag in range?"),
        task("scan", "scan_barcode", "Scan the wristband bar code"),
        route("matches", "Bar code matches the tag?"),
        ('      <Activity Id="confirm" Name="Patient found"><Implementation><No/>'
         '</Implementation><ExtendedAttributes><ExtendedAttribute Name="opspec:Raises" '
         'Value="message:patient_found"/></ExtendedAttributes><Assignments><Assignment '
         'AssignTime="End"><Target>found</Target><Expression>true</Expression></Assignment>'
         '</Assignments></Activity>'),
        route("merge", "Merge", join=True), end()], [
        tr("i1", "start", "read_rfid"), tr("i2", "read_rfid", "tag_seen"),
        tr("i3", "tag_seen", "scan", 'tag != "" &amp;&amp; found == false'),
        tr("i4", "tag_seen", "merge", "OTHERWISE"), tr("i5", "scan", "matches"),
        tr("i6", "matches", "confirm", "patient_id == tag"),
        tr("i7", "matches", "merge", "OTHERWISE"), tr("i8", "confirm", "merge"),
        tr("i9", "merge", "end")],
        rate="2Hz", priority=3, mode="run")


def mission() -> str:
    confirm = ('<Activity Id="wait_found" Name="Wait until the patient is found"><Event>'
               '<IntermediateEvent Trigger="Message"><TriggerResultMessage CatchThrow="CATCH">'
               '<Message Id="msg_found" Name="patient_found"/></TriggerResultMessage>'
               '</IntermediateEvent></Event></Activity>')
    return process("mission", "Mission: find the patient", [
        start(), f"      {confirm}", end()], [
        tr("x1", "start", "wait_found"), tr("x2", "wait_found", "end")],
        priority=1, auto_start=True, mode="run")


APPLICATIONS = {
    "read_range": "Range finder: distance ahead (m)",
    "read_bump": "Bumper: contact since the last read; line sensor: on the ring's rim",
    "drive": "Motors: execute motor_cmd",
    "read_battery": "Battery level (%)",
    "read_rfid": "RFID reader: tag in range",
    "scan_barcode": "Bar-code scanner: wristband id",
}


def package(pid: str, name: str, description: str, world: str, processes: list[str],
            metrics: str, apps: list[str], fields: list[str], run_length: str,
            modes: bool = True) -> str:
    participants = sorted({app_owner(a) for a in apps})
    parts = "\n".join(f'    <Participant Id="{p}" Name="{p.replace("_", " ")}">'
                      f'<ParticipantType Type="SYSTEM"/></Participant>' for p in participants)
    applications = "\n".join(f'    <Application Id="{a}" Name="{APPLICATIONS[a]}"/>'
                             for a in apps)
    mode_xml = ('\n    <ExtendedAttribute Name="opspec:Modes"><opspec:Mode Id="run" '
                'Initial="true"/><opspec:Mode Id="dock"/></ExtendedAttribute>') if modes else ""
    body = "\n".join(processes)
    data = "\n".join(fields)
    return f'''<?xml version="1.0" encoding="UTF-8"?>
<!--
  {description}
  Generated by scripts/make_robot_specs.py from the shape the behaviour-based specs share;
  SISARL-XPDL directives are ExtendedAttributes named opspec:... (docs/sisarl-xpdl.md,
  docs/behaviour-specs.md). The world the simulated devices live in: opspec:World below.
-->
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" xmlns:opspec="urn:opspec:sisarl:1"
         Id="{pid}" Name="{name}">
  <PackageHeader>
    <XPDLVersion>2.1</XPDLVersion>
    <Vendor>opspec</Vendor>
    <Created>2026-11-23</Created>
  </PackageHeader>
  <ConformanceClass GraphConformance="NON_BLOCKED"/>
  <Participants>
{parts}
  </Participants>
  <Applications>
{applications}
  </Applications>
  <DataFields>
{data}
  </DataFields>
  <WorkflowProcesses>
{body}
  </WorkflowProcesses>
  <ExtendedAttributes>
    <ExtendedAttribute Name="opspec:World" Value="{world}"/>
    <ExtendedAttribute Name="opspec:WorldFile" Value="{pid}.world.toml"/>
    <ExtendedAttribute Name="opspec:RunLength" Value="{run_length}"/>{mode_xml}
    <ExtendedAttribute Name="opspec:Metrics">
{metrics}
    </ExtendedAttribute>
  </ExtendedAttributes>
</Package>
'''


ROBOT_FIELDS = [field("distance", "FLOAT", "10.0"), field("bump", "BOOLEAN", "false"),
                field("edge", "BOOLEAN", "false"),
                field("level", "FLOAT", "100.0"), field("escaping", "BOOLEAN", "false"),
                field("escape_cmd", "STRING", '""'), field("avoid_cmd", "STRING", '""'),
                field("wander_cmd", "STRING", '"forward"')]
ROBOT_APPS = ["read_range", "read_bump", "drive", "read_battery"]


def count(name: str, event: str, process: str | None = None, activity: str | None = None
          ) -> str:
    where = (f' Process="{process}"' if process else "") + (
        f' Activity="{activity}"' if activity else "")
    return f'      <opspec:Count Name="{name}" Event="{event}"{where}/>'


def main() -> None:
    shared = [sense(), avoid(), wander(), arbitrate(), battery(), dock()]
    vacuum = package(
        "vacuum_cleaner", "Automatic vacuum cleaner",
        "The automatic vacuum cleaner (EMWF TR-IIS-08-005, Figure 7): wander, avoid obstacles "
        "and, on contact,\n  back up and move randomly; docks when the battery runs low.",
        "vacuum-room", shared[:3] + [manoeuvre("vacuum")] + shared[3:], "\n".join([
            count("cells_covered", "world.covered"), count("collisions", "world.collision"),
            count("manoeuvres", "activity.completed", "manoeuvre", "back_up"),
            count("dockings", "mode.changed")]), ROBOT_APPS, ROBOT_FIELDS,
        # one cleaning run: the battery reaches 20 % at about 67 min, then the robot docks
        run_length="PT75M")
    sumo = package(
        "toy_sumo", "Toy sumo robot",
        "The toy sumo (EMWF TR-IIS-08-005, section 6): the vacuum cleaner's graph with a "
        "move-back-and-hit\n  manoeuvre instead of back-up-and-random-move, in a ring against "
        "an opponent.",
        "sumo-ring", shared[:3] + [manoeuvre("sumo")] + shared[3:], "\n".join([
            count("bouts", "world.bout"), count("bouts_won", "world.bout_won"),
            count("bouts_lost", "world.bout_lost"), count("collisions", "world.collision"),
            count("manoeuvres", "activity.completed", "manoeuvre", "move_back"),
            count("dockings", "mode.changed"),
            '      <opspec:Ratio Name="win_rate" Numerator="bouts_won" Denominator="bouts" Proportion="true"/>']),
        # a tournament of bouts (60 s at most each), over before the battery asks to dock
        ROBOT_APPS, ROBOT_FIELDS, run_length="PT30M")
    cart_fields = [*ROBOT_FIELDS, field("tag", "STRING", '""'),
                   field("patient_id", "STRING", '""'), field("found", "BOOLEAN", "false")]
    cart = package(
        "medication_cart_guidance", "Intelligent medication cart: guidance and propulsion",
        "The intelligent medication cart, guidance and propulsion (EMWF TR-IIS-08-005, "
        "Figure 2): periodic\n  workflows drive the cart down the ward, avoiding obstacles, "
        "until its RFID reader and bar-code\n  scanner identify the patient.",
        "ward", [sense(), avoid(), wander(stop_when_found=True), manoeuvre("vacuum"),
                 identify(), arbitrate(), mission()], "\n".join([
            count("patients_found", "activity.completed", "identify", "confirm"),
            count("collisions", "world.collision"),
            count("cells_covered", "world.covered"),
            ('      <opspec:Duration Name="time_to_find_s" Unit="s">'
            '<opspec:From Event="process.started" Process="mission"/>'
            '<opspec:To Event="activity.completed" Process="mission" Activity="wait_found"/>'
            '</opspec:Duration>')]),
        [*ROBOT_APPS[:3], "read_rfid", "scan_barcode"], cart_fields,
        # one round down the ward: the patient is usually found within two minutes
        run_length="PT10M", modes=False)
    cart = cart.replace('<ExtendedAttribute Name="opspec:Mode" Value="run"/>', "")
    for name, text in (("vacuum_cleaner", vacuum), ("toy_sumo", sumo),
                       ("medication_cart_guidance", cart)):
        (SPECS / f"{name}.xpdl").write_text(text, encoding="utf-8")
        print(f"wrote specs/{name}.xpdl")


if __name__ == "__main__":
    main()
