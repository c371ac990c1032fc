"""Run the commands and code of a Markdown page as a reader would, and compare what they print.

A page is read as a sequence of fenced blocks:

* ``console`` and ``bash`` blocks: a line ``$ COMMAND`` (in ``console``; every non-blank line in
  ``bash``) is a command; ``&&`` chains commands; ``# ...`` ends it as a comment. The lines
  that follow a command in a ``console`` block, up to the next ``$``, are its expected output;
  a line ``…`` among them means "the output continues", and only the lines before it are
  compared. A command line that ends with the comment ``# exit status N`` is expected to exit
  with status N (a command that shows a failure); it must be a single command.
* ``yaml`` (or any other) blocks with ``title="NAME"`` in their info string are files the
  reader saves: they are written to NAME before the next command runs.
* ``python`` blocks are run as a script; a ``text`` block that follows one directly (only
  blank lines between) is its expected output.

Everything runs in one temporary directory, in page order, so later commands see the files of
earlier ones. ``arrange-up`` runs as ``python -m arrange_up`` with the interpreter and the
package under test. A command that exits with another status than the page says (0 unless
it says ``# exit status N``) fails the page.

Printed output is compared after :func:`normalise`, which replaces what changes from run to
run and machine to machine, and nothing else: elapsed seconds (``in 5.6 s``, ``, 1.4 s``) and
the number of worker processes (the default is every core).
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import arrange_up

REPOSITORY = Path(__file__).resolve().parents[2]

FENCE = re.compile(r"^(?P<indent> *)```(?P<info>[^`]*)$")
TITLE = re.compile(r'title="(?P<name>[^"]+)"')
#: The comment that ends a command line expected to exit with a status other than 0.
EXIT_STATUS = re.compile(r"#\s*exit status (?P<status>\d+)\s*$")

#: What :func:`normalise` replaces, and why.
NORMALISATIONS: tuple[tuple[re.Pattern[str], str], ...] = (
    # elapsed wall-clock time, printed by plan, evaluate and repair
    (re.compile(r"\b\d+(\.\d+)? s\b"), "<seconds> s"),
    # the default worker count is every core of the machine
    (re.compile(r"\b\d+ workers?\b"), "<n> workers"),
)


#: A progress line, printed every few seconds off a terminal (cli.shared.LineProgress): how
#: many a command prints depends on the machine's speed, so the pages show none.
PROGRESS_LINE = re.compile(r"^arrange-up [a-z -]+: .* \[\d+:\d\d:\d\d elapsed\]$")


def normalise(text: str) -> list[str]:
    """``text`` as lines without trailing blanks, with timings and worker counts replaced and
    progress lines left out."""
    lines = []
    for line in text.splitlines():
        if PROGRESS_LINE.match(line):
            continue
        for pattern, replacement in NORMALISATIONS:
            line = pattern.sub(replacement, line)
        lines.append(line.rstrip())
    while lines and not lines[-1]:
        lines.pop()
    return lines


@dataclass
class Step:
    """One thing the page asks the reader to do, with the page line it starts on."""

    line: int
    kind: str  # "command", "file" or "python"
    text: str  # the command, the file's content or the script
    name: str = ""  # the file name of a "file" step
    expected: list[str] | None = None  # the output the page shows, if it shows any
    continues: bool = False  # the page shows only the start of the output ("…")
    block: int = 0  # which fenced block (0-based) the step comes from
    exit_status: int = 0  # the status the command must exit with


@dataclass
class Block:
    line: int
    info: str
    body: list[str] = field(default_factory=list)


def blocks(page: Path) -> list[Block]:
    """The fenced blocks of ``page`` (unindented and indented), with their first line."""
    found: list[Block] = []
    current: Block | None = None
    indent = ""
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), start=1):
        match = FENCE.match(line)
        if current is None and match:
            indent = match["indent"]
            current = Block(number, match["info"].strip())
        elif current is not None and match and match["indent"] == indent and not match["info"]:
            found.append(current)
            current = None
        elif current is not None:
            current.body.append(line[len(indent) :] if line.startswith(indent) else line)
    if current is not None:
        raise AssertionError(f"{page}:{current.line}: unclosed fenced block")
    return found


def steps(page: Path) -> list[Step]:
    """What ``page`` asks the reader to do, in order."""
    found: list[Step] = []
    page_blocks = blocks(page)
    for index, block in enumerate(page_blocks):
        language = block.info.split()[0] if block.info else ""
        title = TITLE.search(block.info)
        if title:
            found.append(
                Step(block.line, "file", "\n".join(block.body) + "\n", title["name"], block=index)
            )
        elif language == "python":
            step = Step(block.line, "python", "\n".join(block.body) + "\n", block=index)
            following = page_blocks[index + 1] if index + 1 < len(page_blocks) else None
            if following is not None and following.info == "text" and _adjacent(page, block):
                step.expected = normalise("\n".join(following.body))
            found.append(step)
        elif language == "bash":
            for offset, line in enumerate(block.body, start=1):
                for command in _commands(line):
                    found.append(Step(block.line + offset, "command", command, block=index))
        elif language == "console":
            for offset, line in enumerate(block.body, start=1):
                if line.startswith("$ "):
                    commands = _commands(line[2:])
                    status = EXIT_STATUS.search(line)
                    if status and len(commands) != 1:
                        raise AssertionError(
                            f"{page}:{block.line + offset}: `# exit status` ends a line of "
                            f"{len(commands)} commands; it is for a single command"
                        )
                    for command in commands:
                        found.append(Step(block.line + offset, "command", command, block=index))
                    if status:
                        found[-1].exit_status = int(status["status"])
                elif found and found[-1].block == index and found[-1].kind == "command":
                    last = found[-1]
                    if line.strip() == "…":
                        last.continues = True
                    elif not last.continues:
                        last.expected = [*(last.expected or []), line]
    for step in found:
        if step.kind == "command" and step.expected is not None:
            step.expected = normalise("\n".join(step.expected))
    return found


def _adjacent(page: Path, block: Block) -> bool:
    """Whether only blank lines separate ``block``'s closing fence from the next fence."""
    lines = page.read_text(encoding="utf-8").splitlines()
    number = block.line + len(block.body) + 1  # the closing fence, 1-based
    for line in lines[number:]:
        if FENCE.match(line):
            return True
        if line.strip():
            return False
    return False


def _commands(line: str) -> list[str]:
    """The commands of one shell line: ``&&`` chains them, ``#`` starts a comment."""
    words = shlex.split(line, comments=True)
    commands, current = [], []
    for word in words:
        if word == "&&":
            commands.append(shlex.join(current))
            current = []
        else:
            current.append(word)
    if current:
        commands.append(shlex.join(current))
    return commands


def environment() -> dict[str, str]:
    """The environment of every command: the package under test first on the path, unbuffered
    output (so stdout and stderr interleave as written), no terminal progress display."""
    package_root = str(Path(arrange_up.__file__).resolve().parents[1])
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [package_root, *filter(None, env.get("PYTHONPATH", "").split(os.pathsep))]
    )
    env["PYTHONUNBUFFERED"] = "1"
    env["COLUMNS"] = "100"
    return env


def run_command(command: str, cwd: Path, timeout: float) -> subprocess.CompletedProcess[str]:
    """Run one ``arrange-up ...`` or ``python ...`` command of a page in ``cwd``."""
    words = shlex.split(command)
    if words[0] == "arrange-up":
        argv = [sys.executable, "-m", "arrange_up", *words[1:]]
    elif words[0] in ("python", "python3"):
        argv = [sys.executable, *words[1:]]
    else:
        raise AssertionError(f"the page runs {words[0]!r}, which the doc test does not know")
    return subprocess.run(
        argv,
        cwd=cwd,
        env=environment(),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=timeout,
    )


def run_python(script: str, cwd: Path, timeout: float) -> subprocess.CompletedProcess[str]:
    """Run one ``python`` block of a page as a script in ``cwd``."""
    return subprocess.run(
        [sys.executable, "-c", script],
        cwd=cwd,
        env=environment(),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=timeout,
    )


def compare(page: Path, step: Step, output: str) -> None:
    """Fail unless ``output`` is what ``page`` shows for ``step`` (after :func:`normalise`)."""
    if step.expected is None:
        return
    printed = normalise(output)
    if step.continues:
        printed = printed[: len(step.expected)]
    if printed != step.expected:
        raise AssertionError(
            f"{page.name}:{step.line}: `{step.text}` printed\n"
            + "\n".join(printed)
            + "\n\nbut the page shows\n"
            + "\n".join(step.expected)
        )


def check_exit(page: Path, step: Step, result: subprocess.CompletedProcess[str]) -> None:
    """Fail, with the command's output, unless it exited with the status the page says (0
    unless the line ends ``# exit status N``)."""
    if result.returncode != step.exit_status:
        expected = f" (the page says {step.exit_status})" if step.exit_status else ""
        raise AssertionError(
            f"{page.name}:{step.line}: `{step.text[:200]}` exited {result.returncode}"
            f"{expected}:\n" + result.stdout[-4000:]
        )


def write_file(cwd: Path, step: Step) -> Path:
    """Save a ``title="NAME"`` block of a page as the reader would."""
    path = cwd / step.name
    path.write_text(step.text, encoding="utf-8")
    return path
