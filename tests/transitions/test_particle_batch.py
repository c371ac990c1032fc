"""The particle semantics' batch face: the planner's transition is built from it, its outcomes do
not depend on the worker count or on how jobs are grouped, and common random numbers are
keyed by the step alone."""

from __future__ import annotations

import dataclasses

import pytest

from arrange_up.io.domains import load
from arrange_up.model.world import Pick, Place, Push
from arrange_up.physics.simulation import DEFAULT_SETTINGS, SimulationStatus
from arrange_up.planning.planner import plan
from arrange_up.transitions import particles
from arrange_up.transitions.particles import (
    NOT_AT_REST_REFUSAL,
    OVERLAP_REFUSAL,
    DeterministicSemantics,
    ParticleSemantics,
    Simulated,
)


@pytest.fixture(scope="module")
def blocks2():
    return load("blocks-2")


@pytest.fixture(scope="module")
def nominal(blocks2):
    return plan(blocks2, semantics="deterministic").actions


@pytest.fixture(scope="module")
def first_push(nominal):
    return next(a for a in nominal if isinstance(a, Push))


def _before_push(semantics, nominal):
    """The belief after the nominal plan's actions before its first push."""
    belief = semantics.initial_belief()
    for action in nominal:
        if isinstance(action, Push):
            return belief
        belief = semantics.apply(belief, action)
    raise AssertionError("the plan has no push")


def _jobs(semantics, belief, push, step=0):
    affected = semantics.affected_objects(belief.intervals, push)
    noises = [noise for _, noise in semantics.common_noise(step)]
    return semantics.push_jobs(belief, push, affected, noises)


def test_apply_is_the_batch_face_with_its_own_noise(blocks2, nominal, first_push):
    semantics = ParticleSemantics(blocks2, particles=6, seed=4)
    belief = _before_push(semantics, nominal)
    before = semantics.simulations
    after = semantics.apply(belief, first_push)
    assert semantics.simulations - before == 6  # every particle counts, also after a failure
    affected = semantics.affected_objects(belief.intervals, first_push)
    noises = [semantics.noise(i, s, first_push) for i, s in enumerate(belief.particles)]
    [batch] = semantics.simulate_pushes([semantics.push_jobs(belief, first_push, affected, noises)])
    if after is None:
        assert not batch.ok
    else:
        assert batch.ok and batch.simulated == 6
        assert semantics.moved_particles(belief, batch.outcomes) == after


def test_outcomes_do_not_depend_on_workers_or_grouping(blocks2, nominal, first_push):
    serial = ParticleSemantics(blocks2, particles=8, seed=1, workers=1)
    pooled = ParticleSemantics(blocks2, particles=8, seed=1, workers=2)
    belief = _before_push(serial, nominal)
    longer = Push(first_push.manipulator, first_push.pose, first_push.distance * 1.5)
    groups = [_jobs(serial, belief, first_push), _jobs(serial, belief, longer, step=1)]
    alone = [serial.simulate_pushes([g], stop_on_failure=False)[0] for g in groups]
    assert all(b.simulated == 8 and None not in b.outcomes for b in alone)
    assert serial.simulate_pushes(groups, stop_on_failure=False) == alone
    assert pooled.simulate_pushes(groups, stop_on_failure=False) == alone
    # stopping at failures changes what is simulated, never whether a group failed
    stopped = pooled.simulate_pushes(groups)
    assert [b.ok for b in stopped] == [b.ok for b in alone]
    for b, full in zip(stopped, alone, strict=True):
        assert b.simulated <= 8
        assert all(o is None or o == f for o, f in zip(b.outcomes, full.outcomes, strict=True))
    pooled.close()


def test_a_failure_is_reported_and_stops_its_share():
    bad = Simulated("off_table", ("A",), ())
    assert not bad.ok and bad.reason() == "a particle's push put A off the table"
    assert Simulated("not_at_rest", (), ()).reason() == "a particle's push did not come to rest"
    assert Simulated("ok", (), ()).ok


def test_a_failed_push_says_why_its_transition_is_refused():
    assert Simulated("off_table", ("A", "B"), ()).refusal() == "a push left A, B off the table"
    assert Simulated("not_at_rest", (), ()).refusal() == NOT_AT_REST_REFUSAL
    assert NOT_AT_REST_REFUSAL.startswith(
        "a push did not come to rest within the simulation's time limit "
        f"({DEFAULT_SETTINGS.max_time:g} s"
    )
    assert Simulated("overlap", (), ()).refusal() == OVERLAP_REFUSAL
    assert Simulated("other", (), ()).refusal() == "a push failed in the simulation (other)"


@pytest.mark.parametrize("kind", [ParticleSemantics, DeterministicSemantics])
def test_a_refused_push_counts_its_reason(kind, blocks2, nominal, first_push, monkeypatch):
    semantics = kind(blocks2, particles=4, seed=0)
    belief = _before_push(semantics, nominal)
    assert semantics.apply(belief, first_push) is not None and not semantics.reasons
    real = particles.simulate

    def capped(*args, **kwargs):  # every push hits the simulation's time cap
        return dataclasses.replace(real(*args, **kwargs), status=SimulationStatus.NOT_AT_REST)

    monkeypatch.setattr(particles, "simulate", capped)
    assert semantics.apply(belief, first_push) is None
    affected = semantics.affected_objects(belief.intervals, first_push)
    batch, child = semantics.push_share(belief, first_push, [0], affected)
    assert not batch.ok and child is None
    # one reason per refusal: the share's first failure stops it
    assert semantics.reasons == {NOT_AT_REST_REFUSAL: 2}


def test_common_noise_is_keyed_by_the_step_alone(blocks2):
    semantics = ParticleSemantics(blocks2, particles=3, seed=2)
    again = ParticleSemantics(blocks2, particles=3, seed=2)
    assert semantics.common_noise(5) == again.common_noise(5)
    assert semantics.common_noise(5) != semantics.common_noise(6)
    assert len(semantics.common_noise(0)) == 3


def test_place_and_pick_particles(blocks2, nominal):
    semantics = ParticleSemantics(blocks2, particles=3, seed=0)
    belief = _before_push(semantics, nominal)
    name = belief.names()[0]
    picked = semantics.pick_particles(belief, Pick(name))
    assert name not in picked.names()
    assert semantics.pick_particles(belief, Pick(name), canonical=False).names() == picked.names()
    pose = (5.0, 5.0, 0.0)
    offsets = [(0.1 * i, 0.0, 0.0) for i in range(3)]
    placed = semantics.place_particles(picked, Place(name, pose), offsets)
    xs = [dict(s.poses)[name][0] for s in placed.particles]
    assert xs == [5.0, 5.1, 5.2]
