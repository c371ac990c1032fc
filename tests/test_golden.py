"""The golden outputs (tests/golden.py) are reproduced bit for bit."""

from __future__ import annotations

import json

import pytest
from golden import CASES, compute, golden_path


@pytest.mark.parametrize("case", list(CASES))
def test_golden_output_is_reproduced(case: str) -> None:
    expected = json.loads(golden_path(case).read_text())
    assert compute(case) == expected, f"regenerate with: python tests/golden.py {case}"
