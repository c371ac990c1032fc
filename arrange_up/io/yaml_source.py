"""Reading YAML problem text with every value's position, and collecting diagnostics.

The pieces under the problem builder (:mod:`arrange_up.io.yaml_builder`): :func:`read_text`
reads a file's bytes as UTF-8, :func:`parse` parses YAML into a tree that keeps every value's
position (:mod:`arrange_up.io.yaml_tree`: libyaml, or ruamel's round-trip loader for what
libyaml's reading leaves to it) and reports duplicate keys, a :class:`Node` is one value with its
1-based line and column and key path, a :class:`Report` collects the diagnostics of one source,
and a :class:`NodeReader` checks values (numbers, vectors, mappings, lists) and records what is
wrong at the node where it is written.
"""

from __future__ import annotations

import difflib
import math
import re
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ruamel.yaml.error import MarkedYAMLError, YAMLError
from ruamel.yaml.reader import ReaderError
from ruamel.yaml.scalarbool import ScalarBoolean

from arrange_up.io import yaml_tree
from arrange_up.io.files import (
    ProblemFileTooLarge,
    read_problem_bytes,
    text_place,
    undecodable_place,
)
from arrange_up.io.validation import angle_problem
from arrange_up.io.yaml_tree import YamlMap, join
from arrange_up.model.errors import Diagnostic
from arrange_up.model.problem import Pose
from arrange_up.model.units import Units

__all__ = [
    "Location",
    "Node",
    "NodeReader",
    "Report",
    "at",
    "describe",
    "fmt",
    "is_number",
    "join",
    "long_number",
    "parse",
    "read_text",
    "root_node",
    "suggest",
]


# ---------------------------------------------------------------------------------------------
# reading and parsing
# ---------------------------------------------------------------------------------------------
def read_text(path: Path, source: str) -> tuple[str | None, Diagnostic | None]:
    def fail(message: str, line: int | None = None, column: int | None = None) -> Diagnostic:
        return Diagnostic(source, line, column, "", message)

    try:
        data = read_problem_bytes(path)
    except ProblemFileTooLarge as error:
        return None, fail(str(error))
    except FileNotFoundError:
        return None, fail("no such file; expected a .yaml problem file")
    except IsADirectoryError:
        return None, fail("is a directory; expected a .yaml problem file")
    except PermissionError:
        return None, fail("cannot read the file: permission denied")
    except OSError as error:
        return None, fail(f"cannot read the file: {error.strerror or error}")
    try:
        return data.decode("utf-8-sig"), None
    except UnicodeDecodeError as error:
        line, column = undecodable_place(data, error)
        return None, fail(
            f"not a text file: byte 0x{data[error.start]:02x} is not UTF-8; expected a YAML "
            "problem file in UTF-8",
            line,
            column,
        )


def parse(text: str, report: Report) -> YamlMap | None:
    """Parse YAML text into a tree that keeps every value's position (:mod:`.yaml_tree`).

    Returns the top-level mapping, or ``None`` after recording an error. Duplicate keys are
    found on the whole tree, so every duplicate is reported, not just the first.
    """
    try:
        document = yaml_tree.read(text)
    except MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        what = str(error.problem or "syntax error")
        if error.context:
            what += f" ({error.context})"
        line = mark.line + 1 if mark is not None else None
        column = mark.column + 1 if mark is not None else None
        report.error((line, column), "", f"not valid YAML: {what}")
        return None
    except ReaderError as error:  # a character YAML does not allow, such as NUL
        line, column = text_place(text, error.position)
        report.error(
            (line, column),
            "",
            f"not valid YAML: character {_char(error.character)} is not allowed in a YAML file; "
            "expected printable text",
        )
        return None
    except YAMLError as error:
        report.error(None, "", f"not valid YAML: {_one_line(str(error))}")
        return None
    except RecursionError:
        line, column, depth = deepest(text)
        report.error(
            (line, column),
            "",
            f"not a problem file: the YAML is nested too deeply ({depth} levels here); "
            "expected a mapping of the format's sections (name, table, objects, goal, ...)",
        )
        return None
    except ValueError as error:  # an integer of more digits than Python converts
        line, column, digits = long_number(text)
        if digits:
            report.error(
                (line, column),
                "",
                f"a number of {digits} digits; expected a finite number (a double, at most "
                "about 1e308)",
            )
        else:
            report.error(None, "", f"not valid YAML: {_one_line(str(error))}")
        return None

    if document is None or document.root is None:
        report.error(
            (1, 1),
            "",
            "the file is empty; expected a mapping with at least the keys name, table, "
            "objects and goal",
        )
        return None
    data = document.root
    if not isinstance(data, YamlMap):
        report.error(
            (document.line + 1, document.column + 1),
            "",
            f"not a problem file: the top level is {describe(data)}; expected a mapping with "
            "at least the keys name, table, objects and goal",
        )
        return None
    for line, column, path, key, first in document.duplicates:
        report.error(
            (line, column),
            path,
            f"duplicate key {key!r} (first given at line {first[0]}, column {first[1]}); "
            "expected each key at most once in a mapping",
        )
    return data


def long_number(text: str) -> tuple[int | None, int | None, int]:
    """``(line, column, digits)`` of the first run of more digits than Python converts to an
    integer (``sys.get_int_max_str_digits()``), or ``(None, None, 0)``."""
    limit = sys.get_int_max_str_digits() if hasattr(sys, "get_int_max_str_digits") else 4300
    match = re.search(rf"\d{{{limit + 1},}}", text) if limit else None
    if match is None:
        return None, None, 0
    line, column = text_place(text, match.start())
    return line, column, len(match.group(0))


def deepest(text: str) -> tuple[int, int, int]:
    """``(line, column, depth)`` of the first place where ``text`` is nested deepest: the
    bracket that opens its deepest level of flow collections (``[`` and ``{``, outside quoted
    scalars and comments), or, where block indentation nests deeper than that, the first line
    of the largest indentation (its depth counted in indentation steps of two spaces)."""
    depth = best = 0
    where = (1, 1)
    quote = ""
    for number, line in enumerate(text.splitlines(), start=1):
        for index, char in enumerate(line):
            if quote:
                if char == quote:
                    quote = ""
            elif char in "'\"":
                quote = char
            elif char == "#" and (index == 0 or line[index - 1] in " \t"):
                break
            elif char in "[{":
                depth += 1
                if depth > best:
                    best, where = depth, (number, index + 1)
            elif char in "]}" and depth:
                depth -= 1
    indents = [
        (len(line) - len(line.lstrip(" ")), number)
        for number, line in enumerate(text.splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if indents:
        indent, number = max(indents, key=lambda pair: (pair[0], -pair[1]))
        if indent // 2 > best:
            return number, indent + 1, indent // 2
    return where[0], where[1], best


# ---------------------------------------------------------------------------------------------
# diagnostics and located values
# ---------------------------------------------------------------------------------------------
Location = tuple[int | None, int | None]


class Report:
    """Collects diagnostics for one source."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.diagnostics: list[Diagnostic] = []

    def _add(self, where: Node | Location | None, path: str | None, message: str, sev: str):
        if isinstance(where, Node):
            line, column = where.line, where.column
            path = where.path if path is None else path
        elif where is None:
            line, column = None, None
        else:
            line, column = where
        self.diagnostics.append(Diagnostic(self.source, line, column, path or "", message, sev))  # type: ignore[arg-type]

    def error(self, where: Node | Location | None, path: str | None, message: str) -> None:
        self._add(where, path, message, "error")

    def warning(self, where: Node | Location | None, path: str | None, message: str) -> None:
        self._add(where, path, message, "warning")

    @property
    def error_count(self) -> int:
        return sum(1 for d in self.diagnostics if d.severity == "error")


@dataclass
class Node:
    """A value from the YAML tree with its 1-based position and key path."""

    value: Any
    line: int | None
    column: int | None
    path: str

    @property
    def is_map(self) -> bool:
        return isinstance(self.value, dict)

    @property
    def is_seq(self) -> bool:
        return isinstance(self.value, list)

    @property
    def is_null(self) -> bool:
        return self.value is None

    def has(self, key: str) -> bool:
        return self.is_map and key in self.value

    def key(self, key: Any) -> Node:
        """The key itself, positioned where the key is written."""
        line, column = _lc(self.value, "key", key, (self.line, self.column))
        return Node(key, line, column, join(self.path, key))

    def child(self, key: Any) -> Node:
        """The value under ``key`` (positioned at the key when the value is empty)."""
        value = self.value[key]
        if value is None:
            line, column = _lc(self.value, "key", key, (self.line, self.column))
        else:
            line, column = _lc(self.value, "value", key, (self.line, self.column))
        return Node(value, line, column, join(self.path, key))

    def entries(self) -> list[tuple[Node, Node]]:
        return [(self.key(k), self.child(k)) for k in self.value]

    def items(self) -> list[Node]:
        nodes = []
        for index, value in enumerate(self.value):
            line, column = _lc(self.value, "item", index, (self.line, self.column))
            nodes.append(Node(value, line, column, f"{self.path}[{index}]"))
        return nodes

    def missing(self, key: str) -> Node:
        """Where to report a missing ``key``: the start of this mapping, at the key's path."""
        return Node(None, self.line, self.column, join(self.path, key))


def _lc(container: Any, kind: str, key: Any, default: Location) -> Location:
    """1-based position of a key, value or item (``kind``) from the tree's marks."""
    try:
        if kind == "item":
            line, column = container.marks[key]
        else:
            marks = container.marks[key]
            line, column = (marks[0], marks[1]) if kind == "key" else (marks[2], marks[3])
        return line + 1, column + 1
    except (AttributeError, LookupError, TypeError):  # merged keys have no marks
        return default


def at(node: Node) -> str:
    return f"line {node.line}, column {node.column}"


def _one_line(text: str) -> str:
    return " ".join(text.split())


def fmt(value: float) -> str:
    return f"{value:g}"


def describe(value: Any) -> str:
    """How a YAML value reads in a message: "'abc' (a string)", "a list", ..."""
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool | ScalarBoolean):
        return f"{str(bool(value)).lower()} (a boolean)"
    if isinstance(value, str):
        return f"{str(value)!r} (a string)"
    if isinstance(value, int | float):
        return f"the number {value}"
    if isinstance(value, Mapping):
        return "a mapping"
    if isinstance(value, list | tuple):  # a tuple: a list used as a mapping key
        return "a list"
    return f"a {type(value).__name__} value"


def is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool | ScalarBoolean)


def suggest(key: Any, known: Sequence[str]) -> str:
    if not isinstance(key, str):
        return ""
    close = difflib.get_close_matches(key, known, n=1)
    return f" (did you mean '{close[0]}'?)" if close else ""


def root_node(data: Any) -> Node:
    """The top-level mapping as a :class:`Node`, positioned at its first key (where missing
    top-level keys are reported)."""
    line, column = _lc(data, "key", next(iter(data)), (1, 1)) if data else (1, 1)
    return Node(data, line, column, "")


# ---------------------------------------------------------------------------------------------
# reading values
# ---------------------------------------------------------------------------------------------
class NodeReader:
    """Checks values read from YAML nodes, recording each problem in ``report`` at the node.

    Every method returns the value read (in internal units, through ``units``), or ``None``
    after reporting why it is invalid.
    """

    def __init__(self, report: Report) -> None:
        self.report = report
        self.units = Units()

    def error(self, node: Node, message: str) -> None:
        self.report.error(node, None, message)

    def warn_unknown(self, node: Node, known: Sequence[str], where: str) -> None:
        """Warn about keys of mapping ``node`` not in ``known``."""
        for key_node, _ in node.entries():
            if key_node.value not in known:
                self.report.warning(
                    key_node,
                    None,
                    f"unknown key {key_node.value!r} in {where} is ignored"
                    f"{suggest(key_node.value, known)}; known keys: {', '.join(known)}",
                )

    def required(self, node: Node, key: str, expected: str) -> Node | None:
        """The child ``key`` of mapping ``node``; when it is missing, report "missing required
        key; expected ``expected``" at the mapping and return None."""
        if node.has(key):
            return node.child(key)
        self.error(node.missing(key), f"missing required key; expected {expected}")
        return None

    def mapping(self, node: Node, expected: str, *, null_ok: bool = False) -> bool:
        if node.is_map or (null_ok and node.is_null):
            return True
        self.error(node, f"expected {expected}, got {describe(node.value)}")
        return False

    def string(self, node: Node, expected: str = "a string") -> str | None:
        if isinstance(node.value, str) and node.value.strip():
            return str(node.value)
        self.error(node, f"expected {expected}, got {describe(node.value)}")
        return None

    def number(self, node: Node, what: str = "a number") -> float | None:
        value = node.value
        if is_number(value):
            try:
                result = float(value)
            except OverflowError:
                result = math.inf
            if math.isfinite(result):
                return result
        self.error(node, f"expected {what} (a finite number), got {describe(value)}")
        return None

    def vector(self, node: Node, *forms: Sequence[str]) -> tuple[float, ...] | None:
        """A list of numbers whose length matches one of ``forms`` (their labels)."""
        expected = " or ".join(f"[{', '.join(labels)}]" for labels in forms)
        if not node.is_seq or len(node.value) not in {len(f) for f in forms}:
            got = describe(node.value)
            if node.is_seq:
                got = f"a list of {len(node.value)} value{'s' if len(node.value) != 1 else ''}"
            self.error(node, f"expected {expected}, got {got}")
            return None
        labels = next(f for f in forms if len(f) == len(node.value))
        values = [self.number(item, labels[i]) for i, item in enumerate(node.items())]
        if any(v is None for v in values):
            return None
        return tuple(values)  # type: ignore[arg-type]

    def non_negative(
        self, node: Node, values: tuple[float, ...] | None, what: str
    ) -> tuple[float, ...] | None:
        return self._signed(node, values, what, allow_zero=True)

    def positive(
        self, node: Node, values: tuple[float, ...] | None, what: str
    ) -> tuple[float, ...] | None:
        return self._signed(node, values, what, allow_zero=False)

    def _signed(
        self, node: Node, values: tuple[float, ...] | None, what: str, *, allow_zero: bool
    ) -> tuple[float, ...] | None:
        """``values`` (read from list ``node``) if each is >= 0 (> 0 unless ``allow_zero``),
        else None after reporting every offending item."""
        if values is None:
            return None
        ok = True
        for item, value in zip(node.items(), values, strict=True):
            if value < 0 or (value == 0 and not allow_zero):
                sign = "negative" if value < 0 else "zero"
                bound = ">= 0" if allow_zero else "> 0"
                self.error(item, f"{sign} {what} {fmt(value)}; expected a value {bound}")
                ok = False
        return values if ok else None

    def angle(self, node: Node, value: float) -> float | None:
        """``value`` (the file's angle unit, read from ``node``) in radians, or None after
        reporting an angle too large to mean an orientation (:data:`validation.MAX_ANGLE`)."""
        radians = self.units.angle_in(value)
        reason = angle_problem(radians, self.units.angle)
        if reason is not None:
            self.error(node, f"angle {fmt(value)} {self.units.angle}: {reason}")
            return None
        return radians

    def pose(self, node: Node) -> Pose | None:
        values = self.vector(node, ("x", "y", "theta"))
        if values is None or self.angle(node.items()[2], values[2]) is None:
            return None
        return self.units.pose_in(values)  # type: ignore[arg-type]

    def half_widths(self, node: Node) -> tuple[float, float, float] | None:
        values = self.vector(node, ("dx", "dy", "dtheta"))
        values = self.non_negative(node, values, "half-width")
        if values is None or self.angle(node.items()[2], values[2]) is None:
            return None
        return self.units.pose_in(values)  # type: ignore[arg-type]

    def list_of(self, node: Node, expected: str) -> list[Node] | None:
        if not node.is_seq or not node.value:
            got = "an empty list" if node.is_seq else describe(node.value)
            self.error(node, f"expected {expected}, got {got}")
            return None
        return node.items()

    def range(
        self, node: Node, convert: Callable[[float], float], *, positive: bool = False
    ) -> tuple[float, float] | None:
        """A uniform range ``[low, high]`` with ``0 <= low <= high`` (``0 < low`` when
        ``positive``), converted by ``convert``."""
        values = self.vector(node, ("low", "high"))
        values = (self.positive if positive else self.non_negative)(node, values, "value")
        if values is None:
            return None
        low, high = values
        if low > high:
            self.error(
                node,
                f"low {fmt(low)} is above high {fmt(high)}; expected [low, high] "
                f"with 0 {'<' if positive else '<='} low <= high",
            )
            return None
        return (convert(low), convert(high))

    def numbers(self, node: Node, what: str, *, positive: bool) -> tuple[float, ...] | None:
        items = self.list_of(node, f"a non-empty list of {what}s")
        if items is None:
            return None
        article = "an" if what[0] in "aeiou" else "a"
        values = [self.number(item, f"{article} {what}") for item in items]
        numbers = tuple(v for v in values if v is not None)
        if len(numbers) < len(values):
            return None
        return self.positive(node, numbers, what) if positive else numbers


def _char(character: Any) -> str:
    """A character as ``U+0000`` (ruamel reports code points as ints)."""
    if isinstance(character, int):
        return f"U+{character:04X}"
    if isinstance(character, str) and len(character) == 1:
        return f"U+{ord(character):04X}"
    return repr(character)
