"""README.md's commands run as written: the install line, the tour, the storyboard, the example
output and the library example, in order, in one temporary directory (see :mod:`doc_runner`
for how a page is read and what is normalised).

The tour runs from the root of a clone: the temporary directory gets a link to the
repository's ``domains/`` folder, and nothing is written into the repository.

Two tables say what is not run exactly as written, and why; a test fails when an entry no
longer matches a command of the README, so neither can go stale:

* :data:`COVERED_ELSEWHERE`: the install and test commands, which CI runs itself (``.ci/run``
  creates a fresh virtual environment, runs ``pip install ".[test]"``, then ``pytest``, this
  test included).
* :data:`SCALED_DOWN`: the long commands, each replaced by the same command on a smaller
  problem (fewer runs, rollouts, particles, examples); the options that are not about size
  stay as written. Their output is not compared (the README shows none).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from doc_runner import REPOSITORY, Step, blocks, check_exit, compare, run_command, run_python, steps

PAGE = REPOSITORY / "README.md"
TIMEOUT = 600

#: command as the README writes it -> why the test does not run it
COVERED_ELSEWHERE: dict[str, str] = {
    "python3 -m venv .venv": ".ci/run creates a fresh virtual environment",
    ". .venv/bin/activate": ".ci/run activates it",
    "pip install .": '.ci/run installs the project, with pip install ".[test]"',
    "pip install '.[test]'": ".ci/run runs exactly this",
    "pytest": ".ci/run runs exactly this (this test is part of it)",
}

#: command as the README writes it -> the smaller command the test runs instead
SCALED_DOWN: dict[str, str] = {
    "arrange-up evaluate blocks-7 b7.json --rollouts 1000": (
        "arrange-up evaluate blocks-7 b7.json --rollouts 20"
    ),
    "arrange-up show blocks-7 --plan b7.json --rollouts 100 -o story.png": (
        "arrange-up show blocks-7 --plan b7.json --rollouts 5 -o story.png"
    ),
    "arrange-up evaluate tz-mating tz.fixtures.json --rollouts 300": (
        "arrange-up evaluate tz-mating tz.fixtures.json --rollouts 20"
    ),
    "arrange-up evaluate tz-mating tz.bare.json --rollouts 300": (
        "arrange-up evaluate tz-mating tz.bare.json --rollouts 20"
    ),
    "arrange-up experiment transition-comparison --runs 3 --rollouts 300": (
        "arrange-up experiment transition-comparison --problems blocks-4 --particles 5"
        " --runs 1 --rollouts 5"
    ),
    "arrange-up experiment search-table --timeout 60": (
        "arrange-up experiment search-table --timeout 60 --problems blocks-1"
    ),
    "arrange-up experiment fixtures --plans 5 --particles 10,40,150": (
        "arrange-up experiment fixtures --problems down-push --plans 1 --particles 10 --rollouts 5"
    ),
    "arrange-up train-cbst --controller compliant --rollouts-per-example 1000": (
        "arrange-up train-cbst --controller compliant --examples 10 --rollouts-per-example 2"
        " --test-examples 2"
    ),
    "arrange-up show blocks-3 --plan b3.json --rollouts 30 -o blocks-3-storyboard.png "
    "--animate blocks-3.gif": (
        "arrange-up show blocks-3 --plan b3.json --rollouts 5 -o blocks-3-storyboard.png "
        "--animate blocks-3.gif"
    ),
    "arrange-up bench physics": "arrange-up bench physics --pushes 10 --workers 1",
}


def _readme_commands() -> list[Step]:
    return [step for step in steps(PAGE) if step.kind in ("command", "python")]


def test_the_tables_name_commands_of_the_readme() -> None:
    written = {step.text for step in _readme_commands()}
    for command in [*COVERED_ELSEWHERE, *SCALED_DOWN]:
        assert command in written, f"README.md no longer has `{command}`: update the table"
    for command in SCALED_DOWN:
        assert command not in COVERED_ELSEWHERE


def test_the_readme_runs(tmp_path: Path) -> None:
    (tmp_path / "domains").symlink_to(REPOSITORY / "domains", target_is_directory=True)
    ran = compared = 0
    for step in _readme_commands():
        if step.text in COVERED_ELSEWHERE:
            continue
        if step.kind == "python":
            result = run_python(step.text, tmp_path, TIMEOUT)
        else:
            result = run_command(SCALED_DOWN.get(step.text, step.text), tmp_path, TIMEOUT)
        check_exit(PAGE, step, result)
        if step.expected is not None:
            assert step.text not in SCALED_DOWN
            compare(PAGE, step, result.stdout)
            compared += 1
        ran += 1
    assert ran >= 20 and compared >= 1, (ran, compared)


@pytest.mark.parametrize("index", [i for i, b in enumerate(blocks(PAGE)) if b.info == "yaml"])
def test_the_readme_problem_example_checks(tmp_path: Path, index: int) -> None:
    block = blocks(PAGE)[index]
    (tmp_path / "example.yaml").write_text("\n".join(block.body) + "\n", encoding="utf-8")
    result: subprocess.CompletedProcess[str] = run_command(
        "arrange-up check example.yaml", tmp_path, TIMEOUT
    )
    assert result.returncode == 0, f"README.md:{block.line}: {result.stdout}"


def test_room_table_lists_the_rooms_of_the_house_rule_in_order() -> None:
    """The "How it works" table names every room, in the order (and rows) of ``ROOMS``, the
    order tests/test_house.py enforces."""
    import re
    import sys

    sys.path.insert(0, str(REPOSITORY / "benchmarks"))
    from house import ROOMS

    text = PAGE.read_text(encoding="utf-8")
    section = text[text.index("## How it works") : text.index("## Documentation")]
    rows = [
        tuple(re.findall(r"`(\w+)`", line.split("|")[1]))
        for line in section.splitlines()
        if line.startswith("| `")
    ]
    assert [set(row) for row in rows] == [set(floor) for floor in ROOMS]
