"""Perform a spec's user lane yourself in a terminal UI.

Run SPEC's device workflows on a simulated clock while you perform the user lane: see what the
device does, act with one key, control time, hand your lane to a user model and back. Press ?
in the app for the keys (docs/walkthrough.md).

The recording (a script opspec run --script replays) is written as the session goes, with the
trace beside it; quitting prints the summary (the spec's metrics, the person's response
times), where both files are, and the commands that replay the recording.
"""
from __future__ import annotations

import argparse
import contextlib
import re
import sys
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from opspec.commands import _args
from opspec.errors import ConfigurationError

# the choices, without importing Textual for `opspec --help`
ON_CALL = ("realtime", "pause", "keep")
SOUNDS = ("bell", "system", "off")

__all__ = ["register", "run"]


def _person(text: str) -> str:
    """A participant identifier as --person takes it: printable, on one line."""
    person = text.strip()
    if not person or not person.isprintable():
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a participant identifier: give printable text on one line, "
            "e.g. --person P07")
    return person


def _file_safe(person: str) -> str:
    """The identifier as part of a file name (anything but letters, digits, - and _ is _)."""
    return re.sub(r"[^A-Za-z0-9_-]", "_", person)


def register(subparsers: Any) -> None:
    parser = _args.command(subparsers, "walkthrough", __doc__)
    _args.add_spec(parser)
    parser.add_argument("--speed", type=float, default=None,
                        help="simulated seconds per wall second at start (default 60; 1 "
                        "with a real device bound)")
    # not given (None) is not 0: a replay runs the recorded session's seed instead
    parser.add_argument("--seed", type=_args.seed, default=None,
                        help="run seed: the run of opspec run --seed (default 0; with "
                        "--replay, the recorded session's)")
    length = parser.add_mutually_exclusive_group()
    _args.add_days(length)
    length.add_argument("--until", metavar="T",
                        help="simulated end time: seconds, or a duration (12h30m, PT8H); "
                        "with --replay the default is where the recorded session ended")
    _args.add_user_model(parser, role="what performs your lane when you hand it over: ")
    parser.add_argument("--record", metavar="FILE",
                        help="where to write the recording (default "
                        "walkthroughs/<spec>-<date-time>.json)")
    parser.add_argument("--no-record", action="store_true", help="do not record")
    parser.add_argument("--replay", metavar="FILE",
                        help="replay a recording (or any script) instead of performing")
    _args.add_device_options(parser)
    lab = parser.add_argument_group("for a lab session")
    lab.add_argument("--on-call", choices=ON_CALL, default="realtime",
                     help="what the clock does when the device calls you (an alarm, an "
                     "offer): drop to real time until the call is over (default), pause, or "
                     "keep its speed")
    lab.add_argument("--person", metavar="ID", type=_person,
                     help="the participant's identifier (e.g. P07): written into the "
                     "recording's trace and its file name, so that opspec fit counts "
                     "several sessions of one participant as one person")
    lab.add_argument("--large", action="store_true",
                     help="a layout for a big terminal font: your panel first and full "
                     "width, tall buttons, the clock in big digits (enlarge the terminal's "
                     "font too)")
    lab.add_argument("--high-contrast", action="store_true",
                     help="white and yellow on black, heavy borders, nothing dimmed")
    lab.add_argument("--sound", choices=SOUNDS, default="bell",
                     help="the cue at every alarm: the terminal bell (default), a system "
                     "sound as well (pw-play, paplay, aplay or afplay), or none")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from opspec.request import RunRequest, prepare
    from opspec.run_rules import check_days, parse_until

    if args.speed is not None and not (args.speed > 0):
        raise ConfigurationError(f"--speed must be positive, not {args.speed:g}")
    if args.days is not None:
        check_days(args.days, name="--days")
    until = None if args.until is None else parse_until(args.until, name="--until")
    if args.replay and args.record:
        # a replay records nothing: the recording asked for would silently not be written
        raise ConfigurationError(
            f"--record {args.record} with --replay: a replay records nothing",
            hint=f"its trace: opspec run {args.spec} --script {args.replay} --trace FILE")
    if args.no_record and args.record:
        # one says where to record, the other not to: the recording asked for would
        # silently not be written
        raise ConfigurationError(f"--record {args.record} with --no-record: the session "
                                 "cannot be recorded and not recorded",
                                 hint="leave out one of them")
    seed, seed_note = _seed(args)
    # the person performs the lane; the request's user is the model they hand it over to
    # (--user-model, else the companion SPEC.users.toml), checked against the spec
    prepared = prepare(RunRequest(args.spec, seed=seed, days=args.days, until=until,
                                  user_model=args.user_model))   # a broken spec opens nothing
    # validate's warnings (what runs differently) are shown as notes on the screen
    spec_warnings: list[str] = [str(w) for w in prepared.warnings]
    if seed_note is not None:
        print(f"opspec walkthrough: {seed_note}", file=sys.stderr)
        spec_warnings.append(seed_note)
    package, compiled = prepared.package, prepared.compiled
    model = prepared.user.source if prepared.user.kind == "model" else None
    factory = _model_factory(model, prepared.seed) if model is not None else None
    model_ref = prepared.user_model          # its file, if it came from one
    replay = None
    if args.replay:
        from opspec.tui.replay import load_recording

        # checked against the spec like `opspec run --script` (a misspelt name would never
        # match an offer)
        replay = load_recording(args.replay, compiled)
        if args.days is None and until is None:
            from opspec.tui.replay import refuse_nothing_to_replay

            # the replay ends where the session did (the person quit at 12:34: not the rest
            # of the day without them), as the recording's trace says
            until = refuse_nothing_to_replay(args.replay, "--replay")
    who = f"{_file_safe(args.person)}-" if args.person else ""
    record = None if args.no_record or args.replay else Path(
        args.record or Path("walkthroughs") / (
            f"{Path(args.spec).name.split('.')[0]}-{who}"
            f"{datetime.now(UTC).strftime('%Y%m%d-%H%M%S')}.json"))
    if record is not None:
        from opspec.commands._files import refuse_overwrite, spec_inputs

        # the recording and its trace beside it (tui.session) may not replace an input
        refuse_overwrite([
            ("--record", record), ("--record's trace", record.with_suffix(".trace.jsonl"))], [
            ("SPEC", args.spec),
            ("the user model", model_ref if model_ref and Path(model_ref).exists() else None),
            *spec_inputs(args.spec, package)])
    # Textual would wait for keys that never come (< /dev/null, a pipe): refused below,
    # once the spec is known to start (its own error first), with nothing recorded and no
    # device opened (opening a serial port may reset the board behind it)
    terminal = sys.stdin.isatty() and sys.stdout.isatty()
    if not terminal:                            # an option's own error comes first
        if args.record and record is not None:
            _check_record_folder(record)
        if args.bind:
            from opspec.bindings.profiles import default_profiles_dir, load_profiles

            # the profiles are read (a broken one is said), no port is opened
            load_profiles(args.devices if args.devices else default_profiles_dir())
    with contextlib.ExitStack() as stack:
        performers: dict[str, Any] = {}          # the world: opspec.runs.build adds it
        notes: list[str] = list(spec_warnings)
        devices = None
        if args.bind and terminal:
            from opspec.bindings.attach import attach_devices

            devices = stack.enter_context(attach_devices(args.bind, args.devices,
                                                         spec=compiled))
            performers.update(devices.performers)
            notes.extend(devices.notes)
        from opspec.tui.app import WalkthroughApp
        from opspec.tui.session import WalkSession

        served: dict[str, tuple[str, ...]] = {}
        for binding in devices.bindings if devices is not None else ():
            served[binding.profile.name] = served.get(binding.profile.name, ()) + tuple(
                binding.participants)
        # a real device answers in wall time: start in real time unless told otherwise
        real = devices is not None and devices.requires_wall_clock
        session = WalkSession(compiled, seed=prepared.seed, days=args.days, until=until,
                              record=record if terminal else None,
                              model_factory=factory, performers=performers, replay=replay,
                              spec_path=str(args.spec), device_participants=served,
                              wall_devices=real, on_call=args.on_call, person=args.person)
        if session.failure is not None:        # the run cannot even start (a zero-time cycle)
            session.close()
            raise session.failure
        if not terminal:
            session.close()
            raise ConfigurationError(
                "the walkthrough needs a terminal to read your keys from and draw on, and "
                f"its standard {'input' if not sys.stdin.isatty() else 'output'} is not one",
                hint=f"run it in a terminal; without a person, 'opspec run {args.spec} "
                "--script FILE' plays a script or a recorded walkthrough")
        session.speed = args.speed if args.speed is not None else 1.0 if real else 60.0
        reported: list[dict[str, Any]] = []
        if devices is not None:
            devices.install(session.sim)

            def report_devices() -> None:
                # traced (device.pending) while the trace is open: when the person quits,
                # the app closes the session before the run below returns
                if not reported:
                    reported.append(devices.report())

            session.before_close(report_devices)
        from opspec.tui.sound import Cue

        cue = Cue(args.sound)
        if args.sound == "system" and cue.player is None:
            print("opspec walkthrough: no sound player found (pw-play, paplay, aplay or "
                  "afplay): the alarm cue is the terminal bell", file=sys.stderr)
        app = WalkthroughApp(session, title=package.name or package.id, notes=notes,
                             large=args.large, high_contrast=args.high_contrast, sound=cue)
        interrupted = False
        try:
            app.run()
            interrupted = getattr(app, "interrupted", False)   # the app caught a SIGINT
        except KeyboardInterrupt:          # a SIGINT from outside the terminal's keys
            interrupted = True
        finally:
            cue.close()
            session.close()                # (reports the devices, if the app did not)
    device_report = reported[0] if reported else None
    if session.failure is not None:            # shown in the app; said again in one line
        print(f"opspec walkthrough: {session.failure}", file=sys.stderr)
    # the end in words, as the app showed it: metrics, response times, the recording and the
    # commands that replay it (quoted: they paste as they are)
    print("\n".join(session.summary_lines()))
    if device_report:                          # how the bound devices did, as opspec run says
        from opspec.commands.devices_summary import device_lines

        # when the work was found unfinished: not "at the end" of a run the person left
        when = ("when interrupted" if interrupted
                else "when the run failed" if session.failure is not None
                else "at the end" if session.ended else "when the session was quit")
        print("\n".join(device_lines(device_report, when)))
    return 130 if interrupted else 1 if session.failure is not None else 0


def _seed(args: argparse.Namespace) -> tuple[int, str | None]:
    """The run's seed: ``--seed``, else a replay's recorded session's (its trace header
    says it; the device's draws of another seed would be another session), else 0; and
    what to say when ``--seed`` and the recording's differ (``None``: nothing)."""
    recorded = None
    if args.replay:
        from opspec.tui.replay import recorded_seed

        recorded = recorded_seed(args.replay)
    if args.seed is None:
        return (recorded if recorded is not None else 0), None
    if recorded is None or recorded == args.seed:
        return args.seed, None
    return args.seed, (f"--seed {args.seed} is used, not the recorded session's seed "
                       f"{recorded}: the device's draws are not those the recording was "
                       "made with (leave out --seed to replay the session as it was)")


def _check_record_folder(record: Path) -> None:
    """The folder ``--record`` writes to can be made (what the session would do first);
    folders made to find out are removed again, so a refused walkthrough leaves nothing."""
    missing = [p for p in (record.parent, *record.parent.parents) if not p.exists()]
    try:
        record.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        from opspec.commands._files import write_problem

        raise ConfigurationError(
            write_problem(record, error).replace("cannot write ",
                                                 "cannot write the recording ", 1),
            hint="give --record a path in a folder you can write to, or --no-record") from None
    for folder in missing:                    # innermost first
        try:
            folder.rmdir()
        except OSError:
            break


def _model_factory(model: Any, seed: int) -> Any:
    """The performers of the hand-overs to ``model`` (a UserModel)."""
    handovers = [0]

    def make() -> Any:
        # the first hand-over is user 0, as in `opspec run --seed` (handed over from the
        # start, the walkthrough is that run); each later one a user of its own
        handovers[0] += 1
        user = 0 if handovers[0] == 1 else 1000 + handovers[0]
        # user u's own model (a population's person u), drawing from user_stream(seed, u)
        return model.performer_for(seed, user)

    return make
