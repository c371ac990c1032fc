"""Former home of every command; they now live in one module per command group (see
:mod:`arrange_up.cli`). Kept so ``from arrange_up.cli.commands import main`` keeps working."""

from arrange_up.cli import main

__all__ = ["main"]
