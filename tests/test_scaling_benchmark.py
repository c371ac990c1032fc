"""benchmarks/scaling.py: a tiny sweep writes its rows, resumes without redoing them, and fits
and plots CPU seconds against N (its ``--help`` is tested with every benchmark's)."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "benchmarks" / "scaling.py"


def _run(tmp_path: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    command = [
        sys.executable,
        str(SCRIPT),
        "--parts",
        "2,3",
        "--families",
        "row",
        "--semantics",
        "deterministic",
        "--rollouts",
        "5",
        "--timeout",
        "60",
        "--output",
        str(tmp_path / "scaling.csv"),
        *extra,
    ]
    return subprocess.run(command, capture_output=True, text=True, cwd=tmp_path, timeout=300)


def test_a_tiny_sweep_writes_rows_fits_plots_and_resumes(tmp_path: Path) -> None:
    first = _run(tmp_path, "--png", str(tmp_path / "scaling.png"))
    assert first.returncode == 0, first.stderr
    with (tmp_path / "scaling.csv").open(newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert [(r["family"], r["parts"], r["semantics"]) for r in rows] == [
        ("row", "2", "deterministic"),
        ("row", "3", "deterministic"),
    ]
    for row in rows:
        assert row["status"] == "solved"
        assert int(row["expanded"]) > 0 and int(row["simulations"]) > 0
        assert float(row["cpu_s"]) >= 0 and float(row["peak_mb"]) > 0
        assert row["rollouts"] == "5" and 0 <= int(row["successes"]) <= 5
    assert "row        deterministic k = " in first.stdout
    assert (tmp_path / "scaling.png").read_bytes()[:4] == b"\x89PNG"

    again = _run(tmp_path)
    assert again.returncode == 0, again.stderr
    with (tmp_path / "scaling.csv").open(newline="", encoding="utf-8") as handle:
        assert len(list(csv.DictReader(handle))) == 2  # nothing run twice
    assert "k = " in again.stdout


def test_an_unknown_family_is_refused(tmp_path: Path) -> None:
    result = _run(tmp_path, "--families", "spiral")
    assert result.returncode == 2 and "spiral" in result.stderr
    assert not (tmp_path / "scaling.csv").exists()
