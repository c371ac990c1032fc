"""YAML text to a positioned tree: every mapping key, mapping value and list item with the place
where it is written, and the duplicate keys.

Two parsers build the same tree (:class:`YamlMap`, :class:`YamlSeq` and scalars):

* **libyaml** (PyYAML's C parser, read event by event here): the fast reading, of any one
  document: anchors and aliases of any node, merge keys (``<<``), explicit tags, ``%YAML 1.1`` /
  ``1.2`` and ``%TAG`` directives, tabs where YAML allows them. It means what ruamel's reading
  means: plain scalars are resolved by ruamel's own resolver table of the document's YAML
  version; scalars it does not build itself (anchored or tagged ones, other integer bases,
  timestamps, ...) and collections with a tag other than ``!!map`` / ``!!seq`` are built by
  ruamel's round-trip constructor from nodes made of libyaml's events; merge keys are merged as
  that constructor merges them (the mapping's own keys first, then each merged mapping's keys
  not given yet, the first merged first) and refused with its errors; duplicate keys are found
  at the paths ruamel's walk of its node tree names; an undefined alias or a second document is
  ruamel's error.
* **ruamel's round-trip loader**: the reference reading, pure Python and many times slower
  (``benchmarks/big_inputs.py --files``). It reads the few
  documents the libyaml reading does not take (:class:`Unsupported`: recursive aliases,
  collections as mapping keys, NEL, LS, PS and byte-order marks in the text (which libyaml reads
  as YAML 1.1 line breaks and ruamel otherwise), control characters (which ruamel refuses
  before parsing), nesting deeper than :data:`MAX_FAST_DEPTH`, several errors of building values
  (ruamel's order of building decides which is reported), and a few tag spellings the two
  scanners read differently), words every syntax error libyaml finds (from a short text), and
  reads everything when PyYAML was built without libyaml.

Tabs: YAML allows a tab between tokens on a line (``a:\t1``); libyaml reads it, ruamel refuses
it outside flow collections. The fast reading reads such files; ruamel words a syntax error
found after such a tab in the text with those tabs made spaces (:func:`_untabbed`).
Plain scalars are read by ruamel's YAML 1.2 rules unless ``%YAML 1.1`` says otherwise: ``yes``,
``on`` and ``1:30`` are strings, ``1e3`` is 1000.0, ``017`` is 17, ``.inf`` is infinite. A file
means the same whichever parser reads it; ``tests/io/test_yaml_tree.py`` compares the two.
Why the second reading is kept: docs/design/io.md, "the cost of ruamel alone"
(``benchmarks/yaml_paths.py``).
"""

from __future__ import annotations

import bisect
import gc
import re
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.composer import ComposerError
from ruamel.yaml.constructor import ConstructorError, DuplicateKeyError, RoundTripConstructor
from ruamel.yaml.error import ReusedAnchorWarning, StringMark
from ruamel.yaml.nodes import MappingNode, ScalarNode, SequenceNode
from ruamel.yaml.parser import Parser, ParserError
from ruamel.yaml.resolver import VersionedResolver
from ruamel.yaml.scanner import ScannerError
from ruamel.yaml.tag import Tag

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
#: Characters the libyaml reading leaves to ruamel: control characters and anything ruamel's
#: reader refuses (ruamel refuses the text at once, before parsing), and the line breaks NEL,
#: LS and PS and byte-order marks in the text, which libyaml reads as YAML 1.1 does and ruamel
#: otherwise (``tests/io/test_yaml_tree.py`` shows how).
_RARE = re.compile(
    "[^\t\n\r\x20-\x7e\xa0-\u2027\u202a-\ud7ff\ue000-\ufefe\uff00-\ufffd\U00010000-\U0010ffff]"
)
DEFAULT_TAGS = Parser.DEFAULT_TAGS
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
    its first child to the start of its last (empty when the text has anchors);
    ``scalar_spans`` (for a text with tabs) where the scalars read before the error are."""

    def __init__(
        self,
        error: Exception,
        spans: list[tuple[int, int]],
        scalar_spans: list[tuple[int, int]] | None = None,
    ) -> None:
        super().__init__(str(error))
        self.error = error
        self.spans = spans
        self.scalar_spans = scalar_spans


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
    """The key path of ``key`` under ``path``; a complex key (a YAML list or mapping used as a
    key, which reaches here as a tuple or mapping) is written in YAML's flow style."""
    return f"{path}.{_key_text(key)}" if path else _key_text(key)


def _key_text(key: Any) -> str:
    if isinstance(key, tuple):
        return "[" + ", ".join(_key_text(k) for k in key) + "]"
    if isinstance(key, Mapping):
        return "{" + ", ".join(f"{_key_text(k)}: {_key_text(v)}" for k, v in key.items()) + "}"
    return str(key)


def read(text: str) -> Document | None:
    """The document of ``text`` (``None`` when there is none), read by libyaml when it takes
    the document and by ruamel otherwise; ruamel's exceptions (its syntax errors,
    ``RecursionError``, the ``ValueError`` of an integer too long to convert) propagate."""
    if CParser is not None:
        try:
            return _read_fast(text)
        except _Found as found:
            raise found.error from None
        except Refused as refused:
            text = _untabbed(text, refused)
            _raise_ruamel_error(text, refused)
        except Exception:  # Unsupported, or anything unforeseen: the reference reading decides
            pass
    return read_ruamel(text)


def _untabbed(text: str, refused: Refused) -> str:
    """``text`` with each tab libyaml read as a space between tokens before its error (not in
    a scalar) made a space: ruamel refuses a tab there outside flow collections, which YAML
    allows and libyaml reads, so that ruamel words the error libyaml found."""
    mark = refused.error.problem_mark or refused.error.context_mark
    if refused.scalar_spans is None or mark is None:
        return text
    pieces, at = [], 0
    for start, end in [*refused.scalar_spans, (mark.index, mark.index)]:
        start = min(max(start, at), mark.index)
        pieces += [text[at:start].replace("\t", " "), text[start : max(start, end)]]
        at = max(start, end)
    pieces.append(text[at:])
    return "".join(pieces)


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


def _ruamel_duplicates(root: Any, path: str = "") -> Iterator[Duplicate]:
    """Every duplicate key in ruamel's composed node tree under ``root`` (at ``path``), each
    at the path where this walk (depth first, the last child first) first meets its mapping."""
    seen: set[int] = set()
    stack: list[tuple[Any, str]] = [(root, path)]
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


def _positioned(data: Any, made: dict[int, Any] | None = None) -> Any:
    """ruamel's constructed value with its mappings and lists copied into :class:`YamlMap` and
    :class:`YamlSeq` (shared and recursive ones stay shared; ``made`` maps the ``id`` of each
    to its copy); scalars are kept as they are."""
    made = {} if made is None else made
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
_STR, _NULL, _BOOL, _INT, _FLOAT, _MERGE, _VALUE, _MAP, _SEQ = (
    f"tag:yaml.org,2002:{name}"
    for name in ("str", "null", "bool", "int", "float", "merge", "value", "map", "seq")
)


def _resolver_table(version: tuple[int, int]) -> dict[str, list[tuple[str, re.Pattern[str]]]]:
    """ruamel's implicit resolvers of YAML ``version``: first character -> [(tag, pattern)]."""
    resolvers = VersionedResolver(version=version).versioned_resolver
    anywhere = resolvers.get(None, [])
    return {
        first: [
            (tag, re.compile(regexp.pattern, regexp.flags)) for tag, regexp in listed + anywhere
        ]
        for first, listed in resolvers.items()
        if first is not None
    }


#: ruamel's implicit resolvers per YAML version (a ``%YAML 1.1`` directive selects 1.1's).
_RESOLVERS = {version: _resolver_table(version) for version in ((1, 2), (1, 1))}
_DECIMAL = {(1, 2): re.compile(r"[-+]?[0-9]+"), (1, 1): re.compile(r"[-+]?(?:0|[1-9][0-9]*)")}
_BOOL_VALUES = RoundTripConstructor.bool_values
_INF = RoundTripConstructor.inf_value
_NAN = RoundTripConstructor.nan_value  # ruamel's one object, so two ``.nan`` keys are one key
_DELEGATE = object()  # "ruamel's constructor builds this scalar"


def _resolve(text: str, table: dict[str, list[tuple[str, re.Pattern[str]]]]) -> str:
    """A plain scalar's tag by ruamel's resolver ``table``."""
    for tag, pattern in table.get(text[:1], ()):
        if pattern.match(text):
            return tag
    return _STR


def _native(text: str, tag: str, version: tuple[int, int]) -> Any:
    """A plain, untagged, unanchored scalar's value as ruamel's round-trip constructor builds it
    (equal, and equal in ``str``, ``repr`` and type tests), or :data:`_DELEGATE` for the forms
    left to that constructor (other integer bases, ``_``, sexagesimals, timestamps, ...).
    Raises ``ValueError`` for an integer too long to convert, as ruamel does."""
    if tag == _STR:
        return text
    if tag == _NULL:
        return None
    if tag == _BOOL:
        return _BOOL_VALUES[text.lower()]
    if tag == _INT:
        return int(text) if _DECIMAL[version].fullmatch(text) else _DELEGATE
    if tag == _FLOAT and "_" not in text and ":" not in text:
        lowered = text.lower()
        sign = -1 if lowered[0] == "-" else 1
        if lowered[0] in "+-":
            lowered = lowered[1:]
        if lowered == ".inf":
            return sign * _INF
        if lowered == ".nan":
            return _NAN
        if version != (1, 2) and "e" in lowered and "." not in lowered.split("e")[0]:
            return _DELEGATE  # ruamel warns of a YAML 1.1 mantissa without a dot
        return sign * float(lowered)
    return _DELEGATE


#: A tag as written (ruamel's scanner): ``!<verbatim>``, ``!handle!suffix``, ``!suffix``, ``!``.
_TAG_TOKEN = re.compile(r"!(?:<(?P<verbatim>[^>\s]*)>|(?P<handle>[0-9A-Za-z_-]*!)?)")
_URI = re.compile(r"[0-9A-Za-z\-;/?:@&=+$,_.!~*'()\[\]#]*")
_ANCHOR_NAME = re.compile(r"&[^\s,\[\]{}]+")
_SPACE = re.compile(r"[ \t]*")
_GAP = re.compile(r"(?:[ \t\r\n]|#[^\r\n]*)*")  # spaces, line breaks and comments
_VERSION = re.compile(r"%YAML[ \t]+(1\.[0-9]+)\b")
#: The kinds of node, named as ruamel's merge errors name them.
_SCALAR, _SEQUENCE, _MAPPING = "scalar", "sequence", "mapping"


class _Frame:
    """A mapping or list being read: its value, path, anchor, start, the key read last, the
    duplicate keys found in it and its children that are collections (the node tree ruamel's
    duplicate walk goes through)."""

    __slots__ = ("anchor", "column", "dups", "failed", "first", "first_child", "index", "key")
    __slots__ += ("flow", "kids", "last_child", "line", "merges", "path", "value")

    def __init__(
        self, value: Any, path: str, anchor: str | None, index: int, line: int, column: int
    ):
        self.value = value
        self.path = path
        self.anchor = anchor
        self.index = index
        self.line = line
        self.column = column
        self.key: tuple[Any, str, str, int, int] | None = None  # value, tag, text, line, column
        self.first: dict[tuple[str, str], tuple[int, int]] = {}
        self.dups: list[tuple[int, int, str, tuple[int, int]]] | None = None
        # (key text or item index, _Frame or _Delegated) of each child that is a collection
        self.kids: list[tuple[Any, Any]] | None = None
        self.failed = self.flow = False
        self.merges: list[YamlMap] | None = None
        # Where the first and the latest child (item, or key of a pair) start in the text.
        self.first_child = self.last_child = -1


class _Delegated:
    """A collection ruamel's constructor built (an explicit tag other than map and seq): its
    ruamel node, for the duplicate walk."""

    __slots__ = ("node",)

    def __init__(self, node: Any) -> None:
        self.node = node


#: An anchor's node: value, line, column, kind, the _Frame / _Delegated of a collection (None
#: for a scalar), the tag and text of a scalar, its ruamel mark.
_Anchor = tuple[Any, int, int, str, Any, str, str, Any]


class _Found(Exception):
    """The fast reading found ruamel's ``error`` (raised as ruamel would raise it)."""

    def __init__(self, error: Exception) -> None:
        super().__init__(str(error))
        self.error = error


def read_libyaml(text: str) -> Document | None:
    """``text`` read from libyaml's events into the tree ruamel's reading gives.

    Raises :class:`Unsupported` for what it leaves to ruamel, :class:`Refused` for a text
    libyaml refuses, ruamel's ``ComposerError`` (an undefined alias, a second document) as
    ruamel raises it, and, after reading the whole document as ruamel constructs after
    composing, the one error of building a value (a bad merge, ``ValueError`` for an integer
    too long to convert, ruamel's errors for a tagged value); :class:`Unsupported` when there
    are several (ruamel's order of building decides which is first).
    """
    try:
        return _read_fast(text)
    except _Found as found:
        raise found.error from None


def _read_fast(text: str) -> Document | None:
    """:func:`read_libyaml`, ruamel's errors raised as :class:`_Found`."""
    if CParser is None:
        raise Unsupported("PyYAML without libyaml")
    if _RARE.search(text):
        raise Unsupported("a rare character")
    composer = _Composer(text)
    collecting = gc.isenabled()
    gc.disable()  # the tree is made of many small containers: collections would rescan it often
    try:
        return composer.compose(CParser(text))
    except (ComposerError, ParserError, ScannerError) as error:  # raised as ruamel raises them
        raise _Found(error) from None
    except LibyamlMarkedError as error:
        version = _VERSION.match(text, getattr(error.problem_mark, "index", 0))
        if error.problem == "found incompatible YAML document" and version is not None:
            mark = error.problem_mark  # ruamel's reading fails on an assertion
            raise _Found(
                ParserError(
                    None,
                    None,
                    f"found YAML version {version.group(1)}, which is not supported; expected "
                    "%YAML 1.1 or %YAML 1.2",
                    composer.mark(mark.index, mark.line, mark.column),
                )
            ) from None
        stack = composer.stack
        spans = [] if composer.defined else [(f.first_child, f.last_child) for f in stack]
        spans = [(start, end) for start, end in spans if 0 <= start < end]
        raise Refused(error, spans, composer.scalar_spans) from None
    finally:
        if collecting:
            gc.enable()


class _Composer:
    """One document's events to the positioned tree (see :func:`read_libyaml`)."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.stack: list[_Frame] = []
        self.defined: set[str] = set()  # every anchor seen, for read_libyaml's spans
        #: Where scalars are, when the text has tabs (see _raise_ruamel_error).
        self.scalar_spans: list[tuple[int, int]] | None = [] if "\t" in text else None
        self.version = (1, 2)
        self.table = _RESOLVERS[self.version]
        self.handles: dict[str, str] = dict(DEFAULT_TAGS)
        self.anchors: dict[str, _Anchor] = {}
        self.open: set[str] = set()  # anchors of collections not complete yet
        self.errors: list[Exception] = []  # of building values (raised after reading)
        self._yaml: Any = None
        self._line_starts: list[int] | None = None
        self._buffer: str | None = None

    # ----- ruamel's pieces, made when a value needs them ------------------------------------
    @property
    def constructor(self) -> Any:
        if self._yaml is None:
            self._yaml = YAML(typ="rt")
            self._yaml.version = self.version  # its constructor's processing version
            self._yaml.allow_duplicate_keys = True
        return self._yaml.constructor

    def mark(self, index: int, line: int, column: int) -> StringMark:
        """ruamel's mark of a place (its snippet is read from the text, as ruamel's is)."""
        if self._buffer is None:
            self._buffer = self.text + "\0"  # one copy for every mark, as ruamel's reader's
        return StringMark("<unicode string>", index, line, column, self._buffer, index)

    def mark_at(self, line: int, column: int) -> StringMark:
        if self._line_starts is None:
            self._line_starts = [0] + [m.end() for m in re.finditer(r"\r\n|\r|\n", self.text)]
        return self.mark(self._line_starts[line] + column, line, column)

    def empty_mark(self, index: int, flow: bool) -> StringMark:
        """ruamel's mark of an empty mapping value libyaml puts at ``index``: in a flow mapping
        just after its ``:``, in a block mapping where the next token starts."""
        if flow:
            at = self.text.rfind(":", 0, index) + 1
        else:
            at = _GAP.match(self.text, index).end()  # type: ignore[union-attr]
        self.mark_at(0, 0)  # the line starts
        line = bisect.bisect_right(self._line_starts, at) - 1  # type: ignore[arg-type]
        return self.mark(at, line, at - self._line_starts[line])  # type: ignore[index]

    def properties(self, event: Any) -> tuple[Tag | None, tuple[int, int, int]]:
        """The tag of ``event``'s node as ruamel's parser makes it (None when untagged or
        ``!``), and where ruamel's node starts: at its anchor when it has one, even after the
        tag, else at its tag (libyaml's events start at the first of them)."""
        mark = event.start_mark
        start = (mark.index, mark.line, mark.column)
        text, at, tag = self.text, mark.index, None
        for _ in range(2):
            if text.startswith("&", at):
                anchor = _ANCHOR_NAME.match(text, at)
                if anchor is None:
                    raise Unsupported("an anchor ruamel may scan otherwise")
                start = (at, mark.line, mark.column + at - mark.index)
                at = anchor.end()
            elif text.startswith("!", at):
                token = _TAG_TOKEN.match(text, at)
                if token is None:  # pragma: no cover - the pattern matches any "!"
                    raise Unsupported("a tag")
                if token.group("verbatim") is not None:
                    handle, suffix, at = None, token.group("verbatim"), token.end()
                else:
                    handle = "!" + (token.group("handle") or "")
                    uri = _URI.match(text, token.end())
                    suffix, at = uri.group(0), uri.end()  # type: ignore[union-attr]
                    if not suffix and handle == "!":
                        handle, suffix = None, "!"
                if at < len(text) and text[at] not in " \t\r\n":  # libyaml reads on
                    raise ScannerError(
                        "while scanning a tag",
                        self.mark(
                            token.start(), mark.line, mark.column + token.start() - mark.index
                        ),
                        f"expected ' ', but found {text[at]!r}",
                        self.mark(at, mark.line, mark.column + at - mark.index),
                    )
                tag = Tag(handle=handle, suffix=suffix, handles=self.handles)
                tag.select_transform(False)
            else:
                break
            if "\n" in text[mark.index : at] or "%" in text[mark.index : at]:
                raise Unsupported("properties across lines or with escapes")
            at = _SPACE.match(text, at).end()  # type: ignore[union-attr]
        if tag is not None:
            if str(tag) == "!":
                tag = None
            elif str(tag) != event.tag:
                raise Unsupported("a tag ruamel may read otherwise")
        return tag, start

    def built(self, node: Any) -> Any:
        """The value ruamel's round-trip constructor builds of ``node`` (None after recording
        its error, raised once the document is read)."""
        constructor = self.constructor
        try:
            value = constructor.construct_object(node, deep=True)
            while constructor.state_generators:
                generators, constructor.state_generators = constructor.state_generators, []
                for generator in generators:
                    for _ in generator:
                        pass
        except Exception as error:  # ruamel's error of building the value, raised later
            self.errors.append(error)
            return None
        return value

    # ----- scalars that are not plain, untagged and unanchored ------------------------------
    def scalar(self, event: Any, as_key: bool) -> tuple[Any, str, int, int, Any]:
        """``(value, tag, line, column, ruamel mark)`` of a scalar with an anchor or a tag, or
        a plain one :func:`_native` leaves to ruamel."""
        tag, (index, line, column) = self.properties(event)
        style = event.style or None
        if tag is None:
            plain = style is None or event.tag == "!"  # ruamel resolves "!" as plain
            ident = _resolve(event.value, self.table) if plain else _STR
            if as_key and ident == _VALUE:  # ruamel reads the key "=" as a string
                ident = _STR
            if event.anchor is None and ident != _MERGE:
                value = _native(event.value, ident, self.version) if plain else event.value
                if value is not _DELEGATE:
                    return value, ident, line, column, None
            tag = Tag(suffix=ident)
        else:
            ident = str(tag)
            if as_key and ident == _VALUE:
                tag, ident = Tag(suffix=_STR), _STR
        if as_key and ident == _MERGE:  # a merge key is not built
            return event.value, ident, line, column, None
        mark = self.mark(index, line, column)
        end = event.end_mark
        node = ScalarNode(tag, event.value, mark, self.mark(end.index, end.line, end.column))
        node.style, node.anchor = style, event.anchor
        return self.built(node), ident, line, column, mark

    # ----- collections ruamel's constructor builds ------------------------------------------
    def delegated(self, first: Any, get: Any, depth: int) -> tuple[Any, int, int, Any, Any]:
        """``(value, line, column, _Delegated, ruamel mark)`` of the collection starting with
        event ``first``: its events composed into ruamel's nodes, built by ruamel."""
        inside: dict[str, Any] = {}
        stack: list[Any] = []
        event, root = first, None
        while True:
            kind = type(event)
            if kind is ScalarEvent or kind is AliasEvent:
                if kind is AliasEvent:
                    node = inside.get(event.anchor)
                    if node is None:
                        raise Unsupported("an alias into or out of a tagged collection")
                else:
                    if self.scalar_spans is not None:
                        self.scalar_spans.append((event.start_mark.index, event.end_mark.index))
                    tag, start = self.properties(event)
                    if tag is None:
                        plain = not event.style or event.tag == "!"
                        tag = Tag(suffix=_resolve(event.value, self.table) if plain else _STR)
                    end = event.end_mark
                    node = ScalarNode(
                        tag,
                        event.value,
                        self.mark(*start),
                        self.mark(end.index, end.line, end.column),
                        style=event.style or None,
                        anchor=event.anchor,
                    )
                    self._anchor(event, start, inside, node)
            elif kind is MappingStartEvent or kind is SequenceStartEvent:
                if depth + len(stack) >= MAX_FAST_DEPTH:
                    raise Unsupported("deep nesting")
                tag, start = self.properties(event)
                if tag is None:
                    tag = Tag(suffix=_MAP if kind is MappingStartEvent else _SEQ)
                made = MappingNode if kind is MappingStartEvent else SequenceNode
                node = made(tag, [], self.mark(*start), None, flow_style=event.flow_style)
                node.anchor = event.anchor
                self._anchor(event, start, inside, node)
                stack.append(node)
                event = get()
                continue
            elif kind is MappingEndEvent or kind is SequenceEndEvent:
                node = stack.pop()
                end = event.end_mark
                node.end_mark = self.mark(end.index, end.line, end.column)
            else:  # pragma: no cover - libyaml gives no other event inside a document
                raise Unsupported(f"event {kind.__name__}")
            if not stack:
                root = node
                break
            parent = stack[-1]
            if isinstance(parent, SequenceNode):
                parent.value.append(node)
            elif parent.value and len(parent.value[-1]) == 1:
                parent.value[-1].append(node)
                parent.value[-1] = tuple(parent.value[-1])
            else:
                parent.value.append([node])
            event = get()
        made_copies: dict[int, Any] = {}
        value = _positioned(self.built(root), made_copies)
        for name, node in inside.items():  # anchors later aliases may name: scalars only
            if isinstance(node, ScalarNode):
                built = self.constructor.constructed_objects.get(node)
                mark = node.start_mark
                self.anchors[name] = (
                    built,
                    mark.line,
                    mark.column,
                    _SCALAR,
                    None,
                    str(node.tag),
                    node.value,
                    mark,
                )
            else:
                self.anchors.pop(name, None)
                self.open.add(name)  # an alias of it is left to ruamel
        return (
            value,
            root.start_mark.line,
            root.start_mark.column,
            _Delegated(root),
            root.start_mark,
        )

    def _anchor(self, event: Any, start: tuple[int, int, int], inside: dict, node: Any) -> None:
        if event.anchor is not None:
            self._define(event.anchor, start)
            inside[event.anchor] = node

    def _define(self, anchor: str, start: tuple[int, int, int]) -> None:
        """Note an anchor, warning as ruamel's composer warns when it is defined again."""
        if anchor in self.anchors or anchor in self.open:
            first = self.anchors[anchor][7] if anchor in self.anchors else None
            if first is None:
                raise Unsupported("an anchor defined again inside its own node")
            warnings.warn(
                f"\nfound duplicate anchor {anchor!r}\nfirst occurrence {first}\n"
                f"second occurrence {self.mark(*start)}",
                ReusedAnchorWarning,
                stacklevel=4,
            )
        self.defined.add(anchor)

    # ----- merge keys -----------------------------------------------------------------------
    def merge(self, frame: _Frame, key_mark: tuple[int, int], value: Any, kind: str, mark: Any):
        """The pair ``<<: value`` of the mapping ``frame``, as ruamel's round-trip constructor
        reads it: the mapping, or each mapping of the list, is merged in once the mapping is
        read (its own keys first; of the merged, the first given wins); anything else is
        ruamel's error."""
        context = self.mark(frame.index, frame.line, frame.column)
        if frame.merges:  # ruamel's test: a mapping merged already (not an empty list)
            self._merge_error(
                frame,
                DuplicateKeyError(
                    "while constructing a mapping",
                    context,
                    'found duplicate merge key "<<"',
                    self.mark_at(*key_mark),
                    """\
                        Duplicate merge keys are never allowed, not even when
                        `.allow_duplicate_keys` is set to True
                        """,
                ),
            )
            return
        if frame.merges is None:
            frame.merges = []
        if kind == _MAPPING:
            frame.merges.append(value)
            return
        if kind != _SEQUENCE:
            self._merge_error(
                frame,
                ConstructorError(
                    "while constructing a mapping",
                    context,
                    f"expected a mapping or list of mappings for merging, but found {kind}",
                    mark,
                ),
            )
            return
        for index, item in enumerate(value):
            if not isinstance(item, YamlMap):
                self._merge_error(
                    frame,
                    ConstructorError(
                        "while constructing a mapping",
                        context,
                        "expected a mapping for merging, but found "
                        f"{_SEQUENCE if isinstance(item, YamlSeq) else _SCALAR}",
                        self.mark_at(*value.marks[index]),
                    ),
                )
                return
        frame.merges.extend(value)

    def _merge_error(self, frame: _Frame, error: Exception) -> None:
        if not frame.failed:
            self.errors.append(error)
            frame.failed = True

    # ----- the document ---------------------------------------------------------------------
    def compose(self, parser: Any) -> Document | None:
        """The document of ``parser``'s events (see :func:`read_libyaml`)."""
        get = parser.get_event
        get()  # the stream's start
        event = get()
        if type(event) is StreamEndEvent:
            return None
        if event.version is not None:  # libyaml refuses versions 1.3 and later itself
            if event.version not in _RESOLVERS:
                mark = event.start_mark
                raise ParserError(
                    None,
                    None,
                    f"found YAML version {event.version[0]}.{event.version[1]}, which is not "
                    "supported; expected %YAML 1.1 or %YAML 1.2",
                    self.mark(mark.index, mark.line, mark.column),
                )
            self.version = event.version
            self.table = _RESOLVERS[self.version]
        if event.tags:
            self.handles.update(event.tags)
        stack, anchors, table, version = self.stack, self.anchors, self.table, self.version
        spans = self.scalar_spans
        duplicates_found = False
        while True:
            event = get()
            kind = type(event)
            child: Any = None
            node_mark: Any = None
            if kind is ScalarEvent or kind is AliasEvent:
                if stack:  # a list item or a mapping key starts a child of its collection
                    parent = stack[-1]
                    if parent.key is None or isinstance(parent.value, YamlSeq):
                        if parent.first_child < 0:
                            parent.first_child = event.start_mark.index
                        parent.last_child = event.start_mark.index
            if kind is ScalarEvent:
                source = event.value
                if spans is not None:
                    spans.append((event.start_mark.index, event.end_mark.index))
                value = _DELEGATE
                if event.anchor is None and event.tag is None:
                    mark = event.start_mark
                    line, column = mark.line, mark.column
                    if event.style:
                        value, tag = source, _STR
                    else:
                        tag = _resolve(source, table)
                        if tag != _VALUE and tag != _MERGE:
                            try:
                                value = _native(source, tag, version)
                            except ValueError as error:  # raised once the document is read
                                self.errors.append(error)
                                value = None
                if value is _DELEGATE:
                    as_key = bool(stack) and stack[-1].key is None
                    as_key = as_key and type(stack[-1].value) is YamlMap
                    value, tag, line, column, node_mark = self.scalar(event, as_key)
                    if event.anchor is not None:
                        if node_mark is None:
                            node_mark = self.mark_at(line, column)
                        self._define(event.anchor, (node_mark.index, line, column))
                        anchors[event.anchor] = (
                            value,
                            line,
                            column,
                            _SCALAR,
                            None,
                            tag,
                            source,
                            node_mark,
                        )
                node_kind = _SCALAR
            elif kind is AliasEvent:
                entry = anchors.get(event.anchor)
                if entry is None:
                    if event.anchor in self.open:
                        raise Unsupported("an alias of a node not complete (recursion)")
                    mark = event.start_mark
                    raise ComposerError(
                        None,
                        None,
                        f"found undefined alias {event.anchor!r}",
                        self.mark(mark.index, mark.line, mark.column),
                    )
                value, line, column, node_kind, child, tag, source, node_mark = entry
            elif kind is MappingStartEvent or kind is SequenceStartEvent:
                if len(stack) >= MAX_FAST_DEPTH:
                    raise Unsupported("deep nesting")
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
                tag = event.tag
                if not (
                    tag is None
                    or tag == "!"
                    or tag == (_MAP if kind is MappingStartEvent else _SEQ)
                ):
                    value, line, column, child, node_mark = self.delegated(event, get, len(stack))
                    node_kind = _MAPPING if kind is MappingStartEvent else _SEQUENCE
                    tag = source = ""
                else:
                    container = YamlMap() if kind is MappingStartEvent else YamlSeq()
                    anchor = event.anchor
                    if tag is None and anchor is None:
                        frame = _Frame(container, path, None, mark.index, mark.line, mark.column)
                    else:
                        start = self.properties(event)[1]
                        if anchor is not None:
                            self._define(anchor, start)
                            anchors.pop(anchor, None)
                            self.open.add(anchor)
                        frame = _Frame(container, path, anchor, *start)
                    frame.flow = event.flow_style
                    stack.append(frame)
                    continue
            elif kind is MappingEndEvent or kind is SequenceEndEvent:
                frame = stack.pop()
                frame.first = frame.path = None  # type: ignore[assignment]  # kept for the walk
                value, line, column = frame.value, frame.line, frame.column
                if frame.merges:
                    for merged in frame.merges:
                        for key, item in merged.items():
                            if key not in value:
                                value[key] = item
                node_kind = _MAPPING if kind is MappingEndEvent else _SEQUENCE
                child = frame
                tag = source = ""
                if frame.anchor is not None:
                    node_mark = self.mark(frame.index, line, column)
                    anchors[frame.anchor] = (
                        value,
                        line,
                        column,
                        node_kind,
                        frame,
                        "",
                        "",
                        node_mark,
                    )
                    self.open.discard(frame.anchor)
            else:  # pragma: no cover - libyaml gives no other event inside a document
                raise Unsupported(f"event {kind.__name__}")

            if not stack:
                root = (value, line, column, child)
                break
            parent = stack[-1]
            container = parent.value
            if type(container) is YamlSeq:
                if child is not None:
                    if parent.kids is None:
                        parent.kids = []
                    parent.kids.append((len(container), child))
                container.append(value)
                container.marks.append((line, column))
            elif parent.key is None:
                if node_kind != _SCALAR:
                    raise Unsupported("a collection as a mapping key")
                if kind is AliasEvent and tag == _VALUE:
                    raise Unsupported("an alias of '=' as a mapping key")
                parent.key = (value, tag, source, line, column)
            else:
                key, key_tag, key_text, key_line, key_column = parent.key
                parent.key = None
                if key_tag == _MERGE:
                    if child is not None and type(child) is _Delegated:
                        raise Unsupported("a tagged collection merged")
                    if node_mark is None:
                        node_mark = self.mark_at(line, column)
                        if kind is ScalarEvent and source == "" and not event.style:
                            node_mark = self.empty_mark(node_mark.index, parent.flow)
                    self.merge(parent, (key_line, key_column), value, node_kind, node_mark)
                    continue
                ident = (key_tag, key_text)
                if ident in parent.first:
                    if parent.dups is None:
                        parent.dups = []
                    parent.dups.append(
                        (key_line + 1, key_column + 1, key_text, parent.first[ident])
                    )
                    duplicates_found = True
                else:
                    parent.first[ident] = (key_line + 1, key_column + 1)
                if child is not None:
                    if parent.kids is None:
                        parent.kids = []
                    parent.kids.append((key_text, child))
                if key not in container:  # a later equal key is dropped, as ruamel drops it
                    container[key] = value
                    container.marks[key] = (key_line, key_column, line, column)

        get()  # the document's end
        event = get()
        if type(event) is not StreamEndEvent:
            mark = event.start_mark
            value, line, column, child = root
            raise ComposerError(
                "expected a single document in the stream",
                self.mark_at(line, column),
                "but found another document",
                self.mark(mark.index, mark.line, mark.column),
            )
        if len(self.errors) > 1:
            raise Unsupported("several errors of building values (ruamel's order decides)")
        if self.errors:
            raise _Found(self.errors[0])
        value, line, column, child = root
        duplicates = list(_walk_duplicates(child)) if duplicates_found or self._yaml else []
        return Document(value, line, column, duplicates)


def _walk_duplicates(root: Any) -> Iterator[Duplicate]:
    """The duplicate keys of the tree under ``root`` (a _Frame, _Delegated or None), each at
    the path where ruamel's walk of its node tree (:func:`_ruamel_duplicates`) first meets its
    mapping: depth first, the last child first, each node once, merge pairs left out."""
    seen: set[int] = set()
    stack: list[tuple[Any, str]] = [(root, "")]
    while stack:
        entry, path = stack.pop()
        if entry is None or id(entry) in seen:
            continue
        seen.add(id(entry))
        if type(entry) is _Delegated:
            yield from _ruamel_duplicates(entry.node, path)
            continue
        for line, column, key_text, first in entry.dups or ():
            yield line, column, join(path, key_text), key_text, first
        mapping = type(entry.value) is YamlMap
        for label, kid in entry.kids or ():
            stack.append((kid, join(path, label) if mapping else f"{path}[{label}]"))
