"""Tables and figures of results from runs' summaries (:mod:`.summary`), with the statistics of :mod:`.stats`.

A *cell* is the runs of one method on one domain at one setting (budget, preset and settings, as the suite's table
counts seeds: :func:`.suite.suite_groups`). A run's *score* is its final greedy figure: on the benchmark suite's
domains the one HyAR's Table 2 reports (Platform: the return, whose best is 1; elsewhere the success rate), on other
envs the success rate where the env reports one, else the return; a run not evaluated at the end counts with its
last greedy evaluation during training. Scores of different domains share the scale [0, 1] on the suite's domains,
so they are aggregated across domains as they are.

- :func:`stats_table`: per cell, the mean and the interquartile mean of the scores with 95 % stratified bootstrap
  intervals (with one task, the ordinary bootstrap over the runs);
- :func:`aggregate_table`: per method, the IQM and mean over the domains it ran, stratified by domain;
- :func:`improvement_table`: P(X > Y) of every pair of methods on the domains both ran;
- :func:`efficiency_table`: from the greedy curves, the rate at fractions of the budget, the samples to 90 % of the
  best published rate (censored where never reached) and the normalised area under the curve;
- :func:`plot_profiles`: the performance profiles (share of runs above each score) with their bands;
- :func:`plot_efficiency`: the greedy curves over the fraction of the budget, with their bands;
- :func:`plot_domains`: the same curves, a figure per domain, over samples.

An interval over fewer than :data:`MIN_RUNS` runs is not printed: a bootstrap of two runs can only return their
values, a range that says nothing about a third.
"""

from __future__ import annotations

import itertools
import json
import os
from pathlib import Path

import numpy as np

from pamdp.experiments import stats
from pamdp.experiments.suite import DOMAINS, HYAR_TABLE, _describe, domain_of, method_of

__all__ = [
    "MIN_RUNS",
    "FRACTIONS",
    "published_best",
    "score",
    "finals",
    "cells",
    "stats_table",
    "seeds_wanted",
    "backlog_line",
    "runs_line",
    "planned_cells",
    "aggregate_table",
    "aggregate_line",
    "improvement_table",
    "efficiency_table",
    "standing_table",
    "standing_line",
    "plot_profiles",
    "plot_efficiency",
    "plot_domains",
    "domain_figure",
    "greedy_band",
    "report",
]

MIN_RUNS = 3
"""Fewer runs than this in a cell (or across the domains of an aggregate) get no interval."""
FRACTIONS = (0.1, 0.25, 0.5, 1.0)
"""The fractions of the budget at which the greedy curve is read."""
TARGET = 0.9
"""Samples to reach this fraction of the best published rate are counted."""
SEEDS, CHEAP_SEEDS, CHEAP_MINUTES = 5, 10, 10.0
"""Runs a cell is to have (issue 44): 5 (HyAR ran 5), 10 where a run costs under 10 CPU minutes."""


LATER_RESULTS: dict[str, dict[str, float]] = {
    # CHDP (AAAI 2026), success over 5 runs of its own protocol on the same eight domains
    "CHDP": dict(zip((d[0] for d in DOMAINS), (0.997, 0.809, 0.795, 0.938, 0.942, 0.939, 0.906, 0.798))),
    # HyAR-DDPG, the one column of HyAR's Table 2 beside HyAR-TD3 that is best somewhere (Hard Move n=10)
    "HyAR-DDPG": {"Hard Move n=10": 0.82},
    "MP-DQN": {"Platform": 0.987, "Goal": 0.789},  # Bester et al. 2019; Goal from Masson's hand-set start
    "Hybrid SAC": {"Platform": 0.981, "Goal": 0.728},  # Delalleau et al. 2019
}
"""Published success rates beyond :data:`HYAR_TABLE`, by method and domain (DLPA reports returns, not rates)."""


def _curves(runs: list[dict]) -> list[tuple[tuple[np.ndarray, np.ndarray], float]]:
    """``[((samples, figures), budget), ...]`` of the runs that logged greedy evaluations and recorded their budget."""
    curves = [(curve(s), _budget(s)) for s in runs]
    return [(c, b) for c, b in curves if b is not None and np.isfinite(c[1]).any()]


def _best_cells(summaries: list[dict]) -> dict[str, tuple[str, np.ndarray]]:
    """``{domain: (method, scores)}``: on each domain, the main cell of at least :data:`MIN_RUNS` runs with the highest
    IQM."""
    best: dict[str, tuple[str, np.ndarray]] = {}
    for method, domains in _main_cells(summaries).items():
        for domain, scores in domains.items():
            if len(scores) >= MIN_RUNS and (domain not in best or stats.iqm(scores) > stats.iqm(best[domain][1])):
                best[domain] = (method, scores)
    return best


def literature_best(domain: str) -> tuple[str, float] | None:
    """``(method, figure)``: the best success rate published on a suite domain, HyAR's table and the later papers'."""
    found = [(m, float(t[domain].split()[0])) for m, t in HYAR_TABLE.items() if t.get(domain)]
    found += [(m, t[domain]) for m, t in LATER_RESULTS.items() if domain in t]
    return max(found, key=lambda mv: mv[1]) if found else None


def _standing(summaries: list[dict]) -> list[dict]:
    """Per suite domain with a published figure and a cell of :data:`MIN_RUNS` runs: pamdp's best method against
    the best published figure (:func:`standing_table`'s row, as numbers)."""
    rows = []
    best_cells = _best_cells(summaries)
    by_cell = cells(summaries)
    for domain, _, _ in DOMAINS:
        best = literature_best(domain)
        if best is None or domain not in best_cells:
            continue
        method, scores = best_cells[domain]
        est = stats.interval([scores], stats.iqm)
        verdict = "above" if est.low > best[1] else "below" if est.high < best[1] else "within the interval"
        runs = by_cell[(domain, method)]
        curves = _curves(runs)
        times = [stats.samples_to_reach(*c, target=best[1], budget=b) for c, b in curves]
        rows.append(
            dict(
                domain=domain,
                published=best,
                method=method,
                runs=len(runs),
                estimate=est,
                verdict=verdict,
                reached=stats.median_reached(times) if times else None,
                reached_runs=(sum(t.reached for t in times), len(times)),
                budget=next((b for s in runs if (b := _budget(s)) is not None), None),
            )
        )
    return rows


def _samples(row: dict) -> str:
    median = row["reached"]
    if median is None:
        return "- (no curves)"
    return f"{'' if median.reached else '> '}{median.step:,.0f} ({row['reached_runs'][0]} of {row['reached_runs'][1]})"


def standing_table(summaries: list[dict]) -> str:
    """Per suite domain, pamdp's best method (the highest IQM of a main cell of at least :data:`MIN_RUNS` runs) against
    the best published figure: its IQM with the 95 % interval, the verdict the interval gives, and samples: the
    median to reach that figure (the runs with greedy curves) beside its budget."""
    lines = [
        "| domain | best published | pamdp's best | runs | IQM [95 % CI] | against the published | samples to reach "
        "it (median) | pamdp's budget |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in _standing(summaries):
        (source, figure), est, budget = row["published"], row["estimate"], row["budget"]
        lines.append(
            f"| {row['domain']} | {figure:.3f} ({source}) | {row['method']} | {row['runs']} | {est.value:.3f} "
            f"[{est.low:.3f}, {est.high:.3f}] | {row['verdict']} | {_samples(row)} | "
            f"{'-' if budget is None else f'{budget:,.0f}'} |"
        )
    return "\n".join(lines)


def standing_line(summaries: list[dict]) -> str:
    """:func:`standing_table` as one sentence, for a page that has no room for the table."""
    parts, rows = [], _standing(summaries)
    for row in rows:
        (source, figure), est = row["published"], row["estimate"]
        reach, median, (k, n) = "", row["reached"], row["reached_runs"]
        if median is not None:
            reach = (
                f"; median samples to reach it {'' if median.reached else '> '}{median.step:,.0f} of "
                f"{row['budget']:,.0f}, {k} of {n} runs with curves reached it"
            )
        parts.append(
            f"{row['domain']}: {row['method']} **{est.value:.3f} [{est.low:.3f}, {est.high:.3f}]** ({row['runs']} "
            f"runs; {source} {figure:.3f}: {row['verdict']}{reach})"
        )
    verdicts = [row["verdict"] for row in rows]
    counts = ", ".join(f"{verdicts.count(v)} {v}" for v in ("above", "within the interval", "below") if v in verdicts)
    return (
        "Per domain, pamdp's best method against the best published figure, IQM with its 95 % interval over the "
        f"runs ({counts}): " + "; ".join(parts) + "."
    )


def one_preset_table(summaries: list[dict], suite: list[dict]) -> str:
    """One method with one setting on many domains (the runs ``summaries``): per domain its runs' scores, their IQM
    with the 95 % interval, HyAR-TD3's published figure and whether the IQM is at or above it, beside the best main
    cell of the benchmark suite's runs ``suite`` (the domains' own presets). A last line counts the domains met."""
    lines = [
        "| domain | runs | score per seed | IQM [95 % CI] | HyAR-TD3 published | at or above it | the suite's best "
        "cell (its own preset) |",
        "|---|---|---|---|---|---|---|",
    ]
    best = _best_cells(suite)
    met = judged = 0
    for (row, _), runs in cells(summaries).items():
        domain, scores = _domain(runs[0]), np.array([score(s)[0] for s in runs])
        published = HYAR_TABLE["HyAR-TD3"].get(domain)
        figure = float(published.split()[0]) if published else None
        value = stats.iqm(scores)
        verdict = "-" if figure is None else "yes" if value >= figure else f"no ({value - figure:+.2f})"
        judged += figure is not None
        met += figure is not None and value >= figure
        mine = best.get(domain)
        per_seed = ", ".join(f"{s.get('seed')}: {v:.3f}" for s, v in zip(runs, scores))
        lines.append(
            f"| {row} | {len(runs)} | {per_seed} "
            f"| {_estimate([scores], stats.iqm)} | {published or '- (none published)'} | {verdict} "
            f"| {'-' if mine is None else f'{mine[0]}, {stats.iqm(mine[1]):.3f}'} |"
        )
    return (
        "\n".join(lines) + f"\n\nAt or above HyAR-TD3's published rate on {met} of the {judged} domains it has one for."
    )


def published_best(domain: str) -> float | None:
    """The best figure HyAR's Table 2 gives on a suite domain (of any method: HyAR-TD3's on all eight)."""
    found = [float(column[domain].split()[0]) for column in HYAR_TABLE.values() if column.get(domain)]
    return max(found) if found else None


def _domain(summary: dict) -> str:
    """The suite domain a run is on, else its env id (with its arguments)."""
    domain = domain_of({"env": summary["env"], "env_kwargs": summary.get("env_kwargs") or {}})
    if domain is not None:
        return domain
    kwargs = summary.get("env_kwargs")
    return summary["env"] + (" " + json.dumps(kwargs, sort_keys=True) if kwargs else "")


def _uses_return(summary: dict, domain: str) -> bool:
    """Whether a run's score is its return (Platform's, as HyAR's table; an env that reports no success) or its
    success rate."""
    if domain == "Platform":
        return True
    if domain in {d[0] for d in DOMAINS}:
        return False
    final = summary.get("final") or {}
    return "success_rate" not in final and "success_rate" not in summary["evaluations"]


def curve(summary: dict) -> tuple[np.ndarray, np.ndarray]:
    """A run's greedy evaluations during training: their samples and the figure its score is (rate or return)."""
    key = "mean_return" if _uses_return(summary, _domain(summary)) else "success_rate"
    evaluations = summary["evaluations"]
    values = [np.nan if v is None else v for v in evaluations.get(key, [None] * len(evaluations["samples"]))]
    return np.asarray(evaluations["samples"], dtype=float), np.asarray(values, dtype=float)


def score(summary: dict) -> tuple[float, bool] | None:
    """A run's score and whether it is its final evaluation's (else its last greedy evaluation during training);
    ``None`` for a run evaluated neither way."""
    key = "mean_return" if _uses_return(summary, _domain(summary)) else "success_rate"
    final = summary.get("final") or {}
    if final.get(key) is not None:
        return float(final[key]), True
    _, values = curve(summary)
    logged = values[np.isfinite(values)]
    return (float(logged[-1]), False) if len(logged) else None


def finals(summaries: list[dict]) -> list[dict]:
    """The entries of ``suite-finals.json`` (:func:`.suite.suite_finals`) of the summaries of runs on the suite's
    domains, so that the suite's table is the same whether made from run directories or from their summaries."""
    from pamdp.experiments.suite import merge_finals

    entries = []
    suite = {d[0] for d in DOMAINS}
    for (_, method), runs in cells(summaries).items():
        domain = _domain(runs[0])
        if domain not in suite:
            continue
        cell = next((r for r in runs if r.get("total_steps") or r.get("settings_hash")), runs[0])  # its setting
        for s in runs:
            figure = score(s)
            entries.append(
                dict(
                    domain=domain,
                    method=method,
                    seed=s.get("seed"),
                    value=figure[0],
                    final=figure[1],
                    source=s["origin"],
                    total_steps=cell.get("total_steps"),
                    preset=cell.get("preset"),
                    settings=cell.get("settings_hash"),
                )
            )
    return merge_finals(entries, [])


def cells(summaries: list[dict], planned=()) -> dict[tuple[str, str], list[dict]]:
    """``{(row, method): summaries}``: each domain's cells, a method's main setting (its largest budget, then the
    one of most runs) under the domain's name, any other setting under ``"domain: what tells it apart"``, as the
    suite's table labels its rows. An archived figure, whose settings were not kept, counts with its experiment
    cell's runs where they are all of one setting (the archive kept the figures of the settings in use). Domains in
    the suite's order, then others by name; methods by name. ``planned``: ``(domain, method)`` cells
    (:func:`planned_cells`) that get a cell of no runs where they have none."""
    groups: dict[tuple[str, str], dict[tuple, list[dict]]] = {}
    unrecorded = []
    for s in summaries:
        if score(s) is None:
            continue
        setting = (s.get("total_steps"), s.get("preset"), s.get("settings_hash"))
        if setting == (None, None, None):  # an archived figure: its run's settings were not kept
            unrecorded.append(s)
            continue
        domain = _domain(s)
        groups.setdefault((domain, method_of(s["label"], domain)), {}).setdefault(setting, []).append(s)
    for s in unrecorded:  # with the runs of the same experiment's cell, where it has runs of one setting only
        domain = _domain(s)
        recorded = groups.setdefault((domain, method_of(s["label"], domain)), {})
        same = {st for st, runs in recorded.items() if any(r["label"] == s["label"] for r in runs)}
        recorded.setdefault(same.pop() if len(same) == 1 and len(recorded) == 1 else (None, None, None), []).append(s)
    for cell in planned:  # an experiment's cell that has not run: a row of no runs, where it would stand
        if cell not in groups:
            groups[cell] = {(None, None, None): []}
    order = {d[0]: i for i, d in enumerate(DOMAINS)}
    out: dict[tuple[str, str], list[dict]] = {}
    for domain, method in sorted(groups, key=lambda k: (order.get(k[0], len(order)), k[0], k[1])):
        settings = sorted(groups[(domain, method)].items(), key=lambda kv: (kv[0][0] or 0, len(kv[1])), reverse=True)
        for i, (setting, runs) in enumerate(settings):
            others = [st for st, _ in settings if st != setting]
            row = domain if i == 0 else f"{domain}: {_describe(setting, others)}"
            out[(row, method)] = sorted(runs, key=lambda s: (s.get("seed") is None, s.get("seed") or 0))
    return out


def planned_cells(specs) -> list[tuple[str, str]]:
    """The ``(domain, method)`` cells an experiment's runs define (its :class:`.runner.RunSpec` s), in their order:
    what :func:`stats_table` owes runs for even before any has run."""
    planned: list[tuple[str, str]] = []
    for spec in specs:
        domain = _domain({"env": spec.env, "env_kwargs": dict(spec.env_kwargs)})
        cell = (domain, method_of(spec.label, domain))
        if cell not in planned:
            planned.append(cell)
    return planned


def _main_cells(summaries: list[dict]) -> dict[str, dict[str, np.ndarray]]:
    """``{method: {domain: scores}}`` of each method's main setting on each domain."""
    by_method: dict[str, dict[str, np.ndarray]] = {}
    for (row, method), runs in cells(summaries).items():
        if row == _domain(runs[0]):
            by_method.setdefault(method, {})[row] = np.array([score(s)[0] for s in runs])
    return by_method


def _estimate(tasks: list[np.ndarray], statistic) -> str:
    """``0.950 [0.948, 0.952]``, or the point estimate alone where the runs are too few for an interval."""
    value = stats.aggregate(tasks, statistic)
    if sum(map(len, tasks)) < MIN_RUNS or min(map(len, tasks)) < 2:
        return f"{value:.3f} (no interval: n < {MIN_RUNS})" if len(tasks) == 1 else f"{value:.3f}"
    est = stats.interval(tasks, statistic)
    return f"{est.value:.3f} [{est.low:.3f}, {est.high:.3f}]"


def _cpu_minutes(runs: list[dict]) -> float | None:
    """The median CPU minutes a run of the runs that recorded their cost (archived figures did not): its training
    epochs' CPU time (the summary's ``cpu_seconds``), greedy evaluations not counted."""
    costs = [s["cpu_seconds"] / 60 for s in runs if isinstance(s.get("cpu_seconds"), (int, float))]
    return float(np.median(costs)) if costs else None


def seeds_wanted(cpu_minutes: float | None) -> int:
    """The runs a cell is to have: :data:`CHEAP_SEEDS` where a run costs under :data:`CHEAP_MINUTES` of CPU,
    :data:`SEEDS` otherwise (or where no run recorded its cost)."""
    return CHEAP_SEEDS if cpu_minutes is not None and cpu_minutes < CHEAP_MINUTES else SEEDS


def stats_table(summaries: list[dict], planned=()) -> str:
    """Per cell: its runs, the mean and the IQM of their scores with 95 % bootstrap intervals, how many are still
    training (counted with their last greedy evaluation), the sample efficiency of its runs with greedy curves (as
    :func:`efficiency_table`), the median CPU minutes a run and the runs it still owes (:func:`seeds_wanted`); below
    it, the backlog in all (:func:`backlog_line`). ``planned``: the experiment's ``(domain, method)`` cells
    (:func:`planned_cells`); one with no runs yet gets a row of its own, owing them all."""
    lines = [
        "| domain | method | runs | mean [95 % CI] | IQM [95 % CI] | published best | samples to "
        f"{TARGET * 100:g} % of it (median) | normalised AUC | CPU min a run | runs owed |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    backlog = []
    for (row, method), runs in cells(summaries, planned).items():
        minutes, owed = _owed(runs)
        backlog.append((minutes, owed, len(runs), f"{method} on {row}"))
        if not runs:
            best = published_best(row)
            lines.append(
                f"| {row} | {method} | 0 (never run) | - | - | {'' if best is None else f'{best:.2f}'} | - | - | - | "
                f"{owed} |"
            )
            continue
        scores = np.array([score(s)[0] for s in runs])
        partial = sum(not score(s)[1] for s in runs)
        n = f"{len(runs)}" + (f" ({partial} partial*)" if partial else "")
        best = published_best(_domain(runs[0]))
        mean, mid = _estimate([scores], np.mean), _estimate([scores], stats.iqm)
        cost = "-" if minutes is None else f"{minutes:.1f}"
        reach, auc = _reach_and_auc(runs, _curves(runs))
        lines.append(
            f"| {row} | {method} | {n} | {mean} | {mid} | {'' if best is None else f'{best:.2f}'} | {reach} | {auc} | "
            f"{cost} | {owed or '-'} |"
        )
    return "\n".join(lines) + "\n\n" + _backlog_text(backlog)


def _owed(runs: list[dict]) -> tuple[float | None, int]:
    """A cell's median CPU minutes a run (:func:`_cpu_minutes`) and the runs it still owes (:func:`seeds_wanted`)."""
    minutes = _cpu_minutes(runs)
    return minutes, max(0, seeds_wanted(minutes) - len(runs))


def backlog_line(summaries: list[dict], planned=()) -> str:
    """The runs the cells still owe in all (:func:`seeds_wanted`), and what they cost at each cell's median CPU
    minutes a run, apart from those of cells where no run recorded its cost and of the ``planned`` cells never run
    (:func:`stats_table`)."""
    cells_owed = cells(summaries, planned).items()
    return _backlog_text([(*_owed(runs), len(runs), f"{method} on {row}") for (row, method), runs in cells_owed])


def runs_line(summaries: list[dict], planned=()) -> str:
    """One sentence of each method's runs a cell (its main setting on each domain, as :func:`cells`, and the
    ``planned`` cells never run, as 0), then the backlog (:func:`backlog_line`): the counts a page states without a
    table."""
    counts: dict[str, list[int]] = {}
    for (row, method), runs in cells(summaries, planned).items():
        if not runs or row == _domain(runs[0]):
            counts.setdefault(method, []).append(len(runs))
    parts = []
    for method, found in sorted(counts.items()):
        low, high = min(found), max(found)
        spread = f"{low}" if low == high else f"{low} to {high}"
        parts.append(f"{method} {spread} on {len(found)} domain{'s' * (len(found) > 1)}")
    return f"Runs a cell: {'; '.join(parts)}. {backlog_line(summaries, planned)}"


def _backlog_text(cells_owed: list[tuple[float | None, int, int, str]]) -> str:
    """:func:`backlog_line` of the cells' ``(median CPU minutes a run, runs owed, runs made, name)``."""
    owed = [(cost, n, made, name) for cost, n, made, name in cells_owed if n]
    if not owed:
        return "Runs owed: none."
    unrun = [(n, name) for cost, n, made, name in owed if not made]
    unpriced = sum(n for cost, n, made, _ in owed if cost is None and made)
    minutes = sum(n * cost for cost, n, _, _ in owed if cost is not None)
    priced = sum(n for cost, n, _, _ in owed if cost is not None)
    text = f"Runs owed: {sum(n for _, n, _, _ in owed)} over {len(owed)} cell{'s' * (len(owed) > 1)}"
    if priced:
        text += f"; the {priced} in cells that recorded their cost, about {minutes / 60:.1f} CPU hours at those costs"
    if unpriced:
        text += f"; {unpriced} in cells whose runs recorded none (archived figures)"
    if unrun:
        names = ", ".join(name for _, name in unrun)
        text += f"; {sum(n for n, _ in unrun)} in {len(unrun)} cell{'s' * (len(unrun) > 1)} never run ({names})"
    return text + "."


def _stratified(by_domain: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The domains of a method with at least 2 runs: a stratified bootstrap resamples within each."""
    return {d: x for d, x in by_domain.items() if len(x) >= 2}


def _comparable(
    summaries: list[dict],
) -> tuple[dict[str, dict[str, np.ndarray]], list[str], dict[str, list[np.ndarray]]]:
    """Each method's scores on the domains where it has 2 runs or more (its main setting's); the domains the
    methods share, in the suite's order: those of the method of most domains, narrowed by each other method's in turn
    (most domains first) where that leaves some; and the scores on those domains of each method that has them all.
    A method that ran none of them (P-DQN on Hard Move alone, beside methods that share Platform to Catch Point)
    stays out of the shared comparison instead of emptying it."""
    by_method = {m: _stratified(d) for m, d in _main_cells(summaries).items()}
    by_method = {m: d for m, d in by_method.items() if d}
    shared: set[str] | None = None
    for _, domains in sorted(((m, set(d)) for m, d in by_method.items()), key=lambda md: (-len(md[1]), md[0])):
        if shared is None or shared & domains:
            shared = domains if shared is None else shared & domains
    shared = shared or set()
    order = [d[0] for d in DOMAINS]
    shared = sorted(shared, key=lambda d: (order.index(d) if d in order else len(order), d))
    on_shared = {m: [d[x] for x in shared] for m, d in by_method.items() if shared and set(shared) <= set(d)}
    return by_method, shared, on_shared


def aggregate_table(summaries: list[dict]) -> str:
    """Per method: the IQM and mean of its runs over the domains where it has 2 runs or more (its main setting's),
    stratified by domain, and over the domains that every method has so (the only comparison of like with like)."""
    by_method, shared, on_shared = _comparable(summaries)
    lines = [
        f"| method | domains | runs | IQM [95 % CI] | mean [95 % CI] | IQM on the {len(shared)} shared domains "
        "[95 % CI] |",
        "|---|---|---|---|---|---|",
    ]
    for method, by_domain in by_method.items():
        tasks = list(by_domain.values())
        mine = on_shared.get(method)
        lines.append(
            f"| {method} | {len(tasks)} | {sum(map(len, tasks))} | {_estimate(tasks, stats.iqm)} | "
            f"{_estimate(tasks, np.mean)} | {_estimate(mine, stats.iqm) if mine else '-'} |"
        )
    return "\n".join(lines) + (f"\n\nShared domains: {', '.join(shared)}." if shared else "")


def aggregate_line(summaries: list[dict]) -> str:
    """One sentence of :func:`aggregate_table`: each method's IQM over its domains, best first, then on the shared
    domains (for a page that has no room for the table)."""
    by_method, shared, on_shared = _comparable(summaries)

    def listing(tasks_of: dict[str, list[np.ndarray]]) -> str:
        found = sorted(tasks_of.items(), key=lambda mt: -stats.aggregate(mt[1]))
        parts = [
            f"{method} **{_estimate(tasks, stats.iqm)}** ({len(tasks)} domain{'s' * (len(tasks) > 1)}, "
            f"{sum(map(len, tasks))} runs)"
            for method, tasks in found
        ]
        return "; ".join(parts)

    text = (
        "IQM of the final figures with 95 % stratified bootstrap intervals, over the domains where a method has 2 "
        f"runs or more: {listing({m: list(d.values()) for m, d in by_method.items()})}."
    )
    if not shared:
        return text
    apart = sorted(by_method.keys() - on_shared.keys())
    return (
        f"{text} On the {len(shared)} domains {'they' if apart else 'all'} share ({', '.join(shared)}): "
        f"{listing(on_shared)}" + (f" ({', '.join(apart)}: not on all of them)." if apart else ".")
    )


def improvement_table(summaries: list[dict]) -> str:
    """P(X > Y) with its 95 % interval for every pair of methods, on the domains where both have 2 runs or more."""
    by_method = {m: _stratified(d) for m, d in _main_cells(summaries).items()}
    lines = ["| X | Y | domains | runs of X, of Y | P(X > Y) [95 % CI] |", "|---|---|---|---|---|"]
    for x, y in itertools.combinations(sorted(by_method), 2):
        shared = sorted(set(by_method[x]) & set(by_method[y]))
        if not shared:
            continue
        xs, ys = [by_method[x][d] for d in shared], [by_method[y][d] for d in shared]
        nx, ny = sum(map(len, xs)), sum(map(len, ys))
        if min(nx, ny) < MIN_RUNS:
            continue
        est = stats.probability_of_improvement(xs, ys)
        p = f"{est.value:.2f} [{float(est.low):.2f}, {float(est.high):.2f}]"
        lines.append(f"| {x} | {y} | {len(shared)} | {nx}, {ny} | {p} |")
    return "\n".join(lines)


def _budget(summary: dict) -> float | None:
    budget = summary.get("total_steps")
    return float(budget) if isinstance(budget, int) and budget > 0 else None


def _reach_and_auc(runs: list[dict], curves: list) -> tuple[str, str]:
    """The median samples to reach :data:`TARGET` of the best figure of HyAR's table (``"> N"`` where the median run
    was censored, with how many runs reached it) and the mean normalised AUC of a cell's runs with ``curves``."""
    if not curves:
        return "- (no curves)", "-"
    auc = np.mean([stats.normalised_auc(*c, budget=b) for c, b in curves])
    best = published_best(_domain(runs[0]))
    if best is None:
        return "-", f"{auc:.2f}"
    times = [stats.samples_to_reach(*c, target=TARGET * best, budget=b) for c, b in curves]
    median = stats.median_reached(times)
    count = f"{sum(t.reached for t in times)} of {len(times)} reached"
    return f"{'' if median.reached else '> '}{median.step:,.0f} ({count})", f"{auc:.2f}"


def efficiency_table(summaries: list[dict]) -> str:
    """Per cell with greedy curves: the mean over runs of the greedy figure at 10, 25, 50 and 100 % of the budget,
    the median samples to reach 90 % of the best published figure (:func:`.stats.median_reached`: ``>`` where the
    median run did not reach it within the budget, with how many did) and the mean normalised area under the
    curve. Cells whose runs logged no greedy evaluation during training (or whose summaries came from an archive
    that kept only final figures) are left out."""
    head = " / ".join(f"{f * 100:g}" for f in FRACTIONS) + " %"
    lines = [
        f"| domain | method | runs with curves | greedy figure at {head} of the budget | "
        f"samples to {TARGET * 100:g} % of the published best | normalised AUC |",
        "|---|---|---|---|---|---|",
    ]
    for (row, method), runs in cells(summaries).items():
        curves = _curves(runs)
        if not curves:
            continue
        with np.errstate(all="ignore"):
            at = np.array([stats.rate_at_fractions(*c, budget=b, fractions=FRACTIONS) for c, b in curves])
            rates = " / ".join("-" if np.isnan(col).all() else f"{np.nanmean(col):.2f}" for col in at.T)
        reach, auc = _reach_and_auc(runs, curves)
        lines.append(f"| {row} | {method} | {len(curves)} | {rates} | {reach} | {auc} |")
    return "\n".join(lines)


def plot_profiles(summaries: list[dict], path: str | os.PathLike, title: str = "") -> list[Path]:
    """The performance profile of each method over the domains every method has 2 runs or more on (a profile over
    other domains would compare other tasks): the share of its runs scoring above each threshold, each domain
    weighing the same (:func:`.stats.performance_profile`), with the 95 % stratified bootstrap band; ``path`` with
    ``.png`` and ``.svg`` suffixes (nothing without such a domain)."""
    _, shared, on_shared = _comparable(summaries)
    if not shared:
        return []
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scores = np.concatenate([x for tasks in on_shared.values() for x in tasks])
    tau = np.linspace(min(0.0, scores.min()), max(1.0, scores.max()), 101)
    fig, ax = plt.subplots(figsize=(5.0, 3.4), dpi=110)
    for method, tasks in on_shared.items():
        profile = stats.performance_profile(tasks, tau)
        runs = sum(map(len, tasks))
        line = ax.plot(tau, profile.fraction, label=f"{method} ({runs} runs)", linewidth=1.4, color=_colour(method))[0]
        ax.fill_between(tau, profile.low, profile.high, color=line.get_color(), alpha=0.2, step=None)
    ax.set_xlabel("score tau (success rate; Platform: return)")
    ax.set_ylabel("share of runs above tau\n(each domain weighing the same)", fontsize=9)
    ax.set_title(title or f"over {', '.join(shared)}", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, frameon=False)
    fig.tight_layout()
    return _save(fig, path)


METHOD_COLOURS = ("HyAR-TD3", "Hybrid SAC", "MP-DQN", "PATRPO", "P-DQN")
"""The suite's methods, each drawn in its own colour of Matplotlib's cycle in every panel and figure."""


def _colour(method: str) -> str:
    """A method's colour: the same in every panel (the methods a panel lacks do not shift the others')."""
    known = METHOD_COLOURS.index(method) if method in METHOD_COLOURS else None
    return f"C{known if known is not None else len(METHOD_COLOURS) + sum(map(ord, method)) % 5}"


def _save(fig, path: str | os.PathLike) -> list[Path]:
    """``fig`` as ``path`` with ``.png`` and ``.svg`` suffixes (the SVG without a date and with element ids from a
    fixed salt, so that the same figure redraws to the same file)."""
    import matplotlib
    import matplotlib.pyplot as plt

    written = []
    for suffix in (".png", ".svg"):
        target = Path(path).with_suffix(suffix)
        with matplotlib.rc_context({"svg.hashsalt": "pamdp"}):
            fig.savefig(target, metadata={"Date": None} if suffix == ".svg" else None)
        written.append(target)
    plt.close(fig)
    return written


def _greedy_cells(summaries: list[dict]) -> dict[str, dict[str, tuple[list, int]]]:
    """``{domain: {method: (curves, runs)}}``: each domain's main cells whose runs logged greedy curves
    (:func:`_curves`), with the cell's number of runs (archived runs kept no curve)."""
    by_domain: dict[str, dict[str, tuple[list, int]]] = {}
    for (row, method), runs in cells(summaries).items():
        curves = _curves(runs)
        if curves and row == _domain(runs[0]):
            by_domain.setdefault(row, {})[method] = (curves, len(runs))
    return by_domain


def greedy_band(curves: list, points: np.ndarray, relative: bool) -> dict[str, np.ndarray]:
    """A cell's greedy curve at ``points`` (fractions of each run's budget where ``relative``, else samples): the
    mean over runs of each run's last evaluation made by then, and the 95 % bootstrap interval of that mean where
    the cell has :data:`MIN_RUNS` runs or more (else NaN). ``seen``: the points where every run had been evaluated
    and none had yet stopped (a run still training stops one evaluation interval after its last evaluation), so
    the mean is always over all the cell's runs."""
    at = []
    for (steps, values), budget in curves:
        limits = points * budget if relative else points
        row = stats.rate_at_fractions(steps, values, budget=1.0, fractions=limits)
        done = steps[np.isfinite(values)]
        gap = np.median(np.diff(done)) if len(done) > 1 else 0.0
        row[limits > done[-1] + gap] = np.nan  # past the run's last evaluation: not known yet
        at.append(row)
    at = np.array(at)
    seen = ~np.isnan(at).any(axis=0)
    mean = np.full(len(points), np.nan)
    low, high = mean.copy(), mean.copy()
    mean[seen] = at[:, seen].mean(axis=0)
    if len(curves) >= MIN_RUNS:
        for i in np.flatnonzero(seen):
            band = stats.interval([at[:, i]], np.mean, resamples=500)
            low[i], high[i] = band.low, band.high
    return {"seen": seen, "mean": mean, "low": low, "high": high}


def _draw_greedy(ax, domain: str, methods: dict[str, tuple[list, int]], points: np.ndarray, relative: bool):
    """One domain's panel: each method's :func:`greedy_band` (the legend says how many of the cell's runs logged
    curves) and the :data:`TARGET` share of the best figure of HyAR's table, dashed."""
    for method, (curves, runs) in methods.items():
        band = greedy_band(curves, points, relative)
        seen = band["seen"]
        count = f"{len(curves)}" if len(curves) == runs else f"{len(curves)} of {runs}"
        ax.plot(points[seen], band["mean"][seen], label=f"{method} ({count})", linewidth=1.2, color=_colour(method))
        if len(curves) >= MIN_RUNS:
            ax.fill_between(points[seen], band["low"][seen], band["high"][seen], color=_colour(method), alpha=0.2)
    best = published_best(domain)
    if best is not None:
        ax.axhline(TARGET * best, color="grey", linestyle="--", linewidth=0.8)
    ax.grid(alpha=0.3)


def plot_efficiency(summaries: list[dict], path: str | os.PathLike) -> list[Path]:
    """The greedy curves of each cell with curves, a panel per domain, over the fraction of the budget: the mean over
    runs of the last evaluation made by each fraction, with the 95 % bootstrap band of that mean where the cell has
    :data:`MIN_RUNS` runs or more (:func:`greedy_band`), and the 90 % of the best published figure that the
    efficiency table counts the samples to; ``path`` with ``.png`` and ``.svg`` suffixes (nothing where no run
    logged a curve)."""
    by_domain = _greedy_cells(summaries)
    if not by_domain:
        return []
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    grid = np.linspace(0.02, 1.0, 50)
    cols = min(len(by_domain), 4)
    rows = -(-len(by_domain) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(2.6 * cols, 2.3 * rows), dpi=110, squeeze=False, sharex=True)
    for ax, (domain, methods) in zip(axes.flat, by_domain.items()):
        _draw_greedy(ax, domain, methods, grid, relative=True)
        ax.set_title(domain, fontsize=9)
        ax.legend(fontsize=7, frameon=False)
    for ax in axes.flat[len(by_domain) :]:
        ax.axis("off")
    fig.supxlabel("fraction of the budget", fontsize=9)
    fig.supylabel("greedy figure", fontsize=9)
    fig.suptitle(f"greedy evaluations (dashed: {TARGET * 100:g} % of the best figure of HyAR's table)", fontsize=9)
    fig.tight_layout()
    return _save(fig, path)


def domain_figure(domain: str) -> str:
    """The file name (no suffix) of a suite domain's figure: ``domain-hard-move-n8`` for ``Hard Move n=8``."""
    return "domain-" + domain.lower().replace(" ", "-").replace("=", "")


def plot_domains(summaries: list[dict], out: str | os.PathLike) -> list[Path]:
    """A figure per suite domain whose runs logged greedy curves (:func:`domain_figure` ``.png`` and ``.svg`` in
    ``out``): each method's greedy success rate (Platform: return) over environment samples, the mean over its
    runs with the 95 % bootstrap band (:func:`greedy_band`), and the :data:`TARGET` share of the best figure of
    HyAR's table, dashed. The panels of :func:`plot_efficiency`, one domain at a time and in samples."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import EngFormatter

    written = []
    suite = {d[0] for d in DOMAINS}
    for domain, methods in _greedy_cells(summaries).items():
        if domain not in suite:
            continue
        budget = max(b for curves, _ in methods.values() for _, b in curves)
        points = np.linspace(0.02, 1.0, 50) * budget
        fig, ax = plt.subplots(figsize=(6.4, 3.2), dpi=110)
        _draw_greedy(ax, domain, methods, points, relative=False)
        ax.set_title(domain)
        ax.set_xlabel("environment samples")
        ax.xaxis.set_major_formatter(EngFormatter(sep=""))
        figure = "return" if domain == "Platform" else "success rate"
        ax.set_ylabel(f"greedy {figure}\n(100 episodes)")
        ax.legend(
            loc="upper left",
            bbox_to_anchor=(1.01, 1.0),
            fontsize=8,
            frameon=False,
            title=f"runs with curves\n(dashed: {TARGET * 100:g} % of\nHyAR's best figure)",
            title_fontsize=7,
        )
        fig.tight_layout()
        written += _save(fig, Path(out) / domain_figure(domain))
    return written


def report(summaries: list[dict], planned=()) -> str:
    """The statistics of a set of runs as one markdown page: per cell (with the ``planned`` ones never run, as
    :func:`stats_table`), across domains, pairwise and over samples."""
    parts = [
        "Per method and domain (each method's runs of one setting; scores: success rate, Platform's return):",
        stats_table(summaries, planned),
        "Across domains (stratified by domain):",
        aggregate_table(summaries),
        "Probability of improvement (a run of X beats a run of Y; 0.5: neither tends to do better):",
        improvement_table(summaries),
        "Sample efficiency (greedy evaluations during training):",
        efficiency_table(summaries),
    ]
    return "\n\n".join(parts) + "\n"
