"""An experiment's report: its figures, per-epoch aggregate and results table (:mod:`pamdp.experiments.plots`),
and for runs on the benchmark suite's domains their table beside HyAR's (:mod:`pamdp.experiments.suite`)."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path

import numpy as np

from pamdp.experiments import results
from pamdp.experiments.plots import EXTRA_FIGURES, aggregate, find_groups, plot_curves, results_table
from pamdp.experiments.suite import from_suite_final, load_finals, merge_finals, suite_finals, suite_table
from pamdp.experiments.summary import summarize

__all__ = ["write_report"]


def write_report(
    roots: list[str | os.PathLike],
    out: str | os.PathLike,
    title: str = "",
    x: str = "auto",
    suite_archive: str | os.PathLike | None = None,
    planned=(),
) -> dict[str, Path]:
    """Curves (PNG, SVG), the per-epoch aggregate (CSV) and the results table (markdown) into ``out``.

    ``x``: the curves' x axis, as in :func:`plot_curves`.

    Runs that logged greedy evaluations during training (``eval_every``) also get ``greedy.png`` and
    ``greedy.svg``: the mean +- std across seeds of those evaluations, at the epochs where they were made. Runs on
    an env that reports episode outcomes (``info["is_success"]``) get ``success_rate.png`` and ``.svg``: the
    training success rate per epoch (epochs logged before a run recorded it are left out), and with
    ``eval_every`` ``greedy_success_rate.png`` and ``.svg``, that of the greedy evaluations. Runs on the benchmark
    suite's domains also get ``suite.md``, their table beside HyAR's published one, ``suite-finals.json``, each
    seed's figure (:mod:`pamdp.experiments.suite`), and a figure per domain of their greedy curves with 95 % bands
    (``domain-NAME.png`` and ``.svg``, :func:`.results.plot_domains`). ``suite_archive``: an earlier
    ``suite-finals.json``, whose entries fill the table where no run at hand has their domain, method and seed.

    ``stats.md`` holds the statistics of the runs' final figures (:func:`.results.report`: means and interquartile
    means with bootstrap intervals per method and domain, across domains, the probability of improvement between
    methods, and the sample efficiency of the greedy curves), ``profiles.png`` and ``.svg`` the performance
    profiles of the methods over the domains they all ran, and ``efficiency.png`` and ``.svg`` the greedy curves over
    the fraction of the budget. ``planned``: the experiment's ``(domain, method)`` cells
    (:func:`.results.planned_cells`), so that those not run yet count in the runs owed.
    """
    archived = [] if suite_archive is None else load_finals(suite_archive)  # checked before anything is written
    groups = find_groups(roots)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    png, svg = plot_curves(groups, out / "curves", title, x=x)
    extra = {}
    for name, metric, (png_key, svg_key) in EXTRA_FIGURES:
        logged = {label: runs for label, runs in groups.items() if np.isfinite(aggregate(runs, metric)["mean"]).any()}
        if logged:
            extra[png_key], extra[svg_key] = plot_curves(logged, out / name, title, metric, x)
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
    finals = merge_finals(suite_finals(groups), archived)
    summaries = _summaries(groups, archived)
    if summaries:  # the statistics: intervals over runs, across domains, pairwise and over samples
        (out / "stats.md").write_text(results.report(summaries, planned))
        extra["stats"] = out / "stats.md"
        extra.update({f"profiles_{p.suffix[1:]}": p for p in results.plot_profiles(summaries, out / "profiles")})
        extra.update({f"efficiency_{p.suffix[1:]}": p for p in results.plot_efficiency(summaries, out / "efficiency")})
        extra.update({f"{p.stem}_{p.suffix[1:]}": p for p in results.plot_domains(summaries, out)})  # suite domains
    if finals:  # runs on the benchmark suite's domains: their table beside HyAR's
        (out / "suite.md").write_text(suite_table(finals) + "\n")
        (out / "suite-finals.json").write_text(json.dumps(finals, indent=1) + "\n")
        extra["suite"], extra["suite_finals"] = out / "suite.md", out / "suite-finals.json"
    return {"png": png, "svg": svg, "csv": csv_path, "table": table, **extra}


def _summaries(groups: dict[str, list[Path]], archived: list[dict]) -> list[dict]:
    """The summaries of the runs at hand that record their algorithm and env, and of the archived suite entries of
    final figures whose domain, method and seed no run at hand has."""
    from pamdp.experiments.plots import _recorded

    at_hand = [
        {**summarize(run), "label": recorded.get("label") or label}  # as the figures and tables name the run
        for label, runs in groups.items()
        for run in runs
        if {"algo", "env"} <= set(recorded := _recorded(run))
    ]
    have = {(e["domain"], e["method"], e["seed"]) for e in results.finals(at_hand)}
    kept = [e for e in archived if e["final"] and (e["domain"], e["method"], e["seed"]) not in have]
    return at_hand + [from_suite_final(e) for e in kept]
