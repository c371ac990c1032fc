"""Accuracy and steps of push simulations under chosen physics settings, against a reference.

Usage::

    python benchmarks/push_accuracy.py [--controller compliant,servo] [--draws 3] [--seed 0]
        [--new KEY=VALUE ...] [--csv push-accuracy.csv]
    python benchmarks/push_accuracy.py --alternatives [--controller compliant]
    python benchmarks/push_accuracy.py --rollouts 200 [--particle-plan FILE]

Every push of the catalogue below is simulated from the same start with the same noise under
three settings: the *reference* (dt 1/960, 30 solver iterations, everything else as the old
settings), the *old* settings (those of every push before the settings were chosen by
controller: :data:`arrange_up.physics.settings.SERVO_VALUES` for both controllers) and the
*new* ones (the defaults of each controller, :meth:`PhysicsSettings.for_controller`, or the
defaults with the ``--new`` overrides). A push's *error* under old or new is the largest, over
the parts on the table, of the distance between the part's final centroid and its centroid in
the reference run (in), and likewise of the angle (deg). Printed per controller, for old and
new: the median and the maximum error over all pushes, the mean physics steps per push, the
wall time of the pushes (the two run interleaved, push by push, in this process) and the
pushes whose outcome status differs from the reference's. ``--csv`` writes one row per push
and setting.

The catalogue (every push in each controller; ``--draws`` noise draws of friction, densities
and approach offset per push, from ``--seed``):

* the three scenes of :mod:`arrange_up.physics.bench`: one block pushed 2 in across the open
  board, chains of 3 and 7 blocks pushed into the right wall;
* the pushes of the shipped servo plans (``tests/goldens/servo-*-deterministic.json``, pinned
  bit for bit) of blocks-1 (single blocks), blocks-3 and blocks-7 (blocks pushed along and
  into the walls and corners, rows of up to four blocks), tz-mating (T and Z parts), tt-mating
  (two T parts), create-a-t (bars) and down-push, each from the state the plan's noise-free
  execution under the reference settings reaches before it;
* a fixture: the repaired TZ mating plan below (the fixture bar placed, the Z pushed against
  it, the bar picked, the T pushed onto the Z);
* the L part of ``tests/catalogue.py`` pushed 3.5 in into its board's right wall.

``--versus KEY=VALUE ...`` adds a third setting, the defaults with those overrides (for
example ``compliant_in_solver=true``), to the summary. ``--behaviour N`` reports instead the
compliant controller's behaviour under the reference, old, new (and versus) settings on ``N``
pushes of each scene of ``benchmarks/controller.py``: free pushes' end error and overshoot, the
stall of a block pushed across the open table and its correlation with friction x mass, blocks
thrown ahead of the paddle, rows scattered, the deepest a block went into the wall.

``--alternatives`` prints the same summary for each alternative of :data:`ALTERNATIVES` (the
table of ``docs/design/physics.md``) instead. ``--rollouts N`` measures rollouts per second of
evaluation under old and new settings, paired (alternating rounds in one process, medians): the
servo CBST plan of blocks-7 under the servo and a compliant particle plan of blocks-7 (no CBST
plan of blocks-7 exists under the compliant controller, whose learned model plans nothing
there; ``--particle-plan`` names a plan file, by default one is planned with 25 particles,
seed 0), with their success counts over the same rollout seeds. ``--evaluate N`` prints the
successes of the compliant goldens' plans (:data:`EVALUATED`) in the same ``N`` rollouts under
old and new settings; ``--saturation`` counts the steps during which an exact early exit at a
stall could have ended a compliant push (the set point still moving, the force clipped).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import statistics
import sys
import time
from dataclasses import asdict, dataclass, replace
from fractions import Fraction
from pathlib import Path

import numpy as np

from arrange_up.evaluation.rollouts import Rollouts
from arrange_up.io.domains import load
from arrange_up.io.planfile import read_plan
from arrange_up.model.problem import SERVO_CONTROLLER, ArrangementProblem, ControllerKind
from arrange_up.model.world import (
    Action,
    Pick,
    Place,
    Push,
    WorldState,
    draw_noise,
    nominal_initial_state,
    nominal_noise,
)
from arrange_up.physics.bench import scene
from arrange_up.physics.settings import (
    COMPLIANT_VALUES,
    DEFAULT_SETTINGS,
    SERVO_VALUES,
    PhysicsSettings,
    push_force,
)
from arrange_up.physics.simulation import simulate, simulate_watched

ROOT = Path(__file__).resolve().parents[1]
GOLDENS = ROOT / "tests" / "goldens"

#: The old settings: what every push used before settings were chosen per controller.
OLD = replace(DEFAULT_SETTINGS, **SERVO_VALUES)
#: The reference: a 4x finer step and 3x the solver iterations, the rest as the old settings.
REFERENCE = replace(OLD, dt=1.0 / 960.0, iterations=30)

#: The repaired TZ mating plan (the compliant repair of its nominal plan with 10 particles,
#: seed 0, as ``tests/goldens/repair-tz-mating-p10.json`` held when this benchmark was written).
TZ_REPAIR: tuple[Action, ...] = (
    Place("bar", (3.0, 3.5, 0.0)),
    Push("paddle", (9.823401, 4.0, 1.5707963267948966), 4.0624),
    Pick("bar"),
    Push("paddle", (5.000014, 2.076598, 0.0), 4.3023),
)

#: name -> overrides of the old settings tried for the compliant controller (the table of
#: docs/design/physics.md). ``NEW`` means the compliant controller's new defaults.
ALTERNATIVES: dict[str, dict] = {
    "old": {},
    "rest_interval 0.05": {"rest_interval": 0.05},
    "rest_interval 0.05, iterations 5": {"rest_interval": 0.05, "iterations": 5},
    "rest_interval 0.025": {"rest_interval": 0.025},
    "rest_interval 0.025, 3 checks": {"rest_interval": 0.025, "rest_checks": 3},
    "rest_interval 0.025, iterations 5": {"rest_interval": 0.025, "iterations": 5},
    "rest_interval 0.025, iterations 4": {"rest_interval": 0.025, "iterations": 4},
    "rest_interval 0.0125": {"rest_interval": 0.0125},
    "rest_interval 0.0125, iterations 5": {"rest_interval": 0.0125, "iterations": 5},
    "rest_interval 0.0125, 3 checks, iterations 5": {
        "rest_interval": 0.0125,
        "rest_checks": 3,
        "iterations": 5,
    },
    "rest_interval 0.0125, iterations 4": {"rest_interval": 0.0125, "iterations": 4},
    "rest_interval 0.0125, tol 2.5e-4, iterations 5": {
        "rest_interval": 0.0125,
        "rest_linear_tol": 2.5e-4,
        "rest_angular_tol": 2.5e-4,
        "iterations": 5,
    },
    "rest_interval 0.00625, iterations 5": {"rest_interval": 0.00625, "iterations": 5},
    "sleep 0.05": {"sleep_time": 0.05},
    "rest_interval 0.0125, tol 2.5e-4, iterations 5, sleep 0.05": {
        "rest_interval": 0.0125,
        "rest_linear_tol": 2.5e-4,
        "rest_angular_tol": 2.5e-4,
        "iterations": 5,
        "sleep_time": 0.05,
    },
    "rest_interval 0.0125, tol 2.5e-4, iterations 5, sleep 0.025": {
        "rest_interval": 0.0125,
        "rest_linear_tol": 2.5e-4,
        "rest_angular_tol": 2.5e-4,
        "iterations": 5,
        "sleep_time": 0.025,
    },
    "rest_interval 0.0125, tol 2.5e-4, iterations 3, sleep 0.05": {
        "rest_interval": 0.0125,
        "rest_linear_tol": 2.5e-4,
        "rest_angular_tol": 2.5e-4,
        "iterations": 3,
        "sleep_time": 0.05,
    },
    "chosen: rest_interval 0.0125, tol 1.25e-4, iterations 5, sleep 0.05": {
        "rest_interval": 0.0125,
        "rest_linear_tol": 1.25e-4,
        "rest_angular_tol": 1.25e-4,
        "iterations": 5,
        "sleep_time": 0.05,
    },
    # a coarser time step under today's compliant values (issue 15's last alternative: the
    # set point's travel at the push speed is most of a push's steps, so only a longer step
    # takes fewer of them)
    "compliant values (the defaults, dt 1/240)": dict(COMPLIANT_VALUES),
    "compliant values, dt 1/200": {**COMPLIANT_VALUES, "dt": 1.0 / 200.0},
    "compliant values, dt 1/180": {**COMPLIANT_VALUES, "dt": 1.0 / 180.0},
    "compliant values, dt 1/160": {**COMPLIANT_VALUES, "dt": 1.0 / 160.0},
    "compliant values, dt 1/120": {**COMPLIANT_VALUES, "dt": 1.0 / 120.0},
}


@dataclass(frozen=True)
class Case:
    """One push of the catalogue: its problem, start and action."""

    name: str
    problem: ArrangementProblem
    state: WorldState
    push: Push


def _action(data: dict) -> Action:
    kind = data["type"]
    if kind == "Place":
        return Place(data["obj"], tuple(data["pose"]))
    if kind == "Push":
        return Push(data["manipulator"], tuple(data["pose"]), data["distance"])
    if kind == "Pick":
        return Pick(data["obj"])
    raise ValueError(f"unknown action type {kind!r}")


def _plan_cases(name: str, problem: ArrangementProblem, actions) -> list[Case]:
    """The pushes of ``actions``, each from the state the noise-free execution of the plan
    under the reference settings reaches before it."""
    state = nominal_initial_state(problem)
    noise = nominal_noise(problem)
    cases = []
    for k, action in enumerate(actions):
        if isinstance(action, Push):
            cases.append(Case(f"{name} push {k}", problem, state, action))
        state = simulate(problem, state, action, noise, REFERENCE).state
    return cases


def catalogue(controller: ControllerKind) -> list[Case]:
    """Every push of the catalogue (module docstring) under ``controller``."""

    def controlled(problem: ArrangementProblem) -> ArrangementProblem:
        if controller is ControllerKind.SERVO:
            return replace(problem, controller=SERVO_CONTROLLER)
        return replace(problem, controller=replace(problem.controller, kind=controller))

    cases = []
    for name in ("1 block", "3-block chain", "7-block chain"):
        problem, state, push = scene(name)
        cases.append(Case(name, controlled(problem), state, push))
    for name in ("blocks-1", "blocks-3", "blocks-7", "tz-mating", "tt-mating", "create-a-t"):
        data = json.loads((GOLDENS / f"servo-{name}-deterministic.json").read_text())
        actions = [_action(a) for a in data["actions"]]
        cases += _plan_cases(name, controlled(load(name)), actions)
    data = json.loads((GOLDENS / "servo-down-push-deterministic.json").read_text())
    cases += _plan_cases(
        "down-push", controlled(load("down-push")), [_action(a) for a in data["actions"]]
    )
    cases += _plan_cases("tz-mating repair (fixture)", controlled(load("tz-mating")), TZ_REPAIR)
    sys.path.insert(0, str(ROOT / "tests"))
    from catalogue import tiny  # noqa: PLC0415 - the tests' catalogue, on their path

    problem = controlled(tiny("l-part"))
    state = nominal_initial_state(problem)
    # The L's centroid is (5/6, 5/6) from its outline's lower-left corner; the paddle (pushing
    # along its +y, turned to +x) starts 0.1 in left of the L, level with its middle.
    approach = (2.0 - 5.0 / 6.0 - 0.075 - 0.1, 2.0 - 5.0 / 6.0 + 1.0, -math.pi / 2.0)
    cases.append(Case("l-part into the wall", problem, state, Push("paddle", approach, 3.5)))
    return cases


def _errors(outcome, reference) -> tuple[float, float]:
    """(largest centroid distance in, largest angle difference in deg) over the parts."""
    pos = ang = 0.0
    for (_, a), (_, b) in zip(outcome.state.poses, reference.state.poses, strict=True):
        pos = max(pos, math.hypot(a[0] - b[0], a[1] - b[1]))
        ang = max(ang, abs(math.degrees(a[2] - b[2])))
    return pos, ang


def measure(
    controller: ControllerKind,
    settings: dict[str, PhysicsSettings],
    draws: int,
    seed: int,
    repeat: int = 1,
    reference_runs: dict | None = None,
) -> list[dict]:
    """One row per push, draw and entry of ``settings`` (besides the reference's run):
    ``controller``, ``case``, ``draw``, ``setting``, ``steps``, ``status``,
    ``reference_status``, ``position_error``, ``angle_error``, ``seconds`` (the least of
    ``repeat`` runs). The settings of one push and draw run one after the other, so their
    times are paired. ``reference_runs`` caches the reference's outcomes across calls."""
    rows = []
    rng = np.random.default_rng(seed)
    cache = {} if reference_runs is None else reference_runs
    for case in catalogue(controller):
        for draw in range(draws):
            noise = draw_noise(case.problem, case.push, rng)
            key = (controller, case.name, draw)
            if key not in cache:
                cache[key] = simulate(case.problem, case.state, case.push, noise, REFERENCE)
            reference = cache[key]
            for label, s in settings.items():
                seconds = math.inf
                for _ in range(repeat):
                    t0 = time.perf_counter()
                    outcome = simulate(case.problem, case.state, case.push, noise, s)
                    seconds = min(seconds, time.perf_counter() - t0)
                pos, ang = _errors(outcome, reference)
                rows.append(
                    {
                        "controller": controller.value,
                        "case": case.name,
                        "draw": draw,
                        "setting": label,
                        "steps": outcome.steps,
                        "reference_steps": reference.steps,
                        "status": outcome.status.value,
                        "reference_status": reference.status.value,
                        "position_error": pos,
                        "angle_error": ang,
                        "seconds": seconds,
                    }
                )
    return rows


def summary(rows: list[dict], label: str) -> dict:
    """Median and max errors, mean steps, total seconds, status mismatches and the push of the
    largest position error (``worst``) of one setting."""
    mine = [r for r in rows if r["setting"] == label]
    pos = [r["position_error"] for r in mine]
    ang = [r["angle_error"] for r in mine]
    worst = max(mine, key=lambda r: r["position_error"])
    return {
        "worst": f"{worst['case']} draw {worst['draw']}",
        "pushes": len(mine),
        "median_in": statistics.median(pos),
        "max_in": max(pos),
        "median_deg": statistics.median(ang),
        "max_deg": max(ang),
        "steps": statistics.fmean(r["steps"] for r in mine),
        "seconds": sum(r["seconds"] for r in mine),
        "status_differs": sum(r["status"] != r["reference_status"] for r in mine),
    }


def _print_summaries(controller: str, rows: list[dict], labels) -> None:
    base = summary(rows, labels[0])
    print(
        f"{controller}: {base['pushes']} pushes; reference steps/push "
        f"{statistics.fmean(r['reference_steps'] for r in rows if r['setting'] == labels[0]):.1f}"
    )
    print(
        f"  {'setting':<62} {'median in':>9} {'max in':>7} {'median deg':>10} {'max deg':>7} "
        f"{'steps':>6} {'x steps':>7} {'x time':>6} {'status!=':>8}  worst push"
    )
    for label in labels:
        s = summary(rows, label)
        print(
            f"  {label:<62} {s['median_in']:>9.4f} {s['max_in']:>7.4f} {s['median_deg']:>10.3f} "
            f"{s['max_deg']:>7.3f} {s['steps']:>6.1f} {s['steps'] / base['steps']:>7.2f} "
            f"{s['seconds'] / base['seconds']:>6.2f} {s['status_differs']:>8}  {s['worst']}"
        )


def _overrides(items) -> dict:
    changes: dict = {}
    for item in items:
        key, _, value = item.partition("=")
        if value in ("true", "false"):
            changes[key] = value == "true"
            continue
        number = Fraction(value)
        changes[key] = (
            int(number) if number.denominator == 1 and "." not in value else float(number)
        )
    return changes


def _settings_record(s: PhysicsSettings) -> str:
    return json.dumps({k: v for k, v in asdict(s).items()}, sort_keys=True)


def _particle_plan(problem: ArrangementProblem, path: str | None) -> tuple[Action, ...]:
    """The compliant particle plan of blocks-7: read from ``path``, or planned (25 particles,
    seed 0, one worker)."""
    if path is not None:
        return read_plan(path, problem)[0]
    from arrange_up.planning.planner import plan  # noqa: PLC0415 - only for these modes

    t0 = time.perf_counter()
    result = plan(problem, semantics="particles", particles=25, seed=0, workers=1)
    print(
        f"planned blocks-7 (particles 25, seed 0): {result.status} in "
        f"{time.perf_counter() - t0:.0f} s"
    )
    if not result.solved:
        sys.exit("no compliant particle plan of blocks-7")
    return tuple(result.actions)


def saturation(particle_plan: str | None) -> None:
    """Steps, over the compliant catalogue's pushes and the particle plan's (noise-free, the
    compliant defaults), during which the set point was still moving while the controller's
    force was clipped along the push: the steps an exact early exit at a stall could save."""
    problem = load("blocks-7")
    cases = catalogue(ControllerKind.COMPLIANT)
    cases += _plan_cases("blocks-7 particles", problem, _particle_plan(problem, particle_plan))
    saturated = total = 0
    for case in cases:
        paddle: list = []

        def watch(bodies, paddle=paddle) -> None:
            if bodies is not None:  # None marks the drive's end
                paddle.append(bodies[-1])

        simulate_watched(case.problem, case.state, case.push, watch, nominal_noise(case.problem))
        controller = case.problem.controller
        clip = push_force(case.problem) if controller.force is None else controller.force
        reach = (controller.speed or DEFAULT_SETTINGS.push_speed) * DEFAULT_SETTINGS.dt
        x0, y0 = paddle[0][0], paddle[0][1]
        for k, (x, y, *_) in enumerate(paddle[1:], start=1):
            if k * reach >= case.push.distance:
                break
            saturated += controller.kp * (k * reach - math.hypot(x - x0, y - y0)) > clip
        total += len(paddle)
    print(
        f"{len(cases)} pushes: force clipped while the set point moved in {saturated} of "
        f"{total} steps"
    )


def rollouts_per_second(
    n: int, rounds: int, particle_plan: str | None, new: PhysicsSettings
) -> None:
    """Rollouts per second of the blocks-7 plans under the old settings and ``new`` (explicit
    values, so the same for both controllers; module docstring)."""
    servo_problem = replace(load("blocks-7"), controller=SERVO_CONTROLLER)
    data = json.loads((GOLDENS / "servo-blocks-7-cbst.json").read_text())
    servo_plan = tuple(_action(a) for a in data["actions"])
    compliant_problem = load("blocks-7")
    compliant_plan = _particle_plan(compliant_problem, particle_plan)
    for title, problem, actions in (
        ("servo CBST plan of blocks-7, controller servo", servo_problem, servo_plan),
        ("compliant particle plan of blocks-7", compliant_problem, compliant_plan),
    ):
        runners = {"old": Rollouts(problem, actions, OLD), "new": Rollouts(problem, actions, new)}
        times: dict[str, list[float]] = {"old": [], "new": []}
        successes: dict[str, int] = {"old": 0, "new": 0}
        per_round = n // rounds
        for r in range(rounds):
            for label in ("old", "new") if r % 2 == 0 else ("new", "old"):
                t0 = time.perf_counter()
                wins = sum(
                    runners[label].run(0, i).success
                    for i in range(r * per_round, (r + 1) * per_round)
                )
                times[label].append(per_round / (time.perf_counter() - t0))
                successes[label] += wins
        old_rate, new_rate = statistics.median(times["old"]), statistics.median(times["new"])
        total = per_round * rounds
        print(f"{title}: {total} rollouts (seed 0), {rounds} alternating rounds")
        print(
            f"  old {old_rate:.2f} rollouts/s, {successes['old']}/{total} succeed; "
            f"new {new_rate:.2f} rollouts/s, {successes['new']}/{total} succeed; "
            f"new/old {new_rate / old_rate:.2f}x"
        )


#: Compliant goldens whose plans ``--evaluate`` scores under old and new settings.
EVALUATED = (
    "blocks-4-deterministic",
    "blocks-7-deterministic",
    "blocks-4-p25-s0",
    "blocks-3-p25-s0",
    "tz-mating-deterministic",
    "repair-tz-mating-p10",
    "tt-mating-deterministic",
    "create-a-t-deterministic",
)


def success_counts(n: int, seed: int, new: PhysicsSettings) -> None:
    """Successes of the plans of :data:`EVALUATED` (as the goldens of this checkout hold them)
    in the same ``n`` rollouts (``seed``) under the old settings and ``new``."""
    print(f"{'plan':<28} {'old':>9} {'new':>9} {'same outcome':>12}")
    for case in EVALUATED:
        data = json.loads((GOLDENS / f"{case}.json").read_text())
        name = case.removeprefix("repair-").split("-p")[0].removesuffix("-deterministic")
        problem = load(name)
        actions = [_action(a) for a in data["actions"]]
        old = Rollouts(problem, actions, OLD)
        fresh = Rollouts(problem, actions, new)
        a = [old.run(seed, i) for i in range(n)]
        b = [fresh.run(seed, i) for i in range(n)]
        same = sum(x.success == y.success for x, y in zip(a, b, strict=True))
        wins_old, wins_new = sum(r.success for r in a), sum(r.success for r in b)
        print(f"{case:<28} {wins_old:>5}/{n:<3} {wins_new:>5}/{n:<3} {same:>8}/{n}")


#: The behaviour :func:`behaviour` reports, from ``benchmarks/controller.py``'s measures.
BEHAVIOUR = (
    ("free_end_error_max", "free end err", ".4f"),
    ("free_overshoot_max", "overshoot", ".4f"),
    ("resisted_stall_median", "stall med", ".4f"),
    ("stall_vs_friction_mass_r", "stall r", ".2f"),
    ("thrown_max", "thrown", ".4f"),
    ("row_scattered", "scattered", "d"),
    ("wall_penetration_max", "wall depth", ".4f"),
    ("not_ok", "not ok", "d"),
)


def behaviour(settings: dict[str, PhysicsSettings], pushes: int, seed: int) -> None:
    """The compliant controller's behaviour under each of ``settings`` and the reference, on
    the scenes of ``benchmarks/controller.py`` (the same ``pushes`` noisy pushes of each):
    the free paddle's largest end error and overshoot past its target, the median stall of a
    lone block pushed across the open table and its correlation with friction x the block's
    mass, the largest gap a block was thrown ahead of the paddle, the gathered rows of four
    scattered, the deepest any block went into the wall (its slop allows about 0.005 in) and
    the pushes not ``OK``."""
    from controller import measure  # noqa: PLC0415 - the sibling benchmark, on this path

    controller = load("blocks-7").controller
    print(f"behaviour, compliant controller, {pushes} pushes per scene (seed {seed})")
    print(f"  {'setting':<10}" + "".join(f" {title:>12}" for _, title, _ in BEHAVIOUR))
    for label, s in {"reference": REFERENCE, **settings}.items():
        row = measure(controller, pushes, seed, s)
        cells = "".join(f" {format(row[key], fmt):>12}" for key, _, fmt in BEHAVIOUR)
        print(f"  {label:<10}{cells}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--controller",
        default="compliant,servo",
        help="comma-separated controller kinds (compliant, servo) whose push catalogue is "
        "measured (default: %(default)s)",
    )
    parser.add_argument(
        "--draws",
        type=int,
        default=3,
        help="noise draws (friction, densities, approach offset) per push (default: %(default)s)",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of the noise draws, and of the --evaluate rollouts (default: %(default)s)",
    )
    parser.add_argument(
        "--new",
        nargs="*",
        metavar="KEY=VALUE",
        default=None,
        help="PhysicsSettings fields overriding the new settings' defaults, e.g. dt=1/480 "
        "iterations=20 (numbers, fractions, true or false; default: none)",
    )
    parser.add_argument(
        "--versus",
        nargs="*",
        metavar="KEY=VALUE",
        default=None,
        help="also measure a third setting, 'versus': the defaults with these overrides, e.g. "
        "compliant_in_solver=false (default: none)",
    )
    parser.add_argument(
        "--behaviour",
        type=int,
        default=None,
        metavar="N",
        help="instead, report the compliant controller's behaviour (free overshoot, stall and "
        "its correlation with friction x mass, thrown blocks, wall depth) under reference, old, "
        "new and versus settings, N pushes per scene (default: off)",
    )
    parser.add_argument(
        "--alternatives",
        action="store_true",
        help="instead of old and new, summarise each alternative physics setting of the "
        "script's ALTERNATIVES (the table of docs/design/physics.md)",
    )
    parser.add_argument("--repeat", type=int, default=3, help="timed runs per push (least)")
    parser.add_argument(
        "--csv",
        default=None,
        metavar="FILE",
        help="CSV file to write one row per push and setting to, overwritten "
        "(default: none, print only)",
    )
    parser.add_argument(
        "--rollouts",
        type=int,
        default=None,
        metavar="N",
        help="instead, measure rollouts per second of the blocks-7 plans under old and new "
        "settings, N rollouts per setting and plan, rounded down to a multiple of --rounds "
        "(default: off)",
    )
    parser.add_argument(
        "--rounds",
        type=int,
        default=4,
        help="with --rollouts: alternating old/new rounds the rollouts are split into "
        "(default: %(default)s)",
    )
    parser.add_argument(
        "--particle-plan",
        default=None,
        metavar="FILE",
        help="with --rollouts or --saturation: plan file of the compliant particle plan of "
        "blocks-7 (default: plan it, 25 particles, seed 0)",
    )
    parser.add_argument(
        "--evaluate",
        type=int,
        default=None,
        metavar="N",
        help="instead, print the successes of the compliant goldens' plans in N rollouts "
        "under old and new settings (default: off)",
    )
    parser.add_argument(
        "--saturation",
        action="store_true",
        help="instead, count the steps of compliant pushes during which the force was clipped "
        "while the set point still moved",
    )
    args = parser.parse_args()
    if args.saturation:
        saturation(args.particle_plan)
        return 0
    if args.rollouts is not None or args.evaluate is not None:
        new = DEFAULT_SETTINGS.for_controller(ControllerKind.COMPLIANT)
        new = replace(new, **_overrides(args.new or ()))
        print(f"new: {_settings_record(new)}")
        if args.rollouts is not None:
            rollouts_per_second(args.rollouts, args.rounds, args.particle_plan, new)
        if args.evaluate is not None:
            success_counts(args.evaluate, args.seed, new)
        return 0
    if args.behaviour is not None:
        new = DEFAULT_SETTINGS.for_controller(ControllerKind.COMPLIANT)
        settings = {"old": OLD, "new": replace(new, **_overrides(args.new or ()))}
        if args.versus is not None:
            settings["versus"] = replace(new, **_overrides(args.versus))
        behaviour(settings, args.behaviour, args.seed)
        return 0
    all_rows = []
    print(f"reference: {_settings_record(REFERENCE)}")
    print(f"old: {_settings_record(OLD)}")
    for name in args.controller.split(","):
        controller = ControllerKind(name)
        if args.alternatives:
            settings = {label: replace(OLD, **o) for label, o in ALTERNATIVES.items()}
        else:
            new = DEFAULT_SETTINGS.for_controller(controller)
            if args.new:
                new = replace(new, **_overrides(args.new))
            print(f"new ({name}): {_settings_record(new)}")
            settings = {"old": OLD, "new": new}
            if args.versus is not None:
                versus = replace(
                    DEFAULT_SETTINGS.for_controller(controller), **_overrides(args.versus)
                )
                print(f"versus ({name}): {_settings_record(versus)}")
                settings["versus"] = versus
        rows = measure(controller, settings, args.draws, args.seed, args.repeat)
        _print_summaries(name, rows, list(settings))
        all_rows += rows
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(all_rows[0]))
            writer.writeheader()
            writer.writerows(all_rows)
        print(f"wrote {args.csv}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
