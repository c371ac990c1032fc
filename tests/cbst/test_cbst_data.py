"""CBST training data: feature layout, reproducibility, resuming."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from arrange_up.cbst.data import (
    DEFAULT_GENERATION,
    WALL_PUSHES,
    GenerationSettings,
    generate_dataset,
    generate_example,
    load_dataset,
)
from arrange_up.cbst.features import (
    BUCKLE_LIMIT,
    FEATURE_NAMES,
    TARGET_NAMES,
    Domain,
    contact_type,
)

ROLLOUTS = 6  # tiny: these tests check plumbing, not statistics


def test_contact_type_encoding():
    assert [contact_type(p, n) for p in (False, True) for n in (False, True)] == [0, 1, 2, 3]


def test_example_layout_and_targets():
    record = generate_example(3, seed=11, rollouts=ROLLOUTS)
    n = record["blocks"]
    assert 1 <= n <= 3 and record["ok"] + sum(record["failed"].values()) == ROLLOUTS
    X = np.asarray(record["features"])
    y = np.asarray(record["targets"])
    assert X.shape == (n, len(FEATURE_NAMES)) and y.shape == (n, len(TARGET_NAMES))
    # Paddle side first: ct says "previous is the paddle" for row 0 only; the last row's next
    # is the wall (zero half-widths and offset).
    assert X[0, 11] in (0, 1) and np.all(X[1:, 11] >= 2)
    assert X[-1, 11] in (0, 2) and np.all(X[-1, 6:9] == 0) and X[-1, 10] == 0
    # Consecutive rows share beliefs: row j's current block is row j+1's previous one.
    for j in range(n - 1):
        assert np.allclose(X[j, 3:6], X[j + 1, 0:3]) and np.isclose(X[j, 10], -X[j + 1, 9])
    assert Domain().contains(X).all()
    assert np.all(y[:, 1:] >= 0)  # dy, dth, slip are magnitudes
    assert np.all(y[:, 0] > -0.05)  # dx: x_max is the flush position, up to contact slop


def test_quantile_targets_lie_within_the_rollouts_and_outcomes_give_them_back():
    """Targets as a quantile of the rollouts: 1.0 is the maxima (the default, whose settings
    digest is unchanged), a lower quantile never exceeds them, and the recorded outcomes are
    the rollouts the targets were taken over."""
    rollouts = 40
    at_max = generate_example(2, seed=3, rollouts=rollouts, outcomes=True)
    q90 = replace(DEFAULT_GENERATION, quantile=0.9)
    at_q90 = generate_example(2, seed=3, rollouts=rollouts, settings=q90, outcomes=True)
    assert at_max["features"] == at_q90["features"] and at_max["outcomes"] == at_q90["outcomes"]
    assert q90.digest() != DEFAULT_GENERATION.digest()
    for j, each in enumerate(at_max["outcomes"]):
        each = np.asarray(each)
        assert each.shape == (at_max["ok"], 4)
        top, q = np.asarray(at_max["targets"][j]), np.asarray(at_q90["targets"][j])
        assert np.allclose(top[:3], each.max(axis=0)[:3], atol=1e-5)
        assert np.all(q <= top + 1e-12)
        assert np.allclose(q[:3], np.quantile(each, 0.9, axis=0)[:3], atol=1e-5)
    assert "outcomes" not in generate_example(2, seed=3, rollouts=rollouts)
    with pytest.raises(ValueError, match="quantile"):
        replace(DEFAULT_GENERATION, quantile=1.5)


def test_a_domain_wider_than_a_certain_contact_allows_still_draws_examples():
    """Half-widths across the push up to 0.6 in: two neighbours may leave no room for a
    certain contact; the example is still drawn, with the contact certain."""
    wide = replace(DEFAULT_GENERATION, domain=Domain(block_half=(0.6, 0.6, 30.0)))
    for index in range(40):
        record = generate_example(index, seed=0, rollouts=1, settings=wide)
        X = np.asarray(record["features"])
        assert wide.domain.contains(X).all()
        between = X[1:]
        assert np.all(np.abs(between[:, 9]) + between[:, 1] + between[:, 4] <= 0.6 + 1e-9)


def test_example_depends_only_on_seed_and_index():
    a = generate_example(5, seed=2, rollouts=ROLLOUTS)
    b = generate_example(5, seed=2, rollouts=ROLLOUTS)
    c = generate_example(6, seed=2, rollouts=ROLLOUTS)
    for key in ("features", "targets", "overshoot"):
        assert a[key] == b[key]
    assert a["features"] != c["features"]


def test_generation_resumes_and_refuses_other_settings(tmp_path):
    path = tmp_path / "data.jsonl"
    calls = []

    def progress(stage, done, total):
        calls.append((stage, done, total))

    first = generate_dataset(path, examples=3, rollouts=ROLLOUTS, seed=4, progress=progress)
    assert first["computed"] == 3 and calls[-1] == ("data", 3, 3)
    # A torn last line (an interrupted write) is dropped and recomputed.
    with path.open("a") as fh:
        fh.write('{"index": 99, "broken')
    second = generate_dataset(path, examples=5, rollouts=ROLLOUTS, seed=4)
    assert second["computed"] == 2
    third = generate_dataset(path, examples=5, rollouts=ROLLOUTS, seed=4)
    assert third["computed"] == 0
    indices = sorted(json.loads(line)["index"] for line in path.read_text().splitlines())
    assert indices == [0, 1, 2, 3, 4]
    # Resumed data equals data generated in one go (example i depends only on (seed, i)).
    fresh = tmp_path / "fresh.jsonl"
    generate_dataset(fresh, examples=5, rollouts=ROLLOUTS, seed=4, workers=2, chunksize=2)
    a, b = load_dataset(path), load_dataset(fresh)
    assert np.array_equal(a.X, b.X) and np.array_equal(a.y, b.y)
    assert a.examples == 5 and len(a.groups) == len(a.X)
    with pytest.raises(ValueError, match="other parameters"):
        generate_dataset(path, examples=5, rollouts=ROLLOUTS + 1, seed=4)
    with pytest.raises(ValueError, match="other parameters"):
        load_dataset(path, seed=5)
    # A file of another kind is refused and left as it was, though it ends without a newline.
    notes = tmp_path / "notes.jsonl"
    notes.write_text('{"format": "arrange-up-plan/1"}')
    with pytest.raises(ValueError, match="not a CBST data file"):
        generate_dataset(notes, examples=1, rollouts=ROLLOUTS, seed=4)
    assert notes.read_text() == '{"format": "arrange-up-plan/1"}'


def test_wall_push_rules_draw_the_same_scenes_and_planner_pushes_do_not_buckle():
    # The same examples under the three rules differ only in the commanded distance: the
    # features (the beliefs) are the same. A push to the wall presses the compliant train with
    # the force clip and buckles some (a block ends beyond x_max by more than BUCKLE_LIMIT); a
    # push sent just past the compressed train, as CBST's planner sends it, buckles none.
    rules = {rule: replace(DEFAULT_GENERATION, wall_push=rule) for rule in WALL_PUSHES}
    assert DEFAULT_GENERATION.wall_push == "uniform"
    records = {
        rule: [generate_example(i, 0, 20, settings) for i in range(10)]
        for rule, settings in rules.items()
    }
    for rule in WALL_PUSHES:
        assert [r["features"] for r in records[rule]] == [r["features"] for r in records["uniform"]]

    def buckled(rule):
        return sum(o > BUCKLE_LIMIT for r in records[rule] for o in r["overshoot"])

    assert buckled("wall") >= 3
    assert buckled("planner") == 0
    # Settings digests: "uniform" keeps the digest of data made before it was a setting.
    assert len({settings.digest() for settings in rules.values()}) == 3
    with pytest.raises(ValueError, match="wall_push"):
        GenerationSettings(wall_push="elsewhere")
