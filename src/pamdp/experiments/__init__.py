"""The paper's experiments as files, and what runs and plots them (``pamdp reproduce``, ``pamdp plot``).

Each experiment is a TOML file in ``configs/`` (one per figure of the paper): the env, the budget, the
seeds, optional ``env_kwargs`` for the env's constructor, and a list of runs (a label, an algorithm, a preset,
setting overrides, and optionally their own ``env`` and ``env_kwargs``).
"""

from __future__ import annotations

import dataclasses
import os
import re
from pathlib import Path

from pamdp.experiments.runner import RunSpec

__all__ = ["Experiment", "load_experiment", "available_experiments"]

CONFIG_DIR = Path(__file__).parent / "configs"


def available_experiments() -> list[str]:
    return sorted(p.stem for p in CONFIG_DIR.glob("*.toml"))


@dataclasses.dataclass(frozen=True)
class Experiment:
    name: str
    description: str
    env: str
    total_steps: int
    seeds: tuple[int, ...]
    eval_episodes: int
    runs: tuple[dict, ...]
    env_kwargs: dict = dataclasses.field(default_factory=dict)
    eval_every: int = 0

    def specs(self, seeds=None, scale: float = 1.0, labels=None) -> list[RunSpec]:
        """One :class:`RunSpec` per (run, seed); ``scale`` multiplies the step budget; ``labels`` (run labels
        or their directory names) keeps only those runs, in the experiment's order."""
        if scale <= 0:
            raise ValueError(f"scale = {scale!r}; expected a positive factor")
        steps = max(1, int(round(self.total_steps * scale)))
        runs = self.runs
        if labels is not None:
            names = {name for run in self.runs for name in (run["label"], _slug(run["label"]))}
            unknown = [label for label in labels if label not in names]
            if unknown or not labels:
                raise ValueError(
                    f"run labels {', '.join(map(repr, unknown)) or '(none given)'} not in experiment {self.name!r}; "
                    "expected some of " + ", ".join(repr(run["label"]) for run in self.runs)
                )
            runs = [run for run in self.runs if run["label"] in labels or _slug(run["label"]) in labels]
        out = []
        for run in runs:
            for seed in self.seeds if seeds is None else seeds:
                settings = tuple(sorted(run.get("settings", {}).items()))
                env_kwargs = tuple(sorted({**self.env_kwargs, **run.get("env_kwargs", {})}.items()))
                out.append(
                    RunSpec(
                        run["algo"],
                        run.get("env", self.env),
                        steps,
                        int(seed),
                        run.get("preset"),
                        settings,
                        self.eval_episodes,
                        run["label"],
                        env_kwargs,
                        self.eval_every,
                    )
                )
        return out

    def run_dir(self, root: str | os.PathLike, spec: RunSpec) -> Path:
        return Path(root) / self.name / _slug(spec.label) / f"seed{spec.seed}"


def _slug(label: str) -> str:
    """A run label as a directory name."""
    return re.sub(r"[^A-Za-z0-9_.=-]+", "_", label)


def load_experiment(name_or_path: str | os.PathLike) -> Experiment:
    """An experiment by name (``platform``, ``step-size``, ``kl-estimators``, ``soccer``) or TOML path."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    path = Path(name_or_path)
    if not path.suffix:
        path = CONFIG_DIR / f"{name_or_path}.toml"
    if not path.is_file():
        raise ValueError(
            f"unknown experiment {name_or_path!r}; expected one of {', '.join(available_experiments())} or a TOML file"
        )
    data = tomllib.loads(path.read_text())
    missing = {"env", "total_steps", "seeds", "runs"} - set(data)
    if missing:
        raise ValueError(f"experiment file {path} lacks {sorted(missing)}")
    for i, run in enumerate(data["runs"]):
        if not {"label", "algo"} <= set(run):
            raise ValueError(f"experiment file {path}: run {i} needs a label and an algo, got {run}")
    return Experiment(
        path.stem,
        data.get("description", ""),
        data["env"],
        int(data["total_steps"]),
        tuple(data["seeds"]),
        int(data.get("eval_episodes", 1000)),
        tuple(data["runs"]),
        dict(data.get("env_kwargs", {})),
        int(data.get("eval_every", 0)),
    )
