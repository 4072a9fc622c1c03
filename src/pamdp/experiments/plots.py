"""Learning curves and result tables from run directories (``pamdp plot``).

A *group* is the set of seeds of one setting: the run directories (those holding ``progress.csv``) that
share a parent directory, e.g. ``results/platform/PATRPO/seed0 ... seed4``. Curves show the mean across
seeds with a shaded standard deviation, per epoch, as the paper's figures do.
"""

from __future__ import annotations

import csv
import json
import os
import warnings
from pathlib import Path

import numpy as np

__all__ = ["find_groups", "aggregate", "plot_curves", "results_table", "write_report"]

METRIC = "charts/episodic_return"
GREEDY_METRIC = "eval/mean_return"  # logged every few epochs by runs with eval_every (``--eval-every``)
LABELS = {METRIC: "average return", GREEDY_METRIC: "greedy return (100 episodes)"}


def find_groups(roots: list[str | os.PathLike]) -> dict[str, list[Path]]:
    """``{label: [run dirs]}`` for every directory below ``roots`` that holds a ``progress.csv``."""
    groups: dict[str, list[Path]] = {}
    for root in map(Path, roots):
        if not root.exists():
            raise FileNotFoundError(f"no such directory: {root}")
        runs = [root] if (root / "progress.csv").exists() else sorted(p.parent for p in root.rglob("progress.csv"))
        for run in runs:
            groups.setdefault(run.parent.name if run != root else run.name, []).append(run)
    if not groups:
        raise FileNotFoundError(f"no run directories (with progress.csv) under {', '.join(map(str, roots))}")
    return groups


def _read_progress(run: Path, metric: str) -> tuple[np.ndarray, np.ndarray]:
    with open(run / "progress.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    steps = np.array([float(r["time/total_timesteps"]) for r in rows])
    values = np.array([float(r[metric]) if r.get(metric) not in (None, "") else np.nan for r in rows])
    return steps, values


def aggregate(runs: list[Path], metric: str = METRIC) -> dict[str, np.ndarray]:
    """Per-epoch mean and std across seeds, over the epochs every seed reached."""
    curves = [_read_progress(r, metric) for r in runs]
    n = min(len(s) for s, _ in curves)
    steps = np.mean([s[:n] for s, _ in curves], axis=0)
    values = np.array([v[:n] for _, v in curves])
    with warnings.catch_warnings():  # epochs where no seed logged the metric are NaN, not a warning
        warnings.simplefilter("ignore", RuntimeWarning)
        return {
            "epoch": np.arange(1, n + 1),
            "steps": steps,
            "mean": np.nanmean(values, axis=0) if n else np.array([]),
            "std": np.nanstd(values, axis=0) if n else np.array([]),
            "seeds": np.full(n, len(runs)),
        }


def plot_curves(
    groups: dict[str, list[Path]], path: str | os.PathLike, title: str = "", metric: str = METRIC
) -> list[Path]:
    """Mean +- std learning curves of every group, written as ``path`` with ``.png`` and ``.svg`` suffixes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.0, 3.4), dpi=110)
    for label, runs in groups.items():
        agg = aggregate(runs, metric)
        ok = np.isfinite(agg["mean"])  # a metric logged every few epochs only (greedy evaluations)
        x, mean, std = agg["steps"][ok] / 1e6, agg["mean"][ok], agg["std"][ok]
        line = ax.plot(
            x, mean, label=f"{label} ({len(runs)} seeds)", linewidth=1.4, marker="." if ok.sum() < 40 else None
        )[0]
        ax.fill_between(x, mean - std, mean + std, color=line.get_color(), alpha=0.2)
    # Samples rather than epochs on the x axis: settings may differ in samples per epoch.
    ax.set_xlabel("environment samples (millions)")
    ax.set_ylabel(LABELS.get(metric, metric))
    if title:
        ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, frameon=False)
    fig.tight_layout()
    path = Path(path)
    written = []
    for suffix in (".png", ".svg"):
        target = path.with_suffix(suffix)
        fig.savefig(target)
        written.append(target)
    plt.close(fig)
    return written


def results_table(groups: dict[str, list[Path]]) -> str:
    """A markdown table of the final greedy evaluations (mean +- std across seeds)."""
    lines = [
        "| setting | seeds | greedy return (mean +- std over seeds) | goal rate | steps to goal | last-epoch return |",
        "|---|---|---|---|---|---|",
    ]
    for label, runs in groups.items():
        evals = [json.loads((r / "evaluation.json").read_text()) for r in runs if (r / "evaluation.json").exists()]
        agg = aggregate(runs)
        last = f"{agg['mean'][-1]:.3f} +- {agg['std'][-1]:.3f}" if len(agg["mean"]) else "-"
        if evals:
            ret = np.array([e["mean_return"] for e in evals])
            per_seed = ", ".join(f"{r:.3f}" for r in ret)
            greedy = f"{ret.mean():.3f} +- {ret.std():.3f} ({len(evals)} evaluated: {per_seed})"
            goals = [e["goal_rate"] for e in evals if "goal_rate" in e]
            steps = [e["mean_steps_to_goal"] for e in evals if e.get("mean_steps_to_goal") is not None]
            goal = f"{np.mean(goals):.3f}" if goals else "-"
            to_goal = f"{np.mean(steps):.1f}" if steps else "-"
        else:
            greedy, goal, to_goal = "not evaluated", "-", "-"
        lines.append(f"| {label} | {len(runs)} | {greedy} | {goal} | {to_goal} | {last} |")
    return "\n".join(lines)


def write_report(roots: list[str | os.PathLike], out: str | os.PathLike, title: str = "") -> dict[str, Path]:
    """Curves (PNG, SVG), the per-epoch aggregate (CSV) and the results table (markdown) into ``out``.

    Runs that logged greedy evaluations during training (``eval_every``) also get ``greedy.png`` and
    ``greedy.svg``: the mean +- std across seeds of those evaluations, at the epochs where they were made.
    """
    groups = find_groups(roots)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    png, svg = plot_curves(groups, out / "curves", title)
    greedy = {
        label: runs for label, runs in groups.items() if np.isfinite(aggregate(runs, GREEDY_METRIC)["mean"]).any()
    }
    extra = {}
    if greedy:
        extra["greedy_png"], extra["greedy_svg"] = plot_curves(greedy, out / "greedy", title, GREEDY_METRIC)
    csv_path = out / "curves.csv"
    with open(csv_path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["setting", "epoch", "timesteps", "mean_return", "std_return", "seeds"])
        for label, runs in groups.items():
            agg = aggregate(runs)
            for i in range(len(agg["epoch"])):
                writer.writerow(
                    [
                        label,
                        int(agg["epoch"][i]),
                        int(agg["steps"][i]),
                        agg["mean"][i],
                        agg["std"][i],
                        int(agg["seeds"][i]),
                    ]
                )
    table = out / "results.md"
    table.write_text(results_table(groups) + "\n")
    return {"png": png, "svg": svg, "csv": csv_path, "table": table, **extra}
