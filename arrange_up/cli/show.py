"""The ``show`` command: a problem, a plan's storyboard or animation, or a fixture-placement
heat map."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import click
from rich.progress import BarColumn, MofNCompleteColumn, TextColumn

from arrange_up.cli.shared import (
    FiniteFloat,
    OutputFile,
    fail,
    library_default,
    load_problem,
    read_plan_file,
    seed_option,
    terminal_progress,
)
from arrange_up.figures.animation import WriterUnavailableError, animate_plan, check_writer
from arrange_up.figures.backend import FIGURE_SUFFIXES
from arrange_up.figures.render import draw_problem, write_heatmap
from arrange_up.figures.storyboard import draw_storyboard
from arrange_up.parallel import available_cores
from arrange_up.repair import step_scores
from arrange_up.repair.records import REPAIR_SEMANTICS
from arrange_up.transitions import available


@click.command()
@click.argument("problem")
@click.option(
    "--output",
    "-o",
    type=OutputFile(FIGURE_SUFFIXES),
    default=None,
    help="Where to write the picture (.png, .svg or .pdf); with --plan, the storyboard. "
    "Required unless --plan is given with --animate.",
)
@click.option(
    "--dpi",
    type=click.IntRange(30, 600),
    default=library_default(draw_problem, "dpi"),
    show_default=True,
    help="Resolution of a .png picture, in dots per inch.",
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
    help="Noisy rollouts overlaid in grey on the storyboard and the animation.",
)
@click.option(
    "--animate",
    "animation_file",
    type=click.Path(dir_okay=False, writable=True),
    default=None,
    metavar="OUT.gif|OUT.mp4",
    help="With --plan: write an animation of the plan's execution (.gif; .mp4 needs ffmpeg).",
)
@click.option(
    "--fps",
    type=FiniteFloat(0.1, 60),
    default=library_default(animate_plan, "fps"),
    show_default=True,
    help="Frames per second of the animation.",
)
@click.option(
    "--frames-per-action",
    type=click.IntRange(1, 120),
    default=library_default(animate_plan, "frames_per_action"),
    show_default=True,
    help="Animation frames per action (interpolated between the states before and after it).",
)
@seed_option("Seed of the storyboard's rollouts (as in `evaluate`).")
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
    output: str | None,
    dpi: int,
    plan_file: str | None,
    rollouts: int,
    animation_file: str | None,
    fps: float,
    frames_per_action: int,
    seed: int,
    heatmap_step: int | None,
) -> None:
    """Draw PROBLEM: table, walls, obstacles, parts with their belief shadows, and the goal.

    With --plan, draw the plan's storyboard instead (thesis Figure 3-11): one panel per action
    with the action, the nominal poses, the poses of --rollouts noisy rollouts in grey and the
    belief shadows the planner predicted.

    With --plan and --animate OUT.gif, write an animation of the plan's execution: the
    nominal poses, the predicted belief shadows, the goal and the --rollouts noisy rollouts
    moving together, action by action (--frames-per-action frames each, interpolated between
    the states before and after the action), at --fps frames per second. With -o as well,
    the storyboard is written too.

    For a repaired plan (semantics 'fixtures') the shadows are the plan replayed in the
    particle semantics with the repair's particle count and seed.

    With --plan and --heatmap STEP, draw instead the score of every candidate fixture
    placement for that step of the plan (thesis Figure 4-11), invalid ones marked.

    \b
    Examples:
      arrange-up show blocks-4 -o blocks-4.png
      arrange-up show blocks-4 --plan blocks-4.plan.json --rollouts 100 -o story.png
      arrange-up show blocks-2 --plan blocks-2.plan.json --animate run.gif --rollouts 20
      arrange-up show tz-mating --plan tz.json --heatmap 1 -o heat.png
    """
    loaded = load_problem(problem)
    if heatmap_step is not None and plan_file is None:
        fail("--heatmap needs --plan")
    given = click.get_current_context().get_parameter_source("rollouts")
    if plan_file is None and given is click.core.ParameterSource.COMMANDLINE:
        fail("--rollouts needs --plan: the rollouts are drawn on a plan's storyboard")
    if animation_file is not None:
        if plan_file is None:
            fail("--animate needs --plan")
        if heatmap_step is not None:
            fail("--animate and --heatmap do not go together")
        try:
            check_writer(Path(animation_file))
        except WriterUnavailableError as error:
            fail(f"--animate: {error}")
    elif output is None:
        fail("expected --output (or --plan with --animate)")
    if plan_file is None:
        assert output is not None  # refused above: no plan, so no --animate either
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
        if output is None:
            fail("--heatmap needs --output")
        path = write_heatmap(loaded, scores, Path(output), dpi=dpi)
        click.echo(f"wrote {path}")
        return
    prediction = _prediction(document)
    if output is not None:
        with _rollout_progress(rollouts, "storyboard") as progress:
            path = draw_storyboard(
                loaded,
                actions,
                Path(output),
                rollouts=rollouts,
                seed=seed,
                dpi=min(dpi, 150),
                progress=progress,
                **prediction,
            )
        click.echo(f"wrote {path}")
    if animation_file is not None:
        with _rollout_progress(rollouts, "animation") as progress:
            path = animate_plan(
                loaded,
                actions,
                Path(animation_file),
                rollouts=rollouts,
                seed=seed,
                fps=fps,
                frames_per_action=frames_per_action,
                dpi=dpi if _given("dpi") else library_default(animate_plan, "dpi"),
                progress=progress,
                **prediction,
            )
        click.echo(f"wrote {path}")


def _given(option: str) -> bool:
    """Whether ``option`` was given on the command line (not left to its default)."""
    source = click.get_current_context().get_parameter_source(option)
    return source is click.core.ParameterSource.COMMANDLINE


def _prediction(document: dict[str, Any]) -> dict[str, Any]:
    """How to predict a plan file's shadows: its own semantics, particles and seed; a repaired
    plan's in the particle semantics with the repair's particles and seed; a plan of a
    semantics not installed here in the deterministic one. ``plan_semantics`` names the
    file's semantics when the prediction uses another, so the title says so."""
    recorded = str(document.get("semantics"))
    seed = int(document.get("seed") or 0)
    particles = int(document.get("particles") or 1)
    if recorded in available():
        return {"semantics": recorded, "particles": particles, "plan_seed": seed}
    if recorded == REPAIR_SEMANTICS:
        semantics = "particles"
    else:
        semantics, particles = "deterministic", 1
    return {
        "semantics": semantics,
        "particles": particles,
        "plan_seed": seed,
        "plan_semantics": recorded,
    }


@contextmanager
def _rollout_progress(rollouts: int, what: str) -> Iterator[Callable[[int, int], None] | None]:
    """A live count of the rollouts computed on a terminal (the CLI's progress display)."""
    with terminal_progress(
        TextColumn(f"{what}: rollouts"), BarColumn(), MofNCompleteColumn()
    ) as display:
        if display is None or rollouts == 0:
            yield None
            return
        task = display.add_task(what, total=rollouts)
        yield lambda done, _total: display.update(task, completed=done)
