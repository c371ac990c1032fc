"""Plans as values and as documented JSON files.

A plan file (written by ``arrange-up plan --output PLAN.json``, read by ``evaluate``, ``show``
and ``repair``) is a JSON object::

    {
      "format": "arrange-up-plan/1",
      "problem": {"name": "blocks-4", "hash": "sha256:…", "source": "domain:blocks-4"},
      "units": {"length": "in", "angle": "deg"},
      "status": "solved",
      "semantics": "particles", "particles": 50, "seed": 0,
      "controller": {"kind": "compliant", "kp": 300},
      "search": {"expanded": 41, "generated": 380, …, "elapsed": 12.3},
      "actions": [
        {"type": "place", "object": "A", "pose": [9.1, 0.9, 0.0]},
        {"type": "push", "manipulator": "paddle", "pose": [9.1, -0.3, 0.0], "distance": 2.0},
        {"type": "pick", "object": "bar"}
      ]
    }

Poses and distances are in the problem's own units (``units``). ``actions`` is present, and
the plan complete, only when ``status`` is ``"solved"``; any other status records an honest
failure with its search statistics. ``hash`` identifies the problem's content (see
:func:`arrange_up.model.problem.problem_hash`); the commands that read plans warn when it does not
match the problem they are given, and of every other mismatch (:func:`plan_problem_mismatches`).
``controller`` is the problem's push controller (:func:`controller_to_json`); a file without one
was made before plan files recorded it, when every problem was driven by the servo.
"""

from __future__ import annotations

import dataclasses
import errno
import json
import math
import os
import re
import stat
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, TypeGuard

from arrange_up.counts import is_number
from arrange_up.io.files import text_place, undecodable_place
from arrange_up.io.validation import MAX_POSE_REACH, angle_problem, pose_reach
from arrange_up.io.yaml_settings import SERVO_KEYS, controller_factors
from arrange_up.io.yaml_source import long_number
from arrange_up.model.problem import (
    ArrangementProblem,
    Controller,
    ControllerKind,
    ObjectKind,
    as_triple,
    problem_hash,
)
from arrange_up.model.units import ANGLE_UNITS, LENGTH_UNITS, Units
from arrange_up.model.world import Action, Pick, Place, Push

PLAN_FORMAT = "arrange-up-plan/1"


class PlanFileError(ValueError):
    """A plan file that cannot be read or does not fit its problem; the message says where."""


def action_to_json(action: Action, units: Units) -> dict[str, Any]:
    """One action as a JSON object in the user's units."""
    if isinstance(action, Place):
        return {"type": "place", "object": action.obj, "pose": _pose_out(action.pose, units)}
    if isinstance(action, Push):
        return {
            "type": "push",
            "manipulator": action.manipulator,
            "pose": _pose_out(action.pose, units),
            "distance": _round(units.length_out(action.distance)),
        }
    if isinstance(action, Pick):
        return {"type": "pick", "object": action.obj}
    raise TypeError(f"not an action: {action!r}")


def action_from_json(data: Any, units: Units, problem: ArrangementProblem, where: str) -> Action:
    """Parse one action object (user units) into an internal action, checked against ``problem``.

    Raises :class:`PlanFileError` naming ``where`` (e.g. ``plan.json: actions[3]``).
    """
    if not isinstance(data, Mapping):
        raise PlanFileError(f"{where}: expected an object with a 'type', got {data!r}")
    kind = data.get("type")
    names = {spec.name: spec for spec in problem.objects}

    def name_of(key: str, allowed: tuple[ObjectKind, ...]) -> str:
        name = data.get(key)
        if not isinstance(name, str) or name not in names:
            raise PlanFileError(
                f"{where}.{key}: expected an object of problem {problem.name!r}, got {name!r}"
            )
        if names[name].kind not in allowed:
            raise PlanFileError(
                f"{where}.{key}: {name!r} is a {names[name].kind.value}; "
                f"expected one of {', '.join(k.value for k in allowed)}"
            )
        return name

    def pose_of() -> tuple[float, float, float]:
        pose = data.get("pose")
        if (
            not isinstance(pose, Sequence)
            or isinstance(pose, str)
            or len(pose) != 3
            or not all(_is_number(v) for v in pose)
        ):
            raise PlanFileError(f"{where}.pose: expected [x, y, theta] numbers, got {_shown(pose)}")
        internal = units.pose_in(as_triple(pose))
        reach = pose_reach(problem.table.size)
        for axis, value, size in zip("xy", internal[:2], problem.table.size, strict=True):
            if not -reach <= value <= size + reach:
                raise PlanFileError(
                    f"{where}.pose: {axis} = {_shown(pose['xy'.index(axis)])} {units.length} is "
                    f"more than {MAX_POSE_REACH} table sizes from the table; expected a pose "
                    "on or near it (docs/plan-format.md)"
                )
        reason = angle_problem(internal[2], units.angle)
        if reason is not None:
            raise PlanFileError(f"{where}.pose[2]: angle {pose[2]:g} {units.angle}: {reason}")
        return internal

    movable = (ObjectKind.PART, ObjectKind.FIXTURE, ObjectKind.MANIPULATOR)
    if kind == "place":
        return Place(name_of("object", (ObjectKind.PART, ObjectKind.FIXTURE)), pose_of())
    if kind == "push":
        distance = data.get("distance")
        if not _is_number(distance) or distance < 0:
            raise PlanFileError(
                f"{where}.distance: expected a non-negative number, got {_shown(distance)}"
            )
        reach = pose_reach(problem.table.size)
        if units.length_in(distance) > reach:  # as a pose: a push thousands of tables long
            raise PlanFileError(
                f"{where}.distance: {_shown(distance)} {units.length} is more than "
                f"{MAX_POSE_REACH} table sizes; expected a push of at most "
                f"{units.length_out(reach):g} {units.length} (docs/plan-format.md)"
            )
        return Push(
            name_of("manipulator", (ObjectKind.MANIPULATOR,)), pose_of(), units.length_in(distance)
        )
    if kind == "pick":
        return Pick(name_of("object", movable))
    raise PlanFileError(f"{where}.type: expected 'place', 'push' or 'pick', got {_shown(kind)}")


def plan_document(
    problem: ArrangementProblem,
    actions: Sequence[Action] | None,
    *,
    status: str,
    semantics: str,
    seed: int | None,
    search: Mapping[str, Any],
    extra: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """Build the JSON document of a planning result (see the module docstring)."""
    doc: dict[str, Any] = {
        "format": PLAN_FORMAT,
        "problem": {
            "name": problem.name,
            "hash": problem_hash(problem),
            "source": problem.source,
        },
        "units": {"length": problem.units.length, "angle": problem.units.angle},
        "status": status,
        "semantics": semantics,
        "seed": seed,
    }
    doc["controller"] = controller_to_json(problem)
    if extra:
        doc.update(extra)
    doc["search"] = dict(search)
    if status == "solved" and actions is not None:
        doc["actions"] = [action_to_json(a, problem.units) for a in actions]
    return doc


def controller_to_json(problem: ArrangementProblem) -> dict[str, Any]:
    """The problem's push controller as its ``controller:`` mapping reads, in the problem's
    units (omitted keys were left at their defaults; the servo's only keys are its speed and
    force)."""
    controller = problem.controller
    data: dict[str, Any] = {"kind": controller.kind.value}
    servo = controller.kind is ControllerKind.SERVO
    for key, factor in controller_factors(problem.units).items():
        value = getattr(controller, key)
        if value is not None and not (servo and key not in SERVO_KEYS):
            data[key] = _round(value / factor)
    return data


def write_json_atomic(path: Path, document: Mapping[str, Any]) -> Path:
    """Write JSON to ``path`` atomically: a reader never sees a half-written file."""
    return write_text_atomic(path, json.dumps(document, indent=2) + "\n")


def write_text_atomic(path: Path, text: str) -> Path:
    """Write ``text`` to ``path`` through a temporary file and a rename, so that a reader (or
    a crash) never leaves a half-written file behind. The file gets the permissions of any
    newly created file (``0o666`` less the umask), not the temporary file's private ``0o600``.

    A symbolic link is written through: its target gets the text (atomically, as above) and
    the link stays. A path that is neither a regular file nor missing (a FIFO, a device such as
    ``/dev/stdout``) is written through as well, directly, since a rename would replace the
    special file with a regular one; a directory raises ``IsADirectoryError``. Raises
    ``OSError`` when the text cannot be written (``/dev/full``, a full disk)."""
    path = Path(path)
    if path.is_symlink():
        path = Path(os.path.realpath(path))
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    if path.exists() and not stat.S_ISREG(path.stat().st_mode):
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(text)
        return path
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _umask() -> int:
    # the only portable way to read the umask is to set it; set it straight back (a file
    # another thread creates in between gets 0o022, the common default)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


#: How deeply a plan file's JSON may nest. A plan nests four levels; the limit keeps a
#: hostile file from exhausting the parser's stack.
MAX_DEPTH = 32


#: The largest plan file read, in bytes, and the most actions it may hold: a plan has tens of
#: actions of about 100 bytes each; the limits keep a runaway file (a million actions,
#: ``/dev/zero``) from taking the memory and time of every command that reads plans.
MAX_PLAN_BYTES = 16 * 2**20
MAX_PLAN_ACTIONS = 10_000


def _read_document(path: Path) -> Any:
    """The JSON value of a plan file, or :class:`PlanFileError` naming the place."""
    try:
        with open(path, "rb") as handle:
            data = handle.read(MAX_PLAN_BYTES + 1)
    except IsADirectoryError:
        raise PlanFileError(f"{path}: is a directory; expected a plan file (JSON)") from None
    except OSError as error:
        raise PlanFileError(f"{path}: cannot read plan file: {error.strerror or error}") from None
    if len(data) > MAX_PLAN_BYTES:
        raise PlanFileError(
            f"{path}: larger than {MAX_PLAN_BYTES // 2**20} MiB; expected a plan file (at most "
            f"{MAX_PLAN_ACTIONS} actions, docs/plan-format.md)"
        )
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line, column = undecodable_place(data, error)
        raise PlanFileError(
            f"{path}:{line}:{column}: not a text file: byte 0x{data[error.start]:02x} is not "
            "UTF-8; expected a plan file (JSON in UTF-8)"
        ) from None
    too_deep = _too_deep(text)
    if too_deep is not None:
        line, column = text_place(text, too_deep)
        raise PlanFileError(
            f"{path}:{line}:{column}: nested too deeply; expected a plan file (JSON nested at "
            f"most {MAX_DEPTH} levels)"
        )
    try:
        return json.loads(text, object_pairs_hook=_unique_keys)
    except _DuplicateKey as duplicate:
        line, column = _second_key_place(text, duplicate.key)
        raise PlanFileError(
            f"{path}:{line}:{column}: key {json.dumps(duplicate.key)} appears twice in one "
            "object; a plan file names each key once (JSON readers disagree on which copy "
            "wins)"
        ) from None
    except json.JSONDecodeError as error:
        raise PlanFileError(
            f"{path}:{error.lineno}:{error.colno}: not JSON: {error.msg}; expected a plan "
            "file (a JSON object)"
        ) from None
    except ValueError as error:  # an integer of more digits than Python converts
        number_line, number_column, digits = long_number(text)
        if not digits:
            raise PlanFileError(f"{path}: not a plan file: {error}") from None
        raise PlanFileError(
            f"{path}:{number_line}:{number_column}: a number of {digits} digits; expected a "
            "finite number (a double, at most about 1e308)"
        ) from None


def _too_deep(text: str) -> int | None:
    """The index of the first bracket of JSON ``text`` nested deeper than :data:`MAX_DEPTH`
    (brackets inside strings not counted), or None."""
    depth = 0
    in_string = escaped = False
    for index, char in enumerate(text):
        if in_string:
            if escaped:
                escaped = False
            elif char == "\\":
                escaped = True
            elif char == '"':
                in_string = False
        elif char == '"':
            in_string = True
        elif char in "[{":
            depth += 1
            if depth > MAX_DEPTH:
                return index
        elif char in "]}":
            depth -= 1
    return None


class _DuplicateKey(ValueError):
    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """``json.loads``' object hook: the object, or :class:`_DuplicateKey` for a repeated key."""
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise _DuplicateKey(key)
        out[key] = value
    return out


def _second_key_place(text: str, key: str) -> tuple[int, int]:
    """Line and column of the second place ``key`` is written as an object key in ``text``
    (the file's start when it cannot be told: the key written with escapes)."""
    pattern = re.compile(re.escape(json.dumps(key)) + r"\s*:")
    found = list(pattern.finditer(text))
    return text_place(text, found[1].start()) if len(found) > 1 else (1, 1)


def read_plan(path: str | Path, problem: ArrangementProblem) -> tuple[tuple[Action, ...], dict]:
    """Read a plan file for ``problem``; return its actions (internal units) and the document.

    Raises :class:`PlanFileError` for unreadable files (not UTF-8, not JSON, nested too
    deeply), other formats, unsolved plans and actions that do not fit the problem (numbers
    that are not finite doubles, angles too large to mean an orientation).
    """
    path = Path(path)
    document = _read_document(path)
    if not isinstance(document, dict):
        raise PlanFileError(
            f'{path}: format: expected a plan file, a JSON object with "format": '
            f"{PLAN_FORMAT!r}; got {_shown(document)} ({_json_kind(document)})"
        )
    if document.get("format") != PLAN_FORMAT:
        raise PlanFileError(
            f"{path}: format: expected {PLAN_FORMAT!r}, got {_shown(document.get('format'))}"
        )
    if document.get("status") != "solved":
        raise PlanFileError(
            f"{path}: status: the plan is {_shown(document.get('status'))}, not "
            "'solved'; it holds no actions to use (expected a solved plan)"
        )
    if "actions" not in document:
        raise PlanFileError(
            f"{path}: actions: missing; a solved plan lists its actions (expected a list, "
            "empty when the goal holds at the start)"
        )
    raw_units = document.get("units", {})
    if not isinstance(raw_units, dict):
        raise PlanFileError(
            f'{path}: units: expected an object {{"length": ..., "angle": ...}}, got '
            f"{_json_kind(raw_units)}"
        )
    for key, table, default in (("length", LENGTH_UNITS, "in"), ("angle", ANGLE_UNITS, "deg")):
        unit = raw_units.get(key, default)
        if not isinstance(unit, str) or unit not in table:
            raise PlanFileError(
                f"{path}: units: unknown {key} unit {_shown(unit)}; expected one of "
                f"{', '.join(table)}"
            )
    units = Units(raw_units.get("length", "in"), raw_units.get("angle", "deg"))
    recorded = document.get("problem", {})
    if not isinstance(recorded, dict):
        raise PlanFileError(
            f'{path}: problem: expected an object {{"name", "hash", "source"}} naming '
            f"the problem the plan is for, got {_json_kind(recorded)}"
        )
    raw_actions = document["actions"]
    if not isinstance(raw_actions, list):
        raise PlanFileError(f"{path}: actions: expected a list, got {_json_kind(raw_actions)}")
    if len(raw_actions) > MAX_PLAN_ACTIONS:
        raise PlanFileError(
            f"{path}: actions: {len(raw_actions)} actions; a plan file holds at most "
            f"{MAX_PLAN_ACTIONS} (docs/plan-format.md)"
        )
    try:
        actions = tuple(
            action_from_json(item, units, problem, f"{path}: actions[{i}]")
            for i, item in enumerate(raw_actions)
        )
    except PlanFileError as error:
        whose = recorded.get("name")
        if isinstance(whose, str) and whose != problem.name:  # the likely cause: say it
            raise PlanFileError(f"{error} (the file was planned for problem {whose!r})") from None
        raise
    return actions, document


def plan_problem_mismatches(document: Mapping[str, Any], problem: ArrangementProblem) -> list[str]:
    """Every way the plan ``document`` was made for other than ``problem``, each a warning;
    empty when it fits or records nothing to compare.

    In order: a ``problem`` record that is not an object, or one of another problem (its hash
    differs from ``problem``'s); a push controller of another kind (a file recording its problem
    but no controller was made under the servo). The hash covers the controller, so when the
    controllers differ the content is compared as if ``problem`` had the plan's: a plan of the
    same problem under another controller is warned of its controller only. A controller this
    version cannot read leaves the problem's name to tell another problem.
    """
    if not isinstance(document, Mapping):
        return []
    found: list[str] = []
    recorded = document.get("problem", {})
    if not isinstance(recorded, Mapping):
        found.append(f"its 'problem' is {_json_kind(recorded)}, not an object naming the problem")
        recorded = {}
    # A plan file that records its problem but no controller was made under the servo.
    legacy = {"kind": ControllerKind.SERVO.value} if recorded else None
    controller = document.get("controller", legacy)
    kind = controller.get("kind") if isinstance(controller, Mapping) else controller
    other_kind = controller is not None and kind != problem.controller.kind.value
    recorded_hash, expected = recorded.get("hash"), problem_hash(problem)
    if recorded_hash not in (None, expected):
        same = False
        if other_kind:
            # The hash covers the controller, which is said below: compare the rest.
            planned_under = _controller_from_json(controller, document.get("units"))
            if planned_under is None:
                same = recorded.get("name") == problem.name
            else:
                under = dataclasses.replace(problem, controller=planned_under)
                same = recorded_hash == problem_hash(under)
        if not same:
            found.append(
                f"it was planned for problem {recorded.get('name')!r} with other content "
                f"than {problem.name!r} ({recorded_hash} vs {expected})"
            )
    if other_kind:
        why = " (it names no controller: it was made when the servo was every problem's)"
        found.append(
            f"it was planned under the {kind if isinstance(kind, str) else _shown(kind)} "
            f"controller; problem {problem.name!r} uses the {problem.controller.kind.value} "
            f"one{why if controller is legacy else ''}"
        )
    return found


def _controller_from_json(data: Any, units: Any) -> Controller | None:
    """The controller a plan file records (:func:`controller_to_json`, in its ``units``), or
    ``None`` when it cannot be read as one (another version's kind, a value not a number)."""
    if not isinstance(data, Mapping) or not isinstance(units, Mapping | None):
        return None
    try:
        kind = ControllerKind(data.get("kind"))
        factors = controller_factors(Units(**(units or {})))
    except (TypeError, ValueError):
        return None
    values = {key: data[key] for key in factors if key in data}
    if not all(_is_number(value) for value in values.values()):
        return None
    return Controller(kind=kind, **{key: value * factors[key] for key, value in values.items()})


def _pose_out(pose: Sequence[float], units: Units) -> list[float]:
    return [_round(v) for v in units.pose_out(tuple(pose))]  # type: ignore[arg-type]


def _round(value: float) -> float:
    # 12 significant digits: exact enough to replay, free of binary noise like 0.30000000000000004
    return float(f"{value:.12g}")


def _is_number(value: object) -> TypeGuard[float]:
    """A finite number that converts to a double (a 400-digit integer does not)."""
    if not is_number(value):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _shown(value: Any) -> str:
    """``value`` as a message quotes it, shortened (a plan file may hold anything)."""
    try:
        text = repr(value)
    except ValueError:  # an integer too long to print
        text = "a number of very many digits"
    return text if len(text) <= 60 else text[:57] + "..."


def _json_kind(value: Any) -> str:
    """What a JSON value is, for messages: ``a list``, ``the string 'x'``, ..."""
    if isinstance(value, dict):
        return "an object"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, str):
        return f"the string {_shown(value)}"
    if value is None:
        return "null"
    if isinstance(value, bool):
        return f"{str(value).lower()} (a boolean)"
    return f"the number {_shown(value)}"
