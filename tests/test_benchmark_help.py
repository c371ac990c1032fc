"""The benchmark scripts teach their options: ``python benchmarks/NAME.py --help`` works and
says what every option does.

Every ``add_argument(...)`` call of every ``benchmarks/*.py`` (read with :mod:`ast`, nothing is
imported) must pass ``help=`` (``argparse.SUPPRESS`` counts: a hidden option says so on
purpose), and every script that builds an ``ArgumentParser`` must print its help and exit 0.
The scripts parse their arguments before doing any work, so ``--help`` costs only their
imports (about a second each); the scripts run side by side.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = sorted((ROOT / "benchmarks").glob("*.py"))
HELP_TIMEOUT = 60.0  # seconds, for all the scripts together (they take about 1 s each)


def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def _calls(tree: ast.AST, name: str) -> list[ast.Call]:
    return [
        node
        for node in ast.walk(tree)
        if isinstance(node, ast.Call)
        and isinstance(node.func, ast.Attribute | ast.Name)
        and getattr(node.func, "attr", getattr(node.func, "id", None)) == name
    ]


def _option(call: ast.Call) -> str:
    """The names the call gives (``--limit-gb``, ``-o/--output``, ``files``), or its line."""
    names = [
        arg.value
        for arg in call.args
        if isinstance(arg, ast.Constant) and isinstance(arg.value, str)
    ]
    return "/".join(names) or f"add_argument at line {call.lineno}"


def _has_parser(path: Path) -> bool:
    return bool(_calls(_tree(path), "ArgumentParser"))


PARSER_SCRIPTS = [path for path in SCRIPTS if _has_parser(path)]


def test_benchmarks_found() -> None:
    assert PARSER_SCRIPTS, "no benchmark script with an ArgumentParser found"


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda path: path.name)
def test_every_option_has_help(path: Path) -> None:
    calls = [
        call for call in _calls(_tree(path), "add_argument") if isinstance(call.func, ast.Attribute)
    ]
    missing = [_option(call) for call in calls if not any(k.arg == "help" for k in call.keywords)]
    assert not missing, (
        f"benchmarks/{path.name}: add_argument without help= for {', '.join(missing)}"
    )


@pytest.fixture(scope="module")
def help_runs() -> dict[str, subprocess.CompletedProcess[str]]:
    """``--help`` of every script with a parser, run side by side: name -> finished process."""
    processes = {
        path.name: subprocess.Popen(
            [sys.executable, str(path.relative_to(ROOT)), "--help"],
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for path in PARSER_SCRIPTS
    }
    runs = {}
    try:
        for name, process in processes.items():
            out, err = process.communicate(timeout=HELP_TIMEOUT)
            runs[name] = subprocess.CompletedProcess(process.args, process.returncode, out, err)
    finally:
        for process in processes.values():
            if process.poll() is None:
                process.kill()
                process.communicate()
    return runs


@pytest.mark.parametrize("path", PARSER_SCRIPTS, ids=lambda path: path.name)
def test_help_exits_zero(
    path: Path, help_runs: dict[str, subprocess.CompletedProcess[str]]
) -> None:
    run = help_runs[path.name]
    assert run.returncode == 0, (
        f"python benchmarks/{path.name} --help exited {run.returncode}:\n{run.stderr}"
    )
    assert "usage:" in run.stdout
    assert "--help" in run.stdout
