"""The ``arrange-up`` command: a thin shell over the library.

One module per command group (:mod:`~arrange_up.cli.problems`: domains, check, export;
:mod:`~arrange_up.cli.show`; :mod:`~arrange_up.cli.plan`; :mod:`~arrange_up.cli.evaluate`;
:mod:`~arrange_up.cli.execute`; :mod:`~arrange_up.cli.repair`; :mod:`~arrange_up.cli.train`;
:mod:`~arrange_up.cli.experiments`; :mod:`~arrange_up.cli.bench`; :mod:`~arrange_up.cli.generate`),
and
:mod:`~arrange_up.cli.shared` for what they share. Each command parses its arguments, calls
one library function, renders the result and sets the exit status (0 success, 1 a negative
answer, 2 bad input; see :mod:`~arrange_up.cli.shared`).

This module holds only the top-level group, :func:`main`.
"""

from __future__ import annotations

import importlib
from typing import Any

import click

from arrange_up import __version__

__all__ = ["main"]

# The only lazy imports of the CLI. A command group's module imports the library at module level
# (numpy, shapely, pymunk, matplotlib, rich, ...), which costs many times what this module does
# (the figures and the command that measures them: docs/design/cli.md, "Start-up: one lazy
# place"). So the group imports a command's module only when that command runs, and lists the
# commands with the short help written here (tests/cli/test_lazy_group.py checks it against
# each command's own).
#: command name -> (module in arrange_up.cli, attribute, short help)
COMMANDS: dict[str, tuple[str, str, str]] = {
    "bench": (
        "bench",
        "bench",
        "Measure the speed of the building blocks (figures printed, nothing written).",
    ),
    "check": (
        "problems",
        "check",
        "Validate problem FILES (.yaml, or .pddl of the arrange-up domain).",
    ),
    "domains": (
        "problems",
        "domains",
        "List the shipped problems, usable by name wherever a PROBLEM is asked for.",
    ),
    "evaluate": (
        "evaluate",
        "evaluate",
        "Estimate how reliably PLAN.json achieves PROBLEM's goal, by noisy rollouts.",
    ),
    "execute": (
        "execute",
        "execute",
        "Execute a plan for PROBLEM closed loop: sense, update the belief, replan.",
    ),
    "experiment": (
        "experiments",
        "experiment",
        "Reproduce the thesis's experiments (CSV of every measurement + PNG summary).",
    ),
    "export": (
        "problems",
        "export",
        "Write PROBLEM as a PDDL 2.1 problem of the arrange-up domain (inches, degrees).",
    ),
    "generate": (
        "generate",
        "generate",
        "Write a generated problem file of FAMILY with N parts (the scaling suite).",
    ),
    "plan": ("plan", "plan", "Search belief space for a conformant plan for PROBLEM."),
    "repair": (
        "repair",
        "repair",
        "Make a nominal plan for PROBLEM robust by placing fixtures (thesis ch. 4).",
    ),
    "rescore-cbst": (
        "train",
        "rescore_cbst",
        "Measure a saved CBST MODEL's 8-fold CV and fresh-test scores again.",
    ),
    "show": (
        "show",
        "show",
        "Draw PROBLEM: table, walls, obstacles, parts with their belief shadows, and the goal.",
    ),
    "train-cbst": (
        "train",
        "train_cbst",
        "Generate CBST training data, then tune, evaluate and save its push model (thesis §3.2).",
    ),
}


#: The key of the context's ``meta`` under which the group keeps the arguments it was given.
ARGV_KEY = "arrange_up.argv"


class _LazyGroup(click.Group):
    """A group whose commands are listed from :data:`COMMANDS` and imported when resolved."""

    def make_context(
        self,
        info_name: str | None,
        args: list[str],
        parent: click.Context | None = None,
        **extra: Any,
    ) -> click.Context:
        # the arguments as given, before parsing consumes them: a command that stops early
        # says how to run it again (shared.command_line)
        given = list(args)
        ctx = super().make_context(info_name, args, parent, **extra)
        ctx.meta[ARGV_KEY] = given
        return ctx

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted({*self.commands, *COMMANDS})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in self.commands and cmd_name in COMMANDS:
            module, attribute, _ = COMMANDS[cmd_name]
            command = getattr(importlib.import_module(f"arrange_up.cli.{module}"), attribute)
            self.add_command(command, cmd_name)
        return super().get_command(ctx, cmd_name)

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        # click.Group.format_commands without get_command: a command not imported yet is listed
        # with the short help of COMMANDS, shortened to the width exactly as click shortens.
        names = self.list_commands(ctx)
        limit = formatter.width - 6 - max(len(name) for name in names)
        rows = []
        for name in names:
            command = self.commands.get(name) or click.Command(name, help=COMMANDS[name][2])
            if not command.hidden:
                rows.append((name, command.get_short_help_str(limit)))
        with formatter.section("Commands"):
            formatter.write_dl(rows)


@click.group(
    cls=_LazyGroup,
    context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100},
)
@click.version_option(__version__, prog_name="arrange-up")
def main() -> None:
    """Find conformant plans for robot tabletop manipulation.

    arrange-up plans open-loop sequences of place, push and pick actions that build a goal
    arrangement of parts reliably despite uncertain initial poses, noisy actions and unknown
    friction and density (A. Anders, "Reliably arranging objects", MIT).

    \b
    Start here:
      arrange-up domains                      list the shipped problems
      arrange-up show blocks-4 -o b4.png      draw a problem with its belief shadows and goal
      arrange-up check my-problem.yaml        validate problem files
      arrange-up bench physics                measure simulated pushes per second

    PROBLEM arguments take a path to a .yaml or .pddl file or a shipped domain's name.
    """
