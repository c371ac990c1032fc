"""``arrange-up show --plan --animate``: the animation of a plan, its options and refusals, and
which prediction a plan file's shadows are drawn from."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from matplotlib import animation as mpl_animation
from PIL import Image

from arrange_up.cli import main
from arrange_up.cli.show import _prediction


def run(*args: str):
    return CliRunner().invoke(main, list(args), catch_exceptions=False)


def plan_file(tmp_path):
    path = tmp_path / "b1.json"
    result = run("plan", "blocks-1", "--semantics", "deterministic", "-o", str(path))
    assert result.exit_code == 0, result.output
    return path, len(json.loads(path.read_text())["actions"])


def test_show_animate_writes_a_gif_of_the_plan_and_the_storyboard_too(tmp_path):
    plan, actions = plan_file(tmp_path)
    gif, png = tmp_path / "b1.gif", tmp_path / "b1.png"
    result = run(
        "show", "blocks-1", "--plan", str(plan), "--animate", str(gif), "-o", str(png),
        "--rollouts", "2", "--frames-per-action", "2", "--fps", "3", "--dpi", "30",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert f"wrote {png}" in result.stdout and f"wrote {gif}" in result.stdout
    with Image.open(gif) as image:
        durations = []
        for k in range(image.n_frames):
            image.seek(k)
            durations.append(image.info["duration"])
    # The start held 4 frames, 2 per action, the end held 3 more, at 3 frames per second
    # (the GIF writer merges identical frames into one shown as long; GIF times are in
    # hundredths of a second).
    assert sum(durations) == pytest.approx((4 + 2 * actions + 3) * 1000 / 3, abs=60)
    assert len(durations) < 4 + 2 * actions + 3
    assert png.stat().st_size > 0


def test_show_animate_refusals_exit_2_naming_the_problem(tmp_path, monkeypatch):
    plan, _ = plan_file(tmp_path)
    result = run("show", "blocks-1", "--animate", str(tmp_path / "a.gif"))
    assert result.exit_code == 2 and "--animate needs --plan" in result.stderr
    # rollouts are drawn on a plan: without one, asking for them is refused, not ignored
    result = run("show", "blocks-1", "--rollouts", "20", "-o", str(tmp_path / "p.png"))
    assert result.exit_code == 2 and "--rollouts needs --plan" in result.stderr
    assert not (tmp_path / "p.png").exists()
    assert run("show", "blocks-1", "-o", str(tmp_path / "p.png")).exit_code == 0
    result = run("show", "blocks-1", "--plan", str(plan), "--animate", str(tmp_path / "a.avi"))
    assert result.exit_code == 2 and "unknown animation format '.avi'" in result.stderr
    monkeypatch.setattr(mpl_animation.writers, "is_available", lambda name: name != "ffmpeg")
    result = run("show", "blocks-1", "--plan", str(plan), "--animate", str(tmp_path / "a.mp4"))
    assert result.exit_code == 2
    assert "writing .mp4 needs the ffmpeg program on the PATH" in result.stderr
    assert not (tmp_path / "a.mp4").exists()
    result = run("show", "blocks-1")
    assert result.exit_code == 2 and "expected --output" in result.stderr


def test_a_repaired_plan_is_replayed_with_the_repairs_particles_and_says_so():
    repaired = {"semantics": "fixtures", "particles": 40, "seed": 3}
    assert _prediction(repaired) == {
        "semantics": "particles",
        "particles": 40,
        "plan_seed": 3,
        "plan_semantics": "fixtures",
    }
    own = {"semantics": "particles", "particles": 25, "seed": 1}
    assert _prediction(own) == {"semantics": "particles", "particles": 25, "plan_seed": 1}
    unknown = {"semantics": "no-such-semantics", "particles": 9, "seed": 0}
    assert _prediction(unknown)["semantics"] == "deterministic"
    assert _prediction(unknown)["plan_semantics"] == "no-such-semantics"
