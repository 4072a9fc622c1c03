"""PATRPO (and MP-DQN, Hybrid SAC) on Catch Point (issue 26): arms of settings over a preset, greedy success rates.

    nice python benchmarks/bench_catch_point.py [--runs "tuned,init_log_std=-1.5"] [--seeds 0,1,2] [--out DIR]
        [--record-only]

Each arm is PATRPO's tuned preset with the arm's settings over it, or, where the arm names them, another
algorithm's preset (MP-DQN's ``catch_point``: ``pdqn`` with multi-pass; Hybrid SAC's ``tuned``). Runs the chosen
arms (default: all) seed by seed, one run at a time, each resuming from its checkpoint, and after every finished run
rewrites benchmarks/catch_point.md: per arm, each finished seed's greedy success rate over 1000 episodes, their median,
the median greedy return and the CPU time of a run. The runs go to DIR/catch_point/LABEL/seedN (default
results/bench); ``--record-only`` trains nothing and writes the record from the runs already there. The record
keeps its hand-written notes.
"""

from __future__ import annotations

import json

import numpy as np
from _record import HERE, kept_rows, progress_rows, record_head, seed_by_seed_main, where_unfinished, write_record

from pamdp.experiments import Experiment
from pamdp.experiments.runner import is_finished
from pamdp.experiments.status import epoch_seconds
from pamdp.logger import success_of

RECORD = HERE / "catch_point.md"
ENV = "pamdp/CatchPoint-v0"

CATCH_POINT = {"init_log_std": -1.5, "entropy_coef": 0.05}
"""The ``catch_point`` preset of ``patrpo`` until 2026-12-03 (second session): these settings over the tuned preset;
since then also :data:`CRITIC`."""
CRITIC = {"vf_hidden_sizes": (256, 256), "vf_epochs": 10}
"""The critic of the arm ``catch_point vf 256x256 10 epochs``, in the ``catch_point`` preset since then."""

# label -> (settings over the tuned preset, samples); the tuned preset's own init_log_std is -0.5.
ARMS = {
    "tuned": ({}, 300_000),
    "init_log_std=-1.0": ({"init_log_std": -1.0}, 300_000),
    "init_log_std=-1.5": ({"init_log_std": -1.5}, 300_000),
    "init_log_std=-2.0": ({"init_log_std": -2.0}, 300_000),
    "init_log_std=-1.5 batch_size=10000": ({"init_log_std": -1.5, "batch_size": 10_000}, 300_000),
    "init_log_std=-1.5 entropy_coef=0.1": ({"init_log_std": -1.5, "entropy_coef": 0.1}, 300_000),
    "init_log_std=-1.5 entropy_coef=0.05": ({"init_log_std": -1.5, "entropy_coef": 0.05}, 300_000),
    "init_log_std=-1.5 entropy_coef=0.05 1M": (CATCH_POINT, 1_000_000),
    # 2026-12-02 (second session): one change at a time over the catch_point preset, at HyAR's 1M budget.
    "catch_point pi_c_input=state": ({**CATCH_POINT, "pi_c_input": "state"}, 1_000_000),
    "catch_point batch_size=2000": ({**CATCH_POINT, "batch_size": 2_000}, 1_000_000),
    "catch_point init_log_std=-2.0": ({**CATCH_POINT, "init_log_std": -2.0}, 1_000_000),
    "catch_point entropy_coef=0.02": ({**CATCH_POINT, "entropy_coef": 0.02}, 1_000_000),
    "catch_point delta=0.01": ({**CATCH_POINT, "delta": 0.01}, 1_000_000),
    "catch_point gae_lambda=0.9": ({**CATCH_POINT, "gae_lambda": 0.9}, 1_000_000),
    # 2026-12-03: delta 0.01 scored on all three seeds; one more change over it.
    "catch_point delta=0.01 init_log_std=-2.0": ({**CATCH_POINT, "delta": 0.01, "init_log_std": -2.0}, 1_000_000),
    "catch_point delta=0.01 gae_lambda=0.9": ({**CATCH_POINT, "delta": 0.01, "gae_lambda": 0.9}, 1_000_000),
    "catch_point delta=0.01 gamma=0.95": ({**CATCH_POINT, "delta": 0.01, "gamma": 0.95}, 1_000_000),
    "catch_point delta=0.005": ({**CATCH_POINT, "delta": 0.005}, 1_000_000),
    # 2026-12-03 (second session), against the failures of catch_point_failures.md: early catches (a better critic),
    # a sector given up and an imprecise heading near +-pi (a wider policy), noisy steps (a larger batch).
    "catch_point vf 256x256 10 epochs": ({**CATCH_POINT, **CRITIC}, 1_000_000),
    "catch_point hidden_sizes=256x256": ({**CATCH_POINT, "hidden_sizes": (256, 256)}, 1_000_000),
    "catch_point batch_size=10000": ({**CATCH_POINT, "batch_size": 10_000}, 1_000_000),
    # the critic's arm scored 0.791, 0.934, 0.940 on seeds 0-2: more of it
    "catch_point vf 256x256 20 epochs": ({**CATCH_POINT, **CRITIC, "vf_epochs": 20}, 1_000_000),
    "catch_point vf 256x256 10 epochs batch_size=10000": ({**CATCH_POINT, **CRITIC, "batch_size": 10_000}, 1_000_000),
    # 2026-12-03 (third session): the catch_point preset (with its critic) and one change of the earlier arms that
    # came close (delta 0.01, gae_lambda 0.9), or a slower, steadier fit of its larger critic.
    "catch_point delta=0.01 (critic)": ({**CATCH_POINT, **CRITIC, "delta": 0.01}, 1_000_000),
    "catch_point gae_lambda=0.9 (critic)": ({**CATCH_POINT, **CRITIC, "gae_lambda": 0.9}, 1_000_000),
    "catch_point vf_lr=3e-4 (critic)": ({**CATCH_POINT, **CRITIC, "vf_lr": 3e-4}, 1_000_000),
}

# 2026-12-03 (third session): MP-DQN's catch_point preset (0.125 on seed 0, every greedy episode spent catching)
# explores the parameters only by OU noise of scale 1e-4, so the heading of a move is never varied: arms that
# explore it. They go over the settings that preset had then (`pdqn`'s tuned preset with these), not over the
# preset's name, which since names the last arm's settings.
MPDQN = ("pdqn", "tuned")
MPDQN_CATCH_POINT = {"multi_pass": True, "gamma": 0.99}
"""MP-DQN's ``catch_point`` preset until 2026-12-03 (third session): these settings over ``pdqn``'s tuned preset."""
GAUSSIAN = {**MPDQN_CATCH_POINT, "explore_params": True, "ou_sigma": 0.1, "ou_theta": 1.0}
ARMS |= {
    "MP-DQN explore_params": ({**MPDQN_CATCH_POINT, "explore_params": True}, 300_000, *MPDQN),
    "MP-DQN explore_params gaussian 0.1": (GAUSSIAN, 300_000, *MPDQN),
    "MP-DQN explore_params epsilon_steps=100000": (
        {**MPDQN_CATCH_POINT, "explore_params": True, "epsilon_steps": 100_000},
        300_000,
        *MPDQN,
    ),
}
# Gaussian noise 0.1 scored 0.409 at 300k (explore_params alone 0.208): more of it, and the critics' targets scaled
# down as on Goal (a catch's 20 as 1).
ARMS |= {
    "MP-DQN explore_params gaussian 0.2": ({**GAUSSIAN, "ou_sigma": 0.2}, 300_000, *MPDQN),
    "MP-DQN explore_params gaussian 0.1 reward_scale=0.05": ({**GAUSSIAN, "reward_scale": 0.05}, 300_000, *MPDQN),
    "MP-DQN explore_params gaussian 0.1 hidden_sizes=128x128": (
        {**GAUSSIAN, "hidden_sizes": (128, 128)},
        300_000,
        *MPDQN,
    ),
}
# At 300k a 128x128 Q-network and actor with noise 0.1 scored 0.799 (its training success near 0.8 from 40k samples
# on): it at HyAR's 1M, since MP-DQN's catch_point preset. The two arms below it were stopped for it (seed 0 at 520k
# and 60k samples).
ARMS |= {
    "MP-DQN explore_params gaussian 0.1 hidden_sizes=128x128 1M": (
        {**GAUSSIAN, "hidden_sizes": (128, 128)},
        1_000_000,
        *MPDQN,
    ),
}
# At 300k noise 0.2 scored 0.578 and the reward scale 0.538 (noise 0.1 alone 0.409): both together, and noise 0.2
# alone, at HyAR's 1M.
ARMS |= {
    "MP-DQN explore_params gaussian 0.2 1M": ({**GAUSSIAN, "ou_sigma": 0.2}, 1_000_000, *MPDQN),
    "MP-DQN explore_params gaussian 0.2 reward_scale=0.05 1M": (
        {**GAUSSIAN, "ou_sigma": 0.2, "reward_scale": 0.05},
        1_000_000,
        *MPDQN,
    ),
}

# Hybrid SAC (not in HyAR's table) had not run on Catch Point: its preset tuned on Platform (64x64, a tenth of an
# update a sample, ~0.4 ms a sample here).
ARMS |= {"Hybrid SAC tuned 1M": ({}, 1_000_000, "hsac", "tuned")}


def algo_preset(label: str) -> tuple[str, str]:
    """The algorithm and preset an arm's settings go over: PATRPO's tuned one unless the arm names others."""
    return tuple(ARMS[label][2:]) or ("patrpo", "tuned")


EXPERIMENT = Experiment(
    "catch_point",
    "Catch Point: PATRPO's tuned preset and lower initial parameter noise, MP-DQN's exploration, Hybrid SAC",
    ENV,
    None,
    (0, 1, 2),
    1000,
    tuple(
        dict(zip(("algo", "preset"), algo_preset(label)), label=label, settings=arm[0], total_steps=arm[1])
        for label, arm in ARMS.items()
    ),
)


def _arm_row(label: str, jobs) -> str:
    """One line of the table: the finished seeds' success rates, their median, the median greedy return and CPU
    minutes of a run, and how far the unfinished seeds are."""
    done, partial = [], []
    for spec, out in jobs:
        rows = progress_rows(out)
        if is_finished(out, spec):
            result = json.loads((out / "evaluation.json").read_text())
            done.append((spec.seed, success_of(result)[0], result["mean_return"], sum(map(epoch_seconds, rows))))
        elif rows:
            partial.append(where_unfinished(spec, rows))
    settings = ", ".join(f"{k} = {v}" for k, v in ARMS[label][0].items()) or "(the preset's)"
    if algo_preset(label) != ("patrpo", "tuned"):
        settings = "{} {}: {}".format(*algo_preset(label), settings)
    per_seed = ", ".join(f"{s}: {r:.3f}" for s, r, _, _ in done) or "-"
    rate, ret, cpu = (np.median([d[i] for d in done]) if done else None for i in (1, 2, 3))
    return (
        f"| {label} | {settings} | {jobs[0][0].total_steps:,} | {per_seed} | {'-' if rate is None else f'{rate:.3f}'} "
        f"| {'-' if ret is None else f'{ret:.2f}'} | {'-' if cpu is None else f'{cpu / 60:.1f}'} "
        f"| {'; '.join(partial) or '-'} |"
    )


def write(arms: dict, command: str) -> None:
    lines = record_head(EXPERIMENT.description, command, rewritten=True) + [
        f"- `pamdp train patrpo --env {ENV} --preset tuned --seed N --total-steps S [--SETTING VALUE]` (an arm that "
        "names another algorithm and preset: `pamdp train ALGO --preset PRESET ...`), one run at a time beside other "
        "long runs; success rate and return: 1000 greedy episodes of each seed's final model "
        "(`pamdp evaluate RUN --episodes 1000 --json` gives the same figures)",
        "",
        "| arm | settings over PATRPO's tuned preset (or the named one) | samples | greedy success rate per seed "
        "| median | median greedy return | CPU min per run (median) | unfinished |",
        "|---|---|---|---|---|---|---|---|",
    ]
    kept = kept_rows(RECORD, ARMS)
    for label in ARMS:  # an arm with no run at hand keeps the row the record had
        jobs = arms.get(label)
        has_runs = jobs is not None and any(progress_rows(out) for _, out in jobs)
        if has_runs or (jobs is not None and label not in kept):
            lines.append(_arm_row(label, jobs))
        elif label in kept:
            lines.append(kept[label])
    lines += [
        "",
        "Rows of arms with no run under this invocation's `--out` are kept from the record as they were (their runs "
        "were lost with an earlier machine, or ran under another `--out`). "
        "CPU min per run: the run's CPU time in training (its final evaluation left out), from its progress.csv. "
        "Published success rates at 1M samples (HyAR, Table 2): HyAR-TD3 0.90, P-DQN 0.77, HPPO 0.69.",
    ]
    write_record(lines, RECORD)


if __name__ == "__main__":
    seed_by_seed_main(__doc__, EXPERIMENT, lambda arms, out, command: write(arms, command))
