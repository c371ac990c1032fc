"""The ``arrange-up`` command."""

from arrange_up.cli.commands import main

__all__ = ["main"]
