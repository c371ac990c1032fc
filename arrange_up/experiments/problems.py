"""The problems an experiment measures, driven by the controller it was asked for, and how that
controller is recorded (a ``controller`` column in every row and a ``controller`` setting of the
CSV, so that rows measured under different controllers are never mixed), with the physics
settings it resolves to (a ``physics`` setting: rows simulated with other settling and rest
settings are never mixed either)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

from arrange_up.io.domains import load
from arrange_up.model.problem import ArrangementProblem, driven_by
from arrange_up.physics.settings import DEFAULT_SETTINGS, push_crossing

__all__ = ["controller_setting", "driven_problems", "physics_setting"]


def driven_problems(names: Sequence[str], controller: str | None) -> dict[str, ArrangementProblem]:
    """Each problem of ``names`` (loaded once, in order), driven by a ``controller`` kind at its
    defaults (:func:`~arrange_up.model.problem.driven_by`), or by its own controller when
    ``controller`` is ``None``. Raises ``ValueError`` for an unknown kind."""
    return {
        name: load(name) if controller is None else driven_by(load(name), controller)
        for name in dict.fromkeys(names)
    }


def controller_setting(problems: Mapping[str, ArrangementProblem]) -> str:
    """The CSV setting naming the controller kind the problems are driven by (the kinds in
    alphabetical order, comma-separated, if they differ)."""
    return ",".join(sorted({problem.controller.kind.value for problem in problems.values()}))


#: Settings added after CSVs were first recorded, with the value that turns them off: left out
#: of the record when off, so that the rows of a controller whose physics they did not change
#: (the servo has no stall window) still resume.
_LATER_SETTINGS_OFF: dict[str, Any] = {"stall_window": 0.0, "compliant_in_solver": False}


def physics_setting(problems: Mapping[str, ArrangementProblem]) -> dict[str, dict[str, Any]]:
    """The CSV setting naming the physics settings the problems are simulated with: for each
    controller kind among them, the default settings as that kind resolves them
    (:meth:`~arrange_up.physics.settings.PhysicsSettings.for_controller`), a setting added
    later left out where it is off."""
    kinds = sorted({problem.controller.kind for problem in problems.values()}, key=str)
    record = {}
    for kind in kinds:
        values = dataclasses.asdict(DEFAULT_SETTINGS.for_controller(kind))
        for name, off in _LATER_SETTINGS_OFF.items():
            if values[name] == off:
                del values[name]
        if all(_short_pushes(p) for p in problems.values() if p.controller.kind is kind):
            del values["travel_margin"]
        record[kind.value] = values
    return record


def _short_pushes(problem: ArrangementProblem) -> bool:
    """Whether no push of ``problem`` can outlast ``max_time - travel_margin`` at its push
    speed (none travels further than :func:`~arrange_up.physics.settings.push_crossing`, as the
    simulation bounds it): then ``travel_margin``, a setting added after CSVs were first
    recorded, changes none of its pushes and is left out of the record, so that such rows
    still resume."""
    s = DEFAULT_SETTINGS
    speed = s.push_speed if problem.controller.speed is None else problem.controller.speed
    longest = max(
        (push_crossing(problem.table.size, spec.shape.radius) for spec in problem.manipulators),
        default=0.0,
    )
    return longest / speed <= s.max_time - s.travel_margin
