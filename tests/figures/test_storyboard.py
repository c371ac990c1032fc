"""Tests of ``arrange_up.figures.storyboard``: what a storyboard draws (nominal states,
predicted beliefs, rollouts) and the PNG it writes, for tiny plans of catalogue problems."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import pytest
from catalogue import servo, tiny

from arrange_up.belief.states import ParticleBelief
from arrange_up.evaluation.rollouts import trace_rollout
from arrange_up.figures.backend import pyplot
from arrange_up.figures.scene import describe
from arrange_up.figures.storyboard import (
    LABEL_HEIGHT,
    LEGEND_HEIGHT,
    draw_storyboard,
    storyboard_data,
)
from arrange_up.model.world import Pick, Place, Push

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
EAST, SOUTH = -math.pi / 2, -math.pi
#: A plan of one-block (the deterministic planner's): place, push right, push down.
PLAN = (
    Place("A", (4.088, 0.912, 0.0)),
    Push("paddle", (3.377683, 1.322212, EAST), 0.5473),
    Push("paddle", (3.677788, 1.622523, SOUTH), 0.5475),
)


def png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data.startswith(PNG_SIGNATURE)
    return struct.unpack(">II", data[16:24])


def test_data_has_a_state_and_a_belief_before_and_after_each_action():
    problem = servo(tiny("one-block"))  # PLAN's distances are the servo's
    calls = []
    data = storyboard_data(
        problem, PLAN, rollouts=3, seed=2, progress=lambda done, total: calls.append((done, total))
    )
    assert len(data["nominal"]) == len(data["beliefs"]) == len(PLAN) + 1
    assert data["nominal"][0].poses == () and data["beliefs"][0].names() == ()
    final = data["nominal"][-1].pose("A")
    assert final == pytest.approx((4.5, 0.5, 0.0), abs=0.01)  # the plan works without noise
    assert all(isinstance(b, ParticleBelief) and len(b) == 1 for b in data["beliefs"])
    assert calls == [(1, 3), (2, 3), (3, 3)]
    # Rollout i is rollout i of `evaluate` with the same seed.
    assert data["rollouts"] == [trace_rollout(problem, PLAN, 2, i) for i in range(3)]


def test_data_replays_the_plans_particle_semantics():
    problem = tiny("one-block")
    data = storyboard_data(
        problem, PLAN[:1], rollouts=0, semantics="particles", particles=5, plan_seed=1
    )
    assert data["rollouts"] == []
    placed = data["beliefs"][1]
    assert len(placed) == 5 and placed.names() == ("A",)
    again = storyboard_data(
        problem, PLAN[:1], rollouts=0, semantics="particles", particles=5, plan_seed=1
    )
    assert again["beliefs"][1] == placed
    other = storyboard_data(
        problem, PLAN[:1], rollouts=0, semantics="particles", particles=5, plan_seed=2
    )
    assert other["beliefs"][1] != placed


def test_nominal_states_stop_at_a_failing_action():
    problem = tiny("one-block")
    twice = (PLAN[0], PLAN[0], PLAN[1])  # placing A again while it is on the table fails
    data = storyboard_data(problem, twice, rollouts=1)
    assert data["nominal"][1] is not None
    assert data["nominal"][2:] == [None, None]
    assert len(data["rollouts"][0]) == 2  # the rollout is cut short where it failed


def test_draw_storyboard_writes_a_png_of_one_panel_per_action(tmp_path):
    problem = tiny("one-block")
    out = tmp_path / "figures" / "story.png"
    dpi = 40
    assert draw_storyboard(problem, PLAN, out, rollouts=2, columns=2, dpi=dpi) == out
    # Two columns of four panels (the start and three actions): 2 x 2; the figure is sized
    # from the table (5 x 3 in at 3.6 in per longest side), with room for the legend below.
    scale = 3.6 / 5.0

    def pixels(columns, rows):  # up to a pixel of rounding
        height = rows * (3.0 * scale + LABEL_HEIGHT) + LEGEND_HEIGHT + 0.9
        return pytest.approx(((columns * 5.0 * scale + 0.4) * dpi, height * dpi), abs=1.0)

    assert png_size(out) == pixels(2, 2)
    # More columns than panels: one row of four.
    wide = draw_storyboard(problem, PLAN, tmp_path / "wide.png", rollouts=0, columns=9, dpi=dpi)
    assert png_size(wide) == pixels(4, 1)


def test_draw_storyboard_of_a_fixture_plan_with_particles_closes_its_figure(tmp_path):
    plt = pyplot()  # pyplot on the Agg backend, as the storyboard uses it
    problem = tiny("block-and-fixture")
    plan = (Pick("bar"), Place("A", (5.088, 0.912, 0.0)))
    before = set(plt.get_fignums())
    out = draw_storyboard(
        problem, plan, tmp_path / "fixture.png", rollouts=1, semantics="particles",
        particles=5, dpi=30,
    )  # fmt: skip
    assert png_size(out)[0] > 0
    assert set(plt.get_fignums()) == before


def test_panel_titles_quote_the_problems_units():
    inch, mm = tiny("one-block"), tiny("millimetres")
    assert describe(PLAN[0], inch) == "place A at (4.09, 0.91, 0 deg)"
    assert describe(PLAN[0], mm) == "place A at (103.84, 23.16, 0 deg)"
    assert describe(PLAN[1], mm) == "push 13.90 mm"
    assert describe(Pick("A"), mm) == "pick A"


def test_a_stalled_push_is_drawn_where_the_paddle_stopped():
    # Under the compliant controller a push resisted by the block stops short of its commanded
    # distance: the data record how far the paddle went, which the pictures draw.
    problem = tiny("one-block")  # the default, compliant controller
    data = storyboard_data(problem, PLAN, rollouts=0)
    pushes = [k for k, action in enumerate(PLAN) if isinstance(action, Push)]
    assert [data["travel"][k] is None for k in range(len(PLAN))] == [
        k not in pushes for k in range(len(PLAN))
    ]
    # PLAN's distances are the servo's (a push into a wall): the compliant paddle stops short.
    assert all(0 < data["travel"][k] < PLAN[k].distance for k in pushes)
