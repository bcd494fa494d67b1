"""Run the sessions of a walkthrough study and compare the designs.

Participants perform the spec variants of PROTOCOL in counterbalanced (Latin square) orders,
each session a walkthrough recorded under RECORDINGS/PARTICIPANT/VARIANT.json; a session that
breaks off is started again when the participant resumes.

--participant ID runs that participant's sessions not done yet, in their counterbalanced
order, each after its briefing (--next: only the first of them); --serve serves one link per
participant, whose browser runs the same sessions (opspec.tui.study_serve). Without either:
which sessions are done, the metrics per variant and the paired comparison of the variants
(the statistics of opspec evaluate --compare; docs/walkthrough.md, A study).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from typing import Any

from opspec.commands._args import add_json, command

__all__ = ["register"]


def register(subparsers: Any) -> None:
    parser = command(subparsers, "study", __doc__)
    parser.add_argument("protocol", metavar="PROTOCOL.toml", help="the study protocol")
    parser.add_argument("--participant", metavar="ID",
                        help="run this participant's sessions that are not done yet")
    parser.add_argument("--next", action="store_true",
                        help="with --participant: run only their next session not done")
    add_json(parser, "the summary as JSON (without --participant)")
    web = parser.add_argument_group("participants in a browser")
    web.add_argument("--serve", action="store_true",
                     help="serve the sessions over HTTP: print one link per participant, "
                     "whose browser runs their sessions; recordings are written here "
                     "(needs the study extra: pip install 'opspec[study]')")
    web.add_argument("--host", default="127.0.0.1",
                     help="with --serve: the address to listen on (default 127.0.0.1, this "
                     "machine only; 0.0.0.0 for other machines)")
    web.add_argument("--port", type=int, default=8000,
                     help="with --serve: the port (default 8000; 0: any free one)")
    web.add_argument("--public-url", metavar="URL",
                     help="with --serve: the address participants reach the server at, "
                     "when not host:port (a proxy or tunnel in front)")
    parser.set_defaults(handler=_study)


def _study(args: argparse.Namespace) -> int:
    from opspec.commands._spec import load_any_spec
    from opspec.commands.study_protocol import refuse_unknown_keys
    from opspec.errors import ConfigurationError
    from opspec.tui.study import (
        check_recordings,
        finish_session,
        keep_partial,
        load_protocol,
        session_app,
    )
    from opspec.tui.study_summary import summary, summary_lines

    # first: a misspelt told left a variant unbriefed, and a misspelt [[variants]] was said
    # to be missing, not misspelt
    refuse_unknown_keys(args.protocol)
    protocol = load_protocol(args.protocol)
    for variant in protocol.variants:          # a broken spec opens no session
        load_any_spec(variant.spec)
    check_recordings(protocol)                 # sessions done with another spec: refused
    if args.serve:
        if args.participant is not None:
            raise ConfigurationError("--serve serves every participant's link: leave out "
                             "--participant")
        if not 0 <= args.port <= 65535:
            raise ConfigurationError(f"--port must be 0..65535, not {args.port}")
        try:
            from opspec.tui.study_serve import serve_study
        except ImportError as error:
            raise ConfigurationError(f"--serve needs textual-serve ({error.name} is missing)",
                             hint="pip install 'opspec[study]'") from None
        return serve_study(protocol, host=args.host, port=args.port,
                           public_url=args.public_url)
    if args.next and args.participant is None:
        raise ConfigurationError("--next runs one participant's next session: give --participant")
    # in a browser session stdout carries the app's screen: say the outcome on stderr
    say = sys.stderr if "web_driver" in os.environ.get("TEXTUAL_DRIVER", "") else sys.stdout
    if args.participant is None:
        doc = summary(protocol)
        print(json.dumps(doc, indent=1) if args.json else "\n".join(summary_lines(doc)))
        return 0
    pending = protocol.pending(args.participant)
    if not pending:
        print(f"participant {args.participant}: every session is done", file=say)
        return 0
    for session in pending[:1] if args.next else pending:
        app, walk = session_app(protocol, session)
        try:
            app.run()
        except KeyboardInterrupt:
            pass
        finally:
            walk.close()
        if not finish_session(session, walk):
            kept = keep_partial(session)
            where = ("nothing was recorded" if kept is None else
                     f"what was recorded is kept apart as {kept} (and "
                     f"{kept.name.removesuffix('.json')}.trace.jsonl), not as a session done")
            print(f"participant {args.participant}, session {session.position} "
                  f"({session.variant.id}) broke off before its end; {where}. Resume with: "
                  f"opspec study {args.protocol} --participant {args.participant}", file=say)
            return 1
        print(f"participant {args.participant}, session {session.position} "
              f"({session.variant.id}) done: {session.recording}", file=say)
    if not any(protocol.pending(p) for p in protocol.participants):
        print("\n".join(summary_lines(summary(protocol))), file=say)
    return 0
