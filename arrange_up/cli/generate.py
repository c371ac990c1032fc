"""The ``generate`` command: a problem file of a documented family
(:mod:`arrange_up.io.generate`)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from arrange_up.cli.shared import OutputFile, fail, seed_option, writing_output
from arrange_up.io.generate import (
    BLOCKS_NOISE,
    FAMILIES,
    MAX_PARTS,
    Noise,
    generate_problem,
    min_parts,
)
from arrange_up.io.planfile import write_text_atomic
from arrange_up.io.yaml_problem import check_problem_text


class CommaNumbers(click.ParamType):
    """``count`` finite non-negative numbers separated by commas (``0.2,0.2,15``)."""

    name = "numbers"

    def __init__(self, count: int) -> None:
        self.count = count

    def convert(self, value: Any, param: Any, ctx: Any) -> Any:
        if isinstance(value, tuple):
            return value
        try:
            numbers = tuple(float(item) for item in str(value).split(","))
        except ValueError:
            numbers = ()
        if len(numbers) != self.count or not all(math.isfinite(n) and n >= 0 for n in numbers):
            self.fail(
                f"expected {self.count} non-negative numbers separated by commas, got {value!r}",
                param,
                ctx,
            )
        return numbers


class OneLineErrors(click.Command):
    """A command whose bad command line is one line on stderr, ``arrange-up: generate:
    what is wrong`` (exit 2), where click prints the usage and a hint around it: a script that
    generates many problems logs one line per refusal."""

    def make_context(self, *args: Any, **kwargs: Any) -> click.Context:
        try:
            return super().make_context(*args, **kwargs)
        except click.UsageError as error:
            fail(f"{self.name}: {error.format_message()}")


def _shown(values: tuple[float, ...]) -> str:
    return ",".join(f"{v:g}" for v in values)


_FAMILY_LINES = "\n".join(f"  {name:<10} {line}" for name, line in FAMILIES.items())

HELP = f"""Write a generated problem file of FAMILY with N parts (the scaling suite).

\b
Families (docs/generated-problems.md says how each is laid out):
{_FAMILY_LINES}

Every family is the block world of the shipped construction problems (1-inch blocks, a 2.5 x
0.15 in paddle, walls on all four sides, goal tolerance 0.2 in and 15 deg) on a table grown to
fit N parts with room to place and push; every part starts off the table. The seed chooses what
the family leaves open (the corner, the wall, the mix and order of shapes, the outline of a
relative goal); the same arguments write the same file, byte for byte. The noise is the shipped
block problems' unless given. Without --output the problem is printed.

\b
Example:
  arrange-up generate staircase --parts 12 --seed 0 -o staircase-12.yaml
"""


@click.command(cls=OneLineErrors, help=HELP)
@click.argument("family", type=click.Choice(list(FAMILIES)), metavar="FAMILY")
@click.option(
    "--parts",
    "-n",
    type=click.IntRange(1, MAX_PARTS),
    required=True,
    help=f"Number of parts N (1 to {MAX_PARTS}; relative: at least 2).",
)
@seed_option("Chooses what the family leaves open.")
@click.option(
    "--output",
    "-o",
    type=OutputFile((".yaml", ".yml")),
    default=None,
    help="Where to write the problem (.yaml); default: print it.",
)
@click.option(
    "--place-uncertainty",
    type=CommaNumbers(3),
    default=_shown(BLOCKS_NOISE.place),
    show_default=True,
    help="DX,DY,DTHETA (in, deg): where a place lands around its target.",
)
@click.option(
    "--push-uncertainty",
    type=CommaNumbers(3),
    default=_shown(BLOCKS_NOISE.push),
    show_default=True,
    help="DX,DY,DTHETA (in, deg): the paddle's approach pose around its target.",
)
@click.option(
    "--friction",
    type=CommaNumbers(2),
    default=_shown(BLOCKS_NOISE.friction),
    show_default=True,
    help="LOW,HIGH: the coefficient of friction, drawn uniformly per action.",
)
def generate(
    family: str,
    parts: int,
    seed: int,
    output: str | None,
    place_uncertainty: tuple[float, float, float],
    push_uncertainty: tuple[float, float, float],
    friction: tuple[float, float],
) -> None:
    if parts < min_parts(family):
        fewest = min_parts(family)
        fail(f"generate: --parts: a {family} problem has at least {fewest} parts, got {parts}")
    noise = Noise(place=place_uncertainty, push=push_uncertainty, friction=friction)
    text = generate_problem(family, parts, seed, noise=noise)
    # The options could still make a file the loader refuses (a friction range upside down):
    # nothing invalid is written.
    problem, diagnostics = check_problem_text(text, output or "<generated>")
    if problem is None:
        error = next(d for d in diagnostics if d.is_error)
        fail(f"generate: the options make an invalid problem: {error.path}: {error.message}")
    if output is None:
        click.echo(text, nl=False)
        return
    with writing_output(output):
        write_text_atomic(Path(output), text)
    click.echo(f"wrote {output}: {problem.name} ({parts} parts)")
