"""The ``train-cbst`` command: data, tuning, evaluation and saving of the CBST push model; and
``rescore-cbst``: a saved model's scores measured again."""

from __future__ import annotations

from dataclasses import replace

import click
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    TaskID,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from arrange_up.cbst.data import DEFAULT_GENERATION, SHIPPED_WALL_PUSH, WALL_PUSHES
from arrange_up.cbst.features import TARGET_NAMES, TARGET_UNITS
from arrange_up.cbst.model import rescore_model
from arrange_up.cbst.model import train_cbst as run_training
from arrange_up.cli.shared import (
    EXIT_NEGATIVE,
    FiniteFloat,
    OutputDir,
    OutputFile,
    backend_choice,
    echo_json,
    fail,
    json_option,
    library_default,
    parallel_options,
    quiet_option,
    seed_option,
    stopped_early,
    terminal_progress,
)
from arrange_up.model.problem import Controller, ControllerKind
from arrange_up.parallel import BackendUnavailableError, WorkersLostError

_STAGE_LABELS = {"data": "examples", "test data": "test examples", "fit": "fitting"}
_TRAIN_COLUMNS = (
    TextColumn("{task.description}"),
    BarColumn(),
    MofNCompleteColumn(),
    TimeElapsedColumn(),
    TimeRemainingColumn(),
)


def _stage_display(display):
    """The ``progress(stage, done, total)`` callback that shows each stage as a bar."""
    if display is None:
        return None
    tasks: dict[str, TaskID] = {}

    def update(stage: str, done: int, total: int) -> None:
        if stage not in tasks:
            tasks[stage] = display.add_task(_STAGE_LABELS.get(stage, stage), total=total)
        display.update(tasks[stage], completed=done)

    return update


def _echo_scores(scores: dict) -> None:
    for target, unit in zip(TARGET_NAMES, TARGET_UNITS, strict=True):
        thesis = scores["thesis_test_rmse"].get(target)
        click.echo(
            f"{target:>4}: {scores['cv_folds']}-fold CV RMSE {scores['cv_rmse'][target]:.4f} "
            f"{unit} (R2 {scores['cv_r2'][target]:.3f}); fresh test RMSE "
            f"{scores['test_rmse'][target]:.4f} {unit} (R2 {scores['test_r2'][target]:.3f})"
            + (f"; thesis test RMSE {thesis}" if thesis is not None else "")
        )
    coverage = scores.get("test_coverage")
    if coverage is not None:
        click.echo(
            "fresh test coverage (rollouts inside the predicted box): "
            + ", ".join(f"{name} {share:.2%}" for name, share in coverage.items())
        )


@click.command("train-cbst")
@click.option(
    "--examples",
    type=click.IntRange(10, None),
    default=library_default(run_training, "examples"),
    show_default=True,
    help="Random interval beliefs (thesis: 1800).",
)
@click.option(
    "--rollouts-per-example",
    type=click.IntRange(1, None),
    default=library_default(run_training, "rollouts_per_example"),
    show_default=True,
    help="Simulated pushes per example (thesis: 1000; the shipped compliant model's).",
)
@click.option(
    "--controller",
    type=click.Choice([kind.value for kind in ControllerKind]),
    default=ControllerKind.COMPLIANT.value,
    show_default=True,
    help="The push controller of the rollouts, gains at their defaults; the model plans "
    "only problems with this controller.",
)
@click.option(
    "--wall-push",
    type=click.Choice(WALL_PUSHES),
    default=None,
    help="Where each push sends the paddle: 'uniform' between just past the compressed train "
    "and the wall, 'wall' at the wall, 'planner' where CBST's push to the wall does (under "
    "compliant: past the compressed train by its worst-case stall; docs/cbst.md). "
    "[default: the shipped model's of the controller: planner for compliant, uniform for "
    "servo]",
)
@click.option(
    "--quantile",
    type=FiniteFloat(0.5, 1.0),
    default=DEFAULT_GENERATION.quantile,
    show_default=True,
    help="The quantile of each example's rollouts its targets are (1: their largest, the "
    "thesis's; e.g. 0.99 for boxes that do not widen with the rollouts).",
)
@click.option(
    "--block-half",
    type=(FiniteFloat(min=0.0, min_open=True),) * 3,
    default=DEFAULT_GENERATION.domain.block_half,
    show_default=True,
    help="The training domain: the largest half-widths of a block's belief (in, in, deg).",
)
@click.option(
    "--test-examples",
    type=click.IntRange(1, None),
    default=library_default(run_training, "test_examples"),
    show_default=True,
    help="Examples of the fresh test set (same rollouts, seed --test-seed).",
)
@click.option(
    "--test-seed",
    type=click.IntRange(0, None),
    default=library_default(run_training, "test_seed"),
    show_default=True,
    help="Seed of the fresh test set (must differ from --seed).",
)
@seed_option("Example i depends only on (seed, i); also seeds the forest.")
@parallel_options("examples")
@click.option(
    "--output-dir",
    type=OutputDir(),
    default="cbst-model",
    show_default=True,
    help="Where NAME.npz and NAME.json go (semantics/cbst ships one model per controller).",
)
@click.option(
    "--name",
    default=None,
    help="Model name, as load_model(NAME) finds it [default: the controller's: compliant "
    "or servo].",
)
@click.option(
    "--data",
    "data_path",
    type=OutputFile(),
    default=None,
    help="Resumable .jsonl data file (default OUTPUT_DIR/NAME.data.jsonl).",
)
@click.option(
    "--test-data",
    "test_data_path",
    type=OutputFile(),
    default=None,
    help="Resumable .jsonl file of the test set (default OUTPUT_DIR/NAME.test.jsonl).",
)
@json_option("Print the model card (JSON) on stdout.")
@quiet_option()
def train_cbst(
    examples: int,
    rollouts_per_example: int,
    controller: str,
    wall_push: str | None,
    quantile: float,
    block_half: tuple[float, float, float],
    test_examples: int,
    test_seed: int,
    seed: int,
    workers: int | None,
    backend: str | None,
    scheduler: str | None,
    output_dir: str,
    name: str | None,
    data_path: str | None,
    test_data_path: str | None,
    as_json: bool,
    quiet: bool,
) -> None:
    """Generate CBST training data, then tune, evaluate and save its push model (thesis §3.2).

    The card reports 8-fold cross-validation (by example) RMSE and R2 of every target and
    the scores on a fresh test set. Re-running with the same --data and --test-data files
    resumes: examples already there are skipped.

    \b
    Example:
      arrange-up train-cbst --examples 1800 --rollouts-per-example 1000 --output-dir my-model
    """
    backend = backend_choice(backend, scheduler)
    try:
        with terminal_progress(*_TRAIN_COLUMNS, what="train-cbst", quiet=quiet) as display:
            card = run_training(
                examples=examples,
                rollouts_per_example=rollouts_per_example,
                seed=seed,
                workers=workers,
                output_dir=output_dir,
                controller=Controller(kind=ControllerKind(controller)),
                settings=replace(
                    DEFAULT_GENERATION,
                    wall_push=wall_push or SHIPPED_WALL_PUSH[controller],
                    quantile=quantile,
                    domain=replace(DEFAULT_GENERATION.domain, block_half=block_half),
                ),
                test_examples=test_examples,
                test_seed=test_seed,
                backend=backend,
                scheduler=scheduler,
                name=name,
                data_path=data_path,
                test_data_path=test_data_path,
                progress=_stage_display(display),
            )
    except KeyboardInterrupt:
        fail(
            "interrupted; finished examples are kept in the data file: run again to resume",
            EXIT_NEGATIVE,
        )
    except WorkersLostError as error:
        stopped_early(error, "; finished examples are kept in the data file: run again to resume")
    except (ValueError, BackendUnavailableError) as err:
        fail(str(err))
    if as_json:
        echo_json(card)
        return
    _echo_scores(card["scores"])
    click.echo(
        f"saved {output_dir}/{card['name']}.npz + {card['name']}.json "
        f"({card['controller']['kind']} controller; {card['data']['examples']} "
        f"examples x {card['data']['rollouts_per_example']} rollouts, "
        f"{card['training_seconds']:.0f} s)"
    )


@click.command("rescore-cbst")
@click.argument("model")
@click.option(
    "--data",
    "data_path",
    type=OutputFile(),
    required=True,
    help="Resumable .jsonl file for the model's training data, regenerated from its card.",
)
@click.option(
    "--test-data",
    "test_data_path",
    type=OutputFile(),
    required=True,
    help="Resumable .jsonl file of the fresh test set.",
)
@click.option(
    "--test-examples",
    type=click.IntRange(1, None),
    default=library_default(rescore_model, "test_examples"),
    show_default=True,
    help="Examples of the fresh test set (the card's rollouts).",
)
@click.option(
    "--test-seed",
    type=click.IntRange(0, None),
    default=library_default(rescore_model, "test_seed"),
    show_default=True,
    help="Seed of the fresh test set (must differ from the card's).",
)
@parallel_options("examples")
@click.option("--write", is_flag=True, help="Replace the card's scores with the new ones.")
@json_option("Print the scores (JSON) on stdout.")
@quiet_option()
def rescore_cbst(
    model: str,
    data_path: str,
    test_data_path: str,
    test_examples: int,
    test_seed: int,
    workers: int | None,
    backend: str | None,
    scheduler: str | None,
    write: bool,
    as_json: bool,
    quiet: bool,
) -> None:
    """Measure a saved CBST MODEL's 8-fold CV and fresh-test scores again.

    MODEL is a shipped name or a card path. Its training data is regenerated from the card
    (the same examples, rollouts, seed and settings) for the cross-validation; the model's
    own arrays are scored on the fresh test set and never changed.

    \b
    Example:
      arrange-up rescore-cbst servo --data out/servo.data.jsonl --test-data out/servo.test.jsonl
    """
    backend = backend_choice(backend, scheduler)
    try:
        with terminal_progress(*_TRAIN_COLUMNS, what="rescore-cbst", quiet=quiet) as display:
            scores = rescore_model(
                model,
                data_path=data_path,
                test_data_path=test_data_path,
                test_examples=test_examples,
                test_seed=test_seed,
                workers=workers,
                backend=backend,
                scheduler=scheduler,
                write=write,
                progress=_stage_display(display),
            )
    except KeyboardInterrupt:
        fail(
            "interrupted; finished examples are kept in the data files: run again to resume",
            EXIT_NEGATIVE,
        )
    except WorkersLostError as error:
        stopped_early(error, "; finished examples are kept in the data files: run again to resume")
    except (LookupError, ValueError, BackendUnavailableError) as err:
        fail(str(err))
    if as_json:
        echo_json(scores)
        return
    _echo_scores(scores)
    if write:
        click.echo(f"wrote the scores into {model}'s card")
