"""YAML text to a positioned tree: every mapping key, mapping value and list item with the place
where it is written, and the duplicate keys.

Two parsers build the same tree (:class:`YamlMap`, :class:`YamlSeq` and scalars):

* **libyaml** (PyYAML's C parser, read event by event here): the fast reading. It takes what
  problem files are made of: one document of mappings with scalar keys, lists, plain and quoted
  scalars, anchors and aliases of mappings and lists.
* **ruamel's round-trip loader**: the reference reading. It reads every document the libyaml
  reading does not take (:class:`Unsupported`: directives, explicit tags, merge keys, anchored
  scalars, timestamps, integers other than plain decimals, numbers with ``_``, tabs and rare
  characters, nesting deeper than :data:`MAX_FAST_DEPTH`), every document libyaml refuses (so
  ruamel words each syntax error), and everything when PyYAML was built without libyaml.

Plain scalars are read by ruamel's YAML 1.2 rules in both (its own resolver table): ``yes``,
``on`` and ``1:30`` are strings, ``1e3`` is 1000.0, ``017`` is 17, ``.inf`` is infinite. A file
means the same whichever parser reads it; ``tests/io/test_yaml_tree.py`` compares the two.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.nodes import MappingNode, ScalarNode, SequenceNode
from ruamel.yaml.parser import ParserError
from ruamel.yaml.resolver import VersionedResolver
from ruamel.yaml.scanner import ScannerError

try:  # PyYAML's binding of libyaml; PyYAML wheels ship it
    from yaml import MarkedYAMLError as LibyamlMarkedError
    from yaml import __with_libyaml__
    from yaml.events import (
        AliasEvent,
        MappingEndEvent,
        MappingStartEvent,
        ScalarEvent,
        SequenceEndEvent,
        SequenceStartEvent,
        StreamEndEvent,
    )

    if __with_libyaml__:
        from yaml.cyaml import CParser
    else:  # pragma: no cover - a PyYAML built without libyaml
        CParser = None
except ImportError:  # pragma: no cover - PyYAML is a dependency
    CParser = None

__all__ = [
    "MAX_FAST_DEPTH",
    "Document",
    "Duplicate",
    "Refused",
    "Unsupported",
    "YamlMap",
    "YamlSeq",
    "join",
    "read",
    "read_libyaml",
    "read_ruamel",
]

#: Deeper documents go to ruamel, which decides whether they are nested too deeply to read.
MAX_FAST_DEPTH = 64
#: Characters the libyaml reading leaves to ruamel: tabs, control characters, the YAML 1.1
#: line breaks (NEL, LS, PS), byte-order marks and anything ruamel's reader refuses.
_RARE = re.compile(
    "[^\n\r\x20-\x7e\xa0-\u2027\u202a-\ud7ff\ue000-\ufefe\uff00-\ufffd\U00010000-\U0010ffff]"
)
#: A libyaml syntax error is worded by ruamel reading the text up to this many characters past
#: it (the whole text when ruamel's error is not clearly before the cut, see
#: :func:`_raise_ruamel_error`).
_ERROR_PREFIX = 8192
_CUT_MARGIN = 2048


class Unsupported(Exception):
    """The libyaml reading does not take this document; ruamel reads it."""


class Refused(Exception):
    """libyaml refused the text: ``error`` is its ``MarkedYAMLError``; ``spans`` are the
    ``(start, end)`` character ranges, one per collection open at the error, from the start of
    its first child to the start of its last (empty when the text has anchors)."""

    def __init__(self, error: Exception, spans: list[tuple[int, int]]) -> None:
        super().__init__(str(error))
        self.error = error
        self.spans = spans


class YamlMap(dict):
    """A mapping with ``marks[key] = (key line, key column, value line, value column)``,
    0-based, for each key written in it (keys merged in by ``<<`` have none). Where an empty
    value is written depends on the parser (readers point at its key instead)."""

    __slots__ = ("marks",)

    def __init__(self) -> None:
        super().__init__()
        self.marks: dict[Any, tuple[int, int, int, int]] = {}


class YamlSeq(list):
    """A list with ``marks[index] = (line, column)``, 0-based, of each item."""

    __slots__ = ("marks",)

    def __init__(self) -> None:
        super().__init__()
        self.marks: list[tuple[int, int] | None] = []


#: ``(line, column, path, key, (first line, first column))``, 1-based: a key given again in one
#: mapping (same tag and text), at its path in the document.
Duplicate = tuple[int, int, str, str, tuple[int, int]]


@dataclass
class Document:
    """The top-level value (``None`` when the document is empty), where its node starts
    (0-based) and the duplicate keys."""

    root: Any
    line: int
    column: int
    duplicates: list[Duplicate] = field(default_factory=list)


def join(path: str, key: Any) -> str:
    return f"{path}.{key}" if path else str(key)


def read(text: str) -> Document | None:
    """The document of ``text`` (``None`` when there is none), read by libyaml when it takes
    the document and by ruamel otherwise; ruamel's exceptions (its syntax errors,
    ``RecursionError``, the ``ValueError`` of an integer too long to convert) propagate."""
    if CParser is not None:
        try:
            return read_libyaml(text)
        except Refused as refused:
            _raise_ruamel_error(text, refused)
        except Exception:  # Unsupported, or anything unforeseen: the reference reading decides
            pass
    return read_ruamel(text)


def _raise_ruamel_error(text: str, refused: Refused) -> None:
    """Raise ruamel's error for a text libyaml refused, found in a shorter text that ruamel
    reads as it reads ``text`` up to the error; return (for a reading of the whole text) when
    that cannot be trusted.

    The shorter text ends a little past libyaml's error (a streaming parser finds the same first
    error in a text and in any prefix reaching well past it: a cut is trusted when ruamel's
    error lies clearly before it) and leaves out, in each collection open at the error, the
    children between its first and its last (``refused.spans``): the parser is in the same state
    after the first child as after any other, so it meets the last child, and the error, in the
    same state. ruamel's places are mapped back to ``text``, and trusted only when ruamel's
    error is on the line of libyaml's (or next to it).
    """
    mark = refused.error.problem_mark or refused.error.context_mark
    if mark is None or "\r" in text:
        return
    cut = mark.index + _ERROR_PREFIX
    spans = [(start, end) for start, end in refused.spans if end <= cut]
    if cut >= len(text) and not spans:
        return  # nothing to leave out: the whole text is read anyway
    pieces, kept, removed, at = [], [], 0, 0
    for start, end in spans:
        pieces.append(text[at:start])
        kept.append((start - removed, end - start))  # (start in the shorter text, length)
        removed += end - start
        at = end
    pieces.append(text[at:cut])
    shorter = "".join(pieces)
    try:
        read_ruamel(shorter)
    except (ScannerError, ParserError) as found:  # a syntax error, not a later stage's
        where = found.problem_mark or found.context_mark
        if where is None or (cut < len(text) and where.index >= len(shorter) - _CUT_MARGIN):
            return
        places = {id(place): place for place in (found.problem_mark, found.context_mark)}
        for place in places.values():  # one mark may be both
            if place is not None:
                index = place.index + sum(length for start, length in kept if start <= place.index)
                place.index = index
                place.line = text.count("\n", 0, index)
                place.column = index - (text.rfind("\n", 0, index) + 1)
        if abs(where.line - mark.line) <= 1:  # libyaml puts an error at the end on a line after
            raise
    except Exception:  # the whole text decides
        pass


# ---------------------------------------------------------------------------------------------
# the reference reading: ruamel
# ---------------------------------------------------------------------------------------------
def read_ruamel(text: str) -> Document | None:
    """``text`` read by ruamel's round-trip loader (YAML 1.2), the tree copied into
    :class:`YamlMap` / :class:`YamlSeq` with ruamel's positions."""
    yaml = YAML(typ="rt")
    yaml.allow_duplicate_keys = True  # found and reported from the node tree instead
    node = yaml.compose(text)
    if node is None:
        return None
    data = yaml.constructor.construct_document(node)
    duplicates = list(_ruamel_duplicates(node))
    return Document(_positioned(data), node.start_mark.line, node.start_mark.column, duplicates)


def _ruamel_duplicates(root: Any) -> Iterator[Duplicate]:
    """Every duplicate key in ruamel's composed node tree."""
    seen: set[int] = set()
    stack: list[tuple[Any, str]] = [(root, "")]
    while stack:
        node, path = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, MappingNode):
            first: dict[tuple[str, str], tuple[int, int]] = {}
            for key_node, value_node in node.value:
                if isinstance(key_node, ScalarNode):
                    key_path = join(path, key_node.value)
                    ident = (str(key_node.tag), str(key_node.value))
                    if ident[0].endswith(":merge"):
                        pass
                    elif ident in first:
                        mark = key_node.start_mark
                        yield mark.line + 1, mark.column + 1, key_path, ident[1], first[ident]
                    else:
                        mark = key_node.start_mark
                        first[ident] = (mark.line + 1, mark.column + 1)
                else:
                    key_path = join(path, "?")
                stack.append((value_node, key_path))
        elif isinstance(node, SequenceNode):
            for index, item in enumerate(node.value):
                stack.append((item, f"{path}[{index}]"))


def _positioned(data: Any) -> Any:
    """ruamel's constructed value with its mappings and lists copied into :class:`YamlMap` and
    :class:`YamlSeq` (shared and recursive ones stay shared); scalars are kept as they are."""
    made: dict[int, Any] = {}
    work: list[tuple[Any, Any]] = []

    def shell(value: Any) -> Any:
        if not isinstance(value, dict | list):
            return value
        copy = made.get(id(value))
        if copy is None:
            copy = made[id(value)] = YamlMap() if isinstance(value, dict) else YamlSeq()
            work.append((value, copy))
        return copy

    root = shell(data)
    while work:
        source, copy = work.pop()
        lc = getattr(source, "lc", None)
        records = (lc.data if lc is not None else None) or {}
        if isinstance(copy, YamlMap):
            for key in source:
                copy[key] = shell(source[key])
                record = records.get(key)
                if record is not None:
                    copy.marks[key] = (record[0], record[1], record[2], record[3])
        else:
            for index, item in enumerate(source):
                copy.append(shell(item))
                record = records.get(index)
                copy.marks.append(None if record is None else (record[0], record[1]))
    return root


# ---------------------------------------------------------------------------------------------
# the fast reading: libyaml's events
# ---------------------------------------------------------------------------------------------
_STR, _NULL, _BOOL, _INT, _FLOAT = (
    f"tag:yaml.org,2002:{name}" for name in ("str", "null", "bool", "int", "float")
)
#: ruamel's YAML 1.2 implicit resolvers: first character -> [(tag, pattern)], in its order.
_RESOLVERS: dict[str, list[tuple[str, re.Pattern[str]]]] = {
    first: [(tag, re.compile(regexp.pattern, regexp.flags)) for tag, regexp in resolvers]
    for first, resolvers in VersionedResolver(version=(1, 2)).versioned_resolver.items()
    if first is not None
}
_DECIMAL = re.compile(r"[-+]?[0-9]+")
_INF = float("inf")
_NAN = -_INF / _INF  # one object, as ruamel's, so two ``.nan`` keys are one key


def _resolve(text: str) -> str:
    """A plain scalar's tag by ruamel's YAML 1.2 resolver."""
    for tag, pattern in _RESOLVERS.get(text[:1], ()):
        if pattern.match(text):
            return tag
    return _STR


def _plain(text: str) -> tuple[Any, str]:
    """A plain scalar's value and tag, as ruamel's round-trip constructor reads it."""
    tag = _resolve(text)
    if tag == _STR:
        return text, tag
    if tag == _NULL:
        return None, tag
    if tag == _BOOL:
        return text.lower() == "true", tag
    if tag == _INT and _DECIMAL.fullmatch(text):
        return int(text), tag  # a ValueError past Python's digit limit, as in ruamel
    if tag == _FLOAT and "_" not in text:
        lowered = text.lower()
        sign = -1 if lowered[0] == "-" else 1
        if lowered[0] in "+-":
            lowered = lowered[1:]
        if lowered == ".inf":
            return sign * _INF, tag
        if lowered == ".nan":
            return _NAN, tag
        return sign * float(lowered), tag
    raise Unsupported(f"plain scalar {text!r} ({tag})")


class _Frame:
    """A mapping or list being read: its value, path, anchor, start and the key read last."""

    __slots__ = ("anchor", "column", "first", "first_child", "key", "last_child", "line", "path")
    __slots__ += ("value",)

    def __init__(self, value: Any, path: str, anchor: str | None, line: int, column: int):
        self.value = value
        self.path = path
        self.anchor = anchor
        self.line = line
        self.column = column
        self.key: tuple[Any, str, str, int, int] | None = None  # value, tag, text, line, column
        self.first: dict[tuple[str, str], tuple[int, int]] = {}
        # Where the first and the latest child (item, or key of a pair) start in the text.
        self.first_child = self.last_child = -1


def read_libyaml(text: str) -> Document | None:
    """``text`` read from libyaml's events into the tree ruamel's reading gives.

    Raises :class:`Unsupported` for what it leaves to ruamel, :class:`Refused` for a text
    libyaml refuses, and ``ValueError`` for an integer too long to convert (after reading the
    whole document, as ruamel constructs after composing).
    """
    if CParser is None:
        raise Unsupported("PyYAML without libyaml")
    if _RARE.search(text):
        raise Unsupported("a tab or a rare character")
    stack: list[_Frame] = []
    defined: set[str] = set()
    try:
        return _compose(CParser(text), stack, defined)
    except LibyamlMarkedError as error:
        spans = [] if defined else [(f.first_child, f.last_child) for f in stack]
        spans = [(start, end) for start, end in spans if 0 <= start < end]
        raise Refused(error, spans) from None


def _compose(parser: Any, stack: list[_Frame], defined: set[str]) -> Document | None:
    """The document of ``parser``'s events; ``stack`` holds the collections open, ``defined``
    the anchors seen (for :func:`read_libyaml` when libyaml refuses the text)."""
    get = parser.get_event
    get()  # the stream's start
    event = get()
    if type(event) is StreamEndEvent:
        return None
    if event.version is not None or event.tags:
        raise Unsupported("a directive")
    anchors: dict[str, tuple[Any, int, int]] = {}
    duplicates: list[Duplicate] = []
    too_long: ValueError | None = None
    while True:
        event = get()
        kind = type(event)
        if kind is ScalarEvent or kind is AliasEvent:
            if stack:  # a list item or a mapping key starts a child of its collection
                parent = stack[-1]
                if parent.key is None or isinstance(parent.value, YamlSeq):
                    if parent.first_child < 0:
                        parent.first_child = event.start_mark.index
                    parent.last_child = event.start_mark.index
        if kind is ScalarEvent:
            if event.anchor is not None or event.tag is not None:
                raise Unsupported("an anchored or tagged scalar")
            source = event.value
            if event.style:
                value, tag = source, _STR
            else:
                try:
                    value, tag = _plain(source)
                except ValueError as error:  # raised once the whole document is read
                    too_long = too_long or error
                    value, tag = None, _INT
            mark = event.start_mark
            line, column = mark.line, mark.column
        elif kind is AliasEvent:
            if event.anchor not in anchors:
                raise Unsupported("an alias of an anchor not (yet) complete")
            value, line, column = anchors[event.anchor]
            tag = source = ""
        elif kind is MappingStartEvent or kind is SequenceStartEvent:
            if event.tag is not None:
                raise Unsupported("a tagged collection")
            if len(stack) >= MAX_FAST_DEPTH:
                raise Unsupported("deep nesting")
            if event.anchor is not None:
                if event.anchor in defined:
                    raise Unsupported("an anchor defined twice")
                defined.add(event.anchor)
            mark = event.start_mark
            if stack:
                parent = stack[-1]
                if isinstance(parent.value, YamlSeq):
                    path = f"{parent.path}[{len(parent.value)}]"
                    if parent.first_child < 0:
                        parent.first_child = mark.index
                    parent.last_child = mark.index
                elif parent.key is None:
                    raise Unsupported("a collection as a mapping key")
                else:
                    path = join(parent.path, parent.key[2])
            else:
                path = ""
            container = YamlMap() if kind is MappingStartEvent else YamlSeq()
            stack.append(_Frame(container, path, event.anchor, mark.line, mark.column))
            continue
        elif kind is MappingEndEvent or kind is SequenceEndEvent:
            frame = stack.pop()
            value, line, column = frame.value, frame.line, frame.column
            tag = source = ""
            if frame.anchor is not None:
                anchors[frame.anchor] = (value, line, column)
        else:  # pragma: no cover - libyaml gives no other event inside a document
            raise Unsupported(f"event {kind.__name__}")

        if not stack:
            break
        parent = stack[-1]
        container = parent.value
        if isinstance(container, YamlSeq):
            container.append(value)
            container.marks.append((line, column))
        elif parent.key is None:
            if kind is not ScalarEvent:
                raise Unsupported("an alias as a mapping key")
            parent.key = (value, tag, source, line, column)
        else:
            key, key_tag, key_text, key_line, key_column = parent.key
            parent.key = None
            ident = (key_tag, key_text)
            if ident in parent.first:
                duplicates.append(
                    (
                        key_line + 1,
                        key_column + 1,
                        join(parent.path, key_text),
                        key_text,
                        parent.first[ident],
                    )
                )
            else:
                parent.first[ident] = (key_line + 1, key_column + 1)
            if key not in container:  # a later equal key is dropped, as ruamel drops it
                container[key] = value
                container.marks[key] = (key_line, key_column, line, column)

    get()  # the document's end
    if type(get()) is not StreamEndEvent:
        raise Unsupported("more than one document")
    if duplicates and anchors:
        raise Unsupported("duplicate keys and aliases (ruamel's walk names their paths)")
    if too_long is not None:
        raise too_long
    return Document(value, line, column, duplicates)
