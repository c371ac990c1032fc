"""Bad input at every interface: exit 2, a message naming the file (or option), the place and
what was expected, and never a traceback.

Three families of malformed files (YAML problems, PDDL problems, plan files), each built from
a valid file by one change, and a family of bad command lines. Each case runs the command in
process; a case passes when the command exits 2 before doing any work, with a message that
names where the problem is and what was expected, and without an exception escaping.
"""

from __future__ import annotations

import json
import math
import re
import textwrap
from pathlib import Path

import pytest
from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.geometry.polygons import MAX_POLYGON_VERTICES

REPOSITORY = Path(__file__).resolve().parents[2]

# -- YAML problems -------------------------------------------------------------------------
GOOD_YAML = textwrap.dedent(
    """\
    name: one
    table: {size: [10, 5]}
    objects:
      A: {kind: part, shape: {box: [1, 1]}}
      paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
    initial:
      A: {pose: [2, 2, 0], uncertainty: [0.1, 0.1, 5]}
    goal:
      tolerance: [0.2, 0.2, 15]
      poses: {A: [5, 2, 0]}
    uncertainty:
      place: [0.2, 0.2, 15]
      push: [0.05, 0.05, 3]
      friction: [0.25, 0.55]
      part_density: [0.1, 0.15]
      manipulator_density: [0.35, 0.45]
    """
)
BIG = "1" + "0" * 400  # a 401-digit integer: valid JSON, YAML and PDDL, but no double
HUGE = "1" + "0" * 5000  # more digits than Python converts to an int by default


def _yaml(old: str, new: str) -> str:
    assert old in GOOD_YAML, old
    return GOOD_YAML.replace(old, new, 1)


def _nested_yaml(depth: int) -> str:
    return GOOD_YAML + "extra: " + "[" * depth + "]" * depth + "\n"


#: id -> (content, fragments the message must hold besides the file name and "expected")
YAML_CASES: dict[str, tuple[str | bytes, tuple[str, ...]]] = {
    "part-density-zero": (_yaml("part_density: [0.1", "part_density: [0"), ("> 0",)),
    "manipulator-density-zero": (
        _yaml("manipulator_density: [0.35, 0.45]", "manipulator_density: [0, 0]"),
        ("> 0",),
    ),
    "goal-off-the-table-x": (_yaml("poses: {A: [5, 2, 0]}", "poses: {A: [50, 2, 0]}"), ("goal",)),
    "goal-off-the-table-y": (_yaml("poses: {A: [5, 2, 0]}", "poses: {A: [5, -9, 0]}"), ("goal",)),
    "initial-angle-1e300": (_yaml("pose: [2, 2, 0]", "pose: [2, 2, 1e300]"), ("angle",)),
    "goal-angle-1e300": (_yaml("poses: {A: [5, 2, 0]}", "poses: {A: [5, 2, 1e300]}"), ("angle",)),
    "tolerance-angle-1e300": (_yaml("[0.2, 0.2, 15]", "[0.2, 0.2, 1e300]"), ("angle",)),
    "initial-dx-1e300": (
        _yaml("[0.1, 0.1, 5]", "[1e300, 0.1, 5]"),
        ("initial.A.uncertainty[0]", "at most 1000 in"),
    ),
    "initial-dtheta-1e300": (_yaml("[0.1, 0.1, 5]", "[0.1, 0.1, 1e300]"), ("angle",)),
    "place-dtheta-1e300": (_yaml("place: [0.2, 0.2, 15]", "place: [0.2, 0.2, 1e300]"), ("angle",)),
    "place-angles-1e300": (GOOD_YAML + "planning: {place_angles: [0, 1e300]}\n", ("angle",)),
    "big-integer-pose": (_yaml("pose: [2, 2, 0]", f"pose: [{BIG}, 2, 0]"), ("finite",)),
    "big-integer-table": (_yaml("size: [10, 5]", f"size: [{BIG}, 5]"), ("finite",)),
    "big-integer-box": (_yaml("box: [1, 1]", f"box: [{BIG}, 1]"), ("finite",)),
    "huge-integer": (_yaml("pose: [2, 2, 0]", f"pose: [{HUGE}, 2, 0]"), ("digits",)),
    "not-utf8": (GOOD_YAML.encode() + b"# caf\xe9\n", ("UTF-8",)),
    "nested-10000": (_nested_yaml(10_000), ("nested",)),
    "nested-mapping": (GOOD_YAML + "x: " + "{a: " * 5000 + "1" + "}" * 5000 + "\n", ("nested",)),
    "top-level-list": ("- 1\n- 2\n", ("mapping",)),
    "top-level-string": ("just a sentence\n", ("mapping",)),
    "empty": ("", ("empty",)),
    "nul-character": (GOOD_YAML + "x: \0\n", ("U+0000",)),
    "unsampleable-belief": (
        textwrap.dedent(
            """\
            name: boxed-in
            table: {size: [1, 1]}
            objects:
              A: {kind: part, shape: {box: [1, 1]}}
            initial:
              A: {pose: [0.5, 0.5, 0], uncertainty: [0.1, 0, 0]}
            goal:
              tolerance: [0.2, 0.2]
              poses: {A: [0.5, 0.5, 0]}
            """
        ),
        ("collision-free",),
    ),
    "unsampleable-row": (
        _yaml(
            "initial:\n  A: {pose: [2, 2, 0], uncertainty: [0.1, 0.1, 5]}",
            "initial:\n  A: {pose: [0.5, 2, 0], uncertainty: [0.3, 0, 0]}",
        )
        .replace("table: {size: [10, 5]}", "table: {size: [1, 5], walls: [left, right]}")
        .replace("poses: {A: [5, 2, 0]}", "poses: {A: [0.5, 3, 0]}"),
        ("collision-free",),
    ),
    "nan-pose": (_yaml("pose: [2, 2, 0]", "pose: [.nan, 2, 0]"), ("finite",)),
    "inf-tolerance": (_yaml("[0.2, 0.2, 15]", "[.inf, 0.2, 15]"), ("finite",)),
    "zero-table": (_yaml("size: [10, 5]", "size: [0, 5]"), ("> 0",)),
    "box-area-rounds-to-zero": (_yaml("box: [1, 1]", "box: [1e-300, 1e-300]"), ("degenerate",)),
    "negative-friction": (_yaml("friction: [0.25", "friction: [-0.25"), (">= 0",)),
    "duplicate-key": (GOOD_YAML + "name: two\n", ("duplicate",)),
    "name-is-a-list": (_yaml("name: one", "name: [1, 2]"), ("name",)),
    "overlapping-start": (
        _yaml(
            "initial:\n  A: {pose: [2, 2, 0], uncertainty: [0.1, 0.1, 5]}",
            "initial:\n  A: {pose: [2, 2, 0]}\n  paddle: {pose: [2, 2, 0]}",
        ),
        ("overlaps",),
    ),
    "planning-typo": (GOOD_YAML + "planning: {max_node: 5}\n", ("max_nodes",)),
}

# -- PDDL problems --------------------------------------------------------------------------
GOOD_PDDL = (REPOSITORY / "domains" / "blocks-1.pddl").read_text(encoding="utf-8")
ON_TABLE = "(= (manipulator-density-max) 0.45)\n    (on-table A) (= (x A) 2) (= (y A) 2)"


def _pddl(old: str, new: str) -> str:
    assert old in GOOD_PDDL, old
    return GOOD_PDDL.replace(old, new, 1)


PDDL_CASES: dict[str, tuple[str | bytes, tuple[str, ...]]] = {
    "durative-and-conditional": (
        _pddl(
            "(:domain arrange-up)",
            "(:domain arrange-up)\n  (:requirements :durative-actions :conditional-effects)",
        ),
        (":16:18:", ":durative-actions", "does not support"),
    ),
    "conditional-effects": (
        _pddl("(:domain arrange-up)", "(:domain arrange-up) (:requirements :strips\n :ADL)"),
        (":16:2:", ":ADL"),
    ),
    "big-integer-table": (_pddl("(table-width) 10)", f"(table-width) {BIG})"), ("digits",)),
    "big-integer-goal": (_pddl("(<= (x A) 9.7)", f"(<= (x A) {BIG})"), ("digits",)),
    "big-integer-noise": (_pddl("(= (place-dx) 0.2)", f"(= (place-dx) {BIG})"), ("digits",)),
    "big-integer-pose": (
        _pddl("(= (manipulator-density-max) 0.45)", ON_TABLE.replace("(x A) 2", f"(x A) {BIG}")),
        ("digits",),
    ),
    "angle-huge-theta": (
        _pddl("(= (manipulator-density-max) 0.45)", ON_TABLE + f" (= (theta A) {BIG[:300]})"),
        ("angle",),
    ),
    "angle-huge-goal": (_pddl("(<= (theta A) 15)", f"(<= (theta A) {BIG[:300]})"), ("angle",)),
    "angle-huge-noise": (
        _pddl("(= (push-dtheta) 3)", f"(= (push-dtheta) {BIG[:300]})"),
        ("angle",),
    ),
    "part-density-zero": (
        _pddl("(= (part-density-min) 0.1)", "(= (part-density-min) 0)"),
        ("> 0",),
    ),
    "manipulator-density-zero": (
        _pddl(
            "(= (manipulator-density-min) 0.35) (= (manipulator-density-max) 0.45)",
            "(= (manipulator-density-min) 0) (= (manipulator-density-max) 0)",
        ),
        ("> 0",),
    ),
    "goal-off-the-table": (
        _pddl("(>= (x A) 9.3) (<= (x A) 9.7)", "(>= (x A) 40.3) (<= (x A) 40.7)"),
        ("goal",),
    ),
    "unsampleable-belief": (
        _pddl("(= (manipulator-density-max) 0.45)", ON_TABLE.replace("(x A) 2", "(x A) 0.5"))
        .replace("(= (table-width) 10)", "(= (table-width) 1)")
        .replace("(= (y A) 2)", "(= (y A) 2) (= (dx A) 0.3)")
        .replace("(>= (x A) 9.3) (<= (x A) 9.7)", "(>= (x A) 0.3) (<= (x A) 0.7)"),
        ("collision-free",),
    ),
    "spread-1e300": (
        _pddl("(= (manipulator-density-max) 0.45)", ON_TABLE + " (= (dx A) 1e300)"),
        ("(dx A) is 1e+300 in", "at most 1000 in"),
    ),
    "not-utf8": (GOOD_PDDL.encode() + b"; caf\xe9\n", ("UTF-8",)),
    "nested-parentheses": (GOOD_PDDL + "(" * 5000 + ")" * 5000, ("PDDL",)),
    "empty": ("", ("PDDL",)),
    "other-domain": (_pddl("(:domain arrange-up)", "(:domain blocksworld)"), ("domain",)),
    "unknown-type": (_pddl("A - block-1x1", "A - gizmo"), ("gizmo",)),
    "no-table": (_pddl("(= (table-width) 10) (= (table-depth) 5)", ""), ("table-width",)),
    "negative-noise": (_pddl("(= (place-dx) 0.2)", "(= (place-dx) -0.2)"), (">= 0",)),
    "fluent-set-twice": (
        _pddl("(= (place-dx) 0.2)", "(= (place-dx) 0.2) (= (PLACE-dx) 0.3)"),
        (":25:", "(place-dx) is set a second time"),
    ),
    "empty-goal-interval": (_pddl("(<= (x A) 9.7)", "(<= (x A) 9.1)"), ("empty",)),
    "overlapping-start": (
        _pddl(
            "(= (manipulator-density-max) 0.45)",
            ON_TABLE + " (on-table paddle) (= (x paddle) 2) (= (y paddle) 2)",
        ),
        ("overlaps",),
    ),
}

# -- plan files (for the shipped blocks-1) -------------------------------------------------
GOOD_PLAN = {
    "format": "arrange-up-plan/1",
    "units": {"length": "in", "angle": "deg"},
    "status": "solved",
    "actions": [{"type": "place", "object": "A", "pose": [9.5, 0.5, 0.0]}],
}


def _plan(**changes) -> str:
    return json.dumps({**GOOD_PLAN, **changes})


def _pose(text: str) -> str:
    return _plan().replace("[9.5, 0.5, 0.0]", text)


PLAN_CASES: dict[str, tuple[str | bytes, tuple[str, ...]]] = {
    "top-level-list": ("[1, 2]", ("list",)),
    "top-level-string": ('"plan"', ("string",)),
    "top-level-number": ("42", ("number",)),
    "top-level-null": ("null", ("null",)),
    "not-utf8": (_plan().encode().replace(b'"in"', b'"\xe9"'), ("UTF-8",)),
    "nested-100000": ("[" * 100_000 + "]" * 100_000, ("nested",)),
    "nested-in-actions": (_plan(actions=[json.loads("[" * 40 + "]" * 40)]), ("nested",)),
    "big-integer-x": (_pose(f"[{BIG}, 0.5, 0]"), ("pose",)),
    "big-integer-theta": (_pose(f"[9.5, 0.5, {BIG}]"), ("pose",)),
    "big-integer-distance": (
        _plan(
            actions=[{"type": "push", "manipulator": "paddle", "pose": [1, 1, 0], "distance": 1}]
        ).replace('"distance": 1', f'"distance": {BIG}'),
        ("distance",),
    ),
    "distance-1e300": (
        _plan(
            actions=[{"type": "push", "manipulator": "paddle", "pose": [1, 1, 0], "distance": 1}]
        ).replace('"distance": 1', '"distance": 1e300'),
        ("actions[0].distance", "at most 1000 in"),
    ),
    "huge-integer": (_pose(f"[{HUGE}, 0.5, 0]"), ("digits",)),
    "angle-1e300": (_pose("[9.5, 0.5, 1e300]"), ("angle",)),
    "x-1e300": (_pose("[1e300, 0.5, 0]"), ("pose", "table sizes")),
    "nan-pose": (_pose("[NaN, 0.5, 0]"), ("pose",)),
    "infinite-distance": (
        _plan(
            actions=[{"type": "push", "manipulator": "paddle", "pose": [1, 1, 0], "distance": 1}]
        ).replace('"distance": 1', '"distance": Infinity'),
        ("distance",),
    ),
    "units-a-number": (_plan(units=5), ("units",)),
    "units-length-a-list": (_plan(units={"length": []}), ("units",)),
    "problem-a-string": (_plan(problem="blocks-1"), ("problem",)),
    "actions-an-object": (_plan(actions={"type": "place"}), ("actions",)),
    "action-a-number": (_plan(actions=[3]), ("actions[0]",)),
    "unknown-object": (_plan(actions=[{"type": "pick", "object": "Z"}]), ("actions[0].object",)),
    "empty": ("", ("JSON",)),
    "truncated": (_plan()[:40], ("JSON",)),
    "no-status": (json.dumps({k: v for k, v in GOOD_PLAN.items() if k != "status"}), ("status",)),
}


def _invoke(args: list[str]):
    return CliRunner().invoke(main, args)


def _assert_refused(result, *fragments: str) -> None:
    """Exit 2, no exception escaping (CliRunner catches it: a user would see a traceback),
    and every fragment in the output (stdout and stderr)."""
    escaped = result.exception is not None and not isinstance(result.exception, SystemExit)
    assert not escaped, f"{type(result.exception).__name__}: {result.exception}"
    output = result.output
    assert "Traceback" not in output
    assert result.exit_code == 2, output
    for fragment in fragments:
        assert fragment.lower() in output.lower(), f"{fragment!r} not in:\n{output}"


def _write(path: Path, content: str | bytes) -> Path:
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, encoding="utf-8")
    return path


@pytest.mark.parametrize("case", list(YAML_CASES), ids=lambda c: f"yaml-{c}")
def test_a_bad_yaml_problem_is_refused_with_its_place(tmp_path, case):
    content, fragments = YAML_CASES[case]
    path = _write(tmp_path / f"{case}.yaml", content)
    result = _invoke(["export", str(path), "-o", str(tmp_path / "out.pddl")])
    _assert_refused(result, str(path), "expected", *fragments)
    assert not (tmp_path / "out.pddl").exists()


@pytest.mark.parametrize("case", list(PDDL_CASES), ids=lambda c: f"pddl-{c}")
def test_a_bad_pddl_problem_is_refused_with_its_place(tmp_path, case):
    content, fragments = PDDL_CASES[case]
    path = _write(tmp_path / f"{case}.pddl", content)
    result = _invoke(["export", str(path), "-o", str(tmp_path / "out.pddl")])
    _assert_refused(result, str(path), "expected", *fragments)
    assert not (tmp_path / "out.pddl").exists()


@pytest.mark.parametrize("case", list(PLAN_CASES), ids=lambda c: f"plan-{c}")
def test_a_bad_plan_file_is_refused_with_its_place(tmp_path, case):
    content, fragments = PLAN_CASES[case]
    path = _write(tmp_path / f"{case}.json", content)
    result = _invoke(["evaluate", "blocks-1", str(path), "--rollouts", "1", "--workers", "1"])
    _assert_refused(result, str(path), "expected", *fragments)


def test_show_refuses_a_plan_placing_a_part_at_1e300(tmp_path):
    path = _write(tmp_path / "far.json", PLAN_CASES["x-1e300"][0])
    result = _invoke(["show", "blocks-1", "--plan", str(path), "-o", str(tmp_path / "s.png")])
    _assert_refused(result, str(path), "actions[0].pose", "table sizes")
    assert not (tmp_path / "s.png").exists()


def test_a_pddl_problem_may_declare_its_domains_requirements(tmp_path):
    declared = "(:requirements :strips :TYPING :negative-preconditions :numeric-fluents)"
    text = _pddl("(:domain arrange-up)", f"(:domain arrange-up)\n  {declared}")
    path = _write(tmp_path / "declared.pddl", text)
    result = _invoke(["check", str(path)])
    assert result.exit_code == 0, result.output


def test_the_valid_files_the_cases_start_from_are_accepted(tmp_path):
    # each case above is one change away from these: the change is what is refused
    yaml_file = _write(tmp_path / "good.yaml", GOOD_YAML)
    pddl_file = _write(tmp_path / "good.pddl", GOOD_PDDL)
    plan_file = _write(tmp_path / "good.json", json.dumps(GOOD_PLAN))
    for args in (
        ["export", str(yaml_file), "-o", str(tmp_path / "a.pddl")],
        ["export", str(pddl_file), "-o", str(tmp_path / "b.pddl")],
        ["evaluate", "blocks-1", str(plan_file), "--rollouts", "1", "--workers", "1"],
    ):
        result = _invoke(args)
        assert result.exit_code == 0, result.output
        assert "warning" not in result.output


# -- an angle too large, in the unit it was written in --------------------------------------
_LIMIT = "expected an angle of magnitude at most"
_HUGE_GOAL_ANGLE = ("poses: {A: [5, 2, 0]}", "poses: {A: [5, 2, 1e300]}")
_IN_RADIANS = _yaml("name: one\n", "name: one\nunits: {angle: rad}\n")
#: id -> (file name, content, the command before the file, the command after it, the message:
#: the angle and the limit both in the unit of the file, degrees unless it says otherwise)
ANGLE_UNIT_CASES: dict[str, tuple[str, str, list[str], list[str], str]] = {
    "yaml-degrees": (
        "deg.yaml",
        _yaml(*_HUGE_GOAL_ANGLE),
        ["check"],
        [],
        f"goal.poses.A[2]: angle 1e+300 deg: {_LIMIT} 9.61264e+08 deg (",
    ),
    "yaml-radians": (
        "rad.yaml",
        _IN_RADIANS.replace(*_HUGE_GOAL_ANGLE),
        ["check"],
        [],
        f"goal.poses.A[2]: angle 1e+300 rad: {_LIMIT} 1.67772e+07 rad (",
    ),
    "pddl": (
        "huge.pddl",
        PDDL_CASES["angle-huge-goal"][0],
        ["check"],
        [],
        f"{_LIMIT} 9.61264e+08 deg (",
    ),
    "plan-degrees": (
        "deg.json",
        _pose("[9.5, 0.5, 1e300]"),
        ["evaluate", "blocks-1"],
        ["--rollouts", "1", "--workers", "1"],
        f"pose[2]: angle 1e+300 deg: {_LIMIT} 9.61264e+08 deg (",
    ),
    "plan-radians": (
        "rad.json",
        _pose("[9.5, 0.5, 1e300]").replace('"angle": "deg"', '"angle": "rad"'),
        ["evaluate", "blocks-1"],
        ["--rollouts", "1", "--workers", "1"],
        f"pose[2]: angle 1e+300 rad: {_LIMIT} 1.67772e+07 rad (",
    ),
}


@pytest.mark.parametrize("case", list(ANGLE_UNIT_CASES))
def test_an_angle_too_large_is_refused_with_the_limit_in_the_files_unit(tmp_path, case):
    name, content, before, after, message = ANGLE_UNIT_CASES[case]
    path = _write(tmp_path / name, content)
    result = _invoke([*before, str(path), *after])
    _assert_refused(result, str(path), message)


# -- command lines ---------------------------------------------------------------------------
QUICK_PLAN = ["plan", "blocks-1", "--semantics", "particles", "--particles", "2"]
QUICK_PLAN += ["--max-nodes", "1", "--workers", "1"]
QUICK_EVALUATE = ["evaluate", "blocks-1", "{plan}", "--rollouts", "1", "--workers", "1"]
QUICK_REPAIR = ["repair", "blocks-1", "--particles", "2", "--workers", "1"]
QUICK_COMPARISON = ["experiment", "transition-comparison", "--problems", "blocks-1"]
QUICK_COMPARISON += ["--runs", "1", "--rollouts", "0", "--max-nodes", "1", "--workers", "1"]
QUICK_COMPARISON += ["--semantics", "deterministic", "--output-dir", "{tmp}/results"]
QUICK_FIXTURES = ["experiment", "fixtures", "--problems", "blocks-1", "--plans", "1"]
QUICK_FIXTURES += ["--rollouts", "1", "--workers", "1", "--output-dir", "{tmp}/results"]
QUICK_TABLE = ["experiment", "search-table", "--problems", "blocks-1", "--particles", "2"]
QUICK_TABLE += ["--max-nodes", "1", "--output-dir", "{tmp}/results"]
QUICK_TRAIN = ["train-cbst", "--examples", "10", "--rollouts-per-example", "1"]
QUICK_TRAIN += ["--workers", "1", "--output-dir", "{tmp}/model"]

#: id -> (arguments, fragments the message must hold); {tmp} is a fresh folder holding a
#: regular file "{tmp}/file", {plan} a valid plan file for blocks-1
COMMAND_CASES: dict[str, tuple[list[str], tuple[str, ...]]] = {
    "plan-seed-negative": ([*QUICK_PLAN, "--seed", "-1"], ("--seed",)),
    "plan-weight-nan": ([*QUICK_PLAN, "--weight", "nan"], ("--weight",)),
    "plan-weight-inf": ([*QUICK_PLAN, "--weight", "inf"], ("--weight",)),
    "plan-weight-negative": ([*QUICK_PLAN, "--weight", "-1"], ("--weight",)),
    "plan-timeout-nan": ([*QUICK_PLAN, "--timeout", "nan"], ("--timeout",)),
    "plan-timeout-inf": ([*QUICK_PLAN, "--timeout", "inf"], ("--timeout",)),
    "plan-timeout-zero": ([*QUICK_PLAN, "--timeout", "0"], ("--timeout",)),
    "plan-particles-zero": ([*QUICK_PLAN, "--particles", "0"], ("--particles",)),
    "plan-max-nodes-zero": ([*QUICK_PLAN, "--max-nodes", "0"], ("--max-nodes",)),
    "plan-workers-zero": ([*QUICK_PLAN, "--workers", "0"], ("--workers",)),
    "plan-output-in-a-file": ([*QUICK_PLAN, "-o", "{tmp}/file/plan.json"], ("--output",)),
    "plan-output-a-folder": ([*QUICK_PLAN, "-o", "{tmp}"], ("--output",)),
    "plan-output-in-proc": ([*QUICK_PLAN, "-o", "/proc/arrange-up-plan.json"], ("--output",)),
    "plan-unknown-problem": (["plan", "blocks-one"], ("blocks-one", "did you mean")),
    "plan-a-folder": (["plan", "{tmp}"], ("directory",)),
    "plan-unknown-semantics": ([*QUICK_PLAN, "--semantics", "magic"], ("--semantics",)),
    "plan-unknown-heuristic": ([*QUICK_PLAN, "--heuristic", "magic"], ("--heuristic",)),
    "plan-scheduler-local": (
        [*QUICK_PLAN, "--backend", "local", "--scheduler", "tcp://127.0.0.1:1"],
        ("--scheduler",),
    ),
    "plan-unknown-backend": ([*QUICK_PLAN, "--backend", "ray"], ("--backend",)),
    "evaluate-seed-negative": ([*QUICK_EVALUATE, "--seed", "-1"], ("--seed",)),
    "evaluate-rollouts-zero": ([*QUICK_EVALUATE, "--rollouts", "0"], ("--rollouts",)),
    "evaluate-workers-zero": ([*QUICK_EVALUATE, "--workers", "0"], ("--workers",)),
    "evaluate-record-in-a-file": (
        [*QUICK_EVALUATE, "--record", "{tmp}/file/r.jsonl"],
        ("--record",),
    ),
    "evaluate-plan-a-folder": (["evaluate", "blocks-1", "{tmp}"], ("directory",)),
    "evaluate-scheduler-local": (
        [*QUICK_EVALUATE, "--backend", "local", "--scheduler", "tcp://127.0.0.1:1"],
        ("--scheduler",),
    ),
    # a problem that does not exist: a count not refused would end at once with another message
    "execute-episodes-huge": (
        ["execute", "no-such-problem", "--episodes", "99999999999999999999"],
        ("--episodes", "1000000"),
    ),
    "execute-particles-huge": (
        ["execute", "no-such-problem", "--particles", "99999999999999999999"],
        ("--particles", "100000"),
    ),
    "execute-filter-particles-huge": (
        ["execute", "no-such-problem", "--filter-particles", "99999999999999999999"],
        ("--filter-particles", "100000"),
    ),
    "repair-seed-negative": ([*QUICK_REPAIR, "--seed", "-1"], ("--seed",)),
    "repair-particles-zero": ([*QUICK_REPAIR, "--particles", "0"], ("--particles",)),
    "repair-output-in-a-file": ([*QUICK_REPAIR, "-o", "{tmp}/file/r.json"], ("--output",)),
    "show-svg-as-gif": (["show", "blocks-1", "-o", "{tmp}/b.gif"], ("--output", ".svg")),
    "show-no-suffix": (["show", "blocks-1", "-o", "{tmp}/picture"], ("--output", ".png")),
    "show-output-in-a-file": (["show", "blocks-1", "-o", "{tmp}/file/b.png"], ("--output",)),
    "show-fps-nan": (
        ["show", "blocks-1", "--plan", "{plan}", "--animate", "{tmp}/a.gif", "--fps", "nan"],
        ("--fps", "finite"),
    ),
    "train-quantile-nan": ([*QUICK_TRAIN, "--quantile", "nan"], ("--quantile", "finite")),
    "train-block-half-inf": (
        [*QUICK_TRAIN, "--block-half", "0.1", "inf", "5"],
        ("--block-half", "finite"),
    ),
    "show-seed-negative": (
        ["show", "blocks-1", "--plan", "{plan}", "--seed", "-1", "-o", "{tmp}/s.png"],
        ("--seed",),
    ),
    "export-output-in-a-file": (["export", "blocks-1", "-o", "{tmp}/file/b.pddl"], ("--output",)),
    "comparison-particles-zero": ([*QUICK_COMPARISON, "--particles", "0"], ("--particles",)),
    "comparison-particles-empty": ([*QUICK_COMPARISON, "--particles", ","], ("--particles",)),
    "comparison-timeout-nan": ([*QUICK_COMPARISON, "--timeout", "nan"], ("--timeout",)),
    "comparison-output-in-a-file": (
        [*QUICK_COMPARISON, "--output-dir", "{tmp}/file/results"],
        ("--output-dir",),
    ),
    "fixtures-particles-zero": ([*QUICK_FIXTURES, "--particles", "0"], ("--particles",)),
    "fixtures-timeout-nan": ([*QUICK_FIXTURES, "--timeout", "nan"], ("--timeout",)),
    "search-table-weight-nan": ([*QUICK_TABLE, "--weight", "nan"], ("--weight",)),
    "train-seed-negative": ([*QUICK_TRAIN, "--seed", "-1"], ("--seed",)),
    "train-unknown-wall-push": ([*QUICK_TRAIN, "--wall-push", "far"], ("--wall-push",)),
    "train-output-in-a-file": ([*QUICK_TRAIN, "--output-dir", "{tmp}/file/m"], ("--output-dir",)),
    "train-data-in-a-file": ([*QUICK_TRAIN, "--data", "{tmp}/file/d.jsonl"], ("--data",)),
    "bench-workers-zero": (
        ["bench", "physics", "--pushes", "10", "--workers", "0"],
        ("--workers",),
    ),
    "bench-workers-text": (
        ["bench", "physics", "--pushes", "10", "--workers", "x"],
        ("--workers",),
    ),
    "bench-seed-negative": (
        ["bench", "physics", "--pushes", "10", "--workers", "1", "--seed", "-1"],
        ("--seed",),
    ),
}


@pytest.mark.parametrize("case", list(COMMAND_CASES))
def test_a_bad_command_line_is_refused_before_any_work(tmp_path, case):
    args, fragments = COMMAND_CASES[case]
    (tmp_path / "file").write_text("a regular file, not a folder\n")
    plan = _write(tmp_path / "plan.json", json.dumps(GOOD_PLAN))
    filled = [a.replace("{tmp}", str(tmp_path)).replace("{plan}", str(plan)) for a in args]
    result = _invoke(filled)
    _assert_refused(result, *fragments)
    written = {p.name for p in tmp_path.rglob("*")} - {"file", "plan.json"}
    assert not written, f"the refused command wrote {sorted(written)}"


def test_the_cases_are_as_many_as_reported():
    # the report quotes these counts: files of our own making and command lines
    files = len(YAML_CASES) + len(PDDL_CASES) + len(PLAN_CASES)
    assert files >= 60 and len(COMMAND_CASES) >= 40
    assert all(re.fullmatch(r"[a-z0-9-]+", c) for c in [*YAML_CASES, *PDDL_CASES, *PLAN_CASES])


def test_plan_refuses_a_polygon_over_the_vertex_cap_with_exit_2(tmp_path: Path) -> None:
    """The cap is checked before any quadratic work: refused quickly, with the file's place."""
    n = MAX_POLYGON_VERTICES + 1
    vertices = ", ".join(
        f"[{2 + math.cos(2 * math.pi * k / n):.6f}, {2 + math.sin(2 * math.pi * k / n):.6f}]"
        for k in range(n)
    )
    path = tmp_path / "big.yaml"
    path.write_text(
        "name: big\ntable: {size: [10, 5]}\nobjects:\n"
        f"  A: {{kind: part, shape: {{polygon: [{vertices}]}}}}\n"
        "goal:\n  tolerance: [0.2, 0.2]\n  poses: {A: [5, 2, 0]}\n"
    )
    column = path.read_text().splitlines()[3].index("[[") + 1
    result = _invoke(["plan", str(path), "--semantics", "deterministic"])
    assert result.exit_code == 2, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    assert (
        f"{path}:4:{column}: error: objects.A.shape.polygon: a polygon has {n} vertices; "
        f"expected at most {MAX_POLYGON_VERTICES}" in result.output
    )
