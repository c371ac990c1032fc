"""Closed loop against open loop, on the same simulated worlds (issue 16's targets).

    python benchmarks/closed_loop.py --problems tz-mating --episodes 20
    python benchmarks/closed_loop.py --problems blocks-4 --noise-scale 2 --plan-semantics particles
    python benchmarks/closed_loop.py --problems tz-mating,create-a-t --episodes 200 --output-dir out
    python benchmarks/closed_loop.py --problems create-a-t --plan-semantics particles \
        --plan-particles 25 --episodes 200 --distinct
    python benchmarks/closed_loop.py --problems blocks-4@servo --noise-scale 2 \
        --plan-semantics cbst --semantics cbst

For each problem: a first plan (``--plan-semantics``: ``deterministic`` gives the nominal plan,
the open-loop comparator of the mating problems; ``particles`` a particle plan), then the same
episodes (episode i's world drawn from (seed, i), noise ``--noise-scale`` times the model's)
run twice: open loop (the plan executed as it is: no replans, no sensing) and closed loop
(``--sense``, replanning with ``--semantics`` / ``--particles`` / ``--max-nodes`` /
``--replan-budget``). The two rates are therefore paired. Every episode is appended to a
``.jsonl`` record per problem and mode in ``--output-dir`` (re-running resumes), the first
plan to a plan file there (re-running reads it instead of planning again), and the summary of
each pair to ``closed_loop.json`` there (merged with the problems already in it).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
from pathlib import Path

from arrange_up.evaluation.reliability import wilson_interval
from arrange_up.execution.episodes import EpisodeRecord, run_episode, run_episodes
from arrange_up.execution.replanning import ClosedLoopSettings
from arrange_up.io.domains import load
from arrange_up.io.planfile import plan_problem_mismatches, read_plan, write_json_atomic
from arrange_up.model.problem import driven_by
from arrange_up.planning.planner import plan


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    parser.add_argument(
        "--problems",
        default="tz-mating",
        help="Comma-separated problem names; NAME@CONTROLLER runs a problem under that "
        "controller (blocks-4@servo: the servo, whose CBST model plans it).",
    )
    parser.add_argument(
        "--episodes", type=int, default=20, help="Episodes per problem, open and closed loop."
    )
    parser.add_argument(
        "--seed", type=int, default=0, help="Episode i's world and noise draw from (seed, i)."
    )
    parser.add_argument(
        "--sense",
        default="paddle",
        help="Closed loop's observations: paddle (its final pose after a push), poses (noisy "
        "part poses, a camera) or none.",
    )
    parser.add_argument(
        "--noise-scale",
        type=float,
        default=1.0,
        help="The executor's noise as a multiple of the problem's modelled noise (2: model "
        "error the planner does not know of).",
    )
    parser.add_argument(
        "--plan-semantics",
        default="deterministic",
        help="Semantics of the first plan, which open loop executes as it is.",
    )
    parser.add_argument(
        "--plan-particles", type=int, default=10, help="Particles of the first plan's search."
    )
    parser.add_argument("--semantics", default="deterministic", help="Semantics of the replans.")
    parser.add_argument(
        "--particles", type=int, default=10, help="Particles of each replan's search."
    )
    parser.add_argument("--max-nodes", type=int, default=300, help="Node limit of each replan.")
    parser.add_argument(
        "--replan-budget", type=float, default=30.0, help="Seconds each replan may take."
    )
    parser.add_argument(
        "--filter-particles",
        type=int,
        default=ClosedLoopSettings().filter_particles,
        help="Particles of the belief the observations update.",
    )
    parser.add_argument(
        "--landing",
        default="fail",
        choices=("fail", "shove"),
        help="A push whose paddle is put down onto a part: fails the action, or the physics "
        "resolves the overlap.",
    )
    parser.add_argument(
        "--no-adapt",
        action="store_true",
        help="Keep the modelled noise after a model failure (ClosedLoopSettings.adapt off).",
    )
    parser.add_argument(
        "--output-dir",
        type=Path,
        default=Path("closed-loop-results"),
        help="Where the episode records, first plans and closed_loop.json go (resumed).",
    )
    parser.add_argument(
        "--table",
        action="store_true",
        help="Print closed_loop.json as a Markdown table, run nothing.",
    )
    parser.add_argument(
        "--distinct",
        action="store_true",
        help="Print, per episode, the distinct states among the filter's particles after each "
        "action (the first plan executed with sensing, never replanning), record nothing.",
    )
    args = parser.parse_args(argv)
    out = args.output_dir
    summary_path = out / "closed_loop.json"
    if args.table:
        print(table(out))
        return 0
    out.mkdir(parents=True, exist_ok=True)
    for name in [p for p in args.problems.split(",") if p]:
        base, _, controller = name.partition("@")
        problem = driven_by(load(base), controller) if controller else load(base)
        tag = f"{name}.{args.sense}.x{args.noise_scale:g}.{args.plan_semantics}"
        if args.plan_semantics == "particles":
            tag += str(args.plan_particles)
        actions = first_plan(problem, args, out / f"{tag}.plan.json")
        if actions is None:
            continue
        if args.distinct:
            distinct(problem, actions, args)
            continue
        closed = ClosedLoopSettings(
            filter_particles=args.filter_particles,
            semantics=args.semantics,
            particles=args.particles,
            max_nodes=args.max_nodes,
            budget=args.replan_budget,
            landing=args.landing,
            adapt=not args.no_adapt,
        )
        if args.landing != "fail":
            tag += f".{args.landing}"
        row = {}
        for mode, sense, settings in (
            (
                "open",
                "none",
                ClosedLoopSettings(filter_particles=1, max_replans=0, landing=args.landing),
            ),
            ("closed", args.sense, closed),
        ):
            label = tag if mode == "open" else f"{tag}.{args.semantics}{args.particles}"
            result = run_episodes(
                problem,
                actions,
                sense=sense,
                episodes=args.episodes,
                seed=args.seed,
                scale=args.noise_scale,
                settings=settings,
                record=out / f"{label}.{mode}.jsonl",
                progress=lambda e, mode=mode, name=name: print(
                    f"{name} {mode} episode {e.episode}: {'ok' if e.success else e.failure.kind}"
                    f" ({len(e.replans)} replans)",
                    flush=True,
                ),
            )
            data = result.to_json()
            row[mode] = {
                "successes": data["successes"],
                "trials": data["trials"],
                "rate": data["rate"],
                "interval": data["interval"],
                "replans": data["replans"],
                "model_failures": data["model_failures"],
                "stopped": data["stopped"],
                "failures": data["failures"],
                "settings": data["settings"],
                "sense": sense,
            }
        row["plan"] = {"semantics": args.plan_semantics, "actions": len(actions)}
        if args.plan_semantics == "particles":
            row["plan"]["particles"] = args.plan_particles
        row["noise_scale"] = args.noise_scale
        row["landing"] = args.landing
        # read again before writing: another run may have added its problems meanwhile
        summary = json.loads(summary_path.read_text()) if summary_path.exists() else {}
        summary[f"{tag}.{args.semantics}{args.particles}"] = row
        summary_path.write_text(json.dumps(summary, indent=2) + "\n")
        o, c = row["open"], row["closed"]
        print(
            f"{name}: open loop {o['successes']}/{o['trials']} ({100 * o['rate']:.1f}%), "
            f"closed loop {c['successes']}/{c['trials']} ({100 * c['rate']:.1f}%, "
            f"{c['replans']['per_episode']:.2f} replans per episode, median "
            f"{c['replans']['seconds']['median']} s per replan)",
            flush=True,
        )
    return 0


def first_plan(problem, args, path: Path) -> tuple | None:
    """The first plan: read from ``path`` when an earlier run saved it there (a validated
    particle plan of tt-mating-noisy takes minutes), else planned and saved; None (said) when
    the planner found none."""
    if path.exists():
        actions, document = read_plan(path, problem)
        mismatch = "; and ".join(plan_problem_mismatches(document, problem))
        if mismatch:
            raise SystemExit(f"{path}: {mismatch}; delete it to plan again")
        print(f"{problem.name}: first plan read from {path}", flush=True)
        return actions
    first = plan(
        problem, semantics=args.plan_semantics, particles=args.plan_particles, seed=args.seed
    )
    if not first.solved:
        print(f"{problem.name}: no first plan ({first.reason})", flush=True)
        return None
    actions = first.actions or ()
    write_json_atomic(path, first.document(problem))
    return actions


def distinct(problem, actions, args) -> None:
    """``--distinct``: how many distinct states the posterior holds after each action."""
    settings = ClosedLoopSettings(
        filter_particles=args.filter_particles, threshold=0.0, landing=args.landing
    )
    counts = []
    for episode in range(args.episodes):
        _, outcome, _ = run_episode(
            problem,
            actions,
            args.sense,
            settings,
            args.seed,
            episode,
            scale=args.noise_scale,
            trace=True,
        )
        row = [len({p.poses for p in step.posterior.particles}) for step in outcome.trace]
        counts.extend(row)
        print(f"{problem.name} episode {episode}: distinct states after each action {row}")
    print(
        f"{problem.name}: {args.filter_particles} particles held {min(counts)} to "
        f"{max(counts)} distinct states (median {statistics.median(counts):g}) after an action"
    )


def _read(path: Path) -> tuple[dict, dict[int, EpisodeRecord]]:
    """A record file's header and its episodes by number."""
    lines = [line for line in path.read_text().splitlines() if line.strip()]
    episodes = {}
    for line in lines[1:]:
        record = EpisodeRecord.from_json(json.loads(line))
        episodes[record.episode] = record
    return json.loads(lines[0]), episodes


def _rate(records: list[EpisodeRecord]) -> str:
    good = sum(r.success for r in records)
    low, high = wilson_interval(good, len(records))
    rate = 100 * good / len(records)
    return f"{good}/{len(records)} = {rate:.0f} % ({100 * low:.0f}–{100 * high:.0f})"


def _sign_test(won: int, lost: int) -> float:
    """Two-sided exact sign test of the paired episodes that only one mode got right: the
    chance of a split at least this uneven if either mode were as likely to win each."""
    n = won + lost
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, k) for k in range(min(won, lost) + 1)) / 2**n
    return min(1.0, 2 * tail)


def table(out: Path) -> str:
    """Every closed-loop record in ``out`` beside its open-loop partner, on the episodes both
    hold (paired), as a Markdown table: both rates with their 95% Wilson intervals, the
    closed loop's replans per episode, median seconds per replan, model failures, failures by
    kind, the episodes only the closed (won) or only the open loop (lost) got right with the
    sign test's p of that split, and the replanning settings and filter size its header
    records."""
    lines = [
        "| run | open loop | closed loop | replans / episode | median s / replan "
        "| model failures | closed-loop failures (goal / action / rest / off) "
        "| episodes won / lost by closing the loop (sign test p) | replanning |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for path in sorted(out.glob("*.closed.jsonl")):
        label = path.name.removesuffix(".closed.jsonl")
        partner = out / f"{label.rsplit('.', 1)[0]}.open.jsonl"
        if not partner.exists():
            continue
        header, closed = _read(path)
        _, opened = _read(partner)
        common = sorted(set(closed) & set(opened))
        if not common:
            continue
        c = [closed[i] for i in common]
        times = [r.seconds for e in c for r in e.replans]
        median = f"{statistics.median(times):.2f}" if times else "—"
        kinds = [str(e.failure.kind) for e in c if e.failure is not None]
        counts = " / ".join(
            str(kinds.count(k))
            for k in ("goal_missed", "action_failed", "not_at_rest", "off_table")
        )
        s = header["settings"]
        if s["semantics"] == "deterministic":
            how = f"deterministic from {s.get('candidates', 1)} particles"
        elif s["semantics"] == "cbst":
            how = "cbst from the posterior's intervals"
        else:
            how = f"{s['semantics']}, {s['particles']} particles"
        how += f", {s['max_nodes']} nodes, {s['budget']:g} s"
        how += "" if s.get("adapt") else ", no adapt"
        how += f"; filter {s['filter_particles']} particles"
        won = sum(closed[i].success and not opened[i].success for i in common)
        lost = sum(opened[i].success and not closed[i].success for i in common)
        lines.append(
            f"| {label} | {_rate([opened[i] for i in common])} | {_rate(c)} | "
            f"{statistics.fmean(len(e.replans) for e in c):.2f} | {median} | "
            f"{sum(len(e.model_failures) for e in c)} | {counts} | "
            f"{won} / {lost} ({_sign_test(won, lost):.2g}) | {how} |"
        )
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
