"""The benchmark suite's table and curves: each domain's measured success rates beside HyAR's published ones.

``pamdp reproduce benchmark-suite`` names its runs ``"METHOD on DOMAIN"``; :func:`suite_table` finds each run's
domain from the env (and its arguments) its ``run.json`` records, and its method from the label. A finished run
counts with its final evaluation (1000 greedy episodes); a run still training with its last greedy evaluation
during training (100 episodes), marked as such. Platform's figure is the return, as in HyAR's table; the
others' the success rate (``info["is_success"]``).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from pamdp.algos.logger import success_of

__all__ = ["DOMAINS", "HYAR_TABLE", "domain_of", "suite_cells", "suite_table", "plot_domains"]

DOMAINS: tuple[tuple[str, str, dict], ...] = (
    ("Platform", "pamdp/Platform-v0", {}),
    ("Goal", "pamdp/Goal-v0", {}),
    ("Hard Goal", "pamdp/HardGoal-v0", {}),
    ("Catch Point", "pamdp/CatchPoint-v0", {}),
    *((f"Hard Move n={n}", "pamdp/HardMove-v0", {"n": n}) for n in (4, 6, 8, 10)),
)
"""``(name, env id, env arguments)`` of the eight domains of HyAR's Table 2, in its order."""

# HyAR's Table 2 (Li et al., ICLR 2022), as ../shared/specs/benchmarks.md gives it: mean +- std over 5 runs
# (std where the table gives one). The methods nearest pamdp's: P-DQN (MP-DQN), HPPO (PATRPO, PAPPO), HyAR-TD3.
HYAR_TABLE: dict[str, dict[str, str]] = {
    "HyAR-TD3": dict(
        zip(
            (d[0] for d in DOMAINS),
            ("0.98 +- 0.01", "0.78 +- 0.03", "0.60 +- 0.07", "0.90 +- 0.03")
            + ("0.93 +- 0.02", "0.92 +- 0.04", "0.89 +- 0.03", "0.75 +- 0.05"),
        )
    ),
    "PDQN": dict(
        zip((d[0] for d in DOMAINS), ("0.93 +- 0.05", "0.70 +- 0.07", "0.0", "0.77", "0.69", "0.41", "0.04", "0.06"))
    ),
    "HPPO": dict(zip((d[0] for d in DOMAINS), ("0.80 +- 0.02", "0.0", "0.0", "0.69", "0.09", "0.05", "0.04", "0.05"))),
}


def domain_of(recorded: dict) -> str | None:
    """The suite domain a run's ``run.json`` describes (``None`` for an env outside it)."""
    for name, env, kwargs in DOMAINS:
        if recorded.get("env") == env and (recorded.get("env_kwargs") or {}) == kwargs:
            return name
    return None


def _figure(run: Path, domain: str) -> tuple[float, bool] | None:
    """A run's success rate (Platform: return) and whether it is final: its evaluation's, else its last greedy
    evaluation during training, else ``None``."""
    platform = domain == "Platform"
    if (run / "evaluation.json").exists():
        result = json.loads((run / "evaluation.json").read_text())
        value = result.get("mean_return") if platform else success_of(result)[0]
        if value is not None:
            return float(value), True
    from pamdp.experiments.plots import GREEDY_METRIC, GREEDY_SUCCESS_METRIC, _read_progress

    if (run / "progress.csv").exists():
        _, values = _read_progress(run, GREEDY_METRIC if platform else GREEDY_SUCCESS_METRIC)
        logged = values[np.isfinite(values)]
        if len(logged):
            return float(logged[-1]), False
    return None


def suite_cells(groups: dict[str, list[Path]]) -> dict[tuple[str, str], str]:
    """``{(domain, method): "0.93 +- 0.02 (3 seeds)"}`` from the groups of :func:`plots.find_groups`."""
    from pamdp.experiments.plots import _recorded

    found: dict[tuple[str, str], list[tuple[float, bool]]] = {}
    for label, runs in groups.items():
        for run in runs:
            recorded = _recorded(run)
            domain = domain_of(recorded)
            if domain is None:
                continue
            method = str(recorded.get("label") or label).split(" on ")[0]
            figure = _figure(run, domain)
            if figure is not None:
                found.setdefault((domain, method), []).append(figure)
    cells = {}
    for key, figures in found.items():
        values = np.array([v for v, _ in figures])
        partial = sum(not final for _, final in figures)
        text = f"{values.mean():.2f} +- {values.std():.2f} ({len(values)} seed{'s' * (len(values) > 1)}"
        cells[key] = text + (f", {partial} partial*)" if partial else ")")
    return cells


def suite_table(groups: dict[str, list[Path]]) -> str:
    """A markdown table: each domain's measured figure per method, then HyAR's published ones ("" where no run
    of the groups is on a suite domain)."""
    cells = suite_cells(groups)
    if not cells:
        return ""
    methods = list(dict.fromkeys(method for _, method in cells))
    head = ["domain", *(f"pamdp {m}" for m in methods), *(f"HyAR's {m}" for m in HYAR_TABLE)]
    lines = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    for domain, _, _ in DOMAINS:
        row = [domain, *(cells.get((domain, m), "-") for m in methods), *(t[domain] for t in HYAR_TABLE.values())]
        lines.append("| " + " | ".join(row) + " |")
    lines += [
        "",
        "Success rate (Platform: return), mean +- std over seeds, each seed's final greedy evaluation over 1000 "
        "episodes; * a run still training, counted with its last greedy evaluation (100 episodes). HyAR's columns: "
        "its Table 2 (5 runs, 100 evaluation episodes).",
    ]
    return "\n".join(lines)


def plot_domains(groups: dict[str, list[Path]], out: str | os.PathLike) -> list[Path]:
    """One figure per suite domain with runs (``domain-NAME.png`` and ``.svg``): the greedy success rate (Platform:
    return) of each method's evaluations during training, over samples."""
    from pamdp.experiments.plots import GREEDY_METRIC, GREEDY_SUCCESS_METRIC, _recorded, plot_curves

    by_domain: dict[str, dict[str, list[Path]]] = {}
    for label, runs in groups.items():
        domain = domain_of(_recorded(runs[0]))
        if domain is not None:
            by_domain.setdefault(domain, {})[label.split(" on ")[0]] = runs
    written = []
    for domain, methods in by_domain.items():
        metric = GREEDY_METRIC if domain == "Platform" else GREEDY_SUCCESS_METRIC
        name = "domain-" + domain.lower().replace(" ", "-").replace("=", "")
        written += plot_curves(methods, Path(out) / name, domain, metric, x="samples")
    return written
