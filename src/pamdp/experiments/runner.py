"""Single training runs and the multi-seed runner behind ``pamdp train`` and ``pamdp reproduce``.

A run lives in one directory: ``run.json`` (what was asked), ``progress.csv``, ``tb/``, ``checkpoint.pt``,
``final_model.pt``, ``evaluation.json`` and ``summary.json`` (:mod:`pamdp.experiments.summary`, written last).
:func:`train_run` is resumable: a directory with a final model and an evaluation is done and skipped; one with a
checkpoint continues from it; settings that differ from the recorded ones are refused rather than mixed into one
log.

:func:`run_all` executes many runs, side by side in worker processes (one torch thread each), and reports
a failed run with its error while the others finish.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import csv
import dataclasses
import json
import multiprocessing
import os
import socket
import sys
import time
import traceback
import warnings
from pathlib import Path
from typing import Any, NamedTuple

import filelock

from pamdp._version import __version__
from pamdp.algos import algorithm_class
from pamdp.envs.backends import check_env_kwargs
from pamdp.experiments.summary import SUMMARY, git_commit, write_summary
from pamdp.presets import choose

__all__ = ["RunConfig", "RunSpec", "train_run", "run_lock", "is_finished", "recorded_differences", "run_all"]

LOCK_FILE = ".lock"
HOLDER_FILE = ".lock-holder"  # who holds the lock: beside it, since a locked file is not readable on every system
_CUT_SHORT = ".cut-short"  # a first epoch's log kept aside when its checkpoint was cut short by a kill
# What a run directory holds before its first checkpoint: starting it again from step 0 loses nothing (a summary
# made of it by ``pamdp summarize`` is made again at the end).
_BEFORE_FIRST_CHECKPOINT = {"run.json", "progress.csv", "tb", "stdout.log", SUMMARY, LOCK_FILE, HOLDER_FILE}


@dataclasses.dataclass(frozen=True)
class RunSpec:
    """One training run: an algorithm with settings, on an env, for a seed."""

    algo: str
    env: str
    total_steps: int
    seed: int = 0
    preset: str | None = None
    settings: tuple[tuple[str, Any], ...] = ()
    eval_episodes: int = 1000
    label: str = ""
    env_kwargs: tuple[tuple[str, Any], ...] = ()
    eval_every: int = 0  # epochs between greedy evaluations of 100 episodes during training (0: none)
    init_from: str = ""  # a model file or run directory whose networks start this run's (transfer_weights)
    init_keep: tuple[str, ...] = ()  # tensors that stay this run's own initialisation in that start
    init_widen: tuple[str, ...] = ()  # tensors that take the larger of the source's and this run's initialisation

    def config(self) -> RunConfig:
        """The run's algorithm and settings: its preset (the env's where it names none, as
        :func:`pamdp.presets.choose` picks it), then its settings and seed over it."""
        cls = algorithm_class(self.algo)
        if cls is None:
            raise ValueError(f"algorithm {self.algo!r} is not available in this install")
        choice = choose(cls.config_class, self.preset, self.env, dict(self.env_kwargs))
        config = cls.config_class.from_dict({**dict(self.settings), "seed": self.seed}, base=choice.config)
        return RunConfig(cls, choice.name, config, choice.warning)

    def check(self) -> RunConfig:
        """:meth:`config`, after checking the env's id and arguments against its constructor: everything a run
        needs before anything is written."""
        check_env_kwargs(self.env, dict(self.env_kwargs))
        return self.config()


class RunConfig(NamedTuple):
    """What :meth:`RunSpec.config` resolves, once per run."""

    cls: type
    """The algorithm's class."""
    preset: str
    """The preset the settings go over."""
    config: Any
    """The algorithm's config."""
    warning: str | None
    """Why the preset does not suit the env (one made for another env), or ``None``."""


@contextlib.contextmanager
def run_lock(out: str | os.PathLike):
    """Hold ``out``'s lock (``out/.lock``, an exclusive lock of the operating system's, through :mod:`filelock`) for
    the block: one writer per run directory.

    A second process (or a second holder in this one) asking for it is refused at once with a ``ValueError`` naming
    the holder, whom ``out/.lock-holder`` records. The directory (and its missing parents) is created; if the block
    fails before writing anything into it, they are removed again, so a refused run leaves nothing behind. The
    lock goes with its process, however that ends.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"{out} is a file; expected a run directory (a new one, or one to resume)")
    created = [p for p in (out, *out.parents) if not p.exists()]  # deepest first
    out.mkdir(parents=True, exist_ok=True)
    made = [name for name in (LOCK_FILE, HOLDER_FILE) if not (out / name).exists()]
    lock = filelock.FileLock(out / LOCK_FILE, timeout=0)
    try:
        lock.acquire()
    except filelock.Timeout:
        holder = (out / HOLDER_FILE).read_text().strip() if (out / HOLDER_FILE).exists() else ""
        raise ValueError(
            f"{out} is in use: {holder or 'another process'} is writing that run; wait for it to end or use "
            "another directory"
        ) from None
    try:
        (out / HOLDER_FILE).write_text(f"pamdp process {os.getpid()} on {socket.gethostname()}\n")
        yield
    except BaseException:  # what this made and nothing has written into goes again
        lock.release()
        for name in made:
            with contextlib.suppress(OSError):
                os.remove(out / name)
        for directory in created:
            with contextlib.suppress(OSError):  # not empty: the run wrote into it
                directory.rmdir()
        raise
    finally:
        lock.release()  # (a second release of a released lock does nothing)


def is_finished(out: str | Path, spec: RunSpec) -> bool:
    """Whether ``out`` holds ``spec``'s final model for its whole budget (and its evaluation, if it asks for one).

    :func:`train_run` skips such a run (after checking its recorded settings); ``pamdp reproduce --status``
    counts it as done.
    """
    from pamdp.algos.checkpoints import FINAL_MODEL

    out = Path(out)
    if not (out / FINAL_MODEL).exists() or not (out / "run.json").exists():
        return False
    try:
        recorded = json.loads((out / "run.json").read_text())
    except (OSError, json.JSONDecodeError):
        return False
    if recorded.get("total_steps") != spec.total_steps:
        return False
    return spec.eval_episodes <= 0 or (out / "evaluation.json").exists()


def recorded_differences(spec: RunSpec, summary: dict) -> list[str]:
    """What keeps a kept summary (:mod:`pamdp.experiments.summary`) from standing for ``spec``'s run: ``[]`` where
    it is of a finished run of the same algorithm, settings (seed included), env with its arguments and budget,
    evaluated at the end if ``spec`` asks for it; else each difference in words (``budget: 500 in the summary,
    1000 asked``).

    ``pamdp reproduce --recorded`` skips the runs it finds so: a run tree lost with its machine need not train
    again where its summary was committed. A summary converted from the suite's archive of figures (source
    ``suite-finals.json``) holds no algorithm, settings or budget; the results' tables count it as its cell's seed,
    and so does this: only what it holds is compared.
    """
    from pamdp.experiments.plots import setting_of
    from pamdp.experiments.summary import SOURCES

    asked = setting_of({"algo": spec.algo, "config": spec.check().config.to_dict()})["settings"]
    if summary.get("source") == SOURCES[1]:  # an archive entry: what it does not hold stands as asked
        held = {k: v for k, v in summary.items() if v is not None}
        summary = {"algo": spec.algo, "total_steps": spec.total_steps, "settings_hash": asked, **held}
    differ = []
    if summary.get("algo") != spec.algo:
        differ.append(f"algorithm: {summary.get('algo')!r} in the summary, {spec.algo!r} asked")
    else:
        if summary.get("settings_hash") != asked:
            differ.append(f"settings digest: {summary.get('settings_hash')!r} in the summary, {asked!r} asked")
        if summary.get("seed") != spec.seed:
            differ.append(f"seed: {summary.get('seed')!r} in the summary, {spec.seed} asked")
    differ += _env_differences(summary, spec.env, dict(spec.env_kwargs), "in the summary")
    if summary.get("total_steps") != spec.total_steps:
        differ.append(f"budget: {summary.get('total_steps')!r} in the summary, {spec.total_steps} asked")
    if not summary.get("finished"):
        differ.append(f"the run had trained {summary.get('samples')} samples, not finished")
    elif spec.eval_episodes > 0:
        episodes = (summary.get("final") or {}).get("episodes")
        if not summary.get("final"):
            differ.append("no final evaluation in the summary")
        elif episodes is not None and episodes != spec.eval_episodes:
            differ.append(f"final evaluation: {episodes} episodes in the summary, {spec.eval_episodes} asked")
    return differ


def _read_run_json(path: Path) -> dict:
    """A run's ``run.json`` (``{}`` where there is none); one that is not a JSON object is refused, naming it."""
    if not path.exists():
        return {}
    try:
        recorded = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path} is not valid JSON ({exc.msg}); expected the run.json pamdp train writes") from exc
    if not isinstance(recorded, dict):
        raise ValueError(f"{path} holds a {type(recorded).__name__}; expected the run.json pamdp train writes")
    return recorded


def env_defaults(env: str) -> dict:
    """The arguments of ``env``'s constructor that have defaults (``{"n": 4, ...}`` for Hard Move; ``{}`` for an
    unregistered env or a constructor without a signature)."""
    import inspect

    from pamdp.envs.backends import env_creator

    try:
        params = inspect.signature(env_creator(env)).parameters.values()
    except (ValueError, TypeError):
        return {}
    return {p.name: p.default for p in params if p.default is not inspect.Parameter.empty}


def _env_differences(recorded: dict, env: str, env_kwargs: dict, where: str) -> list[str]:
    """The env, else its arguments, where ``recorded`` (a ``run.json`` or a summary, ``where`` saying which) differs
    from ``env`` with ``env_kwargs``; the arguments count with their defaults: Hard Move's ``{"n": 4}`` is its
    ``{}``."""
    if recorded.get("env") != env:
        return [f"env: {recorded.get('env')!r} {where}, {env!r} asked"]
    defaults = env_defaults(env)
    if {**defaults, **(recorded.get("env_kwargs") or {})} != {**defaults, **env_kwargs}:
        return [f"env_kwargs: {recorded.get('env_kwargs')!r} {where}, {env_kwargs!r} asked"]
    return []


def _differences(recorded: dict, asked: dict) -> list[str]:
    """What differs between a recorded run and the one asked for, setting by setting: ``delta: 0.01 in the
    run, 0.05 asked``. Env arguments count with their defaults: Hard Move's ``{"n": 4}`` is its ``{}``."""
    differ = _env_differences(recorded, asked["env"], asked["env_kwargs"], "in the run")
    old, new = recorded.get("config", {}), asked["config"]
    for name in sorted(set(old) | set(new)):
        if old.get(name) != new.get(name):
            differ.append(f"{name}: {old.get(name)!r} in the run, {new.get(name)!r} asked")
    return differ


def _set_aside_name(out: Path, name: str) -> Path:
    """The first free name for a cut-short ``name``: ``NAME.cut-short``, then ``NAME.cut-short.2``, ... (a run
    cut short twice keeps both logs)."""
    path, n = out / f"{name}{_CUT_SHORT}", 1
    while path.exists():
        n += 1
        path = out / f"{name}{_CUT_SHORT}.{n}"
    return path


def _check_fresh_directory(out: Path) -> None:
    """Refuse to start a run from step 0 in a directory whose contents that would replace or mix with."""
    present = sorted(os.listdir(out)) if out.is_dir() else []
    progress = out / "progress.csv"
    if progress.exists():
        with open(progress, newline="") as f:
            epochs = sum(1 for _ in csv.DictReader(f))
        if epochs == 1 and not (out / "evaluation.json").exists():
            # A kill between the first epoch's log row and its checkpoint: nothing to resume, nothing lost by
            # starting again; the cut-short log (and its TensorBoard events) are kept beside, renamed.
            for name in ("progress.csv", "tb"):
                if (out / name).exists():
                    os.replace(out / name, _set_aside_name(out, name))
            present = sorted(os.listdir(out))
        elif epochs:
            raise ValueError(
                f"{out} holds a progress.csv of {epochs} epochs but no checkpoint to resume from; starting again "
                "would replace that log: move the directory away to start again, or use another directory"
            )
    # (temporary files are an atomic write's, cut short by a kill)
    foreign = [
        name
        for name in present
        if name not in _BEFORE_FIRST_CHECKPOINT and not name.endswith(".tmp") and _CUT_SHORT not in name
    ]
    if foreign:
        raise ValueError(
            f"{out} holds {', '.join(foreign)} and no pamdp checkpoint; expected a new or empty directory, "
            "or a run directory to resume"
        )


def _prepare(
    spec: RunSpec, out: str | os.PathLike, log=print, run_config: RunConfig | None = None
) -> tuple[Any, dict | None]:
    """The model to train for ``spec`` in ``out`` (new or resumed) and ``None``, or ``None`` and the evaluation of
    a run already finished. The caller holds ``out``'s :func:`run_lock`."""
    from pamdp.algos.checkpoints import CHECKPOINT, FINAL_MODEL
    from pamdp.atomic import atomic_write_text

    cls, preset, config, warning = run_config or spec.check()
    out = Path(out)
    run_info = {
        "algo": spec.algo,
        "env": spec.env,
        "env_kwargs": dict(spec.env_kwargs),
        "preset": preset,
        "total_steps": spec.total_steps,
        "config": config.to_dict(),
        "pamdp_version": __version__,  # of the code that last trained the run (a resumed run may span several)
        "git_commit": git_commit(),
    }
    if warning is not None:  # a preset made for another env: said at the run's start and kept with it
        warnings.warn(warning, UserWarning, stacklevel=2)
        run_info["preset_warning"] = warning
    if spec.label:  # what figures and tables call the run (its directory holds a file-name-safe form)
        run_info["label"] = spec.label
    if spec.init_from:
        run_info["init_from"] = spec.init_from
    if spec.init_keep:
        run_info["init_keep"] = list(spec.init_keep)
    if spec.init_widen:
        run_info["init_widen"] = list(spec.init_widen)
    run_file, eval_file = out / "run.json", out / "evaluation.json"
    if (out / CHECKPOINT).exists() or (out / FINAL_MODEL).exists():
        as_written = _read_run_json(run_file)
        if as_written.get("algo") != spec.algo:  # before its settings, which another algorithm does not know
            raise ValueError(
                f"{out} holds a run of algorithm {as_written.get('algo')!r}, not {spec.algo!r}; "
                "resume it with that algorithm or use another output directory"
            )
        recorded = dict(as_written)  # compared below with the defaults of settings added since filled in
        if "config" in recorded:  # settings added since the run started count as their defaults
            recorded["config"] = cls.config_class.from_dict(recorded["config"]).to_dict()
        recorded.setdefault("env_kwargs", {})
        differ = _differences(recorded, run_info)
        if differ:
            raise ValueError(
                f"{out} holds a run with other settings ({'; '.join(differ)}); "
                "resume it with the same settings or use another output directory"
            )
        if is_finished(out, spec):
            log(f"{out}: already finished")
            if spec.label and recorded.get("label") != spec.label:  # a run recorded before run.json held labels
                atomic_write_text(run_file, json.dumps({**as_written, "label": spec.label}, indent=2))
            if not (out / SUMMARY).exists():  # a run finished before runs wrote their summary
                write_summary(out)
            return None, json.loads(eval_file.read_text()) if eval_file.exists() else {}
        model = cls.load(out / CHECKPOINT if (out / CHECKPOINT).exists() else out / FINAL_MODEL)
        if model.num_timesteps > spec.total_steps:  # training cannot be undone; its evaluation stays as it is
            raise ValueError(
                f"{out} holds a run trained for {model.num_timesteps:,} steps, more than the {spec.total_steps:,} "
                f"asked; give its own budget of {as_written.get('total_steps', model.num_timesteps):,} steps to "
                "resume or skip it (more extends it), or use another output directory"
            )
        log(f"resuming {out} at step {model.num_timesteps:,} of {spec.total_steps:,}")
    else:
        _check_fresh_directory(out)
        model = cls(spec.env, config, env_kwargs=dict(spec.env_kwargs))
        if spec.init_from:
            _warm_start(model, spec.init_from, log, spec.init_keep, spec.init_widen)
    atomic_write_text(run_file, json.dumps({**run_info, "command": sys.argv}, indent=2))
    return model, None


def _warm_start(model, source: str, log, keep: tuple[str, ...] = (), widen: tuple[str, ...] = ()) -> None:
    """Start ``model``'s networks from the model in ``source``, its observation's features matched by name where
    the two envs' observations differ (``feature_names`` of their domains, e.g. Half Field Offense 1v0 and 1v1). A
    run directory gives its final model: a run still training (only a checkpoint) is refused."""
    from pamdp.algos.checkpoints import FINAL_MODEL, read_checkpoint, transfer_weights

    if Path(source).is_dir():
        if not (Path(source) / FINAL_MODEL).is_file():
            raise ValueError(
                f"cannot start from {source}: it holds no {FINAL_MODEL} (a run not finished yet, or no run); "
                "expected a finished run directory or a model file"
            )
        source = str(Path(source) / FINAL_MODEL)
    payload = read_checkpoint(source)
    new = model.observation_space.shape[0]
    old = int((payload.get("shapes") or {}).get("observation", [new])[0])
    columns = None
    if old != new:
        names = _feature_names(model.env_id, model.env_kwargs)
        source_names = _feature_names(payload.get("env_id"), payload.get("env_kwargs") or {})
        if names is None or source_names is None or len(source_names) != old:
            raise ValueError(
                f"cannot start from {source}: its env's observation has {old} features, this one's {new}, and the "
                "envs do not name their features; expected a model of an env with this observation"
            )
        columns = [source_names.index(n) if n in source_names else None for n in names]
    mapped = sum(v == "inputs mapped" for v in transfer_weights(model, source, columns, keep, widen).values())
    new_features = 0 if columns is None else sum(c is None for c in columns)
    kept = f"; kept its own {', '.join(keep)}" if keep else ""
    kept += f"; widened {', '.join(widen)}" if widen else ""
    log(f"networks started from {source} ({mapped} input layers mapped, {new_features} new features start at 0{kept})")


def _feature_names(env_id: str | None, env_kwargs: dict) -> list[str] | None:
    """The names of an env's observation features, where its domain gives them."""
    if env_id is None:
        return None
    import gymnasium as gym

    env = gym.make(env_id, **env_kwargs)
    try:
        names = getattr(getattr(env.unwrapped, "domain", None), "feature_names", None)
        return None if names is None else list(names)
    finally:
        env.close()


def _train(model, spec: RunSpec, out: str | os.PathLike, progress_bar: bool, log=print, callback=None) -> dict:
    """Train a prepared model to ``spec``'s budget, save its final model and evaluate it.

    ``callback``: ``learn``'s, called after every epoch (and its checkpoint).
    """
    from pamdp.algos.checkpoints import FINAL_MODEL
    from pamdp.atomic import atomic_write_text
    from pamdp.evaluation import evaluate

    out = Path(out)
    start, start_steps = time.time(), model.num_timesteps
    model.learn(
        max(spec.total_steps - model.num_timesteps, 0),
        progress_bar=progress_bar,
        run_dir=out,
        eval_every=spec.eval_every,
        callback=callback,
    )
    model.save(out / FINAL_MODEL, replay=False)  # for acting; checkpoint.pt keeps the buffer for resuming
    updates = f"{model.num_updates:,} gradient updates" if model.num_updates else "no gradient update: untrained"
    log(
        f"trained {model.num_timesteps - start_steps:,} steps in {time.time() - start:.0f} s, "
        f"{model.num_timesteps:,} of {spec.total_steps:,} in all ({updates}); model in {out / FINAL_MODEL}"
    )
    result = {}
    if spec.eval_episodes > 0:
        result = evaluate(model, episodes=spec.eval_episodes, seed=10_000 + spec.seed)
        atomic_write_text(out / "evaluation.json", json.dumps(result, indent=2))
    write_summary(out)  # last: it reads the evaluation
    return result


def train_run(
    spec: RunSpec,
    out: str | os.PathLike,
    progress_bar: bool = True,
    log=print,
    callback=None,
    run_config: RunConfig | None = None,
) -> dict:
    """Train (or resume, or skip) one run in ``out``; returns its evaluation (or ``{}`` without one).

    ``callback``: called after every epoch (and its checkpoint) with the model and the epoch's statistics.
    ``run_config``: ``spec.check()`` where the caller has checked the spec already (``None``: checked here).
    """
    with run_lock(out):
        model, done = _prepare(spec, out, log, run_config)
        return done if model is None else _train(model, spec, out, progress_bar, log, callback=callback)


def _stop_when_orphaned(parent: int, every: float = 1.0) -> None:
    """End this worker process once its runner ``parent`` is gone (killed, say, with ``kill`` rather than Ctrl-C,
    which reaches the whole process group): an orphan would train on unseen and hold its run's lock, so that the
    runner started again could not resume the run. The run keeps its last checkpoint to resume from."""
    import signal
    import threading

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(every)
        os.kill(os.getpid(), signal.SIGTERM)

    threading.Thread(target=watch, name="pamdp-orphan-watch", daemon=True).start()


def _also_to(log, run: str, show):
    """A ``warnings.showwarning`` that also writes each warning to the run's ``log`` (its ``stdout.log``, kept with
    the run: a diverged critic, say) and names the ``run`` in the one shown, which the runs beside it share."""

    def shown(message, category, filename, lineno, file=None, line=None):
        print(f"{category.__name__}: {message}", file=log, flush=True)
        show(f"{run}: {message}", category, filename, lineno, file, line)

    return shown


def _worker(spec: RunSpec, out: str, callback=None, parent: int | None = None) -> dict:
    import torch

    from pamdp._memory import keep_freed_memory

    if parent is not None:
        _stop_when_orphaned(parent)
    keep_freed_memory()  # a spawned process: the parent's allocator settings are not inherited
    torch.set_num_threads(1)
    log_file = Path(out) / "stdout.log"
    Path(out).mkdir(parents=True, exist_ok=True)
    with open(log_file, "a") as f, warnings.catch_warnings():
        warnings.showwarning = _also_to(f, f"{spec.label or spec.algo}, seed {spec.seed}", warnings.showwarning)
        return train_run(
            spec, out, progress_bar=False, log=lambda msg: print(msg, file=f, flush=True), callback=callback
        )


@dataclasses.dataclass
class RunOutcome:
    spec: RunSpec
    out: str
    result: dict | None
    error: str | None
    seconds: float


def _ready(pending: list, running) -> list:
    """The jobs of ``pending`` whose ``init_from`` names no job still pending or ``running``, in order."""
    unfinished = {os.path.normpath(out) for _, out in [*pending, *running]}
    return [job for job in pending if os.path.normpath(job[0].init_from or ".") not in unfinished]


def _started_after_their_sources(jobs: list) -> list:
    """``jobs`` in their order but for a run started from another job's model, which comes after that job."""
    ordered, pending = [], list(jobs)
    while pending:
        job = (_ready(pending, ()) or pending)[0]  # none ready: a circle of init_from, whose runs then fail
        ordered.append(job)
        pending.remove(job)
    return ordered


def run_all(jobs: list[tuple[RunSpec, str]], workers: int = 1, log=print) -> list[RunOutcome]:
    """Run ``(spec, out_dir)`` jobs, ``workers`` at a time in separate processes (1: in this process); a run
    started from another job's model (``init_from``) starts once that job has ended, the others in their order."""
    outcomes: list[RunOutcome] = []
    if workers <= 1:
        for spec, out in _started_after_their_sources(jobs):
            t0 = time.time()
            try:
                o = RunOutcome(spec, out, _worker(spec, out), None, time.time() - t0)
            except Exception:
                o = RunOutcome(spec, out, None, traceback.format_exc(), time.time() - t0)
            outcomes.append(o)
            log(_describe(o))
        return outcomes
    ctx = multiprocessing.get_context("spawn")

    def run_job(spec: RunSpec, out: str) -> RunOutcome:
        # A process pool of its own per run: a worker that dies (killed, out of memory) breaks only its own
        # pool, so it fails its own run alone while the runs beside it go on.
        t0 = time.time()
        try:
            with cf.ProcessPoolExecutor(max_workers=1, mp_context=ctx) as pool:
                result = pool.submit(_worker, spec, out, None, os.getpid()).result()
                return RunOutcome(spec, out, result, None, time.time() - t0)
        except Exception as exc:
            return RunOutcome(spec, out, None, "".join(traceback.format_exception(exc)), time.time() - t0)

    pending, running = list(jobs), {}
    with cf.ThreadPoolExecutor(max_workers=workers) as threads:
        while pending or running:
            ready = _ready(pending, running.values())
            for job in (ready or pending[:1] * (not running))[: workers - len(running)]:  # [:1]: a circle fails
                pending.remove(job)
                running[threads.submit(run_job, *job)] = job
            finished, _ = cf.wait(running, return_when=cf.FIRST_COMPLETED)
            for fut in finished:
                del running[fut]
                outcomes.append(fut.result())
                log(_describe(outcomes[-1]))
    return outcomes


def _describe(o: RunOutcome) -> str:
    if o.error is not None:
        return f"FAILED {o.out} after {o.seconds:.0f} s:\n{o.error}"
    ret = o.result.get("mean_return") if o.result else None
    return f"done {o.out} in {o.seconds:.0f} s" + (f": greedy return {ret:.3f}" if ret is not None else "")
