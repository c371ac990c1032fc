"""Tests of the finder of shipped folders (``arrange_up.io.resources``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from arrange_up.io import resources
from arrange_up.io.resources import shipped_dir


def test_the_checkout_holds_the_shipped_folders() -> None:
    for name in ("domains", "semantics", "semantics/cbst"):
        assert shipped_dir(name, name).is_dir()


def test_the_wheel_layout_wins_and_a_missing_folder_names_both_places(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "wheel" / "semantics" / "cbst").mkdir(parents=True)
    (tmp_path / "checkout" / "semantics" / "cbst").mkdir(parents=True)
    monkeypatch.setattr(resources, "WHEEL_DIR", tmp_path / "wheel")
    monkeypatch.setattr(resources, "CHECKOUT_DIR", tmp_path / "checkout")
    assert shipped_dir("semantics/cbst", "models") == tmp_path / "wheel" / "semantics" / "cbst"
    assert shipped_dir("semantics", "semantics") == tmp_path / "wheel" / "semantics"
    (tmp_path / "checkout" / "domains").mkdir()
    assert shipped_dir("domains", "domains") == tmp_path / "checkout" / "domains"
    with pytest.raises(FileNotFoundError) as missing:
        shipped_dir("nothing", "things")
    message = str(missing.value)
    assert message.startswith("arrange-up's shipped things are missing")
    assert str(tmp_path / "wheel" / "nothing") in message
    assert str(tmp_path / "checkout" / "nothing") in message
