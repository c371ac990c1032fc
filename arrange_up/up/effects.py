"""The effects of place and push in unified-planning: one thin module.

unified-planning 1.3 expresses effects computed by foreign code as *simulated effects*
(``SimulatedEffect(fluents, function)``); upstream is replacing them with "interpreted
functions". Everything that depends on that mechanism lives here, so the switch touches one
module: :func:`attach_effects` gives the ``place`` and ``push`` actions built by
:func:`arrange_up.up.compile.to_up` their simulated effects, and :class:`PoseFluents` converts
between a UP state and an arrange-up :class:`~arrange_up.model.world.WorldState`.

An effect resolves an action by the chosen semantics (``deterministic``: the nominal planner's
transition, i.e. arrange-up's physics with the noise-free draw of
:func:`arrange_up.model.world.nominal_noise`), exactly as the planner predicts it, and writes back:

* ``x``, ``y``, ``theta`` of the placed object (place) or of every movable object (push);
  lengths in inches and angles in **degrees**, as exact ``Fraction`` constants rounded to 9
  decimals (``Real(Fraction("9.088"))``, never binary fractions of floats);
* angles wrapped as the planner's beliefs store them (:class:`arrange_up.belief.states.AngleFrame`):
  into the shape's symmetry period around the absolute goal angle (else around 0), so a goal
  interval ``target ± tolerance`` on ``theta`` agrees with the planner's goal test, which treats
  angles modulo the symmetry (a square block turned 90 degrees is the same block);
* for a relative goal, ``rel_x``/``rel_y``/``rel_theta`` of every goal part: its pose in the
  reference part's frame, the angle wrapped into the part's period around its relative target
  (0 while the part or the reference is off the table).

An action the semantics refuses (a part pushed off the table, a simulation that never comes to
rest) raises ``UPInvalidActionError``: UP's simulator then treats it as inapplicable and its
``SequentialPlanValidator`` reports the plan INVALID with the reason.

The effect callables keep the :class:`~arrange_up.model.problem.ArrangementProblem` they were made
for (``problem``) and a fingerprint of the UP problem's content (``fingerprint``), which is how
:func:`arrange_up.up.compile.from_up` maps a compiled problem, or any clone of it, back.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from unified_planning.exceptions import UPInvalidActionError
from unified_planning.model import SimulatedEffect

from arrange_up.belief.states import ParticleBelief, symmetry_period, wrap_angle
from arrange_up.geometry.se2 import relative
from arrange_up.model.problem import ArrangementProblem, problem_hash
from arrange_up.model.world import Action, Place, Push, WorldState
from arrange_up.transitions import make_semantics

__all__ = [
    "NOMINAL_SEMANTICS",
    "PoseFluents",
    "TransitionEffect",
    "attach_effects",
    "check_semantics",
    "exact",
    "exact_degrees",
]

#: Semantics names :func:`attach_effects` accepts. A UP state is one world state, so only the
#: single-particle, noise-free semantics can be compiled into effects; ``nominal`` is an alias.
NOMINAL_SEMANTICS: tuple[str, ...] = ("deterministic", "nominal")


def exact(value: float) -> Fraction:
    """A float as the exact decimal it stands for, to 9 decimals: ``0.1 -> Fraction(1, 10)``."""
    return Fraction(str(round(float(value), 9)))


def exact_degrees(radians: float) -> Fraction:
    """An angle in radians as exact degrees (9 decimals)."""
    return exact(math.degrees(float(radians)))


@dataclass(frozen=True, eq=False)
class PoseFluents:
    """The UP fluent expressions of one compiled problem, by object name.

    ``fluents`` holds the UP ``Fluent`` objects by name (``x``, ``y``, ``theta``,
    ``on_table``); ``movable`` lists the non-obstacle objects in problem order; ``rel`` maps
    each part of a relative goal to its ``(rel_x, rel_y, rel_theta)`` expressions (empty for
    absolute goals).
    """

    fluents: Mapping[str, Any]
    movable: tuple[str, ...]
    on_table: Mapping[str, Any]
    x: Mapping[str, Any]
    y: Mapping[str, Any]
    theta: Mapping[str, Any]
    rel: Mapping[str, tuple[Any, Any, Any]]

    def read(self, problem: ArrangementProblem, state: Any) -> WorldState:
        """The world state held by a UP ``state`` (inches, radians)."""
        poses = {}
        for name in self.movable:
            if state.get_value(self.on_table[name]).bool_constant_value():
                poses[name] = (
                    float(state.get_value(self.x[name]).constant_value()),
                    float(state.get_value(self.y[name]).constant_value()),
                    math.radians(float(state.get_value(self.theta[name]).constant_value())),
                )
        return WorldState.from_mapping(problem, poses)

    def values(
        self, problem: ArrangementProblem, world: WorldState, names: Sequence[str] | None = None
    ) -> dict[Any, Fraction]:
        """Exact values of the pose fluents of ``names`` (default: every object in ``world``)
        and of the relative-goal fluents, for ``world``. Angles are written as stored (the
        caller passes canonical states) except the relative ones, wrapped here."""
        out: dict[Any, Fraction] = {}
        for name in world.names() if names is None else names:
            pose = world.pose(name)
            if pose is None:
                continue
            out[self.x[name]] = exact(pose[0])
            out[self.y[name]] = exact(pose[1])
            out[self.theta[name]] = exact_degrees(pose[2])
        out.update(self.relative_values(problem, world))
        return out

    def relative_values(
        self, problem: ArrangementProblem, world: WorldState
    ) -> dict[Any, Fraction]:
        goal = problem.goal
        if goal.reference is None:
            return {}
        out: dict[Any, Fraction] = {}
        ref = world.pose(goal.reference)
        for part, (fx, fy, ftheta) in self.rel.items():
            pose = world.pose(part)
            if ref is None or pose is None:
                out[fx] = out[fy] = out[ftheta] = Fraction(0)
                continue
            rx, ry, _ = relative(ref, pose)
            period = symmetry_period(problem.object(part).shape)
            theta = wrap_angle(pose[2] - ref[2], goal.target(part)[2], period)
            out[fx] = exact(rx)
            out[fy] = exact(ry)
            out[ftheta] = exact_degrees(theta)
        return out


class TransitionEffect:
    """The function of one action's simulated effect: ``(up_problem, state, params) -> values``.

    ``kind`` is ``"place"`` or ``"push"``. It returns values in the order of its
    ``SimulatedEffect``'s fluents: for a place the parameter-dependent ``x(o)``, ``y(o)``,
    ``theta(o)``; then ``x``, ``y``, ``theta`` of each object named in ``written`` (a push:
    every movable object); then the relative-goal fluents.
    The transition model is built on first use, so compiling stays cheap and the callable
    pickles (UP's parallel engines pickle problems).
    """

    def __init__(
        self,
        problem: ArrangementProblem,
        semantics: str,
        kind: str,
        pose_fluents: PoseFluents,
        written: Sequence[str],
    ) -> None:
        self.problem = problem
        self.semantics = semantics
        self.kind = kind
        self.pose_fluents = pose_fluents
        self.written = tuple(written)
        self.fingerprint: str | None = None  # set by compile.to_up once the problem is complete
        self._model: Any = None
        self._content: str | None = None

    # Two compilations of the same problem (same content hash, wherever it was read from) give
    # equal effects, hence equal UP actions: a plan made for one ``to_up(problem)`` validates
    # against another.
    def _key(self) -> tuple[Any, ...]:
        if self._content is None:
            self._content = problem_hash(self.problem)
        return (self.kind, self.semantics, self.written, self._content)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, TransitionEffect) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash((self.kind, self.semantics, self.written, self.problem.name))

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state["_model"] = None
        return state

    # -- the effect ----------------------------------------------------------------------------
    def __call__(self, up_problem: Any, state: Any, params: Mapping[Any, Any]) -> list[Any]:
        values = {_name(p): v for p, v in params.items()}
        action = self.action(values)
        world = self.pose_fluents.read(self.problem, state)
        after = self.model().apply(ParticleBelief((world,)), action)
        if after is None:
            raise UPInvalidActionError(
                f"{action} fails under the {self.semantics!r} semantics of problem "
                f"{self.problem.name!r}: a part or fixture would leave the table or the "
                "simulation does not come to rest"
            )
        (result,) = after.particles
        em = up_problem.environment.expression_manager
        out = []
        if self.kind == "place":
            assert isinstance(action, Place)
            pose = result.pose(action.obj)
            assert pose is not None
            out += [em.Real(exact(pose[0])), em.Real(exact(pose[1]))]
            out.append(em.Real(exact_degrees(pose[2])))
        computed = self.pose_fluents.values(self.problem, result, self.written)
        for name in self.written:
            for table in (self.pose_fluents.x, self.pose_fluents.y, self.pose_fluents.theta):
                fluent = table[name]
                # an object off the table keeps whatever its (meaningless) pose fluents hold
                value = computed.get(fluent)
                out.append(em.Real(value) if value is not None else state.get_value(fluent))
        relative = self.pose_fluents.relative_values(self.problem, result)
        for triple in self.pose_fluents.rel.values():
            out += [em.Real(relative[f]) for f in triple]
        return out

    def action(self, values: Mapping[str, Any]) -> Action:
        """The arrange-up action meant by the actual parameters (UP constants, degrees)."""

        def num(key: str) -> float:
            return float(values[key].constant_value())

        def obj(key: str) -> str:
            value = values[key]  # an object expression as UP passes it, or an Object
            return str(value.object().name if hasattr(value, "object") else value.name)

        pose = (num("px"), num("py"), math.radians(num("ptheta")))
        if self.kind == "place":
            return Place(obj("o"), pose)
        return Push(obj("m"), pose, num("distance"))

    def model(self) -> Any:
        if self._model is None:
            self._model = make_semantics("deterministic", self.problem, particles=1, seed=0)
        return self._model


def check_semantics(semantics: str) -> None:
    """Raise ``ValueError`` unless ``semantics`` can be compiled into effects."""
    if semantics not in NOMINAL_SEMANTICS:
        raise ValueError(
            f"semantics {semantics!r} cannot be compiled into unified-planning effects: a UP "
            f"state is one world state, so only {' / '.join(NOMINAL_SEMANTICS)} (one particle, "
            "no noise) can be; plan with other semantics through the 'arrange-up' engine's "
            "'semantics' parameter"
        )


def attach_effects(
    problem: ArrangementProblem,
    semantics: str,
    place: Any,
    push: Any,
    pose_fluents: PoseFluents,
) -> tuple[TransitionEffect, TransitionEffect]:
    """Give the ``place`` and ``push`` actions of a compiled problem their simulated effects.

    Raises ``ValueError`` for a semantics that cannot be compiled into effects.
    """
    check_semantics(semantics)
    rel = [f for triple in pose_fluents.rel.values() for f in triple]

    obj = place.parameter("o")
    place_fluents = [pose_fluents.fluents[key](obj) for key in ("x", "y", "theta")]
    place_effect = TransitionEffect(problem, semantics, "place", pose_fluents, ())
    place.set_simulated_effect(SimulatedEffect(place_fluents + rel, place_effect))

    # every movable object: a push may move any part, fixture or manipulator on the table
    pushed = list(pose_fluents.movable)
    push_fluents = [
        table[name]
        for name in pushed
        for table in (pose_fluents.x, pose_fluents.y, pose_fluents.theta)
    ]
    push_effect = TransitionEffect(problem, semantics, "push", pose_fluents, pushed)
    push.set_simulated_effect(SimulatedEffect(push_fluents + rel, push_effect))
    return place_effect, push_effect


def _name(parameter: Any) -> str:
    return str(getattr(parameter, "name", parameter))
