"""Learning curves and result tables from run directories (``pamdp plot``).

A *group* is the set of seeds of one setting: the run directories (those holding ``progress.csv``) that
share a parent directory, e.g. ``results/platform/PATRPO/seed0 ... seed4``. Curves show the mean across
seeds with a shaded standard deviation, per epoch, over training epochs as the paper's figures do (or over
samples, where the settings' epochs differ in size).
"""

from __future__ import annotations

import csv
import functools
import json
import os
import warnings
from pathlib import Path

import numpy as np

from pamdp.logger import RENAMED, success_of

__all__ = [
    "find_groups",
    "aggregate",
    "final_values",
    "seeds_label",
    "x_axis",
    "draw_curves",
    "plot_curves",
    "results_table",
]

METRIC = "charts/episodic_return"
GREEDY_METRIC = "eval/mean_return"  # logged every few epochs by runs with eval_every (``--eval-every``)
SUCCESS_METRIC = "charts/success_rate"  # logged by runs on envs that report each episode's outcome
GREEDY_SUCCESS_METRIC = "eval/success_rate"  # with eval_every, on those envs
LABELS = {
    METRIC: "average return",
    GREEDY_METRIC: "greedy return (100 episodes)",
    SUCCESS_METRIC: "success rate (training episodes)",
    GREEDY_SUCCESS_METRIC: "greedy success rate (100 episodes)",
}
# Figures beside the curves, for the runs that logged their metric: (name, metric, report keys)
EXTRA_FIGURES = (
    ("greedy", GREEDY_METRIC, ("greedy_png", "greedy_svg")),
    ("success_rate", SUCCESS_METRIC, ("success_png", "success_svg")),
    ("greedy_success_rate", GREEDY_SUCCESS_METRIC, ("greedy_success_png", "greedy_success_svg")),
)


def find_groups(roots: list[str | os.PathLike]) -> dict[str, list[Path]]:
    """``{label: [run dirs]}`` for every directory below ``roots`` that holds a ``progress.csv``.

    A run's label is the one its ``run.json`` records (an experiment's ``PASVG(0)``, whose directory is
    ``PASVG_0_``), else the name of the directory holding its seeds (or its own name, for a run given alone).
    Runs are averaged together only if they share their label, algorithm and env (with its arguments), and their
    budget, preset and settings (:func:`setting_of`; a smoke test is no seed of a full
    run): where runs of one label differ in those, each kind is a group of its own, named ``label (algo on env)``
    or ``label (2,000 steps, preset paper)`` by what tells them apart.
    """
    found: dict[tuple[str, tuple], list[Path]] = {}
    for root in map(Path, roots):
        if not root.exists():
            raise FileNotFoundError(f"no such directory: {root}")
        runs = [root] if (root / "progress.csv").exists() else _run_dirs(root)
        for run in runs:
            recorded = _recorded(run)
            label = str(recorded.get("label") or "") or (run.parent.name if run != root else run.name)
            found.setdefault((label, (*_kind(recorded), *run_setting(run).values())), []).append(run)
    if not found:
        raise FileNotFoundError(f"no run directories (with progress.csv) under {', '.join(map(str, roots))}")
    kinds: dict[str, list[tuple]] = {}
    for label, kind in found:
        kinds.setdefault(label, []).append(kind)
    return {_group_name(label, kind, kinds[label]): runs for (label, kind), runs in found.items()}


def _group_name(label: str, kind: tuple, kinds: list[tuple]) -> str:
    """``label``, or where runs of that label are of several kinds, ``label (what tells this kind apart)``."""
    if len(kinds) == 1:
        return label
    algo, env, steps, preset, digest = kind
    parts = []
    if any(k[:2] != (algo, env) for k in kinds):
        parts.append(f"{algo} on {env}")
    if any(k[2] != steps for k in kinds):
        parts.append(f"{steps:,} steps" if steps is not None else "budget not recorded")
    if any(k[:3] == kind[:3] and k[3] != preset for k in kinds):
        parts.append(f"preset {preset}")
    if any(k[:4] == kind[:4] and k[4] != digest for k in kinds):
        parts.append(f"settings {digest}")
    return f"{label} ({', '.join(parts)})"


def _run_dirs(root: Path) -> list[Path]:
    """The directories below ``root`` that hold a ``progress.csv``, sorted. Symbolic links are followed (a tree
    gathered from several places by links is read whole), each real directory once, so that two links to one
    run count it once and a link back up the tree ends the walk there. The walk goes in name order, so which of
    two paths to one run is kept (its label comes from its parent's name) does not depend on the file system."""
    seen, runs = set(), []
    for path, subdirs, files in os.walk(root, followlinks=True):
        subdirs.sort()
        real = os.path.realpath(path)
        if real in seen:
            subdirs.clear()
            continue
        seen.add(real)
        if "progress.csv" in files:
            runs.append(Path(path))
    return sorted(runs)


def _changed_settings(algo, config: dict) -> dict:
    """The settings of a recorded config that differ from the algorithm's defaults, so that a run recorded before a
    setting existed is a seed of one recorded after (the new setting at its default, as a resume counts it), and a
    digest made of them stays the same when a setting is added; the config as recorded where the algorithm is
    unknown or the config no longer loads."""
    from pamdp.algos import algorithm_class

    try:
        cls = algorithm_class(algo) if isinstance(algo, str) else None
        if cls is None:
            return config
        defaults = cls.config_class().to_dict()
        return {k: v for k, v in cls.config_class.from_dict(config).to_dict().items() if v != defaults[k]}
    except (ValueError, TypeError):  # an unknown algorithm, or settings it no longer takes
        return config


def setting_of(recorded: dict) -> dict:
    """What tells apart runs that are not seeds of one another: the budget, the preset and a digest of the algorithm
    and all its settings but the seed (``None`` where the run's ``run.json`` does not record them)."""
    import hashlib

    config = recorded.get("config")
    digest = None
    if isinstance(config, dict):
        config = _changed_settings(recorded.get("algo"), config)
        text = json.dumps([recorded.get("algo"), {k: v for k, v in config.items() if k != "seed"}], sort_keys=True)
        digest = hashlib.sha256(text.encode()).hexdigest()[:8]
    steps = recorded.get("total_steps")
    return {
        "total_steps": steps if isinstance(steps, int) and not isinstance(steps, bool) else None,
        "preset": recorded.get("preset") if isinstance(recorded.get("preset"), str) else None,
        "settings": digest,
    }


@functools.lru_cache(maxsize=4096)
def _setting_of_file(path: str, stamp: tuple[int, int]) -> dict:
    return setting_of(_recorded(Path(path).parent))


def run_setting(run: str | os.PathLike) -> dict:
    """:func:`setting_of` a run directory's ``run.json``, computed once per version of the file: a plot groups the
    runs, the suite's table and the summaries all ask for it, and each time loads the algorithm's config."""
    path = Path(run).resolve() / "run.json"
    try:
        stat = path.stat()
    except OSError:
        return setting_of({})
    return dict(_setting_of_file(str(path), (stat.st_mtime_ns, stat.st_size)))


def _recorded(run: Path) -> dict:
    """A run's ``run.json`` (``{}`` where it has none, or one that is not a JSON object)."""
    try:
        recorded = json.loads((run / "run.json").read_text())
    except (OSError, ValueError):
        return {}
    return recorded if isinstance(recorded, dict) else {}


def _kind(recorded: dict) -> tuple[str, str]:
    """What a run is a run of: its algorithm, and its env with the env's arguments."""
    env = str(recorded.get("env") or "an unrecorded env")
    if recorded.get("env_kwargs"):
        env += " " + json.dumps(recorded["env_kwargs"], sort_keys=True)
    return str(recorded.get("algo") or "an unrecorded algorithm"), env


def _read_progress(run: Path, metric: str) -> tuple[np.ndarray, np.ndarray]:
    path = run / "progress.csv"
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        rows = list(reader)
        columns = reader.fieldnames or []
    if "time/total_timesteps" not in columns:
        raise ValueError(
            f"{path} has no column 'time/total_timesteps' (columns: {', '.join(columns) or 'none'}); "
            "expected a progress.csv written by pamdp train"
        )
    if metric not in columns and RENAMED.get(metric) in columns:  # a run logged before the name was general
        metric = RENAMED[metric]
    try:
        steps = np.array([float(r["time/total_timesteps"]) for r in rows])
        values = np.array([float(r[metric]) if r.get(metric) not in (None, "") else np.nan for r in rows])
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path}: {exc}; expected numbers in every column pamdp train writes") from exc
    return steps, values


def aggregate(runs: list[Path], metric: str = METRIC) -> dict[str, np.ndarray]:
    """Per-epoch mean and std across the seeds that reached each epoch.

    An arm still training has seeds at different epochs: every epoch any seed reached is kept, and ``seeds``
    counts the seeds behind each epoch's mean, so a finished seed's curve is not cut to a new seed's first epoch.
    """
    curves = [_read_progress(r, metric) for r in runs]
    n = max((len(s) for s, _ in curves), default=0)
    steps = np.full((len(curves), n), np.nan)
    values = np.full((len(curves), n), np.nan)
    for i, (s, v) in enumerate(curves):
        steps[i, : len(s)], values[i, : len(v)] = s, v
    with warnings.catch_warnings():  # epochs where no seed logged the metric are NaN, not a warning
        warnings.simplefilter("ignore", RuntimeWarning)
        return {
            "epoch": np.arange(1, n + 1),
            "steps": np.nanmean(steps, axis=0) if n else np.array([]),
            "mean": np.nanmean(values, axis=0) if n else np.array([]),
            "std": np.nanstd(values, axis=0) if n else np.array([]),
            "seeds": np.isfinite(steps).sum(axis=0),
        }


def final_values(runs: list[Path], metric: str = METRIC) -> tuple[np.ndarray, np.ndarray]:
    """Each run's last logged ``metric`` and the epoch it was logged at (runs that logged none left out)."""
    values, epochs = [], []
    for run in runs:
        _, v = _read_progress(run, metric)
        logged = np.flatnonzero(np.isfinite(v))
        if len(logged):
            values.append(v[logged[-1]])
            epochs.append(logged[-1] + 1)
    return np.array(values), np.array(epochs, dtype=int)


def seeds_label(agg: dict[str, np.ndarray], total: int) -> str:
    """``5 seeds``, or, for an arm still training, ``3 seeds, 1 past epoch 12``: how many seeds each part of the
    curve stands on."""
    if not len(agg["seeds"]) or agg["seeds"].min() == total:
        return f"{total} seed{'s' * (total != 1)}"
    full = int((agg["seeds"] == total).sum())  # seeds only drop out along the curve
    return f"{total} seeds, {int(agg['seeds'][-1])} past epoch {full}"


X_AXES = ("auto", "epochs", "samples")


def samples_per_epoch(agg: dict[str, np.ndarray]) -> float | None:
    """The median number of samples per epoch of an aggregate (``None`` with fewer than two epochs)."""
    steps = agg["steps"]
    return float(np.median(np.diff(np.concatenate([[0.0], steps])))) if len(steps) >= 2 else None


def x_axis(aggs: dict[str, dict[str, np.ndarray]], x: str = "auto") -> tuple[str, dict[str, np.ndarray]]:
    """The x axis label and each group's x values: training epochs, as the paper's figures, or samples.

    ``auto`` takes epochs when every group's epochs hold the same number of samples (within 1 %: off-policy
    epochs end on the first whole batch of env steps past their size), else samples, since epochs of
    different sizes would misalign the curves.
    """
    if x not in X_AXES:
        raise ValueError(f"x axis {x!r}; expected one of {', '.join(X_AXES)}")
    sizes = [s for s in map(samples_per_epoch, aggs.values()) if s is not None]
    same = bool(sizes) and max(sizes) <= 1.01 * min(sizes)
    if x == "samples" or (x == "auto" and not same):
        return "environment samples (millions)", {k: a["steps"] / 1e6 for k, a in aggs.items()}
    label = "training epochs"
    if sizes:
        size = f"{min(sizes):,.0f}" if same else f"{min(sizes):,.0f} to {max(sizes):,.0f}"
        label += f" ({size} samples each)"
    return label, {k: a["epoch"].astype(float) for k, a in aggs.items()}


def draw_curves(groups: dict[str, list[Path]], title: str = "", metric: str = METRIC, x: str = "auto"):
    """The matplotlib figure of :func:`plot_curves`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    aggs = {label: aggregate(runs, metric) for label, runs in groups.items()}
    xlabel, xs = x_axis(aggs, x)
    fig, ax = plt.subplots(figsize=(5.0, 3.4), dpi=110)
    for label, runs in groups.items():
        agg = aggs[label]
        ok = np.isfinite(agg["mean"])  # a metric logged every few epochs only (greedy evaluations)
        xv, mean, std = xs[label][ok], agg["mean"][ok], agg["std"][ok]
        name = f"{label} ({seeds_label(agg, len(runs))})"
        few = ok.sum() < 40  # points drawn as dots, so that a short run's curve (one epoch, even) shows
        line = ax.plot(xv, mean, label=name, linewidth=1.4, marker="o" if few else None, markersize=3)[0]
        ax.fill_between(xv, mean - std, mean + std, color=line.get_color(), alpha=0.2)
    # From 0, so that a curve of one point spans no zero-width range, whose ticks would crowd into each other
    ax.set_xlim(left=0.0)
    if xlabel.startswith("training epochs"):
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel(xlabel)
    ax.set_ylabel(LABELS.get(metric, metric))
    if title:
        ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, frameon=False)
    fig.tight_layout()
    return fig


def plot_curves(
    groups: dict[str, list[Path]], path: str | os.PathLike, title: str = "", metric: str = METRIC, x: str = "auto"
) -> list[Path]:
    """Mean +- std learning curves of every group, written as ``path`` with ``.png`` and ``.svg`` suffixes.

    ``x``: ``epochs`` (the paper's axis), ``samples``, or ``auto`` (see :func:`x_axis`).
    """
    import matplotlib.pyplot as plt

    fig = draw_curves(groups, title, metric, x)
    path = Path(path)
    written = []
    for suffix in (".png", ".svg"):
        target = path.with_suffix(suffix)
        fig.savefig(target)
        written.append(target)
    plt.close(fig)
    return written


def results_table(groups: dict[str, list[Path]]) -> str:
    """A markdown table of the final greedy evaluations (mean +- std across seeds) and each seed's gradient updates
    (:func:`update_counts`)."""
    lines = [
        "| setting | seeds | greedy return (mean +- std over seeds) | success rate | steps to success "
        "| last-epoch return | gradient updates |",
        "|---|---|---|---|---|---|---|",
    ]
    for label, runs in groups.items():
        evals = [_evaluation(r / "evaluation.json") for r in runs if (r / "evaluation.json").exists()]
        finals, epochs = final_values(runs)
        last = "-"
        if len(finals):
            last = f"{finals.mean():.3f} +- {finals.std():.3f}"
            if epochs.min() != epochs.max():  # an arm still training: say where each seed is
                last += f" (epochs {', '.join(map(str, epochs))})"
        if evals:
            ret = np.array([e["mean_return"] for e in evals])
            per_seed = ", ".join(f"{r:.3f}" for r in ret)
            greedy = f"{ret.mean():.3f} +- {ret.std():.3f} ({len(evals)} evaluated: {per_seed})"
            goals = [rate for rate, _ in map(success_of, evals) if rate is not None]
            steps = [n for _, n in map(success_of, evals) if n is not None]
            goal = f"{np.mean(goals):.3f}" if goals else "-"
            to_goal = f"{np.mean(steps):.1f}" if steps else "-"
        else:
            greedy, goal, to_goal = "not evaluated", "-", "-"
        lines.append(f"| {label} | {len(runs)} | {greedy} | {goal} | {to_goal} | {last} | {update_counts(runs)} |")
    return "\n".join(lines)


def update_counts(runs: list[Path]) -> str:
    """Each run's gradient updates (its epochs' ``train/updates`` summed, what ``model.num_updates`` counts), a run
    that made none flagged ``0 (untrained)``, one that logged no count ``-``."""
    counts = []
    for run in runs:
        _, updates = _read_progress(run, "train/updates")
        logged = updates[np.isfinite(updates)]
        total = int(logged.sum())
        counts.append("-" if not len(logged) else f"{total:,}" if total else "0 (untrained)")
    return ", ".join(counts)


def _evaluation(path: Path) -> dict:
    """A run's ``evaluation.json``, refused with its path where it lacks what the table shows."""
    try:
        result = json.loads(path.read_text())
    except ValueError as exc:
        raise ValueError(f"{path} is not valid JSON ({exc}); expected the evaluation.json pamdp train writes") from exc
    if not isinstance(result, dict) or not isinstance(result.get("mean_return"), (int, float)):
        raise ValueError(f"{path} holds no mean_return; expected the evaluation.json pamdp train writes")
    return result
