"""A study's walkthrough served to participants' browsers (``opspec study PROTOCOL --serve``).

Remote, unmoderated sessions are common in usability research. The researcher runs this
on their machine; every participant gets one link (a secret token, kept in
``RECORDINGS/links.json`` so the links stay the same when the server is started again).
Opening the link starts that participant's next session not done — the very walkthrough
``opspec study --participant`` runs on a terminal, briefing first — in a process of its
own on the researcher's machine, drawn in the browser by textual-serve (Textualize's
library that runs a Textual app behind a web page: xterm.js in the page, the app's
screen and keys over a websocket). The recording and trace are therefore written on the
researcher's side, under ``RECORDINGS/PARTICIPANT/VARIANT.json``, exactly where a terminal
session writes them; the browser only shows and types.

One link, one session at a time: a second window opening the same link while a session
runs is told so and gets nothing. A session the participant leaves (tab closed, connection
lost) is stopped and kept as a partial recording; the next visit starts it again. When a
session ends the page offers to go on ("Restart" in textual-serve's words): the next
session not done, until all are.
"""

from __future__ import annotations

import asyncio
import json
import logging
import secrets
import shlex
import sys
from pathlib import Path
from typing import Any

from opspec.errors import ConfigurationError, SourceLocation

__all__ = ["participant_links", "serve_study", "study_server"]

log = logging.getLogger("opspec.study.serve")

#: where the participants' link tokens are kept, inside the study's recordings folder
LINKS_FILE = "links.json"


def participant_links(protocol: Any) -> dict[str, str]:
    """Participant -> the secret token of their link: read from ``RECORDINGS/links.json``,
    new ones made (and written) for participants who have none yet."""
    path = Path(protocol.recordings) / LINKS_FILE
    links: dict[str, str] = {}
    if path.is_file():
        try:
            found = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as error:
            raise ConfigurationError(
                f"cannot read the participants' links: {error}",
                location=SourceLocation(str(path)),
                hint="remove the file to give every participant a new link") from None
        if not isinstance(found, dict) or not all(
                isinstance(k, str) and isinstance(v, str) for k, v in found.items()):
            raise ConfigurationError(
                "the participants' links must be a JSON object of participant -> token",
                location=SourceLocation(str(path)),
                hint="remove the file to give every participant a new link")
        links = {p: t for p, t in found.items() if p in protocol.participants}
    changed = False
    for participant in protocol.participants:
        if participant not in links:
            links[participant] = secrets.token_urlsafe(12)
            changed = True
    if changed:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(links, indent=1) + "\n", encoding="utf-8")
    return links


def session_command(protocol_path: Path, participant: str) -> str:
    """The shell command of one browser session: the participant's next session not done,
    run by this Python (so the same installation and environment)."""
    return " ".join(shlex.quote(part) for part in (
        sys.executable, "-m", "opspec", "study", str(protocol_path), "--participant",
        participant, "--next"))


_PAGE = """<!DOCTYPE html><html><head><meta charset="utf-8"><title>{title}</title>
<style>body {{ background: #0c181f; color: #eee; font-family: sans-serif; margin: 15vh auto;
max-width: 36em; font-size: 1.2em; }}</style></head>
<body><h1>{title}</h1><p id="message">{message}</p></body></html>"""


def _server_class() -> type:
    import aiohttp_jinja2
    import jinja2
    from aiohttp import web
    from textual_serve.app_service import AppService
    from textual_serve.server import Server

    class StudyServer(Server):  # type: ignore[misc]
        """textual-serve's server with one route per participant link instead of one app."""

        def __init__(self, protocol: Any, links: dict[str, str], host: str, port: int,
                     public_url: str | None) -> None:
            super().__init__("opspec study", host=host, port=port, title=protocol.name,
                             public_url=public_url)
            self.protocol = protocol
            self.by_token = {token: p for p, token in links.items()}
            self.active: set[str] = set()     # a session open now (one per link)
            self.fixed_url = public_url is not None

        def initialize_logging(self) -> None:
            pass                      # the researcher's terminal shows our lines only

        async def on_startup(self, app: web.Application) -> None:
            pass

        async def _make_app(self) -> web.Application:
            app = web.Application()
            aiohttp_jinja2.setup(app, loader=jinja2.FileSystemLoader(self.templates_path))
            app.add_routes([
                web.get("/", self.handle_root),
                web.get("/p/{token}", self.handle_index, name="index"),
                web.get("/p/{token}/ws", self.handle_websocket, name="websocket"),
                web.static("/static", self.statics_path, name="static"),
            ])
            return app

        def _participant(self, request: web.Request) -> str:
            participant = self.by_token.get(request.match_info["token"])
            if participant is None:
                raise web.HTTPNotFound(
                    text=_PAGE.format(title="No such session",
                                      message="This link is not a session of the study. "
                                      "Ask the researcher for your link."),
                    content_type="text/html")
            return participant

        async def handle_root(self, request: web.Request) -> web.Response:
            # no list of participants here: a link is the only way into a session
            return web.Response(text=_PAGE.format(
                title=self.protocol.name, message="Open the link the researcher sent you."),
                content_type="text/html")

        async def handle_index(self, request: web.Request) -> web.StreamResponse:
            participant = self._participant(request)
            pending = self.protocol.pending(participant)
            if not pending:
                return web.Response(text=_PAGE.format(
                    title=self.protocol.name, message="Every session of yours is done. "
                    "Thank you for taking part."), content_type="text/html")
            if participant in self.active:
                return web.Response(status=409, text=_PAGE.format(
                    title=self.protocol.name, message="Your session is already open in "
                    "another window or tab: go on there (or close it and reload this "
                    "page)."), content_type="text/html")
            token = request.match_info["token"]
            base = self.public_url.rstrip("/")
            ws = base + str(request.app.router["websocket"].url_for(token=token))
            ws = ("wss:" if ws.startswith("https:") else "ws:") + ws.split(":", 1)[1]
            context = {
                "font_size": 16, "app_websocket_url": ws, "ping_url": "",
                "config": {"static": {"url": base + "/static/"}},
                "application": {"name": f"{self.protocol.name}: participant {participant}, "
                                f"session {pending[0].position} of "
                                f"{len(self.protocol.variants)}"}}
            return aiohttp_jinja2.render_template("app_index.html", request, context)

        async def handle_websocket(self, request: web.Request) -> web.WebSocketResponse:
            participant = self._participant(request)
            websocket = web.WebSocketResponse(heartbeat=15)
            await websocket.prepare(request)
            if participant in self.active or not self.protocol.pending(participant):
                await websocket.close()
                return websocket
            self.active.add(participant)
            before = {s.variant.id for s in self.protocol.pending(participant)}
            width = _to_int(request.query.get("width"), 80)
            height = _to_int(request.query.get("height"), 24)
            print(f"{participant}: session started in a browser", flush=True)
            service = AppService(
                session_command(self.protocol.path, participant),
                write_bytes=websocket.send_bytes, write_str=websocket.send_str,
                close=websocket.close, download_manager=self.download_manager,
                debug=False)
            try:
                await service.start(width, height)
                try:
                    await self._process_messages(websocket, service)
                finally:
                    await service.stop()
            except asyncio.CancelledError:
                await websocket.close()
            except Exception as error:  # a broken connection must not stop the server
                log.warning("%s: session failed: %s", participant, error)
            finally:
                await service.stop()
                self.active.discard(participant)
                after = {s.variant.id for s in self.protocol.pending(participant)}
                done = sorted(before - after)
                print(f"{participant}: " + (
                    f"session {', '.join(done)} done, recorded under "
                    f"{self.protocol.recordings / participant}" if done else
                    "session left before its end (kept as a partial recording; the link "
                    "starts it again)"), flush=True)
            return websocket

        async def start(self) -> web.AppRunner:
            """Listen (port 0: any free one, then named in the links) and return the
            runner to clean up."""
            runner = web.AppRunner(await self._make_app(), handle_signals=False)
            await runner.setup()
            site = web.TCPSite(runner, self.host, self.port)
            await site.start()
            sockets = getattr(site._server, "sockets", None) or []  # noqa: SLF001
            if sockets and not self.fixed_url:
                self.port = sockets[0].getsockname()[1]
                self.public_url = f"http://{self.host}:{self.port}"
            return runner

    return StudyServer


def _to_int(value: str | None, default: int) -> int:
    try:
        return max(10, min(1000, int(value or "")))
    except ValueError:
        return default


def study_server(protocol: Any, links: dict[str, str], host: str, port: int,
                 public_url: str | None = None) -> Any:
    """The server of ``protocol``'s participant links (textual-serve's, one route each)."""
    return _server_class()(protocol, links, host, port, public_url)


def serve_study(protocol: Any, *, host: str, port: int, public_url: str | None) -> int:
    """Serve every participant's link until Ctrl+C; print the links first."""
    links = participant_links(protocol)
    server = study_server(protocol, links, host, port, public_url)

    async def main() -> None:
        runner = await server.start()
        base = server.public_url.rstrip("/")
        print(f"study {protocol.name}: one link per participant, served on {base} "
              "(Ctrl+C stops; recordings under "
              f"{protocol.recordings}):", flush=True)
        for participant in protocol.participants:
            todo = len(protocol.pending(participant))
            print(f"  {participant}  {base}/p/{links[participant]}  "
                  f"({todo} session(s) to do)", flush=True)
        try:
            await asyncio.Event().wait()
        finally:
            await runner.cleanup()

    try:
        asyncio.run(main())
    except KeyboardInterrupt:
        pass
    print("stopped serving; `opspec study PROTOCOL` prints what was done", flush=True)
    return 0
