"""Belief update: the planner's beliefs conditioned on what was sensed.

Particle beliefs (:class:`ParticleFilter`). After an action, every particle is propagated
through it with its own noise drawn from the problem's model, exactly as a rollout executes
an action (:meth:`arrange_up.evaluation.rollouts.Rollouts.step`: the same physics, the same
failures); a particle whose prediction failed (the real action did not) is dropped. Each
survivor predicts the observation noise-free (:meth:`Sensor.predict
<arrange_up.execution.observations.Sensor.predict>`) and is weighted by the observation's
likelihood, then the particles are resampled (systematic resampling) back to the filter's
count.

The likelihood is the sensor's Gaussian widened by a kernel: a few hundred particles cannot
represent a 0.01-inch encoder reading (almost none would land within its noise, and the
weights would rest on one particle or none), so each component's variance is the sensor's
plus the square of a kernel bandwidth, Silverman's rule on the spread of the predictions
(``1.06 * std * n ** -0.2``), as a regularised particle filter smooths its particles.

**Model failure.** The observation is *explained* when some particle predicts it within
``gate`` (4) widened standard deviations in every component. When none does, the world did
something the model does not allow (a placement outside the modelled uncertainty, the failure
the thesis saw on its robot), and :class:`Update` reports a :class:`ModelFailure`. It is not
hidden, and the filter then tries to recover: it propagates the action again with the
problem's noise ``scale`` times wider (2, then 4;
:func:`~arrange_up.execution.executor.scaled_problem`) and the objects already on the table
displaced within ``scale - 1`` times the place uncertainty, and keeps the first of these that
explains the observation (the failure records the scale); when none does, it keeps the
widest, weighted all the same (the record says ``recovered: false``). With ``adapt`` (the
default) the world has shown itself noisier than modelled, so the filter goes on propagating
with the scale that explained it (:attr:`ParticleFilter.scale`), and the loop checks and
replans with that scale too.

Interval beliefs (CBST, :func:`intersect_intervals`): a ``poses`` observation bounds each
object to within ``gate`` standard deviations of what was seen; the belief's box is
intersected with that bound, and an empty intersection is a model failure. A ``paddle``
observation bounds no part's pose directly, so it leaves an interval belief unchanged.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from arrange_up.belief.compiled import compile_problem
from arrange_up.belief.states import (
    IntervalBelief,
    ObjectInterval,
    ParticleBelief,
    sample_initial_particles,
)
from arrange_up.evaluation.rollouts import Rollouts
from arrange_up.execution.executor import scaled_problem
from arrange_up.execution.observations import Observation, Sensor
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action, WorldState

__all__ = [
    "DEFAULT_GATE",
    "RECOVERY_SCALES",
    "ModelFailure",
    "ParticleFilter",
    "Update",
    "intersect_intervals",
]

#: Widened standard deviations within which some particle must predict an observation.
DEFAULT_GATE = 4.0
#: The noise scales a filter tries, in order, when the model cannot explain an observation.
RECOVERY_SCALES: tuple[float, ...] = (2.0, 4.0)


@dataclass(frozen=True)
class ModelFailure:
    """An observation the belief could not explain.

    ``action`` is the episode's action index after which it was sensed; ``excess`` the best
    particle's largest residual in widened standard deviations (``inf`` when every particle's
    prediction failed); ``scale`` the noise scale that explained it on recovery (None: none
    did, ``recovered`` is False).
    """

    action: int
    excess: float
    scale: float | None

    @property
    def recovered(self) -> bool:
        return self.scale is not None

    def to_json(self) -> dict[str, Any]:
        return {
            "action": self.action,
            "excess": None if not np.isfinite(self.excess) else self.excess,
            "scale": self.scale,
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> ModelFailure:
        excess = data["excess"]
        scale = data["scale"]
        return cls(
            int(data["action"]),
            float("inf") if excess is None else float(excess),
            None if scale is None else float(scale),
        )


@dataclass(frozen=True)
class Update:
    """One belief update: the ``predicted`` belief (the particles propagated through the
    action, before weighting; None when every prediction failed), the ``posterior``, the
    effective sample size of the weights (``ess``, the particle count when the observation
    was uninformative), and the model failure, if any."""

    predicted: ParticleBelief | None
    posterior: ParticleBelief
    ess: float
    failure: ModelFailure | None = None


class ParticleFilter:
    """The particle belief of one episode, conditioned on each observation (module docstring).

    ``rng`` is the filter's only source of randomness (propagation noise and resampling), so
    an episode's beliefs are reproducible from its seed.
    """

    def __init__(
        self,
        problem: ArrangementProblem,
        sensor: Sensor,
        particles: int,
        rng: np.random.Generator,
        *,
        gate: float = DEFAULT_GATE,
        recovery: Sequence[float] = RECOVERY_SCALES,
        landing: str = "fail",
        adapt: bool = True,
    ) -> None:
        if particles < 1:
            raise ValueError(f"a particle filter needs at least one particle, got {particles}")
        self.problem = problem
        self.sensor = sensor
        self.particles = particles
        self.rng = rng
        self.gate = gate
        self.recovery = tuple(recovery)
        self.landing = landing
        self.adapt = adapt
        #: The noise scale the filter propagates with: 1 (the problem's model) until a model
        #: failure was recovered at a wider scale, with ``adapt``, then that scale.
        self.scale = 1.0
        self.compiled = compile_problem(problem)
        self.frame = self.compiled.frame
        self._rollouts = {1.0: Rollouts(problem, (), landing=landing)}

    def initial(self) -> ParticleBelief:
        """The prior: particles drawn from the problem's initial intervals."""
        return sample_initial_particles(self.compiled, self.particles, self.rng)

    def update(
        self, belief: ParticleBelief, action: Action, index: int, observation: Observation
    ) -> Update:
        """``belief`` after ``action`` (the episode's ``index``-th) and ``observation``."""
        states, predictions = self._predict(belief.particles, action, index, self.scale)
        weights, excess = self._weigh(observation, predictions)
        failure = None
        if excess > self.gate:
            scale = None
            for factor in (f for f in self.recovery if f > self.scale):
                wide_states, wide_predictions = self._predict(
                    self._displaced(belief.particles, factor), action, index, factor
                )
                wide_weights, wide_excess = self._weigh(observation, wide_predictions)
                if wide_states or not states:
                    states, weights = wide_states, wide_weights
                if wide_excess <= self.gate:
                    scale = factor
                    break
            failure = ModelFailure(index, excess, scale)
            if scale is not None and self.adapt:
                self.scale = scale
        if not states:
            # Nothing the model (even widened) predicts survives the action: keep the belief
            # as it was; the failure says so.
            return Update(None, belief, 0.0, failure)
        predicted = ParticleBelief(tuple(states))
        if weights is None:
            posterior = self._resample(states, np.full(len(states), 1.0 / len(states)))
            return Update(predicted, posterior, float(len(states)), failure)
        ess = float(1.0 / np.sum(weights * weights))
        return Update(predicted, self._resample(states, weights), ess, failure)

    # -- the steps ----------------------------------------------------------------------------
    def _step(self, factor: float) -> Rollouts:
        hit = self._rollouts.get(factor)
        if hit is None:
            hit = self._rollouts[factor] = Rollouts(
                scaled_problem(self.problem, factor), (), landing=self.landing
            )
        return hit

    def _predict(
        self, particles: Sequence[WorldState], action: Action, index: int, factor: float
    ) -> tuple[list[WorldState], list[Observation]]:
        """The surviving particles after ``action`` under noise ``factor`` times the model's,
        with their noise-free observations."""
        rollouts = self._step(factor)
        states, predictions = [], []
        for state in particles:
            step = rollouts.step(index, action, state, self.rng)
            if step.failure is None and step.outcome is not None:
                states.append(self.frame.canonical(step.state))
                predictions.append(self.sensor.predict(action, step.outcome))
        return states, predictions

    def _weigh(
        self, observation: Observation, predictions: list[Observation]
    ) -> tuple[np.ndarray | None, float]:
        """Normalised weights (None: the observation is uninformative, all equal) and the best
        prediction's largest residual in widened standard deviations (``inf`` when there is
        no prediction, 0 when uninformative)."""
        if not predictions:
            return None, float("inf")
        if not observation.informative:
            return None, 0.0
        found = self.sensor.residuals(observation, predictions)
        if found is None:
            return None, 0.0
        delta, sigma = found
        n = len(predictions)
        bandwidth = 1.06 * delta.std(axis=0) * n**-0.2
        z = delta / np.sqrt(sigma * sigma + bandwidth * bandwidth)
        excess = float(np.abs(z).max(axis=1).min())
        log_w = -0.5 * np.sum(z * z, axis=1)
        w = np.exp(log_w - log_w.max())
        return w / w.sum(), excess

    def _displaced(self, particles: Sequence[WorldState], factor: float) -> list[WorldState]:
        """Every object on the table moved uniformly within ``factor - 1`` times the place
        uncertainty: placements the model did not allow for."""
        half = np.asarray(self.problem.uncertainty.place, dtype=float) * (factor - 1.0)
        out = []
        for state in particles:
            offsets = self.rng.uniform(-1.0, 1.0, size=(len(state.poses), 3)) * half
            out.append(
                WorldState(
                    tuple(
                        (name, tuple(float(v + d) for v, d in zip(pose, offset, strict=True)))  # type: ignore[misc]
                        for (name, pose), offset in zip(state.poses, offsets, strict=True)
                    )
                )
            )
        return out

    def _resample(self, states: Sequence[WorldState], weights: np.ndarray) -> ParticleBelief:
        """Systematic resampling of ``states`` by ``weights`` to the filter's count."""
        n = self.particles
        positions = (self.rng.random() + np.arange(n)) / n
        cumulative = np.cumsum(weights)
        cumulative[-1] = 1.0
        chosen = np.searchsorted(cumulative, positions, side="right")
        return ParticleBelief(tuple(states[int(i)] for i in chosen))


def intersect_intervals(
    belief: IntervalBelief, observation: Observation, sensor: Sensor, gate: float = DEFAULT_GATE
) -> tuple[IntervalBelief, tuple[str, ...]]:
    """An interval belief intersected with what a ``poses`` observation bounds: each observed
    object's box with ``seen ± gate * sigma`` (angles compared modulo the object's symmetry
    period). Returns the new belief and the objects whose intersection was empty (a model
    failure; their box is replaced by the observation's bound). A ``paddle`` observation or
    none leaves the belief unchanged."""
    if observation.poses is None:
        return belief, ()
    seen = dict(observation.poses)
    sigma = np.asarray(sensor.poses_sigma, dtype=float) * gate
    objects, empty = [], []
    for name, interval in belief.objects:
        pose = seen.get(name)
        if pose is None:
            objects.append((name, interval))
            continue
        centre = np.asarray(pose, dtype=float)
        period = sensor.periods.get(name, 2.0 * np.pi)
        # the observed angle moved to the period nearest the box's centre
        centre[2] += period * np.round((interval.center[2] - centre[2]) / period)
        low = np.maximum(np.asarray(interval.low), centre - sigma)
        high = np.minimum(np.asarray(interval.high), centre + sigma)
        if np.any(low > high):
            empty.append(name)
            low, high = centre - sigma, centre + sigma
        objects.append((name, ObjectInterval.from_bounds(low.tolist(), high.tolist())))
    return IntervalBelief(tuple(objects)), tuple(empty)
