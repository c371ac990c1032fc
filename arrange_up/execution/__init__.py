"""Closed-loop execution: execute a plan with sensing, update the belief, replan (thesis §3.3,
§5.2: "a belief-space replanning paradigm that adds some sensing, such as the final position
of the paddle after a push").

One concern per module:

* :mod:`~arrange_up.execution.executor`: the :class:`Executor` protocol a robot integration
  implements (execute one action, return an observation) and the :class:`SimulatedExecutor`.
* :mod:`~arrange_up.execution.observations`: observations (``paddle``, ``poses``, ``none``)
  and their noise models (:class:`Sensor`).
* :mod:`~arrange_up.execution.belief`: conditioning a particle belief on an observation
  (:class:`ParticleFilter`; unexplained observations are :class:`ModelFailure` records) and
  intersecting an interval belief with what an observation bounds.
* :mod:`~arrange_up.execution.replanning`: the loop (:class:`ClosedLoop`), the library call a
  robot integration uses.
* :mod:`~arrange_up.execution.episodes`: many simulated episodes, judged and summarised
  (``arrange-up execute``).

The protocol and a robot bridge's outline: ``docs/execution.md``.
"""

from arrange_up.execution.belief import ModelFailure, ParticleFilter, Update, intersect_intervals
from arrange_up.execution.episodes import (
    ClosedLoopResult,
    EpisodeRecord,
    run_episode,
    run_episodes,
    sensor_for,
)
from arrange_up.execution.executor import (
    ExecutionFailed,
    Executor,
    SimulatedExecutor,
    scaled_problem,
)
from arrange_up.execution.observations import SENSES, Observation, Sensor
from arrange_up.execution.replanning import ClosedLoop, ClosedLoopSettings, LoopOutcome, Replan

__all__ = [
    "SENSES",
    "ClosedLoop",
    "ClosedLoopResult",
    "ClosedLoopSettings",
    "EpisodeRecord",
    "ExecutionFailed",
    "Executor",
    "LoopOutcome",
    "ModelFailure",
    "Observation",
    "ParticleFilter",
    "Replan",
    "Sensor",
    "SimulatedExecutor",
    "Update",
    "intersect_intervals",
    "run_episode",
    "run_episodes",
    "scaled_problem",
    "sensor_for",
]
