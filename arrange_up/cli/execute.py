"""The ``execute`` command: closed-loop execution with sensing, belief update and replanning,
on the simulated executor (:mod:`arrange_up.execution`)."""

from __future__ import annotations

from typing import Any

import click
from rich.progress import BarColumn, MofNCompleteColumn, TextColumn

from arrange_up.cli.evaluate import _failure_lines
from arrange_up.cli.shared import (
    EXIT_NEGATIVE,
    FiniteFloat,
    OutputFile,
    check_semantics,
    echo_json,
    fail,
    json_option,
    landing_option,
    load_problem,
    quiet_option,
    read_plan_file,
    seed_option,
    terminal_progress,
)
from arrange_up.evaluation.evaluate import MAX_ROLLOUTS
from arrange_up.evaluation.records import RecordFileError, plan_hash
from arrange_up.execution.episodes import EpisodeRecord, run_episode, run_episodes
from arrange_up.execution.observations import SENSES
from arrange_up.execution.replanning import ClosedLoopSettings
from arrange_up.model.problem import problem_hash
from arrange_up.planning.planner import plan as run_plan

_DEFAULTS = ClosedLoopSettings()


@click.command()
@click.argument("problem")
@click.argument("plan_file", metavar="[PLAN.json]", required=False, type=click.Path(dir_okay=False))
@click.option(
    "--sense",
    type=click.Choice(SENSES),
    default="paddle",
    show_default=True,
    help="What is observed after each action: the paddle's final pose after a push (joint "
    "encoders), every part's pose (a camera), or nothing.",
)
@click.option(
    "--episodes",
    type=click.IntRange(1, MAX_ROLLOUTS),
    default=20,
    show_default=True,
    help="Episodes (at most 1,000,000).",
)
@seed_option("Episode i's world and the loop's draws derive from (seed, i).")
@click.option(
    "--replan-budget",
    type=FiniteFloat(0, None, min_open=True),
    default=_DEFAULTS.budget,
    show_default=True,
    help="Seconds one replan may take.",
)
@click.option(
    "--semantics",
    default=_DEFAULTS.semantics,
    show_default=True,
    help="Semantics of replanning (and of the first plan when no PLAN is given).",
)
@click.option(
    "--particles",
    type=click.IntRange(1, 100_000),
    default=_DEFAULTS.particles,
    show_default=True,
    help="Particles of a replan's start belief (particles semantics).",
)
@click.option(
    "--max-nodes",
    type=click.IntRange(1, None),
    default=_DEFAULTS.max_nodes,
    show_default=True,
    help="Node limit of one replan.",
)
@click.option(
    "--max-replans",
    type=click.IntRange(0, None),
    default=_DEFAULTS.max_replans,
    show_default=True,
    help="Replans per episode (0: execute the plan open loop, still sensing).",
)
@click.option(
    "--filter-particles",
    type=click.IntRange(1, 100_000),
    default=_DEFAULTS.filter_particles,
    show_default=True,
    help="Particles of the belief conditioned on the observations.",
)
@click.option(
    "--threshold",
    type=FiniteFloat(0, 1),
    default=_DEFAULTS.threshold,
    show_default=True,
    help="Replan when the rest of the plan's estimated success falls below this.",
)
@click.option(
    "--noise-scale",
    type=FiniteFloat(0, None, min_open=True),
    default=1.0,
    show_default=True,
    help="The simulated world's noise, as a multiple of the problem's modelled noise.",
)
@landing_option(", in the world and in the belief alike")
@click.option(
    "--record",
    type=OutputFile(),
    default=None,
    help="Append every episode to this .jsonl file as it finishes; re-running with the same "
    "file resumes the run.",
)
@click.option(
    "--storyboard",
    type=OutputFile((".png", ".svg", ".pdf")),
    default=None,
    help="Also draw episode --storyboard-episode: per action the true world, the observation "
    "and the posterior (PNG, SVG or PDF).",
)
@click.option(
    "--storyboard-episode",
    type=click.IntRange(0, None),
    default=0,
    show_default=True,
    help="The episode --storyboard draws (run again, traced: the same episode).",
)
@json_option("Print a machine-readable summary (JSON) on stdout.")
@quiet_option()
def execute(
    problem: str,
    plan_file: str | None,
    sense: str,
    episodes: int,
    seed: int,
    replan_budget: float,
    semantics: str,
    particles: int,
    max_nodes: int,
    max_replans: int,
    filter_particles: int,
    threshold: float,
    noise_scale: float,
    landing: str,
    record: str | None,
    storyboard: str | None,
    storyboard_episode: int,
    as_json: bool,
    quiet: bool,
) -> None:
    """Execute a plan for PROBLEM closed loop: sense, update the belief, replan.

    Each episode draws a world (initial poses, every action's noise, scaled by --noise-scale),
    executes the plan one action at a time in the physics, conditions a particle belief on
    what --sense observes (a belief that cannot explain an observation is reported as a model
    failure), estimates the rest of the plan's success under the posterior and replans from
    the posterior when it falls below --threshold. Without PLAN.json, the first plan is made
    with --semantics. Prints the success rate with its 95% Wilson interval, replans per
    episode, planning time per replan and the failures by kind.

    \b
    Examples:
      arrange-up execute blocks-2 --episodes 5
      arrange-up execute tz-mating --semantics deterministic --sense paddle --episodes 20
      arrange-up execute blocks-4 b4.json --noise-scale 2 --record b4.episodes.jsonl --json
      arrange-up execute tz-mating --semantics deterministic --storyboard tz-episode.png

    Exit status: 0 the episodes ran (whatever the rate), 1 no first plan was found or
    interrupted, 2 bad input.
    """
    check_semantics(semantics)
    if storyboard is not None and storyboard_episode >= episodes:
        fail(
            f"--storyboard-episode {storyboard_episode}: expected one of the episodes run, "
            f"0 to {episodes - 1} (--episodes {episodes})"
        )
    loaded = load_problem(problem)
    if plan_file is not None:
        actions, _ = read_plan_file(loaded, plan_file, warn_mismatch=True)
    else:
        with terminal_progress(
            TextColumn("{task.description}"), what="execute", quiet=quiet
        ) as display:
            if display is not None:
                display.add_task(f"planning the first plan ({semantics})")
            first = run_plan(loaded, semantics=semantics, particles=particles, seed=seed)
        if not first.solved:
            fail(f"no first plan: {first.reason}", EXIT_NEGATIVE)
        actions = first.actions or ()
    settings = ClosedLoopSettings(
        filter_particles=filter_particles,
        threshold=threshold,
        semantics=semantics,
        particles=particles,
        max_nodes=max_nodes,
        budget=replan_budget,
        max_replans=max_replans,
        landing=landing,
    )

    finished: list[EpisodeRecord] = []
    read_back: set[int] = set()
    episodes_display: Any = None  # the progress display, while the episodes run
    episodes_task: Any = None

    def resume(numbers: tuple[int, ...]) -> None:
        read_back.update(numbers)
        if not as_json and not quiet:
            many = "episode" if len(numbers) == 1 else "episodes"
            click.echo(f"  resumed {len(numbers)} {many} from {record}", err=True)

    def report(episode: EpisodeRecord) -> None:
        finished.append(episode)
        if episodes_display is not None and episodes_task is not None:
            episodes_display.update(episodes_task, completed=len(finished))
        if not as_json and not quiet and episode.episode not in read_back:
            outcome = "ok" if episode.success else str(episode.failure.kind)  # type: ignore[union-attr]
            click.echo(
                f"  episode {episode.episode}: {outcome}, {episode.actions} actions, "
                f"{len(episode.replans)} replans, {len(episode.model_failures)} model failures",
                err=True,
            )

    episodes_columns = (TextColumn("episodes"), BarColumn(), MofNCompleteColumn())
    try:
        with terminal_progress(*episodes_columns, what="execute", quiet=quiet) as episodes_display:
            episodes_task = (
                None
                if episodes_display is None
                else episodes_display.add_task("episodes", total=episodes)
            )
            result = run_episodes(
                loaded,
                actions,
                sense=sense,
                episodes=episodes,
                seed=seed,
                scale=noise_scale,
                settings=settings,
                record=record,
                progress=report,
                on_resume=resume,
            )
    except KeyboardInterrupt:
        if record:
            kept = f"the finished episodes are in {record}: run again to resume"
        else:
            kept = "they are not kept: --record FILE keeps every finished episode to resume"
        reached = sum(e.success for e in finished)
        earlier = f"{len(read_back)} of them resumed from {record}; " if read_back else ""
        fail(
            f"interrupted after {len(finished)} of {episodes} episodes ({earlier}{reached} "
            f"reached the goal; no result is given for part of a run); {kept}",
            EXIT_NEGATIVE,
        )
    except (RecordFileError, ValueError) as error:
        fail(str(error))
    if storyboard is not None:
        from arrange_up.figures.episode import draw_episode  # matplotlib: only when drawing

        _, outcome, executor = run_episode(
            loaded, actions, sense, settings, seed, storyboard_episode, scale=noise_scale,
            trace=True,
        )  # fmt: skip
        draw_episode(loaded, executor.trace, outcome, storyboard)
    if as_json:
        summary = result.to_json()
        summary.update(
            episodes=episodes,
            problem={"name": loaded.name, "hash": problem_hash(loaded), "source": loaded.source},
            plan={"path": plan_file, "hash": plan_hash(actions), "actions": len(actions)},
            record=record,
            storyboard=storyboard,
            episode_records=[e.to_json() for e in result.episodes],
        )
        echo_json(summary)
        return
    rel = result.reliability
    low, high = rel.interval
    click.echo(
        f"{loaded.name}: {rel.successes} of {rel.trials} closed-loop episodes reached the goal: "
        f"{100.0 * rel.rate:.1f}% (95% Wilson interval {100.0 * low:.1f}%-{100.0 * high:.1f}%)"
    )
    median = result.median_replan_seconds
    timing = "" if median is None else f", median {median:.2f} s per replan"
    resumed = f", {result.resumed} resumed from {record}" if result.resumed else ""
    click.echo(
        f"sense {sense}, noise x{noise_scale:g}, landing {landing}, seed {seed}: "
        f"{result.mean_replans:.2f} replans per episode ({len(result.replans)} in all{timing}), "
        f"{result.model_failures} model failures, {rel.elapsed:.1f} s{resumed}"
    )
    if rel.failures.total:
        click.echo(f"failures: {rel.failures.total}")
        for line in _failure_lines(loaded, actions, rel.failures):
            click.echo(line)
    if record:
        click.echo(f"episodes recorded in {record}")
    if storyboard:
        click.echo(f"episode {storyboard_episode} drawn in {storyboard}")
