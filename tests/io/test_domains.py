"""Tests of the shipped problems (``domains/*.yaml``) and of finding them by name."""

from __future__ import annotations

import math
import shutil
import tomllib
from pathlib import Path

import pytest
import shapely

from arrange_up.geometry import shapes as geometry
from arrange_up.io import domains, resources
from arrange_up.io.domains import (
    DomainInfo,
    UnknownDomainError,
    domain_names,
    domains_dir,
    first_sentence,
    list_domains,
    load,
    resolve_problem,
)
from arrange_up.io.yaml_problem import load_problem
from arrange_up.model.problem import WALL_EDGES, ArrangementProblem

BLOCKS = {
    "blocks-1": 1,
    "blocks-2": 2,
    "blocks-3": 3,
    "blocks-4": 4,
    "blocks-7": 7,
    "blocks-9": 9,
    "blocks-9-square": 9,
}
REARRANGEMENT = ("down-push", "create-a-t", "tz-mating", "tt-mating", "tt-mating-noisy")
EXPECTED = (*BLOCKS, *REARRANGEMENT)
RELATIVE = ("create-a-t", "tz-mating", "tt-mating", "tt-mating-noisy")
MATING = ("tz-mating", "tt-mating", "tt-mating-noisy")

# Thesis Table 4.2, in the thesis's units: initial pose uncertainty (in, deg), action
# uncertainty (in, deg), friction range, part density range, manipulator density range.
TABLE_4_2 = {
    "create-a-t": ((0.35, 5), (0.05, 5), (0.5, 0.6), (0.1, 0.15), (0.35, 0.45)),
    "tz-mating": ((0.05, 1), (0.05, 3), (0.5, 0.6), (0.1, 0.15), (0.35, 0.45)),
    "tt-mating": ((0.5, 5), (0.05, 3), (0.5, 0.6), (0.1, 0.15), (0.35, 0.45)),
    "tt-mating-noisy": ((0.5, 5), (0.05, 3), (0.5, 0.6), (0.01, 1.0), (0.1, 1.0)),
    "down-push": ((1.0, 15), (0.2, 1), (0.5, 0.6), (0.1, 0.15), (0.55, 0.6)),
}


def _half(inches: float, degrees: float) -> tuple[float, float, float]:
    return (inches, inches, math.radians(degrees))


@pytest.fixture(scope="module")
def problems() -> dict[str, ArrangementProblem]:
    return {name: load_problem(domains_dir() / f"{name}.yaml") for name in EXPECTED}


# -- the shipped set ---------------------------------------------------------------------------


def test_domains_dir_exists_and_holds_the_problems() -> None:
    directory = domains_dir()
    assert directory.is_dir()
    assert (directory / "blocks-4.yaml").is_file()


def test_expected_names_are_all_shipped() -> None:
    assert set(EXPECTED) <= set(domain_names())


@pytest.mark.parametrize("name", domain_names())
def test_every_shipped_domain_loads(name: str) -> None:
    path = resolve_problem(name)
    problem = load_problem(path)
    assert problem.name == name == path.stem
    assert problem.description, "every shipped problem says what it models"
    assert "thesis" in problem.description
    assert problem.parts and problem.manipulators


def test_list_domains_reports_each_problem(problems: dict[str, ArrangementProblem]) -> None:
    infos = {info.name: info for info in list_domains()}
    assert set(EXPECTED) <= set(infos)
    for name, problem in problems.items():
        info = infos[name]
        assert isinstance(info, DomainInfo)
        assert info.path == resolve_problem(name)
        assert info.parts == len(problem.parts)
        assert info.goal_kind == ("relative" if problem.goal.is_relative else "absolute")
        assert info.summary == first_sentence(problem.description)
        assert info.summary.endswith(".") and "\n" not in info.summary
        assert len(info.summary) < 100


def test_first_sentence_keeps_abbreviations() -> None:
    assert first_sentence("From ch. 3 of the thesis.  Then more. ") == "From ch. 3 of the thesis."
    assert first_sentence("  no full stop\n here ") == "no full stop here"
    assert first_sentence("") == ""


# -- block-world construction (thesis ch. 3) ---------------------------------------------------


@pytest.mark.parametrize("name", BLOCKS)
def test_block_world_setup(name: str, problems: dict[str, ArrangementProblem]) -> None:
    problem = problems[name]
    n = BLOCKS[name]
    assert problem.table.size == (10.0, 5.0)
    assert set(problem.table.walls) == set(WALL_EDGES)
    assert [p.name for p in problem.parts] == list("ABCDEFGHI"[:n])
    for part in problem.parts:
        assert part.shape.box == (1.0, 1.0)
    (paddle,) = problem.manipulators
    assert paddle.name == "paddle" and paddle.shape.box == (2.5, 0.15)
    assert problem.fixtures == () and problem.obstacles == ()
    assert problem.initial == (), "blocks start off the table"
    u = problem.uncertainty
    assert u.place == pytest.approx(_half(0.2, 15))
    assert u.push == pytest.approx(_half(0.05, 3))
    assert u.friction == pytest.approx((0.25, 0.55))
    assert u.part_density == pytest.approx((0.1, 0.15))
    assert u.manipulator_density == pytest.approx((0.35, 0.45))
    assert not problem.goal.is_relative
    assert problem.goal.tolerance == pytest.approx(_half(0.2, 15))
    assert set(problem.goal.parts) == {p.name for p in problem.parts}


@pytest.mark.parametrize("name", BLOCKS)
def test_block_goals_are_flush_in_the_lower_right_corner(
    name: str, problems: dict[str, ArrangementProblem]
) -> None:
    """Every block is square to the board, and has the right wall or a block flush on its right
    and the bottom wall or a block flush below: pushes right and down can make it certain."""
    problem = problems[name]
    cells = {name: problem.goal.target(name) for name in problem.goal.parts}
    centres = {(round(x, 9), round(y, 9)) for x, y, _ in cells.values()}
    assert len(centres) == len(cells)
    assert (9.5, 0.5) in centres, "one block sits in the corner"
    for x, y, theta in cells.values():
        assert theta == 0.0
        assert 0.5 <= x <= 9.5 and 0.5 <= y <= 4.5
        assert x == 9.5 or (round(x + 1, 9), y) in centres
        assert y == 0.5 or (x, round(y - 1, 9)) in centres
    union = shapely.union_all(
        [geometry.footprint(problem.object(n).shape.parts, pose) for n, pose in cells.items()]
    )
    assert union.geom_type == "Polygon" and union.area == pytest.approx(len(cells))


def test_blocks_4_is_the_format_example(problems: dict[str, ArrangementProblem]) -> None:
    goal = problems["blocks-4"].goal
    assert goal.target("A") == pytest.approx((9.5, 0.5, 0.0))
    assert goal.target("B") == pytest.approx((8.5, 0.5, 0.0))
    assert {(x, y) for x, y, _ in (goal.target(p) for p in "ABCD")} == {
        (9.5, 0.5),
        (8.5, 0.5),
        (9.5, 1.5),
        (8.5, 1.5),
    }


def test_block_shapes_of_the_larger_goals(problems: dict[str, ArrangementProblem]) -> None:
    rows7 = sorted(round(pose[1], 9) for _, pose in problems["blocks-7"].goal.targets)
    assert rows7.count(0.5) == 4 and rows7.count(1.5) == 3  # a staircase
    rows9 = sorted(round(pose[1], 9) for _, pose in problems["blocks-9"].goal.targets)
    assert rows9.count(0.5) == 6 and rows9.count(1.5) == 3  # a longer staircase
    assert problems["blocks-9"].planning.max_nodes == 10000
    xs9 = {round(pose[0], 9) for _, pose in problems["blocks-9-square"].goal.targets}
    ys9 = {round(pose[1], 9) for _, pose in problems["blocks-9-square"].goal.targets}
    assert xs9 == {7.5, 8.5, 9.5} and ys9 == {0.5, 1.5, 2.5}  # a 3x3 square


# -- rearrangement problems (thesis ch. 4) -----------------------------------------------------


@pytest.mark.parametrize("name", REARRANGEMENT)
def test_table_4_2_parameters(name: str, problems: dict[str, ArrangementProblem]) -> None:
    problem = problems[name]
    initial, action, friction, part_density, manipulator_density = TABLE_4_2[name]
    assert {e.name for e in problem.initial} >= {p.name for p in problem.parts}
    for part in problem.parts:
        entry = problem.initial_of(part.name)
        assert entry is not None
        assert entry.uncertainty == pytest.approx(_half(*initial))
    u = problem.uncertainty
    assert u.push == pytest.approx(_half(*action))
    assert u.place == pytest.approx(_half(*action))
    assert u.friction == pytest.approx(friction)
    assert u.part_density == pytest.approx(part_density)
    assert u.manipulator_density == pytest.approx(manipulator_density)


@pytest.mark.parametrize("name", REARRANGEMENT)
def test_rearrangement_workspace(name: str, problems: dict[str, ArrangementProblem]) -> None:
    problem = problems[name]
    assert problem.table.walls == (), "chapter 4's parts can be pushed off the table"
    assert len(problem.fixtures) == 1 and len(problem.manipulators) == 1
    assert problem.goal.is_relative == (name in RELATIVE)
    width, depth = problem.table.size
    hulls = []
    for entry in problem.initial:
        shape = problem.object(entry.name).shape
        xmin, ymin, xmax, ymax = geometry.shadow_box(shape.parts, entry.pose, entry.uncertainty)
        assert 0 <= xmin and xmax <= width and 0 <= ymin and ymax <= depth
        hulls.append(geometry.shadow_hull(shape.parts, entry.pose, entry.uncertainty))
    for i, a in enumerate(hulls):
        for b in hulls[i + 1 :]:
            assert a.intersection(b).area == pytest.approx(0.0, abs=1e-9)


def test_down_push_goal_is_straight_below(problems: dict[str, ArrangementProblem]) -> None:
    problem = problems["down-push"]
    (part,) = problem.parts
    start = problem.initial_of(part.name)
    assert start is not None
    x, y, theta = problem.goal.target(part.name)
    width, depth = problem.table.size
    assert x == pytest.approx(start.pose[0]) and theta == pytest.approx(start.pose[2])
    assert y < start.pose[1] - 1.0
    assert start.pose == pytest.approx((width / 2, depth / 2, 0.0))


def test_paddle_lengths_follow_the_thesis(problems: dict[str, ArrangementProblem]) -> None:
    def length(name: str) -> float:
        (paddle,) = problems[name].manipulators
        assert paddle.shape.box is not None
        return max(paddle.shape.box)

    assert length("tt-mating") > length("tz-mating") > length("down-push")  # long > medium


def test_noisy_tt_mating_differs_only_in_densities(
    problems: dict[str, ArrangementProblem],
) -> None:
    plain, noisy = problems["tt-mating"], problems["tt-mating-noisy"]
    assert (plain.table, plain.objects, plain.initial, plain.goal) == (
        noisy.table,
        noisy.objects,
        noisy.initial,
        noisy.goal,
    )
    assert plain.uncertainty.place == noisy.uncertainty.place
    assert plain.uncertainty.push == noisy.uncertainty.push
    assert plain.uncertainty.friction == noisy.uncertainty.friction


@pytest.mark.parametrize("name", RELATIVE)
def test_relative_goal_parts_touch_without_overlapping(
    name: str, problems: dict[str, ArrangementProblem]
) -> None:
    problem = problems[name]
    reference = problem.goal.reference
    assert reference is not None
    ref = geometry.footprint(problem.object(reference).shape.parts, (0.0, 0.0, 0.0))
    for part, relative in problem.goal.targets:
        other = geometry.footprint(problem.object(part).shape.parts, relative)
        assert ref.intersection(other).area < 1e-9
        assert ref.distance(other) < 1e-6
        # they share edges (at least an inch of them), not a corner
        contact = ref.buffer(1e-6).intersection(other).area / 1e-6
        assert contact > 1.0


@pytest.mark.parametrize("name", MATING)
def test_mating_parts_are_non_convex_and_interlock(
    name: str, problems: dict[str, ArrangementProblem]
) -> None:
    """Each mated part reaches into the other's convex hull: they interlock, not just abut."""
    problem = problems[name]
    reference = problem.goal.reference
    assert reference is not None
    ref = geometry.footprint(problem.object(reference).shape.parts, (0.0, 0.0, 0.0))
    ((part, relative),) = problem.goal.targets
    other = geometry.footprint(problem.object(part).shape.parts, relative)
    for shape in (ref, other):
        assert shape.convex_hull.area > shape.area + 0.5
    assert other.intersection(ref.convex_hull).area > 0.4
    assert ref.intersection(other.convex_hull).area > 0.4
    # touching along 4 inches of edge
    assert ref.buffer(1e-6).intersection(other).area / 1e-6 == pytest.approx(4.0, rel=1e-3)


# -- resolving names -----------------------------------------------------------------------------


def test_resolve_name_with_and_without_extension() -> None:
    path = resolve_problem("blocks-4")
    assert path == domains_dir() / "blocks-4.yaml"
    assert resolve_problem("blocks-4.yaml") == path
    assert resolve_problem(path) == path
    assert resolve_problem(str(path)) == path


def test_an_existing_path_wins(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    own = tmp_path / "blocks-4.yaml"
    shutil.copy(domains_dir() / "blocks-2.yaml", own)
    monkeypatch.chdir(tmp_path)
    assert resolve_problem("blocks-4.yaml") == Path("blocks-4.yaml")
    assert resolve_problem("blocks-4") == domains_dir() / "blocks-4.yaml"  # not a file here
    elsewhere = tmp_path / "mine.yaml"
    shutil.copy(own, elsewhere)
    assert resolve_problem(str(elsewhere)) == elsewhere


def test_unknown_name_suggests_close_matches() -> None:
    with pytest.raises(UnknownDomainError) as info:
        resolve_problem("tz-mateing")
    error = info.value
    assert isinstance(error, LookupError)
    assert error.suggestions[0] == "tz-mating"
    assert "did you mean" in str(error) and "'tz-mating'" in str(error)
    assert "blocks-4" in str(error)  # the shipped names are listed
    with pytest.raises(UnknownDomainError, match="blocks-4"):
        resolve_problem("blcks-4")


def test_unknown_path_is_reported_as_a_missing_file() -> None:
    with pytest.raises(UnknownDomainError, match="no such problem file") as info:
        resolve_problem("nowhere/blocks-4.yaml")
    assert info.value.suggestions == ("blocks-4",)
    with pytest.raises(UnknownDomainError, match="directory"):
        resolve_problem(str(domains_dir()))


def test_suffix_selects_among_files_of_one_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for file in ("a.yaml", "a.pddl", "b.pddl"):
        (tmp_path / file).write_text("")
    monkeypatch.setattr(domains, "domains_dir", lambda: tmp_path)
    monkeypatch.chdir(tmp_path.parent)
    assert resolve_problem("a") == tmp_path / "a.yaml"
    assert resolve_problem("a.pddl") == tmp_path / "a.pddl"
    assert resolve_problem("b") == tmp_path / "b.pddl"
    assert domain_names() == ["a", "b"]
    with pytest.raises(UnknownDomainError):
        resolve_problem("b.yaml")


def test_wheel_layout_is_preferred(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    shipped = tmp_path / "_shipped" / "domains"
    shipped.mkdir(parents=True)
    shutil.copy(domains_dir() / "blocks-1.yaml", shipped / "blocks-1.yaml")
    monkeypatch.setattr(resources, "WHEEL_DIR", tmp_path / "_shipped")
    assert domains_dir() == shipped
    assert domain_names() == ["blocks-1"]
    monkeypatch.setattr(resources, "CHECKOUT_DIR", tmp_path / "missing")
    monkeypatch.setattr(resources, "WHEEL_DIR", tmp_path / "missing-too")
    with pytest.raises(FileNotFoundError):
        domains_dir()


def test_wheel_mapping_matches_pyproject() -> None:
    # The tests live in the checkout even when the package under test is an installed wheel.
    pyproject = Path(__file__).resolve().parents[2] / "pyproject.toml"
    config = tomllib.loads(pyproject.read_text())
    force = config["tool"]["hatch"]["build"]["targets"]["wheel"]["force-include"]
    package = Path(domains.__file__).resolve().parents[1]
    for name in ("domains", "semantics"):
        assert package.parent / force[name] == resources.WHEEL_DIR / name


def test_load_by_name_and_by_path() -> None:
    by_name = load("blocks-4")
    assert by_name.name == "blocks-4" and by_name.source == "domain:blocks-4"
    path = domains_dir() / "blocks-4.yaml"
    by_path = load(str(path))
    assert by_path.source != "domain:blocks-4"
    assert by_path.goal == by_name.goal
    with pytest.raises(UnknownDomainError):
        load("no-such-problem")
