"""What every action generator shares: the push directions, the distance resolutions and the
options the planner sets per semantics (:class:`PushOptions`)."""

from __future__ import annotations

from dataclasses import dataclass

from arrange_up.model.problem import Pose

#: Direction name -> unit vector in the world frame.
DIRECTIONS: dict[str, tuple[float, float]] = {
    "+x": (1.0, 0.0),
    "-x": (-1.0, 0.0),
    "+y": (0.0, 1.0),
    "-y": (0.0, -1.0),
}
#: The wall each push direction heads for.
WALL_AHEAD = {"+x": "right", "-x": "left", "+y": "top", "-y": "bottom"}
#: ``(axis, sign)`` -> direction name.
DIRECTION_OF = {(0 if ux else 1, int(ux + uy)): name for name, (ux, uy) in DIRECTIONS.items()}
#: Gap kept between the manipulator's approach shadow and the part's shadow (inches).
APPROACH_GAP = 0.02
#: Minimum useful push (inches): shorter candidates are dropped.
MIN_PUSH = 0.05
#: Candidate distances closer than this are considered the same (inches).
DISTANCE_RESOLUTION = 0.01


@dataclass(frozen=True)
class PushOptions:
    """The push rules the planner switches per semantics (:mod:`arrange_up.planning.actions`).

    Attributes
    ----------
    unclipped_pushes
        Also offer a push from the nearest position that clips no shadow ahead
        (:mod:`~arrange_up.planning.generators.approach`).
    settled_wall_pushes
        Offer pushes to a wall (or fence) even once the part and its train lie within their
        goal intervals along the push (:mod:`~arrange_up.planning.generators.distances`).
    compressed_wall_pushes
        Under the compliant controller, send a push to a wall to the front of the compressed
        train plus its overdrive, not to the wall itself
        (:mod:`~arrange_up.planning.generators.stall`).
    solve_distances
        Solve a push's distance for its part's travel in noise-free simulations
        (:mod:`~arrange_up.planning.generators.stall`).
    clearance_pushes
        Offer the mating push stopped short of the notch
        (:mod:`~arrange_up.planning.generators.mating_pushes`).
    """

    unclipped_pushes: bool = False
    settled_wall_pushes: bool = False
    compressed_wall_pushes: bool = False
    solve_distances: bool = True
    clearance_pushes: bool = True


def clean_pose(pose: Pose) -> Pose:
    """Round a generated pose's position to 1e-6 in so plans print and compare cleanly. The
    angle is kept exact: it comes from exact axis directions (``-pi/2`` converts to exactly
    -90 degrees only unrounded)."""
    return (round(float(pose[0]), 6) + 0.0, round(float(pose[1]), 6) + 0.0, float(pose[2]) + 0.0)
