"""``opspec study PROTOCOL.toml``: the sessions of a walkthrough study, and its summary.

``--participant ID`` runs that participant's sessions not done yet, in their counterbalanced
order, each after its briefing; without it, the study's status, the summary per variant and
the paired comparison of the designs (docs/walkthrough.md, *A study*).
"""

from __future__ import annotations

import argparse
import json
from typing import Any

__all__ = ["register"]


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "study", help="run the sessions of a walkthrough study and compare the designs",
        description="Participants perform the spec variants of PROTOCOL in counterbalanced "
        "(Latin square) orders, each session a walkthrough recorded under "
        "RECORDINGS/PARTICIPANT/VARIANT.json; a session that breaks off is started again "
        "when the participant resumes. Without --participant: which sessions are done, the "
        "metrics per variant and the paired comparison of the variants (the statistics of "
        "opspec evaluate --compare).")
    parser.add_argument("protocol", metavar="PROTOCOL.toml", help="the study protocol")
    parser.add_argument("--participant", metavar="ID",
                        help="run this participant's sessions that are not done yet")
    parser.add_argument("--json", action="store_true",
                        help="print the summary as JSON (without --participant)")
    parser.set_defaults(handler=_study)


def _study(args: argparse.Namespace) -> int:
    from opspec.commands._spec import load_any_spec
    from opspec.tui.study import (
        finish_session,
        load_protocol,
        session_app,
        summary,
        summary_lines,
    )

    protocol = load_protocol(args.protocol)
    for variant in protocol.variants:          # a broken spec opens no session
        load_any_spec(variant.spec)
    if args.participant is None:
        doc = summary(protocol)
        print(json.dumps(doc, indent=1) if args.json else "\n".join(summary_lines(doc)))
        return 0
    pending = protocol.pending(args.participant)
    if not pending:
        print(f"participant {args.participant}: every session is done")
        return 0
    for session in pending:
        app, walk = session_app(protocol, session)
        try:
            app.run()
        except KeyboardInterrupt:
            pass
        finally:
            walk.close()
        if not finish_session(session, walk):
            print(f"participant {args.participant}, session {session.position} "
                  f"({session.variant.id}) broke off before its end; its recording is kept "
                  f"as a partial one. Resume with: opspec study {args.protocol} "
                  f"--participant {args.participant}")
            return 1
        print(f"participant {args.participant}, session {session.position} "
              f"({session.variant.id}) done: {session.recording}")
    if not any(protocol.pending(p) for p in protocol.participants):
        print("\n".join(summary_lines(summary(protocol))))
    return 0
