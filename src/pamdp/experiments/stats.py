"""Statistics a reviewer can trust: interval estimates over few runs, and sample efficiency from logged curves.

Agarwal et al. (2021), "Deep Reinforcement Learning at the Edge of the Statistical Precipice" (NeurIPS), showed
that the usual report of a deep-RL comparison, a mean or median of three to five runs per task without an
uncertainty estimate, often reverses when more runs are made. Their remedy, which this module follows:

- aggregate with the **interquartile mean** (IQM), robust to the odd failed or lucky run yet using half the
  runs, where the median uses one and the mean lets one outlier move it;
- always give an **interval**, from a **stratified bootstrap**: the runs are resampled with replacement within
  each task (here: each domain) independently, so each bootstrap sample keeps every task with its number of
  runs, as a rerun of the study would, and the aggregate is recomputed on each sample;
- show the whole distribution with **performance profiles** (the share of runs above each score), and compare
  two methods with the **probability of improvement** P(X > Y), which says how often a run of one beats a run
  of the other, not by how much.

The bootstrap is SciPy's :func:`scipy.stats.bootstrap` with the percentile method. Given several samples it
resamples each independently (``paired=False``), which is exactly the stratified scheme when each task's runs
are one sample; the aggregate is a statistic of all samples together. ``rliable``, the authors' library, was
not used: it was archived in 2025, its last release (1.2.0) installs but fails to import with pandas 3 (through
its ``arch`` dependency), and it brings ``arch``, pandas, seaborn and absl along for what SciPy does alone. On
pandas 2 it imports, and gives the same point estimates as this module and intervals within Monte-Carlo error.

Every function takes plain NumPy arrays; ``scores_by_task`` is a sequence of one array per task (domain), each
holding that task's runs. Scores from different domains should be normalised to a common scale (e.g. the goal
rate, or a return divided by the published best) before they are aggregated across domains.

The tasks may have different numbers of runs; each task then weighs the same in an aggregate, as in Agarwal et
al.'s score matrices of as many runs on every task (and as :func:`probability_of_improvement` averages over
tasks): before pooling, each task's runs are repeated to the least common multiple of the tasks' run counts.
Pooling them as they are would let the task with most runs set the aggregate, and running more seeds of one
domain would move a method's score across domains. With equal counts nothing is repeated.

The sample-efficiency measures read one run's evaluation curve (``steps``, ``values``), e.g. the greedy rate
logged every few epochs in ``progress.csv``; rows whose value is NaN (epochs without an evaluation) are dropped.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike
from scipy import stats

__all__ = [
    "Estimate",
    "Profile",
    "Reached",
    "aggregate",
    "interval",
    "iqm",
    "median_reached",
    "normalised_auc",
    "performance_profile",
    "probability_of_improvement",
    "rate_at_fractions",
    "samples_to_reach",
]

RESAMPLES = 2000  # Agarwal et al. use 2000 to 50000; 2000 puts a 95 % bound's Monte-Carlo error well below its width


class Estimate(NamedTuple):
    """A point estimate and its bootstrap interval (arrays for a vector-valued statistic)."""

    value: float | np.ndarray
    low: float | np.ndarray
    high: float | np.ndarray


class Profile(NamedTuple):
    """A performance profile: at each threshold tau, the share of runs scoring above tau, and its band."""

    thresholds: np.ndarray
    fraction: np.ndarray
    low: np.ndarray
    high: np.ndarray


class Reached(NamedTuple):
    """When a curve first reached a target: ``step``, or, if ``reached`` is False, the step it was censored at."""

    step: float
    reached: bool


def iqm(scores: ArrayLike, axis: int | None = None) -> float | np.ndarray:
    """The interquartile mean: the mean of the middle 50 % of the runs, the lowest and highest quarters dropped.

    A handful of runs per task makes the mean hostage to one diverged or lucky seed and the median to the
    one run in the middle; the IQM keeps half the runs, so it is nearly as statistically efficient as the
    mean and nearly as robust as the median (Agarwal et al. 2021, section 4.2).

    Over all runs of all tasks together (``axis=None``: flattened), as rliable's ``aggregate_iqm`` does.
    Quartile boundaries that fall between runs are rounded inwards to whole runs, as
    ``scipy.stats.trim_mean(x, 0.25)`` (which rliable calls) does: ``floor(n / 4)`` runs are dropped from each
    end, so for n not a multiple of 4 slightly more than half the runs are kept (10 runs: the middle 6).
    """
    x = np.asarray(scores, dtype=float)
    if axis is None:
        x, axis = x.ravel(), -1
    if x.shape[axis] == 0:
        raise ValueError("iqm of no scores")
    return stats.trim_mean(x, 0.25, axis=axis)


def _strata(scores_by_task: Sequence[ArrayLike], name: str = "scores_by_task") -> list[np.ndarray]:
    """The tasks' runs as 1-D float arrays, checked to be resamplable."""
    tasks = [np.asarray(t, dtype=float).ravel() for t in scores_by_task]
    if not tasks:
        raise ValueError(f"{name} holds no task")
    for i, t in enumerate(tasks):
        if len(t) < 2:  # one run resamples to itself: its task would add no spread, a too-narrow interval
            raise ValueError(f"{name}[{i}] has {len(t)} run(s); a bootstrap interval needs at least 2 per task")
    return tasks


def _equal_weights(samples, axis: int = -1) -> np.ndarray:
    """The tasks' runs concatenated along ``axis``, each task's runs repeated to the least common multiple of the
    tasks' run counts, so that every task weighs the same in a statistic of the pool."""
    counts = [x.shape[axis] for x in samples]
    common = math.lcm(*counts)
    return np.concatenate([np.repeat(x, common // n, axis=axis) for x, n in zip(samples, counts)], axis=axis)


def _pool_size(samples) -> int:
    """The length of :func:`_equal_weights`' pool, without building it."""
    return len(samples) * math.lcm(*(len(x) for x in samples))


def _bootstrap(samples: list[np.ndarray], statistic, confidence: float, resamples: int, seed: int):
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must lie in (0, 1), got {confidence}")
    if resamples < 1:
        raise ValueError(f"resamples must be at least 1, got {resamples}")
    result = stats.bootstrap(
        samples,
        statistic,
        n_resamples=resamples,
        confidence_level=confidence,
        method="percentile",  # as Agarwal et al.; BCa is NaN where the jackknife is flat, as at a profile's ends
        paired=False,  # each task's runs resampled on their own: the stratified bootstrap
        vectorized=True,
        batch=max(1, 1_000_000 // _pool_size(samples)),  # resampled pools of 1M values at a time at most
        rng=np.random.default_rng(seed),
    )
    return result.confidence_interval.low, result.confidence_interval.high


def aggregate(scores_by_task: Sequence[ArrayLike], statistic: Callable[..., float | np.ndarray] = iqm) -> float:
    """``statistic`` of the runs of all tasks together, each task weighing the same (the point estimate of
    :func:`interval`, which also takes tasks of a single run)."""
    tasks = [np.asarray(t, dtype=float).ravel() for t in scores_by_task]
    if not tasks or not all(len(t) for t in tasks):
        raise ValueError("aggregate needs at least one task, each with at least one run")
    return float(statistic(_equal_weights(tasks)))


def interval(
    scores_by_task: Sequence[ArrayLike],
    statistic: Callable[..., float | np.ndarray] = iqm,
    confidence: float = 0.95,
    resamples: int = RESAMPLES,
    seed: int = 0,
) -> Estimate:
    """An aggregate of all runs across tasks, with its stratified percentile-bootstrap interval.

    Each bootstrap sample redraws, for every task independently, as many runs as it has, with replacement;
    ``statistic`` is applied to the runs of all tasks together (each task weighing the same, see the module's
    notes), and the interval runs from the
    ``(1 - confidence) / 2`` to the ``(1 + confidence) / 2`` quantile of the ``resamples`` values it takes.
    Stratifying keeps each sample a study of the same tasks with the same number of runs: resampling the
    pooled runs instead could draw a sample made of one task's runs, widening the interval with a variability
    between tasks that a rerun of the study would never show.

    ``statistic(x, axis=-1)`` reduces the last axis of ``x`` (``iqm``, ``np.mean``, ``np.median``, ...) and
    receives the tasks' runs concatenated along it. For one task this is the ordinary bootstrap over its runs.
    Results are reproducible given ``seed``.
    """
    tasks = _strata(scores_by_task)

    def pooled(*samples, axis=-1):
        return statistic(_equal_weights(samples, axis=axis), axis=axis)

    low, high = _bootstrap(tasks, pooled, confidence, resamples, seed)
    return Estimate(pooled(*tasks), low, high)


def performance_profile(
    scores_by_task: Sequence[ArrayLike],
    thresholds: ArrayLike,
    confidence: float = 0.95,
    resamples: int = RESAMPLES,
    seed: int = 0,
) -> Profile:
    """The score distribution of the runs of all tasks: at each threshold tau, the share of runs scoring above it.

    A profile (Agarwal et al.'s "run-score distribution", after Dolan and More's profiles for optimisers)
    shows every quantile at once: one method's curve lying above another's at every tau says it is better
    whatever summary one picks. A run scoring exactly tau does not count as above it; each task weighs the same
    (the share is the average over tasks of each task's share). The band around the curve is the stratified
    percentile bootstrap of each point, as in :func:`interval`.
    """
    tasks = _strata(scores_by_task)
    tau = np.asarray(thresholds, dtype=float).ravel()

    def above(*samples, axis=-1):
        x = _equal_weights(samples, axis=axis)
        return np.mean(x > tau.reshape((-1,) + (1,) * x.ndim), axis=-1)  # thresholds first, as SciPy expects

    low, high = _bootstrap(tasks, above, confidence, resamples, seed)
    return Profile(tau, above(*tasks), np.asarray(low), np.asarray(high))


def probability_of_improvement(
    x_by_task: Sequence[ArrayLike],
    y_by_task: Sequence[ArrayLike],
    confidence: float = 0.95,
    resamples: int = RESAMPLES,
    seed: int = 0,
) -> Estimate:
    """P(X > Y): the chance that a run of method X beats a run of method Y on a task, averaged over tasks.

    On each task the probability is estimated by comparing every run of X with every run of Y, a tie
    counting one half: the Mann-Whitney U statistic divided by the number of pairs. Averaging over tasks
    weighs each task equally, whatever its number of runs. P(X > Y) = 0.5 means neither method tends to do
    better; unlike a difference of means it ignores by how much a run wins, so one huge score cannot make it.
    Agarwal et al. read an interval whose lower end exceeds 0.5 as a statistically meaningful improvement.

    The interval resamples the runs of X and of Y within each task independently (a stratified bootstrap).
    """
    xs, ys = _strata(x_by_task, "x_by_task"), _strata(y_by_task, "y_by_task")
    if len(xs) != len(ys):
        raise ValueError(f"x_by_task has {len(xs)} tasks, y_by_task {len(ys)}; both methods need the same tasks")

    def average(*samples, axis=-1):
        per_task = []
        for x, y in zip(samples[: len(xs)], samples[len(xs) :]):
            x, y = np.moveaxis(x, axis, -1)[..., :, None], np.moveaxis(y, axis, -1)[..., None, :]
            per_task.append(np.mean((x > y) + 0.5 * (x == y), axis=(-2, -1)))
        return np.mean(per_task, axis=0)

    low, high = _bootstrap(xs + ys, average, confidence, resamples, seed)
    return Estimate(float(average(*xs, *ys)), low, high)


def _curve(steps: ArrayLike, values: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The evaluations of a curve: NaN values dropped, steps checked to increase."""
    s, v = np.asarray(steps, dtype=float).ravel(), np.asarray(values, dtype=float).ravel()
    if s.shape != v.shape:
        raise ValueError(f"steps has {len(s)} points, values {len(v)}")
    s, v = s[~np.isnan(v)], v[~np.isnan(v)]
    if np.any(np.diff(s) <= 0):
        raise ValueError("steps must increase strictly along the curve")
    return s, v


def rate_at_fractions(
    steps: ArrayLike, values: ArrayLike, budget: float, fractions: Sequence[float] = (0.1, 0.25, 0.5, 1.0)
) -> np.ndarray:
    """The curve's value at fixed fractions of the training budget: how far a run got with a tenth of its samples.

    At each fraction f, the last evaluation made at or before step ``f * budget`` (never a later one, which
    would credit the run with samples it had not yet used). NaN where no evaluation had been made by then.
    """
    s, v = _curve(steps, values)
    limits = np.asarray(fractions, dtype=float) * budget
    last = np.searchsorted(s, limits * (1 + 1e-12), side="right") - 1  # 1e-12: 0.1 * budget may round below
    return np.where(last >= 0, v[np.maximum(last, 0)], np.nan)


def samples_to_reach(steps: ArrayLike, values: ArrayLike, target: float, budget: float | None = None) -> Reached:
    """The first step at which the curve's value is at least ``target`` (e.g. 90 % of the published best rate).

    A run that never reached it is censored, not dropped or given an invented time: the result is
    ``Reached(budget, False)`` (the last evaluated step if no ``budget`` is given), meaning "more than this".
    Averaging censored times as if they were reached would flatter the slow method; report the share reached
    beside them, or a survival estimate.
    """
    s, v = _curve(steps, values)
    hit = np.flatnonzero(v >= target)
    if len(hit):
        return Reached(float(s[hit[0]]), True)
    if budget is None and not len(s):
        raise ValueError("a curve with no evaluation and no budget has no step to be censored at")
    return Reached(float(budget if budget is not None else s[-1]), False)


def median_reached(results: Sequence[Reached]) -> Reached:
    """The median over runs of :func:`samples_to_reach`, censored runs included as what they are: later than the
    step they were censored at.

    A censored run ranks after every run that reached the target (its time is unknown but beyond its budget, and
    runs of one cell share a budget), so the median is known whenever more than half the runs reached it: the
    middle run's step (the mean of the two middle ones for an even number of runs). Where a middle run is censored,
    the result is censored too: ``Reached(b, False)``, "more than b", with the censored middle runs counted at their
    censoring step. Dropping the censored runs instead would report the fast minority's median.
    """
    if not results:
        raise ValueError("median_reached of no runs")
    reached = sorted(r.step for r in results if r.reached)
    censored = sorted(r.step for r in results if not r.reached)
    if censored and reached and censored[0] < reached[-1]:
        raise ValueError(
            f"a run censored at step {censored[0]:g} before another reached the target at {reached[-1]:g}; "
            "expected the runs of one budget"
        )
    ranked = reached + censored
    middle = ranked[(len(ranked) - 1) // 2 : len(ranked) // 2 + 1]
    return Reached(float(np.mean(middle)), len(ranked) // 2 < len(reached))


def normalised_auc(steps: ArrayLike, values: ArrayLike, budget: float, initial: float | None = None) -> float:
    """The area under the curve over [0, budget] divided by ``budget``: the curve's average over training.

    A rate in [0, 1] gives an AUC in [0, 1], 1 for a run at full rate from its first sample; it rewards
    learning early as well as ending high. The curve is joined linearly between evaluations (trapezoids)
    and held flat after its last one; past ``budget`` it is cut at ``budget``. Before its first evaluation
    the curve starts from ``initial`` at step 0 when given (e.g. an untrained policy's rate), else its first
    value is held flat back to step 0, which invents no value but credits a run's first evaluation to the
    samples before it (the same for every method evaluated on the same schedule).
    """
    if budget <= 0:
        raise ValueError(f"budget must be positive, got {budget}")
    s, v = _curve(steps, values)
    if not len(s):
        raise ValueError("a curve with no evaluation has no area")
    if initial is not None and s[0] > 0:
        s, v = np.concatenate([[0.0], s]), np.concatenate([[initial], v])
    grid = np.unique(np.concatenate([[0.0, budget], s[(s > 0) & (s < budget)]]))
    y = np.interp(grid, s, v)  # interp holds the curve flat before its first point and after its last
    return float(np.sum(np.diff(grid) * (y[1:] + y[:-1]) / 2) / budget)
