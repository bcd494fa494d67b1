"""Start a new spec: a small runnable device (pill reminder or stove guard), its user
model and tests.

Write the folder NAME/ with NAME.xpdl (--template pill, the default: a pill reminder - a
device workflow with a timed start, a reminder whose wait has a deadline, a retry and an
escalation to a caregiver, and the user's manual lane; --template stove: a stove guard - the
device watches, the user must confirm, the guard escalates by cutting the power),
NAME.users.toml (its user model, picked up by opspec run and opspec evaluate because it sits
beside the spec), test_NAME.py (spec tests: run them with 'python -m pytest NAME') and a
README.md listing the commands to try. The spec validates, runs and passes its tests as
written. The templates are package data (opspec/commands/templates/new/<template>/).

Exit status: 0 written; 2 the folder already exists (it is never overwritten), the name is
not usable, or the folder cannot be written.
"""

from __future__ import annotations

import argparse
import re
import string
import sys
from importlib import resources
from pathlib import Path
from typing import Any

from opspec.commands._args import command

__all__ = ["SHAPES", "TEMPLATES", "register", "render", "run"]

#: The device shapes ``opspec new --template`` offers: name -> what it is.
SHAPES: dict[str, str] = {
    "pill": "a pill reminder: beeps at 09:00 and 21:00, waits for 'taken', beeps again, "
            "then tells the caregiver",
    "stove": "a stove guard: watches the stove, asks the user to confirm, alerts again, then "
             "cuts the power and tells the caregiver",
}

# template file -> output file name (``$name`` / ``$ident`` substituted in both).
TEMPLATES: tuple[tuple[str, str], ...] = (
    ("spec.xpdl.tmpl", "${name}.xpdl"),
    ("users.toml.tmpl", "${name}.users.toml"),
    ("test.py.tmpl", "test_${ident}.py"),
    ("README.md.tmpl", "README.md"),
)

# A name is used in file names, an XML comment and an XPDL Id: letters, digits, '_', '-', '.'
# (no '--', which XML comments forbid), starting with a letter or digit.
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")


def register(subparsers: Any) -> None:
    parser = command(subparsers, "new", __doc__)
    parser.add_argument("name", metavar="NAME",
                        help="the folder to create; its last part names the files")
    parser.add_argument("--template", choices=tuple(SHAPES), default="pill",
                        help="the device to start from: " + "; ".join(
                            f"{k}: {v}" for k, v in SHAPES.items()) + " (default: pill)")
    parser.set_defaults(handler=run)


def render(name: str, template: str = "pill") -> dict[str, str]:
    """The files of a new spec called ``name`` from ``template`` (:data:`SHAPES`): output
    file name -> text."""
    # name_pad: spaces as wide as the name, so that a line without it (python -m pytest)
    # keeps its comment in the column of the lines with it
    values = {"name": name, "ident": identifier(name), "name_pad": " " * len(name)}
    folder = resources.files("opspec.commands").joinpath("templates", "new", template)
    return {string.Template(target).substitute(values):
            string.Template(folder.joinpath(source).read_text(encoding="utf-8"))
            .substitute(values)
            for source, target in TEMPLATES}


def identifier(name: str) -> str:
    """``name`` as a Python identifier and XPDL Id (``pill-box.v2`` -> ``pill_box_v2``)."""
    ident = re.sub(r"\W", "_", name)
    return ident if ident[:1].isalpha() or ident[:1] == "_" else f"spec_{ident}"


def run(args: argparse.Namespace) -> int:
    folder = Path(args.name)
    name = folder.name
    if not _NAME.fullmatch(name) or "--" in name:
        print(f"opspec new: {name!r} cannot name a spec: use letters, digits, '_', '-' and "
              "'.', starting with a letter or digit (e.g. 'pill_reminder')", file=sys.stderr)
        return 2
    if folder.exists() or folder.is_symlink():
        print(f"opspec new: {folder} already exists; nothing written (choose another name or "
              "move it away)", file=sys.stderr)
        return 2
    files = render(name, getattr(args, "template", "pill"))
    try:
        folder.mkdir(parents=True)
        for file_name, text in files.items():
            (folder / file_name).write_text(text, encoding="utf-8")
    except OSError as error:
        reason = error.strerror or str(error)
        print(f"opspec new: cannot write {folder}: {reason}", file=sys.stderr)
        return 2
    spec = folder / f"{name}.xpdl"
    print(f"opspec new: wrote {folder}/ ({', '.join(files)})")
    print(f"  try: opspec run {spec}")
    print(f"       opspec evaluate {spec} --users 20 --days 2")
    print(f"       python -m pytest {folder}")
    return 0
