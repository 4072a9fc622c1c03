"""Shared by the learning benchmarks: run an experiment file and write a markdown record of it."""

from __future__ import annotations

import argparse
import csv
import datetime as dt
import json
import os
import platform
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from pamdp.experiments import load_experiment
from pamdp.experiments.report import write_report
from pamdp.experiments.runner import is_finished, run_all
from pamdp.experiments.status import epoch_seconds

HERE = Path(__file__).parent


def machine() -> str:
    cpu = "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    import torch

    return (
        f"{cpu}, {os.cpu_count()} cores; Python {platform.python_version()}, NumPy {np.__version__}, "
        f"torch {torch.__version__}; load average at the end {os.getloadavg()[0]:.1f}"
    )


NOTES_HEADING = "## Notes (written by hand"


def record_head(title: str, command: str, rewritten: bool = False) -> list[str]:
    """A record's first lines: its title, the command with the commit it ran at, the date and the machine
    (``rewritten``: the date says the record is rewritten after every finished run)."""
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=HERE)
    date = dt.datetime.now().isoformat(timespec="minutes") + (" (rewritten after every finished run)" * rewritten)
    return [
        f"# {title}",
        "",
        f"- command: `{command}` (commit {commit.stdout.strip()})",
        f"- date: {date}",
        f"- machine: {machine()}",
    ]


def progress_rows(run: Path) -> list[dict]:
    """A run directory's ``progress.csv`` rows (none before its first epoch)."""
    if not (run / "progress.csv").exists():
        return []
    with open(run / "progress.csv", newline="") as f:
        return list(csv.DictReader(f))


def cpu_ms_per_sample(rows: list[dict]) -> float:
    """A run's CPU time in training (its greedy evaluations left out) per sample, in ms, from its rows."""
    return sum(epoch_seconds(r) for r in rows) / float(rows[-1]["time/total_timesteps"]) * 1e3


def where_unfinished(spec, rows: list[dict], metric: str | None = None, digits: int = 2, unit: str = "") -> str:
    """``seed N at S[unit][, greedy V (100 episodes)]``: how far an unfinished run is, with its last greedy
    evaluation of ``metric`` (a progress.csv column) if it has one."""
    evals = [r for r in rows if metric and r.get(metric)]
    last = f", greedy {float(evals[-1][metric]):.{digits}f} (100 episodes)" if evals else ""
    return f"seed {spec.seed} at {int(float(rows[-1]['time/total_timesteps'])):,}{unit}{last}"


def arm_runs(jobs, metric: str, digits: int = 2, unit: str = "") -> tuple[list, list[str]]:
    """An arm's runs as a record table reads them: ``[(seed, evaluation, CPU ms per sample), ...]`` of its finished
    runs (``evaluation.json`` read) and :func:`where_unfinished` (of ``metric``) of each started one."""
    done, partial = [], []
    for spec, out in jobs:
        rows = progress_rows(out)
        if is_finished(out, spec):
            done.append((spec.seed, json.loads((out / "evaluation.json").read_text()), cpu_ms_per_sample(rows)))
        elif rows:
            partial.append(where_unfinished(spec, rows, metric, digits, unit))
    return done, partial


def per_seed(pairs) -> str:
    """``0: 0.999, 1: 0.893``: a figure per seed from ``(seed, figure)`` pairs, ``-`` where there are none."""
    return ", ".join(f"{seed}: {value:.3f}" for seed, value in pairs) or "-"


def median_minutes(runs, total_steps: int) -> str:
    """The median CPU minutes of training a run of ``total_steps`` samples, over :func:`arm_runs`' finished runs."""
    return f"{np.median([cost * total_steps / 6e4 for _, _, cost in runs]):.1f}" if runs else "-"


def run_together(commands: list[list[str]]) -> list[dict]:
    """Start the worker processes ``commands`` and let them time together: each prints ``ready`` once built and
    warmed up, starts on a line ``go`` on its stdin, and ends by printing its result as one JSON line."""
    procs = [subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True) for cmd in commands]
    for proc in procs:
        if proc.stdout.readline().strip() != "ready":
            raise SystemExit(f"a worker failed before timing (exit code {proc.wait()})")
    for proc in procs:
        proc.stdin.write("go\n")
        proc.stdin.flush()
    results = []
    for proc in procs:
        out, _ = proc.communicate()
        if proc.returncode != 0:
            raise SystemExit(f"worker failed with exit code {proc.returncode}")
        results.append(json.loads(out.strip().splitlines()[-1]))
    return results


def hand_notes(record: Path) -> str:
    """The hand-written notes section of an existing record (from its heading to the end), or ``""``.

    A rerun rewrites the generated part of the record and keeps these notes, so resuming a benchmark never
    deletes what was written about it.
    """
    if not record.exists():
        return ""
    text = record.read_text()
    start = text.find(NOTES_HEADING)
    return text[start:].strip() if start >= 0 else ""


def write_record(lines: list[str], record: str | os.PathLike | None) -> str:
    """Print the generated record ``lines`` and, given a ``record`` path, write them there followed by the
    hand-written notes already in it (see :func:`hand_notes`). Returns the generated text."""
    text = "\n".join(lines) + "\n"
    print(text)
    if record:
        notes = hand_notes(Path(record))
        Path(record).write_text(text + (f"\n{notes}\n" if notes else ""))
    return text


def kept_rows(record: str | os.PathLike, labels) -> dict[str, str]:
    """The table rows of the existing ``record`` whose first cell is one of ``labels``, by label: a record
    rewritten from the runs at hand keeps them for the arms whose runs are not there (lost with a machine, or
    under another ``--out``), so that no figure measured earlier is dropped."""
    path, labels = Path(record), set(labels)
    rows = {}
    for line in path.read_text().splitlines() if path.exists() else ():
        cells = line.split("|")
        if line.startswith("| ") and len(cells) > 2 and cells[1].strip() in labels:
            rows[cells[1].strip()] = line
    return rows


def seed_by_seed(
    exp, labels: list[str], seeds: list[int], out_root: str, write, workers: int = 1, train: bool = True
) -> dict:
    """Train the arms ``labels`` of experiment ``exp`` seed by seed across the arms, so that a cut-short invocation
    still compares them, each run resuming from its checkpoint or skipped once finished; ``write(arms)`` rewrites
    the record before and after each seed's runs (``train=False``: only before). ``arms``: ``{label: [(RunSpec,
    run dir), ...]}`` in seed order."""
    jobs = {label: exp.jobs(out_root, exp.specs(seeds, labels=[label])) for label in labels}
    arms = {label: [(spec, Path(out)) for spec, out in pairs] for label, pairs in jobs.items()}
    write(arms)
    for i in range(len(seeds) if train else 0):
        todo = [arms[label][i] for label in labels if not is_finished(arms[label][i][1], arms[label][i][0])]
        if todo:
            run_all([(spec, str(out)) for spec, out in todo], workers=workers)
            write(arms)
    return arms


def seed_by_seed_main(doc: str, exp, write) -> None:
    """The command line of a benchmark made with :func:`seed_by_seed`: ``--runs`` (comma-separated arm labels,
    default every arm of ``exp``), ``--seeds`` (default ``exp``'s), ``--workers``, ``--out`` (the runs' root,
    default ``results/bench``) and ``--record-only`` (train nothing: write the record from the runs under
    ``--out``); ``write(arms, out_root, command)`` rewrites the record."""
    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", default=None, help="comma-separated arm labels (default: all)")
    p.add_argument("--seeds", default=None, help="comma-separated seeds (default: the experiment's)")
    p.add_argument("--workers", type=int, default=1, help="runs side by side in processes")
    p.add_argument("--out", default="results/bench", help="root of the runs")
    p.add_argument("--record-only", action="store_true", help="train nothing, write the record")
    a = p.parse_args()
    seeds = [int(s) for s in a.seeds.split(",")] if a.seeds else list(exp.seeds)
    labels = a.runs.split(",") if a.runs else [run["label"] for run in exp.runs]
    command = "python " + " ".join(sys.argv)
    record = lambda arms: write(arms, a.out, command)  # noqa: E731
    seed_by_seed(exp, labels, seeds, a.out, record, a.workers, train=not a.record_only)


def run_and_record(
    experiment: str,
    out_root: str,
    record: str,
    workers: int,
    scale: float,
    seeds,
    runs=None,
    title=None,
) -> None:
    """Run ``experiment`` (a TOML file next to this script, or a packaged experiment's name such as
    ``platform``), only its arms labelled ``runs`` if given, and write ``record`` with its figures.

    The runs go where ``pamdp reproduce`` puts them (``OUT/NAME/LABEL/seedN``), so a benchmark made of a
    packaged experiment's arm shares its runs with ``pamdp reproduce NAME --out OUT``.
    """
    exp = load_experiment(HERE / experiment if experiment.endswith(".toml") else experiment)
    specs = exp.specs(seeds, scale, runs)
    jobs = exp.jobs(out_root, specs)
    finished_before = all(is_finished(Path(out), spec) for spec, out in jobs)
    t0 = time.time()
    outcomes = run_all(jobs, workers=workers)
    wall = time.time() - t0
    if finished_before and (HERE / record).exists() and not any(o.error for o in outcomes):
        # Every run had finished before: the record already says what they gave, with its own command and date.
        print(json.dumps({"record": str(HERE / record), "unchanged": "every run had finished before"}))
        return
    title = title or exp.description
    if runs is None:
        report = write_report([Path(out_root) / exp.name], Path(out_root) / exp.name, title)
    else:  # the chosen arms alone, reported beside the experiment's own report
        arms = list(dict.fromkeys(exp.run_dir(out_root, s).parent for s in specs))
        report = write_report(arms, Path(out_root) / exp.name / f"report-{Path(record).stem}", title)
    figure = HERE / "results" / f"{Path(record).stem}.png"
    figure.parent.mkdir(exist_ok=True)
    shutil.copy(report["png"], figure)
    greedy_figure = None
    if "greedy_png" in report:  # runs with eval_every: greedy evaluations during training
        greedy_figure = HERE / "results" / f"{Path(record).stem}_greedy.png"
        shutil.copy(report["greedy_png"], greedy_figure)
    per_run = {}  # training time of each run from its own log, so that resumed and skipped runs count too
    for o in outcomes:
        per_run.setdefault(o.spec.label, []).append(sum(map(epoch_seconds, progress_rows(Path(o.out)))))
    lines = record_head(title, f"python {' '.join(sys.argv)}") + [
        f"- {len(jobs)} runs of {jobs[0][0].total_steps:,} steps, {workers} processes at a time"
        + "; this invocation took "
        f"{wall / 60:.1f} min (runs finished by an earlier, interrupted invocation are skipped, partial ones resumed)",
        "- training time of one run (median per setting, from its progress.csv; another run beside it): "
        + ", ".join(f"{k} {np.median(v) / 60:.1f} min" for k, v in per_run.items()),
        "",
        report["table"].read_text().strip(),
        "",
        f"![learning curves](results/{figure.name})",
        "",
        "Greedy return: the mean over 1000 evaluation episodes of each seed's final model, then mean +- std over",
        "seeds. Curves: the mean episodic return of each epoch's (stochastic) training episodes.",
    ]
    if greedy_figure is not None:
        lines += [
            "",
            f"![greedy evaluations during training](results/{greedy_figure.name})",
            "",
            "Greedy evaluations during training: 100 episodes of the greedy policy every few epochs "
            "(`eval_every`), mean +- std over seeds.",
        ]
    failed = [o for o in outcomes if o.error]
    if failed:
        lines += ["", f"{len(failed)} runs failed:"] + [
            f"- {o.out}: {o.error.strip().splitlines()[-1]}" for o in failed
        ]
    notes = hand_notes(HERE / record)
    if notes:
        lines += ["", notes]
    (HERE / record).write_text("\n".join(lines) + "\n")
    print(json.dumps({"record": str(HERE / record), "wall_minutes": wall / 60}))


def main(experiment: str, doc: str, workers: int = 2, runs=None, record=None, title=None) -> None:
    """The command line every learning benchmark shares:
    ``[--workers N] [--scale F] [--seeds 0,1] [--out DIR]``.

    ``experiment``, ``runs`` and ``title`` as in :func:`run_and_record`; ``record`` defaults to the
    experiment file's name with ``.md``.
    """
    import argparse

    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--workers", type=int, default=workers)
    p.add_argument("--scale", type=float, default=1.0)
    p.add_argument("--seeds", default=None)
    p.add_argument("--out", default="results/bench")
    a = p.parse_args()
    seeds = [int(s) for s in a.seeds.split(",")] if a.seeds else None
    record = record or Path(experiment).with_suffix(".md").name
    run_and_record(experiment, a.out, record, a.workers, a.scale, seeds, runs, title)
