"""``python -m arrange_up`` runs the ``arrange-up`` command."""

from arrange_up.cli import main

main()
