"""Compile an arrangement problem to a unified-planning ``Problem``, and map it back.

:func:`to_up` builds a UP model of an :class:`~arrange_up.model.problem.ArrangementProblem`:

* **Types** ``movable`` (every object that can be on or off the table) with subtypes
  ``placeable`` (``part``, ``fixture``) and ``manipulator``; ``obstacle`` for fixed objects
  (which have no fluents: they never move).
* **Fluents** of movables: ``on_table(o)`` (bool, default false) and the pose ``x(o)``,
  ``y(o)``, ``theta(o)`` (real, default 0, meaningless while ``o`` is off the table). For a
  relative goal also ``rel_x(p)``, ``rel_y(p)``, ``rel_theta(p)``: the pose of part ``p`` in the
  reference part's frame.
* **Actions** ``place(o - placeable, px, py, ptheta)``: precondition ``not on_table(o)``;
  ``push(m - manipulator, px, py, ptheta, distance)``: precondition ``not on_table(m)`` (the
  approach pose ``px, py, ptheta``; the push drives ``distance`` inches perpendicular to the
  manipulator's long side, then lifts it off); ``pick(o - movable)``: precondition
  ``on_table(o)``, effect ``not on_table(o)``. Place and push poses are real parameters; what
  they do to the poses is not symbolic: simulated effects resolve it by the chosen semantics
  (:mod:`arrange_up.up.effects`). Place also sets ``on_table(o)``.
* **Goals**, one condition each: ``on_table(p)`` and ``target - tol <= f(p) <= target + tol``
  for ``f`` in ``x``, ``y``, ``theta`` of each goal part (no ``theta`` condition when the
  tolerance allows any angle). A relative goal constrains ``rel_x``, ``rel_y``, ``rel_theta``
  instead, and needs ``on_table`` of the reference too. A fixture that starts off the table
  must end off it (``not on_table(f)``), as the planner's goal test says
  (:mod:`arrange_up.belief.goals`).

**Units.** The UP model uses **inches and degrees**, like the ``.pddl`` files, whatever the
problem file used: numbers a user reads in a UP plan are the numbers they would write. All
numbers are exact ``Fraction`` constants of the decimals they stand for (9 decimals), never the
binary fractions that Python floats would become.

**Angles modulo symmetry.** The planner treats an angle modulo the shape's rotational symmetry
(a square block turned 90 degrees is the same block). The effects therefore write ``theta`` wrapped
into the symmetry period around the goal angle (``rel_theta`` around the relative target), as
the planner's beliefs store it, so the interval conditions mean what the planner's goal test
means (see :mod:`arrange_up.up.effects`).

:func:`from_up` maps a UP problem back to the :class:`ArrangementProblem`: for one made by
:func:`to_up` (or a clone of one) through its effects, which carry the problem and a
fingerprint of the UP content (a problem edited after compiling is refused rather than
silently mapped back to the original); for one read by UP's ``PDDLReader`` by rebuilding it from
the PDDL vocabulary (:mod:`arrange_up.io.pddl`).

Only this module, :mod:`arrange_up.up.effects`, :mod:`arrange_up.io.pddl`,
:mod:`arrange_up.up.plan_writer` and the engines' modules (:mod:`arrange_up.up.engine_base`,
:mod:`~arrange_up.up.engine_io` and one module per engine) import unified-planning.
"""

from __future__ import annotations

import functools
import hashlib
import math
import re
from collections.abc import Sequence
from fractions import Fraction
from typing import Any

import unified_planning.model as m
from unified_planning.environment import get_environment
from unified_planning.model.problem_kind_versioning import LATEST_PROBLEM_KIND_VERSION
from unified_planning.plans import ActionInstance, SequentialPlan

from arrange_up.belief.states import AngleFrame
from arrange_up.io.pddl import problem_from_up
from arrange_up.io.pddl_domain import domain_pddl_text
from arrange_up.model.problem import ArrangementProblem, ObjectKind
from arrange_up.model.world import Action, Pick, Place, Push, nominal_initial_state
from arrange_up.up.effects import (
    NOMINAL_SEMANTICS,
    PoseFluents,
    TransitionEffect,
    attach_effects,
    check_semantics,
    exact,
    exact_degrees,
)

__all__ = [
    "ACTION_NAMES",
    "ARRANGE_UP_CORE_KIND",
    "FLUENT_NAMES",
    "NOMINAL_SEMANTICS",
    "READABLE_KIND",
    "TO_UP_KIND",
    "TYPE_NAMES",
    "equip_pddl_problem",
    "from_up",
    "made_by_to_up",
    "plan_from_up",
    "plan_to_up",
    "to_up",
]

TYPE_NAMES = ("movable", "placeable", "part", "fixture", "manipulator", "obstacle")
FLUENT_NAMES = ("on_table", "x", "y", "theta", "rel_x", "rel_y", "rel_theta")
ACTION_NAMES = ("place", "push", "pick")


def _kind(*extra: tuple[str, str]) -> m.ProblemKind:
    kind = m.ProblemKind(version=LATEST_PROBLEM_KIND_VERSION)
    kind.set_problem_class("ACTION_BASED")
    kind.set_problem_type("SIMPLE_NUMERIC_PLANNING")
    kind.set_typing("FLAT_TYPING")
    kind.set_typing("HIERARCHICAL_TYPING")
    kind.set_conditions_kind("NEGATIVE_CONDITIONS")
    kind.set_parameters("REAL_ACTION_PARAMETERS")
    kind.set_fluents_type("REAL_FLUENTS")
    kind.set_simulated_entities("SIMULATED_EFFECTS")
    for setter, feature in extra:
        getattr(kind, setter)(feature)
    return kind


#: The problem kind of every problem :func:`to_up` makes (the same for every arrange-up problem:
#: ``tests/up/test_engines.py`` checks it for each shipped domain).
TO_UP_KIND = _kind()
#: The widest kind :func:`from_up` can read: :data:`TO_UP_KIND`, and below it what ``PDDLReader``
#: makes of arrange-up's PDDL domain (no real parameters, no simulated effects, numeric
#: fluents whose initial value may be undefined). A problem with any other feature (integer or
#: object fluents, durative actions, scheduling, hierarchies, ...) is not an arrange-up problem.
READABLE_KIND = _kind(("set_initial_state", "UNDEFINED_INITIAL_NUMERIC"))
#: The features every arrange-up problem has, whichever way it was made (:func:`to_up` or
#: ``PDDLReader`` with arrange-up's domain): typed objects, real fluents, numeric goals and the
#: negative preconditions of place and push. A kind without one of them (a classical problem,
#: or the bare ``ACTION_BASED`` kind unified-planning's meta engines ask about) is no
#: arrange-up problem.
ARRANGE_UP_CORE_KIND = m.ProblemKind(
    {
        "ACTION_BASED",
        "SIMPLE_NUMERIC_PLANNING",
        "FLAT_TYPING",
        "HIERARCHICAL_TYPING",
        "NEGATIVE_CONDITIONS",
        "REAL_FLUENTS",
    },
    version=LATEST_PROBLEM_KIND_VERSION,
)

_KIND_TYPE = {
    ObjectKind.PART: "part",
    ObjectKind.FIXTURE: "fixture",
    ObjectKind.MANIPULATOR: "manipulator",
    ObjectKind.OBSTACLE: "obstacle",
}


def to_up(
    problem: ArrangementProblem, semantics: str = "deterministic", *, environment: Any = None
) -> Any:
    """The unified-planning ``Problem`` of ``problem`` (see the module docstring).

    ``semantics`` resolves the effects of place and push; only ``deterministic`` (alias
    ``nominal``) can be compiled, since a UP state is a single world state. ``environment``
    is a UP ``Environment`` (default: the global one).

    Raises ``ValueError`` for another semantics or for an object named like one of the model's
    types, fluents or actions (unified-planning refuses such a clash).
    """
    check_semantics(semantics)
    _check_names(problem)
    env = get_environment(environment)
    em, tm = env.expression_manager, env.type_manager
    up = m.Problem(problem.name, environment=env)

    movable = tm.UserType("movable")
    placeable = tm.UserType("placeable", movable)
    types = {
        "part": tm.UserType("part", placeable),
        "fixture": tm.UserType("fixture", placeable),
        "manipulator": tm.UserType("manipulator", movable),
        "obstacle": tm.UserType("obstacle"),
    }
    real = tm.RealType()
    fluents = {
        "on_table": m.Fluent("on_table", tm.BoolType(), o=movable, environment=env),
        "x": m.Fluent("x", real, o=movable, environment=env),
        "y": m.Fluent("y", real, o=movable, environment=env),
        "theta": m.Fluent("theta", real, o=movable, environment=env),
    }
    up.add_fluent(fluents["on_table"], default_initial_value=False)
    for key in ("x", "y", "theta"):
        up.add_fluent(fluents[key], default_initial_value=0)

    objects = {}
    for spec in problem.objects:
        objects[spec.name] = m.Object(spec.name, types[_KIND_TYPE[spec.kind]], env)
        up.add_object(objects[spec.name])
    movable_names = tuple(s.name for s in problem.objects if s.kind is not ObjectKind.OBSTACLE)

    def table(key: str) -> dict[str, Any]:
        return {name: fluents[key](objects[name]) for name in movable_names}

    rel: dict[str, tuple[Any, Any, Any]] = {}
    if problem.goal.reference is not None:
        rel_fluents = [
            m.Fluent(name, real, p=types["part"], environment=env)
            for name in ("rel_x", "rel_y", "rel_theta")
        ]
        for fluent in rel_fluents:
            up.add_fluent(fluent, default_initial_value=0)
        rel = {part: tuple(f(objects[part]) for f in rel_fluents) for part in problem.goal.parts}
    pose_fluents = PoseFluents(
        fluents,
        movable_names,
        table("on_table"),
        table("x"),
        table("y"),
        table("theta"),
        rel,
    )

    # -- actions ---------------------------------------------------------------------------
    width, depth = exact(problem.table.width), exact(problem.table.depth)
    place = m.InstantaneousAction(
        "place",
        o=placeable,
        px=tm.RealType(0, width),
        py=tm.RealType(0, depth),
        ptheta=real,
        _env=env,
    )
    place.add_precondition(em.Not(fluents["on_table"](place.parameter("o"))))
    place.add_effect(fluents["on_table"](place.parameter("o")), True)
    push = m.InstantaneousAction(
        "push",
        m=types["manipulator"],
        px=real,
        py=real,
        ptheta=real,
        distance=tm.RealType(0, None),
        _env=env,
    )
    push.add_precondition(em.Not(fluents["on_table"](push.parameter("m"))))
    pick = m.InstantaneousAction("pick", o=movable, _env=env)
    pick.add_precondition(fluents["on_table"](pick.parameter("o")))
    pick.add_effect(fluents["on_table"](pick.parameter("o")), False)
    effects = attach_effects(problem, semantics, place, push, pose_fluents)
    has_manipulator = bool(problem.manipulators)
    for action in (place, push, pick):
        if action is push and not has_manipulator:
            continue  # a push action over an empty type would be dead weight
        up.add_action(action)

    # -- initial state ---------------------------------------------------------------------
    start = AngleFrame.of(problem).canonical(nominal_initial_state(problem))
    for name in start.names():
        up.set_initial_value(pose_fluents.on_table[name], True)
    for fluent, value in pose_fluents.values(problem, start).items():
        up.set_initial_value(fluent, em.Real(value))

    # -- goals -----------------------------------------------------------------------------
    for condition in _goal_conditions(problem, pose_fluents, em):
        up.add_goal(condition)

    fingerprint = _fingerprint(up)
    for effect in effects:
        effect.fingerprint = fingerprint
    return up


def _goal_conditions(problem: ArrangementProblem, fl: PoseFluents, em: Any) -> list[Any]:
    goal = problem.goal
    tol_x, tol_y, tol_theta = goal.tolerance
    out = []
    if goal.reference is not None:
        out.append(fl.on_table[goal.reference])
    for part, (tx, ty, ttheta) in goal.targets:
        out.append(fl.on_table[part])
        if goal.reference is None:
            fx, fy, ftheta = fl.x[part], fl.y[part], fl.theta[part]
        else:
            fx, fy, ftheta = fl.rel[part]
        bounds = [(fx, exact(tx), exact(tol_x)), (fy, exact(ty), exact(tol_y))]
        if tol_theta is not None:
            bounds.append((ftheta, exact_degrees(ttheta), exact_degrees(tol_theta)))
        for fluent, target, tol in bounds:
            out.append(em.GE(fluent, em.Real(target - tol)))
            out.append(em.LE(fluent, em.Real(target + tol)))
    for name in problem.put_away:
        out.append(em.Not(fl.on_table[name]))
    return out


def _check_names(problem: ArrangementProblem) -> None:
    reserved = set(TYPE_NAMES + FLUENT_NAMES + ACTION_NAMES)
    clashes = [spec.name for spec in problem.objects if spec.name in reserved]
    if clashes:
        raise ValueError(
            f"problem {problem.name!r}: object name(s) {', '.join(map(repr, clashes))} clash "
            "with the unified-planning model's vocabulary (types "
            f"{', '.join(TYPE_NAMES)}; fluents {', '.join(FLUENT_NAMES)}; actions "
            f"{', '.join(ACTION_NAMES)}); unified-planning refuses two elements with one name: "
            "rename the object"
        )


def _fingerprint(up_problem: Any) -> str:
    """A digest of what a user could edit in a compiled problem: objects, initial values,
    goals and action names. A clone has the same fingerprint."""
    lines = [f"name {up_problem.name}"]
    lines += sorted(f"object {o.name} - {o.type}" for o in up_problem.all_objects)
    lines += sorted(f"init {k} = {v}" for k, v in up_problem.explicit_initial_values.items())
    lines += [f"goal {g}" for g in up_problem.goals]
    lines += [f"action {a.name}" for a in up_problem.actions]
    return hashlib.sha256("\n".join(lines).encode("utf-8")).hexdigest()


def _effect_of(up_problem: Any) -> TransitionEffect | None:
    for action in getattr(up_problem, "actions", ()):
        effect = getattr(action, "simulated_effect", None)
        function = getattr(effect, "function", None)
        if isinstance(function, TransitionEffect):
            return function
    return None


def made_by_to_up(up_problem: Any) -> bool:
    """True if ``up_problem`` was made by :func:`to_up` (or is a clone of such a problem)."""
    return _effect_of(up_problem) is not None


def from_up(up_problem: Any) -> ArrangementProblem:
    """The :class:`ArrangementProblem` of a unified-planning problem.

    * Made by :func:`to_up` (or cloned from one): the compiled problem, found through the
      problem's effects. Raises ``ValueError`` if the UP problem was edited since (objects,
      initial values, goals or actions differ from what :func:`to_up` made).
    * Read by UP's ``PDDLReader`` with arrange-up's domain: rebuilt from the PDDL vocabulary
      (:func:`arrange_up.io.pddl.problem_from_up`); raises
      :class:`~arrange_up.model.errors.ProblemFormatError` (a ``ValueError``) when it does not fit
      the vocabulary. Names are as UP read them: lowercase, since PDDL is case-insensitive
      (:func:`arrange_up.io.pddl.load_pddl_problem` restores the written case from the file).
    * Anything else, refused with ``ValueError`` before any reading: a problem that is not a
      plain UP ``Problem`` (scheduling, hierarchical, multi-agent, contingent, ...), has a
      feature outside :data:`READABLE_KIND`, or was read with another domain (its actions and
      their parameter types are not the ``place``, ``push`` and ``pick`` of arrange-up's).
    """
    effect = _effect_of(up_problem)
    if effect is None:
        _check_readable(up_problem)
    else:
        if effect.fingerprint != _fingerprint(up_problem):
            raise ValueError(
                f"unified-planning problem {up_problem.name!r} was made by "
                "arrange_up.up.compile.to_up but has been edited since (its objects, initial "
                "values, goals or actions differ); edits to a compiled problem cannot be mapped "
                "back: change the ArrangementProblem and compile it again"
            )
        return effect.problem
    return problem_from_up(up_problem)


def equip_pddl_problem(up_problem: Any, problem: ArrangementProblem) -> None:
    """Give a problem read by ``PDDLReader`` from arrange-up's domain, **in place**, what PDDL
    cannot express: the real parameters of ``place`` (``px``, ``py``, ``ptheta``) and ``push``
    (also ``distance``) and their simulated effects (:func:`~arrange_up.up.effects.attach_effects`,
    the deterministic semantics), as :func:`to_up` builds them. ``problem`` is
    :func:`from_up` of it.

    The engines call it before answering a plan for such a problem, so that the plan's actions
    are the problem's own (unified-planning's ``SequentialPlanValidator`` and simulator accept
    only those) and carry the poses and distances. Pose fluents without an initial value are
    given one (an object on the table: its nominal pose, angle wrapped as :func:`to_up` does;
    off it: 0, meaningless as in :func:`to_up`), since an effect reads and writes them. The
    problem's kind gains ``REAL_ACTION_PARAMETERS`` and ``SIMULATED_EFFECTS``; afterwards
    :func:`made_by_to_up` is true of it and :func:`from_up` maps it back through its effects
    (an edit after that is refused, as for a compiled problem). Idempotent: a problem already
    equipped (or made by :func:`to_up`) is left alone."""
    if made_by_to_up(up_problem):
        return
    env = up_problem.environment
    tm, em = env.type_manager, env.expression_manager
    real = tm.RealType()
    place, push = up_problem.action("place"), up_problem.action("push")
    _add_parameters(
        place,
        env,
        px=tm.RealType(0, exact(problem.table.width)),
        py=tm.RealType(0, exact(problem.table.depth)),
        ptheta=real,
    )
    _add_parameters(push, env, px=real, py=real, ptheta=real, distance=tm.RealType(0, None))
    fluents = {key: up_problem.fluent(key) for key in ("x", "y", "theta")}
    fluents["on_table"] = up_problem.fluent("on-table")
    movable = tuple(s.name for s in problem.objects if s.kind is not ObjectKind.OBSTACLE)

    def table(key: str) -> dict[str, Any]:
        return {name: fluents[key](up_problem.object(name)) for name in movable}

    rel: dict[str, tuple[Any, Any, Any]] = {}
    if problem.goal.reference is not None:
        reference = up_problem.object(problem.goal.reference)
        rel = {
            part: tuple(
                up_problem.fluent(name)(up_problem.object(part), reference)
                for name in ("rel-x", "rel-y", "rel-theta")
            )
            for part in problem.goal.parts
        }
    pose_fluents = PoseFluents(
        fluents, movable, table("on_table"), table("x"), table("y"), table("theta"), rel
    )
    start = AngleFrame.of(problem).canonical(nominal_initial_state(problem))
    known = up_problem.explicit_initial_values
    for fluent, value in pose_fluents.values(problem, start).items():
        if fluent not in known:
            up_problem.set_initial_value(fluent, em.Real(value))
    for name in movable:
        for key in ("x", "y", "theta"):
            fluent = getattr(pose_fluents, key)[name]
            if fluent not in up_problem.explicit_initial_values:
                up_problem.set_initial_value(fluent, em.Real(Fraction(0)))
    effects = attach_effects(problem, "deterministic", place, push, pose_fluents)
    fingerprint = _fingerprint(up_problem)
    for effect in effects:
        effect.fingerprint = fingerprint


def _add_parameters(action: Any, environment: Any, **types: Any) -> None:
    """Append real parameters to a unified-planning action. unified-planning 1.3 has no public
    way to (its actions take their parameters when made); they live in the ordered mapping
    ``_parameters``, which equality, grounding and printing read."""
    for name, type_ in types.items():
        if name not in action._parameters:
            action._parameters[name] = m.Parameter(name, type_, environment)


def _check_readable(up_problem: Any) -> None:
    """Raise ``ValueError`` unless ``up_problem`` is a plain UP ``Problem`` whose kind is within
    :data:`READABLE_KIND`: the PDDL vocabulary reader assumes both (numeric initial values,
    object parameters, goals)."""
    if not isinstance(up_problem, m.Problem) or type(up_problem) is not m.Problem:
        raise ValueError(
            f"a unified-planning {type(up_problem).__name__} is not an arrange-up problem: "
            "expected a Problem made by arrange_up.up.compile.to_up or read by PDDLReader from "
            "arrange-up's PDDL domain"
        )
    outside = sorted(set(up_problem.kind.features) - set(READABLE_KIND.features))
    if outside:
        raise ValueError(
            f"problem {up_problem.name!r} has features no arrange-up problem has: "
            f"{', '.join(outside)}"
        )
    # The planner plans arrange-up's place, push and pick whatever actions the problem lists,
    # so a problem read with another domain (an action renamed, removed or added) is refused:
    # its plan would name actions that domain does not have.
    actions = {a.name: tuple(p.type.name for p in a.parameters) for a in up_problem.actions}
    expected = _domain_actions()
    if actions != expected:
        shown = ", ".join(f"{n}({', '.join(t)})" for n, t in sorted(actions.items()))
        wanted = ", ".join(f"{n}({', '.join(t)})" for n, t in sorted(expected.items()))
        raise ValueError(
            f"problem {up_problem.name!r} was read with another domain than arrange-up's: its "
            f"actions are {shown or 'none'}, expected {wanted} (read it with "
            "arrange_up.io.pddl_domain.domain_path())"
        )


@functools.cache
def _domain_actions() -> dict[str, tuple[str, ...]]:
    """The actions of arrange-up's PDDL domain and their parameter types, from its text."""
    pattern = r"\(:action\s+([\w-]+)\s+:parameters\s+\(([^)]*)\)"
    return {
        name: tuple(re.findall(r"-\s*([\w-]+)", parameters))
        for name, parameters in re.findall(pattern, domain_pddl_text())
    }


# ---------------------------------------------------------------------------------------------
# plans
# ---------------------------------------------------------------------------------------------
def plan_to_up(up_problem: Any, actions: Sequence[Action]) -> Any:
    """A UP ``SequentialPlan`` of arrange-up actions (inches, radians) for a problem made by
    :func:`to_up`: real parameters are exact decimals (9 places), angles in degrees."""
    em = up_problem.environment.expression_manager
    out = []
    for action in actions:
        if isinstance(action, Place):
            params = [up_problem.object(action.obj), *_pose_params(em, action.pose)]
            out.append(ActionInstance(up_problem.action("place"), params))
        elif isinstance(action, Push):
            params = [up_problem.object(action.manipulator), *_pose_params(em, action.pose)]
            params.append(em.Real(exact(action.distance)))
            out.append(ActionInstance(up_problem.action("push"), params))
        elif isinstance(action, Pick):
            out.append(ActionInstance(up_problem.action("pick"), [up_problem.object(action.obj)]))
        else:
            raise TypeError(f"not an arrange-up action: {action!r}")
    return SequentialPlan(out, environment=up_problem.environment)


def plan_from_up(plan: Any, problem: ArrangementProblem | None = None) -> tuple[Action, ...]:
    """The arrange-up actions (inches, radians) of a UP ``SequentialPlan`` over the model of
    :func:`to_up`.

    With ``problem``, an object name the problem does not have is read as the problem's one
    object of that name in another case: PDDL names are case-insensitive and unified-planning's
    ``PDDLReader`` lowercases them, so a plan solved from a PDDL-read problem names ``t`` what
    the file (and :func:`arrange_up.io.pddl.load_pddl_problem`) names ``T``. A name matching
    no object, or several, is kept as it is (the evaluation then reports it).

    Raises ``ValueError`` for another kind of plan, or an action that is not ``place``,
    ``push`` or ``pick`` with the parameters :func:`to_up` gives them (an object, then
    numbers)."""
    name_of = _object_names(problem)
    if not isinstance(plan, SequentialPlan):
        raise ValueError(
            f"a {type(plan).__name__} is not a sequential plan; expected a SequentialPlan of "
            "place/push/pick actions"
        )
    out: list[Action] = []
    for k, instance in enumerate(plan.actions):
        name = instance.action.name
        params = instance.actual_parameters
        arity = _ARITY.get(name)
        if arity is None:
            raise ValueError(f"action {k + 1}, {name!r}, is not place, push or pick")
        if (
            len(params) != arity
            or not params[0].is_object_exp()
            or not all(p.is_int_constant() or p.is_real_constant() for p in params[1:])
        ):
            raise ValueError(
                f"action {k + 1}, {instance}, does not have the parameters of arrange-up's "
                f"{name} (an object, then {arity - 1} numbers)"
            )
        obj = name_of(params[0].object().name)
        if name == "pick":
            out.append(Pick(obj))
            continue
        x, y, theta = (float(p.constant_value()) for p in params[1:4])
        pose = (x, y, math.radians(theta))
        if name == "place":
            out.append(Place(obj, pose))
        else:
            out.append(Push(obj, pose, float(params[4].constant_value())))
    return tuple(out)


def _object_names(problem: ArrangementProblem | None) -> Any:
    """``name -> name`` of ``problem``'s object named so, or else its one object of that name
    in another case (see :func:`plan_from_up`)."""
    if problem is None:
        return lambda name: name
    exact = {spec.name for spec in problem.objects}
    folded: dict[str, list[str]] = {}
    for spec in problem.objects:
        folded.setdefault(spec.name.lower(), []).append(spec.name)

    def name_of(name: str) -> str:
        if name in exact:
            return name
        matches = folded.get(name.lower(), [])
        return matches[0] if len(matches) == 1 else name

    return name_of


#: The number of parameters of each action of :func:`to_up`'s model.
_ARITY = {"place": 4, "push": 5, "pick": 1}


def _pose_params(em: Any, pose: Sequence[float]) -> list[Any]:
    return [em.Real(exact(pose[0])), em.Real(exact(pose[1])), em.Real(exact_degrees(pose[2]))]
