"""The example prints its answers only: no credits banner from unified-planning in among them."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_example_prints_no_credits_banner() -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    done = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "plan_with_unified_planning.py"), "blocks-1"],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("blocks-1: SOLVED_SATISFICING"), done.stdout
    assert lines[-1] == "unified-planning's validator: VALID"
    assert "Credits" not in done.stdout and "\x1b[" not in done.stdout
