"""The executor protocol a robot integration implements, and the simulated executor.

An :class:`Executor` executes one action and returns what was sensed
(:class:`~arrange_up.execution.observations.Observation`), or raises
:class:`ExecutionFailed` when the action could not be carried out (the robot refused it, a
part fell off the table, the push never came to rest). That is the whole contract: a ROS 2
or real-arm bridge maps :class:`~arrange_up.model.world.Place`,
:class:`~arrange_up.model.world.Push` and :class:`~arrange_up.model.world.Pick` to its motion
commands and its encoders or camera to an observation (``docs/execution.md``,
``examples/fake_robot.py``).

:class:`SimulatedExecutor` is the physics standing in for the robot: it draws the true
initial state and every action's noise as an evaluation rollout does
(:mod:`arrange_up.evaluation.rollouts`, the same failures), optionally with noise ``scale``
times wider than the problem models (:func:`scaled_problem`: the robustness-to-model-error
test), and senses with a :class:`~arrange_up.execution.observations.Sensor`. It knows the true
state, which a robot does not: only the experiment harness reads it to judge the goal.
"""

from __future__ import annotations

import dataclasses
from typing import Protocol, runtime_checkable

import numpy as np

from arrange_up.belief.compiled import compile_problem
from arrange_up.belief.states import sample_initial_particles
from arrange_up.evaluation.outcomes import Failure
from arrange_up.evaluation.rollouts import Rollouts
from arrange_up.execution.observations import Observation, Sensor
from arrange_up.model.problem import ArrangementProblem, Uncertainty, as_triple
from arrange_up.model.world import Action, WorldState

__all__ = ["ExecutionFailed", "Executor", "SimulatedExecutor", "scaled_problem"]


class ExecutionFailed(Exception):
    """The executor could not carry out an action: ``failure`` says why (the kinds of
    :mod:`arrange_up.evaluation.outcomes`; ``failure.action`` is the action's index in the
    episode)."""

    def __init__(self, failure: Failure) -> None:
        super().__init__(failure.reason or str(failure.kind))
        self.failure = failure


@runtime_checkable
class Executor(Protocol):
    """What closed-loop execution needs from a robot.

    ``execute(action, index)`` carries out ``action`` (internal units: inches, radians; the
    ``index``-th action of the episode, counting from 0) and returns the observation made
    after it; it raises :class:`ExecutionFailed` when the action could not be carried out.
    """

    def execute(self, action: Action, index: int) -> Observation: ...


def scaled_problem(problem: ArrangementProblem, scale: float) -> ArrangementProblem:
    """``problem`` with every noise ``scale`` times as wide: the initial, place and push
    half-widths multiplied, the friction and density ranges widened about their middles (a
    range's low end is kept above zero: a density or friction cannot be negative)."""
    if scale == 1.0:
        return problem
    if not scale > 0.0:
        raise ValueError(f"noise scale must be positive, got {scale!r}")

    def widen(low_high: tuple[float, float]) -> tuple[float, float]:
        low, high = low_high
        middle, half = 0.5 * (low + high), 0.5 * (high - low) * scale
        return (max(middle - half, 0.05 * middle), middle + half)

    unc = problem.uncertainty
    scaled = Uncertainty(
        place=tuple(v * scale for v in unc.place),  # type: ignore[arg-type]
        push=tuple(v * scale for v in unc.push),  # type: ignore[arg-type]
        friction=widen(unc.friction),
        part_density=widen(unc.part_density),
        manipulator_density=widen(unc.manipulator_density),
    )
    initial = tuple(
        dataclasses.replace(e, uncertainty=as_triple(v * scale for v in e.uncertainty))
        for e in problem.initial
    )
    return dataclasses.replace(problem, uncertainty=scaled, initial=initial)


class SimulatedExecutor:
    """The physics as the robot of one episode.

    The world derives from ``numpy.random.default_rng([seed, episode])``: the true initial
    state (as a rollout draws it, from the initial intervals), then each action's noise; the
    observations' noise from a stream of its own, so the same episode meets the same world
    whatever it senses (open and closed loop are paired). ``scale`` widens the world's noise
    beyond the problem's model (:func:`scaled_problem`); ``landing`` is the rollouts' rule for
    a paddle put down onto a part.
    """

    def __init__(
        self,
        problem: ArrangementProblem,
        sensor: Sensor,
        seed: int,
        episode: int,
        *,
        scale: float = 1.0,
        landing: str = "fail",
    ) -> None:
        self.world = scaled_problem(problem, scale)
        self.sensor = sensor
        self.rollouts = Rollouts(self.world, (), landing=landing)
        self.rng = np.random.default_rng([seed, episode])
        self.sense_rng = np.random.default_rng([seed, episode, 0x5E45E])
        self.state: WorldState = sample_initial_particles(
            compile_problem(self.world), 1, self.rng
        ).particles[0]
        #: The true state before the first action, then after each (for storyboards).
        self.trace: list[WorldState] = [self.state]

    def execute(self, action: Action, index: int) -> Observation:
        step = self.rollouts.step(index, action, self.state, self.rng)
        if step.failure is not None:
            raise ExecutionFailed(step.failure)
        assert step.outcome is not None
        self.state = step.state
        self.trace.append(self.state)
        return self.sensor.observe(action, step.outcome, self.sense_rng)
