"""A problem may declare at most ``MAX_OBJECTS`` objects: beyond it the file is refused when
read (exit 2, the count and the limit named), before the pairwise work of checking and
sampling that ignored ``plan --timeout`` for 10,000 parts. Tabletop problems have tens."""

from __future__ import annotations

import textwrap
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.io.domains import check_problem_file
from arrange_up.io.validation import MAX_OBJECTS

REPOSITORY = Path(__file__).resolve().parents[2]


def _many_parts_yaml(parts: int) -> str:
    """A valid problem of ``parts`` 0.5-inch blocks on a grid, plus a paddle."""
    columns = 20
    rows = -(-parts // columns)
    objects = "".join(f"  P{i}: {{kind: part, shape: {{box: [0.5, 0.5]}}}}\n" for i in range(parts))
    initial = "".join(
        f"  P{i}: {{pose: [{1 + 2 * (i % columns)}, {1 + 2 * (i // columns)}, 0]}}\n"
        for i in range(parts)
    )
    return (
        textwrap.dedent(
            f"""\
            name: many
            table: {{size: [{2 * columns + 1}, {2 * rows + 1}]}}
            goal:
              tolerance: [0.2, 0.2, 15]
              poses: {{P0: [1, 1, 0]}}
            uncertainty:
              place: [0.2, 0.2, 15]
            """
        )
        + "objects:\n"
        + objects
        + "  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}\n"
        + "initial:\n"
        + initial
    )


@pytest.mark.parametrize("parts", [MAX_OBJECTS, 10_000])
def test_plan_refuses_more_objects_than_the_limit_at_load(tmp_path: Path, parts: int) -> None:
    path = tmp_path / "many.yaml"
    path.write_text(_many_parts_yaml(parts), encoding="utf-8")
    started = time.perf_counter()
    result = CliRunner().invoke(main, ["plan", str(path), "--timeout", "1"])
    elapsed = time.perf_counter() - started
    assert result.exit_code == 2, result.output
    assert f"{path}:" in result.output
    assert f"error: objects: the problem declares {parts + 1} objects" in result.output
    assert f"expected at most {MAX_OBJECTS}" in result.output
    assert "Traceback" not in result.output
    assert elapsed < 5.0


def test_a_problem_at_the_limit_is_accepted(tmp_path: Path) -> None:
    path = tmp_path / "many.yaml"
    path.write_text(_many_parts_yaml(MAX_OBJECTS - 1), encoding="utf-8")
    problem, diagnostics = check_problem_file(path)
    assert problem is not None, [str(d) for d in diagnostics]
    assert len(problem.parts) == MAX_OBJECTS - 1
    assert MAX_OBJECTS >= 100  # a documented floor: never refuse a plausible problem


def test_a_pddl_problem_with_too_many_objects_is_refused(tmp_path: Path) -> None:
    text = (REPOSITORY / "domains" / "blocks-1.pddl").read_text(encoding="utf-8")
    extra = "".join(f"    X{i} - block-1x1\n" for i in range(MAX_OBJECTS))
    path = tmp_path / "many.pddl"
    path.write_text(text.replace("    A - block-1x1\n", "    A - block-1x1\n" + extra))
    problem, diagnostics = check_problem_file(path)
    assert problem is None
    assert any(
        d.is_error and f"declares {MAX_OBJECTS + 2} objects" in d.message and d.line is not None
        for d in diagnostics
    ), [str(d) for d in diagnostics]
