"""What a robot senses after an action, and the noise of its sensors.

Three senses (:data:`SENSES`):

* ``paddle``: after a push, the manipulator's pose when the push ended, just before it is
  lifted off (:attr:`~arrange_up.physics.simulation.StepOutcome.manipulator_pose`), as a
  robot's own joint encoders give it. A place or a pick observes nothing. Noise: Gaussian,
  standard deviation :data:`PADDLE_SIGMA` (0.01 in in x and y, 0.5 degree in angle: an arm's
  forward kinematics at the wrist, after calibration).
* ``poses``: after every action, the pose of every object on the table, as a camera over the
  table gives them. Noise: Gaussian, :data:`POSES_SIGMA` (0.02 in, 1 degree: a fiducial or
  model-based pose estimate at arm's length).
* ``none``: nothing; closed-loop execution then only replans on what it predicts.

An :class:`Observation` is the same value whether a real robot or the simulated executor made
it; a :class:`Sensor` both draws noisy observations from a simulated outcome (the simulated
executor's side) and compares an observation with a particle's noise-free prediction (the
belief update's side), so the noise model is written once.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from arrange_up.model.problem import Pose
from arrange_up.model.world import Action, Push
from arrange_up.physics.simulation import StepOutcome

__all__ = [
    "PADDLE_SIGMA",
    "POSES_SIGMA",
    "SENSES",
    "Observation",
    "Sensor",
]

#: The senses a closed-loop execution can use (see the module docstring).
SENSES: tuple[str, ...] = ("paddle", "poses", "none")
#: Standard deviation of a paddle observation: (in, in, rad).
PADDLE_SIGMA: tuple[float, float, float] = (0.01, 0.01, math.radians(0.5))
#: Standard deviation of each observed part pose: (in, in, rad).
POSES_SIGMA: tuple[float, float, float] = (0.02, 0.02, math.radians(1.0))


@dataclass(frozen=True)
class Observation:
    """What was sensed after one action (internal units: inches, radians).

    ``paddle`` is the manipulator's final pose after a push (``paddle`` sense), ``poses`` the
    pose of every object on the table (``poses`` sense); each is ``None`` when not sensed. An
    observation with neither is uninformative: the belief update leaves the prediction as it
    is.
    """

    paddle: Pose | None = None
    poses: tuple[tuple[str, Pose], ...] | None = None

    @property
    def informative(self) -> bool:
        return self.paddle is not None or self.poses is not None

    def to_json(self) -> dict[str, Any]:
        data: dict[str, Any] = {}
        if self.paddle is not None:
            data["paddle"] = list(self.paddle)
        if self.poses is not None:
            data["poses"] = {name: list(pose) for name, pose in self.poses}
        return data

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Observation:
        paddle = data.get("paddle")
        poses = data.get("poses")
        return cls(
            None if paddle is None else tuple(float(v) for v in paddle),  # type: ignore[arg-type]
            None
            if poses is None
            else tuple((name, tuple(float(v) for v in pose)) for name, pose in poses.items()),  # type: ignore[misc]
        )


def _wrap(delta: np.ndarray, period: np.ndarray) -> np.ndarray:
    """Angle differences folded into ``[-period/2, period/2)``."""
    return (delta + 0.5 * period) % period - 0.5 * period


@dataclass(frozen=True)
class Sensor:
    """One sense and its noise: draws observations and scores predictions against them.

    ``periods`` maps each object to its rotational symmetry period (an observed square at 0
    and at 90 degrees is the same square): part angle differences are folded by it.
    """

    sense: str
    periods: Mapping[str, float]
    paddle_sigma: tuple[float, float, float] = PADDLE_SIGMA
    poses_sigma: tuple[float, float, float] = POSES_SIGMA

    def __post_init__(self) -> None:
        if self.sense not in SENSES:
            raise ValueError(f"unknown sense {self.sense!r}; expected one of {', '.join(SENSES)}")

    def predict(self, action: Action, outcome: StepOutcome) -> Observation:
        """The noise-free observation of ``outcome`` (the result of executing ``action``)."""
        if self.sense == "paddle":
            if isinstance(action, Push) and outcome.manipulator_pose is not None:
                return Observation(paddle=tuple(outcome.manipulator_pose))  # type: ignore[arg-type]
            return Observation()
        if self.sense == "poses":
            return Observation(poses=outcome.state.poses)
        return Observation()

    def observe(
        self, action: Action, outcome: StepOutcome, rng: np.random.Generator
    ) -> Observation:
        """A noisy observation of ``outcome``: the prediction plus Gaussian noise drawn from
        ``rng`` (the same number of draws for the same observation shape)."""
        exact = self.predict(action, outcome)
        paddle = poses = None
        if exact.paddle is not None:
            noise = rng.normal(0.0, self.paddle_sigma)
            paddle = tuple(float(v + e) for v, e in zip(exact.paddle, noise, strict=True))
        if exact.poses is not None:
            noisy = []
            for name, pose in exact.poses:
                noise = rng.normal(0.0, self.poses_sigma)
                noisy.append((name, tuple(float(v + e) for v, e in zip(pose, noise, strict=True))))
            poses = tuple(noisy)
        return Observation(paddle, poses)  # type: ignore[arg-type]

    def vector(
        self, observation: Observation, names: tuple[str, ...]
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """``observation`` as one flat vector with, per component, the sensor's standard
        deviation and the angle period (0 for lengths): ``(values, sigma, period)``, or None
        when it is uninformative. ``names`` fixes the order of observed poses."""
        values: list[float] = []
        sigma: list[float] = []
        period: list[float] = []
        if observation.paddle is not None:
            values.extend(observation.paddle)
            sigma.extend(self.paddle_sigma)
            period.extend((0.0, 0.0, 2.0 * math.pi))
        if observation.poses is not None:
            seen = dict(observation.poses)
            for name in names:
                values.extend(seen[name])
                sigma.extend(self.poses_sigma)
                period.extend((0.0, 0.0, self.periods.get(name, 2.0 * math.pi)))
        if not values:
            return None
        return np.array(values), np.array(sigma), np.array(period)

    def residuals(
        self, observation: Observation, predictions: list[Observation]
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """Per prediction, the observation minus the prediction, component by component
        (angles folded by their period): an array ``(len(predictions), d)``, with the sensor's
        standard deviation per component (``d``). None when the observation is uninformative.

        Raises ``ValueError`` when the observation names other objects than a prediction (an
        object seen on the table that the belief does not have, or the other way round).
        """
        names = tuple(name for name, _ in observation.poses or ())
        target = self.vector(observation, names)
        if target is None:
            return None
        values, sigma, period = target
        rows = []
        for predicted in predictions:
            if observation.poses is not None and (
                predicted.poses is None or {n for n, _ in predicted.poses} != set(names)
            ):
                raise ValueError(
                    "the observation sees other objects on the table than the belief holds"
                )
            vector = self.vector(predicted, names)
            if vector is None or len(vector[0]) != len(values):
                raise ValueError("the observation senses something the prediction does not")
            rows.append(values - vector[0])
        delta = np.array(rows)
        angular = period > 0.0
        delta[:, angular] = _wrap(delta[:, angular], period[angular])
        return delta, sigma
