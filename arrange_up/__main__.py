"""``python -m arrange_up`` runs the ``arrange-up`` command."""

from arrange_up.cli.commands import main

main()
