"""An interrupt from outside the terminal's keys (``kill -INT``, a supervisor stopping the
session) ends the walkthrough as ``q`` does, and is remembered, so that the command says the
session was interrupted and exits with status 130.

Textual reads Ctrl+C as a key (the terminal is in raw mode). A SIGINT sent from outside went
to asyncio's runner instead, which cancelled the app's task: the app ended, the command
printed the summary as after a normal end (a bound device's unfinished work "at the end")
and exited with status 0.
"""

from __future__ import annotations

import asyncio
import contextlib
import signal
from collections.abc import Callable

__all__ = ["watch_interrupts"]


def watch_interrupts(on_interrupt: Callable[[], None]) -> Callable[[], None]:
    """Call ``on_interrupt`` on the running loop at SIGINT; returns what stops watching.
    Where the loop cannot watch signals (not the main thread, Windows), nothing changes."""
    loop = asyncio.get_running_loop()
    try:
        loop.add_signal_handler(signal.SIGINT, on_interrupt)
    except (NotImplementedError, RuntimeError, ValueError):
        return lambda: None

    def release() -> None:
        with contextlib.suppress(NotImplementedError, RuntimeError, ValueError):
            loop.remove_signal_handler(signal.SIGINT)

    return release
