"""The top-level group: commands listed from its table, imported only when they run."""

from __future__ import annotations

import importlib
import subprocess
import sys

import click
import pytest
from click.testing import CliRunner

from arrange_up.cli import COMMANDS, _LazyGroup, main

HEAVY = ("numpy", "shapely", "pymunk", "matplotlib", "unified_planning", "rich", "sklearn")


def real_command(name: str) -> click.Command:
    module, attribute, _ = COMMANDS[name]
    return getattr(importlib.import_module(f"arrange_up.cli.{module}"), attribute)


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_the_table_names_each_command_with_its_own_short_help(name):
    command = real_command(name)
    assert command.name == name
    listed = click.Command(name, help=COMMANDS[name][2])
    for limit in (20, 45, 60, 80, 200):
        assert listed.get_short_help_str(limit) == command.get_short_help_str(limit)


def test_every_command_of_the_command_modules_is_in_the_table():
    defined = set()
    for module in {module for module, _, _ in COMMANDS.values()}:
        name = f"arrange_up.cli.{module}"
        defined |= {
            value
            for value in vars(importlib.import_module(name)).values()
            if isinstance(value, click.Command) and value.callback.__module__ == name
        }
    top_level = {real_command(name) for name in COMMANDS}
    subcommands = {
        sub
        for command in top_level
        if isinstance(command, click.Group)
        for sub in command.commands.values()
    }
    assert defined == top_level | subcommands


@pytest.mark.parametrize("width", [40, 80, 100, 160])
def test_listing_before_and_after_the_commands_are_imported_is_the_same(width):
    fresh = _LazyGroup("arrange-up", help=main.help)
    loaded = click.Group(
        "arrange-up", help=main.help, commands={name: real_command(name) for name in COMMANDS}
    )
    lazy_help = CliRunner().invoke(fresh, ["--help"], terminal_width=width).output
    loaded_help = CliRunner().invoke(loaded, ["--help"], terminal_width=width).output
    assert lazy_help == loaded_help
    assert not fresh.commands  # listing imported nothing


def test_help_imports_neither_the_library_nor_the_command_modules():
    code = (
        "import sys\n"
        "from arrange_up.cli import main\n"
        "try:\n"
        "    main(['--help'])\n"
        "except SystemExit:\n"
        "    pass\n"
        "print(' '.join(sorted(sys.modules)))\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    modules = proc.stdout.split("\n")[-2].split()
    assert "Commands:" in proc.stdout
    assert not [m for m in modules if m.split(".")[0] in HEAVY]
    command_modules = {f"arrange_up.cli.{module}" for module, _, _ in COMMANDS.values()}
    assert not command_modules & set(modules)


def test_a_command_runs_through_the_group():
    result = CliRunner().invoke(main, ["domains"])
    assert result.exit_code == 0 and "blocks-4" in result.output
    assert main.get_command(click.Context(main), "domains") is real_command("domains")


def test_unknown_command_exits_2():
    result = CliRunner().invoke(main, ["no-such-command"])
    assert result.exit_code == 2 and "No such command" in result.output


def test_version():
    result = CliRunner().invoke(main, ["--version"])
    assert result.exit_code == 0 and result.output.startswith("arrange-up, version ")
