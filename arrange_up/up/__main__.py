"""``python -m arrange_up.up``: make arrange-up's engines visible to programs that never import
``arrange_up``, above all unified-planning's ``up`` command.

    python -m arrange_up.up              # print the up.ini sections naming the engines
    python -m arrange_up.up --install    # add them to this environment's up.ini

unified-planning 1.3 has no entry points; a program that does not import ``arrange_up`` finds
its engines only in a configuration file (:func:`arrange_up.up.registration.up_ini`). ``up`` is
a script in the environment's ``bin`` directory (``Scripts`` on Windows), and unified-planning
reads ``up.ini`` from every parent directory of the running script, so ``--install`` writes
``<sys.prefix>/up.ini``: seen by that environment's ``up`` command and by scripts inside the
environment, by nothing else. (A ``~/.up.ini`` would be read by every program of the user,
and break unified-planning in every environment without arrange-up.)
"""

from __future__ import annotations

import argparse
import configparser
import sys
from pathlib import Path

from arrange_up.up.registration import ENGINES, up_ini


def install(path: Path) -> bool:
    """Add the engines' sections to the configuration file ``path`` (created if missing);
    False when it already names every engine where it is defined (nothing is written).

    A file that names some of the engines, or names one with a module or class that does not
    define it (one written before the engines moved), is not edited: ``SystemExit`` says what
    to change by hand."""
    present = configparser.ConfigParser()
    if path.exists():
        present.read(path, encoding="utf-8")
    missing = [name for name, _, _ in ENGINES if not present.has_section(f"engine {name}")]
    if not missing:
        stale = [
            name
            for name, module_name, class_name in ENGINES
            if present.get(f"engine {name}", "module_name", fallback=None) != module_name
            or present.get(f"engine {name}", "class_name", fallback=None) != class_name
        ]
        if stale:
            raise SystemExit(
                f"{path} names {', '.join(stale)} with another module or class than the one "
                "defining it: edit it by hand (python -m arrange_up.up prints the sections)"
            )
        return False
    if len(missing) < len(ENGINES):
        raise SystemExit(
            f"{path} names some of arrange-up's engines but not {', '.join(missing)}: edit it by "
            "hand (python -m arrange_up.up prints the sections)"
        )
    text = path.read_text(encoding="utf-8") if path.exists() else ""
    separator = (
        "" if not text or text.endswith("\n\n") else ("\n" if text.endswith("\n") else "\n\n")
    )
    path.write_text(text + separator + up_ini(), encoding="utf-8")
    return True


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m arrange_up.up",
        description="Print (or install) the unified-planning configuration that names "
        "arrange-up's engines, for programs that never import arrange_up (the up command).",
    )
    parser.add_argument(
        "--install",
        action="store_true",
        help=f"add the sections to {Path(sys.prefix) / 'up.ini'}, read by this environment's "
        "up command",
    )
    args = parser.parse_args(argv)
    if not args.install:
        sys.stdout.write(up_ini())
        return 0
    path = Path(sys.prefix) / "up.ini"
    if install(path):
        print(f"added arrange-up's engines to {path}")
    else:
        print(f"{path} already names arrange-up's engines")
    return 0


if __name__ == "__main__":
    sys.exit(main())
