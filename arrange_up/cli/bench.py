"""The ``bench`` commands: the speed of the building blocks."""

from __future__ import annotations

import click

from arrange_up.cli.shared import (
    comma_integers,
    comma_separated,
    fail,
    library_default,
    seed_option,
    workers_limit_help,
)
from arrange_up.parallel import check_workers
from arrange_up.physics.bench import bench_physics


@click.group()
def bench() -> None:
    """Measure the speed of the building blocks (figures printed, nothing written)."""


@bench.command("physics")
@click.option(
    "--pushes",
    type=click.IntRange(10, 1_000_000),
    default=300,
    show_default=True,
    help="Pushes simulated per scene and worker count.",
)
@click.option(
    "--workers",
    type=str,
    default=comma_separated(library_default(bench_physics, "workers")),
    show_default=True,
    help=f"Comma-separated process counts to measure. {workers_limit_help()}",
)
@seed_option("Seeds the noise of the pushes.")
def bench_physics_command(pushes: int, workers: str, seed: int) -> None:
    """Push rollouts per second: 1 block, a 3-block and a 7-block chain against a wall.

    Each push is a full place-to-rest simulation in a fresh space at dt 1/240 s.
    """
    counts = tuple(comma_integers("--workers", workers))
    for count in counts:
        try:
            check_workers(count)
        except ValueError as error:
            fail(f"--workers: {error}")
    rows = bench_physics(
        n_pushes=pushes, workers=counts, seed=seed, progress=lambda msg: click.echo(msg, err=True)
    )
    click.echo(
        f"{'scene':<16} {'workers':>7} {'pushes':>7} {'seconds':>8} {'pushes/s':>9} "
        f"{'ms/push':>8} {'not at rest':>11}"
    )
    for row in rows:
        click.echo(
            f"{row['scene']:<16} {row['workers']:>7} {row['pushes']:>7} "
            f"{row['seconds']:>8.2f} {row['pushes_per_second']:>9.0f} "
            f"{row['ms_per_push']:>8.2f} {row['not_at_rest']:>11}"
        )
