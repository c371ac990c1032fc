"""The shipped problems: find them by name, list them, load them.

arrange-up ships a set of problems (the block-world construction problems of thesis chapter 3
and the rearrangement problems of chapter 4) as ``.yaml`` files. Wherever a problem is asked
for, a user may give either a path to a problem file or the name of a shipped problem::

    >>> from arrange_up.io.domains import load, resolve_problem
    >>> resolve_problem("blocks-4").name
    'blocks-4.yaml'
    >>> load("blocks-4").goal.is_relative
    False

The shipped files live in the repository's ``domains/`` folder; an installed wheel carries the
same folder as ``arrange_up/_shipped/domains`` (see :mod:`arrange_up.io.resources`), so names
work without a checkout. :func:`domains_dir` finds whichever is present.
"""

from __future__ import annotations

import dataclasses
import difflib
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ruamel.yaml import YAML

from arrange_up.io.pddl_reader import check_pddl_problem
from arrange_up.io.resources import shipped_dir
from arrange_up.io.yaml_problem import check_problem
from arrange_up.model.errors import Diagnostic, ProblemFormatError
from arrange_up.model.problem import ArrangementProblem

__all__ = [
    "PROBLEM_SUFFIXES",
    "DomainInfo",
    "UnknownDomainError",
    "check_problem_file",
    "domain_names",
    "domains_dir",
    "first_sentence",
    "list_domains",
    "load",
    "load_checked",
    "resolve_problem",
]

#: File suffixes of problem files, in order of preference when a name matches several files.
PROBLEM_SUFFIXES: tuple[str, ...] = (".yaml", ".yml", ".pddl")

_SENTENCE_END = re.compile(r"(?<=[.!?])\s+(?=[A-Z])")


class UnknownDomainError(LookupError):
    """``name`` is neither an existing problem file nor the name of a shipped problem.

    ``suggestions`` holds the closest shipped names (possibly none) and ``available`` every
    shipped name; ``str()`` is a complete message for a user.
    """

    def __init__(
        self,
        name: str,
        suggestions: tuple[str, ...] = (),
        available: tuple[str, ...] = (),
        reason: str | None = None,
    ) -> None:
        self.name = name
        self.suggestions = tuple(suggestions)
        self.available = tuple(available)
        self.reason = reason
        super().__init__(self._message())

    def _message(self) -> str:
        if self.reason is not None:
            text = self.reason
        else:
            text = f"unknown problem {self.name!r}: no such file and no shipped domain of that name"
        if len(self.suggestions) == 1:
            text += f"; did you mean {self.suggestions[0]!r}?"
        elif self.suggestions:
            text += "; did you mean one of " + ", ".join(repr(s) for s in self.suggestions) + "?"
        if self.available:
            text += " (shipped domains: " + ", ".join(self.available) + ")"
        return text

    def __str__(self) -> str:
        return self._message()


@dataclass(frozen=True)
class DomainInfo:
    """One shipped problem, as :func:`list_domains` reports it.

    ``name`` is what :func:`resolve_problem` accepts (the file name without its suffix),
    ``summary`` the first sentence of the file's ``description``, ``parts`` the number of
    declared parts and ``goal_kind`` ``"absolute"`` or ``"relative"`` (``"?"`` when the file
    could not be read).
    """

    name: str
    path: Path
    summary: str
    parts: int
    goal_kind: str
    description: str = ""


def domains_dir() -> Path:
    """The folder holding the shipped problems.

    An installed wheel's ``arrange_up/_shipped/domains`` wins; otherwise the checkout's
    ``domains/`` next to the package (a source tree or an editable install).

    Raises:
        FileNotFoundError: neither folder exists (a broken installation).
    """
    return shipped_dir("domains", "domains")


def _shipped_files() -> dict[str, Path]:
    """Shipped name -> file, one file per name (``.yaml`` preferred over ``.pddl``)."""
    found: dict[str, Path] = {}
    directory = domains_dir()
    for suffix in PROBLEM_SUFFIXES:
        for path in sorted(directory.glob(f"*{suffix}")):
            if path.is_file():
                found.setdefault(path.stem, path)
    return dict(sorted(found.items()))


def domain_names() -> list[str]:
    """The names of the shipped problems, sorted."""
    return list(_shipped_files())


def first_sentence(text: str) -> str:
    """The first sentence of ``text`` with whitespace collapsed (all of it if there is no
    sentence break). Abbreviations followed by a lowercase word or a digit (``ch. 3``) do not
    end a sentence."""
    text = " ".join(text.split())
    return _SENTENCE_END.split(text, maxsplit=1)[0] if text else ""


def _scan_yaml(path: Path) -> tuple[str, int, str]:
    """``(description, parts, goal kind)`` read from a YAML problem without validating it."""
    data: Any = YAML(typ="safe", pure=True).load(path.read_text(encoding="utf-8"))
    if not isinstance(data, dict):
        return "", 0, "?"
    description = data.get("description")
    objects = data.get("objects")
    parts = 0
    if isinstance(objects, dict):
        parts = sum(
            1 for spec in objects.values() if isinstance(spec, dict) and spec.get("kind") == "part"
        )
    goal = data.get("goal")
    goal_kind = "?"
    if isinstance(goal, dict):
        if "relative" in goal:
            goal_kind = "relative"
        elif "poses" in goal:
            goal_kind = "absolute"
    return (description if isinstance(description, str) else ""), parts, goal_kind


def _scan_other(path: Path) -> tuple[str, int, str]:
    """Full load for formats without a cheap scan (``.pddl``); unreadable files get ``?``."""
    try:
        problem = load(path)
    except Exception:  # a listing must not fail because of one file
        return "", 0, "?"
    return (
        problem.description,
        len(problem.parts),
        "relative" if problem.goal.is_relative else "absolute",
    )


def list_domains() -> list[DomainInfo]:
    """Every shipped problem, sorted by name.

    YAML files are scanned, not validated (listing stays fast and never fails on one bad
    file); load a problem with :func:`load` to validate it.
    """
    infos = []
    for name, path in _shipped_files().items():
        try:
            if path.suffix in (".yaml", ".yml"):
                description, parts, goal_kind = _scan_yaml(path)
            else:
                description, parts, goal_kind = _scan_other(path)
        except Exception:  # an unreadable file is listed, not fatal
            description, parts, goal_kind = "", 0, "?"
        infos.append(
            DomainInfo(
                name=name,
                path=path,
                summary=first_sentence(description),
                parts=parts,
                goal_kind=goal_kind,
                description=" ".join(description.split()),
            )
        )
    return infos


def _suggest(name: str, names: list[str]) -> tuple[str, ...]:
    """Close matches for a mistyped name: difflib's, then names containing what was typed."""
    key = name.lower()
    lowered = {n.lower(): n for n in names}
    close = [lowered[m] for m in difflib.get_close_matches(key, list(lowered), n=3, cutoff=0.6)]
    if not close and len(key) >= 2:
        close = [n for n in names if key in n.lower()][:3]
    return tuple(close)


def resolve_problem(name_or_path: str | Path) -> Path:
    """The problem file meant by ``name_or_path``.

    An existing file wins. Otherwise the argument is taken as the name of a shipped problem,
    with or without a suffix (``blocks-4``, ``blocks-4.yaml``, ``blocks-4.pddl``); without a
    suffix a ``.yaml`` file is preferred.

    Raises:
        UnknownDomainError: (a :class:`LookupError`) neither a file nor a shipped name; the
            message suggests the closest shipped names.
    """
    text = str(name_or_path)
    path = Path(text).expanduser()
    if path.is_file():
        return path
    try:
        shipped = _shipped_files()
    except FileNotFoundError:
        shipped = {}
    names = list(shipped)
    if path.is_dir():
        raise UnknownDomainError(
            text, (), tuple(names), reason=f"{text!r} is a directory, not a problem file"
        )

    looks_like_path = "/" in text or "\\" in text or text.startswith((".", "~"))
    stem, suffix = text, ""
    if path.suffix.lower() in PROBLEM_SUFFIXES:
        stem, suffix = text[: -len(path.suffix)], path.suffix.lower()
    if not looks_like_path and shipped:
        if suffix:
            exact = domains_dir() / f"{stem}{suffix}"
            if exact.is_file():
                return exact
        elif stem in shipped:
            return shipped[stem]

    base = Path(stem).name
    if looks_like_path:
        hint = (base,) if base in shipped else _suggest(base, names)
        raise UnknownDomainError(text, hint, (), reason=f"no such problem file: {text}")
    raise UnknownDomainError(text, _suggest(base, names), tuple(names))


def check_problem_file(path: str | Path) -> tuple[ArrangementProblem | None, list[Diagnostic]]:
    """Validate a problem file by its suffix (``.pddl`` through the PDDL front end, anything
    else as YAML): ``(problem, diagnostics)``, ``problem`` being ``None`` when there is at
    least one error; the diagnostics include the warnings. Never raises for a bad file."""
    if Path(path).suffix.lower() == ".pddl":
        return check_pddl_problem(path)
    return check_problem(path)


def load_problem_file(path: str | Path) -> ArrangementProblem:
    """Load a problem file by its suffix (see :func:`check_problem_file`). Raises
    :class:`arrange_up.model.errors.ProblemFormatError`."""
    problem, diagnostics = check_problem_file(path)
    if problem is None:
        raise ProblemFormatError(diagnostics)
    return problem


def load_checked(name_or_path: str | Path) -> tuple[ArrangementProblem, list[Diagnostic]]:
    """Resolve ``name_or_path`` (see :func:`resolve_problem`) and load the problem, with the
    warnings found in its file (the loaders never refuse a file for warnings alone).

    A shipped problem loaded by name records ``source="domain:NAME"``.

    Raises:
        UnknownDomainError: nothing matches ``name_or_path``.
        arrange_up.model.errors.ProblemFormatError: the file is not a valid problem.
    """
    path = resolve_problem(name_or_path)
    problem, diagnostics = check_problem_file(path)
    if problem is None:
        raise ProblemFormatError(diagnostics)
    if not Path(str(name_or_path)).expanduser().is_file():
        problem = dataclasses.replace(problem, source=f"domain:{path.stem}")
    return problem, diagnostics


def load(name_or_path: str | Path) -> ArrangementProblem:
    """:func:`load_checked` without the warnings."""
    return load_checked(name_or_path)[0]
