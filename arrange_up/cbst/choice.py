"""Which learned model a problem plans with: a model predicts pushes only in the physics it
was trained in, and the push controller is part of that physics.

A model card names its controller (``"controller"``: the kind and every gain, each a number
or ``"default"``); a card without one predates the controller setting and was trained under
the servo. The shipped models are one per controller kind (:data:`SHIPPED_MODELS`), and the
name ``"default"`` means the shipped model of the problem's controller.

Two controllers are the same when their kinds are and every gain the kind uses has the same
value once resolved in the problem (``None`` gains at their defaults, as the physics resolves
them: :func:`arrange_up.physics.simulation.compliant_gains`, the problem's force clip
:func:`arrange_up.physics.settings.push_force`, the push speed); gains are compared for the
paddle the model was trained with, the only manipulator it predicts.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import fields
from pathlib import Path
from typing import Any

from arrange_up.cbst.store import DEFAULT_MODEL, SHIPPED_MODELS, load_model, shipped_name
from arrange_up.cbst.trained import TrainedModel
from arrange_up.counts import is_number
from arrange_up.model.problem import ArrangementProblem, Controller, ControllerKind
from arrange_up.physics.settings import DEFAULT_SETTINGS, push_force

__all__ = [
    "card_controller",
    "controller_record",
    "describe",
    "model_for",
    "resolved_gains",
]


#: The gains each controller kind uses (the physics ignores the others).
_USED: dict[ControllerKind, tuple[str, ...]] = {
    ControllerKind.COMPLIANT: ("kp", "kp_angle", "speed", "force", "torque"),
    ControllerKind.SERVO: ("speed", "force"),
}


def controller_record(controller: Controller) -> dict[str, Any]:
    """The card's ``"controller"``: the kind and every gain, ``"default"`` for ``None``."""
    record: dict[str, Any] = {"kind": str(controller.kind)}
    for f in fields(controller):
        if f.name != "kind":
            value = getattr(controller, f.name)
            record[f.name] = "default" if value is None else float(value)
    return record


def card_controller(card: Mapping[str, Any], where: str | Path = "the model card") -> Controller:
    """The controller a card was trained under (the servo when the card names none).

    Raises ``ValueError`` naming ``where`` for a ``"controller"`` that is not a mapping of a
    known kind and numeric or ``"default"`` gains."""
    record = card.get("controller")
    if record is None:
        return Controller(kind=ControllerKind.SERVO)
    kinds = ", ".join(k.value for k in ControllerKind)
    if not isinstance(record, Mapping) or record.get("kind") not in set(ControllerKind):
        raise ValueError(f"{where}: controller must be a mapping with kind one of {kinds}")
    values: dict[str, Any] = {"kind": ControllerKind(record["kind"])}
    for f in fields(Controller):
        if f.name == "kind" or f.name not in record:
            continue
        value = record[f.name]
        if value == "default":
            value = None
        elif not is_number(value) or value <= 0:
            raise ValueError(
                f"{where}: controller {f.name} must be a positive number or 'default', "
                f"got {value!r}"
            )
        if value is None and f.name == "kp":
            raise ValueError(f"{where}: controller kp must be a positive number")
        values[f.name] = None if value is None else float(value)
    return Controller(**values)


def resolved_gains(
    controller: Controller, problem: ArrangementProblem, paddle_size: tuple[float, float]
) -> dict[str, float]:
    """The gains ``controller``'s kind uses, with the defaults resolved in ``problem`` for a
    paddle of ``paddle_size`` (inches; internal units, see
    :class:`~arrange_up.model.problem.Controller`)."""
    radius = math.hypot(0.5 * paddle_size[0], 0.5 * paddle_size[1])
    force = push_force(problem) if controller.force is None else controller.force
    gains = {
        "kp": controller.kp,
        "kp_angle": (
            controller.kp * radius * radius if controller.kp_angle is None else controller.kp_angle
        ),
        "speed": DEFAULT_SETTINGS.push_speed if controller.speed is None else controller.speed,
        "force": force,
        "torque": force * radius if controller.torque is None else controller.torque,
    }
    return {name: float(gains[name]) for name in _USED[controller.kind]}


def describe(controller: Controller, gains: Mapping[str, float] | None = None) -> str:
    """``"compliant (kp 300, speed default, ...)"``: the kind and its gains (``gains`` when
    given, else the controller's own values)."""
    if gains is None:
        gains = {name: getattr(controller, name) for name in _USED[controller.kind]}
    parts = [
        f"{name} {'default' if value is None else format(value, '.6g')}"
        for name, value in gains.items()
    ]
    return f"{controller.kind} ({', '.join(parts)})"


def model_for(
    problem: ArrangementProblem, name_or_path: str | Path = DEFAULT_MODEL
) -> TrainedModel:
    """The model ``name_or_path`` (a shipped name, ``"default"`` for the shipped model of the
    problem's controller, or a card path), checked to have been trained under the problem's
    controller.

    Raises ``LookupError`` for an unknown name, and ``ValueError`` for a model that does not
    load (:func:`~arrange_up.cbst.store.load_model`) or was trained under another controller:
    the message names the model, both controllers and what to use instead."""
    wanted = problem.controller
    resolved = shipped_name(name_or_path, wanted)
    model = load_model(resolved)
    trained = card_controller(model.card_, model.card_path_)
    paddle = (float(model.card_["paddle_size"][0]), float(model.card_["paddle_size"][1]))
    mine = resolved_gains(wanted, problem, paddle)
    theirs = resolved_gains(trained, problem, paddle)
    if trained.kind is wanted.kind and all(
        math.isclose(mine[k], theirs[k], rel_tol=1e-9, abs_tol=1e-12) for k in mine
    ):
        return model
    label = (
        f"{name_or_path!s}"
        if str(name_or_path) == str(resolved)
        else (f"{name_or_path!s} ({resolved})")
    )
    advice = (
        f"plan with the shipped model {SHIPPED_MODELS[wanted.kind]!r} (or give no model: the "
        f"shipped one for the problem's controller), or train one with "
        f"`arrange-up train-cbst --controller {wanted.kind}`"
    )
    if trained.kind is wanted.kind:
        advice = (
            "train a model with these gains (arrange_up.cbst.model.train_cbst with a "
            "GenerationSettings controller)"
        )
    raise ValueError(
        f"CBST model {label} was trained under the {describe(trained, theirs)} controller, "
        f"but problem {problem.name!r} uses the {describe(wanted, mine)} controller: a model "
        f"predicts pushes only under the controller it was trained with; {advice}"
    )
