"""Every command block with shown output in README.md and docs/*.md runs, and prints what the
page shows: the docs cannot drift from the program.

Sybil reads the pages. A command block is a fenced block whose first line starts with ``$ ``:
the commands (``$ …``, a trailing ``\\`` continues one) and, under each, its output. Each
block runs in a fresh temporary folder holding ``specs/`` (a link to the repository's) and,
when the page says so in an HTML comment just above the block (invisible on the page), the
files of a folder of this repository:

* ``<!-- docs-test: in tests/docs/tutorial/step2 -->`` — the tutorial's spec as it stands at
  that step (``test_tutorial_files_are_the_pages_blocks`` checks they hold what the page
  shows);
* ``<!-- docs-test: exit 1 -->`` — the command's exit status (default 0);
* ``<!-- docs-test: slow REASON -->`` — runs only with ``OPSPEC_DOCS_SLOW=1`` (no block is
  marked so now: the README's first command, 1,000 users x 30 days, takes about 20 s from
  source, and its table is the evidence that the speed work changed no outcome);
* ``<!-- docs-test: skip REASON -->`` — not run (say why).

What varies between runs is marked in the shown output: a line ``...`` stands for any lines;
wall-clock times (``in 4.7 s on 2 worker(s)``, pytest's ``in 2.98s``) and the progress line on
stderr are normalised before comparing (:data:`VARYING`).
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import pytest
from sybil import Document, Example, Region, Sybil
from sybil.parsers.markdown.lexers import FencedCodeBlockLexer

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
DIRECTIVE = re.compile(r"<!--\s*docs-test:\s*(?P<args>.*?)\s*-->")

#: Parts of an output that differ from run to run, and what they become in both texts.
VARYING: tuple[tuple[re.Pattern[str], str], ...] = (
    (re.compile(r"\d+ replications in [\d.]+ s on \d+ worker\(s\)"),
     "N replications in T s on W worker(s)"),
    (re.compile(r" in [\d.]+s( \(\d+:\d+:\d+\))?$", re.M), " in Ts"),
)
#: Lines of stderr that only show progress on a terminal.
PROGRESS = re.compile(r"^opspec evaluate: \d+/\d+ users .*$\n?", re.M)


@dataclass(frozen=True)
class Block:
    """One command block: its commands with their shown outputs, and its directives."""

    commands: tuple[tuple[str, str], ...]
    folder: str | None = None
    status: int = 0
    slow: str | None = None
    skip: str | None = None


def _parse_block(source: str, directives: list[str]) -> Block:
    commands: list[tuple[str, list[str]]] = []
    lines = source.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("$ "):
            command = line[2:]
            while command.endswith("\\") and i + 1 < len(lines):
                i += 1
                command = command[:-1] + " " + lines[i].strip()
            commands.append((command, []))
        elif commands:
            commands[-1][1].append(line)
        i += 1
    folder = slow = skip = None
    status = 0
    for args in directives:
        word, _, rest = args.partition(" ")
        if word == "in":
            folder = rest.strip()
        elif word == "exit":
            status = int(rest)
        elif word == "slow":
            slow = rest.strip() or "slow"
        elif word == "skip":
            skip = rest.strip() or "not run"
    return Block(tuple((c, "\n".join(out)) for c, out in commands), folder, status, slow,
                 skip)


class CommandBlockParser:
    """Sybil parser: fenced blocks that start with ``$ ``, with the ``docs-test`` directives
    of the HTML comments between the previous block and this one."""

    def __init__(self) -> None:
        self.lexer = FencedCodeBlockLexer(language=r"[\w-]*",
                                          mapping={"source": "source"})

    def __call__(self, document: Document) -> list[Region]:
        regions = []
        previous_end = 0
        for region in self.lexer(document):
            source = str(region.lexemes["source"])
            between = document.text[previous_end:region.start]
            previous_end = region.end
            if not source.startswith("$ "):
                continue
            directives = [m.group("args") for m in DIRECTIVE.finditer(between)]
            region.parsed = _parse_block(source, directives)
            region.evaluator = _evaluate
            regions.append(region)
        return regions


def _normalise(text: str) -> str:
    text = PROGRESS.sub("", text)
    for pattern, replacement in VARYING:
        text = pattern.sub(replacement, text)
    return "\n".join(line.rstrip() for line in text.strip("\n").splitlines())


def _matches(shown: str, printed: str) -> bool:
    """``printed`` is ``shown``, where a line ``...`` in ``shown`` stands for any lines."""
    pattern = "".join(r"(?:[^\n]*\n)*" if line.strip() == "..." else re.escape(line) + r"\n"
                      for line in _normalise(shown).splitlines())
    return re.fullmatch(pattern, _normalise(printed) + "\n") is not None


def _environment(folder: Path) -> dict[str, str]:
    bin_dir = str(Path(sys.executable).parent)
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("PYTEST_", "TEXTUAL_", "COLUMNS", "LINES"))}
    env["PATH"] = bin_dir + os.pathsep + env.get("PATH", "")
    env["OPSPEC_PURE_PYTHON"] = env.get("OPSPEC_PURE_PYTHON", "1")
    env["PYTHONUNBUFFERED"] = "1"
    return env


def _evaluate(example: Example) -> str | None:
    block: Block = example.parsed
    if block.skip:
        pytest.skip(f"docs-test skip: {block.skip}")
    if block.slow and not os.environ.get("OPSPEC_DOCS_SLOW"):
        pytest.skip(f"docs-test slow ({block.slow}): run with OPSPEC_DOCS_SLOW=1")
    with tempfile.TemporaryDirectory(prefix="opspec-docs-") as tmp:
        return _run(example, block, Path(tmp))


def _run(example: Example, block: Block, work: Path) -> str | None:
    if block.folder:
        shutil.copytree(ROOT / block.folder, work, dirs_exist_ok=True)
    (work / "specs").symlink_to(ROOT / "specs", target_is_directory=True)
    env = _environment(work)
    for command, shown in block.commands:
        text = command.split(" #", 1)[0].strip()          # a trailing comment explains
        # stderr into stdout, unbuffered: the two interleave as on a terminal
        done = subprocess.run(shlex.split(text), cwd=work, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, timeout=600, check=False)
        printed = done.stdout
        if done.returncode != block.status:
            return (f"{example.path}:{example.line}: `{text}` exited {done.returncode}, the "
                    f"page says {block.status}\n{printed}")
        if not _matches(shown, printed):
            return (f"{example.path}:{example.line}: `{text}` printed\n{printed}\n"
                    f"--- but the page shows\n{shown}")
    return None


SYBIL = Sybil(parsers=[CommandBlockParser()], path="../..")
EXAMPLES = [(page, example) for page in PAGES for example in SYBIL.parse(page)]


@pytest.mark.parametrize(("page", "example"), EXAMPLES,
                         ids=[f"{p.name}:{e.line}" for p, e in EXAMPLES])
def test_the_page_shows_what_the_command_prints(page: Path, example: Example) -> None:
    example.evaluate()


def test_every_page_with_commands_is_read() -> None:
    assert {p.name for p, _ in EXAMPLES} >= {"README.md", "tutorial.md"}


def test_tutorial_files_are_the_pages_blocks() -> None:
    """The tutorial's step folders hold what its page shows: the first spec and the user
    model and scripts whole, every later XML fragment line for line in its step's spec (a
    fragment shows what changes; the folder is the spec with the change made)."""
    page = (ROOT / "docs" / "tutorial.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```(\w*)\n(.*?)```", page, re.S)
    xml = [text for lang, text in blocks if lang == "xml"]
    toml = [text for lang, text in blocks if lang == "toml"]
    folder = ROOT / "tests" / "docs" / "tutorial"
    assert (folder / "step1" / "pill.xpdl").read_text(encoding="utf-8") == xml[0]
    assert (folder / "step2" / "answer.toml").read_text(encoding="utf-8") == toml[0]
    assert (folder / "step6" / "pill.users.toml").read_text(encoding="utf-8") == toml[1]
    assert (folder / "step6" / "test_pill.py").read_text(encoding="utf-8") == next(
        text for lang, text in blocks if lang == "python")
    for fragment, step in zip(xml[1:], ["step2", "step2", "step3", "step4", "step5", "step6"],
                              strict=True):
        spec = (folder / step / "pill.xpdl").read_text(encoding="utf-8").splitlines()
        missing = [line for line in fragment.splitlines() if line.strip()
                   and line not in spec]
        assert not missing, f"{step}/pill.xpdl lacks {missing[:3]}"
