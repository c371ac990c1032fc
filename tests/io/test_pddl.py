"""Tests of the PDDL front end (``arrange_up.io.pddl``) and the shape catalogue."""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import pytest
from unified_planning.io import PDDLReader

from arrange_up.io.domains import domain_names, domains_dir, load
from arrange_up.io.pddl import (
    PddlExportError,
    domain_path,
    domain_pddl_text,
    load_pddl_problem,
    load_pddl_problem_text,
    write_pddl_problem,
)
from arrange_up.io.shape_catalogue import build_shape, load_catalogue
from arrange_up.model.errors import ProblemFormatError
from arrange_up.model.problem import (
    SERVO_CONTROLLER,
    ObjectKind,
    ObjectSpec,
    PlanningHints,
    problem_hash,
)
from arrange_up.model.units import Units
from arrange_up.up.compile import from_up

SHIPPED_PDDL = sorted(p.stem for p in domains_dir().glob("*.pddl"))
SMALL = ("blocks-1", "blocks-2", "down-push")


def _expressible(name: str) -> bool:
    try:
        write_pddl_problem(load(name))
    except PddlExportError:
        return False
    return True


def test_the_shipped_domain_is_generated_from_the_catalogue():
    assert domain_path().read_text(encoding="utf-8") == domain_pddl_text()


def test_every_shipped_domain_that_pddl_can_express_ships_as_pddl():
    expressible = [name for name in domain_names() if _expressible(name)]
    assert expressible  # every shipped problem uses catalogue shapes
    assert sorted(expressible) == [n for n in SHIPPED_PDDL if n in expressible]
    assert set(SHIPPED_PDDL) >= set(expressible)


@pytest.mark.parametrize("name", SHIPPED_PDDL)
def test_pddlreader_parses_every_shipped_pddl_unchanged(name):
    up = PDDLReader().parse_problem(str(domain_path()), str(domains_dir() / f"{name}.pddl"))
    assert up.name == name.lower()
    assert {a.name for a in up.actions} == {"place", "push", "pick"}


@pytest.mark.parametrize("name", SHIPPED_PDDL)
def test_yaml_and_pddl_give_the_same_problem(name):
    from_yaml = load(name)
    path = domains_dir() / f"{name}.pddl"
    from_pddl = load_pddl_problem(path)
    assert problem_hash(from_pddl) == problem_hash(from_yaml)
    assert from_pddl.description == " ".join(from_yaml.description.split())
    assert from_pddl.source == str(path)
    # the shipped file is what the writer writes today
    assert path.read_text(encoding="utf-8") == write_pddl_problem(from_yaml)


@pytest.mark.parametrize("name", [n for n in SMALL if n in SHIPPED_PDDL])
def test_yaml_and_pddl_give_the_same_deterministic_plan(name):
    from arrange_up.planning.planner import plan

    from_yaml = plan(load(name), semantics="deterministic", seed=0)
    from_pddl = plan(
        load_pddl_problem(domains_dir() / f"{name}.pddl"), semantics="deterministic", seed=0
    )
    assert from_yaml.solved
    assert from_pddl.actions == from_yaml.actions


def test_names_keep_their_written_case():
    problem = load_pddl_problem(domains_dir() / "blocks-2.pddl")
    assert [o.name for o in problem.objects] == ["A", "B", "paddle"]
    # UP's reader lowercases; from_up of its problem keeps UP's names
    up = PDDLReader().parse_problem(str(domain_path()), str(domains_dir() / "blocks-2.pddl"))
    assert [o.name for o in from_up(up).objects] == ["a", "b", "paddle"]


def test_written_pddl_uses_inches_degrees_and_plain_decimals():
    text = write_pddl_problem(load("tt-mating"))
    assert "(= (theta T2) 180)" in text
    assert "(>= (rel-theta T2 T1) 170) (<= (rel-theta T2 T1) 190)" in text
    assert "(= (part-density-min) 0.1)" in text
    assert not re.search(r"\d[eE][-+]?\d", text)  # no exponents: PDDL has none


def test_export_refuses_what_pddl_cannot_express():
    problem = load("blocks-1")
    odd = build_shape("box", [1.3, 0.7], "odd")
    refused = dataclasses.replace(
        problem,
        objects=(ObjectSpec("A", ObjectKind.PART, odd), *problem.objects[1:]),
        planning=PlanningHints(push_distances=(1.0,)),
    )
    with pytest.raises(PddlExportError) as caught:
        write_pddl_problem(refused)
    message = str(caught.value)
    assert "'blocks-1' cannot be written as PDDL" in message
    assert (
        "object 'A': its shape (box 1.3 x 0.7 in) is not a part shape of the catalogue" in message
    )
    assert "planning.push_distances" in message
    assert len(caught.value.reasons) == 2
    # A PDDL problem is driven by the default controller: a servo problem cannot be written.
    with pytest.raises(PddlExportError, match="controller: kind servo"):
        write_pddl_problem(dataclasses.replace(problem, controller=SERVO_CONTROLLER))


def test_an_export_refusal_gives_sizes_in_the_files_unit_and_the_catalogues():
    problem = load("blocks-1")
    post = build_shape("box", [0.5, 0.25], "post")
    millimetres = dataclasses.replace(
        problem,
        units=Units("mm", "deg"),
        objects=(
            *problem.objects,
            ObjectSpec("post", ObjectKind.OBSTACLE, post, (5.0, 2.5, 0.0)),
        ),
    )
    with pytest.raises(PddlExportError) as caught:
        write_pddl_problem(millimetres)
    assert (
        "object 'post': its shape (box 12.7 x 6.35 mm = 0.5 x 0.25 in) is not an obstacle "
        "shape of the catalogue"
    ) in str(caught.value)


def test_export_refuses_names_pddl_cannot_carry():
    problem = load("blocks-2")
    a, b, paddle = problem.objects
    renamed = dataclasses.replace(
        problem,
        name="two blocks",
        objects=(dataclasses.replace(a, name="theta"), dataclasses.replace(b, name="_b"), paddle),
    )
    with pytest.raises(PddlExportError) as caught:
        write_pddl_problem(renamed)
    reasons = " | ".join(caught.value.reasons)
    assert "'two blocks' is not a PDDL name" in reasons
    assert "object 'theta': the name is taken by the PDDL vocabulary" in reasons
    assert "object '_b': not a PDDL name" in reasons


def test_load_reports_an_unknown_type_with_its_position():
    text = (domains_dir() / "blocks-1.pddl").read_text().replace("A - block-1x1", "A - blok")
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(text, "b1.pddl")
    (diagnostic,) = caught.value.diagnostics
    assert diagnostic.file == "b1.pddl"
    assert diagnostic.line is not None and diagnostic.column is not None
    assert "unknown name 'blok'" in diagnostic.message
    assert "block-1x1" in diagnostic.message


def test_load_reports_syntax_errors_with_line_and_column():
    text = (domains_dir() / "blocks-1.pddl").read_text().replace("(= (table-width) 10)", "(= (")
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(text, "b1.pddl")
    (diagnostic,) = caught.value.diagnostics
    assert diagnostic.line is not None
    assert str(diagnostic).startswith(f"b1.pddl:{diagnostic.line}:")


def test_load_reports_vocabulary_errors_together():
    text = (domains_dir() / "blocks-2.pddl").read_text()
    text = text.replace("(= (table-width) 10) ", "")
    text = text.replace("(<= (x B) 8.7)", "(<= (x B) 8.9)")  # B's x half-width 0.3, A's 0.2
    text = text.replace("(= (friction-max) 0.55)", "")
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(text, "b2.pddl")
    messages = [d.message for d in caught.value.errors]
    assert any("missing (table-width)" in m for m in messages)
    assert any("one tolerance for every goal part" in m for m in messages)
    assert any("only one of (friction-min) and (friction-max)" in m for m in messages)
    assert all(d.file == "b2.pddl" for d in caught.value.diagnostics)


def test_load_refuses_a_goal_without_both_bounds_and_a_missing_pose():
    text = (domains_dir() / "down-push.pddl").read_text()
    text = text.replace("(<= (y block) 3.5)", "").replace("(= (x block) 6) ", "")
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(text, "dp.pddl")
    messages = " | ".join(d.message for d in caught.value.errors)
    assert "(y block) has no (<= ...) bound" in messages
    assert "block is on the table but has no (x block)" in messages


def test_the_goal_states_that_a_fixture_off_the_table_must_end_off_it():
    # down-push's bar starts off the table: the format's rule (it must end off it) is stated
    text = write_pddl_problem(load("down-push"))
    assert "(not (on-table bar))" in text.split("(:goal")[1]
    up = PDDLReader().parse_problem(str(domain_path()), str(domains_dir() / "down-push.pddl"))
    assert "(not on-table(bar))" in str(up.goals)
    assert load_pddl_problem(domains_dir() / "down-push.pddl").put_away == ("bar",)
    # a file without it (written before the rule was stated) reads as before: the rule holds
    old = text.replace("(not (on-table bar))", "")
    assert problem_hash(load_pddl_problem_text(old, "dp.pddl")) == problem_hash(load("down-push"))
    # a fixture that starts on the table may stay: the goal is refused, not tightened
    on = text.replace(
        "(on-table block) (= (x block) 6)",
        "(on-table bar) (= (x bar) 1) (= (y bar) 1)\n    (on-table block) (= (x block) 6)",
    )
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(on, "dp.pddl")
    (error,) = caught.value.errors
    assert "bar is a fixture that starts on the table (it may stay)" in error.message
    assert error.line == on.splitlines().index("    (not (on-table bar))") + 1


def test_the_goal_refuses_what_contradicts_the_put_away_rule():
    text = write_pddl_problem(load("down-push"))
    part = text.replace("(not (on-table bar))", "(not (on-table block))")
    with pytest.raises(ProblemFormatError, match=r"block is a part; a goal can require off"):
        load_pddl_problem_text(part, "dp.pddl")
    kept = text.replace("(not (on-table bar))", "(on-table bar)")
    with pytest.raises(ProblemFormatError, match=r"\(on-table bar\): bar is a fixture that starts"):
        load_pddl_problem_text(kept, "dp.pddl")
    # one error for the one condition (not also "a goal places parts only")
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(kept, "dp.pddl")
    assert len(caught.value.errors) == 1


def test_an_on_table_goal_without_a_pose_is_refused_not_dropped():
    # Dropped, B's (on-table B) left a goal of A alone, and a plan that never placed B was
    # reported solved; a manipulator's, a goal no push keeps (the paddle is lifted off).
    text = (domains_dir() / "blocks-2.pddl").read_text()
    bare = re.sub(r"\(>= \(\w+ B\) [^)]*\)+ \(<= \(\w+ B\) [^)]*\)+\n", "", text)
    assert "(x B)" not in bare.split("(:goal")[1] and "(on-table B)" in bare
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(bare, "b2.pddl")
    (error,) = caught.value.errors
    assert error.message.startswith("(on-table B): B is a part without goal intervals")
    assert error.line == bare.splitlines().index("    (on-table B)") + 1
    paddle = text.replace("    (on-table B)\n", "    (on-table B)\n    (on-table paddle)\n")
    with pytest.raises(ProblemFormatError, match=r"\(on-table paddle\): paddle is a manipulator"):
        load_pddl_problem_text(paddle, "b2.pddl")
    # restating a goal part's place on the table is kept, as the shipped files do
    assert load_pddl_problem_text(text, "b2.pddl").goal.parts == ("A", "B")


def test_a_refused_density_bound_is_the_one_error():
    # both bounds are given; the one refused is not also reported as missing
    text = (domains_dir() / "blocks-2.pddl").read_text()
    zero = re.sub(r"\(= \(part-density-min\) [\d.]+\)", "(= (part-density-min) 0)", text)
    assert zero != text
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(zero, "b2.pddl")
    (error,) = caught.value.errors
    assert error.message == "(part-density-min) is 0; expected a value > 0 (a density)"


def test_load_refuses_another_domain_and_a_missing_file(tmp_path: Path):
    text = (
        (domains_dir() / "blocks-1.pddl")
        .read_text()
        .replace("(:domain arrange-up)", "(:domain blocksworld)")
    )
    with pytest.raises(ProblemFormatError, match="expected 'arrange-up'"):
        load_pddl_problem_text(text, "b1.pddl")
    with pytest.raises(ProblemFormatError, match="no such file"):
        load_pddl_problem(tmp_path / "missing.pddl")


def test_catalogue_shapes_match_the_shipped_yaml_shapes():
    catalogue = load_catalogue()
    assert catalogue.entry("BLOCK-1X1") is catalogue.entry("block-1x1")
    tee = load("tt-mating").object("T1").shape
    assert catalogue.entry("tee").shape == tee
    assert catalogue.match(ObjectKind.PART, tee).type_name == "tee"
    assert catalogue.match(ObjectKind.FIXTURE, tee) is None
    for entry in catalogue.entries:
        assert entry.type_name.lower() not in {"block", "paddle", "bar"}  # shipped object names


def test_obstacles_round_trip():
    problem = load("blocks-1")
    pillar = ObjectSpec(
        "post", ObjectKind.OBSTACLE, build_shape("box", [0.5, 0.5], "post"), (5.0, 2.5, 0.0)
    )
    with_post = dataclasses.replace(problem, objects=(*problem.objects, pillar))
    text = write_pddl_problem(with_post)
    assert "post - pillar" in text and "(= (x post) 5)" in text
    assert problem_hash(load_pddl_problem_text(text)) == problem_hash(with_post)


def test_a_malformed_catalogue_is_refused(tmp_path: Path):
    from arrange_up.io.shape_catalogue import CatalogueError

    bad = tmp_path / "shapes.yaml"
    bad.write_text("format: arrange-up-shapes/1\ntypes:\n  blob: {kind: part, box: [1, -1]}\n")
    with pytest.raises(CatalogueError, match=r"types\.blob\.box: box size must be positive"):
        load_catalogue(bad)


def test_the_pddl_reader_warns_as_the_yaml_reader_does():
    # warnings do not refuse a file; a command that loads it prints them (check_pddl_problem)
    from arrange_up.io.pddl_reader import check_pddl_problem_text

    text = (
        (domains_dir() / "blocks-1.pddl")
        .read_text()
        .replace("(= (friction-max) 0.55)", "(= (friction-max) 1000000)")
        .replace("(>= (x A) 9.3) (<= (x A) 9.7)", "(>= (x A) 9.5) (<= (x A) 9.9)")
    )
    problem, diagnostics = check_pddl_problem_text(text, "b1.pddl")
    assert problem is not None
    warnings = [str(d) for d in diagnostics]
    assert len(warnings) == 2 and all(": warning: " in w for w in warnings)
    assert "b1.pddl:27:32:" in warnings[0] and "(friction-max) is 1000000" in warnings[0]
    assert "b1.pddl:31:" in warnings[1] and "at its goal pose A spans x 9.2..10.2" in warnings[1]


# -- numbers: standard PDDL writes a negative number as (- 15) --------------------------------
EXPRESSIBLE = [name for name in domain_names() if _expressible(name)]


def _signed_literals(text: str) -> str:
    """``text`` with ``(- 15)`` written the non-standard way, ``-15`` (files written before)."""
    return re.sub(r"\(- ([0-9.]+)\)", r"-\1", text)


@pytest.mark.parametrize("name", EXPRESSIBLE)
def test_a_second_pddl_parser_reads_every_export(name, tmp_path: Path):
    strict = pytest.importorskip("pddl")
    domain = strict.parse_domain(domain_path())
    assert domain.name == "arrange-up"
    exported = tmp_path / f"{name}.pddl"
    exported.write_text(write_pddl_problem(load(name)), encoding="utf-8")
    for path in (exported, *(domains_dir() / f"{n}.pddl" for n in SHIPPED_PDDL if n == name)):
        parsed = strict.parse_problem(path)
        assert parsed.name == name
        assert {str(o.name) for o in parsed.objects} == {s.name for s in load(name).objects}


def test_negative_numbers_are_written_as_standard_pddl():
    text = write_pddl_problem(load("tz-mating"))
    assert "(>= (rel-y Z T) (- 0.6)) (<= (rel-y Z T) (- 0.2))" in text
    code = re.sub(r";[^\n]*", "", text)
    assert not re.search(r"(?<![(\w])-\d", code)  # no signed literal outside comments


@pytest.mark.parametrize("name", EXPRESSIBLE)
def test_both_forms_of_a_negative_number_load_the_same_problem(name):
    text = write_pddl_problem(load(name))
    written = load_pddl_problem_text(text, "new.pddl")
    before = load_pddl_problem_text(_signed_literals(text), "old.pddl")
    assert problem_hash(written) == problem_hash(before) == problem_hash(load(name))


def test_a_negative_initial_angle_and_goal_bound_in_standard_form_load():
    text = write_pddl_problem(load("tz-mating")).replace(
        "(= (theta Z) 90)", "(= (theta Z) (- 270))"
    )
    problem = load_pddl_problem_text(text, "tz.pddl")
    (z,) = (entry for entry in problem.initial if entry.name == "Z")
    assert z.pose[2] == pytest.approx(math.radians(-270))
    assert dict(problem.goal.targets)["Z"][1] == pytest.approx(-0.4)


def test_a_non_numeric_initial_value_is_refused_with_its_place():
    text = (
        (domains_dir() / "blocks-1.pddl")
        .read_text()
        .replace("(= (table-width) 10)", "(= (table-width) (* (table-depth) 2))")
    )
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(text, "b1.pddl")
    message = str(caught.value)
    assert "b1.pddl:" in message and "expected a number" in message


def _edited_blocks_1(old: str, new: str) -> str:
    text = (domains_dir() / "blocks-1.pddl").read_text()
    assert old in text
    return text.replace(old, new)


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        # a name nothing declares, in the file's spelling (the reader lower-cases it)
        (
            "(on-table A)",
            "(on-table Cube)",
            "unknown name or value 'Cube': expected a number, or an object declared under :objects",
        ),
        ("(= (table-width) 10)", "(= (table-width) ten)", "unknown name or value 'ten'"),
        (
            "(on-table A)",
            "(on-table A) (> (mass A) 1)",
            "cannot read '(mass A)': expected a function of the arrange-up domain",
        ),
        ("A - ", "A a - ", "the name 'a' is defined twice (PDDL names ignore case"),
    ],
    ids=["unknown object", "word for a number", "unknown function", "names differing in case"],
)
def test_what_unified_plannings_reader_refuses_is_said_in_the_files_words(old, new, expected):
    text = _edited_blocks_1(old, new)
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(text, "b1.pddl")
    [diagnostic] = caught.value.diagnostics
    assert expected in diagnostic.message and "unified-planning" not in diagnostic.message
    assert diagnostic.line is not None and diagnostic.column is not None
    written = text.splitlines()[diagnostic.line - 1][diagnostic.column - 1 :]
    assert written.lower().startswith(expected.split("'")[1].lower())


def test_a_problem_without_a_goal_is_refused_at_its_define():
    text = (domains_dir() / "blocks-1.pddl").read_text()
    goal = text.index("(:goal")
    text = text[:goal] + ")\n"  # the goal section and what follows cut off
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(text, "b1.pddl")
    [diagnostic] = caught.value.diagnostics
    assert "missing (:goal ...)" in diagnostic.message and diagnostic.line is not None


# -- what unified-planning's PDDLWriter writes ---------------------------------------------
@pytest.mark.parametrize("name", SHIPPED_PDDL)
def test_pddl_written_by_unified_planning_is_read(name, tmp_path: Path):
    from unified_planning.io import PDDLWriter

    up = PDDLReader().parse_problem(str(domain_path()), str(domains_dir() / f"{name}.pddl"))
    path = tmp_path / "written.pddl"
    path.write_text(PDDLWriter(up).get_problem(), encoding="utf-8")
    problem = load_pddl_problem(path)
    assert problem.name == name  # not PDDLWriter's NAME-problem
    assert problem_hash(problem) == problem_hash(from_up(up))
    assert load(str(path)).name == name


def test_pddl_written_from_the_to_up_model_is_refused_with_what_to_do(tmp_path: Path):
    from unified_planning.io import PDDLWriter

    from arrange_up.up.compile import to_up

    path = tmp_path / "written.pddl"
    path.write_text(PDDLWriter(to_up(load("blocks-1"))).get_problem(), encoding="utf-8")
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem(path)
    message = str(caught.value)
    assert str(path) in message and "write_pddl_problem" in message
