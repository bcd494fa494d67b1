"""Write the README's walkthrough screenshot (an SVG) deterministically.

    .venv/bin/python tests/tui/screenshot.py docs/img/walkthrough.svg

The dispenser at its second alarm (the first went unanswered): the alarm rings, the report's
deadline counts down, and the person is offered the right and the wrong button.
"""

from __future__ import annotations

import asyncio
import sys
from pathlib import Path

from opspec.engine.compiled import compile_package
from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"


async def shoot(out: Path, size: tuple[int, int] = (100, 30)) -> None:
    session = WalkSession(compile_package(open_spec(SPEC)))
    session.paused = True
    app = WalkthroughApp(session, title="Smart medication dispenser")
    async with app.run_test(size=size) as pilot:
        await pilot.press("u", "x")                     # 08:00: the first alarm, not heard
        await pilot.press("u", "a", "w", "w", "w", "a")  # 08:05: hear, walk 90 s: the buttons
        await pilot.pause()
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(app.export_screenshot(title="opspec walkthrough"), encoding="utf-8")


if __name__ == "__main__":
    asyncio.run(shoot(Path(sys.argv[1] if len(sys.argv) > 1 else "walkthrough.svg")))
