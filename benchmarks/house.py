"""Figures of the package's structure, read from the source with :mod:`ast` (nothing is imported).

    python benchmarks/house.py                       # the checkout this file is in
    python benchmarks/house.py --root PATH           # another checkout (its arrange_up/ folder)
    python benchmarks/house.py --json                # the same figures for machines
    python benchmarks/house.py --from arrange_up.repair.repairer:repair_plan --param problem

Sizes
    Modules and packages; the largest module (lines), class (lines from its ``class`` line to its
    last, its methods: functions directly in its body, and its attributes: names assigned in its
    body plus ``self.NAME`` targets in its methods) and function (lines from its ``def`` line to
    its last, nested functions and methods included); functions over 100 lines; functions with
    10 or more parameters (every declared parameter, ``*args`` and ``**kwargs`` included, a
    method's ``self`` or ``cls`` not).

Imports
    Imports of the package's own modules inside function bodies (once per statement;
    ``if TYPE_CHECKING:`` blocks at module level are not function bodies), and every indented
    import statement of the package's own modules (any block: functions, ``if``, ``try``).

Typing
    ``type: ignore`` comments (tokens, so a string that mentions one does not count); ``Any``
    in annotations: every ``Any`` (or ``typing.Any``) inside a parameter's or a return's
    annotation or an annotated assignment's, string annotations parsed, once per occurrence
    (``dict[str, Any]`` counts one); and the annotations that are ``Any`` itself.

The walk of one value through the calls
    Starting from a function and one of its parameters (by default ``problem`` of
    ``arrange_up.planning.planner:plan``; also the repair's and the evaluation's entries), each
    visited function is read for the calls that hand the value on:

    - *The value* inside a function is the parameter it arrived in and every alias of it: a
      name or ``self.NAME`` assigned the value itself (``p = problem``, ``self.problem =
      problem``, ``x = a or problem``, ``x = problem if c else other``). An attribute or any
      other expression computed from it (``problem.table``, ``frame_of(problem)``) is *derived*
      from it, not the value.
    - A *stop* is a call site, in a visited function (nested functions and lambdas included: a
      closure hands on what it captures), that passes the value itself as an argument to a
      function of the package. Callees are resolved statically: names by the module's imports
      (package re-exports followed) and its own definitions and local functions; ``module.f``;
      ``Class.method``; methods where the receiver's class is known (``self``, a parameter or
      variable annotated with a class of the package, a variable assigned ``Class(...)`` or a
      call annotated to return one, an attribute annotated in its class or assigned
      ``Class(...)`` in a method); constructors through ``__init__`` (found up the package's
      base classes), else the fields of a dataclass or ``NamedTuple``; ``super().f``. Calls
      through ``*args``/``**kwargs`` or ``functools.partial``, callables held in variables or
      registries, and calls into other libraries are not stops.
    - Each callee reached is visited once, with the value in the parameter it was first passed
      to; later calls to it still count as stops. An object that keeps the value (a method
      visited assigns it to ``self.NAME``, or a record's field receives it) hands it on from
      its other methods: each of its class's own methods that mentions ``self.NAME`` is
      visited once too, with ``self.NAME`` as the value (no stop counted for that). Other
      objects' attributes are not followed (``context.problem`` read from a record passed on).
      ``reached`` is the number of functions visited, the start included.
    - A *climb* is a stop whose callee lies in a room earlier in the pipeline than the caller's
      (``ROOMS``, the floors of docs/design/README.md, enforced by ``tests/test_house.py``:
      the package's rooms in the order a problem flows through them; the design's list of rooms
      names transitions before cbst and planning before evaluation, but the imports run the
      other way, so the floors decide). Calls within a room are never climbs; a room can only
      call earlier rooms, so the climbs are the stops that leave the caller's room.
    - A *return* is a visited function one of whose ``return`` statements (not those of its
      nested functions) returns an expression that mentions the value or a name derived from
      it (names assigned, looped over or bound by ``with`` from expressions that mention the
      value or a derived name, to a fixed point, flow-insensitively).
"""

from __future__ import annotations

import argparse
import ast
import io
import json
import tokenize
from dataclasses import dataclass, field
from pathlib import Path

PACKAGE = "arrange_up"
MANY_PARAMETERS = 10
LONG_FUNCTION = 100  # lines
TOP_SHOWN = 10

#: The rooms, earliest in the pipeline first; rooms on one floor are peers (docs/design/README.md).
ROOMS: tuple[tuple[str, ...], ...] = (
    ("counts",),
    ("search", "parallel", "model"),
    ("geometry",),
    ("io",),
    ("physics",),
    ("belief",),
    ("cbst",),
    ("transitions",),
    ("evaluation",),
    ("planning",),
    ("execution",),
    ("repair",),
    ("up",),
    ("figures",),
    ("experiments",),
    ("cli",),
)
FLOOR = {room: floor for floor, rooms in enumerate(ROOMS) for room in rooms}

WALKS = {
    "plan": ("arrange_up.planning.planner:plan", "problem"),
    "repair": ("arrange_up.repair.repairer:repair_plan", "problem"),
    "evaluation": ("arrange_up.evaluation.evaluate:evaluate_plan", "problem"),
}

FunctionNode = ast.FunctionDef | ast.AsyncFunctionDef


# ---------------------------------------------------------------------------------------------
# The index: modules, their functions and classes, and what their imported names stand for


@dataclass
class Function:
    module: str
    qualname: str
    node: FunctionNode
    owner: Klass | None = None

    @property
    def name(self) -> str:
        return f"{self.module}:{self.qualname}"

    @property
    def kind(self) -> str:
        """``static``, ``class`` or ``instance`` for methods, ``plain`` otherwise."""
        if self.owner is None:
            return "plain"
        names = {_dotted(d) for d in self.node.decorator_list}
        if "staticmethod" in names:
            return "static"
        return "class" if "classmethod" in names else "instance"

    def parameters(self) -> list[str]:
        """Every declared parameter, ``self``/``cls`` of a bound method left out."""
        a = self.node.args
        names = [p.arg for p in (*a.posonlyargs, *a.args, *a.kwonlyargs)]
        names += [p.arg for p in (a.vararg, a.kwarg) if p is not None]
        return names[1:] if self.kind in ("class", "instance") else names


@dataclass
class Klass:
    module: str
    node: ast.ClassDef
    methods: dict[str, Function] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return f"{self.module}:{self.node.name}"

    def is_record(self) -> bool:
        """A dataclass or NamedTuple: constructed from its annotated fields."""
        decorators = {
            _dotted(d.func if isinstance(d, ast.Call) else d) for d in self.node.decorator_list
        }
        bases = {_dotted(b) for b in self.node.bases}
        return bool({"dataclass", "dataclasses.dataclass"} & decorators) or bool(
            {"NamedTuple", "typing.NamedTuple"} & bases
        )

    def fields(self) -> list[str]:
        return [
            s.target.id
            for s in self.node.body
            if isinstance(s, ast.AnnAssign)
            and isinstance(s.target, ast.Name)
            and "ClassVar" not in ast.unparse(s.annotation)
        ]

    def attributes(self) -> set[str]:
        names = set()
        for statement in self.node.body:
            targets = (
                statement.targets if isinstance(statement, ast.Assign) else [statement.target]
                if isinstance(statement, ast.AnnAssign) else []
            )  # fmt: skip
            names |= {t.id for t in targets if isinstance(t, ast.Name)}
        for method in self.methods.values():
            names |= {path[5:] for path in _self_targets(method.node)}
        return names


@dataclass
class Module:
    name: str
    path: Path
    tree: ast.Module
    source: str
    functions: dict[str, Function] = field(default_factory=dict)
    classes: dict[str, Klass] = field(default_factory=dict)
    #: local name -> ("module", dotted) or ("attr", module, name)
    imports: dict[str, tuple[str, ...]] = field(default_factory=dict)


def _dotted(node: ast.AST) -> str:
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        return f"{_dotted(node.value)}.{node.attr}"
    return ""


def _self_targets(func: ast.AST) -> set[str]:
    """``self.NAME`` paths assigned anywhere in ``func``."""
    found = set()
    for node in ast.walk(func):
        targets = (
            node.targets if isinstance(node, ast.Assign)
            else [node.target] if isinstance(node, ast.AnnAssign | ast.AugAssign) else []
        )  # fmt: skip
        for target in targets:
            if isinstance(target, ast.Attribute) and _dotted(target.value) == "self":
                found.add(f"self.{target.attr}")
    return found


def _module_name(root: Path, path: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _absolute(module: Module, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    package = module.name.split(".")
    if module.path.name != "__init__.py":
        package = package[:-1]
    package = package[: len(package) - node.level + 1]
    return ".".join([*package, node.module] if node.module else package)


class Index:
    """Every module of the package under ``root``, parsed once."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.modules: dict[str, Module] = {}
        for path in sorted((root / PACKAGE).rglob("*.py")):
            source = path.read_text(encoding="utf-8")
            module = Module(_module_name(root, path), path, ast.parse(source), source)
            self.modules[module.name] = module
        for module in self.modules.values():
            self._collect(module)

    def _collect(self, module: Module) -> None:
        for node in module.tree.body:
            if isinstance(node, FunctionNode):
                module.functions[node.name] = Function(module.name, node.name, node)
            elif isinstance(node, ast.ClassDef):
                klass = Klass(module.name, node)
                for item in node.body:
                    if isinstance(item, FunctionNode):
                        klass.methods[item.name] = Function(
                            module.name, f"{node.name}.{item.name}", item, klass
                        )
                module.classes[node.name] = klass
        for node in ast.walk(module.tree):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.asname:
                        module.imports[alias.asname] = ("module", alias.name)
                    else:
                        top = alias.name.split(".")[0]
                        module.imports[top] = ("module", top)
            elif isinstance(node, ast.ImportFrom):
                source = _absolute(module, node)
                for alias in node.names:
                    module.imports[alias.asname or alias.name] = ("attr", source, alias.name)

    # -- resolution ---------------------------------------------------------------------------

    def member(self, module: str, name: str, seen: frozenset[str] = frozenset()) -> object:
        """What ``module.name`` is: a Function, a Klass, a module name (str) or None."""
        if f"{module}.{name}" in self.modules:
            return f"{module}.{name}"
        return self.lookup(module, name, seen)

    def lookup(self, module: str, name: str, seen: frozenset[str] = frozenset()) -> object:
        """What ``name`` means at the top level of ``module``."""
        key = f"{module}:{name}"
        if module not in self.modules or key in seen:
            return None
        found = self.modules[module]
        if name in found.functions:
            return found.functions[name]
        if name in found.classes:
            return found.classes[name]
        target = found.imports.get(name)
        if target is None:
            return None
        if target[0] == "module":
            return target[1] if target[1] in self.modules else None
        return self.member(target[1], target[2], seen | {key})

    def method(
        self, klass: Klass, name: str, seen: frozenset[str] = frozenset()
    ) -> Function | None:
        """``name`` on ``klass`` or, failing that, on its bases of the package."""
        if name in klass.methods:
            return klass.methods[name]
        for base in self.bases(klass):
            if base.name not in seen:
                found = self.method(base, name, seen | {klass.name})
                if found is not None:
                    return found
        return None

    def bases(self, klass: Klass) -> list[Klass]:
        found = []
        for base in klass.node.bases:
            target = self.expression(klass.module, base)
            if isinstance(target, Klass):
                found.append(target)
        return found

    def expression(self, module: str, node: ast.AST) -> object:
        """A dotted name read at the top level of ``module``."""
        if isinstance(node, ast.Name):
            return self.lookup(module, node.id)
        if isinstance(node, ast.Attribute):
            base = self.expression(module, node.value)
            if isinstance(base, str):
                return self.member(base, node.attr)
            if isinstance(base, Klass):
                return self.method(base, node.attr)
        return None

    def annotated_class(self, module: str, annotation: ast.AST | None) -> Klass | None:
        """The one class of the package an annotation names (``X``, ``X | None``, ``"X"``)."""
        if annotation is None:
            return None
        if isinstance(annotation, ast.Constant) and isinstance(annotation.value, str):
            try:
                annotation = ast.parse(annotation.value, mode="eval").body
            except SyntaxError:
                return None
        if isinstance(annotation, ast.BinOp) and isinstance(annotation.op, ast.BitOr):
            sides = [self.annotated_class(module, s) for s in (annotation.left, annotation.right)]
            classes = [s for s in sides if s is not None]
            return classes[0] if len(classes) == 1 else None
        target = self.expression(module, annotation)
        return target if isinstance(target, Klass) else None

    def attribute_class(self, klass: Klass, attr: str) -> Klass | None:
        """The class of ``self.attr`` in ``klass``: annotated in its body or assigned a
        constructor call in one of its methods."""
        for statement in klass.node.body:
            if (
                isinstance(statement, ast.AnnAssign)
                and isinstance(statement.target, ast.Name)
                and statement.target.id == attr
            ):
                return self.annotated_class(klass.module, statement.annotation)
        for method in klass.methods.values():
            for node in ast.walk(method.node):
                if isinstance(node, ast.AnnAssign) and _dotted(node.target) == f"self.{attr}":
                    return self.annotated_class(klass.module, node.annotation)
                if (
                    isinstance(node, ast.Assign)
                    and any(_dotted(t) == f"self.{attr}" for t in node.targets)
                    and isinstance(node.value, ast.Call)
                ):
                    made = self.expression(klass.module, node.value.func)
                    if isinstance(made, Klass):
                        return made
        return None


# ---------------------------------------------------------------------------------------------
# Sizes, imports and typing


def _own(node: ast.Import | ast.ImportFrom) -> bool:
    if isinstance(node, ast.ImportFrom):
        return node.level > 0 or (node.module or "").split(".")[0] == PACKAGE
    return any(alias.name.split(".")[0] == PACKAGE for alias in node.names)


def _lines(node: ast.AST) -> int:
    return node.end_lineno - node.lineno + 1


def _functions(index: Index) -> list[Function]:
    """Every function of the package, nested ones and methods included."""
    found = []
    for module in index.modules.values():
        for node in ast.walk(module.tree):
            if isinstance(node, ast.ClassDef):
                owner = Klass(module.name, node)
                found += [
                    Function(module.name, f"{node.name}.{m.name}", m, owner)
                    for m in node.body
                    if isinstance(m, FunctionNode)
                ]
        methods = {id(f.node) for f in found if f.module == module.name}
        found += [
            Function(module.name, node.name, node)
            for node in ast.walk(module.tree)
            if isinstance(node, FunctionNode) and id(node) not in methods
        ]
    return found


def _annotations(tree: ast.AST) -> list[ast.AST]:
    """Every annotation of parameters, returns and annotated assignments, string ones parsed."""
    annotations: list[ast.AST] = []
    for node in ast.walk(tree):
        if isinstance(node, FunctionNode):
            a = node.args
            params = [*a.posonlyargs, *a.args, *a.kwonlyargs, a.vararg, a.kwarg]
            annotations += [p.annotation for p in params if p is not None and p.annotation]
            annotations += [node.returns] if node.returns else []
        elif isinstance(node, ast.AnnAssign):
            annotations.append(node.annotation)
    parsed = []
    for annotation in annotations:
        if isinstance(annotation, ast.Constant) and isinstance(annotation.value, str):
            try:
                annotation = ast.parse(annotation.value, mode="eval").body
            except SyntaxError:
                continue
        parsed.append(annotation)
    return parsed


def _is_any(node: ast.AST) -> bool:
    return isinstance(node, ast.Name | ast.Attribute) and _dotted(node) in ("Any", "typing.Any")


def _type_ignores(source: str) -> int:
    tokens = tokenize.generate_tokens(io.StringIO(source).readline)
    return sum(1 for t in tokens if t.type == tokenize.COMMENT and "type: ignore" in t.string)


def sizes(index: Index) -> dict[str, object]:
    modules = list(index.modules.values())
    largest_module = max(modules, key=lambda m: len(m.source.splitlines()))
    classes = [k for m in modules for k in m.classes.values()]
    for module in modules:  # nested classes too
        classes += [
            Klass(module.name, n)
            for n in ast.walk(module.tree)
            if isinstance(n, ast.ClassDef) and n.name not in module.classes
        ]
    largest_class = max(classes, key=lambda k: _lines(k.node))
    for item in largest_class.node.body:
        if isinstance(item, FunctionNode):
            largest_class.methods[item.name] = Function(largest_class.module, item.name, item)
    functions = _functions(index)
    largest_function = max(functions, key=lambda f: _lines(f.node))
    many = sorted(
        (f for f in functions if len(f.parameters()) >= MANY_PARAMETERS),
        key=lambda f: (-len(f.parameters()), f.name),
    )
    annotations = [a for m in modules for a in _annotations(m.tree)]
    local = indented = 0
    for module in modules:
        top = {id(node) for node in module.tree.body}
        local_lines = set()
        for func in ast.walk(module.tree):
            if isinstance(func, FunctionNode):
                local_lines |= {
                    n.lineno
                    for n in ast.walk(func)
                    if isinstance(n, ast.Import | ast.ImportFrom) and _own(n)
                }
        local += len(local_lines)
        indented += sum(
            1
            for n in ast.walk(module.tree)
            if isinstance(n, ast.Import | ast.ImportFrom) and _own(n) and id(n) not in top
        )
    return {
        "modules": len(modules),
        "packages": len({m.path.parent for m in modules}),
        "largest_module": {
            "module": str(largest_module.path.relative_to(index.root)),
            "lines": len(largest_module.source.splitlines()),
        },
        "largest_class": {
            "class": largest_class.name,
            "lines": _lines(largest_class.node),
            "methods": len(largest_class.methods),
            "attributes": len(largest_class.attributes()),
        },
        "largest_function": {
            "function": largest_function.name,
            "lines": _lines(largest_function.node),
        },
        f"functions_over_{LONG_FUNCTION}_lines": sum(
            1 for f in functions if _lines(f.node) > LONG_FUNCTION
        ),
        f"functions_with_{MANY_PARAMETERS}_or_more_parameters": len(many),
        "most_parameters": {f.name: len(f.parameters()) for f in many[:TOP_SHOWN]},
        "function_local_imports_of_the_package": local,
        "indented_imports_of_the_package": indented,
        "type_ignore_comments": sum(_type_ignores(m.source) for m in modules),
        "any_in_annotations": sum(1 for a in annotations for node in ast.walk(a) if _is_any(node)),
        "annotations_that_are_any": sum(1 for a in annotations if _is_any(a)),
    }


# ---------------------------------------------------------------------------------------------
# The walk


def room(module: str) -> str:
    """``arrange_up.io.pddl`` -> ``io``; the package root -> ``__init__``."""
    return module.split(".")[1] if module.count(".") else "__init__"


def floor(module: str) -> int:
    """The room's floor; modules outside the rooms (former paths, the root) sit above them all."""
    return FLOOR.get(room(module), len(ROOMS))


def _mentions(node: ast.AST, names: set[str]) -> bool:
    return any(
        (isinstance(n, ast.Name) and n.id in names)
        or (isinstance(n, ast.Attribute) and _dotted(n) in names)
        for n in ast.walk(node)
    )


def _own_body(func: FunctionNode) -> list[ast.AST]:
    """The nodes of ``func`` outside its nested functions, lambdas and classes."""
    found, stack = [], list(func.body)
    while stack:
        node = stack.pop()
        found.append(node)
        if not isinstance(node, FunctionNode | ast.Lambda | ast.ClassDef):
            stack += list(ast.iter_child_nodes(node))
    return found


def _bound(targets: list[ast.AST]) -> set[str]:
    """Names and ``self.NAME`` paths an assignment's targets bind."""
    found = set()
    for target in targets:
        for node in ast.walk(target):
            if isinstance(node, ast.Name):
                found.add(node.id)
            elif isinstance(node, ast.Attribute) and _dotted(node.value) == "self":
                found.add(f"self.{node.attr}")
    return found


def _is_value(node: ast.AST, value: set[str]) -> bool:
    """Whether ``node`` evaluates to the value itself (not to something derived from it)."""
    if isinstance(node, ast.Name | ast.Attribute):
        return _dotted(node) in value
    if isinstance(node, ast.NamedExpr):
        return _is_value(node.value, value)
    if isinstance(node, ast.IfExp):
        return _is_value(node.body, value) or _is_value(node.orelse, value)
    if isinstance(node, ast.BoolOp):
        return any(_is_value(v, value) for v in node.values)
    return False


def _aliases(func: FunctionNode, start: str) -> set[str]:
    value = {start}
    changed = True
    while changed:
        changed = False
        for node in ast.walk(func):
            pairs = []
            if isinstance(node, ast.Assign):
                pairs = [(t, node.value) for t in node.targets]
            elif isinstance(node, ast.AnnAssign | ast.NamedExpr) and node.value is not None:
                pairs = [(node.target, node.value)]
            for target, expr in pairs:
                name = _dotted(target)
                if (
                    name
                    and (name.count(".") == 0 or name.startswith("self."))
                    and name not in value
                ):
                    if _is_value(expr, value):
                        value.add(name)
                        changed = True
    return value


def _derived(func: FunctionNode, value: set[str]) -> set[str]:
    derived = set(value)
    changed = True
    while changed:
        changed = False
        for node in _own_body(func):
            pairs = []
            if isinstance(node, ast.Assign):
                pairs = [(node.targets, node.value)]
            elif isinstance(node, ast.AnnAssign | ast.AugAssign) and node.value is not None:
                pairs = [([node.target], node.value)]
            elif isinstance(node, ast.NamedExpr):
                pairs = [([node.target], node.value)]
            elif isinstance(node, ast.For | ast.AsyncFor):
                pairs = [([node.target], node.iter)]
            elif isinstance(node, ast.With | ast.AsyncWith):
                pairs = [([i.optional_vars], i.context_expr) for i in node.items if i.optional_vars]
            for targets, expr in pairs:
                new = _bound(targets) - derived
                if new and _mentions(expr, derived):
                    derived |= new
                    changed = True
    return derived


@dataclass
class Stop:
    caller: str
    callee: str
    line: int
    climb: bool


@dataclass
class Walk:
    start: str
    parameter: str
    stops: list[Stop] = field(default_factory=list)
    reached: list[str] = field(default_factory=list)
    returns: list[str] = field(default_factory=list)

    def summary(self) -> dict[str, object]:
        return {
            "from": self.start,
            "parameter": self.parameter,
            "stops": len(self.stops),
            "climbs": sum(1 for s in self.stops if s.climb),
            "returns": len(self.returns),
            "reached": len(self.reached),
        }


class _Scope:
    """What the names of one visited function stand for."""

    def __init__(self, index: Index, func: Function) -> None:
        self.index, self.func = index, func
        self.nested = {
            n.name: Function(func.module, f"{func.qualname}.<locals>.{n.name}", n)
            for n in ast.walk(func.node)
            if isinstance(n, FunctionNode) and n is not func.node
        }
        self.instances: dict[str, Klass] = {}
        for node in ast.walk(func.node):
            if isinstance(node, ast.arg) and node.annotation is not None:
                klass = index.annotated_class(func.module, node.annotation)
                if klass is not None:
                    self.instances[node.arg] = klass
        for node in ast.walk(func.node):
            if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                klass = index.annotated_class(func.module, node.annotation)
                if klass is not None:
                    self.instances[node.target.id] = klass
            elif isinstance(node, ast.Assign) and len(node.targets) == 1:
                if (
                    isinstance(node.targets[0], ast.Name)
                    and node.targets[0].id not in self.instances
                ):
                    made = self.resolve(node.value)
                    if isinstance(made, _Instance):
                        self.instances[node.targets[0].id] = made.klass

    def resolve(self, node: ast.AST) -> object:
        """Module name, Function (with how it is bound), Klass or _Instance, or None."""
        if isinstance(node, ast.Name):
            if node.id == "self" and self.func.owner is not None:
                return _Instance(self.func.owner)
            if node.id in self.instances:
                return _Instance(self.instances[node.id])
            if node.id in self.nested:
                return _Bound(self.nested[node.id], False)
            found = self.index.lookup(self.func.module, node.id)
            return _Bound(found, False) if isinstance(found, Function) else found
        if isinstance(node, ast.Attribute):
            base = self.resolve(node.value)
            if _is_super(node.value) and self.func.owner is not None:
                for klass in self.index.bases(self.func.owner):
                    method = self.index.method(klass, node.attr)
                    if method is not None:
                        return _Bound(method, method.kind != "static")
                return None
            if isinstance(base, str):
                found = self.index.member(base, node.attr)
                return _Bound(found, False) if isinstance(found, Function) else found
            if isinstance(base, Klass):
                method = self.index.method(base, node.attr)
                return _Bound(method, method.kind == "class") if method else None
            if isinstance(base, _Instance):
                method = self.index.method(base.klass, node.attr)
                if method is not None:
                    return _Bound(method, method.kind != "static")
                klass = self.index.attribute_class(base.klass, node.attr)
                return _Instance(klass) if klass is not None else None
            return None
        if isinstance(node, ast.Call):
            made = self.resolve(node.func)
            if isinstance(made, Klass):
                return _Instance(made)
            if isinstance(made, _Bound):
                klass = self.index.annotated_class(made.func.module, made.func.node.returns)
                return _Instance(klass) if klass is not None else None
        return None


def _is_super(node: ast.AST) -> bool:
    return isinstance(node, ast.Call) and _dotted(node.func) == "super"


@dataclass
class _Instance:
    klass: Klass


@dataclass
class _Bound:
    func: Function
    skip_first: bool


def _receiver(index: Index, scope: _Scope, call: ast.Call) -> tuple[str, list[str], object]:
    """(callee's name, its parameters as the call fills them, what to visit) or ("", [], None)."""
    target = scope.resolve(call.func)
    if isinstance(target, _Bound):
        a = target.func.node.args
        params = [p.arg for p in (*a.posonlyargs, *a.args)]
        return target.func.name, params[1:] if target.skip_first else params, target.func
    if isinstance(target, Klass):
        init = index.method(target, "__init__")
        if init is not None:
            params = [p.arg for p in (*init.node.args.posonlyargs, *init.node.args.args)]
            return init.name, params[1:], init
        if target.is_record():
            return target.name, target.fields(), target
    return "", [], None


def _keyword_targets(visit: object) -> set[str]:
    if isinstance(visit, Function):
        a = visit.node.args
        return {p.arg for p in (*a.posonlyargs, *a.args, *a.kwonlyargs)}
    return set(visit.fields()) if isinstance(visit, Klass) else set()


def _hold(klass: Klass, attribute: str, seen: set[str], queue: list[tuple[Function, str]]) -> None:
    """An instance of ``klass`` keeps the value in ``attribute``: each of its methods not yet
    visited is, with that attribute as the value."""
    for method in klass.methods.values():
        if method.name not in seen and _mentions(method.node, {attribute}):
            seen.add(method.name)
            queue.append((method, attribute))


def walk(index: Index, start: str, parameter: str) -> Walk:
    """Follow ``parameter`` of ``start`` (``module:function`` or ``module:Class.method``)."""
    module, _, qualname = start.partition(":")
    first = index.lookup(module, qualname.split(".")[0])
    if isinstance(first, Klass) and "." in qualname:
        first = index.method(first, qualname.split(".", 1)[1])
    if not isinstance(first, Function):
        raise LookupError(f"{start}: no such function of the package")
    if parameter not in first.parameters():
        raise LookupError(f"{start} has no parameter {parameter!r}")
    result = Walk(start, parameter)
    seen: set[str] = {first.name}
    queue: list[tuple[Function, str]] = [(first, parameter)]
    while queue:
        func, name = queue.pop(0)
        result.reached.append(func.name)
        value = _aliases(func.node, name)
        scope = _Scope(index, func)
        for call in sorted(
            (n for n in ast.walk(func.node) if isinstance(n, ast.Call)),
            key=lambda n: (n.lineno, n.col_offset),
        ):
            passed = [i for i, a in enumerate(call.args) if _is_value(a, value)]
            passed_by_name = [k.arg for k in call.keywords if k.arg and _is_value(k.value, value)]
            if not passed and not passed_by_name:
                continue
            callee, params, visit = _receiver(index, scope, call)
            if visit is None:
                continue
            targets = [params[i] for i in passed if i < len(params)]
            targets += [k for k in passed_by_name if k in _keyword_targets(visit)]
            if not targets:
                continue
            result.stops.append(
                Stop(func.name, callee, call.lineno, floor(callee) < floor(func.module))
            )
            key = visit.name
            if key in seen:
                continue
            seen.add(key)
            if isinstance(visit, Function):
                queue.append((visit, targets[0]))
            else:
                _hold(visit, f"self.{targets[0]}", seen, queue)
        kept = sorted(v for v in value if v.startswith("self."))
        if func.owner is not None and kept:
            _hold(func.owner, kept[0], seen, queue)
        derived = _derived(func.node, value)
        if any(
            isinstance(n, ast.Return) and n.value is not None and _mentions(n.value, derived)
            for n in _own_body(func.node)
        ):
            result.returns.append(func.name)
    return result


# ---------------------------------------------------------------------------------------------


def measure(root: Path, walks: dict[str, tuple[str, str]] | None = None) -> dict[str, object]:
    """Every figure of the module docstring for the checkout at ``root``."""
    index = Index(root)
    figures = sizes(index)
    figures["walks"] = {}
    for label, (start, parameter) in (WALKS if walks is None else walks).items():
        try:
            figures["walks"][label] = walk(index, start, parameter).summary()
        except LookupError as missing:  # a checkout from before or after this entry
            figures["walks"][label] = {"from": start, "parameter": parameter, "error": str(missing)}
    return figures


def _report(figures: dict[str, object]) -> str:
    lines = []
    for key, value in figures.items():
        if key == "walks":
            for label, w in value.items():
                if "error" in w:
                    lines.append(f"walk ({label}): {w['error']}")
                    continue
                lines.append(
                    f"walk of {w['parameter']!r} from {w['from']} ({label}): {w['stops']} stops, "
                    f"{w['climbs']} climbs, {w['returns']} returns, {w['reached']} functions"
                )
        elif isinstance(value, dict) and key == "most_parameters":
            lines.append("most parameters: " + ", ".join(f"{k} {v}" for k, v in value.items()))
        elif isinstance(value, dict):
            lines.append(f"{key.replace('_', ' ')}: " + ", ".join(f"{v}" for v in value.values()))
        else:
            lines.append(f"{key.replace('_', ' ')}: {value}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        description="Figures of arrange_up's structure (sizes, typing, the walk of one value).",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--root",
        type=Path,
        default=Path(__file__).resolve().parents[1],
        help="the checkout to measure (the folder holding arrange_up/); default: this one",
    )
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    parser.add_argument(
        "--from",
        dest="start",
        metavar="MODULE:FUNCTION",
        help="walk from this function only (e.g. arrange_up.repair.repairer:repair_plan); "
        "default: the plan's, the repair's and the evaluation's entries",
    )
    parser.add_argument(
        "--param", default="problem", help="the parameter whose value is walked (default: problem)"
    )
    parser.add_argument(
        "--stops",
        action="store_true",
        help="also list every stop of the walks (caller, line, callee)",
    )
    args = parser.parse_args(argv)
    walks = {"given": (args.start, args.param)} if args.start else None
    figures = measure(args.root, walks)
    if args.stops:
        index = Index(args.root)
        for label, (start, parameter) in (WALKS if walks is None else walks).items():
            try:
                stops = walk(index, start, parameter).stops
            except LookupError as missing:
                parser.error(str(missing))
            for stop in stops:
                mark = " climb" if stop.climb else ""
                print(f"{label}: {stop.caller}:{stop.line} -> {stop.callee}{mark}")
    print(json.dumps(figures, indent=2) if args.json else _report(figures))


if __name__ == "__main__":
    main()
