"""The benchmark suite's table and curves: each domain's measured success rates beside HyAR's published ones.

``pamdp reproduce benchmark-suite`` names its runs ``"METHOD on DOMAIN"``; :func:`suite_table` finds each run's
domain from the env (and its arguments, with the constructor's defaults) its ``run.json`` records, and its method
from the label. A cell averages the seeds of one setting (budget, preset and settings,
:func:`.plots.setting_of`): runs of another setting get rows of their own, never counted as seeds of it. A finished run
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

from pamdp.experiments.plots import run_setting
from pamdp.experiments.runner import env_defaults
from pamdp.logger import success_of

__all__ = [
    "DOMAINS",
    "HYAR_TABLE",
    "from_suite_final",
    "domain_of",
    "method_of",
    "suite_finals",
    "load_finals",
    "merge_finals",
    "suite_groups",
    "suite_rows",
    "suite_cells",
    "format_cell",
    "suite_table",
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
    """The suite domain a run's ``run.json`` describes (``None`` for an env outside it). The env's arguments count
    with its defaults: a Hard Move run that gave no ``n`` is a run of its default ``n = 4``."""
    env = recorded.get("env")
    if env not in {e for _, e, _ in DOMAINS}:
        return None
    defaults = env_defaults(env)
    given = {**defaults, **(recorded.get("env_kwargs") or {})}
    for name, domain_env, kwargs in DOMAINS:
        if env == domain_env and given == {**defaults, **kwargs}:
            return name
    return None


def method_of(label: str, domain: str) -> str:
    """What the suite table calls a run's method: its label without the ``" on DOMAIN"`` the suite's labels end
    with (``"MP-DQN on Hard Move n=4"``: ``MP-DQN``); any other label whole."""
    suffix = f" on {domain}"
    return label[: -len(suffix)] if label.endswith(suffix) and len(label) > len(suffix) else label


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
    ``{"domain", "method", "seed", "value", "final", "source", "total_steps", "preset", "settings"}`` (the last three:
    :func:`.plots.setting_of`; ``final``: its evaluation of 1000 episodes, else
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
                method = method_of(str(recorded.get("label") or label), domain)
                seed = _seed_of(run, recorded)
                finals.append(dict(domain=domain, method=method, seed=seed, value=figure[0], final=figure[1]))
                finals[-1]["source"] = Path(*Path(run).resolve().parts[-3:]).as_posix()
                finals[-1].update(run_setting(run))
    return finals


FINALS_KEYS = {"domain": str, "method": str, "seed": int, "value": float, "final": bool, "source": str}
"""The keys of a suite-finals entry and their types."""
SETTING_KEYS = {"total_steps": int, "preset": str, "settings": str}
"""The keys of :func:`.plots.setting_of`: in entries since issue 46 (``None`` where the run did not record them, and in
older archives' entries, which lack them)."""


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
        if not isinstance(entry, dict) or not set(FINALS_KEYS) <= set(entry) <= set(FINALS_KEYS) | set(SETTING_KEYS):
            got = sorted(entry) if isinstance(entry, dict) else entry
            raise ValueError(
                f"{where}: {got!r}; expected an object with the keys {sorted(FINALS_KEYS)} "
                f"(and optionally {sorted(SETTING_KEYS)})"
            )
        for key, kind in {**FINALS_KEYS, **SETTING_KEYS}.items():
            value = entry.get(key)
            ok = isinstance(value, kind) and not (kind is int and isinstance(value, bool))
            ok = ok or (key in ("seed", *SETTING_KEYS) and value is None)  # not recorded
            if kind is float:
                ok = isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value)
            if not ok:
                raise ValueError(
                    f"{where}: {key} = {value!r}; expected a {'finite number' if kind is float else kind.__name__}"
                )
        if entry["domain"] not in names:
            raise ValueError(f"{where}: domain = {entry['domain']!r}; expected one of {names}")
    return [{**dict.fromkeys(SETTING_KEYS), **entry} for entry in entries]


def _setting_key(entry: dict) -> tuple:
    return tuple(entry.get(key) for key in SETTING_KEYS)


def merge_finals(at_hand: list[dict], archived: list[dict]) -> list[dict]:
    """``archived`` entries with those of ``at_hand`` over them (a run at hand replaces the archived entry of its
    domain, method, seed and setting, or of an archived entry that recorded no setting), in the table's domain
    order, then by method, setting and seed. Runs of another setting are kept beside: they are no seeds of it."""
    unrecorded = _setting_key({})
    merged = {(e["domain"], e["method"], e["seed"], _setting_key(e)): e for e in archived}
    for e in at_hand:
        merged.pop((e["domain"], e["method"], e["seed"], unrecorded), None)
        merged[(e["domain"], e["method"], e["seed"], _setting_key(e))] = e
    order = {d[0]: i for i, d in enumerate(DOMAINS)}
    return sorted(
        merged.values(),
        key=lambda e: (order[e["domain"]], e["method"], repr(_setting_key(e)), -1 if e["seed"] is None else e["seed"]),
    )


def format_cell(values: np.ndarray, partial: int) -> str:
    """A cell of the table: mean +- std over the seeds' figures, how many seeds, and how many are still training."""
    text = f"{values.mean():.2f} +- {values.std():.2f} ({len(values)} seed{'s' * (len(values) > 1)}"
    return text + (f", {partial} partial*)" if partial else ")")


def suite_groups(finals: list[dict]) -> dict[tuple[str, str, tuple], list[dict]]:
    """The entries of each ``(domain, method, setting)``: the seeds of one setting, whose figures a cell shows."""
    groups: dict[tuple[str, str, tuple], list[dict]] = {}
    for e in finals:
        groups.setdefault((e["domain"], e["method"], _setting_key(e)), []).append(e)
    return groups


def _describe(setting: tuple, others: list[tuple]) -> str:
    """A setting's row label: its budget, and its preset and settings' digest where they tell it from ``others``
    (the other settings of its domain and method)."""
    steps, preset, digest = setting
    parts = [f"{steps:,} steps" if steps is not None else "budget not recorded"]
    if any(o[0] == steps and o[1] != preset for o in others) or (preset is not None and not others):
        parts.append(f"preset {preset}")
    if any(o[:2] == setting[:2] and o[2] != digest for o in others):
        parts.append(f"settings {digest}")
    return ", ".join(parts)


def suite_rows(finals: list[dict]) -> list[tuple[str, dict[str, str]]]:
    """The table's rows, ``(row label, {method: cell})``: per domain, in HyAR's order, a first row with each method's
    main setting (its largest budget, then the one of most seeds), then a row per other setting, labelled
    ``"Platform: 2,000 steps"``; no run is counted as a seed of another setting."""
    groups = suite_groups(finals)
    rows = []
    for domain, _, _ in DOMAINS:
        by_method: dict[str, list[tuple]] = {}
        for d, method, setting in groups:
            if d == domain:
                by_method.setdefault(method, []).append(setting)
        main: dict[str, str] = {}
        extra: dict[str, dict[str, str]] = {}
        for method, settings in by_method.items():
            settings.sort(key=lambda st: (st[0] or 0, len(groups[(domain, method, st)])), reverse=True)
            for i, setting in enumerate(settings):
                entries = groups[(domain, method, setting)]
                values = np.array([float(e["value"]) for e in entries])
                cell = format_cell(values, sum(not e["final"] for e in entries))
                if i == 0:
                    main[method] = cell
                else:
                    others = [st for st in settings if st != setting]
                    extra.setdefault(f"{domain}: {_describe(setting, others)}", {})[method] = cell
        rows.append((domain, main))
        rows += sorted(extra.items())
    return rows


def suite_cells(finals: list[dict]) -> dict[tuple[str, str], str]:
    """``{(row label, method): "0.93 +- 0.02 (3 seeds)"}`` from entries of :func:`suite_finals` (see
    :func:`suite_rows`)."""
    return {(label, method): cell for label, cells in suite_rows(finals) for method, cell in cells.items()}


def suite_table(finals: list[dict]) -> str:
    """A markdown table: each domain's measured figure per method (entries of :func:`suite_finals`), then HyAR's
    published ones ("" without entries)."""
    rows = suite_rows(finals)
    methods = list(dict.fromkeys(method for _, cells in rows for method in cells))
    if not methods:
        return ""
    head = ["domain", *(f"pamdp {m}" for m in methods), *(f"HyAR's {m}" for m in HYAR_TABLE)]
    lines = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    for label, cells in rows:
        hyar = [t[label] if label in t else "" for t in HYAR_TABLE.values()]
        lines.append("| " + " | ".join([label, *(cells.get(m, "-") for m in methods), *hyar]) + " |")
    lines += [
        "",
        "Success rate (Platform: return), mean +- std over seeds, each seed's final greedy evaluation over 1000 "
        "episodes; * a run still training, counted with its last greedy evaluation (100 episodes). A domain's first "
        "row holds each method's runs of its largest budget; runs of another budget, preset or settings have rows of "
        "their own below it and are never counted as seeds of another. HyAR's columns: its Table 2 (5 runs, 100 "
        "evaluation episodes). Per seed, with where each figure comes from: `suite-finals.json` beside this table.",
    ]
    return "\n".join(lines)


def from_suite_final(entry: dict) -> dict:
    """The summary of a benchmark-suite run known only by its entry of ``suite-finals.json`` (its tree lost): the
    final figure (the return on Platform, else the success rate), its seed and what the entry recorded of the
    setting; the env is the entry's domain's. Nothing the entry does not hold is filled in: ``algo``, ``config``,
    costs and evaluations during training are ``None`` or empty."""
    from pamdp.experiments.summary import FORMAT, SOURCES

    if not entry.get("final"):  # a run's last greedy evaluation during training: 100 episodes at unknown samples
        raise ValueError(f"suite entry {entry}: not a final evaluation; expected the entry of a finished run")
    _, env, env_kwargs = next(d for d in DOMAINS if d[0] == entry["domain"])
    figure = "mean_return" if entry["domain"] == "Platform" else "success_rate"
    return {
        "format": FORMAT,
        "source": SOURCES[1],
        "origin": entry["source"],
        "label": f"{entry['method']} on {entry['domain']}",
        "algo": None,
        "preset": entry.get("preset"),
        "env": env,
        "env_kwargs": dict(env_kwargs),
        "seed": entry["seed"],
        "total_steps": entry.get("total_steps"),
        "settings_hash": entry.get("settings"),
        "config": None,
        "pamdp_version": None,
        "git_commit": None,
        "finished": True,
        "samples": None,
        "epochs": None,
        "gradient_updates": None,
        "cpu_seconds": None,
        "wall_seconds": None,
        "evaluations": {"samples": []},
        "final": {figure: entry["value"]},
    }
