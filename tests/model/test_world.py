"""Tests of world states and noise draws (``arrange_up.model.world``)."""

from __future__ import annotations

import numpy as np
import pytest

from arrange_up.model.problem import (
    ArrangementProblem,
    Goal,
    InitialObject,
    ObjectKind,
    ObjectSpec,
    Shape,
    Table,
    Uncertainty,
)
from arrange_up.model.world import (
    Pick,
    Place,
    Push,
    WorldState,
    draw_noise,
    movable_names,
    nominal_initial_state,
    nominal_noise,
)

BLOCK = Shape((((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)),), box=(1.0, 1.0))
PROBLEM = ArrangementProblem(
    name="w",
    table=Table((10.0, 5.0)),
    objects=(
        ObjectSpec("A", ObjectKind.PART, BLOCK),
        ObjectSpec("B", ObjectKind.PART, BLOCK),
        ObjectSpec("paddle", ObjectKind.MANIPULATOR, BLOCK),
        ObjectSpec("post", ObjectKind.OBSTACLE, BLOCK, (8.0, 4.0, 0.0)),
    ),
    initial=(InitialObject("B", (3.0, 1.0, 0.0)), InitialObject("A", (1.0, 1.0, 0.5))),
    goal=Goal((("A", (5.0, 2.0, 0.0)),), (0.2, 0.2, None)),
    uncertainty=Uncertainty(
        place=(0.2, 0.2, 0.1),
        push=(0.05, 0.05, 0.02),
        friction=(0.25, 0.55),
        part_density=(0.1, 0.15),
        manipulator_density=(0.35, 0.45),
    ),
)


def test_states_follow_the_problem_order_whatever_the_mapping_order() -> None:
    state = WorldState.from_mapping(PROBLEM, {"B": (3, 1, 0), "A": (1, 1, 0.5)})
    assert state.names() == ("A", "B")
    assert state == WorldState.from_mapping(PROBLEM, {"A": (1, 1, 0.5), "B": (3, 1, 0)})
    assert state.pose("B") == (3.0, 1.0, 0.0) and isinstance(state.pose("B")[0], float)
    assert state.pose("paddle") is None
    assert "A" in state and "paddle" not in state
    assert state.as_dict() == {"A": (1.0, 1.0, 0.5), "B": (3.0, 1.0, 0.0)}
    assert nominal_initial_state(PROBLEM) == state
    with pytest.raises(KeyError, match="unknown objects"):
        WorldState.from_mapping(PROBLEM, {"C": (0, 0, 0)})


def test_movable_names_leave_out_obstacles() -> None:
    assert movable_names(PROBLEM) == ("A", "B", "paddle")


def test_every_action_consumes_the_same_random_values() -> None:
    actions = [Place("A", (5, 2, 0)), Push("paddle", (5, 1, 0), 1.0), Pick("A")]
    draws, states = [], []
    for action in actions:
        rng = np.random.default_rng(7)
        draws.append(draw_noise(PROBLEM, action, rng))
        states.append(rng.bit_generator.state)
    assert states[0] == states[1] == states[2]
    place, push, pick = draws
    # the domain parameters are the same draw whatever the action
    assert place.friction == push.friction == pick.friction
    assert pick.pose_offset == (0.0, 0.0, 0.0)
    for noise, half in ((place, PROBLEM.uncertainty.place), (push, PROBLEM.uncertainty.push)):
        assert all(abs(o) <= h for o, h in zip(noise.pose_offset, half, strict=True))
        assert noise.pose_offset != (0.0, 0.0, 0.0)
    assert 0.25 <= place.friction <= 0.55
    assert 0.1 <= place.part_density <= 0.15
    assert 0.35 <= place.manipulator_density <= 0.45


def test_nominal_noise_is_the_middle_of_every_range() -> None:
    noise = nominal_noise(PROBLEM)
    assert noise.pose_offset == (0.0, 0.0, 0.0)
    assert noise.friction == pytest.approx(0.4)
    assert noise.part_density == pytest.approx(0.125)
    assert noise.manipulator_density == pytest.approx(0.4)
