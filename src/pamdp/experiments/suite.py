"""The benchmark suite's table and curves: each domain's measured success rates beside HyAR's published ones.

``pamdp reproduce benchmark-suite`` names its runs ``"METHOD on DOMAIN"``; :func:`suite_table` finds each run's
domain from the env (and its arguments) its ``run.json`` records, and its method from the label. A finished run
counts with its final evaluation (1000 greedy episodes); a run still training with its last greedy evaluation
during training (100 episodes), marked as such. Platform's figure is the return, as in HyAR's table; the
others' the success rate (``info["is_success"]``).

Each seed's figure is an entry of ``suite-finals.json``, written beside the table. Runs are lost when a machine
goes; handed back as an archive (``pamdp plot --suite-archive FILE``), the entries of earlier runs fill the table
where no run at hand has the same domain, method and seed.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from pamdp.algos.logger import success_of

__all__ = [
    "DOMAINS",
    "HYAR_TABLE",
    "domain_of",
    "suite_finals",
    "load_finals",
    "merge_finals",
    "suite_cells",
    "suite_table",
    "plot_domains",
]

DOMAINS: tuple[tuple[str, str, dict], ...] = (
    ("Platform", "pamdp/Platform-v0", {}),
    ("Goal", "pamdp/Goal-v0", {}),
    ("Hard Goal", "pamdp/HardGoal-v0", {}),
    ("Catch Point", "pamdp/CatchPoint-v0", {}),
    *((f"Hard Move n={n}", "pamdp/HardMove-v0", {"n": n}) for n in (4, 6, 8, 10)),
)
"""``(name, env id, env arguments)`` of the eight domains of HyAR's Table 2, in its order."""

# HyAR's Table 2 (Li et al., "HyAR: Addressing Discrete-Continuous Action Reinforcement Learning via Hybrid Action
# Representation", ICLR 2022): mean +- std over 5 runs
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


def _seed_of(run: Path, recorded: dict) -> int | None:
    """A run's seed: its recorded settings', else its directory's name (``seedN``)."""
    seed = (recorded.get("config") or {}).get("seed")
    if seed is None and run.name.startswith("seed") and run.name[4:].isdigit():
        seed = int(run.name[4:])
    return None if seed is None else int(seed)


def suite_finals(groups: dict[str, list[Path]]) -> list[dict]:
    """One entry per run of the groups (:func:`plots.find_groups`) on a suite domain with a figure:
    ``{"domain", "method", "seed", "value", "final", "source"}`` (``final``: its evaluation of 1000 episodes, else
    its last greedy evaluation during training; ``source``: the run's directory, its last three parts, as
    ``benchmark-suite/PATRPO_on_Goal/seed0``: where it lies under the runs' root, without a machine's own path)."""
    from pamdp.experiments.plots import _recorded

    finals = []
    for label, runs in groups.items():
        for run in runs:
            recorded = _recorded(run)
            domain = domain_of(recorded)
            figure = None if domain is None else _figure(run, domain)
            if figure is not None:
                method = str(recorded.get("label") or label).split(" on ")[0]
                seed = _seed_of(run, recorded)
                finals.append(dict(domain=domain, method=method, seed=seed, value=figure[0], final=figure[1]))
                finals[-1]["source"] = Path(*Path(run).resolve().parts[-3:]).as_posix()
    return finals


FINALS_KEYS = {"domain": str, "method": str, "seed": int, "value": float, "final": bool, "source": str}
"""The keys of a suite-finals entry and their types."""


def load_finals(path: str | os.PathLike) -> list[dict]:
    """The entries of a ``suite-finals.json`` (as :func:`write_report` writes it), each checked: a ``ValueError``
    names the file, the entry and what was expected."""
    try:
        entries = json.loads(Path(path).read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise ValueError(f"suite archive {path}: cannot read it as JSON ({e})") from None
    if not isinstance(entries, list):
        raise ValueError(f"suite archive {path}: a {type(entries).__name__}; expected a list of entries")
    names = [d[0] for d in DOMAINS]
    for i, entry in enumerate(entries):
        where = f"suite archive {path}, entry {i}"
        if not isinstance(entry, dict) or set(entry) != set(FINALS_KEYS):
            got = sorted(entry) if isinstance(entry, dict) else entry
            raise ValueError(f"{where}: {got!r}; expected an object with the keys {sorted(FINALS_KEYS)}")
        for key, kind in FINALS_KEYS.items():
            value = entry[key]
            ok = isinstance(value, kind) and not (kind is int and isinstance(value, bool))
            ok = ok or (key == "seed" and value is None)  # a run whose seed was not recorded
            if kind is float:
                ok = isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value)
            if not ok:
                raise ValueError(
                    f"{where}: {key} = {value!r}; expected a {'finite number' if kind is float else kind.__name__}"
                )
        if entry["domain"] not in names:
            raise ValueError(f"{where}: domain = {entry['domain']!r}; expected one of {names}")
    return entries


def merge_finals(at_hand: list[dict], archived: list[dict]) -> list[dict]:
    """``archived`` entries with those of ``at_hand`` over them (a run at hand replaces the archived entry of its
    domain, method and seed), in the table's domain order, then by method and seed."""
    merged = {(e["domain"], e["method"], e["seed"]): e for e in [*archived, *at_hand]}
    order = {d[0]: i for i, d in enumerate(DOMAINS)}
    return sorted(
        merged.values(), key=lambda e: (order[e["domain"]], e["method"], -1 if e["seed"] is None else e["seed"])
    )


def suite_cells(finals: list[dict]) -> dict[tuple[str, str], str]:
    """``{(domain, method): "0.93 +- 0.02 (3 seeds)"}`` from entries of :func:`suite_finals`."""
    found: dict[tuple[str, str], list[tuple[float, bool]]] = {}
    for e in finals:
        found.setdefault((e["domain"], e["method"]), []).append((float(e["value"]), bool(e["final"])))
    cells = {}
    for key, figures in found.items():
        values = np.array([v for v, _ in figures])
        partial = sum(not final for _, final in figures)
        text = f"{values.mean():.2f} +- {values.std():.2f} ({len(values)} seed{'s' * (len(values) > 1)}"
        cells[key] = text + (f", {partial} partial*)" if partial else ")")
    return cells


def suite_table(finals: list[dict]) -> str:
    """A markdown table: each domain's measured figure per method (entries of :func:`suite_finals`), then HyAR's
    published ones ("" without entries)."""
    cells = suite_cells(finals)
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
        "its Table 2 (5 runs, 100 evaluation episodes). Per seed, with where each figure comes from: "
        "`suite-finals.json` beside this table.",
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
