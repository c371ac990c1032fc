"""An undeclared name under 'initial' or 'goal' is refused with a list of the names that would
be valid at that place: objects of the kinds allowed there, with a valid name and a kind that
could be read (never an obstacle in 'initial', a non-part in a goal, the reference among a
relative goal's poses, or a name refused under 'objects')."""

from __future__ import annotations

from arrange_up.io.yaml_problem import check_problem_text

OBJECTS = """
name: suggestions
table: {size: [10, 5]}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  B: {kind: part, shape: {box: [1, 1]}}
  2B: {kind: part, shape: {box: [1, 1]}}
  W: {kind: prat, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
  bar: {kind: fixture, shape: {box: [2, 0.5]}}
  post: {kind: obstacle, shape: {box: [0.5, 0.5]}, pose: [5, 2.5, 0]}
"""


def _messages(text: str) -> dict[str, str]:
    problem, diagnostics = check_problem_text(OBJECTS + text, "suggestions.yaml")
    assert problem is None
    return {d.path: d.message for d in diagnostics}


def test_initial_suggests_only_valid_parts_manipulators_and_fixtures():
    messages = _messages(
        "initial:\n  Q: {pose: [3, 2, 0]}\n"
        "goal:\n  tolerance: [0.2, 0.2]\n  poses: {A: [9, 1, 0]}\n"
    )
    assert messages["initial.Q"] == (
        "'Q' in 'initial' is not declared under 'objects'; expected one of the declared "
        "parts, manipulators and fixtures (A, B, paddle, bar)"
    )


def test_a_goal_suggests_only_valid_parts():
    messages = _messages("goal:\n  tolerance: [0.2, 0.2]\n  poses: {C: [9, 1, 0]}\n")
    assert messages["goal.poses.C"] == (
        "'C' in the goal is not declared under 'objects'; expected one of the declared parts (A, B)"
    )


def test_a_relative_goal_suggests_parts_and_not_the_reference_among_its_poses():
    relative = "goal:\n  tolerance: [0.2, 0.2]\n  relative:\n    reference: {}\n    poses: {}\n"
    messages = _messages(relative.format("A", "{C: [1, 0, 0]}"))
    assert messages["goal.relative.poses.C"].endswith(
        "expected one of the declared parts other than the reference (B)"
    )
    messages = _messages(relative.format("R", "{B: [1, 0, 0]}"))
    assert messages["goal.relative.reference"].endswith("expected one of the declared parts (A, B)")
