"""The paper's experiments as files, and what runs and plots them (``pamdp reproduce``, ``pamdp plot``).

Each experiment is a TOML file in ``configs/`` (one per figure of the paper, and ``benchmark-suite``): the env,
the budget, the seeds, optional ``env_kwargs`` for the env's constructor, and a list of runs (a label, an
algorithm, a preset, setting overrides, and optionally their own ``env``, ``env_kwargs``, ``total_steps`` and
``eval_every``: a suite of domains gives each its own budget; ``init_from``, the label of an earlier run whose
final model of the same seed (or of its one seed, for a run that lists a single seed) starts this one's networks:
a curriculum; ``init_keep``, the tensors such a run keeps of its own initialisation, e.g. ``["policy.log_std"]``,
or a tensor's row, ``"policy.log_std[2]"``; ``init_widen``, those that take the larger of the two; and ``seeds``,
a run's own seeds in place of the experiment's). The experiment's ``env`` and ``total_steps`` may be left out
where every run gives its own.
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

from pamdp.experiments.runner import RunSpec
from pamdp.experiments.summary import _slug

__all__ = ["Experiment", "load_experiment", "available_experiments"]

CONFIG_DIR = Path(__file__).parent / "configs"


def available_experiments() -> list[str]:
    return sorted(p.stem for p in CONFIG_DIR.glob("*.toml"))


@dataclasses.dataclass(frozen=True)
class Experiment:
    name: str
    description: str
    env: str | None  # None: each run names its own
    total_steps: int | None  # None: each run gives its own
    seeds: tuple[int, ...]
    eval_episodes: int
    runs: tuple[dict, ...]
    env_kwargs: dict = dataclasses.field(default_factory=dict)
    eval_every: int = 0

    def specs(self, seeds=None, scale: float = 1.0, labels=None) -> list[RunSpec]:
        """One :class:`RunSpec` per (run, seed); ``seeds`` replaces the experiment's seeds (not a run's own);
        ``scale`` multiplies each run's step budget; ``labels`` (run labels or their directory names) keeps only
        those runs, in the experiment's order."""
        if scale <= 0:
            raise ValueError(f"scale = {scale!r}; expected a positive factor")
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
            steps = max(1, int(round(run.get("total_steps", self.total_steps) * scale)))
            for seed in run.get("seeds", self.seeds if seeds is None else seeds):  # a run's own seeds stay
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
                        run.get("eval_every", self.eval_every),
                        run.get("init_from", ""),
                        tuple(run.get("init_keep", ())),
                        tuple(run.get("init_widen", ())),
                    )
                )
        return out

    def run_dir(self, root: str | os.PathLike, spec: RunSpec) -> Path:
        return Path(root) / self.name / _slug(spec.label) / f"seed{spec.seed}"

    def jobs(self, root: str | os.PathLike, specs: list[RunSpec]) -> list[tuple[RunSpec, str]]:
        """``(spec, run directory)`` for each spec, a run's ``init_from`` label turned into that run's directory
        for the same seed, or for its one seed where that run lists a single seed: one stage serving every seed
        of the runs that start from it (it must finish first: runs that start from another come after it in the
        file)."""
        own_seeds = {run["label"]: run.get("seeds") for run in self.runs}

        def started(spec: RunSpec) -> RunSpec:
            if not spec.init_from:
                return spec
            seeds = own_seeds.get(spec.init_from)
            seed = seeds[0] if seeds is not None and len(seeds) == 1 else spec.seed
            source = self.run_dir(root, dataclasses.replace(spec, label=spec.init_from, seed=seed))
            return dataclasses.replace(spec, init_from=str(source))

        return [(started(spec), str(self.run_dir(root, spec))) for spec in specs]


def load_experiment(name_or_path: str | os.PathLike) -> Experiment:
    """An experiment by name (one of :func:`available_experiments`: ``platform``, ``benchmark-suite``, ...) or TOML
    path."""
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
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"experiment file {path} is not valid TOML: {exc}") from exc
    _check_experiment(path, data)
    return Experiment(
        path.stem,
        data.get("description", ""),
        data.get("env"),
        int(data["total_steps"]) if "total_steps" in data else None,
        tuple(data["seeds"]),
        int(data.get("eval_episodes", 1000)),
        tuple(data["runs"]),
        dict(data.get("env_kwargs", {})),
        int(data.get("eval_every", 0)),
    )


MAX_STEPS = 10**12  # as ``pamdp train --total-steps``: a budget beyond this is a typing slip
_KEYS = {"description", "env", "total_steps", "seeds", "eval_episodes", "eval_every", "env_kwargs", "runs"}
_RUN_KEYS = {
    "label",
    "algo",
    "preset",
    "settings",
    "env",
    "env_kwargs",
    "total_steps",
    "eval_every",
    "init_from",
    "init_keep",
    "init_widen",
    "seeds",
}


def _whole(value, low: int, high: int | None = None) -> bool:
    """Whether a TOML value is an integer from ``low`` to ``high`` (``1e6`` included: users write budgets so)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != value:  # NaN
        return False
    return value == int(value) and low <= value and (high is None or value <= high)


def _count(value) -> bool:
    return isinstance(value, int) and _whole(value, 0)


def _check_seeds(refuse, what: str, seeds) -> None:
    if not isinstance(seeds, list) or not seeds or not all(_whole(s, 0) and isinstance(s, int) for s in seeds):
        refuse(what, seeds, "a list of integer seeds >= 0")
    if len(set(seeds)) < len(seeds):
        refuse(what, seeds, "each seed once")


def _check_experiment(path: Path, data: dict) -> None:
    """Refuse what an experiment file gets wrong, naming the key, its value and what was expected: a misspelt key
    would otherwise be ignored, and a seed given twice would write one run directory twice."""

    def refuse(what: str, value, expected: str):
        raise ValueError(f"experiment file {path}: {what} = {value!r}; expected {expected}")

    missing = {"seeds", "runs"} - set(data)
    if missing:
        raise ValueError(f"experiment file {path} lacks {sorted(missing)}")
    for key in sorted(set(data) - _KEYS):
        refuse(key, data[key], "only the keys " + ", ".join(sorted(_KEYS)))
    budget = f"a whole number of steps from 1 to {MAX_STEPS:.0e}"
    if "total_steps" in data and not _whole(data["total_steps"], 1, MAX_STEPS):
        refuse("total_steps", data["total_steps"], budget)
    _check_seeds(refuse, "seeds", data["seeds"])
    for key in ("eval_episodes", "eval_every"):
        if key in data and not _count(data[key]):
            refuse(key, data[key], "an integer >= 0")
    runs = data["runs"]
    if not isinstance(runs, list) or not runs or not all(isinstance(run, dict) for run in runs):
        refuse("runs", runs, "one or more [[runs]] tables")
    if "env_kwargs" in data and not isinstance(data["env_kwargs"], dict):
        refuse("env_kwargs", data["env_kwargs"], "a table of the env's constructor arguments")
    dirs: dict[str, str] = {}
    for i, run in enumerate(runs):
        if not {"label", "algo"} <= set(run):
            raise ValueError(f"experiment file {path}: run {i} needs a label and an algo, got {run}")
        for key in sorted(set(run) - _RUN_KEYS):
            refuse(f"runs[{i}].{key}", run[key], "only the keys " + ", ".join(sorted(_RUN_KEYS)))
        for key in ("settings", "env_kwargs"):
            if key in run and not isinstance(run[key], dict):
                refuse(f"runs[{i}].{key}", run[key], "a table")
        for key in ("env", "total_steps"):  # each run needs its own where the experiment gives none
            if key not in run and key not in data:
                raise ValueError(f"experiment file {path}: run {i} ({run['label']!r}) has no {key}, nor has the file")
        if "total_steps" in run and not _whole(run["total_steps"], 1, MAX_STEPS):
            refuse(f"runs[{i}].total_steps", run["total_steps"], budget)
        if "seeds" in run:
            _check_seeds(refuse, f"runs[{i}].seeds", run["seeds"])
        if "eval_every" in run and not _count(run["eval_every"]):
            refuse(f"runs[{i}].eval_every", run["eval_every"], "an integer >= 0")
        if "init_from" in run and run["init_from"] not in [r.get("label") for r in runs[:i]]:
            refuse(f"runs[{i}].init_from", run["init_from"], "the label of a run listed before it")
        for key in ("init_keep", "init_widen"):
            names = run.get(key, [])
            if (
                not (isinstance(names, list) and all(isinstance(k, str) for k in names))
                or names
                and "init_from" not in run
            ):
                refuse(
                    f"runs[{i}].{key}",
                    names,
                    "a list of tensor names such as 'policy.log_std' or rows such as 'policy.log_std[2]', "
                    "with init_from",
                )
        slug = _slug(str(run["label"]))
        if slug in dirs:
            refuse(f"runs[{i}].label", run["label"], f"a label whose directory differs from {dirs[slug]!r}'s ({slug})")
        dirs[slug] = run["label"]
