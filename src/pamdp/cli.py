"""The ``pamdp`` command: ``train``, ``evaluate``, ``render`` (and, with the experiments, ``reproduce``, ``plot``,
``summarize``).

``pamdp train patrpo`` trains PATRPO on Platform with the tuned preset, shows a progress bar and ends with
a greedy evaluation. Every setting of the algorithm's config is also a flag (``--delta 0.01``,
``--hidden-sizes 64,64``), and ``--config FILE`` (TOML or JSON) sets several; the order of precedence is
preset, then file, then flags. A run writes into ``--out DIR``: ``run.json`` (what was asked),
``progress.csv``, ``tb/`` (TensorBoard), ``checkpoint.pt`` after every epoch, ``final_model.pt``,
``evaluation.json`` and ``summary.json``. Starting the same command again with the same ``--out`` resumes from the
checkpoint.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as dt
import json
import math
import os
import sys
import types
import typing
import warnings
from pathlib import Path

from pamdp import __version__
from pamdp._memory import keep_freed_memory
from pamdp.algos import ALGORITHMS, algorithm_class
from pamdp.experiments import available_experiments
from pamdp.experiments.runner import RunSpec, train_run
from pamdp.presets import default_preset, preset_names

MAX_STEPS = 10**12  # a budget beyond this is a typing slip (10^12 steps take decades on one core)
MAX_SEED = 2**32 - 1


class _Parser(argparse.ArgumentParser):
    """Options spelled out in full (``--delt`` is no ``--delta``), and a refusal in one line naming the value."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")

    def parse_args(self, args=None, namespace=None):
        """As argparse's, but an unknown option is refused by the command it was given to, not by ``pamdp``."""
        parsed, extra = self.parse_known_args(args, namespace)
        if extra:
            prog = " ".join(filter(None, (self.prog, getattr(parsed, "command", None))))
            self.exit(2, f"{prog}: error: unrecognized arguments: {' '.join(extra)} (see {prog} --help)\n")
        return parsed


def _items(text: str, example: str = "64,64") -> list[str]:
    """The items of a comma-separated list; an empty one (``64,,32``, ``64,``) is a slip, not a separator."""
    items = [t.strip() for t in text.split(",")]
    if any(not t for t in items):
        expected = f"expected comma-separated values such as {example}"
        raise argparse.ArgumentTypeError(f"{text!r} has an empty item; {expected}")
    return items


def _whole(text: str) -> int | None:
    """``text`` as an integer, also written as an integral float (``1e6``) or with underscores; else ``None``."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        value = float(text)
    except ValueError:
        return None
    return int(value) if math.isfinite(value) and value == int(value) else None


def _integer(low: int, high: int | None = None, what: str = "an integer"):
    """An argparse type: an integer from ``low`` to ``high`` (``1e6`` accepted)."""
    expected = f"{what} >= {low:,}" if high is None else f"{what} from {low:,} to {high:,}"

    def parse(text: str) -> int:
        value = _whole(text)
        if value is None or value < low or (high is not None and value > high):
            raise argparse.ArgumentTypeError(f"{text!r}; expected {expected}")
        return value

    return parse


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text!r}; expected a positive finite number such as 0.1")
    return value


def _parse_value(text: str, hint):
    """A command-line string as a value of the config field's type (tuples as comma-separated lists)."""
    origin = typing.get_origin(hint)
    if origin is tuple:
        (item,) = {a for a in typing.get_args(hint) if a is not Ellipsis}
        return [_parse_value(t, item) for t in _items(text)]
    if origin in (typing.Union, types.UnionType):
        if text.lower() == "none":
            return None
        hint = next(t for t in typing.get_args(hint) if t is not type(None))
    if hint is bool:
        if text.lower() in ("1", "true", "yes", "on"):
            return True
        if text.lower() in ("0", "false", "no", "off"):
            return False
        raise argparse.ArgumentTypeError(f"{text!r} is not a boolean; expected true or false")
    if hint is int:
        value = _whole(text)
        if value is None:
            raise argparse.ArgumentTypeError(f"{text!r} is not a valid int; expected an integer such as 64")
        return value
    try:
        return hint(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"{text!r} is not a valid {hint.__name__}") from exc


_positive_int = _integer(1)
_count = _integer(0)
_seed = _integer(0, MAX_SEED, "a seed")


MAX_RANGE = 1000
"""The most seeds one range of ``--seeds`` may name."""


def _seed_list(text: str) -> list[int]:
    """Comma-separated seeds, each a seed or an inclusive range ``first-last`` (``0-4,9``)."""
    seeds: list[int | None] = []
    for item in text.split(","):
        first, dash, last = item.partition("-")
        if first and dash:  # a range; a leading "-" is a negative seed, refused below
            low, high = _whole(first), _whole(last)
            if low is None or high is None or not 0 <= low <= high <= MAX_SEED:
                raise argparse.ArgumentTypeError(f"{text!r}: {item!r} is not a range first-last; expected such as 5-9")
            if high - low >= MAX_RANGE:  # a run a seed: a range this long is a typing slip, not an experiment
                raise argparse.ArgumentTypeError(
                    f"{text!r}: {item!r} names {high - low + 1} seeds; expected at most {MAX_RANGE}"
                )
            seeds.extend(range(low, high + 1))
        else:
            seeds.append(_whole(item))
    if any(s is None or not 0 <= s <= MAX_SEED for s in seeds):
        raise argparse.ArgumentTypeError(
            f"{text!r}; expected comma-separated seeds >= 0 or ranges, such as 0,1,2 or 0-4"
        )
    twice = sorted({s for s in seeds if seeds.count(s) > 1})
    if twice:  # two runs of one seed would write one run directory
        raise argparse.ArgumentTypeError(f"{text!r} names seed {twice[0]} twice; expected each seed once")
    return seeds


def _json_object(text: str) -> dict:
    try:
        value = json.loads(text)
    except json.JSONDecodeError as exc:
        raise argparse.ArgumentTypeError(f"{text!r} is not valid JSON ({exc.msg}); expected an object") from exc
    if not isinstance(value, dict):
        raise argparse.ArgumentTypeError(f"{text!r}; expected a JSON object such as '{{\"deterministic\": true}}'")
    return value


def _add_config_flags(parser: argparse.ArgumentParser, config_class) -> None:
    group = parser.add_argument_group(f"{config_class.__name__} settings (override the preset)")
    hints = config_class.field_types()
    for f in dataclasses.fields(config_class):
        if f.name == "seed":
            continue
        hint = hints[f.name]
        check = config_class.check_of(f.name)
        group.add_argument(
            "--" + f.name.replace("_", "-"),
            dest="cfg_" + f.name,
            type=lambda s, h=hint: _parse_value(s, h),
            default=None,
            metavar=f.name.upper(),
            help=f.metadata.get("help", "") + (f" Valid: {check.expected}." if check else ""),
        )


def _read_config_file(path: str) -> dict:
    try:
        text = Path(path).read_text()
    except OSError as exc:
        raise ValueError(f"config file {path!r}: {exc.strerror}; expected a TOML or JSON file of settings") from exc
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    kind = "JSON" if path.endswith(".json") else "TOML"
    try:
        values = json.loads(text) if kind == "JSON" else tomllib.loads(text)
    except (json.JSONDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ValueError(f"config file {path!r} is not valid {kind}: {exc}") from exc
    if not isinstance(values, dict):
        raise ValueError(f"config file {path!r} holds a {type(values).__name__}; expected a table of settings")
    return values


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="pamdp", description="Reinforcement learning in parameterized action spaces.")
    parser.add_argument("--version", action="version", version=f"pamdp {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    names = [name for name in ALGORITHMS if algorithm_class(name) is not None]
    train = sub.add_parser("train", help=f"train {', '.join(names)} (default env: Platform), then evaluate it")
    algos = train.add_subparsers(dest="algo", required=True, metavar="ALGO")
    for name in ALGORITHMS:
        cls = algorithm_class(name)
        if cls is None:
            continue
        p = algos.add_parser(name, help=ALGORITHMS[name].help)
        p.add_argument("--env", default="pamdp/Platform-v0", help="registered env id (default: %(default)s)")
        p.add_argument("--env-kwargs", type=_json_object, default=None, help="JSON object of env constructor arguments")
        p.add_argument("--seed", type=_seed, default=None, help="random seed (default: the config file's, else 0)")
        p.add_argument(
            "--total-steps",
            type=_integer(1, MAX_STEPS, "a number of steps"),
            default=None,
            help=f"environment steps, 1e6 or 1000000 (default: {ALGORITHMS[name].total_steps:,})",
        )
        p.add_argument(
            "--out", default=None, help="run directory (default: runs/ALGO-ENV-seedN-TIME); reuse it to resume"
        )
        p.add_argument(
            "--preset",
            default=None,
            choices=preset_names(cls.config_class),
            help=f"settings preset (default: the env's where it has one, else {default_preset(cls.config_class)})",
        )
        p.add_argument("--config", default=None, help="TOML or JSON file of settings")
        p.add_argument(
            "--init-from",
            default=None,
            metavar="MODEL",
            help="start the networks from a model of the same algorithm (a run directory or model file), trained on "
            "this env or one whose features this env's observation extends (Half Field Offense 1v0 for 1v1)",
        )
        p.add_argument(
            "--init-keep",
            type=_names,
            default=(),
            metavar="TENSORS",
            help="with --init-from: comma-separated tensors that keep this run's own initialisation, e.g. "
            "policy.log_std (PATRPO's exploration, then set by --init-log-std), or rows of one: policy.log_std[2]",
        )
        p.add_argument(
            "--init-widen",
            type=_names,
            default=(),
            metavar="TENSORS",
            help="with --init-from: comma-separated tensors that take, entry by entry, the larger of the model's and "
            "this run's own initialisation, e.g. policy.log_std: exploration at least --init-log-std",
        )
        p.add_argument(
            "--eval-episodes", type=_count, default=1000, help="greedy evaluation episodes at the end (0: none)"
        )
        p.add_argument(
            "--eval-every",
            type=_count,
            default=0,
            help="epochs between greedy evaluations of 100 episodes during training, logged as eval/* (0: none)",
        )
        p.add_argument("--no-progress", action="store_true", help="no progress bar")
        p.add_argument(
            "--wandb",
            action="store_true",
            help="log to Weights & Biases too: the figures of progress.csv, the config, the final evaluation "
            '(needs pip install "pamdp[wandb]"; WANDB_MODE=offline: local files only)',
        )
        p.add_argument("--wandb-project", default="pamdp", help="W&B project with --wandb (default: %(default)s)")
        _add_config_flags(p, cls.config_class)

    ev = sub.add_parser("evaluate", help="evaluate a trained model (a run directory or a model file)")
    ev.add_argument("model", help="run directory written by `pamdp train`, or a saved model file")
    ev.add_argument("--episodes", type=_positive_int, default=1000, help="episodes to play (default: %(default)s)")
    ev.add_argument(
        "--seed", type=_seed, default=None, help="env seed (default: 10000 + the training seed, as train's)"
    )
    ev.add_argument("--stochastic", action="store_true", help="sample actions instead of the greedy ones")
    ev.add_argument("--json", action="store_true", help="print one JSON object")

    rp = sub.add_parser(
        "reproduce", help="run an experiment (the paper's figures, the benchmark suite) and plot it: all runs and seeds"
    )
    rp.add_argument("name", help=f"{', '.join(available_experiments())}, or an experiment TOML file")
    rp.add_argument(
        "--seeds",
        type=_seed_list,
        default=None,
        help="comma-separated seeds or ranges, e.g. 0-4,9 (default: the experiment's)",
    )
    rp.add_argument(
        "--runs", type=_items, default=None, help="comma-separated run labels to run (default: all), e.g. --runs PATRPO"
    )
    rp.add_argument(
        "--scale", type=_positive_float, default=1.0, help="multiply the step budget, e.g. 0.1 for a quick look"
    )
    rp.add_argument(
        "--workers", type=_positive_int, default=1, help="runs side by side in processes (one torch thread each)"
    )
    rp.add_argument("--out", default="results", help="results root (default: %(default)s)")
    rp.add_argument("--backend", choices=["local", "ray"], default="local", help="local processes or a Ray cluster")
    rp.add_argument("--address", default=None, help="Ray cluster address HOST:PORT (with --backend ray)")
    rp.add_argument(
        "--status",
        action="store_true",
        help="train nothing: list each run's state (done, partial, not started, recorded) and the training time "
        "still to go",
    )
    rp.add_argument(
        "--recorded",
        default=None,
        metavar="DIR",
        help="kept run summaries (DIR/ARM/seedN.json, as `pamdp summarize --out` writes them, e.g. "
        "docs/results/summaries/benchmark-suite): a run with no finished directory under --out whose summary there "
        "is of the same settings, env, seed and budget is not trained again",
    )

    pl = sub.add_parser("plot", help="learning curves (PNG, SVG) and a results table from run directories")
    pl.add_argument("dirs", nargs="+", help="directories holding run directories (grouped by parent: one curve each)")
    pl.add_argument("--out", default=None, help="where to write curves.png/.svg, curves.csv, results.md")
    pl.add_argument("--title", default="")
    pl.add_argument(
        "--x",
        choices=["auto", "epochs", "samples"],
        default="auto",
        help="x axis: training epochs as the paper's figures, samples, or auto: epochs unless the settings' "
        "epochs differ in size (default: %(default)s)",
    )
    pl.add_argument(
        "--suite-archive",
        default=None,
        help="an earlier suite-finals.json (the benchmark suite's per-seed figures): its entries fill suite.md "
        "where no run at hand has their domain, method and seed",
    )

    sm = sub.add_parser(
        "summarize", help="each run's summary.json (settings, costs, greedy evaluations: a few KB) from its directory"
    )
    sm.add_argument("dirs", nargs="+", help="run directories, or directories holding them")
    sm.add_argument(
        "--out",
        default=None,
        help="write OUT/ARM/seedN.json (ARM: the run's label as a directory name) instead of RUN/summary.json, "
        "e.g. docs/results/summaries/EXPERIMENT",
    )
    sm.add_argument(
        "--finished",
        action="store_true",
        help="only the runs that finished (a final evaluation, or their whole budget): to collect a queue's results "
        "while some of its runs still train",
    )

    rd = sub.add_parser("render", help="write one episode to a GIF (a trained model, or random actions in an env)")
    rd.add_argument("source", help="run directory, model file, or a registered env id (random actions)")
    rd.add_argument("--out", default="episode.gif", help="GIF path (default: %(default)s)")
    rd.add_argument("--seed", type=_seed, default=0, help="env seed (default: %(default)s)")

    tu = sub.add_parser("tune", help="search an algorithm's settings on an env with Optuna; write the best as a preset")
    tu.add_argument("algo", metavar="ALGO", choices=names, help=", ".join(names))
    tu.add_argument("--env", default="pamdp/Platform-v0", help="registered env id (default: %(default)s)")
    tu.add_argument("--trials", type=_positive_int, default=20, metavar="N", help="in all, a resumed study's included")
    steps = _integer(1, MAX_STEPS, "a number of steps")
    tu.add_argument("--steps-per-trial", type=steps, default=200_000, metavar="S", help="a trial's budget (200,000)")
    where = tu.add_mutually_exclusive_group()
    where.add_argument("--study-dir", metavar="DIR", help="directory of the SQLite study (default: tune/ALGO-ENVNAME)")
    where.add_argument("--storage", metavar="URL", help="an Optuna storage URL instead, e.g. sqlite:///study.db")
    tu.add_argument("--workers", type=_positive_int, default=1, metavar="W", help="trials side by side in processes")
    tu.add_argument("--seed", type=_seed, default=0, help="the sampler's seed and every trial's (default: 0)")
    tu.add_argument("--pruner", choices=["median", "hyperband", "none"], default="median", help="(default: median)")
    tu.add_argument("--preset", default=None, help="the settings the search goes over (default: the env's, as train)")
    tu.add_argument("--eval-episodes", type=_positive_int, default=100, help="greedy episodes of each evaluation")
    tu.add_argument("--out", metavar="FILE", help="the best settings as a TOML preset (default: DIR/best.toml)")
    return parser


# -- train -------------------------------------------------------------------------------------------


def _names(text: str) -> tuple[str, ...]:
    """A comma-separated list of tensor names, none empty."""
    return tuple(_items(text, example="policy.log_std"))


def _train_spec(args, cls) -> RunSpec:
    for flag, names in (("--init-keep", args.init_keep), ("--init-widen", args.init_widen)):
        if names and not args.init_from:
            raise ValueError(f"{flag} {','.join(names)} without --init-from; expected both or neither")
    file_values = _read_config_file(args.config) if args.config else {}
    file_preset = file_values.pop("preset", None)
    preset = args.preset or file_preset
    seed = args.seed if args.seed is not None else file_values.pop("seed", 0)  # the config checks its type
    file_values.pop("seed", None)
    flags = {k[4:]: v for k, v in vars(args).items() if k.startswith("cfg_") and v is not None}
    total = args.total_steps if args.total_steps is not None else ALGORITHMS[args.algo].total_steps
    settings = {**file_values, **flags}
    env_kwargs = tuple(sorted((args.env_kwargs or {}).items()))
    return RunSpec(
        args.algo,
        args.env,
        total,
        seed,
        preset,
        tuple(sorted(settings.items())),
        args.eval_episodes,
        "",
        env_kwargs,
        args.eval_every,
        args.init_from or "",
        tuple(args.init_keep),
        tuple(args.init_widen),
    )


def cmd_train(args) -> int:
    cls = algorithm_class(args.algo)
    spec = _train_spec(args, cls)
    run_config = spec.check()  # the settings and the env's arguments, before any directory is created
    stamp = dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    out = Path(args.out or f"runs/{args.algo}-{args.env.split('/')[-1]}-seed{spec.seed}-{stamp}")
    tracker = _wandb_tracker(args, spec, run_config.preset, out) if args.wandb else None
    result = None
    try:
        result = train_run(
            spec,
            out,
            progress_bar=not args.no_progress,
            log=lambda m: print(m, file=sys.stderr),
            run_config=run_config,
            callback=tracker,
        )
    except KeyboardInterrupt:
        from pamdp.algos.checkpoints import CHECKPOINT

        if (out / CHECKPOINT).exists():
            print(f"\ninterrupted; the last checkpoint is in {out}: run the same command to resume", file=sys.stderr)
        else:
            print(
                "\ninterrupted before the first checkpoint; nothing to resume: run it again to start", file=sys.stderr
            )
        return 130
    finally:
        if tracker is not None:
            tracker.finish(summary=result)
    if result:
        print(_format_evaluation(result, env_id=args.env))
    return 0


def _wandb_tracker(args, spec: RunSpec, preset: str, out: Path):
    """``--wandb``'s tracker, refused at once (before the run directory is made) where wandb is not installed. The
    preset is the run's (the model, made from its settings, names none)."""
    from pamdp.callbacks import WandbCallback

    config = {"preset": preset, "total_steps": spec.total_steps, "run_dir": str(out)}
    try:
        return WandbCallback(project=args.wandb_project, name=out.name, config=config)
    except ImportError as exc:
        raise ValueError(str(exc)) from None


# -- reproduce, plot --------------------------------------------------------------------------------
def cmd_reproduce(args) -> int:
    from pamdp.experiments import load_experiment, results
    from pamdp.experiments.report import write_report

    exp = load_experiment(args.name)
    file = next((p for p in (Path(args.out), *Path(args.out).parents) if p.exists() and not p.is_dir()), None)
    if file is not None:  # else every run would fail alike, each with its traceback
        raise ValueError(f"--out {args.out}: {file} is a file; expected a results directory (new, or one to go on in)")
    seeds = args.seeds
    labels = args.runs
    jobs = exp.jobs(args.out, exp.specs(seeds, args.scale, labels))
    for spec, _ in jobs:
        spec.check()  # every setting and env argument is checked before the first run starts
    recorded = _recorded_runs(jobs, args.recorded) if args.recorded is not None else {}
    if args.status:
        from pamdp.experiments.status import format_status, recorded_status, run_status

        statuses = [
            recorded_status(spec, recorded[spec.label, spec.seed])
            if (spec.label, spec.seed) in recorded
            else run_status(spec, out)
            for spec, out in jobs
        ]
        print(format_status(exp.name, statuses, args.workers), end="")
        return 0
    if recorded:
        print(f"{exp.name}: {len(recorded)} runs recorded in {args.recorded}: not trained again", file=sys.stderr)
        jobs = [(spec, out) for spec, out in jobs if (spec.label, spec.seed) not in recorded]
        if not jobs:
            return 0
    root = Path(args.out) / exp.name
    root.mkdir(parents=True, exist_ok=True)  # else every run would fail alike: refused here in one line naming it
    if not os.access(root, os.W_OK):
        raise ValueError(f"--out {args.out}: {root} is not writable; expected a directory this user may write into")
    budgets = sorted({spec.total_steps for spec, _ in jobs})
    steps = f"{budgets[0]:,}" if len(budgets) == 1 else f"{budgets[0]:,} to {budgets[-1]:,}"
    print(f"{exp.name}: {exp.description}; {len(jobs)} runs of {steps} steps", file=sys.stderr)
    if args.backend == "ray":
        from pamdp.experiments.ray_backend import run_all_ray

        outcomes = run_all_ray(jobs, address=args.address, log=lambda m: print(m, file=sys.stderr))
    else:
        from pamdp.experiments.runner import run_all

        outcomes = run_all(jobs, workers=args.workers, log=lambda m: print(m, file=sys.stderr))
    failed = [o for o in outcomes if o.error is not None]
    planned = results.planned_cells(exp.specs())  # the whole experiment's cells, also those not run yet
    _print_report(
        write_report([Path(args.out) / exp.name], Path(args.out) / exp.name, exp.description, planned=planned)
    )
    if failed:
        print(f"{len(failed)} of {len(outcomes)} runs failed: {', '.join(o.out for o in failed)}", file=sys.stderr)
        return 1
    return 0


def _recorded_runs(jobs, root: str) -> dict:
    """``{(label, seed): its summary}`` for the jobs whose run directory is not finished and whose summary under
    ``root`` stands for it (:func:`.runner.recorded_differences`); a summary of another setting is named on stderr,
    and its run trains."""
    from pamdp.experiments.runner import is_finished, recorded_differences
    from pamdp.experiments.summary import load, summary_path

    if not Path(root).is_dir():
        raise ValueError(f"--recorded {root}: not a directory; expected one of run summaries (ARM/seedN.json)")
    found = {}
    for spec, out in jobs:
        path = summary_path(root, spec.label, spec.seed)
        if is_finished(out, spec) or not path.exists():
            continue
        summary = load(path)
        differ = recorded_differences(spec, summary)
        if differ:
            print(f"{path} is not this run ({'; '.join(differ)}): it trains", file=sys.stderr)
        else:
            found[spec.label, spec.seed] = summary
    return found


def cmd_plot(args) -> int:
    from pamdp.experiments.report import write_report

    _print_report(write_report(args.dirs, args.out or args.dirs[0], args.title, args.x, args.suite_archive))
    return 0


def cmd_summarize(args) -> int:
    from pamdp.experiments.plots import _run_dirs
    from pamdp.experiments.summary import save, summarize, write_summary

    runs = []
    for root in map(Path, args.dirs):
        if not root.is_dir():
            raise ValueError(f"{root} is not a directory; expected a run directory or one holding run directories")
        runs += [root] if (root / "run.json").exists() else _run_dirs(root)
    if not runs:
        raise ValueError(f"no run directories (with run.json and progress.csv) under {', '.join(args.dirs)}")
    kept = [(run, summarize(run)) for run in runs]  # each run summarized once, whether filtered, saved or written
    if args.finished:
        kept = [(run, s) for run, s in kept if s["finished"]]
        if not kept:
            print(f"no finished run under {', '.join(args.dirs)}", file=sys.stderr)
            return 0
    written = save([s for _, s in kept], args.out) if args.out else [write_summary(run, s) for run, s in kept]
    print("\n".join(map(str, written)))
    return 0


def _print_report(report: dict) -> None:
    """The results table on stdout, the figures' paths on stderr."""
    print(report["table"].read_text())
    if "suite" in report:
        print(report["suite"].read_text())
    if "stats" in report:
        print(report["stats"].read_text())
    figures = [v for k, v in report.items() if k.endswith(("png", "svg"))]
    print(f"figures: {', '.join(map(str, figures))}", file=sys.stderr)


# -- evaluate, render ----------------------------------------------------------------------------
# What a success is where the env's own word says it better than "success" (``info["is_success"]``)
SUCCESS_WORDS = {
    "pamdp/HalfFieldOffense-v0": "goal",
    "pamdp/HalfFieldOffenseGoalie-v0": "goal",
    "pamdp/Goal-v0": "goal",
    "pamdp/HardGoal-v0": "goal",
}


def _format_evaluation(result: dict, policy: str = "greedy", env_id: str | None = None) -> str:
    """One line: ``policy`` (greedy, or stochastic) return, length, and, where the env reports success, the
    success rate (the goal rate on the soccer envs) and the mean steps of the successful episodes."""
    from pamdp.logger import success_of

    text = (
        f"{policy} return over {result['episodes']} episodes: {result['mean_return']:.4f} +- {result['std_return']:.4f}"
    )
    text += f" (mean length {result['mean_length']:.1f} steps)"
    rate, steps = success_of(result)
    if rate is not None:
        word = SUCCESS_WORDS.get(env_id, "success")
        text += f"; {word} rate {rate:.3f}" + (f", {steps:.1f} steps to {word}" if steps is not None else "")
    if len(result.get("endings", {})) > 1:  # how the others ended, where the env says (HFO's statuses)
        text += "; endings: " + ", ".join(f"{name} {share:.3f}" for name, share in result["endings"].items())
    return text


def cmd_evaluate(args) -> int:
    from pamdp.algos import load_model
    from pamdp.evaluation import evaluate

    model = load_model(args.model)
    seed = args.seed if args.seed is not None else 10_000 + model.config.seed
    policy = "stochastic" if args.stochastic else "greedy"
    result = evaluate(model, episodes=args.episodes, seed=seed, deterministic=not args.stochastic)
    print(json.dumps({**result, "policy": policy}) if args.json else _format_evaluation(result, policy, model.env_id))
    return 0


def cmd_render(args) -> int:
    import gymnasium

    import pamdp  # noqa: F401  (registers the envs)
    from pamdp.algos import load_model
    from pamdp.envs.backends import env_creator
    from pamdp.envs.rendering import record_episode
    from pamdp.spaces import HybridActionSpace

    if args.source in gymnasium.registry:
        env_id, env_kwargs, policy, masked = args.source, {}, None, False
    else:  # a model trained with the env's action masks acts with them, as in training and evaluate
        model = load_model(args.source)
        env_id, env_kwargs, policy, masked = model.env_id, model.env_kwargs, model.predict, model.config.action_mask
    modes = getattr(env_creator(env_id), "metadata", {}).get("render_modes", [])
    if "rgb_array" not in modes:
        raise ValueError(f"env {env_id!r} draws no frames (render modes {modes}); expected one with 'rgb_array'")
    try:  # another package's env: its own errors (a missing drawing library) in one line too
        env = gymnasium.make(env_id, render_mode="rgb_array", **env_kwargs)
    except gymnasium.error.Error as exc:
        raise ValueError(f"env {env_id!r} cannot be made ({exc})") from None
    try:
        HybridActionSpace.from_gym(env.action_space)
    except ValueError:
        env.close()
        raise ValueError(
            f"env {env_id!r} has the action space {env.action_space}, not a parameterized one; expected a pamdp env "
            f"such as {', '.join(sorted(k for k in gymnasium.registry if k.startswith('pamdp/'))[:3])}"
        ) from None
    try:
        fps = env.metadata.get("render_fps") or 20  # the env's real time (Goal's sub-steps: 30 a second)
        path, total = record_episode(env, policy, args.out, seed=args.seed, fps=fps, action_mask=masked)
    except gymnasium.error.Error as exc:
        raise ValueError(f"env {env_id!r} cannot draw its frames ({exc})") from None
    finally:
        env.close()
    print(f"wrote {path} (return {total:.4f}, {fps:g} frames a second)")
    return 0


def cmd_tune(args) -> int:
    from pamdp.experiments.tune import Search, require_optuna, tune, write_preset

    require_optuna()
    name = f"{args.algo}-{args.env.split('/')[-1]}"
    root = Path(args.study_dir or f"tune/{name}")
    storage = args.storage or f"sqlite:///{root / 'study.db'}"
    out = Path(args.out or (root if args.storage is None else Path()) / "best.toml")
    search = Search(args.algo, args.env, args.trials, args.steps_per_trial, storage, name, seed=args.seed)
    search = dataclasses.replace(search, preset=args.preset, pruner=args.pruner, eval_episodes=args.eval_episodes)
    search.check()
    existing = next(p for p in (out.parent.absolute(), *out.parent.absolute().parents) if p.exists())
    if out.is_dir() or not existing.is_dir() or not os.access(existing, os.W_OK):
        raise ValueError(f"--out {args.out or out}: cannot be written ({existing} is not a writable directory)")
    out.parent.mkdir(parents=True, exist_ok=True)
    study = tune(search, workers=args.workers, log=lambda m: print(m, file=sys.stderr))
    info = write_preset(study, out)
    print(
        f"best {info['objective']} {info['best_value']:.4f} (trial {info['best_trial']}); {info['trials']} trials: "
        f"{info['complete']} complete, {info['pruned']} pruned, {info['failed']} failed; {info['cpu_seconds']:.0f} "
        f"CPU s\nwrote {out} and {out.with_suffix('.json')}: pamdp train {args.algo} --env {args.env} --config {out}"
    )
    return 0


def _warning_line(message, category, filename, lineno, line=None) -> str:
    return f"pamdp: warning: {str(message).replace(chr(10), ' ')}\n"


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.command in ("train", "reproduce", "evaluate"):
        keep_freed_memory()
    # A warning reads as one line of the command's, not as Python's "file:line: UserWarning:"; the API keeps those.
    formatwarning, warnings.formatwarning = warnings.formatwarning, _warning_line
    handlers = {
        "train": cmd_train,
        "evaluate": cmd_evaluate,
        "render": cmd_render,
        "reproduce": cmd_reproduce,
        "plot": cmd_plot,
        "summarize": cmd_summarize,
        "tune": cmd_tune,
    }
    try:
        return handlers[args.command](args)
    except KeyboardInterrupt:  # train says where its checkpoint is; the others stop as they are
        resume = "; run the same command to resume (finished runs are skipped)" if args.command == "reproduce" else ""
        print(f"\npamdp {args.command}: interrupted{resume}", file=sys.stderr)
        return 130
    except ValueError as exc:
        print(f"pamdp {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # a missing file, a read-only or full disk: the path and the system's reason
        if exc.filename is None:
            message = str(exc)
        else:
            message = f"{exc.filename}: {exc.strerror or exc}; expected a readable file or a writable directory"
        print(f"pamdp {args.command}: error: {message}", file=sys.stderr)
        return 2
    finally:
        warnings.formatwarning = formatwarning


if __name__ == "__main__":
    raise SystemExit(main())
