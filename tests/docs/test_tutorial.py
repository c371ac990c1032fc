"""docs/tutorial.md runs as written: every command and code block, in order, in one empty
directory, each printing what the page shows (see :mod:`doc_runner` for how a page is read and
what is normalised).

Nothing is scaled down: the tutorial's problem is small enough to run as written. One step is
conditional: the animation (``show --animate``) runs only when ``arrange-up show --help``
lists ``--animate``; otherwise :func:`test_tutorial_animation` is skipped, saying why.

The pictures the page shows (``docs/images/tutorial-*.png``) are the ones its commands write.
To regenerate them::

    ARRANGE_UP_DOC_IMAGES=docs/images pytest tests/docs/test_tutorial.py
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from doc_runner import (
    REPOSITORY,
    Step,
    check_exit,
    compare,
    run_command,
    run_python,
    steps,
    write_file,
)

PAGE = REPOSITORY / "docs" / "tutorial.md"
#: Generous per-step limit; each step takes seconds.
TIMEOUT = 300


def _is_animation(step: Step) -> bool:
    return step.kind == "command" and "--animate" in step.text.split()


def _run(step: Step, cwd: Path) -> subprocess.CompletedProcess[str] | None:
    if step.kind == "file":
        write_file(cwd, step)
        return None
    if step.kind == "python":
        return run_python(step.text, cwd, TIMEOUT)
    return run_command(step.text, cwd, TIMEOUT)


@pytest.fixture(scope="module")
def tutorial(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[Step]]:
    """The directory in which every step of the page but the animation ran, and those steps."""
    cwd = tmp_path_factory.mktemp("tutorial")
    page_steps = steps(PAGE)
    ran = []
    for step in page_steps:
        if _is_animation(step):
            continue
        result = _run(step, cwd)
        if result is not None:
            check_exit(PAGE, step, result)
            compare(PAGE, step, result.stdout)
        ran.append(step)
    target = os.environ.get("ARRANGE_UP_DOC_IMAGES")
    if target:
        for picture in cwd.glob("tutorial-*"):
            shutil.copy2(picture, REPOSITORY / target / picture.name)
    return cwd, ran


def test_tutorial_runs_as_written(tutorial: tuple[Path, list[Step]]) -> None:
    cwd, ran = tutorial
    kinds = {step.kind for step in ran}
    assert kinds == {"file", "command", "python"}, kinds
    # the page shows output for most commands, and all of it was compared
    assert sum(step.expected is not None for step in ran) >= 8


def test_tutorial_pictures_are_made_by_its_commands(tutorial: tuple[Path, list[Step]]) -> None:
    cwd, _ = tutorial
    shown = re.findall(r"!\[[^\]]*\]\(images/([^)]+)\)", PAGE.read_text(encoding="utf-8"))
    assert shown, "the tutorial shows no pictures"
    for name in shown:
        assert name.startswith("tutorial-"), name
        assert (cwd / name).is_file(), f"no command of the tutorial writes {name}"
        assert (REPOSITORY / "docs" / "images" / name).is_file(), f"docs/images/{name} missing"


def test_tutorial_animation(tutorial: tuple[Path, list[Step]]) -> None:
    cwd, _ = tutorial
    animations = [step for step in steps(PAGE) if _is_animation(step)]
    assert len(animations) == 1, "the tutorial has one animation step"
    (step,) = animations
    help_text = run_command("arrange-up show --help", cwd, TIMEOUT).stdout
    if "--animate" not in help_text:
        pytest.skip(
            f"tutorial.md:{step.line}: `{step.text}` not run: "
            "`arrange-up show --help` does not list --animate in this version"
        )
    result = run_command(step.text, cwd, TIMEOUT)
    check_exit(PAGE, step, result)
    compare(PAGE, step, result.stdout)
    output = [word for word in step.text.split() if word.endswith(".gif")]
    assert output and (cwd / output[0]).stat().st_size > 0
