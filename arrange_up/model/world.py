"""World states, primitive actions and one draw of the world's noise.

These are the values the physics consumes and produces (thesis §1.2.1): a :class:`WorldState`
says which movable objects are on the table and where; an action is a :class:`Place`, a
:class:`Push` or a :class:`Pick`; an :class:`ActionNoise` is one draw of everything
nondeterministic about executing one action (pose noise, friction, densities).

Randomness is always passed in as a :class:`numpy.random.Generator`; nothing here keeps global
state, so a seed fully determines a rollout.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from arrange_up.model.problem import ArrangementProblem, HalfWidths, ObjectKind, Pose, as_triple


@dataclass(frozen=True)
class WorldState:
    """Poses of the movable objects currently on the table.

    ``poses`` is ordered as the problem declares its objects, so equal states compare and hash
    equal and the physics builds bodies in a fixed order (needed for bit-identical replay).
    Obstacles are not listed (they never move). A push lifts its manipulator off again, so a
    manipulator is listed only if the problem starts with it on the table.
    """

    poses: tuple[tuple[str, Pose], ...]

    @classmethod
    def from_mapping(cls, problem: ArrangementProblem, poses: Mapping[str, Pose]) -> WorldState:
        """Build a state with the problem's object order from a name -> pose mapping."""
        unknown = set(poses) - {spec.name for spec in problem.objects}
        if unknown:
            raise KeyError(f"unknown objects {sorted(unknown)} in problem {problem.name!r}")
        return cls(
            tuple(
                (spec.name, as_triple(float(v) for v in poses[spec.name]))
                for spec in problem.objects
                if spec.name in poses
            )
        )

    def as_dict(self) -> dict[str, Pose]:
        return dict(self.poses)

    def names(self) -> tuple[str, ...]:
        return tuple(name for name, _ in self.poses)

    def pose(self, name: str) -> Pose | None:
        for other, pose in self.poses:
            if other == name:
                return pose
        return None

    def __contains__(self, name: object) -> bool:
        return any(other == name for other, _ in self.poses)


@dataclass(frozen=True)
class Place:
    """Put ``obj`` (a part or fixture not on the table) down at ``pose``."""

    obj: str
    pose: Pose


@dataclass(frozen=True)
class Push:
    """Put ``manipulator`` down at approach ``pose``, drive it ``distance`` inches
    perpendicular to its long side, wait until everything is at rest, lift it off."""

    manipulator: str
    pose: Pose
    distance: float


@dataclass(frozen=True)
class Pick:
    """Remove ``obj`` from the table (no uncertainty, thesis §1.2.2)."""

    obj: str


Action = Place | Push | Pick


@dataclass(frozen=True)
class ActionNoise:
    """One draw of the nondeterminism of executing one action.

    ``pose_offset`` is added to the commanded pose (the placed pose for a place, the approach
    pose for a push); the domain parameters hold for the whole action.
    """

    pose_offset: HalfWidths = (0.0, 0.0, 0.0)
    friction: float = 0.5
    part_density: float = 0.125
    manipulator_density: float = 0.4


def _uniform_offset(rng: np.random.Generator, half: HalfWidths) -> HalfWidths:
    u = rng.uniform(-1.0, 1.0, size=3)
    return (float(u[0] * half[0]), float(u[1] * half[1]), float(u[2] * half[2]))


def draw_noise(
    problem: ArrangementProblem, action: Action, rng: np.random.Generator
) -> ActionNoise:
    """Draw the noise of one action from the problem's uncertainty, uniformly.

    Always consumes the same number of random values whatever the action, so a rollout's
    random stream does not shift when an action changes kind.
    """
    unc = problem.uncertainty
    offset_place = _uniform_offset(rng, unc.place)
    offset_push = _uniform_offset(rng, unc.push)
    friction = float(rng.uniform(*unc.friction))
    part_density = float(rng.uniform(*unc.part_density))
    manipulator_density = float(rng.uniform(*unc.manipulator_density))
    if isinstance(action, Place):
        offset = offset_place
    elif isinstance(action, Push):
        offset = offset_push
    else:
        offset = (0.0, 0.0, 0.0)
    return ActionNoise(offset, friction, part_density, manipulator_density)


def nominal_noise(problem: ArrangementProblem) -> ActionNoise:
    """The noise-free draw: no pose offset, every domain parameter at the middle of its range."""
    unc = problem.uncertainty
    return ActionNoise(
        (0.0, 0.0, 0.0),
        0.5 * (unc.friction[0] + unc.friction[1]),
        0.5 * (unc.part_density[0] + unc.part_density[1]),
        0.5 * (unc.manipulator_density[0] + unc.manipulator_density[1]),
    )


def nominal_initial_state(problem: ArrangementProblem) -> WorldState:
    """The initial state at the nominal poses (no uncertainty)."""
    return WorldState.from_mapping(problem, {e.name: e.pose for e in problem.initial})


def movable_names(problem: ArrangementProblem) -> tuple[str, ...]:
    """Names of objects that can appear in a world state: everything but obstacles."""
    return tuple(spec.name for spec in problem.objects if spec.kind is not ObjectKind.OBSTACLE)
