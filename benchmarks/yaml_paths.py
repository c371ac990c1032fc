"""The cost of one YAML reading path: ``arrange-up check`` on the adversarial files of
``benchmarks/big_inputs.py --files``, read the current way and by ruamel alone.

    python benchmarks/yaml_paths.py                          # every kind of file, one round
    python benchmarks/yaml_paths.py --rounds 3               # three rounds, each path's best
    python benchmarks/yaml_paths.py --kinds objects-8500 merges-8500 --timeout 300

The two paths, each ``arrange-up check FILE`` in a fresh child process:

- ``libyaml``: the package as shipped (:func:`arrange_up.io.yaml_tree.read`: libyaml's events,
  ruamel for the documents libyaml does not take and to word syntax errors);
- ``ruamel``: the same command with ``yaml_tree.CParser`` set to ``None`` before it runs, the
  package's own reading when PyYAML has no libyaml: ruamel's round-trip loader for every file,
  which is what one reading path without the second parser would be.

For each file the two paths run one after the other, the first path alternating from file to
file and round to round so that a change of the machine's load falls on both. A child is
stopped after ``--timeout`` seconds (``+`` after its figures) and its address space limited to
``--limit-gb``. Printed per file: its size; per path the exit status, CPU seconds (user +
system of the child itself, from ``os.wait4``) and peak resident memory (``ru_maxrss``), the
least over the rounds; the ratios ruamel / libyaml; and what the check said: ``passed`` (exit
0) or ``refused at LINE:COL`` (exit 2, its first error written ``FILE:LINE:COL: error:``), once
when both paths said the same, else each path's.
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from big_inputs import KINDS, run_child  # noqa: E402

PATHS = {
    "libyaml": ("-m", "arrange_up"),
    "ruamel": (
        "-c",
        "from arrange_up.io import yaml_tree\n"
        "yaml_tree.CParser = None\n"
        "from arrange_up.cli import main\n"
        "main()",
    ),
}


def _contract(status: str, lines: list[str], path: Path) -> str:
    """``passed`` (exit 0), ``refused at L:C`` (exit 2, the first error at ``FILE:LINE:COL``)
    or what the check did instead."""
    if status.startswith("exit 0"):
        return "passed"
    errors = [re.match(rf"{re.escape(str(path))}:(\d+):(\d+): error", line) for line in lines]
    found = [m for m in errors if m is not None]
    if status.startswith("exit 2") and found:
        return f"refused at {found[0][1]}:{found[0][2]}"
    return status[:60]


def compare(kinds: list[str], rounds: int, timeout: float, limit: int) -> None:
    names = list(PATHS)
    print(
        f"{'file':<20} {'kB':>5}  {'libyaml CPU s':>13} {'MB':>5}  "
        f"{'ruamel CPU s':>12} {'MB':>5}  {'CPU x':>6} {'MB x':>5}  check",
        flush=True,
    )
    total = dict.fromkeys(names, 0.0)
    with tempfile.TemporaryDirectory() as tmp:
        for number, name in enumerate(kinds):
            text = KINDS[name]()
            path = Path(tmp) / f"{name}.yaml"
            path.write_text(text, encoding="utf-8")
            best: dict[str, tuple[float, float, str, bool]] = {}
            for round_ in range(rounds):
                order = names if (number + round_) % 2 == 0 else names[::-1]
                for reading in order:
                    lines: list[str] = []
                    status, _, peak, cpu = run_child(
                        ["check", str(path)], timeout, limit, entry=PATHS[reading], output=lines
                    )
                    stopped = status.startswith("stopped")
                    old = best.get(reading)
                    if old is None or cpu < old[0]:
                        best[reading] = (cpu, peak, _contract(status, lines, path), stopped)
            fast, slow = best["libyaml"], best["ruamel"]
            for reading in names:
                total[reading] += best[reading][0]
            same = fast[2] == slow[2]
            print(
                f"{name:<20} {len(text.encode()) / 1000:5.0f}  "
                f"{fast[0]:12.2f}{'+' if fast[3] else ' '} {fast[1]:5.0f}  "
                f"{slow[0]:11.2f}{'+' if slow[3] else ' '} {slow[1]:5.0f}  "
                f"{slow[0] / fast[0]:6.1f} {slow[1] / fast[1]:5.2f}  "
                + (fast[2] if same else f"libyaml: {fast[2]}; ruamel: {slow[2]}"),
                flush=True,
            )
    print(
        f"{'all':<20} {'':>5}  {total['libyaml']:12.2f}  {'':>5}  "
        f"{total['ruamel']:11.2f}  {'':>5}  {total['ruamel'] / total['libyaml']:6.1f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--kinds",
        nargs="+",
        choices=sorted(KINDS),
        default=list(KINDS),
        metavar="KIND",
        help="check only these kinds of file, from: " + ", ".join(sorted(KINDS)),
    )
    parser.add_argument(
        "--rounds", type=int, default=1, help="runs of each path per file (default: 1)"
    )
    parser.add_argument(
        "--timeout",
        type=float,
        default=120.0,
        help="seconds after which a child is stopped (default: %(default)s)",
    )
    parser.add_argument(
        "--limit-gb",
        type=float,
        default=4.0,
        help="address-space limit of each child, in GiB (default: %(default)s)",
    )
    options = parser.parse_args()
    compare(options.kinds, options.rounds, options.timeout, int(options.limit_gb * 2**30))


if __name__ == "__main__":
    main()
