"""Parallel and staged successor evaluation (arrange_up.planning.successors): the plan and the
statistics do not depend on where successors are simulated, and staging saves simulations
without changing the plan."""

from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest
from test_parallel import _die_once

import arrange_up
from arrange_up import parallel
from arrange_up.belief.states import ParticleBelief
from arrange_up.model.problem import SERVO_CONTROLLER, driven_by
from arrange_up.model.world import WorldState
from arrange_up.parallel import get_runner
from arrange_up.planning import planner as planner_module
from arrange_up.planning import successors
from arrange_up.planning.planner import plan


def _outcome(result) -> tuple:
    stats = {k: v for k, v in result.stats.items() if k != "elapsed"}
    return result.status, result.actions, stats


@pytest.mark.parametrize(("name", "particles"), [("blocks-2", 8), ("blocks-3", 6)])
def test_same_plan_and_statistics_for_one_and_two_local_workers(name, particles):
    problem = arrange_up.load(name)
    one = plan(problem, particles=particles, seed=0, workers=1)
    two = plan(problem, particles=particles, seed=0, workers=2)
    assert one.solved
    assert _outcome(two) == _outcome(one)


def test_same_plan_on_a_dask_cluster():
    distributed = pytest.importorskip("distributed")
    problem = arrange_up.load("blocks-2")
    local = plan(problem, particles=6, seed=1, workers=1)
    # threads in this process: a cluster that starts in a fraction of a second; the workers
    # still receive the problem through scatter and build their own task from it
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        try:
            on_dask = plan(
                problem,
                particles=6,
                seed=1,
                backend="dask",
                scheduler=cluster.scheduler_address,
            )
        finally:
            parallel.shutdown()
    assert _outcome(on_dask) == _outcome(local)


def test_staged_pushes_save_simulations_and_keep_the_plan(monkeypatch):
    # under the servo, 10-particle blocks-2 meets pushes whose first share is already
    # dominated (the servo golden case of the same name)
    problem = dataclasses.replace(arrange_up.load("blocks-2"), controller=SERVO_CONTROLLER)
    staged = plan(problem, particles=10, seed=0, workers=1)
    monkeypatch.setattr(successors, "first_share", lambda belief, affected: ())
    whole = plan(problem, particles=10, seed=0, workers=1)
    assert staged.actions == whole.actions and staged.solved
    assert staged.stats["pruned_dominated"] == whole.stats["pruned_dominated"] > 0
    assert staged.stats["transitions_simulated"] < whole.stats["transitions_simulated"]


def _belief(particles: int) -> ParticleBelief:
    rng = np.random.default_rng(3)
    return ParticleBelief(
        [WorldState(tuple((n, tuple(rng.normal(size=3))) for n in "AB")) for _ in range(particles)]
    )


def test_first_share_is_the_extreme_particles_of_the_pushed_objects():
    belief = _belief(20)
    share = successors.first_share(belief, frozenset({"B"}))
    column = belief.poses[:, 1, :]
    extremes = set(column.argmin(axis=0)) | set(column.argmax(axis=0))
    assert share == tuple(sorted(int(i) for i in extremes))
    # a coordinate's least and greatest are two particles, more than half of 3: not staged
    assert successors.first_share(_belief(3), frozenset({"A", "B"})) == ()


def _context_id(context: object, item: int) -> tuple[int, int, int]:
    return os.getpid(), id(context), item * 2


def test_a_session_ships_its_context_to_each_worker_once():
    runner = get_runner("local", workers=2)
    session = runner.session(_context_id, {"problem": list(range(1000))})
    answers = [session.submit(i) for i in range(30)]
    results = [a.result() for a in answers]
    assert [r[2] for r in results] == [2 * i for i in range(30)]
    contexts: dict[int, set[int]] = {}
    for pid, context, _ in results:
        contexts.setdefault(pid, set()).add(context)
    assert all(len(ids) == 1 for ids in contexts.values())  # unpickled once per worker


def test_a_task_lost_with_its_worker_is_sent_again(tmp_path):
    runner = get_runner("local", workers=2)
    session = runner.session(_die_once, str(tmp_path / "died"))  # the worker dies once
    assert session.submit(41).result() == 42
    assert (tmp_path / "died").exists()


def test_serial_sessions_compute_only_what_is_asked_for():
    calls = []
    session = get_runner("local", workers=1).session(lambda c, x: calls.append(x) or x, None)
    pending = [session.submit(i) for i in range(3)]
    assert calls == [] and not pending[1].done()
    assert pending[1].result() == 1 and calls == [1]


def test_a_belief_from_another_process_hashes_as_one_made_here():
    # Python salts string hashes per process: a belief a worker sent back must hash anew, or
    # duplicate detection would never find it
    belief = _belief(4)
    runner = get_runner("local", workers=2)
    made_there = runner.session(_make_belief, None).submit(4).result()
    assert made_there == belief and hash(made_there) == hash(belief)
    assert {made_there} == {belief} and not made_there.poses.flags.writeable


def _make_belief(context: object, particles: int) -> ParticleBelief:
    return _belief(particles)


def test_cbst_plans_in_this_process_whatever_the_workers(monkeypatch):
    # A learned prediction is cheaper than a worker's round trip: with workers asked for, a
    # CBST search opens no worker session, and its plan is the serial one.
    def refuse(self, fn, context):
        raise AssertionError("a CBST search opened a worker session")

    monkeypatch.setattr(parallel.LocalRunner, "session", refuse)
    problem = driven_by(arrange_up.load("blocks-2"), "servo")  # the model that plans it
    serial = plan(problem, semantics="cbst", workers=1)
    asked = plan(problem, semantics="cbst", workers=2)
    assert asked.status.value == "solved" and asked.actions == serial.actions


def test_a_cbst_search_on_dask_makes_no_runner(monkeypatch):
    # the runner is made after the task, only for a semantics that simulates pushes: a CBST
    # search asked to run on Dask starts no LocalCluster (nor connects to a scheduler)
    def refuse(self, *args, **kwargs):
        raise AssertionError("a CBST search made a Dask runner")

    monkeypatch.setattr(parallel.DaskRunner, "__init__", refuse)
    problem = driven_by(arrange_up.load("blocks-2"), "servo")
    serial = plan(problem, semantics="cbst", workers=1)
    on_dask = plan(problem, semantics="cbst", backend="dask", workers=2)
    assert on_dask.solved and on_dask.actions == serial.actions


def test_bad_backend_options_fail_before_the_task_is_built(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the task was built")

    monkeypatch.setattr(planner_module.BeliefTask, "build", refuse)
    problem = arrange_up.load("blocks-1")
    with pytest.raises(ValueError, match="scheduler address needs the dask backend"):
        plan(problem, semantics="cbst", backend="local", scheduler="tcp://127.0.0.1:1")
    with pytest.raises(ValueError, match="unknown backend"):
        plan(problem, backend="ray")
