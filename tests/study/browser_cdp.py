"""Just enough of the Chrome DevTools Protocol to drive a page in headless Chromium: open a
URL, read the page's state, type keys (as a person's key presses reach the page).

The protocol is the one Chromium speaks to its own tools (https://chromedevtools.github.io/
devtools-protocol/: Target, Page, Runtime.evaluate, Input.dispatchKeyEvent); the websocket
client is aiohttp's, which textual-serve brings. No browser download: Chromium is the
system's (scripts/system-deps.sh).
"""

from __future__ import annotations

import asyncio
import json
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

#: the key events of the keys a walkthrough participant uses: (key, code, keyCode, text)
KEYS = {"enter": ("Enter", "Enter", 13, "\r"), "space": (" ", "Space", 32, " ")}


class Browser:
    """One headless Chromium with one page, driven over its DevTools websocket."""

    def __init__(self, executable: str) -> None:
        self.profile = tempfile.TemporaryDirectory(prefix="opspec-chromium-",
                                                   ignore_cleanup_errors=True)
        self.process = subprocess.Popen(
            [executable, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
             "--disable-extensions", "--remote-debugging-port=0",
             f"--user-data-dir={self.profile.name}", "--window-size=1200,800",
             "about:blank"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self._id = 0
        self.ws: Any = None
        self.http: Any = None

    async def __aenter__(self) -> Browser:
        import aiohttp

        port_file = Path(self.profile.name) / "DevToolsActivePort"
        for _ in range(600):                     # a bound on the start, not a timed check
            if port_file.is_file() and port_file.read_text().strip():
                break
            if self.process.poll() is not None:
                raise RuntimeError("Chromium exited at start")
            await asyncio.sleep(0.1)
        port = int(port_file.read_text().split()[0])
        self.http = aiohttp.ClientSession()
        async with self.http.get(f"http://127.0.0.1:{port}/json/list") as response:
            pages = [t for t in await response.json() if t.get("type") == "page"]
        self.ws = await self.http.ws_connect(pages[0]["webSocketDebuggerUrl"],
                                             max_msg_size=0)
        return self

    async def __aexit__(self, *exc: object) -> None:
        if self.ws is not None:
            await self.ws.close()
        if self.http is not None:
            await self.http.close()
        self.process.terminate()
        try:
            self.process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.process.kill()
        self.profile.cleanup()

    async def call(self, method: str, **params: Any) -> dict[str, Any]:
        self._id += 1
        mine = self._id
        await self.ws.send_str(json.dumps({"id": mine, "method": method, "params": params}))
        while True:
            message = json.loads((await self.ws.receive()).data)
            if message.get("id") == mine:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return message.get("result", {})

    async def open(self, url: str) -> None:
        await self.call("Page.navigate", url=url)

    async def evaluate(self, expression: str) -> Any:
        found = await self.call("Runtime.evaluate", expression=expression,
                                returnByValue=True)
        return found.get("result", {}).get("value")

    async def wait_for(self, expression: str, seconds: float = 60.0) -> Any:
        """Poll ``expression`` in the page until it is truthy (a bound, not a timed check)."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            value = await self.evaluate(expression)
            if value:
                return value
            await asyncio.sleep(0.2)
        raise AssertionError(f"the page never showed {expression!r}")

    async def click(self, x: float, y: float) -> None:
        """A left click at (x, y) of the page, as a person clicks into it."""
        for kind in ("mousePressed", "mouseReleased"):
            await self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left",
                            clickCount=1)

    async def press(self, key: str) -> None:
        """One key press as the keyboard gives it: down (with its text), up."""
        if key in KEYS:
            name, code, key_code, text = KEYS[key]
        else:
            name, code, key_code, text = key, f"Key{key.upper()}", ord(key.upper()), key
        await self.call("Input.dispatchKeyEvent", type="keyDown", key=name, code=code,
                        windowsVirtualKeyCode=key_code, text=text)
        await self.call("Input.dispatchKeyEvent", type="keyUp", key=name, code=code,
                        windowsVirtualKeyCode=key_code)
