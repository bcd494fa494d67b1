"""The cue at every alarm: the terminal bell, a system sound, or none (``--sound``).

A lab with older participants may need a cue louder than a terminal's bell (which many
terminals show as a flash, or mute). ``system`` plays a short tone through the first sound
player found on the machine (``pw-play``, ``paplay``, ``aplay``, ``afplay``), as well as the
bell; the tone (880 Hz, 0.4 s) is written once to a temporary WAV file with the standard
library's :mod:`wave`. A player is started without waiting for it, one at a time (an alarm
while the last tone still plays does not stack them), and stopped when the walkthrough quits.
"""

from __future__ import annotations

import math
import os
import shutil
import struct
import subprocess
import tempfile
import wave
from typing import Any

__all__ = ["PLAYERS", "SOUNDS", "Cue", "find_player"]

SOUNDS = ("bell", "system", "off")
#: players tried in order, with the arguments that make them quiet
PLAYERS = (("pw-play",), ("paplay",), ("aplay", "-q"), ("afplay",))
_RATE = 22_050


def find_player() -> tuple[str, ...] | None:
    """The command line of the first sound player on ``PATH`` (``None``: there is none)."""
    for command in PLAYERS:
        path = shutil.which(command[0])
        if path is not None:
            return (path, *command[1:])
    return None


def _tone(path: str, hz: float = 880.0, seconds: float = 0.4) -> None:
    frames = int(_RATE * seconds)
    with wave.open(path, "wb") as out:
        out.setnchannels(1)
        out.setsampwidth(2)
        out.setframerate(_RATE)
        # a sine at half amplitude with 10 ms fades (no click at either end)
        fade = int(_RATE * 0.01)
        out.writeframes(b"".join(
            struct.pack("<h", int(16_000 * min(1.0, i / fade, (frames - i) / fade)
                                  * math.sin(2 * math.pi * hz * i / _RATE)))
            for i in range(frames)))


class Cue:
    """See the module docstring. ``kind`` is one of :data:`SOUNDS`; ``player`` the command
    for ``system`` (default: :func:`find_player`; without one only the bell sounds)."""

    def __init__(self, kind: str = "bell", player: tuple[str, ...] | None = None) -> None:
        if kind not in SOUNDS:
            raise ValueError(f"sound must be one of {', '.join(SOUNDS)}, not {kind!r}")
        self.kind = kind
        self.player = (player or find_player()) if kind == "system" else None
        self._file: str | None = None
        self._playing: subprocess.Popen[bytes] | None = None
        self.played = 0                     # cues given (tests count them)

    def play(self, app: Any) -> None:
        """Give the cue: ``app.bell()`` unless ``off``, and the tone for ``system``."""
        if self.kind == "off":
            return
        self.played += 1
        app.bell()
        if self.player is None:
            return
        if self._playing is not None and self._playing.poll() is None:
            return                          # the last tone still plays
        try:
            if self._file is None:
                handle, self._file = tempfile.mkstemp(prefix="opspec-cue-", suffix=".wav")
                os.close(handle)
                _tone(self._file)
            self._playing = subprocess.Popen(       # a player found on PATH
                [*self.player, self._file], stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        except OSError:
            self.player = None              # it cannot play here: the bell goes on

    def close(self) -> None:
        """Stop a tone still playing and remove the tone's file."""
        if self._playing is not None and self._playing.poll() is None:
            self._playing.terminate()
            try:
                self._playing.wait(timeout=1.0)
            except subprocess.TimeoutExpired:
                self._playing.kill()
        self._playing = None
        if self._file is not None:
            try:
                os.unlink(self._file)
            except OSError:
                pass
            self._file = None
