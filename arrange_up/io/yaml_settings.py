"""The ``uncertainty:``, ``planning:`` and ``controller:`` sections of a YAML problem: the
noise of actions and of the world, the action generator's hints, and the push controller
(``docs/problem-format.md``; ``planning:`` and ``controller:`` in
``docs/problem-format-planner.md``)."""

from __future__ import annotations

from typing import Any

from arrange_up.io import validation
from arrange_up.io.yaml_source import Node, NodeReader, describe, fmt, is_number, suggest
from arrange_up.model.problem import (
    DEFAULT_CONTROLLER,
    Controller,
    ControllerKind,
    PlanningHints,
    Uncertainty,
)
from arrange_up.model.units import Units

__all__ = [
    "CONTROLLER_KEYS",
    "controller_factors",
    "PLANNING_KEYS",
    "PUSH_DIRECTIONS",
    "SERVO_KEYS",
    "UNCERTAINTY_KEYS",
    "SettingsReader",
]

PUSH_DIRECTIONS = ("+x", "-x", "+y", "-y")
PLANNING_KEYS = ("place_offsets", "place_angles", "push_distances", "push_directions", "max_nodes")
CONTROLLER_KEYS = ("kind", "kp", "kp_angle", "speed", "force", "torque")
#: Keys the servo controller reads (the others tune the compliant controller only).
SERVO_KEYS = ("kind", "speed", "force")


def controller_factors(units: Units) -> dict[str, float]:
    """For each numeric ``controller:`` key, the factor from the file's units to internal ones
    (a file's value times it): ``kp`` in mass/s^2 needs none, ``speed`` is a length per second,
    ``force`` a mass x length/s^2, ``torque`` a mass x length^2/s^2 and ``kp_angle`` a torque
    per angle unit."""
    length = units.length_factor
    return {
        "kp": 1.0,
        "kp_angle": length * length / units.angle_factor,
        "speed": length,
        "force": length,
        "torque": length * length,
    }


UNCERTAINTY_KEYS = ("place", "push", "friction", "part_density", "manipulator_density")


class SettingsReader(NodeReader):
    """Reads the settings sections for :class:`~arrange_up.io.yaml_builder.ProblemBuilder`, into
    its report and in its units (set ``units`` before reading)."""

    # -- uncertainty ----------------------------------------------------------------------------
    def uncertainty(self, root: Node) -> Uncertainty | None:
        default = Uncertainty()
        if not root.has("uncertainty"):
            return default
        node = root.child("uncertainty")
        if not self.mapping(
            node, "a mapping with any of " + ", ".join(UNCERTAINTY_KEYS), null_ok=True
        ):
            return None
        if node.is_null:
            return default
        self.warn_unknown(node, UNCERTAINTY_KEYS, "'uncertainty'")
        values: dict[str, Any] = {}
        ok = True
        for key in ("place", "push"):
            if node.has(key):
                values[key] = self.half_widths(node.child(key))
                ok &= values[key] is not None
        units = self.units
        # densities must be positive: a body of zero mass cannot be simulated
        for key, convert, positive in (
            ("friction", float, False),
            ("part_density", units.density_in, True),
            ("manipulator_density", units.density_in, True),
        ):
            if node.has(key):
                values[key] = self.range(node.child(key), convert, positive=positive)
                ok &= values[key] is not None
        friction = values.get("friction")
        if friction is not None and friction[1] > validation.MAX_FRICTION:
            self.report.warning(
                node.child("friction"),
                None,
                f"friction up to {fmt(friction[1])} is far above real table-top materials "
                f"(below ~1.5); every push will stick. Expected at most "
                f"{fmt(validation.MAX_FRICTION)}: check the value",
            )
        return Uncertainty(**values) if ok else None

    def _known_keys(self, node: Node, keys: tuple[str, ...], what: str, why: str = "") -> bool:
        """Report every key of mapping ``node`` not among ``keys`` as an error (an unknown
        ``what``, with the nearest known key and ``why`` it is not just a warning); True if
        there was none."""
        ok = True
        for key_node, _ in node.entries():
            if key_node.value not in keys:
                self.error(
                    key_node,
                    f"unknown {what} {key_node.value!r}{suggest(key_node.value, keys)}; "
                    f"expected one of {', '.join(keys)}{why}",
                )
                ok = False
        return ok

    # -- planning hints -------------------------------------------------------------------------
    def planning(self, root: Node) -> PlanningHints | None:
        if not root.has("planning"):
            return PlanningHints()
        node = root.child("planning")
        if not self.mapping(
            node, "a mapping of planning hints (" + ", ".join(PLANNING_KEYS) + ")", null_ok=True
        ):
            return None
        if node.is_null:
            return PlanningHints()
        ok = self._known_keys(
            node,
            PLANNING_KEYS,
            "planning hint",
            " (a misspelt hint would silently change planning)",
        )
        hints: dict[str, Any] = {}
        units = self.units
        if node.has("place_offsets"):
            items = self.list_of(node.child("place_offsets"), "a non-empty list of [dx, dy]")
            offsets = None if items is None else [self.vector(i, ("dx", "dy")) for i in items]
            if offsets is None or any(o is None for o in offsets):
                ok = False
            else:
                hints["place_offsets"] = tuple(
                    (units.length_in(o[0]), units.length_in(o[1]))  # type: ignore[index]
                    for o in offsets
                )
        if node.has("place_angles"):
            child = node.child("place_angles")
            numbers = self.numbers(child, "angle", positive=False)
            angles = None
            if numbers is not None:
                angles = [self.angle(i, v) for i, v in zip(child.items(), numbers, strict=True)]
            ok &= angles is not None and None not in angles
            if ok and angles is not None:
                hints["place_angles"] = tuple(angles)
        if node.has("push_distances"):
            numbers = self.numbers(node.child("push_distances"), "distance", positive=True)
            ok &= numbers is not None
            if numbers is not None:
                hints["push_distances"] = tuple(units.length_in(v) for v in numbers)
        if node.has("push_directions"):
            directions = self.push_directions(node.child("push_directions"))
            ok &= directions is not None
            hints["push_directions"] = directions
        if node.has("max_nodes"):
            child = node.child("max_nodes")
            value = child.value
            if is_number(value) and isinstance(value, int) and value > 0:
                hints["max_nodes"] = int(value)
            else:
                self.error(child, f"expected a positive whole number, got {describe(value)}")
                ok = False
        return PlanningHints(**hints) if ok else None

    # -- the push controller --------------------------------------------------------------------
    def controller(self, root: Node) -> Controller | None:
        """The ``controller:`` mapping (``docs/problem-format-planner.md``), converted to internal
        units by :func:`controller_factors`."""
        if not root.has("controller"):
            return DEFAULT_CONTROLLER
        node = root.child("controller")
        if not self.mapping(
            node, "a mapping {kind: compliant | servo, ...} (" + ", ".join(CONTROLLER_KEYS) + ")"
        ):
            return None
        # An error, not a warning: a misspelt gain would silently change the physics.
        ok = self._known_keys(node, CONTROLLER_KEYS, "controller key")
        kinds = tuple(kind.value for kind in ControllerKind)
        kind: ControllerKind | None = DEFAULT_CONTROLLER.kind
        if node.has("kind"):
            kind_node = node.child("kind")
            if kind_node.value in kinds:
                kind = ControllerKind(kind_node.value)
            else:
                kind = None
                self.error(
                    kind_node, f"expected {' or '.join(kinds)}, got {describe(kind_node.value)}"
                )
        if kind is ControllerKind.SERVO:
            for key_node, _ in node.entries():
                if key_node.value in CONTROLLER_KEYS and key_node.value not in SERVO_KEYS:
                    self.error(
                        key_node,
                        f"{key_node.value!r} tunes the compliant controller only; the servo "
                        f"reads {', '.join(SERVO_KEYS)}",
                    )
                    ok = False
        values: dict[str, Any] = {}
        for key, factor in controller_factors(self.units).items():
            if not node.has(key):
                continue
            child = node.child(key)
            value = self.number(child, f"a positive {key}")
            if value is None:
                ok = False
            elif value <= 0:
                self.error(child, f"expected a positive {key}, got {fmt(value)}")
                ok = False
            else:
                values[key] = value * factor
        if kind is None or not ok:
            return None
        return Controller(kind=kind, **values)

    def push_directions(self, node: Node) -> tuple[str, ...] | None:
        items = self.list_of(node, f"a non-empty list drawn from {', '.join(PUSH_DIRECTIONS)}")
        if items is None:
            return None
        chosen: list[str] = []
        ok = True
        for item in items:
            if item.value not in PUSH_DIRECTIONS:
                self.error(
                    item,
                    f"unknown push direction {describe(item.value)}; expected one "
                    f"of {', '.join(repr(d) for d in PUSH_DIRECTIONS)} (quoted)",
                )
                ok = False
            elif item.value in chosen:
                self.error(
                    item, f"push direction {item.value!r} is listed twice; list each at most once"
                )
                ok = False
            else:
                chosen.append(str(item.value))
        return tuple(chosen) if ok else None
