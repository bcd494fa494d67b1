"""An independent dispenser board for end-to-end tests, written from devices/README.md and
devices/medication_dispenser.toml alone: it imports nothing from opspec and runs as its own
process on one end of a pseudo-terminal pair (socat), like the firmware on the real board.

Protocol (115200 8N1, lines end with "\\n"):
  ALARM ON       -> OK   (one alarm pattern; it does not latch)
  ALARM OFF      -> OK
  DISPENSE <n>   -> OK DISPENSED <n> | ERR JAM | ERR EMPTY <n>
  anything else  -> ERR UNKNOWN
  unsolicited    <- BUTTON REPORT    (the user's report button)
  debug lines    <- # ...            (ignored by the host)

The simulated user presses *report* once per dose, ``--press-ms`` after the first ALARM ON
of that dose (a DISPENSE ends the dose). Faults: ``--garbage N`` answers the first N commands
with garbled bytes (``--noise``: unsolicited junk after the first DISPENSE;
``--noise-before``: noise lines, a garbled and a cut-off frame before each DISPENSE reply,
which then comes in two pieces);
``--late-ms MS --late-count N`` sends the first N replies MS late;
``--jam`` / ``--empty`` make every DISPENSE fail; ``--unplug-on PREFIX --socat-pid PID`` pulls
the cable (kills socat, so both ends of the pair vanish) when a command starting with PREFIX
arrives. Every command received is printed to stdout as ``RX <line>``.
"""

from __future__ import annotations

import argparse
import heapq
import os
import select
import signal
import sys
import termios
import time
import tty

GARBLED = b"\xfe\x15%$GARBLED$%\x07\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("port")
    parser.add_argument("--press-ms", type=float, default=20.0)
    parser.add_argument("--no-press", action="store_true")
    parser.add_argument("--press-at-ms", type=float, default=None,
                        help="also press report once, this long after the board starts")
    parser.add_argument("--garbage", type=int, default=0)
    parser.add_argument("--noise", action="store_true",
                        help="send a debug line, an unknown line and a garbled line 10 ms "
                        "after answering the first DISPENSE")
    parser.add_argument("--noise-before", action="store_true",
                        help="before each reply to DISPENSE: a debug line, an unknown line, "
                        "a garbled line and a cut-off frame, then the reply in two pieces")
    parser.add_argument("--late-ms", type=float, default=0.0)
    parser.add_argument("--late-count", type=int, default=0)
    parser.add_argument("--jam", action="store_true")
    parser.add_argument("--empty", action="store_true")
    parser.add_argument("--unplug-on", default="")
    parser.add_argument("--socat-pid", type=int, default=0)
    args = parser.parse_args(argv)

    fd = os.open(args.port, os.O_RDWR | os.O_NOCTTY)
    tty.setraw(fd)
    attrs = termios.tcgetattr(fd)
    attrs[3] &= ~termios.ECHO
    termios.tcsetattr(fd, termios.TCSANOW, attrs)
    out: list[tuple[float, int, bytes]] = []   # (due time, seq, bytes) heap
    seq = 0

    def send(data: bytes, delay_s: float = 0.0) -> None:
        nonlocal seq
        seq += 1
        heapq.heappush(out, (time.monotonic() + delay_s, seq, data))

    print("READY", flush=True)
    if args.press_at_ms is not None:
        send(b"BUTTON REPORT\n", args.press_at_ms / 1000)
    noisy = args.noise
    commands = 0
    pressed = False
    unplugged = False
    buffer = b""
    while True:
        timeout = max(0.0, out[0][0] - time.monotonic()) if out else 0.5
        try:
            ready, _, _ = select.select([fd], [], [], timeout)
        except InterruptedError:
            continue
        while out and out[0][0] <= time.monotonic():
            _, _, data = heapq.heappop(out)
            if not unplugged:
                try:
                    os.write(fd, data)
                except OSError:
                    return 0
        if not ready:
            continue
        try:
            chunk = os.read(fd, 256)
        except OSError:
            return 0           # the other end is gone
        if not chunk:
            return 0
        buffer += chunk
        while b"\n" in buffer:
            raw, buffer = buffer.split(b"\n", 1)
            line = raw.decode("ascii", "replace").strip()
            if not line:
                continue
            print(f"RX {line}", flush=True)
            if unplugged:
                continue
            if args.unplug_on and line.startswith(args.unplug_on):
                unplugged = True
                print("UNPLUG", flush=True)
                if args.socat_pid:
                    os.kill(args.socat_pid, signal.SIGTERM)
                continue
            commands += 1
            if line in ("ALARM ON", "ALARM OFF"):
                reply = b"OK\n"
                if line == "ALARM ON" and not pressed and not args.no_press:
                    pressed = True
                    send(b"BUTTON REPORT\n", args.press_ms / 1000)
            elif line.startswith("DISPENSE "):
                slot = line.split(" ", 1)[1]
                pressed = False
                if args.jam:
                    reply = b"ERR JAM\n"
                elif args.empty:
                    reply = f"ERR EMPTY {slot}\n".encode()
                else:
                    reply = f"OK DISPENSED {slot}\n".encode()
            else:
                reply = b"ERR UNKNOWN\n"
            if commands <= args.garbage:
                reply = GARBLED
            delay = args.late_ms / 1000 if commands <= args.late_count else 0.0
            if args.noise_before and line.startswith("DISPENSE "):
                # what a board with a chatty motor driver sends: noise, then the reply
                for noise in (b"# motor 1840 ms\n", b"HELLO THERE\n", GARBLED, b"OK DISP\n"):
                    send(noise, delay)
                    delay += 0.01
                send(reply[:5], delay)               # the reply, in two pieces
                reply, delay = reply[5:], delay + 0.01
            send(reply, delay)
            if noisy and line.startswith("DISPENSE "):
                noisy = False
                for noise in (b"# drawer motor 1840 ms\n", b"HELLO THERE\n", GARBLED):
                    send(noise, delay + 0.01)


if __name__ == "__main__":
    sys.exit(main())
