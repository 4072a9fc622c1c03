"""Single training runs and the multi-seed runner behind ``pamdp train`` and ``pamdp reproduce``.

A run lives in one directory: ``run.json`` (what was asked), ``progress.csv``, ``tb/``, ``checkpoint.pt``,
``final_model.pt`` and ``evaluation.json``. :func:`train_run` is resumable: a directory with a final model
and an evaluation is done and skipped; one with a checkpoint continues from it; settings that differ from
the recorded ones are refused rather than mixed into one log.

:func:`run_all` executes many runs, side by side in worker processes (one torch thread each), and reports
a failed run with its error while the others finish.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import json
import multiprocessing
import os
import sys
import threading
import time
import traceback
from pathlib import Path
from typing import Any

from pamdp.algos import ALGORITHMS, DEFAULT_PRESET, algorithm_class, default_preset

__all__ = [
    "RunSpec",
    "default_preset",
    "train_run",
    "is_finished",
    "run_all",
    "group_jobs",
    "train_stack",
    "algorithm_class",
    "ALGORITHMS",
    "DEFAULT_PRESET",
]


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

    def config(self):
        cls = algorithm_class(self.algo)
        if cls is None:
            raise ValueError(f"algorithm {self.algo!r} is not available in this install")
        preset = self.preset or default_preset(cls.config_class)
        base = cls.config_class.preset(preset)
        return cls, preset, cls.config_class.from_dict({**dict(self.settings), "seed": self.seed}, base=base)


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


def _prepare(spec: RunSpec, out: str | os.PathLike, log=print) -> tuple[Any, dict | None]:
    """The model to train for ``spec`` in ``out`` (new or resumed) and ``None``, or ``None`` and the evaluation of
    a run already finished."""
    from pamdp.algos.checkpoints import CHECKPOINT, FINAL_MODEL, atomic_write_text

    cls, preset, config = spec.config()
    out = Path(out)
    run_info = {
        "algo": spec.algo,
        "env": spec.env,
        "env_kwargs": dict(spec.env_kwargs),
        "preset": preset,
        "total_steps": spec.total_steps,
        "config": config.to_dict(),
    }
    if spec.label:  # what figures and tables call the run (its directory holds a file-name-safe form)
        run_info["label"] = spec.label
    run_file, eval_file = out / "run.json", out / "evaluation.json"
    if (out / CHECKPOINT).exists() or (out / FINAL_MODEL).exists():
        as_written = json.loads(run_file.read_text()) if run_file.exists() else {}
        recorded = dict(as_written)  # compared below with the defaults of settings added since filled in
        if "config" in recorded:  # settings added since the run started count as their defaults
            recorded["config"] = cls.config_class.from_dict(recorded["config"]).to_dict()
        recorded.setdefault("env_kwargs", {})
        differ = sorted(k for k in ("algo", "env", "env_kwargs", "config") if recorded.get(k) != run_info[k])
        if differ:
            raise ValueError(
                f"{out} holds a run with other {', '.join(differ)}; "
                "resume it with the same settings or use another output directory"
            )
        if is_finished(out, spec):
            log(f"{out}: already finished")
            if spec.label and recorded.get("label") != spec.label:  # a run recorded before run.json held labels
                atomic_write_text(run_file, json.dumps({**as_written, "label": spec.label}, indent=2))
            return None, json.loads(eval_file.read_text()) if eval_file.exists() else {}
        model = cls.load(out / CHECKPOINT if (out / CHECKPOINT).exists() else out / FINAL_MODEL)
        log(f"resuming {out} at step {model.num_timesteps:,} of {spec.total_steps:,}")
    else:
        out.mkdir(parents=True, exist_ok=True)
        model = cls(spec.env, config, env_kwargs=dict(spec.env_kwargs))
    atomic_write_text(run_file, json.dumps({**run_info, "command": sys.argv}, indent=2))
    return model, None


def _train(
    model, spec: RunSpec, out: str | os.PathLike, progress_bar: bool, log=print, trained=None, callback=None
) -> dict:
    """Train a prepared model to ``spec``'s budget, save its final model and evaluate it.

    ``trained``: called once training is over, before saving and evaluating (a seed stack's ``leave``).
    ``callback``: ``learn``'s, called after every epoch (and its checkpoint).
    """
    from pamdp.algos.checkpoints import FINAL_MODEL, atomic_write_text
    from pamdp.evaluation import evaluate

    out = Path(out)
    start = time.time()
    model.learn(
        max(spec.total_steps - model.num_timesteps, 0),
        progress_bar=progress_bar,
        run_dir=out,
        eval_every=spec.eval_every,
        callback=callback,
    )
    if trained is not None:
        trained()
    model.save(out / FINAL_MODEL, replay=False)  # for acting; checkpoint.pt keeps the buffer for resuming
    log(f"trained {model.num_timesteps:,} steps in {time.time() - start:.0f} s; model in {out / FINAL_MODEL}")
    if spec.eval_episodes <= 0:
        return {}
    result = evaluate(model, episodes=spec.eval_episodes, seed=10_000 + spec.seed)
    atomic_write_text(out / "evaluation.json", json.dumps(result, indent=2))
    return result


def train_run(spec: RunSpec, out: str | os.PathLike, progress_bar: bool = True, log=print, callback=None) -> dict:
    """Train (or resume, or skip) one run in ``out``; returns its evaluation (or ``{}`` without one).

    ``callback``: called after every epoch (and its checkpoint) with the model and the epoch's statistics.
    """
    model, done = _prepare(spec, out, log)
    return done if model is None else _train(model, spec, out, progress_bar, log, callback=callback)


def stack_key(spec: RunSpec):
    """Runs with the same key can share a seed stack (:mod:`pamdp.algos.stacking`); ``None``: this one cannot."""
    from pamdp.algos.stacking import can_stack

    cls = algorithm_class(spec.algo)
    if cls is None or not can_stack(cls):
        return None
    if hasattr(cls, "_stack_refusal") and cls._stack_refusal(spec.config()[2]):
        return None
    return json.dumps(dataclasses.asdict(dataclasses.replace(spec, seed=0)), sort_keys=True, default=repr)


def train_stack(specs: list[RunSpec], outs: list[str | os.PathLike], logs: list) -> list[Any]:
    """Train runs that differ in their seed only in one seed stack (each resumed or skipped as by
    :func:`train_run`); returns each run's evaluation, or the exception it failed with.

    Runs the stack cannot take together (resumed at Adam steps it cannot align, see
    :func:`pamdp.algos.stacking.step_class`) go in separate stacks, trained side by side in threads.
    """
    from pamdp.algos.stacking import SeedStack

    results: list[Any] = [None] * len(specs)
    models = {}
    for i, (spec, out, log) in enumerate(zip(specs, outs, logs)):
        try:
            model, done = _prepare(spec, out, log)
        except Exception as exc:  # noqa: BLE001 - this run fails, the others go on
            results[i] = exc
            continue
        if model is None:
            results[i] = done
        else:
            models[i] = model
    if not models:
        return results
    # Runs resumed at different Adam steps cannot share a stack: each class of them gets one, all of them
    # trained side by side in this process's threads.
    from pamdp.algos.stacking import adam_step, step_class

    classes: dict[int, list[int]] = {}
    for i, model in models.items():
        classes.setdefault(step_class(model), []).append(i)
    training = set(models)  # the runs whose training is not over; set.discard is atomic and idempotent

    def share() -> float:  # the process's CPU time goes to the runs still training in it
        return float(max(len(training), 1))

    def job(i):
        def train(leave):
            def trained():
                training.discard(i)
                leave()

            try:
                return _train(models[i], specs[i], outs[i], False, logs[i], trained=trained)
            finally:
                training.discard(i)

        return train

    def run_class(order: list[int]) -> None:
        seeds = [specs[j].seed for j in order]
        for i in order:
            models[i]._cpu_share = share
            if len(order) > 1:
                logs[i](f"stacked with seeds {seeds}; {len(models)} runs in this process")
            else:
                logs[i](f"in a stack of its own (Adam step {adam_step(models[i])}); {len(models)} runs in this process")
        try:
            for i, outcome in zip(order, SeedStack([models[i] for i in order]).run([job(i) for i in order])):
                results[i] = outcome
        except Exception as exc:  # noqa: BLE001 - the stack itself failed: so did each of its runs
            for i in order:
                results[i] = exc

    threads = [threading.Thread(target=run_class, args=(order,)) for order in classes.values()]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return results


def _worker(spec: RunSpec, out: str, callback=None) -> dict:
    import torch

    from pamdp._memory import keep_freed_memory

    keep_freed_memory()  # a spawned process: the parent's allocator settings are not inherited
    torch.set_num_threads(1)
    log_file = Path(out) / "stdout.log"
    Path(out).mkdir(parents=True, exist_ok=True)
    with open(log_file, "a") as f:
        return train_run(
            spec, out, progress_bar=False, log=lambda msg: print(msg, file=f, flush=True), callback=callback
        )


def _stack_worker(specs: list[RunSpec], outs: list[str]) -> list[Any]:
    """A process training a seed stack; a failed run's exception comes back as its traceback's text."""
    import contextlib

    import torch

    from pamdp._memory import keep_freed_memory

    keep_freed_memory()
    torch.set_num_threads(1)
    with contextlib.ExitStack() as files:
        logs = []
        for out in outs:
            Path(out).mkdir(parents=True, exist_ok=True)
            f = files.enter_context(open(Path(out) / "stdout.log", "a"))
            logs.append(lambda msg, f=f: print(msg, file=f, flush=True))
        results = train_stack(specs, outs, logs)
    return [_Failed("".join(traceback.format_exception(r))) if isinstance(r, BaseException) else r for r in results]


@dataclasses.dataclass
class _Failed:
    error: str


@dataclasses.dataclass
class RunOutcome:
    spec: RunSpec
    out: str
    result: dict | None
    error: str | None
    seconds: float


def group_jobs(jobs: list[tuple[RunSpec, str]], stack: int) -> list[list[tuple[RunSpec, str]]]:
    """``jobs`` in groups of at most ``stack`` runs that can share a seed stack (a group of one runs alone).

    The runs of a setting are split as evenly as ``stack`` allows: 5 seeds with ``stack = 3`` give 3 + 2.
    """
    if stack < 1:
        raise ValueError(f"stack = {stack!r}; expected an integer >= 1")
    by_key: dict[Any, list[tuple[RunSpec, str]]] = {}
    slots: list[Any] = []  # a lone job, or the key of a setting's stackable jobs, in the order jobs come
    for job in jobs:
        key = stack_key(job[0]) if stack > 1 else None
        if key is None:
            slots.append([job])
        else:
            if key not in by_key:
                slots.append(key)
            by_key.setdefault(key, []).append(job)
    groups: list[list[tuple[RunSpec, str]]] = []
    for slot in slots:
        if isinstance(slot, list):
            groups.append(slot)
            continue
        members = by_key[slot]
        n = -(-len(members) // stack)  # groups needed
        size, extra = divmod(len(members), n)
        start = 0
        for g in range(n):
            end = start + size + (g < extra)
            groups.append(members[start:end])
            start = end
    return groups


def run_all(jobs: list[tuple[RunSpec, str]], workers: int = 1, log=print, stack: int = 1) -> list[RunOutcome]:
    """Run ``(spec, out_dir)`` jobs, ``workers`` at a time in separate processes (1: in this process).

    ``stack``: seeds of one setting trained together in one process, for the algorithms that support it
    (:mod:`pamdp.algos.stacking`); a worker then runs a stack of up to ``stack`` runs.
    """
    outcomes: list[RunOutcome] = []
    groups = group_jobs(jobs, stack)

    def outcomes_of(group, results, t0) -> list[RunOutcome]:
        done = []
        for (spec, out), r in zip(group, results):
            if isinstance(r, _Failed):
                done.append(RunOutcome(spec, out, None, r.error, time.time() - t0))
            else:
                done.append(RunOutcome(spec, out, r, None, time.time() - t0))
        return done

    if workers <= 1:
        for group in groups:
            t0 = time.time()
            if len(group) > 1:
                specs, outs = [s for s, _ in group], [o for _, o in group]
                try:
                    new = outcomes_of(group, _stack_worker(specs, outs), t0)
                except Exception:
                    error = traceback.format_exc()
                    new = [RunOutcome(spec, out, None, error, time.time() - t0) for spec, out in group]
            else:
                spec, out = group[0]
                try:
                    new = [RunOutcome(spec, out, _worker(spec, out), None, time.time() - t0)]
                except Exception:
                    new = [RunOutcome(spec, out, None, traceback.format_exc(), time.time() - t0)]
            for o in new:
                outcomes.append(o)
                log(_describe(o))
        return outcomes
    ctx = multiprocessing.get_context("spawn")

    def run_group(group) -> list[RunOutcome]:
        # A process pool of its own per group: a worker that dies (killed, out of memory) breaks only its own
        # pool, so it fails its own runs alone while the runs beside it go on.
        t0 = time.time()
        try:
            with cf.ProcessPoolExecutor(max_workers=1, mp_context=ctx) as pool:
                if len(group) > 1:
                    specs, outs = [s for s, _ in group], [o for _, o in group]
                    return outcomes_of(group, pool.submit(_stack_worker, specs, outs).result(), t0)
                spec, out = group[0]
                return [RunOutcome(spec, out, pool.submit(_worker, spec, out).result(), None, time.time() - t0)]
        except Exception as exc:
            error = "".join(traceback.format_exception(exc))
            return [RunOutcome(spec, out, None, error, time.time() - t0) for spec, out in group]

    with cf.ThreadPoolExecutor(max_workers=workers) as threads:
        for fut in cf.as_completed([threads.submit(run_group, group) for group in groups]):
            for o in fut.result():
                outcomes.append(o)
                log(_describe(o))
    return outcomes


def _describe(o: RunOutcome) -> str:
    if o.error is not None:
        return f"FAILED {o.out} after {o.seconds:.0f} s:\n{o.error}"
    ret = o.result.get("mean_return") if o.result else None
    return f"done {o.out} in {o.seconds:.0f} s" + (f": greedy return {ret:.3f}" if ret is not None else "")
