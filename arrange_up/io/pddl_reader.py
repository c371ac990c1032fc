"""Reading a PDDL problem of the arrange-up domain into an
:class:`~arrange_up.model.problem.ArrangementProblem`, through unified-planning's ``PDDLReader``
(see :mod:`arrange_up.io.pddl` for the vocabulary), with diagnostics located in the text."""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

from arrange_up.io import validation
from arrange_up.io.files import (
    ProblemFileTooLarge,
    read_problem_bytes,
    text_place,
    undecodable_place,
)
from arrange_up.io.pddl_domain import (
    ANGLE_FUNCTIONS,
    DOMAIN_FILE,
    DOMAIN_NAME,
    NOISE_FUNCTIONS,
    PDDL_UNITS,
    POSE_FUNCTIONS,
    RELATIVE_FUNCTIONS,
    SPREAD_FUNCTIONS,
    TABLE_FUNCTIONS,
    WALL_PREDICATES,
    domain_path,
    num,
)
from arrange_up.io.shape_catalogue import load_catalogue
from arrange_up.io.validation import (
    MAX_POSE_REACH,
    WIDE_SPREAD,
    Placed,
    pose_reach,
    too_many_objects,
)
from arrange_up.model.errors import Diagnostic, ProblemFormatError, sort_diagnostics
from arrange_up.model.problem import (
    ArrangementProblem,
    Goal,
    InitialObject,
    ObjectKind,
    ObjectSpec,
    Table,
    Uncertainty,
)

__all__ = [
    "check_pddl_problem",
    "check_pddl_problem_text",
    "load_pddl_problem",
    "load_pddl_problem_text",
    "problem_from_up",
    "problem_name_place",
]

Checked = tuple[ArrangementProblem | None, list[Diagnostic]]


def load_pddl_problem(path: str | Path, domain: str | Path | None = None) -> ArrangementProblem:
    """Load a ``.pddl`` problem of the arrange-up domain (default: the shipped domain file).

    Raises :class:`~arrange_up.model.errors.ProblemFormatError` whose diagnostics name the file,
    the line and column where they can (UP's reader reports little; the offending object or
    fluent is looked up in the text) and what was expected.
    """
    return _loaded(check_pddl_problem(path, domain))


def load_pddl_problem_text(
    text: str, source: str = "<text>", domain: str | Path | None = None
) -> ArrangementProblem:
    """Like :func:`load_pddl_problem`, for PDDL ``text`` named ``source`` in messages."""
    return _loaded(check_pddl_problem_text(text, source, domain))


def _loaded(checked: Checked) -> ArrangementProblem:
    problem, diagnostics = checked
    if problem is None:
        raise ProblemFormatError(diagnostics)
    return problem


def check_pddl_problem(path: str | Path, domain: str | Path | None = None) -> Checked:
    """Validate a ``.pddl`` problem file: ``(problem, diagnostics)``, ``problem`` being ``None``
    when there is at least one error; the diagnostics include the warnings. Never raises for a
    bad file."""
    source = str(path)
    try:
        data = read_problem_bytes(Path(path))
    except ProblemFileTooLarge as error:
        return None, [Diagnostic(source, None, None, "", str(error))]
    except FileNotFoundError:
        return None, [Diagnostic(source, None, None, "", "no such file; expected a .pddl file")]
    except IsADirectoryError:
        return None, [Diagnostic(source, None, None, "", "is a directory; expected a .pddl file")]
    except OSError as error:
        message = f"cannot read the file: {error.strerror or error}"
        return None, [Diagnostic(source, None, None, "", message)]
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line, column = undecodable_place(data, error)
        message = (
            f"not a text file: byte 0x{data[error.start]:02x} is not UTF-8; expected a PDDL "
            "problem file in UTF-8"
        )
        return None, [Diagnostic(source, line, column, "", message)]
    return check_pddl_problem_text(text, source, domain)


def check_pddl_problem_text(
    text: str, source: str = "<text>", domain: str | Path | None = None
) -> Checked:
    """Like :func:`check_pddl_problem`, for PDDL ``text`` named ``source`` in messages."""
    try:
        return _check_text(text, source, domain)
    except ProblemFormatError as error:
        return None, list(error.diagnostics)
    except Exception as error:  # a safety net: a bug here must not become a traceback
        message = (
            f"internal error while checking the file ({type(error).__name__}: {error}); "
            "please report this"
        )
        return None, [Diagnostic(source, None, None, "", message)]


def _check_text(text: str, source: str, domain: str | Path | None) -> Checked:
    # Lazy: unified-planning is slow to import (docs/design/io.md) and io.domains imports this
    # module, so loading a YAML problem by name would pay for it otherwise.
    from unified_planning.io import PDDLReader

    domain_file = Path(domain) if domain is not None else domain_path()
    domain_text = domain_file.read_text(encoding="utf-8")
    located = _Text(text)
    declared = located.domain_name()
    foreign = declared is not None and declared.lower() != DOMAIN_NAME
    if foreign and located.up_writer_name() is None:
        assert declared is not None
        line, column = located.find(r"\(\s*:domain\s+" + re.escape(declared))
        raise ProblemFormatError(
            [
                Diagnostic(
                    source,
                    line,
                    column,
                    ":domain",
                    f"the problem is for domain {declared!r}; expected {DOMAIN_NAME!r} "
                    f"(arrange-up reads problems of its own domain, {DOMAIN_FILE}, and what "
                    "unified-planning's PDDLWriter writes of one: problem NAME-problem for "
                    "domain NAME-domain)",
                )
            ]
        )
    supported = _Text(domain_text).requirements()
    unsupported = located.unsupported_requirement(supported)
    if unsupported is not None:
        token, index = unsupported
        line, column = located.position(index)
        raise ProblemFormatError(
            [
                Diagnostic(
                    source,
                    line,
                    column,
                    ":requirements",
                    f"the problem requires {token}, which arrange-up does not support; "
                    "expected none or those its domain declares "
                    f"({' '.join(sorted(supported))}): its actions "
                    "are instantaneous, with unconditional effects",
                )
            ]
        )
    try:
        up_problem = PDDLReader().parse_problem_string(domain_text, text)
    except Exception as error:  # UP raises many kinds; each becomes one diagnostic
        diagnostic = _reader_diagnostic(error, source, located)
        if located.up_writer_name() is not None:
            diagnostic = dataclasses.replace(diagnostic, message=diagnostic.message + _UP_WRITER)
        raise ProblemFormatError([diagnostic]) from None
    builder = _Builder(up_problem, source, located)
    problem = builder.build()
    return problem, sort_diagnostics(builder.diagnostics)


_UP_WRITER = (
    "; the file looks written by unified-planning's PDDLWriter, which arrange-up reads when it "
    "wrote a problem of arrange-up's PDDL domain (one PDDLReader read from a .pddl file). The "
    "model of arrange_up.up.compile.to_up has no shapes and other names: write its arrangement "
    "problem with arrange_up.io.pddl.write_pddl_problem instead"
)


def problem_from_up(
    up_problem: Any, *, source: str | None = None, text: str | None = None
) -> ArrangementProblem:
    """Rebuild an :class:`ArrangementProblem` from a UP problem in the PDDL vocabulary (as
    ``PDDLReader`` makes it from a problem of the arrange-up domain).

    ``text`` (the problem's PDDL source) restores the names' written case and locates
    diagnostics; without it names stay as UP holds them (lowercase). Raises
    :class:`~arrange_up.model.errors.ProblemFormatError` listing every problem found.
    """
    source = source or f"<unified-planning problem {up_problem.name}>"
    builder = _Builder(up_problem, source, _Text(text) if text is not None else None)
    problem = builder.build()
    errors = [d for d in builder.diagnostics if d.is_error]
    if errors or problem is None:
        if not errors:  # pragma: no cover - every refusal records an error
            builder.error("", "", "the problem could not be rebuilt")
        raise ProblemFormatError(sort_diagnostics(builder.diagnostics))
    return problem


#: ``(problem NAME``: the problem's name, group 1.
_PROBLEM_NAME = re.compile(r"\(\s*problem\s+([^\s()]+)", flags=re.IGNORECASE)


def problem_name_place(text: str) -> tuple[int, int] | None:
    """Line and column (1-based) of the problem's name in the PDDL ``text`` (comments skipped),
    or None when it names none."""
    source = _Text(text)
    match = _PROBLEM_NAME.search(source.code)
    return source.position(match.start(1)) if match else None


class _Text:
    """The PDDL source of a problem: names as written, and positions of things in it."""

    def __init__(self, text: str) -> None:
        self.text = text
        # comments blanked out (same length, so positions stay valid)
        self.code = re.sub(r";[^\n]*", lambda m: " " * len(m.group(0)), text)

    def position(self, index: int) -> tuple[int, int]:
        return text_place(self.text, index)

    def token_at(self, line: int, column: int | None, pattern: str = r"[^\s()]+") -> str | None:
        """What ``pattern`` (by default a name or a number) matches at ``line``, ``column``
        (1-based), as the file spells it; None when it matches nothing there."""
        lines = self.text.splitlines()
        if not 1 <= line <= len(lines) or column is None:
            return None
        match = re.match(pattern, lines[line - 1][column - 1 :])
        return match.group(0) if match else None

    def find(self, pattern: str) -> tuple[int | None, int | None]:
        match = re.search(pattern, self.code, flags=re.IGNORECASE)
        return self.position(match.start()) if match else (None, None)

    def assigned_again(self) -> list[tuple[str, int, int]]:
        """Each numeric fluent ``:init`` sets a second time (whatever its case), as written
        there, with the line and column of the second ``(=``. A reader keeps one of the values
        and drops the other without a word, so the file is ambiguous."""
        start = re.search(r"\(\s*:init\b", self.code, flags=re.IGNORECASE)
        if start is None:
            return []
        end = re.compile(r"\(\s*:(goal|metric|constraints)\b", flags=re.IGNORECASE)
        stop = end.search(self.code, start.end())
        section = self.code[start.end() : stop.start() if stop else len(self.code)]
        seen: set[str] = set()
        again = []
        for match in re.finditer(r"\(\s*=\s*(\([^()]*\))", section):
            fluent = match.group(1)
            key = " ".join(fluent.strip("()").lower().split())
            if key in seen:
                again.append((fluent, *self.position(start.end() + match.start())))
            seen.add(key)
        return again

    def declared_again(self, name: str) -> tuple[int | None, int | None]:
        """Where ``:objects`` declares ``name`` (whatever its case) a second time, or, declared
        once (named like a type of the domain), where it does so."""
        section = re.search(r"\(\s*:objects\b[^)]*\)", self.code, flags=re.IGNORECASE)
        if section is None:
            return None, None
        pattern = rf"(?<![\w-]){re.escape(name)}(?![\w-])"
        found = list(re.finditer(pattern, section.group(0), flags=re.IGNORECASE))[:2]
        return self.position(section.start() + found[-1].start()) if found else (None, None)

    def requirements(self) -> set[str]:
        """The requirement flags the ``:requirements`` section declares, lowercased."""
        return {token.lower() for token, _index in self._requirement_tokens()}

    def unsupported_requirement(self, supported: set[str]) -> tuple[str, int] | None:
        """The first requirement flag declared that is not in ``supported``, as written, with
        its index in the text; None when every one is."""
        for token, index in self._requirement_tokens():
            if token.lower() not in supported:
                return token, index
        return None

    def _requirement_tokens(self) -> list[tuple[str, int]]:
        section = re.search(r"\(\s*:requirements\b([^()]*)\)", self.code, flags=re.IGNORECASE)
        if section is None:
            return []
        start = section.start(1)
        return [(m.group(0), start + m.start()) for m in re.finditer(r"\S+", section.group(1))]

    def domain_name(self) -> str | None:
        match = re.search(r"\(\s*:domain\s+([^\s()]+)", self.code, flags=re.IGNORECASE)
        return match.group(1) if match else None

    def problem_name(self) -> str | None:
        match = _PROBLEM_NAME.search(self.code)
        return match.group(1) if match else None

    def up_writer_name(self) -> str | None:
        """``NAME`` when the problem is ``NAME-problem`` of domain ``NAME-domain``, the names
        unified-planning's ``PDDLWriter`` gives a problem ``NAME`` and its domain."""
        domain, problem = self.domain_name(), self.problem_name()
        if domain is None or problem is None:
            return None
        stem = domain[: -len("-domain")]
        if domain.lower().endswith("-domain") and problem.lower() == f"{stem}-problem".lower():
            return problem[: -len("-problem")]
        return None

    def object_names(self) -> list[str]:
        """Object names in the ``:objects`` section, as written, in order."""
        match = re.search(r"\(\s*:objects\b", self.code, flags=re.IGNORECASE)
        if not match:
            return []
        depth, end = 1, match.end()
        while end < len(self.code) and depth:
            depth += {"(": 1, ")": -1}.get(self.code[end], 0)
            end += 1
        tokens = self.code[match.end() : end - 1].split()
        names, skip = [], False
        for token in tokens:
            if skip:
                skip = False
            elif token == "-":
                skip = True
            else:
                names.append(token)
        return names

    def description(self) -> str:
        """The ``; description:`` comment block written by :func:`write_pddl_problem`."""
        lines = self.text.splitlines()
        for i, line in enumerate(lines):
            if line.startswith("; description:"):
                parts = [line[len("; description:") :].strip()]
                for more in lines[i + 1 :]:
                    if not more.startswith(";   "):
                        break
                    parts.append(more[4:].strip())
                return " ".join(parts)
        return ""


def _reader_diagnostic(error: Exception, source: str, located: _Text) -> Diagnostic:
    line = column = None
    message = str(error).strip() or type(error).__name__
    if isinstance(error, RecursionError):
        return Diagnostic(
            source,
            None,
            None,
            "",
            "not valid PDDL: nested too deeply; expected a (define (problem ...)) of the "
            f"{DOMAIN_NAME} domain",
        )
    if hasattr(error, "lineno") and hasattr(error, "col"):  # pyparsing's ParseException
        line, column = int(error.lineno), int(error.col)
        message = f"not valid PDDL: {getattr(error, 'msg', message)}"
    elif isinstance(error, KeyError):
        name = str(error.args[0]) if error.args else "?"
        line, column = located.find(rf"(?<![\w-]){re.escape(name)}(?![\w-])")
        message = (
            f"unknown name {name!r}: not a type, function or object of the {DOMAIN_NAME} "
            f"domain ({DOMAIN_FILE}); expected object types among the shape types of "
            f"{load_catalogue().path} ({', '.join(load_catalogue().type_names)})"
        )
    else:
        found = re.search(r"line:?\s*(\d+),\s*col:?\s*(\d+)", message)
        if found:
            line, column = int(found.group(1)), int(found.group(2))
        line, column, message = _explained(message, line, column, located)
    return Diagnostic(source, line, column, "", message)


def _explained(
    message: str, line: int | None, column: int | None, located: _Text
) -> tuple[int | None, int | None, str]:
    """unified-planning's reader ``message`` (at ``line``, ``column`` when it gives them) as
    this format's words: what was found, in the file's own spelling, and what was expected;
    ``(line, column, message)``, the message its own when it is none of those known."""
    expression = re.match(r"Found invalid expression: (.*?)\. From line", message)
    handled = re.match(r"Not able to handle: (.*?) found at line", message)
    twice = re.match(r"Name (\S+) already defined!", message)
    if expression and line is not None:
        written = located.token_at(line, column) or expression.group(1)
        said = (
            f"unknown name or value {written!r}: expected a number, or an object declared "
            "under :objects"
        )
    elif handled and line is not None:
        written = located.token_at(line, column, r"\([^()]*\)") or handled.group(1)
        said = (
            f"cannot read {written!r}: expected a function of the {DOMAIN_NAME} domain "
            f"({DOMAIN_FILE}) applied to declared objects"
        )
    elif message.startswith("Missing goal section"):
        line, column = located.find(r"\(\s*define")
        said = "missing (:goal ...): expected a goal section in the problem"
    elif twice:
        name = twice.group(1)
        line, column = located.declared_again(name)
        said = (
            f"the name {name!r} is defined twice (PDDL names ignore case, and an object may "
            "not be named like a type of the domain): expected names unique regardless of case"
        )
    else:
        said = f"unified-planning's PDDL reader refused the problem: {message}"
    return line, column, said


@dataclass
class _Builder:
    """Rebuilds an :class:`ArrangementProblem` from a UP problem in the PDDL vocabulary."""

    up: Any
    source: str
    located: _Text | None
    diagnostics: list[Diagnostic] = field(default_factory=list)
    #: The goal's ``(on-table X)`` and ``(not (on-table X))`` conditions, as
    #: ``("on-table" | "off-table", X)`` (:meth:`check_table_goals`).
    table_goals: list[tuple[str, str]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.catalogue = load_catalogue()
        written = self.located.object_names() if self.located is not None else []
        self.case = {name.lower(): name for name in written}

    # -- diagnostics ---------------------------------------------------------------------
    def error(self, path: str, pattern: str, message: str, severity: str = "error") -> None:
        line = column = None
        if self.located is not None and pattern:
            line, column = self.located.find(pattern)
        self.diagnostics.append(
            Diagnostic(self.source, line, column, path, message, severity)  # type: ignore[arg-type]
        )

    def name(self, up_name: str) -> str:
        return self.case.get(up_name.lower(), up_name)

    # -- the whole problem -----------------------------------------------------------------
    def build(self) -> ArrangementProblem | None:
        refused = too_many_objects(len(self.up.all_objects))
        if refused is not None:  # refused before any per-object work
            self.error("objects", r"\(\s*:objects", refused)
            return None
        kinds, objects = self.objects()
        values = self.initial_values(kinds)
        self.assigned_once()
        if any(d.is_error for d in self.diagnostics):
            return None  # numbers that are not doubles would fail every later check
        table = self.table(values)
        uncertainty = self.uncertainty(values)
        initial, obstacles = self.poses(values, kinds, table)
        goal = self.goal(kinds)
        self.check_table_goals(kinds, {entry.name for entry in initial}, goal)
        if any(d.is_error for d in self.diagnostics):
            return None
        assert table is not None and uncertainty is not None and goal is not None
        specs = tuple(
            ObjectSpec(spec.name, spec.kind, spec.shape, obstacles.get(spec.name))
            for spec in objects
        )
        name = self.up.name
        if self.located is not None:
            name = self.located.up_writer_name() or self.located.problem_name() or name
        problem = ArrangementProblem(
            name=name,
            table=table,
            objects=specs,
            initial=tuple(initial),
            goal=goal,
            uncertainty=uncertainty,
            description=self.located.description() if self.located is not None else "",
            units=PDDL_UNITS,
            source=self.source,
        )
        self.check_placement(problem)
        self.check_goal_on_table(problem)
        self.check_goal_overlaps(problem)
        if any(d.is_error for d in self.diagnostics):
            return None
        if validation.unsampleable(problem):
            self.error(
                "init",
                r"\(\s*:init",
                f"no collision-free initial state in {validation.SAMPLE_DRAWS} draws from the "
                "initial uncertainties (dx, dy, dtheta): objects overlap each other, an "
                "obstacle or a wall in every one; expected uncertainties from which particles "
                "can be drawn",
            )
            return None
        return problem

    # -- objects ---------------------------------------------------------------------------
    def objects(self) -> tuple[dict[str, ObjectKind], list[ObjectSpec]]:
        kinds: dict[str, ObjectKind] = {}
        specs: list[ObjectSpec] = []
        order = {name.lower(): i for i, name in enumerate(self.case.values())}
        up_objects = sorted(self.up.all_objects, key=lambda o: order.get(o.name.lower(), 1 << 30))
        for obj in up_objects:
            name = self.name(obj.name)
            type_name = obj.type.name
            entry = self.catalogue.entry(type_name)
            if entry is None:
                self.error(
                    f"objects.{name}",
                    rf"(?<![\w-]){re.escape(obj.name)}\s+-",
                    f"object {name} has type {type_name!r}; expected a shape type of the "
                    f"catalogue {self.catalogue.path} ({', '.join(self.catalogue.type_names)})",
                )
                continue
            kinds[name] = entry.kind
            specs.append(ObjectSpec(name, entry.kind, entry.shape))
        if not specs and not any(d.is_error for d in self.diagnostics):
            self.error("objects", r"\(\s*:objects", "no objects; expected at least one part")
        return kinds, specs

    # -- :init -----------------------------------------------------------------------------
    def initial_values(self, kinds: dict[str, ObjectKind]) -> dict[tuple[str, ...], Any]:
        """``(function, arg, ...) -> value`` (Fraction or bool) of every explicit value."""
        out: dict[tuple[str, ...], Any] = {}
        for fluent_exp, value in self.up.explicit_initial_values.items():
            key = (fluent_exp.fluent().name, *(self.name(a.object().name) for a in fluent_exp.args))
            # a negative number is (- 15) in standard PDDL, an expression to UP: simplify it
            value = value.simplify()
            if value.is_bool_constant():
                out[key] = value.bool_constant_value()
            elif value.is_int_constant() or value.is_real_constant():
                number = Fraction(value.constant_value())
                if self.finite(number, f"init.{key[0]}", _fluent_pattern(key)):
                    out[key] = number
            else:
                function = key[0]
                self.error(
                    f"init.{function}",
                    rf"\(\s*=\s*\(\s*{re.escape(function)}[\s)]",
                    f"({' '.join(key)}) is set to {value}; expected a number (a negative one "
                    "written -15 or (- 15))",
                )
        return out

    def assigned_once(self) -> None:
        """Refuse a numeric fluent that ``:init`` sets twice (the reader would keep one value)."""
        if self.located is None:
            return
        for fluent, line, column in self.located.assigned_again():
            self.diagnostics.append(
                Diagnostic(
                    self.source,
                    line,
                    column,
                    f"init.{fluent.strip('()').split()[0]}",
                    f"{' '.join(fluent.split())} is set a second time; expected each value set "
                    "once in :init",
                )
            )

    def finite(self, number: Fraction, path: str, pattern: str) -> bool:
        """Whether ``number`` is a usable double; reported at ``pattern`` when it is not."""
        try:
            float(number)
        except OverflowError:
            digits = len(str(abs(number.numerator) // number.denominator))
            self.error(
                path,
                pattern,
                f"a number of {digits} digits is too large; expected a finite number of at "
                "most 1e308 (a double)",
            )
            return False
        return True

    def angle(self, path: str, pattern: str, degrees: Fraction) -> bool:
        """Whether ``degrees`` is a usable angle (see :data:`validation.MAX_ANGLE`)."""
        reason = validation.angle_problem(PDDL_UNITS.angle_in(float(degrees)), PDDL_UNITS.angle)
        if reason is not None:
            self.error(path, pattern, f"angle {num(float(degrees))} deg: {reason}")
            return False
        return True

    def number(self, values: dict, key: tuple[str, ...], default: Fraction | None) -> Any:
        value = values.get(key, default)
        if value is None:
            return None
        return Fraction(value)

    def table(self, values: dict) -> Table | None:
        size = []
        for name in TABLE_FUNCTIONS:
            value = values.get((name,))
            if value is None:
                self.error(
                    "init",
                    r"\(\s*:init",
                    f"missing ({name}); expected the table's size in inches, e.g. (= ({name}) 10)",
                )
            elif value <= 0:
                self.error(
                    f"init.{name}",
                    rf"\(\s*{name}\s*\)",
                    f"({name}) is {num(float(value))}; expected a positive size in inches",
                )
            else:
                size.append(float(value))
        walls = tuple(edge for pred, edge in WALL_PREDICATES.items() if values.get((pred,)))
        return Table((size[0], size[1]), walls) if len(size) == 2 else None

    def uncertainty(self, values: dict) -> Uncertainty | None:
        defaults = Uncertainty()
        fields: dict[str, list[float]] = {
            attr: list(getattr(defaults, attr)) for attr, _ in NOISE_FUNCTIONS.values()
        }
        given: dict[str, set[int]] = {attr: set() for attr in fields}
        ok = True
        stated: dict[str, set[int]] = {attr: set() for attr in given}  # refused values too
        for name, (attr, index) in NOISE_FUNCTIONS.items():
            value = values.get((name,))
            if value is None:
                continue
            stated[attr].add(index)
            density = "density" in name  # a body of zero mass cannot be simulated
            if value < 0 or (density and value == 0):
                self.error(
                    f"init.{name}",
                    rf"\(\s*{name}\s*\)",
                    f"({name}) is {num(float(value))}; expected a value "
                    f"{'> 0 (a density)' if density else '>= 0'}",
                )
                ok = False
                continue
            if name.endswith("dtheta") and not self.angle(
                f"init.{name}", rf"\(\s*{name}\s*\)", value
            ):
                ok = False
                continue
            fields[attr][index] = self.convert(name, value)
            given[attr].add(index)
        for attr in ("friction", "part_density", "manipulator_density"):
            stem = attr.replace("_", "-")
            if len(stated[attr]) == 1:
                self.error(
                    "init",
                    rf"\(\s*{stem}-(min|max)\s*\)",
                    f"only one of ({stem}-min) and ({stem}-max) is given; expected both (a "
                    "uniform range) or neither (the default)",
                )
                ok = False
            elif len(given[attr]) == 2 and fields[attr][0] > fields[attr][1]:
                self.error(
                    "init",
                    rf"\(\s*{stem}-min\s*\)",
                    f"({stem}-min) is above ({stem}-max); expected min <= max",
                )
                ok = False
        if not ok:
            return None
        if fields["friction"][1] > validation.MAX_FRICTION:
            self.error(
                "init.friction-max",
                r"\(\s*friction-max\s*\)",
                f"(friction-max) is {num(fields['friction'][1])}, far above real table-top "
                f"materials (below ~1.5); every push will stick. Expected at most "
                f"{num(validation.MAX_FRICTION)}: check the value",
                severity="warning",
            )
        return Uncertainty(**{attr: tuple(v) for attr, v in fields.items()})  # type: ignore[arg-type]

    @staticmethod
    def convert(function: str, value: Fraction) -> float:
        """A PDDL number (inches, degrees) in internal units (inches, radians)."""
        if function in ANGLE_FUNCTIONS or function.endswith("dtheta"):
            return PDDL_UNITS.angle_in(float(value))
        return float(value)

    def poses(
        self, values: dict, kinds: dict[str, ObjectKind], table: Table | None = None
    ) -> tuple[list[InitialObject], dict[str, tuple[float, float, float]]]:
        reach = pose_reach(table.size) if table is not None else math.inf
        initial: list[InitialObject] = []
        obstacles: dict[str, tuple[float, float, float]] = {}
        on_table = [key[1] for key, v in values.items() if key[0] == "on-table" and v is True]
        for name, kind in kinds.items():
            if kind is ObjectKind.OBSTACLE and name not in on_table:
                on_table.append(name)
        for name in on_table:
            if name not in kinds:
                continue
            pose = []
            for function in POSE_FUNCTIONS:
                value = values.get((function, name))
                if value is None and function == "theta":
                    value = Fraction(0)
                if value is None:
                    self.error(
                        f"init.{function}({name})",
                        rf"\(\s*on-table\s+{re.escape(name)}\s*\)",
                        f"{name} is on the table but has no ({function} {name}); expected its "
                        f"nominal pose: (= (x {name}) ...) (= (y {name}) ...) and optionally "
                        f"(= (theta {name}) ...) in degrees",
                    )
                    break
                if function == "theta" and not self.angle(
                    f"init.theta({name})", rf"\(\s*theta\s+{re.escape(name)}\s*\)", value
                ):
                    break
                pose.append(self.convert(function, value))
            if len(pose) != 3:
                continue
            if kinds[name] is ObjectKind.OBSTACLE:
                obstacles[name] = (pose[0], pose[1], pose[2])
                continue
            spread = []
            for function in SPREAD_FUNCTIONS:
                value = values.get((function, name), Fraction(0))
                if value < 0:
                    self.error(
                        f"init.{function}({name})",
                        rf"\(\s*{function}\s+{re.escape(name)}\s*\)",
                        f"({function} {name}) is {num(float(value))}; expected a half-width >= 0",
                    )
                elif function != "dtheta" and value > reach:
                    self.error(
                        f"init.{function}({name})",
                        rf"\(\s*{function}\s+{re.escape(name)}\s*\)",
                        f"({function} {name}) is {float(value):g} in, more than "
                        f"{MAX_POSE_REACH} table sizes; expected a half-width of at most "
                        f"{num(reach)} in ({WIDE_SPREAD})",
                    )
                elif function == "dtheta":
                    self.angle(
                        f"init.dtheta({name})",
                        rf"\(\s*dtheta\s+{re.escape(name)}\s*\)",
                        value,
                    )
                spread.append(self.convert(function, value))
            initial.append(
                InitialObject(name, (pose[0], pose[1], pose[2]), (spread[0], spread[1], spread[2]))
            )
        return initial, obstacles

    # -- :goal -----------------------------------------------------------------------------
    def goal(self, kinds: dict[str, ObjectKind]) -> Goal | None:
        bounds: dict[str, dict[str, list[Fraction | None]]] = {}
        references: set[str] = set()
        functions_used: set[str] = set()
        ok = True
        for condition in _conjuncts(self.up.goals):
            parsed = self.goal_condition(condition)
            if parsed is None:
                ok = False
                continue
            if parsed[0] in ("on-table", "off-table"):
                self.table_goals.append(parsed)
                continue
            function, part, reference, low, high = parsed
            functions_used.add(function)
            if reference is not None:
                references.add(reference)
            slot = bounds.setdefault(part, {}).setdefault(function, [None, None])
            if low is not None:
                slot[0] = low if slot[0] is None else max(slot[0], low)
            if high is not None:
                slot[1] = high if slot[1] is None else min(slot[1], high)
        if not ok:
            return None
        if not bounds:
            self.error(
                "goal",
                r"\(\s*:goal",
                "no goal intervals; expected (>= (x P) lo) (<= (x P) hi) and the same for y "
                "(and theta) of each goal part, or rel-x/rel-y/rel-theta for a relative goal",
            )
            return None
        relative = any(f.startswith("rel-") for f in functions_used)
        if relative and any(not f.startswith("rel-") for f in functions_used):
            self.error(
                "goal",
                r"\(\s*:goal",
                "the goal mixes absolute (x, y, theta) and relative (rel-x, rel-y, rel-theta) "
                "conditions; expected one kind",
            )
            return None
        reference = None
        if relative:
            if len(references) != 1:
                self.error(
                    "goal",
                    r"\(\s*:goal",
                    f"a relative goal has one reference part; found {sorted(references)}",
                )
                return None
            (reference,) = references
            if kinds.get(reference) is not ObjectKind.PART:
                self.error(
                    "goal",
                    rf"(?<![\w-]){re.escape(reference)}\s*\)",
                    f"the reference {reference} of a relative goal must be a part",
                )
                return None
        names = RELATIVE_FUNCTIONS if relative else POSE_FUNCTIONS
        targets = []
        tolerance: list[Fraction | None] | None = None
        for part, dims in bounds.items():
            if kinds.get(part) is not ObjectKind.PART:
                kind = kinds.get(part)
                self.error(
                    f"goal.{part}",
                    rf"\(\s*[\w-]+\s+{re.escape(part)}[\s)]",
                    f"a goal for {part}, which is "
                    f"{'not an object' if kind is None else 'a ' + kind.value}; only parts have "
                    "goal poses",
                )
                ok = False
                continue
            if part == reference:
                self.error(
                    f"goal.{part}",
                    "",
                    f"{part} is the reference of the relative goal and cannot have a pose "
                    "relative to itself",
                )
                ok = False
                continue
            target: list[Fraction] = []
            half: list[Fraction | None] = []
            for function in names:
                low, high = dims.get(function, [None, None])
                if low is None and high is None and function in ("theta", "rel-theta"):
                    target.append(Fraction(0))
                    half.append(None)
                    continue
                if low is None or high is None:
                    missing = ">=" if low is None else "<="
                    self.error(
                        f"goal.{function}({part})",
                        rf"\(\s*{function}\s+{re.escape(part)}[\s)]",
                        f"({function} {part}) has no ({missing} ...) bound; expected both bounds "
                        "of an interval target +- tolerance",
                    )
                    ok = False
                    break
                if low > high:
                    self.error(
                        f"goal.{function}({part})",
                        rf"\(\s*{function}\s+{re.escape(part)}[\s)]",
                        f"({function} {part}) must lie in [{num(float(low))}, "
                        f"{num(float(high))}], an empty interval; expected the (>= ...) bound "
                        "at most the (<= ...) bound",
                    )
                    ok = False
                    break
                target.append((low + high) / 2)
                half.append((high - low) / 2)
            else:
                if tolerance is None:
                    tolerance = half
                elif tolerance != half:
                    self.error(
                        f"goal.{part}",
                        rf"\(\s*[\w-]+\s+{re.escape(part)}[\s)]",
                        f"the goal interval of {part} has half-widths {_halves(half)}, another "
                        f"part's have {_halves(tolerance)}; expected one tolerance for every "
                        "goal part (an arrange-up problem has one)",
                    )
                    ok = False
                    continue
                targets.append(
                    (
                        part,
                        (
                            float(target[0]),
                            float(target[1]),
                            PDDL_UNITS.angle_in(float(target[2])),
                        ),
                    )
                )
        if not ok or tolerance is None:
            return None
        tol_theta = tolerance[2]
        return Goal(
            tuple(targets),
            (
                float(tolerance[0]),  # type: ignore[arg-type]
                float(tolerance[1]),  # type: ignore[arg-type]
                None if tol_theta is None else PDDL_UNITS.angle_in(float(tol_theta)),
            ),
            reference,
        )

    def goal_condition(self, condition: Any) -> Any:
        """``("on-table", name)``, ``("off-table", name)`` (for ``(not (on-table name))``),
        ``(function, part, reference, low, high)`` or ``None`` (reported)."""
        if condition.is_fluent_exp() and condition.fluent().name == "on-table":
            return "on-table", self.name(condition.args[0].object().name)
        if condition.is_not():
            (inner,) = condition.args
            if inner.is_fluent_exp() and inner.fluent().name == "on-table":
                return "off-table", self.name(inner.args[0].object().name)
        if condition.is_le() or condition.is_lt() or condition.is_equals():
            # a bound written (- 0.6) is an expression to UP: simplify it to its number
            left, right = (arg.simplify() for arg in condition.args)
            if left.is_fluent_exp() and right.is_constant():
                fluent, value, side = left, Fraction(right.constant_value()), "high"
            elif right.is_fluent_exp() and left.is_constant():
                fluent, value, side = right, Fraction(left.constant_value()), "low"
            else:
                fluent = None
            if fluent is not None and fluent.fluent().name in POSE_FUNCTIONS + RELATIVE_FUNCTIONS:
                function = fluent.fluent().name
                args = [self.name(a.object().name) for a in fluent.args]
                pattern = rf"\(\s*{function}\s+{re.escape(args[0])}[\s)]"
                if not self.finite(value, f"goal.{function}({args[0]})", pattern):
                    return None
                if function in ANGLE_FUNCTIONS and not self.angle(
                    f"goal.{function}({args[0]})", pattern, value
                ):
                    return None
                reference = args[1] if len(args) == 2 else None
                if condition.is_equals():
                    return function, args[0], reference, value, value
                if side == "high":
                    return function, args[0], reference, None, value
                return function, args[0], reference, value, None
        self.error(
            "goal",
            r"\(\s*:goal",
            f"unsupported goal condition {condition}; expected (on-table P), (>= (x P) lo), "
            "(<= (x P) hi) and likewise y, theta, or rel-x/rel-y/rel-theta of (P R), or "
            "(not (on-table F)) for a fixture F that starts off the table",
        )
        return None

    def check_table_goals(
        self, kinds: dict[str, ObjectKind], initial: set[str], goal: Goal | None
    ) -> None:
        """The goal's ``(on-table X)`` and ``(not (on-table X))`` conditions, one error each
        where they ask for what the planner does not plan for.

        ``(not (on-table F))`` states the format's rule that a fixture starting off the table
        ends off it (the rule holds whether the goal states it or not): it may name only such a
        fixture, and no ``(on-table F)`` may contradict the rule. ``(on-table X)`` is kept only
        for a part the goal places (one with pose intervals, or a relative goal's reference),
        which it restates; anywhere else (a part anywhere on the table, a manipulator left on
        it) it is refused rather than dropped, since a plan ignoring it would be reported as
        reaching the goal (not judged while the goal itself has errors: ``goal`` is None)."""
        placed = set() if goal is None else {*goal.parts, goal.reference}
        for condition, name in self.table_goals:
            kind = kinds.get(name)
            put_away = kind is ObjectKind.FIXTURE and name not in initial
            if condition == "off-table" and not put_away:
                what = (
                    "not an object"
                    if kind is None
                    else "a fixture that starts on the table (it may stay)"
                    if kind is ObjectKind.FIXTURE
                    else f"a {kind.value}"
                )
                self.error(
                    f"goal.{name}",
                    rf"\(\s*not\s+\(\s*on-table\s+{re.escape(name)}\s*\)",
                    f"(not (on-table {name})): {name} is {what}; a goal can require off the "
                    "table only a fixture that starts off it (and every such fixture must end "
                    "off it, stated or not)",
                )
                continue
            if condition != "on-table":
                continue
            if put_away:
                why = (
                    f"{name} is a fixture that starts off the table, and such a fixture must "
                    f"end off it; expected (not (on-table {name})) or no condition on it"
                )
            elif goal is None or name in placed:
                continue
            elif kind is ObjectKind.PART:
                why = (
                    f"{name} is a part without goal intervals: arrange-up plans for goal "
                    f"poses, (>= (x {name}) lo) (<= (x {name}) hi) and the same for y (and "
                    f"theta), and (on-table {name}) alone asks for none; give its intervals or "
                    "drop the condition"
                )
            else:
                lifted = " (lifted off after every push)" if kind is ObjectKind.MANIPULATOR else ""
                what = "not an object" if kind is None else f"a {kind.value}{lifted}"
                why = f"{name} is {what}; a goal places parts only, so drop the condition"
            self.error(
                f"goal.{name}",
                rf"\(\s*on-table\s+{re.escape(name)}\s*\)",
                f"(on-table {name}): {why}",
            )

    def check_goal_overlaps(self, problem: ArrangementProblem) -> None:
        """Parts that overlap at their nominal goal poses are a warning
        (:func:`~arrange_up.io.validation.goal_overlaps`), at the goal."""
        for a, b, area in validation.goal_overlaps(problem):
            self.error(
                f"goal.{b}",
                r"\(\s*:goal",
                f"at their goal poses {a} and {b} overlap by {num(area)} square in: no plan "
                "reaches the nominal arrangement, only poses within the tolerance that "
                "separate them can meet the goal; expected goal poses at which the parts "
                "touch at most",
                severity="warning",
            )

    def check_goal_on_table(self, problem: ArrangementProblem) -> None:
        """An absolute goal whose part cannot be on the table is an error; one whose part
        sticks out of the table at the target pose a warning."""
        goal = problem.goal
        if goal.is_relative:
            return
        width, depth = problem.table.size
        for name, pose in goal.targets:
            found = validation.goal_outside(
                problem.object(name).shape, pose, goal.tolerance[:2], problem.table.size
            )
            if found is None:
                continue
            verdict, (xmin, ymin, xmax, ymax) = found
            where = f"the table [0, {num(width)}] x [0, {num(depth)}] in"
            if verdict == "unreachable":
                self.error(
                    f"goal.{name}",
                    r"\(\s*:goal",
                    f"the goal of {name} is off the table even within the tolerance (its "
                    f"centroid must be on {where}); expected a goal interval on the table",
                )
            else:
                self.error(
                    f"goal.{name}",
                    r"\(\s*:goal",
                    f"at its goal pose {name} spans x {num(xmin)}..{num(xmax)}, y "
                    f"{num(ymin)}..{num(ymax)}, beyond {where}: only poses within the "
                    "tolerance that keep it on the table can meet the goal",
                    severity="warning",
                )

    # -- placement (the semantic checks of io.validation, shared with the YAML reader) --------
    def check_placement(self, problem: ArrangementProblem) -> None:
        placed = []
        for spec in problem.obstacles:
            assert spec.pose is not None  # an obstacle always has its fixed pose
            placed.append(Placed(spec.name, spec.shape, spec.pose))
        placed += [Placed(e.name, problem.object(e.name).shape, e.pose) for e in problem.initial]
        width, depth = problem.table.size
        for check in validation.check_placement(placed, problem.table.size):
            name = check.name
            if check.outside is not None:
                xmin, ymin, xmax, ymax = check.outside
                self.error(
                    f"init.x({name})",
                    rf"\(\s*x\s+{re.escape(name)}\s*\)",
                    f"{name} lies outside the table: at its nominal pose it spans x "
                    f"{num(xmin)}..{num(xmax)}, y {num(ymin)}..{num(ymax)}; expected it "
                    f"within [0, {num(width)}] x [0, {num(depth)}] in",
                )
            for index, overlap in check.overlaps:
                self.error(
                    f"init.x({name})",
                    rf"\(\s*x\s+{re.escape(name)}\s*\)",
                    f"{name} overlaps {placed[index].name} at their nominal poses (overlap area "
                    f"{num(overlap)} in²); expected shapes that touch at most",
                )


def _fluent_pattern(key: tuple[str, ...]) -> str:
    """Where the value of fluent ``(function arg ...)`` is set in the text."""
    return r"\(\s*" + r"\s+".join(re.escape(part) for part in key) + r"\s*\)"


def _conjuncts(goals: Iterable[Any]) -> list[Any]:
    out = []
    stack = list(goals)[::-1]
    while stack:
        node = stack.pop()
        if node.is_and():
            stack.extend(list(node.args)[::-1])
        else:
            out.append(node)
    return out


def _halves(half: list[Fraction | None]) -> str:
    return "[" + ", ".join("any" if h is None else num(float(h)) for h in half) + "]"
