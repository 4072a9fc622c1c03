"""A run's summary: the few kilobytes of a run directory that every table and statistic of the results needs.

A run directory holds megabytes (checkpoints, TensorBoard events) and lives outside the repository, where it is
lost with its machine. Its ``summary.json`` keeps what a results table reads: what was run (algorithm, preset,
settings and their digest, env and its arguments, seed, budget, pamdp's version and git commit where ``run.json``
recorded them), what it cost (samples, gradient updates, CPU and wall seconds of training), each greedy evaluation
made during training (samples, mean return, success rate, mean length) and the final greedy evaluation. All of it
is read from the run's ``run.json``, ``progress.csv`` and ``evaluation.json`` by :func:`summarize`, so a summary can
be made of any run tree, old or new; ``pamdp train`` and ``pamdp reproduce`` write one at the end of each run, and
``pamdp summarize`` makes them of existing trees.

The results' summaries are committed under ``docs/results/summaries/EXPERIMENT/ARM/seedN.json`` (:func:`save`),
from which ``docs/gen_results.py`` regenerates the tables of ``docs/results.md``. For runs whose trees were lost
before summaries existed, the benchmark suite's ``suite-finals.json`` entries are converted
(``pamdp.experiments.suite.from_suite_final``): such a summary holds only what the entry recorded, and says so in
``source``.
"""

from __future__ import annotations

import csv
import json
import os
import re
import subprocess
from pathlib import Path

from pamdp.logger import RENAMED, success_of

__all__ = ["FORMAT", "SUMMARY", "git_commit", "summarize", "write_summary", "load", "save", "summary_path"]

FORMAT = 1
"""The summary's format version, kept in each file: a reader refuses a newer one rather than misread it."""
SUMMARY = "summary.json"
SOURCES = ("run directory", "suite-finals.json")
"""Where a summary's figures come from: a run directory (all of them), or an entry of the suite's archive of
per-seed figures (only the final figure and what the entry recorded of the setting)."""
_EVAL_COLUMNS = {key: f"eval/{key}" for key in ("mean_return", "success_rate", "mean_length")}


def git_commit() -> str | None:
    """The commit checked out where pamdp's source lies (changes not committed are not told apart): ``None`` for an
    installed package (even one installed inside another project's repository, whose commit says nothing of
    pamdp's code) or without git."""
    package = Path(__file__).resolve().parents[1]
    try:
        done = subprocess.run(
            ["git", "-C", str(package), "rev-parse", "HEAD", "--show-toplevel"],
            capture_output=True,
            text=True,
            timeout=10,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    lines = done.stdout.split()
    if done.returncode != 0 or len(lines) != 2 or not re.fullmatch(r"[0-9a-f]{40}", lines[0]):
        return None
    return lines[0] if (Path(lines[1]) / "src" / "pamdp").resolve() == package else None


def _number(text: str | None) -> float | None:
    return float(text) if text not in (None, "") else None


def _short(x: float | None) -> float | None:
    """A logged figure to 6 significant digits: a 100-episode mean is not known better, and the file stays small."""
    return None if x is None else float(f"{x:.6g}")


def _relative(run: Path) -> str:
    """A run's directory as the last three parts of its path (``benchmark-suite/PATRPO_on_Goal/seed0``): where it
    lies under the runs' root, without a machine's own path (as the suite's archive names its sources)."""
    return Path(*run.resolve().parts[-3:]).as_posix()


def summarize(run: str | os.PathLike) -> dict:
    """The summary of one run directory (see the module's docstring), read from its ``run.json``, ``progress.csv``
    and ``evaluation.json``; ``None`` stands for what the run did not record (``cpu_seconds`` of runs logged before
    epochs timed their CPU, ``final`` of a run not evaluated at the end). A run's label is the one ``run.json``
    records, else the name of its arm's directory for a run in an experiment's layout (``ARM/seedN``), else its own
    directory's name."""
    from pamdp.experiments.plots import _recorded, run_setting

    run = Path(run)
    recorded = _recorded(run)
    if not recorded.get("algo") or not recorded.get("env"):
        raise ValueError(f"{run} has no run.json naming its algo and env; expected a run directory of pamdp train")
    rows: list[dict] = []
    if (run / "progress.csv").exists():
        with open(run / "progress.csv", newline="") as f:
            rows = list(csv.DictReader(f))
    config = recorded.get("config") if isinstance(recorded.get("config"), dict) else {}

    def total(column: str) -> float | None:
        values = [_number(r.get(column)) for r in rows]
        return None if not rows or any(v is None for v in values) else sum(values)

    evaluations: dict[str, list] = {"samples": []} | {key: [] for key in _EVAL_COLUMNS}
    for r in rows:
        found = {k: _number(r.get(c, r.get(RENAMED.get(c, ""), ""))) for k, c in _EVAL_COLUMNS.items()}
        if all(v is None for v in found.values()):  # an epoch without a greedy evaluation
            continue
        evaluations["samples"].append(int(float(r["time/total_timesteps"])))
        for key, value in found.items():
            evaluations[key].append(_short(value))
    evaluations = {k: v for k, v in evaluations.items() if any(x is not None for x in v) or k == "samples"}
    final = None
    if (run / "evaluation.json").exists():
        result = json.loads((run / "evaluation.json").read_text())
        rate, steps = success_of(result)
        final = {
            "episodes": result.get("episodes"),
            "mean_return": result.get("mean_return"),
            "std_return": result.get("std_return"),
            "mean_length": result.get("mean_length"),
        }
        if rate is not None:
            final.update(success_rate=rate, steps_to_success=steps)
    updates, cpu, wall = total("train/updates"), total("time/epoch_cpu_seconds"), total("time/epoch_seconds")
    samples = int(float(rows[-1]["time/total_timesteps"])) if rows else 0
    budget = recorded.get("total_steps")
    return {
        "format": FORMAT,
        "source": SOURCES[0],
        "origin": _relative(run),
        "label": recorded.get("label") or (run.parent.name if re.fullmatch(r"seed\d+", run.name) else run.name),
        "algo": recorded["algo"],
        "preset": recorded.get("preset"),
        "env": recorded["env"],
        "env_kwargs": recorded.get("env_kwargs") or {},
        "seed": config.get("seed"),
        "total_steps": budget,
        "settings_hash": run_setting(run)["settings"],
        "config": config,
        "pamdp_version": recorded.get("pamdp_version"),
        "git_commit": recorded.get("git_commit"),
        "finished": final is not None or (isinstance(budget, int) and samples >= budget),
        "samples": samples,
        "epochs": len(rows),
        "gradient_updates": None if updates is None else int(updates),
        "cpu_seconds": None if cpu is None else round(cpu, 1),
        "wall_seconds": None if wall is None else round(wall, 1),
        "evaluations": evaluations,
        "final": final,
    }


def write_summary(run: str | os.PathLike, summary: dict | None = None) -> Path:
    """:func:`summarize` ``run`` (or take its ``summary``, made already) into its own ``summary.json``, atomically (a
    kill leaves the old one or none)."""
    from pamdp.atomic import atomic_write_text

    path = Path(run) / SUMMARY
    atomic_write_text(path, json.dumps(summarize(run) if summary is None else summary, indent=1) + "\n")
    return path


def load(path: str | os.PathLike) -> dict:
    """A summary file, checked to be one this version reads: a ``ValueError`` names the file and what is wrong."""
    try:
        summary = json.loads(Path(path).read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise ValueError(f"summary {path}: cannot read it as JSON ({exc})") from None
    if not isinstance(summary, dict) or summary.get("format") != FORMAT:
        got = summary.get("format") if isinstance(summary, dict) else type(summary).__name__
        raise ValueError(f"summary {path}: format {got!r}; expected a pamdp run summary of format {FORMAT}")
    if summary.get("source") not in SOURCES:
        raise ValueError(f"summary {path}: source {summary.get('source')!r}; expected one of {list(SOURCES)}")
    for key, kind, what in (("label", str, "string"), ("env", str, "string"), ("evaluations", dict, "table")):
        if not isinstance(summary.get(key), kind):
            raise ValueError(f"summary {path}: {key} = {summary.get(key)!r}; expected a {what}")
    if not isinstance(summary.get("final"), (dict, type(None))):
        raise ValueError(f"summary {path}: final = {summary.get('final')!r}; expected a table or null")
    return summary


def save(summaries: list[dict], root: str | os.PathLike) -> list[Path]:
    """Each summary as ``root/ARM/seedN.json`` (``ARM``: its label as an experiment names its run's directory),
    refusing two summaries of one arm and seed rather than keep one of them silently."""

    paths: dict[Path, dict] = {}
    for summary in summaries:
        if not isinstance(summary.get("seed"), int):
            raise ValueError(f"the run {summary['origin']} records no seed; expected a run.json with its config")
        path = summary_path(root, summary["label"], summary["seed"])
        if path in paths:
            raise ValueError(
                f"two runs of {summary['label']!r} seed {summary['seed']}: {paths[path]['origin']} and "
                f"{summary['origin']}; expected one run per arm and seed"
            )
        paths[path] = summary
    for path, summary in paths.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(summary, indent=1) + "\n")
    return list(paths)


def summary_path(root: str | os.PathLike, label: str, seed: int) -> Path:
    """Where :func:`save` keeps the summary of run ``label``'s seed ``seed`` under ``root``: ``root/ARM/seedN.json``,
    the layout of an experiment's run directories (``ARM``: the label as a directory name)."""
    return Path(root) / _slug(label) / f"seed{seed}.json"


def _slug(label: str) -> str:
    """A run label as a directory name."""
    return re.sub(r"[^A-Za-z0-9_.=-]+", "_", label)
