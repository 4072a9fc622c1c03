"""``pamdp tune`` on Catch Point against the hand-found preset (issue 47): does a search find settings as good?

    nice python benchmarks/bench_tune.py [--algo patrpo] [--trials 20] [--steps 300000] [--seeds 1,2,3,4,5]
        [--out DIR] [--record-only]

Runs the search of ``pamdp tune ALGO --env pamdp/CatchPoint-v0`` (trials of ``--steps`` samples, trained with seed 0,
the median pruner) in DIR/tune (resumed if it is there), then trains the best settings and the env's hand-found
preset (PATRPO's ``catch_point``: benchmarks/catch_point.md) for the same ``--steps`` on the held-out ``--seeds``,
one run at a time, seed by seed across the two arms, each resuming from its checkpoint. After every run it writes
benchmarks/tune_catch_point.md: the search's figures, the settings it found and, per arm, each seed's greedy success
rate over 1000 episodes and the CPU time. ``--record-only`` trains nothing and writes the record from what DIR
holds. The record keeps its hand-written notes.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

from _record import HERE, progress_rows, record_head, write_record

from pamdp.experiments.runner import RunSpec, is_finished, run_all
from pamdp.experiments.status import epoch_seconds
from pamdp.experiments.tune import Search, load_study, tune, write_preset

RECORD = HERE / "tune_catch_point.md"
ENV = "pamdp/CatchPoint-v0"


def arms(info: dict) -> dict[str, dict]:
    """Arm label -> settings over the search's base preset: the preset as it is, and the best trial's settings."""
    return {f"{info['preset']} (hand-found)": {}, f"tuned (trial {info['best_trial']})": info["best_settings"]}


def arm_specs(args, info: dict, label: str, settings: dict) -> list[tuple[RunSpec, str]]:
    settings = tuple(sorted((k, tuple(v) if isinstance(v, list) else v) for k, v in settings.items()))
    slug = label.split(" ")[0]
    return [
        (RunSpec(args.algo, ENV, args.steps, seed, info["preset"], settings, 1000), f"{args.out}/{slug}/seed{seed}")
        for seed in args.seeds
    ]


def _cpu_minutes(run: Path) -> float:
    return sum(epoch_seconds(r) for r in progress_rows(run)) / 60


def _span(study) -> str:
    """When the search's trials ran, first start to last end, over every invocation that ran some."""
    trials = [t for t in study.get_trials(deepcopy=False) if t.datetime_complete is not None]
    start, end = min(t.datetime_start for t in trials), max(t.datetime_complete for t in trials)
    return f"{start:%Y-%m-%d %H:%M} to {end:%H:%M} ({(end - start).total_seconds() / 60:.0f} min of wall time)"


def record(args, info: dict, study) -> list[str]:
    command = " ".join(["python benchmarks/bench_tune.py", *sys.argv[1:]])
    lines = record_head(f"pamdp tune {args.algo} on Catch Point against the hand-found preset", command)
    lines += [
        f"- search: `pamdp tune {args.algo} --env {ENV} --trials {args.trials} --steps-per-trial {args.steps} "
        f"--study-dir {args.out}/tune` (seed 0, median pruner, 100 greedy episodes per evaluation, "
        f"{info['trials']} trials: {info['complete']} complete, {info['pruned']} pruned, {info['failed']} failed); "
        f"CPU time of its trials {info['cpu_seconds'] / 60:.1f} min" + f", its trials from {_span(study)}",
        f"- best trial {info['best_trial']}: {info['objective']} {info['best_value']:.3f} (100 greedy episodes, "
        "training seed 0); the arms below train on held-out seeds and evaluate 1000 greedy episodes each",
        f"- comparison: `pamdp train {args.algo} --env {ENV} --preset {info['preset']} --seed N --total-steps "
        f"{args.steps} [--config {args.out}/tune/best.toml]`, one run at a time at `nice -n 15` beside other long "
        "runs on a 2-core machine (the search's trials too)",
        "",
        f"| setting | {info['preset']} (hand-found) | found by the search |",
        "|---|---|---|",
    ]
    base = RunSpec(args.algo, ENV, args.steps, 0, info["preset"]).config().config
    for name, value in info["best_settings"].items():
        ours = getattr(base, name)
        ours = list(ours) if isinstance(ours, tuple) else ours
        shown = f"{value:.4g}" if isinstance(value, float) else value
        lines.append(f"| `{name}` | {ours} | {shown} |")
    lines += [
        "",
        "| arm | samples | greedy success rate per seed (1000 episodes) | mean | median | CPU min per run (median) |",
        "|---|---|---|---|---|---|",
    ]
    total_cpu = info["cpu_seconds"] / 60
    for label, settings in arms(info).items():
        rates, cpu = {}, []
        for spec, out in arm_specs(args, info, label, settings):
            out = Path(out)
            if is_finished(out, spec):
                rates[spec.seed] = json.loads((out / "evaluation.json").read_text())["success_rate"]
            cpu.append(_cpu_minutes(out))
        total_cpu += sum(cpu)
        per_seed = ", ".join(f"{s}: {r:.3f}" for s, r in rates.items()) or "-"
        mean = f"{statistics.mean(rates.values()):.3f}" if rates else "-"
        median = f"{statistics.median(rates.values()):.3f}" if rates else "-"
        cpu_median = f"{statistics.median(cpu):.1f}" if cpu else "-"
        lines.append(f"| {label} | {args.steps:,} | {per_seed} | {mean} | {median} | {cpu_median} |")
    lines += ["", f"CPU budget in all (search and comparison, training only): {total_cpu:.0f} min."]
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--algo", default="patrpo")
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--steps", type=int, default=300_000)
    parser.add_argument("--seeds", type=lambda s: [int(x) for x in s.split(",")], default=[1, 2, 3, 4, 5])
    parser.add_argument("--out", default="results/bench/tune_catch_point")
    parser.add_argument("--record-only", action="store_true")
    args = parser.parse_args()
    name = f"{args.algo}-CatchPoint-v0"
    search = Search(args.algo, ENV, args.trials, args.steps, f"sqlite:///{args.out}/tune/study.db", name)
    study = load_study(search) if args.record_only else tune(search)
    info = write_preset(study, f"{args.out}/tune/best.toml")
    if not args.record_only:  # seed by seed across the arms, so that a cut-short invocation compares like with like
        per_arm = [arm_specs(args, info, label, settings) for label, settings in arms(info).items()]
        for job in [job for seed_jobs in zip(*per_arm) for job in seed_jobs]:
            run_all([job], workers=1)
            write_record(record(args, info, study), RECORD)
    write_record(record(args, info, study), RECORD)


if __name__ == "__main__":
    main()
