"""The statistics of pamdp.experiments.stats against independent computations: sorting, counting, enumerating."""

import itertools
import math

import numpy as np
import pytest
from scipy import stats as scipy_stats

from pamdp.experiments import stats


def test_iqm_of_eight_runs_is_the_mean_of_their_middle_four():
    runs = [9.0, 1.0, 7.0, 3.0, 100.0, -50.0, 5.0, 4.0]  # sorted: -50 1 | 3 4 5 7 | 9 100
    assert stats.iqm(runs) == pytest.approx((3 + 4 + 5 + 7) / 4)
    assert stats.iqm(np.reshape(runs, (4, 2))) == pytest.approx(4.75)  # runs x tasks: all runs together


@pytest.mark.parametrize(
    "runs, kept",
    [
        ([1000.0, 0, 1, 2, 3, 4, 5, 6, 7, 8], [2, 3, 4, 5, 6, 7]),  # n/4 = 2.5: two dropped at each end
        ([60.0, 1, 2, 3, 4, 5], [2, 3, 4, 5]),  # n/4 = 1.5: one dropped at each end
        ([3.0, -7, 2], [-7, 2, 3]),  # n/4 = 0.75: none dropped
    ],
)
def test_iqm_rounds_a_fractional_quartile_inwards(runs, kept):
    assert stats.iqm(runs) == pytest.approx(np.mean(kept))


def test_interval_of_two_tasks_of_two_runs_matches_the_hand_worked_bootstrap():
    # Task A's runs resample to means 0, 1/2, 1/2, 1 and task B's to 2, 3, 3, 4, each with probability 1/4;
    # the mean of all four runs is the average of the two, so its 16 equally likely values run from
    # (0 + 2) / 2 = 1 to (1 + 4) / 2 = 5/2, each end with probability 1/16 > 2.5 %: the 95 % interval is
    # [1, 5/2]. Resampling the pooled runs would reach 0 (four draws of A's 0) and 4.
    est = stats.interval([[0.0, 1.0], [2.0, 4.0]], np.mean, resamples=4000, seed=1)
    assert (est.value, est.low, est.high) == (pytest.approx(1.75), pytest.approx(1.0), pytest.approx(2.5))


@pytest.mark.parametrize("confidence", [0.5, 0.9])
def test_interval_matches_the_exact_bootstrap_distribution_within_monte_carlo_error(confidence):
    tasks = [[0.0, 1.0, 5.0], [10.0, 13.0, 20.0]]
    exact = np.sort(
        [stats.iqm(a + b) for a in itertools.product(tasks[0], repeat=3) for b in itertools.product(tasks[1], repeat=3)]
    )
    resamples = 20_000

    def quantile(p):  # of the exact distribution: the smallest value whose CDF reaches p
        return exact[math.ceil(p * len(exact)) - 1]

    est = stats.interval(tasks, stats.iqm, confidence=confidence, resamples=resamples, seed=2)
    for bound, p in ((est.low, (1 - confidence) / 2), (est.high, (1 + confidence) / 2)):
        slack = 4 * math.sqrt(p * (1 - p) / resamples)  # four standard errors of the empirical CDF at p
        assert quantile(p - slack) <= bound <= quantile(p + slack)
    assert stats.interval(tasks, stats.iqm, confidence=confidence, resamples=resamples, seed=2) == est


def test_an_aggregate_weighs_each_task_the_same_whatever_its_number_of_runs():
    # Ten runs at 0 on one task, two at 1 on the other: each task is half the study, so the IQM's middle half
    # is half zeros and half ones. Pooling the twelve runs as they are would drop three at each end and keep
    # six zeros: the task with more runs would decide.
    tasks = [[0.0] * 10, [1.0, 1.0]]
    assert stats.interval(tasks, stats.iqm).value == pytest.approx(0.5) == stats.aggregate(tasks)
    assert stats.iqm(np.concatenate(tasks)) == 0.0
    assert stats.aggregate([[0.0] * 10, [1.0]]) == pytest.approx(0.5)  # one run: no interval, the same weight
    assert stats.interval(tasks, np.mean).value == pytest.approx(0.5)  # the mean of the tasks' means
    # three runs and two: repeated to six each, so 0 1 5 twice and 7 9 three times: the middle six of twelve
    est = stats.interval([[0.0, 1.0, 5.0], [7.0, 9.0]], stats.iqm, resamples=200)
    assert est.value == pytest.approx(np.mean([1, 5, 5, 7, 7, 7]))


def test_interval_needs_two_runs_per_task():
    with pytest.raises(ValueError, match=r"scores_by_task\[1\] has 1 run"):
        stats.interval([[1.0, 2.0], [3.0]])


def test_performance_profile_counts_the_runs_above_each_threshold():
    tasks = [[0.1, 0.5, 0.9], [0.5, 0.7]]
    thresholds = [0.0, 0.5, 0.8, 1.0]
    # each task's share of runs above tau, averaged over the two tasks (each weighs the same)
    counted = [np.mean([sum(1 for s in t if s > tau) / len(t) for t in tasks]) for tau in thresholds]
    profile = stats.performance_profile(tasks, thresholds, seed=3)
    np.testing.assert_allclose(profile.fraction, counted)
    np.testing.assert_allclose(profile.fraction, [1.0, (1 / 3 + 1 / 2) / 2, (1 / 3 + 0) / 2, 0.0])
    assert profile.low[0] == profile.high[0] == 1.0 and profile.low[-1] == profile.high[-1] == 0.0
    assert profile.low[1] < 5 / 12 < profile.high[1]


def test_performance_profile_band_is_stratified():
    # Every stratified resample keeps task A's two zeros and task B's two ones: the share above 1/2 is
    # always 1/2, so the band has no width. Pooled resampling would spread it over [0, 1].
    profile = stats.performance_profile([[0.0, 0.0], [1.0, 1.0]], [0.5], seed=4)
    assert (profile.fraction[0], profile.low[0], profile.high[0]) == (0.5, 0.5, 0.5)


def test_probability_of_improvement_enumerates_pairs_with_ties_as_halves():
    x = [[1.0, 2.0, 3.0], [0.0, 6.0]]
    y = [[2.0, 2.0], [5.0, 1.0, 0.0]]
    per_task = [np.mean([1.0 if a > b else 0.5 if a == b else 0.0 for a in xt for b in yt]) for xt, yt in zip(x, y)]
    assert per_task == [3 / 6, 3.5 / 6]
    est = stats.probability_of_improvement(x, y, seed=5)
    assert est.value == pytest.approx(np.mean(per_task))
    assert est.low < est.value < est.high
    u = [scipy_stats.mannwhitneyu(xt, yt).statistic / (len(xt) * len(yt)) for xt, yt in zip(x, y)]
    assert est.value == pytest.approx(np.mean(u))
    assert stats.probability_of_improvement(y, x, seed=5).value == pytest.approx(1 - est.value)


def test_probability_of_improvement_of_a_method_that_always_wins_is_one_without_spread():
    est = stats.probability_of_improvement([[5.0, 6.0], [2.0, 3.0]], [[1.0, 2.0], [0.0, 1.0]], seed=6)
    assert tuple(est) == (1.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="same tasks"):
        stats.probability_of_improvement([[1.0, 2.0]], [[1.0, 2.0], [3.0, 4.0]])


def test_rate_at_fractions_takes_the_last_evaluation_at_or_before_each_fraction():
    steps = [50, 75, 100, 250, 400, 1000]
    values = [0.1, np.nan, 0.2, 0.3, 0.4, 0.9]  # NaN: an epoch without an evaluation
    np.testing.assert_array_equal(stats.rate_at_fractions(steps, values, 1000), [0.2, 0.3, 0.4, 0.9])
    np.testing.assert_array_equal(stats.rate_at_fractions(steps, values, 1000, (0.01, 0.06)), [np.nan, 0.1])
    assert stats.rate_at_fractions([58], [0.5], 100, (0.58,))[0] == 0.5  # 0.58 * 100 is 57.99999999999999


def test_samples_to_reach_is_censored_at_the_budget_when_never_reached():
    assert stats.samples_to_reach([10, 20, 30], [0.2, 0.95, 0.5], 0.9) == (20.0, True)
    assert stats.samples_to_reach([10, 20, 30], [0.2, 0.9, 0.5], 0.9) == (20.0, True)  # reaching counts
    assert stats.samples_to_reach([10, 20, 30], [0.2, 0.8, 0.5], 0.9, budget=40) == (40.0, False)
    assert stats.samples_to_reach([10, 20, 30], [0.2, 0.8, 0.5], 0.9) == (30.0, False)


@pytest.mark.parametrize(
    "runs, median",
    [
        ([(30, True), (10, True), (100, False)], (30.0, True)),  # 10 30 | >100: the middle run reached it
        ([(30, True), (100, False), (100, False)], (100.0, False)),  # 30 | >100 >100: "more than the budget"
        ([(30, True), (10, True), (20, True), (100, False)], (25.0, True)),  # 10 20 30 >100: (20 + 30) / 2
        ([(30, True), (10, True), (100, False), (100, False)], (65.0, False)),  # (30 + >100) / 2: more than 65
    ],
)
def test_median_reached_ranks_censored_runs_after_every_reached_one(runs, median):
    assert stats.median_reached([stats.Reached(float(s), r) for s, r in runs]) == median


def test_median_reached_refuses_runs_censored_before_another_reached_the_target():
    with pytest.raises(ValueError, match="censored at step 50 before another reached the target at 80"):
        stats.median_reached([stats.Reached(80.0, True), stats.Reached(50.0, False)])


def test_normalised_auc_is_the_hand_computed_trapezoid_over_the_budget():
    steps, values = [10, 20, 40], [0.5, 1.0, 1.0]
    # first value held back to 0: 0.5 * 10, then (0.5 + 1) / 2 * 10, 1 * 20, and flat from 40 to 50: 1 * 10
    assert stats.normalised_auc(steps, values, 50) == pytest.approx((5 + 7.5 + 20 + 10) / 50)
    # from an initial 0 at step 0 instead: (0 + 0.5) / 2 * 10 on the first stretch
    assert stats.normalised_auc(steps, values, 50, initial=0.0) == pytest.approx((2.5 + 7.5 + 20 + 10) / 50)
    # cut at the budget: (0 + 0.5) / 2 * 10 between 10 and 20, on the way to 1 at 30
    assert stats.normalised_auc([10, 30], [0.0, 1.0], 20) == pytest.approx(2.5 / 20)
    with pytest.raises(ValueError, match="increase"):
        stats.normalised_auc([20, 10], [0.0, 1.0], 20)
