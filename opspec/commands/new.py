"""Start a new spec: a small runnable device (pill reminder or stove guard), its user
model and tests.

Write the folder NAME/ with NAME.xpdl (--template pill, the default: a pill reminder - a
device workflow with a timed start, a reminder whose wait has a deadline, a retry and an
escalation to a caregiver, and the user's manual lane; --template stove: a stove guard - the
device watches, the user must confirm, the guard escalates by cutting the power),
NAME.users.toml (its user model, picked up by opspec run and opspec evaluate because it sits
beside the spec), test_NAME.py (spec tests, NAME as a Python name: test_pill_box.py for
pill-box; run them with 'python -m pytest NAME') and a README.md listing the commands to try.
The spec validates, runs and passes its tests as written. The templates are package data
(opspec/commands/templates/new/<template>/).

Exit status: 0 written; 2 the folder already exists (it is never overwritten), the name is
not usable (no folder's name, such as '.', or a spec file's, such as pill.xpdl), or the folder
cannot be written (nothing is left behind).
"""

from __future__ import annotations

import argparse
import contextlib
import re
import shlex
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
# NAME is the folder, so 'pill.xpdl' would write pill.xpdl/pill.xpdl.xpdl
_SPEC_SUFFIXES = (".xpdl", ".bpmn", ".wfs")


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


def _name_problem(typed: str, folder: Path) -> str | None:
    """Why ``typed`` (the NAME argument, as ``folder``) cannot be the new spec's folder, or
    None. Said with what was typed: ``.`` has no last part, and quoting ``''`` reads as if
    nothing had been typed."""
    name = folder.name
    if name in ("", ".", ".."):
        return (f"{typed!r} names no new folder: NAME is the folder to create, and its last "
                "part names the files (e.g. 'opspec new pill_reminder' writes "
                "pill_reminder/pill_reminder.xpdl)")
    if not _NAME.fullmatch(name) or "--" in name:
        return (f"{name!r} cannot name a spec: use the letters a-z and A-Z (no accents), "
                "digits, '_', '-' and '.', starting with a letter or digit (e.g. "
                "'pill_reminder')")
    if name.lower().endswith(_SPEC_SUFFIXES):
        bare = folder.with_name(folder.stem)
        return (f"{typed!r} is a spec file's name, but NAME is the folder to create, and "
                f"its last part names the files: opspec new {shlex.quote(str(bare))} "
                f"writes {bare / (bare.name + '.xpdl')}")
    return None


def run(args: argparse.Namespace) -> int:
    folder = Path(args.name)
    name = folder.name
    problem = _name_problem(args.name, folder)
    if problem:
        print(f"opspec new: {problem}", file=sys.stderr)
        return 2
    if folder.exists() or folder.is_symlink():
        print(f"opspec new: {folder} already exists; nothing written (choose another name or "
              "move it away)", file=sys.stderr)
        return 2
    files = render(name, getattr(args, "template", "pill"))
    # the folders mkdir makes, innermost first: a failed write takes them away again, so
    # that trying again is not refused with "already exists" by a half-written folder
    made = [folder, *(p for p in folder.parents if not p.exists())]
    try:
        folder.mkdir(parents=True)
        for file_name, text in files.items():
            (folder / file_name).write_text(text, encoding="utf-8")
    except OSError as error:
        from opspec.commands._files import write_problem

        _remove(made, files)
        print(f"opspec new: {write_problem(folder, error)}; nothing written", file=sys.stderr)
        return 2
    spec = folder / f"{name}.xpdl"
    print(f"opspec new: wrote {folder}/ ({', '.join(files)})")
    # quoted, so that each line pasted into a shell runs as shown (a folder with a space)
    print(f"  try: opspec run {shlex.quote(str(spec))}")
    print(f"       opspec evaluate {shlex.quote(str(spec))} --users 20 --days 2")
    print(f"       python -m pytest {shlex.quote(str(folder))}")
    return 0


def _remove(made: list[Path], files: dict[str, str]) -> None:
    """Take away what a failed :func:`run` wrote: ``files`` in the first of ``made``, then
    the folders of ``made`` that are empty (only these: nothing else is touched)."""
    for file_name in files:
        with contextlib.suppress(OSError):
            (made[0] / file_name).unlink(missing_ok=True)
    for folder in made:
        with contextlib.suppress(OSError):
            folder.rmdir()
