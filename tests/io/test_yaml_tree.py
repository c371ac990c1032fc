"""Tests of ``arrange_up.io.yaml_tree``: libyaml's reading gives the tree ruamel's reading gives
(values, their types as the readers see them, every position, duplicate keys) and ruamel's
errors, for plain files and for every feature (anchors, aliases, merge keys, tags, directives,
tabs; hand-written cases and generated documents), leaves to ruamel what it does not take, and
syntax errors keep ruamel's words and places."""

from __future__ import annotations

import math
import random
import sys
import warnings
from pathlib import Path
from typing import Any

import pytest

from arrange_up.io import yaml_tree
from arrange_up.io.validation import MAX_OBJECTS
from arrange_up.io.yaml_problem import check_problem_text
from arrange_up.io.yaml_source import Report, parse
from arrange_up.io.yaml_tree import Document, Refused, Unsupported, YamlMap, YamlSeq

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(REPOSITORY / "benchmarks"))
from big_inputs import featured  # noqa: E402
from yaml_documents import documents  # noqa: E402

pytestmark = [
    pytest.mark.skipif(yaml_tree.CParser is None, reason="PyYAML without libyaml"),
    pytest.mark.filterwarnings("ignore:\\s*found duplicate anchor"),  # ruamel's, for a case
    pytest.mark.filterwarnings("ignore::ruamel.yaml.error.MantissaNoDotYAML1_1Warning"),
]


# ---------------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------------
def _kind(value: Any) -> tuple[bool, ...]:
    """What the readers can tell about a scalar: its isinstance tests."""
    return (
        value is None,
        isinstance(value, bool),
        isinstance(value, int),
        isinstance(value, float),
        isinstance(value, str),
    )


def assert_same_value(fast: Any, reference: Any, pairs: dict[int, Any]) -> None:
    """``fast`` reads like ``reference`` for every reader: same containers with the same marks
    (shared ones shared alike), scalars equal in kind, ``str`` and ``repr``."""
    if isinstance(reference, YamlMap | YamlSeq):
        if id(reference) in pairs:
            assert pairs[id(reference)] is fast, "a shared value is not shared alike"
            return
        pairs[id(reference)] = fast
        assert type(fast) is type(reference)
        if isinstance(reference, YamlMap):  # keys by repr: two NaN keys are never equal
            # An empty value has no place of its own (readers point at its key).
            assert [
                (repr(k), m if reference[k] is not None else m[:2])
                for k, m in reference.marks.items()
            ] == [(repr(k), m if fast[k] is not None else m[:2]) for k, m in fast.marks.items()]
            assert [repr(k) for k in fast] == [repr(k) for k in reference]
            fast, reference = (
                dict(zip(map(repr, fast), fast.values(), strict=True)),
                dict(zip(map(repr, reference), reference.values(), strict=True)),
            )
            for key in reference:
                assert_same_value(fast[key], reference[key], pairs)
        else:
            assert fast.marks == reference.marks
            assert len(fast) == len(reference)
            for a, b in zip(fast, reference, strict=True):
                assert_same_value(a, b, pairs)
        return
    assert _kind(fast) == _kind(reference), (fast, reference)
    assert (str(fast), repr(fast)) == (str(reference), repr(reference))
    if isinstance(reference, float) and not math.isnan(reference):
        assert fast == reference and math.copysign(1, fast) == math.copysign(1, reference)


def assert_same_document(fast: Document | None, reference: Document | None) -> None:
    if reference is None:
        assert fast is None
        return
    assert fast is not None
    assert (fast.line, fast.column) == (reference.line, reference.column)
    assert sorted(fast.duplicates) == sorted(reference.duplicates)
    assert_same_value(fast.root, reference.root, {})


def diagnostics(text: str) -> list[str]:
    report = Report("f.yaml")
    parse(text, report)
    return [str(d) for d in report.diagnostics]


# ---------------------------------------------------------------------------------------------
# documents libyaml reads: the same tree as ruamel's
# ---------------------------------------------------------------------------------------------
FAST = {
    "mapping": "a: 1\nb: two\nc: [3, 4.5]\n",
    "nested": "a:\n  b:\n    c: [1, [2, [3]]]\n  d: {e: f, g: [h, i]}\n",
    "block lists": "a:\n- 1\n-  x\n-\n- - 2\n  - 3\nb:\n  - {c: d}\n  -   e\n",
    "indentless list": "a:\n- [1, 2]\n- [3, 4]\nb: 5\n",
    "empty values": "a:\nb: ~\nc: null\nd: []\ne: {}\nf: ''\n",
    "flow": "{a: [1, 2], b: {c: d}, 'e f': \"g\"}\n",
    "flow pairs": "a: [x: 1, y]\nb: [x:y, {b:c}]\n",
    "explicit keys": "? a\n: b\n? c\n",
    "top-level list": "- a\n- b: c\n",
    "top-level scalar": "just words\n",
    "document markers": "---\na: 1\n...\n",
    "comments": "# head\na: 1 # one\n# mid\nb: [2, # two\n  3]\n",
    "quoting": "a: 'it''s'\nb: \"x\\ty\\u00e9\\/z \\\n  w\"\nc: \"\\N\\_\\L\\P\"\nd: '1'\n",
    "multi-line plain": "a: plain\n  multi line\n\n  para\nb: c\n",
    "block scalars": (
        "a: |\n  one\n  two\nb: >\n  three\n  four\n\n  five\nc: |+\n  six\n\nd: >-\n  x\n"
    ),
    "unicode": "name: 'é ü 中 😀'\ndescription: Überall ² → ok\nobjects: {Ä: 1}\n",
    "crlf": "a:\r\n  b: 1\r\n  c: [2, 3]\r\n",
    "cr": "a:\r  b: 1\r",
    "anchors of collections": "u: &u [0.2, 0.2, 15]\nv: *u\nm: &m {a: 1}\nn: [*m, *m]\n",
    "duplicates": "a: 1\nb: {c: 2, c: 3}\na: 4\nd:\n  - {e: 1, e: 2}\n",
    "equal keys of other tags": "1: a\n'1': b\n1.0: c\n01: d\n.nan: e\n.NaN: f\n",
    "long lines": "a: [" + ", ".join(f"[{k}.5, -{k}e-3]" for k in range(2000)) + "]\n",
    "flow across lines": "a: [1,\n2,\n   3]\nb: {c: 1,\n  d: 2}\n",
    "colon in scalars": "url: http://x.y/z\nt: 12:30:00x\nk: a:b\n",
}

SCALARS = (
    "true True TRUE false False FALSE yes no on off y n Yes ON "
    "1 -1 +1 0 -0 017 08 0o17 1_000 0x1F 0b101 1:30 1:30:00 "
    "1.5 -1.5 +1.5 .5 -.5 1. 1e3 1E3 1.0e3 -1.0e-3 1e-3 1.0e+3 .5e+3 1e400 -0.0 "
    ".inf -.inf +.inf .Inf .INF .nan .NaN .NAN inf nan NaN "
    "null Null NULL ~ nul 2024-01-01 hello 'q' "
).split()


@pytest.mark.parametrize("name", sorted(FAST))
def test_libyaml_reads_the_tree_ruamel_reads(name: str) -> None:
    text = FAST[name]
    assert_same_document(yaml_tree.read_libyaml(text), yaml_tree.read_ruamel(text))


def test_every_plain_scalar_reads_as_ruamel_reads_it() -> None:
    for scalar in SCALARS:
        for version in ("", "%YAML 1.1\n---\n"):
            text = f"{version}key: {scalar}\nlist: [{scalar}]\n{scalar}: key\n"
            assert_same_document(yaml_tree.read_libyaml(text), yaml_tree.read_ruamel(text))


@pytest.mark.parametrize(
    ("scalar", "value"),
    [
        # YAML 1.2 as ruamel reads it, not PyYAML's YAML 1.1
        ("yes", "yes"),
        ("no", "no"),
        ("on", "on"),
        ("off", "off"),
        ("y", "y"),
        ("1:30", "1:30"),
        ("0o17", 15),
        ("017", 17),
        ("08", 8),
        ("1e3", 1000.0),
        ("1.0e3", 1000.0),
        ("-1e-3", -0.001),
        ("0x1F", 31),
        ("1_000", 1000),
        ("true", True),
        ("False", False),
        ("~", None),
        ("Null", None),
        (".inf", math.inf),
        ("-.inf", -math.inf),
        ("inf", "inf"),
        ("nan", "nan"),
    ],
)
def test_scalars_mean_what_they_meant(scalar: str, value: Any) -> None:
    report = Report("f.yaml")
    data = parse(f"key: {scalar}\n", report)
    assert data is not None and not report.diagnostics
    assert data["key"] == value and type(data["key"]) is not bool or type(value) is bool
    assert _kind(data["key"]) == _kind(value)


def test_nan_reads_as_a_number() -> None:
    data = parse("key: .nan\n", Report("f.yaml"))
    assert data is not None and isinstance(data["key"], float) and math.isnan(data["key"])


@pytest.mark.parametrize("path", sorted((REPOSITORY / "domains").glob("*.yaml")), ids=str)
def test_the_shipped_problems_are_read_by_libyaml_as_by_ruamel(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    assert_same_document(yaml_tree.read_libyaml(text), yaml_tree.read_ruamel(text))


def test_positions_of_an_aliased_value_are_those_of_its_anchor() -> None:
    text = "u: &u [1, 2]\nv: *u\n"
    document = yaml_tree.read_libyaml(text)
    assert document is not None
    root = document.root
    assert root["v"] is root["u"]
    assert root.marks["v"] == (1, 0, 0, 3)  # the key where written, the value at the anchor


# ---------------------------------------------------------------------------------------------
# every feature: the same tree or the same error
# ---------------------------------------------------------------------------------------------
#: Every feature the libyaml reading takes besides plain files: the same tree, or the same error.
FEATURES = {
    "directive 1.1": "%YAML 1.1\n---\na: yes\nb: 017\nc: 1:30\nd: on\ne: 0b101\nf: 1.5\ng: 1e3\n",
    "directive 1.2": "%YAML 1.2\n---\na: yes\nb: 017\n",
    "tag directive": "%TAG !e! tag:yaml.org,2002:\n---\na: !e!float 1\nb: !e!str x\n",
    "explicit tag": "a: !!str 1\nb: !!float 2\nc: !!int '3'\nd: !!bool yes\ne: !!null ''\n",
    "tagged collections": "a: !!map {b: 1}\nc: !!seq [1]\nd: ! [2]\n",
    "verbatim tag": "a: !<tag:yaml.org,2002:str> 1\nb: !<tag:yaml.org,2002:float> 2\n",
    "local tag": "a: !thing 1\nb: !thing {x: 1}\nc: !thing [1, 2]\n",
    "non-specific tag": "a: ! 1\nb: ! 'x'\n",
    "rare standard tags": (
        "a: !!set {x, y}\nb: !!omap [c: 1]\nc: !!binary aGVsbG8=\nd: !!timestamp 2024-01-01\n"
        "e: !!pairs [f: 1]\n"
    ),
    "tag and anchor": "a: !!float &x 1\nb: &y !!float 2\nc: [*x, *y]\nd: !!map &m {e: 1}\nf: *m\n",
    "tag not followed by a space": "a: [!<tag:yaml.org,2002:str>, 1]\n",
    "merge key": "base: &b {x: 1, y: 2}\nc:\n  <<: *b\n  y: 3\n",
    "merge of a list": "b1: &b1 {x: 1, y: 2}\nb2: &b2 {x: 3, z: 4}\nc:\n  w: 0\n  <<: [*b1, *b2]\n",
    "merge inline": "c: {<<: {x: 1, x: 2}, y: 3}\n",
    "merge of a merged mapping": "a: &a {x: 1}\nb: &b {<<: *a, y: 2}\nc: {<<: *b, z: 3}\n",
    "merge of a scalar": "c:\n  <<: 1\n",
    "merge of an empty value": "c:\n  <<:\n  d: 1\n",
    "merge of an empty value in flow": "e: {<<: }\n",
    "merge of a list of scalars": "c:\n  <<: [{a: 1}, 1]\n",
    "merge of an aliased list": "l: &l [{a: 1}, {b: 2}]\nc: {<<: *l}\n",
    "merge twice": "c: {<<: {a: 1}, <<: {b: 1}}\n",
    "merge after an empty list": "<<: []\n<<: {p: 1}\n",
    "anchored scalar": "a: &x 1\nb: *x\nc: &t true\nd: &s hi\ne: &n ~\nf: &f 1.5\ng: *t\n",
    "aliased scalar key": "a: &k b\n*k : 1\n",
    "reused anchor": "a: &x [1]\nb: &x [2]\nc: *x\n",
    "undefined alias": "a: *nowhere\n",
    "timestamp": "a: 2024-01-01\nb: 2024-01-01 10:00:00\n",
    "hex integer": "a: 0x1F\nb: 0o17\nc: 0b11\n",
    "underscores": "a: 1_000.5\nb: 1_000\n",
    "value key": "=: a\nb: =\n",
    "two documents": "a: 1\n---\nb: 2\n",
    "duplicates with an alias": "a: &m [1]\nb: {c: 1, c: 2}\nd: *m\n",
    "duplicates in a shared mapping": "a: &m {c: 1, c: 2}\nb: [*m, *m]\n",
    "duplicates in a merged mapping": "a: {<<: {c: 1, c: 2}, d: 1}\n",
    "duplicates dropped from the tree": "a: {c: {x: 1, x: 2}}\na: {d: {y: 1, y: 2}}\n",
    "tabs in flow and comments": "a: [1,\t2]\nb: {c:\t1} #\tnote\nc: 'x\ty'\nd: |\n  x\ty\n",
    "integer too long, merged": "a: &a {x: " + "7" * 5000 + "}\nb: {<<: *a}\n",
}


@pytest.mark.parametrize("name", sorted(FEATURES))
def test_libyaml_reads_every_feature_as_ruamel_reads_it(name: str) -> None:
    text = FEATURES[name]
    try:
        yaml_tree.read_libyaml(text)
    except Exception as error:  # one of ruamel's errors, raised as ruamel raises it
        assert not isinstance(error, (Unsupported, Refused)), error
    with warnings.catch_warnings(record=True) as fast_warnings:
        warnings.simplefilter("always")
        found = diagnostics(text)
    with warnings.catch_warnings(record=True) as reference_warnings:
        warnings.simplefilter("always")
        reference = _reference_diagnostics(text)
    assert found == reference
    assert [str(w.message) for w in fast_warnings] == [str(w.message) for w in reference_warnings]
    if not reference:
        assert_same_document(yaml_tree.read(text), yaml_tree.read_ruamel(text))


def _outcome(read: Any, text: str) -> Any:
    """``read(text)``, or the name of the exception it raises (ruamel fails on some documents,
    such as a ``!!set`` merged into a mapping; the fast reading leaves those to it)."""
    try:
        return read(text)
    except Exception as error:
        return type(error).__name__


@pytest.mark.parametrize("seed", range(4))
def test_generated_documents_read_as_ruamel_reads_them(seed: int) -> None:
    """Random documents mixing every feature (``yaml_documents``): the same diagnostics, and
    the same tree when ruamel reads one; most of them read by libyaml."""
    taken = 0
    texts = documents(60, seed)
    for text in texts:
        try:
            yaml_tree.read_libyaml(text)
            taken += 1
        except Unsupported:
            pass
        except Exception:  # an error, compared below
            taken += 1
        assert _outcome(diagnostics, text) == _outcome(_reference_diagnostics, text), text
        try:
            reference = yaml_tree.read_ruamel(text)
        except Exception:
            continue
        assert_same_document(yaml_tree.read(text), reference)
    assert taken >= 0.85 * len(texts)


@pytest.mark.parametrize(
    "text",
    [
        "a:\t1\n",
        "a: 1\t\nb: 2\t# c\n",
        "a: &x\t1\nb:\t*x\n",
        "a: !!int\t1\n",
        "a:\n  - 1\n  - {b:\t[2,\t3]}\nc:\t'q\tr'\n",
        "a: 1\n  \t\nb: 2\n",
    ],
)
def test_tabs_are_read_where_yaml_allows_them(text: str) -> None:
    """A tab between tokens on a line, which ruamel refuses outside flow collections: read as
    ruamel reads the text with a space there (tabs within scalars kept)."""
    spaced = text.replace(":\t", ": ").replace(",\t", ", ").replace("\t#", " #")
    spaced = spaced.replace("\t\n", " \n").replace("&x\t", "&x ").replace("!!int\t", "!!int ")
    fast = yaml_tree.read_libyaml(text)
    assert not diagnostics(text)
    assert fast is not None and fast.root
    reference = yaml_tree.read_ruamel(spaced)
    assert_same_document(fast, reference)


def test_a_tab_within_a_plain_scalar_is_kept() -> None:
    document = yaml_tree.read_libyaml("a: x\ty\nb: [c\td]\n")
    assert document is not None and document.root == {"a": "x\ty", "b": ["c\td"]}


@pytest.mark.parametrize(
    "text",
    [
        "a:\n\tb: 1\n",
        "a:\t1\nb:\n\t- 2\n",
        "a:\t[1,\t2\nb: 3\n",
        "a: 'x\ty'\nb:\t{c: 1\n",
    ],
)
def test_a_syntax_error_after_tabs_yaml_allows_is_worded_where_it_is(text: str) -> None:
    """ruamel words the error libyaml finds, not a tab before it that libyaml read."""
    found = diagnostics(text)
    assert len(found) == 1 and ": error: not valid YAML: " in found[0]
    untabbed = text[: text.index("\n", text.index("\n") + 1)].replace(":\t", ": ")
    untabbed = untabbed.replace(",\t", ", ") + text[len(untabbed) :]
    assert found == _reference_diagnostics(untabbed)


def test_an_unsupported_yaml_version_is_an_error_not_a_crash() -> None:
    """ruamel's reading fails on an assertion for %YAML 1.0 or 1.3."""
    for version in ("1.0", "1.3"):
        assert diagnostics(f"%YAML {version}\n---\na: 1\n") == [
            f"f.yaml:1:1: error: not valid YAML: found YAML version {version}, which is not "
            "supported; expected %YAML 1.1 or %YAML 1.2"
        ]


@pytest.mark.parametrize("feature", ["anchors", "merges", "tags", "directives", "tabs"])
def test_big_files_using_each_feature_are_read_by_libyaml(
    monkeypatch: pytest.MonkeyPatch, feature: str
) -> None:
    """A problem of the most objects allowed (:data:`MAX_OBJECTS`, 14-40 kB) using the feature
    on every line is read without ruamel (whose reading of big files takes seconds:
    ``benchmarks/big_inputs.py --files``) and checks; a small one reads as ruamel reads it."""
    small = featured(30, feature)
    if feature != "tabs":  # ruamel refuses a tab after a colon in block context
        assert_same_document(yaml_tree.read(small), yaml_tree.read_ruamel(small))
    text = featured(MAX_OBJECTS, feature)
    assert len(text) > 14_000

    def refuse(text: str) -> None:
        raise AssertionError("read by ruamel")

    monkeypatch.setattr(yaml_tree, "read_ruamel", refuse)
    problem, found = check_problem_text(text, "big.yaml")
    assert problem is not None and len(problem.objects) == MAX_OBJECTS, found


# ---------------------------------------------------------------------------------------------
# what libyaml leaves to ruamel
# ---------------------------------------------------------------------------------------------
LEFT_TO_RUAMEL = {
    "recursive alias": "a: &x [1, *x]\n",
    "alias as key": "a: &k [1]\n? *k\n: 2\n",
    "collection as key": "[1, 2]: a\n",
    "NEL": "a: 'x\x85y'\n",
    "line separator": "a: 'x\u2028y'\n",
    "byte-order mark": "a: '\ufeff'\n",
    "control character": "a: '\x07'\n",
    "deep nesting": "a: " + "[" * 70 + "]" * 70 + "\n",
    "alias out of a tagged collection": "a: &x [1]\nb: !thing [*x]\n",
    "several errors": "a: {<<: 1}\nb: {<<: 2}\n",
}


@pytest.mark.parametrize("name", sorted(LEFT_TO_RUAMEL))
def test_what_libyaml_does_not_take_is_read_by_ruamel(name: str) -> None:
    text = LEFT_TO_RUAMEL[name]
    with pytest.raises((Unsupported, Refused)) as raised:
        yaml_tree.read_libyaml(text)
    assert raised.type in (Unsupported, Refused)
    assert diagnostics(text) == _reference_diagnostics(text)


def test_without_libyaml_every_document_is_read_by_ruamel(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    text = (REPOSITORY / "domains" / "tt-mating.yaml").read_text(encoding="utf-8")
    fast = check_problem_text(text, "tt.yaml")
    monkeypatch.setattr(yaml_tree, "CParser", None)
    with pytest.raises(Unsupported):
        yaml_tree.read_libyaml(text)
    assert check_problem_text(text, "tt.yaml") == fast


def test_an_integer_too_long_to_convert_is_reported_as_before() -> None:
    text = "a: 1\nb: " + "7" * 5000 + "\n"
    with pytest.raises(ValueError):
        yaml_tree.read_libyaml(text)
    assert diagnostics(text) == _reference_diagnostics(text)
    assert diagnostics(text) == [
        "f.yaml:2:4: error: a number of 5000 digits; expected a finite number (a double, at "
        "most about 1e308)"
    ]


# ---------------------------------------------------------------------------------------------
# syntax errors: ruamel's words and places
# ---------------------------------------------------------------------------------------------
def _reference_diagnostics(text: str) -> list[str]:
    """The diagnostics with libyaml switched off (ruamel reads everything)."""
    saved = yaml_tree.CParser
    yaml_tree.CParser = None
    try:
        return diagnostics(text)
    finally:
        yaml_tree.CParser = saved


BROKEN = {
    "unclosed flow": "name: t\ntable: {size: [10, 5]\nobjects: {}\n",
    "tab indentation": "name: t\ntable:\n\tsize: [1, 1]\n",
    "bad indentation": "a:\n  b: 1\n c: 2\n",
    "mapping in a scalar": "a: b: c\n",
    "unclosed quote": "a: 'x\nb: 1\n",
    "stray bracket": "a: [1, 2]]\n",
    "missing comma": "a: [1 2, [3 4]\n",
    "bad escape": 'a: "\\q"\n',
    "alias to nothing": "a: [*x]\n",
    "nul": "a: 1\x00\n",
    "block in flow": "a: [|\n  x\n]\n",
    "key without value in flow": "a: {b, c: [}\n",
    "document end then content": "a: 1\n...\nb\n",
}


@pytest.mark.parametrize("name", sorted(BROKEN))
def test_syntax_errors_keep_ruamels_words_and_places(name: str) -> None:
    text = BROKEN[name]
    found = diagnostics(text)
    assert found and all(": error: " in line for line in found)
    assert found == _reference_diagnostics(text)


def _big(tail: str, vertices: int = 20_000) -> str:
    points = ", ".join(f"[{k * 1e-4:.9f}, {k * 2e-4:.9f}]" for k in range(vertices))
    return f"name: big\ntable: {{size: [10, 5]}}\nshape:\n  polygon: [{points}]\n{tail}"


@pytest.mark.parametrize(
    ("where", "text"),
    [
        ("early", "name: [big\nx: 1\n" + _big("goal: {}\n")),
        ("late", _big("goal: {a: [1, 2}\n")),
        ("cut off", _big("")[:-4000]),
        ("in a long line", _big("")[:300_000] + "]]]\n"),
    ],
)
def test_syntax_errors_of_big_files_keep_ruamels_words_and_places(where: str, text: str) -> None:
    assert diagnostics(text) == _reference_diagnostics(text)


@pytest.mark.parametrize(
    "text",
    [
        "name: [big\nx: 1\n" + _big("goal: {}\n"),
        _big("goal: {a: [1, 2}\n"),
        _big("")[:-4000],
        "objects:\n" + "".join(f"  O{k}: {{kind: part}}\n" for k in range(3000)) + "  P: [\n",
    ],
    ids=["early", "late", "cut off", "block mapping"],
)
def test_a_syntax_error_of_a_big_file_is_worded_from_a_short_text(
    monkeypatch: pytest.MonkeyPatch, text: str
) -> None:
    lengths: list[int] = []
    read_ruamel = yaml_tree.read_ruamel

    def recording(text: str) -> Document | None:
        lengths.append(len(text))
        return read_ruamel(text)

    monkeypatch.setattr(yaml_tree, "read_ruamel", recording)
    found = diagnostics(text)
    assert len(found) == 1 and ": error: not valid YAML: " in found[0]
    assert lengths and max(lengths) < 10_000 < len(text)


def _mutations(text: str, count: int, seed: int) -> list[str]:
    """``count`` broken versions of ``text``: cut off, a few characters deleted, or a character
    YAML gives meaning to inserted, at random places."""
    rng = random.Random(seed)
    inserts = ["]", "[", "{", "}", ",", ":", "'", '"', "- ", "? ", "#", "\n  x: ", "  ", "\n-"]
    found = []
    for _ in range(count):
        k = rng.randrange(len(text))
        mode = rng.randrange(3)
        if mode == 0:
            found.append(text[:k])
        elif mode == 1:
            found.append(text[:k] + text[k + rng.randint(1, 3) :])
        else:
            found.append(text[:k] + rng.choice(inserts) + text[k:])
    return found


def _star(vertices: int, block: bool) -> str:
    points = [f"[{math.cos(k):.4f}, {math.sin(k):.4f}]" for k in range(vertices)]
    if block:
        polygon = "\n" + "".join(f"        - {point}\n" for point in points)
    else:
        polygon = " [" + ",\n          ".join(points) + "]\n"
    objects = "".join(f"  O{k}: {{kind: part, shape: {{box: [1, 1]}}}}\n" for k in range(20))
    return (
        f"name: s\ntable: {{size: [10, 5]}}\nobjects:\n{objects}  A:\n    kind: part\n"
        f"    shape:\n      polygon:{polygon}goal:\n  tolerance: [0.2, 0.2]\n"
        "  poses: {A: [5, 2, 0]}\n"
    )


@pytest.mark.parametrize(
    "source", ["tt-mating.yaml", "blocks-4.yaml", "block list", "flow list"], ids=str
)
def test_broken_texts_keep_ruamels_words_and_places(source: str) -> None:
    if source.endswith(".yaml"):
        text = (REPOSITORY / "domains" / source).read_text(encoding="utf-8")
    else:
        text = _star(150, block=source == "block list")
    for broken in _mutations(text, 40, seed=len(source)):
        assert diagnostics(broken) == _reference_diagnostics(broken), repr(broken[-80:])
