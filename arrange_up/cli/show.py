"""The ``show`` command: a problem, a plan's storyboard or a fixture-placement heat map."""

from __future__ import annotations

from pathlib import Path

import click

from arrange_up.cli.shared import (
    SEED,
    OutputFile,
    fail,
    library_default,
    load_problem,
    read_plan_file,
)
from arrange_up.figures.backend import FIGURE_SUFFIXES
from arrange_up.figures.render import draw_problem, write_heatmap
from arrange_up.figures.storyboard import draw_storyboard
from arrange_up.parallel import available_cores
from arrange_up.repair.fixture_repair import step_scores
from arrange_up.transitions import available


@click.command()
@click.argument("problem")
@click.option(
    "--output",
    "-o",
    type=OutputFile(FIGURE_SUFFIXES),
    required=True,
    help="Where to write the picture (.png, .svg or .pdf).",
)
@click.option(
    "--dpi",
    type=click.IntRange(30, 600),
    default=library_default(draw_problem, "dpi"),
    show_default=True,
)
@click.option(
    "--plan",
    "plan_file",
    type=click.Path(dir_okay=False),
    default=None,
    help="Draw a storyboard of this plan file: one panel per action.",
)
@click.option(
    "--rollouts",
    type=click.IntRange(0, 10_000),
    default=library_default(draw_storyboard, "rollouts"),
    show_default=True,
    help="Noisy rollouts overlaid in grey on the storyboard.",
)
@click.option(
    "--seed",
    type=SEED,
    default=0,
    show_default=True,
    help="Seed of the storyboard's rollouts (as in `evaluate`).",
)
@click.option(
    "--heatmap",
    "heatmap_step",
    type=click.IntRange(1, None),
    default=None,
    metavar="STEP",
    help="With --plan: draw the fixture-placement scores of nominal step STEP "
    "(thesis Figure 4-11); for a repaired plan, the repair's step number.",
)
def show(
    problem: str,
    output: str,
    dpi: int,
    plan_file: str | None,
    rollouts: int,
    seed: int,
    heatmap_step: int | None,
) -> None:
    """Draw PROBLEM: table, walls, obstacles, parts with their belief shadows, and the goal.

    With --plan, draw the plan's storyboard instead (thesis Figure 3-11): one panel per action
    with the action, the nominal poses, the poses of --rollouts noisy rollouts in grey and the
    belief shadows the planner predicted.

    With --plan and --heatmap STEP, draw instead the score of every candidate fixture
    placement for that step of the plan (thesis Figure 4-11), invalid ones marked.

    \b
    Examples:
      arrange-up show blocks-4 -o blocks-4.png
      arrange-up show blocks-4 --plan blocks-4.plan.json --rollouts 100 -o story.png
      arrange-up show tz-mating --plan tz.json --heatmap 1 -o heat.png
    """
    loaded = load_problem(problem)
    if heatmap_step is not None and plan_file is None:
        fail("--heatmap needs --plan")
    if plan_file is None:
        path = draw_problem(loaded, Path(output), dpi=dpi)
        click.echo(f"wrote {path}")
        return
    actions, document = read_plan_file(loaded, plan_file, warn_mismatch=True)
    if heatmap_step is not None:
        try:
            scores = step_scores(
                loaded, actions, heatmap_step, document=document, workers=available_cores()
            )
        except ValueError as error:
            fail(f"--heatmap: {error}")
        path = write_heatmap(loaded, scores, Path(output), dpi=dpi)
        click.echo(f"wrote {path}")
        return
    semantics = document.get("semantics")
    if semantics not in available():
        semantics = "deterministic"  # e.g. repaired plans: show the nominal prediction
    path = draw_storyboard(
        loaded,
        actions,
        Path(output),
        rollouts=rollouts,
        seed=seed,
        semantics=semantics,
        particles=int(document.get("particles") or 1),
        plan_seed=int(document.get("seed") or 0),
        dpi=min(dpi, 150),
    )
    click.echo(f"wrote {path}")
