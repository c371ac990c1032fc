"""``benchmarks/startup.py`` measures ``arrange-up --help`` of the checkouts it is given, each
importing its own ``arrange_up``, against ``python -c pass``."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_startup_benchmark_reports_a_ratio_per_checkout() -> None:
    run = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "startup.py"), "--repeat", "1", "--json"],
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    figures = json.loads(run.stdout)
    assert list(figures) == [str(ROOT)]
    measured = figures[str(ROOT)]
    assert measured["python -c pass"] > 0 and measured["arrange-up --help"] > 0
    # arrange-up imports click and the package on top of the bare interpreter
    assert measured["ratio"] > 1
