"""Tests of plan files (``arrange_up.io.planfile``): the JSON round trip and its refusals."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import pytest

from arrange_up.io.planfile import (
    PlanFileError,
    plan_document,
    plan_problem_mismatch,
    read_plan,
    write_json_atomic,
)
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.model.world import Pick, Place, Push

PROBLEM = load_problem_text(
    """\
name: plans
units: {length: cm, angle: deg}
table: {size: [25, 12]}
objects:
  A: {kind: part, shape: {box: [2.5, 2.5]}}
  paddle: {kind: manipulator, shape: {box: [6, 0.4]}}
goal: {tolerance: [0.5, 0.5], poses: {A: [20, 2, 0]}}
"""
)
ACTIONS = (
    Place("A", (2.0, 1.0, math.radians(15))),
    Push("paddle", (2.0, 0.2, 0.0), 1.5),
    Pick("A"),
)


def write_plan(tmp_path: Path, **changes: object) -> Path:
    document = plan_document(
        PROBLEM, ACTIONS, status="solved", semantics="deterministic", seed=0, search={}
    )
    document.update(changes)
    return write_json_atomic(tmp_path / "plan.json", document)


def test_a_plan_round_trips_in_the_problems_units(tmp_path: Path) -> None:
    path = write_plan(tmp_path)
    document = json.loads(path.read_text())
    assert document["units"] == {"length": "cm", "angle": "deg"}
    assert document["actions"][0]["pose"] == pytest.approx([5.08, 2.54, 15.0])
    actions, read_back = read_plan(path, PROBLEM)
    assert read_back == document
    assert [type(a) for a in actions] == [Place, Push, Pick]
    assert actions[0].pose == pytest.approx(ACTIONS[0].pose)
    assert actions[1].distance == pytest.approx(1.5)
    assert plan_problem_mismatch(document, PROBLEM) is None
    other = dataclasses.replace(PROBLEM, name="other")
    assert "planned for problem 'plans'" in plan_problem_mismatch(document, other)


def test_unsolved_plans_and_misfitting_actions_are_refused(tmp_path: Path) -> None:
    document = plan_document(
        PROBLEM, None, status="node-limit", semantics="deterministic", seed=0, search={}
    )
    assert "actions" not in document
    unsolved = write_json_atomic(tmp_path / "unsolved.json", document)
    with pytest.raises(PlanFileError, match="not 'solved'"):
        read_plan(unsolved, PROBLEM)
    wrong_kind = write_plan(
        tmp_path, actions=[{"type": "place", "object": "paddle", "pose": [1, 1, 0]}]
    )
    with pytest.raises(PlanFileError, match=r"actions\[0\]\.object: 'paddle' is a manipulator"):
        read_plan(wrong_kind, PROBLEM)
    (tmp_path / "broken.json").write_text("{")
    with pytest.raises(PlanFileError, match="not JSON"):
        read_plan(tmp_path / "broken.json", PROBLEM)
