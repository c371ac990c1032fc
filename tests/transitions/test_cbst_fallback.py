"""CBST's simulated fallback: pushes the compliant model refuses are answered by the physics."""

from __future__ import annotations

import dataclasses
import math

import pytest

from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.io.domains import load as load_domain
from arrange_up.model.problem import Controller, ControllerKind
from arrange_up.model.world import Place, Push
from arrange_up.planning.planner import plan
from arrange_up.transitions.cbst import FALLBACK_PARTICLES, CBSTSemantics
from arrange_up.transitions.fallback import SimulatedFallback


def _short_push(center, distance: float = 1.5) -> Push:
    """A paddle push toward +x starting 0.4 in behind a block at ``center``, stopping far
    short of the wall (no model prediction: the push does not compress the block against it)."""
    back = 0.5 + 0.4 + 0.075
    return Push("paddle", (center[0] - back, center[1], -0.5 * math.pi), distance)


@pytest.fixture(scope="module")
def compliant():
    problem = load_domain("blocks-1")
    assert problem.controller.kind is ControllerKind.COMPLIANT
    return problem


def test_a_push_the_model_refuses_falls_back_to_the_physics(compliant):
    sem = CBSTSemantics(compliant)
    assert sem.fallback is not None
    assert not sem.place_rings  # its boxes would not hold a ring's longer pushes
    belief = sem.apply(sem.initial_belief(), Place("A", (5.0, 2.5, 0.0)))
    out = sem.apply(belief, _short_push((5.0, 2.5)))
    assert out is not None
    assert sem.fallback_counts() == (1, 1)
    assert sem.simulations == FALLBACK_PARTICLES[ControllerKind.COMPLIANT]
    moved = out.get("A")
    # pushed toward +x, stopping short of the wall (at x = 10) and well past where it was
    assert 5.0 < moved.low[0] and moved.high[0] < 9.5
    assert moved.low[1] < 2.5 + 0.3 and moved.high[1] > 2.5 - 0.3
    # equal questions get equal answers, in this semantics and in a fresh one of the seed
    assert sem.apply(belief, _short_push((5.0, 2.5))) == out
    assert CBSTSemantics(compliant).apply(belief, _short_push((5.0, 2.5))) == out


def test_the_box_spans_the_ends_of_the_simulations(compliant):
    fallback = SimulatedFallback(compliant, particles=12, seed=3)
    belief = IntervalBelief((("A", ObjectInterval((5.0, 2.5, 0.0), (0.2, 0.2, 0.2))),))
    answer = fallback.push(belief, _short_push((5.0, 2.5)))
    assert isinstance(answer, dict) and set(answer) == {"A"}
    # eight corners and four uniform draws, each pushed once
    assert fallback.simulations == 12
    box = answer["A"]
    assert all(h > 0.0 for h in box.half)
    # another seed draws other states and noise: another, overlapping box
    other = SimulatedFallback(compliant, particles=12, seed=4).push(belief, _short_push((5.0, 2.5)))
    assert isinstance(other, dict) and other["A"] != box
    assert other["A"].low[0] < box.high[0] and box.low[0] < other["A"].high[0]


def test_a_push_the_physics_refuses_is_refused_with_its_reason(compliant):
    # no wall ahead: the block is pushed off the table's open edge
    open_right = dataclasses.replace(
        compliant,
        table=dataclasses.replace(
            compliant.table, walls=tuple(w for w in compliant.table.walls if w != "right")
        ),
    )
    sem = CBSTSemantics(open_right)
    belief = sem.apply(sem.initial_belief(), Place("A", (9.0, 2.5, 0.0)))
    assert sem.apply(belief, _short_push((9.0, 2.5), distance=3.0)) is None
    assert sem.fallback_counts() == (0, 1)
    assert any("off the table" in reason for reason in sem.reasons)


def test_the_servo_model_has_no_fallback(compliant):
    servo = dataclasses.replace(compliant, controller=Controller(kind=ControllerKind.SERVO))
    sem = CBSTSemantics(servo)
    assert sem.fallback is None and sem.fallback_counts() is None
    assert sem.place_rings
    belief = sem.apply(sem.initial_belief(), Place("A", (5.0, 2.5, 0.0)))
    assert sem.apply(belief, _short_push((5.0, 2.5))) is None
    assert plan(servo, semantics="cbst", validate=0).fallbacks is None


def test_the_plan_reports_the_fallbacks_of_every_search():
    result = plan(load_domain("blocks-2"), semantics="cbst", validate=0)
    assert result.solved and result.fallbacks is not None
    fell, pushes = result.fallbacks
    assert 0 < fell <= pushes
    assert result.fallback_line() == (
        f"simulated fallback: {fell} of {pushes} push transitions fell back to the physics"
    )
    # the agenda's searches are added up
    twice = result.after([result], max_nodes=10)
    assert twice.fallbacks == (2 * fell, 2 * pushes)
