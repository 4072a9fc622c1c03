"""Run summaries and the results' tables (issue 44): a summary says what its run's logs say, survives a round trip,
and the tables of a small hand-made set of summaries hold the hand-computed cells."""

import csv
import dataclasses
import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from pamdp import __version__
from pamdp.cli import main
from pamdp.experiments import results
from pamdp.experiments.runner import RunSpec, recorded_differences
from pamdp.experiments.suite import from_suite_final
from pamdp.experiments.summary import load, save, summarize

ROOT = Path(__file__).resolve().parents[1]
TINY = ["--hidden-sizes", "16", "--vf-hidden-sizes", "16", "--batch-size", "500", "--num-envs", "4"]


def _train(out, steps):
    argv = ["train", "patrpo", "--total-steps", str(steps), "--eval-every", "1", "--eval-episodes", "20"]
    assert main([*argv, "--out", str(out), "--no-progress", "--seed", "3", *TINY]) == 0


def _rows(run):
    with open(run / "progress.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_the_summary_of_a_real_run_is_what_its_logs_say_and_follows_a_resume(tmp_path, capsys):
    run = tmp_path / "run"
    _train(run, 1500)
    first = json.loads((run / "summary.json").read_text())
    assert first["samples"] >= 1500 and len(first["evaluations"]["samples"]) == 3
    _train(run, 2500)  # the same run, further: resumed, and its summary rewritten at the end
    summary = json.loads((run / "summary.json").read_text())
    rows, final, recorded = (
        _rows(run),
        json.loads((run / "evaluation.json").read_text()),
        json.loads((run / "run.json").read_text()),
    )
    assert len(rows) == summary["epochs"] == 5
    assert summary["samples"] == int(float(rows[-1]["time/total_timesteps"])) >= 2500
    assert summary["evaluations"]["samples"] == [int(float(r["time/total_timesteps"])) for r in rows]
    for key in ("mean_return", "mean_length"):
        assert summary["evaluations"][key] == pytest.approx([float(r[f"eval/{key}"]) for r in rows], rel=1e-5)
    assert "success_rate" not in summary["evaluations"]  # Platform reports no success: nothing invented
    assert summary["gradient_updates"] == sum(int(float(r["train/updates"])) for r in rows) == 5
    assert summary["cpu_seconds"] == pytest.approx(sum(float(r["time/epoch_cpu_seconds"]) for r in rows), abs=0.06)
    assert summary["wall_seconds"] == pytest.approx(sum(float(r["time/epoch_seconds"]) for r in rows), abs=0.06)
    assert summary["final"] == {k: final[k] for k in ("episodes", "mean_return", "std_return", "mean_length")}
    assert summary["final"]["episodes"] == 20
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True).stdout
    assert (summary["pamdp_version"], summary["git_commit"]) == (__version__, commit.strip() or None)
    assert (summary["algo"], summary["env"], summary["seed"], summary["total_steps"]) == (
        "patrpo",
        "pamdp/Platform-v0",
        3,
        2500,
    )
    assert summary["config"] == recorded["config"] and summary["finished"] is True
    assert summary == summarize(run)  # the same function, applied to the directory again
    assert (run / "summary.json").stat().st_size < 10_000
    # `pamdp plot` of the run adds its statistics: one run, so no interval
    capsys.readouterr()
    assert main(["plot", str(run), "--out", str(tmp_path / "fig")]) == 0
    stats_md = (tmp_path / "fig" / "stats.md").read_text()
    assert f"| Platform | run | 1 | {final['mean_return']:.3f} (no interval: n < 3) |" in stats_md
    assert stats_md in capsys.readouterr().out


def _summary(label, env, seed, value, curve=None, budget=400, env_kwargs=None, cpu=None):
    """A hand-made summary of a finished run: its final figure and, optionally, greedy evaluations (samples, figure)
    and its CPU seconds."""
    key = "mean_return" if env == "pamdp/Platform-v0" else "success_rate"
    samples, values = zip(*curve) if curve else ((), ())
    return {
        "format": 1,
        "source": "run directory",
        "origin": f"x/{label}/seed{seed}",
        "label": label,
        "algo": "patrpo",
        "preset": "tuned",
        "env": env,
        "env_kwargs": env_kwargs or {},
        "seed": seed,
        "total_steps": budget,
        "settings_hash": "abc",
        "config": {},
        "finished": True,
        "cpu_seconds": cpu,
        "evaluations": {"samples": list(samples), key: list(values)},
        "final": {key: value, "mean_return": value},
    }


def test_a_summary_round_trips_through_its_file_and_the_cli_writes_the_same(tmp_path):
    summaries = [_summary("A on Goal", "pamdp/Goal-v0", s, v, [(100, 0.5), (400, v)]) for s, v in enumerate((0.1, 0.2))]
    paths = save(summaries, tmp_path / "exp")
    assert [p.relative_to(tmp_path) for p in paths] == [
        Path("exp/A_on_Goal/seed0.json"),
        Path("exp/A_on_Goal/seed1.json"),
    ]
    assert [load(p) for p in paths] == summaries
    with pytest.raises(ValueError, match="two runs of 'A on Goal' seed 0"):
        save([summaries[0], summaries[0]], tmp_path / "again")
    with pytest.raises(ValueError, match="x/A on Goal/seed0 records no seed"):
        save([{**summaries[0], "seed": None}], tmp_path / "unseeded")
    (tmp_path / "bad.json").write_text(json.dumps({**summaries[0], "format": 2}))
    with pytest.raises(ValueError, match="format 2; expected a pamdp run summary of format 1"):
        load(tmp_path / "bad.json")


def test_pamdp_summarize_writes_each_runs_summary_where_asked(tmp_path, capsys):
    run = tmp_path / "exp" / "arm" / "seed3"
    _train(run, 500)
    (run / "summary.json").unlink()
    assert main(["summarize", str(tmp_path / "exp"), "--out", str(tmp_path / "kept")]) == 0
    assert load(tmp_path / "kept" / "arm" / "seed3.json") == summarize(run)  # label: the arm's directory
    assert not (run / "summary.json").exists()  # the run tree is only read
    assert main(["summarize", str(run)]) == 0
    assert json.loads((run / "summary.json").read_text()) == summarize(run)
    assert main(["summarize", str(tmp_path / "kept")]) == 2
    assert "no run directories" in capsys.readouterr().err
    # a run still training (no final evaluation yet, fewer samples than its budget) is left out with --finished
    training = shutil.copytree(run, tmp_path / "exp" / "arm" / "seed4")
    (training / "evaluation.json").unlink()
    (training / "summary.json").unlink()
    recorded = json.loads((training / "run.json").read_text())
    (training / "run.json").write_text(json.dumps({**recorded, "seed": 4, "total_steps": 1000}))
    assert summarize(training)["finished"] is False
    assert main(["summarize", str(tmp_path / "exp"), "--finished", "--out", str(tmp_path / "done")]) == 0
    assert sorted(p.name for p in (tmp_path / "done" / "arm").iterdir()) == ["seed3.json"]
    assert main(["summarize", str(training), "--finished"]) == 0 and not (training / "summary.json").exists()


def test_a_summary_of_a_run_cut_before_its_first_checkpoint_does_not_stop_it_starting_again(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    (run / "run.json").write_text(json.dumps({"algo": "patrpo", "env": "pamdp/Platform-v0", "config": {"seed": 0}}))
    (run / "progress.csv").write_text("time/total_timesteps,charts/episodic_return\n500,0.1\n")  # one epoch, killed
    assert main(["summarize", str(run)]) == 0 and not load(run / "summary.json")["finished"]
    _train(run, 500)
    assert load(run / "summary.json")["finished"] and load(run / "summary.json")["seed"] == 3


def test_an_archived_suite_entry_becomes_a_summary_of_its_final_figure_only():
    entry = dict(domain="Hard Move n=6", method="PATRPO", seed=2, value=0.971, final=True, source="lost run")
    entry.update(total_steps=None, preset=None, settings=None)
    summary = from_suite_final(entry)
    assert summary["source"] == "suite-finals.json" and summary["origin"] == "lost run"
    assert (summary["env"], summary["env_kwargs"], summary["final"]) == (
        "pamdp/HardMove-v0",
        {"n": 6},
        {"success_rate": 0.971},
    )
    assert summary["algo"] is None and summary["cpu_seconds"] is None and summary["evaluations"] == {"samples": []}
    assert results.finals([summary]) == [entry]  # and back: the suite's table reads the same figure
    platform = from_suite_final({**entry, "domain": "Platform", "value": 0.9})
    assert platform["final"] == {"mean_return": 0.9}
    with pytest.raises(ValueError, match="not a final evaluation"):
        from_suite_final({**entry, "final": False})
    # `reproduce --recorded` takes it for its cell's seed, as the tables do, comparing what it holds
    spec = RunSpec("patrpo", "pamdp/HardMove-v0", 1_000_000, seed=2, env_kwargs=(("n", 6),), preset="hard_move")
    assert recorded_differences(spec, summary) == []
    other = dataclasses.replace(spec, seed=3, env_kwargs=(("n", 8),))
    assert recorded_differences(other, summary) == [
        "seed: 2 in the summary, 3 asked",
        "env_kwargs: {'n': 6} in the summary, {'n': 8} asked",
    ]


def _synthetic():
    """Two methods on Platform and Goal: A with runs 0, 1, 1 on Goal (curves) and four on Platform, B below A."""
    curve = [(100, 0.1), (200, 0.5), (300, 0.9), (400, 1.0)]
    runs = [
        _summary("A on Goal", "pamdp/Goal-v0", s, v, curve, cpu=c)
        for s, v, c in zip(range(3), (0, 1, 1), (60, 900, 1500))
    ]
    runs += [
        _summary("A on Platform", "pamdp/Platform-v0", s, v, cpu=c)
        for s, v, c in zip(range(4), (0.9, 0.2, 0.6, 1.0), (300, 540, None, 720))
    ]
    runs += [_summary("B on Goal", "pamdp/Goal-v0", s, v - 2.0, [(400, 0.0)]) for s, v in enumerate((0.5, 0.7))]
    runs += [_summary("B on Platform", "pamdp/Platform-v0", s, v - 2.0) for s, v in enumerate((0.1, 0.3, 0.5))]
    return runs


def _cells(table):
    return {tuple(line.split(" | ")[:2]): line.split(" | ")[2:] for line in table.splitlines()[2:]}


def test_the_statistics_tables_hold_the_hand_computed_cells():
    runs = _synthetic()
    table, backlog = results.stats_table(runs).split("\n\n")
    cells = _cells(table)
    # Goal, A: runs 0, 1, 1. The mean of three draws is 0 with probability (1/3)^3 = 1/27 > 2.5 % and 1 with
    # (2/3)^3 > 2.5 %: the 95 % percentile interval is [0, 1]; three runs drop none from the IQM.
    # A run of 1, 15 or 25 CPU minutes: the median 15 is not cheap, so the cell is to have 5 runs and owes 2
    # (its samples to 90 % of 0.78 and its AUC: as in the efficiency table below)
    assert cells[("| Goal", "A")] == [
        "3",
        "0.667 [0.000, 1.000]",
        "0.667 [0.000, 1.000]",
        "0.78",
        "300 (3 of 3 reached)",
        "0.51",
        "15.0",
        "2 |",
    ]
    # Platform, A: sorted 0.2 0.6 0.9 1.0, the IQM their middle two
    platform = cells[("| Platform", "A")]
    assert platform[0] == "4" and platform[1].startswith(f"{np.mean([0.9, 0.2, 0.6, 1.0]):.3f} [")
    assert platform[2].startswith(f"{(0.6 + 0.9) / 2:.3f} [")
    # no curves; the median of 5, 9 and 12 minutes (one run unrecorded): cheap, 10 wanted
    assert platform[4:] == ["- (no curves)", "-", "9.0", "6 |"]
    assert cells[("| Goal", "B")][4:] == ["> 400 (0 of 2 reached)", "0.00", "-", "3 |"]  # no cost recorded: 5 wanted
    assert cells[("| Goal", "B")][1:3] == ["-1.400 (no interval: n < 3)"] * 2  # two runs: no interval
    # owed: Goal A 2 at 15 min, Platform A 6 at 9 min (84 min); Goal B 3 and Platform B 2, no cost recorded
    assert backlog == (
        "Runs owed: 13 over 4 cells; the 8 in cells that recorded their cost, about 1.4 CPU hours at those costs; "
        "5 in cells whose runs recorded none (archived figures)."
    )
    assert results.backlog_line(runs) == backlog  # the line alone, as the table's foot
    # the runs a cell by method, counted above (A: Goal 3, Platform 4; B: Goal 2, Platform 3), then the same backlog
    assert results.runs_line(runs) == f"Runs a cell: A 3 to 4 on 2 domains; B 2 to 3 on 2 domains. {backlog}"
    # an experiment's cell that never ran (C on Catch Point) gets a row after the runs' domains (the suite's order),
    # owing 5 runs (no cost known), HyAR's best there 0.90 (../shared/specs/benchmarks.md); a planned cell that ran
    # (A on Goal) changes nothing
    planned = [("Goal", "A"), ("Catch Point", "C")]
    table, with_unrun = results.stats_table(runs, planned).split("\n\n")
    assert table.splitlines()[-1] == "| Catch Point | C | 0 (never run) | - | - | 0.90 | - | - | - | 5 |"
    assert with_unrun == backlog.replace("13 over 4", "18 over 5")[:-1] + "; 5 in 1 cell never run (C on Catch Point)."
    assert results.backlog_line(runs, planned) == with_unrun
    line = results.runs_line(runs, planned)
    assert line == f"Runs a cell: A 3 to 4 on 2 domains; B 2 to 3 on 2 domains; C 0 on 1 domain. {with_unrun}"
    aggregate = _cells(results.aggregate_table(runs).split("\n\n")[0])
    # each domain weighs the same: Goal's 3 runs repeated 4 times, Platform's 4 runs 3 times; of the 24, sorted
    # 0 x4, 0.2 x3, 0.6 x3, 0.9 x3, 1 x11, six dropped at each end leave 0.2, 0.6 x3, 0.9 x3, 1 x5
    pooled = [0.2] + [0.6] * 3 + [0.9] * 3 + [1.0] * 5
    assert aggregate[("| A", "2")][1].startswith(f"{np.mean(pooled):.3f} [")
    improvement = _cells(results.improvement_table(runs))
    assert improvement[("| A", "B")] == ["2", "7, 5", "1.00 [1.00, 1.00] |"]  # every run of A beats every run of B
    efficiency = _cells(results.efficiency_table(runs))
    # A's curve at 40, 100, 200 and 400 samples: none yet, 0.1, 0.5, 1.0; 90 % of HyAR's 0.78 = 0.702 first reached
    # at 300; area: 0.1 held back to 0, then trapezoids: (10 + 30 + 70 + 95) / 400 = 0.5125
    assert efficiency[("| Goal", "A")] == ["3", "- / 0.10 / 0.50 / 1.00", "300 (3 of 3 reached)", "0.51 |"]
    # B's one evaluation, 0.0 at the end of its budget: never reached, so censored there
    assert efficiency[("| Goal", "B")] == ["2", "- / - / - / 0.00", "> 400 (0 of 2 reached)", "0.00 |"]
    assert ("| Platform", "A") not in efficiency  # no curve logged
    standing = _cells(results.standing_table(runs))
    # Goal: the best published is CHDP's 0.809; A (IQM 0.667) beats B (-1.4 over 2 runs: too few to stand). A's
    # interval [0, 1] holds 0.809: neither above nor below; its curve first reaches 0.809 at 300 samples.
    assert standing[("| Goal", "0.809 (CHDP)")] == [
        "A",
        "3",
        "0.667 [0.000, 1.000]",
        "within the interval",
        "300 (3 of 3)",
        "400 |",
    ]
    # Platform: A (IQM 0.75) beats B (0.3 - 2). A redrawn set of A's four runs has an IQM of 1.0 (its middle two
    # both 1.0) when three or four draws are the 1.0: 4 (1/4)^3 (3/4) + (1/4)^4 = 5.1 % > 2.5 %, so the interval
    # reaches 1.0 and holds CHDP's 0.997; no curves logged
    platform = standing[("| Platform", "0.997 (CHDP)")]
    assert platform[:2] == ["A", "4"] and platform[3:] == ["within the interval", "- (no curves)", "400 |"]
    line = results.standing_line(runs)  # the README's sentence of the same rows
    assert line.startswith("Per domain, pamdp's best method against the best published figure, IQM with its 95 % ")
    assert "over the runs (2 within the interval): Platform: A **" in line
    assert line.endswith(
        "Goal: A **0.667 [0.000, 1.000]** (3 runs; CHDP 0.809: within the interval; median samples to reach it 300 "
        "of 400, 3 of 3 runs with curves reached it)."
    )
    # runs that all score 0.5 on Platform and 0.95 on Hard Move n=4: intervals of one point, below 0.997 and above 0.942
    low = [_summary("C on Platform", "pamdp/Platform-v0", seed, 0.5) for seed in range(3)]
    high = [_summary("C on Hard Move n=4", "pamdp/HardMove-v0", seed, 0.95, env_kwargs={"n": 4}) for seed in range(3)]
    standing = _cells(results.standing_table(low + high))
    assert standing[("| Platform", "0.997 (CHDP)")][2:4] == ["0.500 [0.500, 0.500]", "below"]
    assert standing[("| Hard Move n=4", "0.942 (CHDP)")][2:4] == ["0.950 [0.950, 0.950]", "above"]


def test_the_suites_planned_cells_are_its_configs_runs():
    import tomllib

    from pamdp.experiments import load_experiment

    planned = results.planned_cells(load_experiment("benchmark-suite").specs())
    path = Path(results.__file__).parent / "configs" / "benchmark-suite.toml"
    labels = [run["label"] for run in tomllib.loads(path.read_text())["runs"]]
    # one cell a run of the config, its label split at " on " (the suite's labels are "METHOD on DOMAIN")
    assert sorted(planned) == sorted(tuple(reversed(label.split(" on "))) for label in labels)


def test_every_committed_suite_summary_is_of_a_run_the_suite_asks_for_now():
    """A cell's table row counts its runs of one setting, the one of most runs. A summary of settings the config no
    longer asks (a preset changed after the runs) would still stand as the cell's runs there, and its runs owed
    would read none while `pamdp reproduce --recorded` trains them all again: such summaries are to be moved out of
    docs/results/summaries/benchmark-suite (their figures kept in the record's text), or the runs redone."""
    from pamdp.experiments import load_experiment

    specs = {(s.label, s.seed): s for s in load_experiment("benchmark-suite").specs(seeds=range(10))}
    paths = sorted((ROOT / "docs" / "results" / "summaries" / "benchmark-suite").rglob("*.json"))
    assert len(paths) >= 200
    stale = {}
    for path in paths:
        summary = load(path)
        spec = specs.get((summary["label"], summary["seed"]))
        differences = ["no such run in the config"] if spec is None else recorded_differences(spec, summary)
        if differences:
            stale[str(path.relative_to(ROOT))] = differences
    assert stale == {}


def test_the_readme_line_ranks_methods_by_their_aggregate_with_each_domain_weighing_the_same():
    # X: six runs at 0 on Goal, two at 1 on Platform: each domain half the study, an IQM of 0.5 (pooled as they
    # are, the middle four of eight would all be Goal's zeros: 0.0). Y: 0.3 everywhere. X ranks first.
    x = [_summary("X on Goal", "pamdp/Goal-v0", seed, 0.0) for seed in range(6)]
    x += [_summary("X on Platform", "pamdp/Platform-v0", seed, 1.0) for seed in range(2)]
    y = [_summary(f"Y on {d}", f"pamdp/{d}-v0", seed, 0.3) for d in ("Goal", "Platform") for seed in range(2)]
    line = results.aggregate_line(x + y)
    assert line.index("X **0.500 [") < line.index("Y **0.300 [0.300, 0.300]**")
    # Z ran only Catch Point, which neither X nor Y ran: it stays out of the shared comparison instead of emptying
    # it, and the line and table say so
    z = [_summary("Z on Catch Point", "pamdp/CatchPoint-v0", seed, 0.9) for seed in range(3)]
    line = results.aggregate_line(x + y + z)
    assert "On the 2 domains they share (Platform, Goal): X **0.500 [" in line
    assert line.endswith("(Z: not on all of them).") and "Z **0.900 [0.900, 0.900]** (1 domain, 3 runs)" in line
    table = _cells(results.aggregate_table(x + y + z).split("\n\n")[0])
    assert table[("| Z", "1")][-1] == "- |"


def test_the_one_preset_table_judges_each_domain_against_hyars_figure_and_counts_them():
    one = [_summary("C on Platform", "pamdp/Platform-v0", seed, v) for seed, v in enumerate((0.99, 1.0, 0.97))]
    one += [_summary("C on Goal", "pamdp/Goal-v0", seed, 0.5) for seed in range(3)]
    one += [_summary("C on Moving", "pamdp/Moving-v0", seed, 0.7) for seed in range(2)]
    table = results.one_preset_table(one, _synthetic())
    rows = _cells(table.split("\n\n")[0])
    # Platform: three runs, none dropped from the IQM: their mean 0.987 >= HyAR-TD3's 0.98; the suite's best cell is
    # A's (the IQM of 0.2 0.6 0.9 1.0: 0.75)
    assert rows[("| Platform", "3")][0] == "0: 0.990, 1: 1.000, 2: 0.970"
    assert rows[("| Platform", "3")][1].startswith(f"{np.mean([0.99, 1.0, 0.97]):.3f} [0.970, 1.000]")
    assert rows[("| Platform", "3")][2:] == ["0.98 +- 0.01", "yes", "A, 0.750 |"]
    assert rows[("| Goal", "3")][2:] == ["0.78 +- 0.03", "no (-0.28)", "A, 0.667 |"]
    assert rows[("| pamdp/Moving-v0", "2")][2:] == ["- (none published)", "-", "- |"]
    assert table.endswith("on 1 of the 2 domains it has one for.")


def test_a_cells_greedy_band_is_the_mean_of_each_runs_last_evaluation_and_stops_where_a_run_stops():
    # three runs evaluated every 100 samples of a 400-sample budget; the third is still training (last at 200)
    a = ((np.array([100.0, 200, 300, 400]), np.array([0.0, 0.2, 0.4, 0.8])), 400.0)
    b = ((np.array([100.0, 200, 300, 400]), np.array([0.1, 0.1, 0.5, 0.5])), 400.0)
    c = ((np.array([100.0, 200]), np.array([0.3, 0.6])), 400.0)
    points = np.array([50.0, 150, 250, 300, 350])
    band = results.greedy_band([a, b], points, relative=False)
    # by 50 samples no run had been evaluated; by 150: 0.0 and 0.1; by 250: 0.2 and 0.1; by 300: 0.4 and 0.5
    assert band["seen"].tolist() == [False, True, True, True, True]
    np.testing.assert_allclose(band["mean"][1:], [0.05, 0.15, 0.45, 0.45])
    assert np.isnan(band["low"]).all()  # two runs: no interval
    # the run still training counts up to one interval past its last evaluation (300), not after it
    band = results.greedy_band([a, b, c], points, relative=False)
    assert band["seen"].tolist() == [False, True, True, True, False]
    np.testing.assert_allclose(band["mean"][1:4], [0.4 / 3, 0.9 / 3, 1.5 / 3])
    # the band at 300 samples: the percentile bootstrap of the mean of (0.4, 0.5, 0.6) lies within their range
    assert 0.4 <= band["low"][3] < 0.5 < band["high"][3] <= 0.6
    # the same points as fractions of each run's budget
    relative = results.greedy_band([a, b, c], points / 400, relative=True)
    np.testing.assert_array_equal(relative["mean"], band["mean"])


def test_the_figures_are_drawn_where_there_is_something_to_draw(tmp_path):
    runs = _synthetic()
    profiles = results.plot_profiles(runs, tmp_path / "profiles")
    efficiency = results.plot_efficiency(runs, tmp_path / "efficiency")
    assert [p.name for p in profiles + efficiency] == [
        "profiles.png",
        "profiles.svg",
        "efficiency.png",
        "efficiency.svg",
    ]
    assert all(0 < p.stat().st_size < 1_000_000 for p in profiles + efficiency)
    assert "A (7 runs)" in profiles[1].read_text()  # both domains are shared: A's 3 + 4 runs
    platform_only = [s for s in runs if s["env"] == "pamdp/Platform-v0"]  # no curves
    assert results.plot_efficiency(platform_only, tmp_path / "none") == []
    # a figure per domain with curves, in samples: Goal's (A's and B's curves), none for Platform (no curve)
    domains = results.plot_domains(runs, tmp_path)
    assert [p.name for p in domains] == ["domain-goal.png", "domain-goal.svg"]
    assert "A (3)" in domains[1].read_text() and "B (2)" in domains[1].read_text()
    assert results.plot_profiles([runs[0]], tmp_path / "one") == []  # one run: no domain with 2 runs to resample
    # the committed figures are checked against redrawn ones: the same runs must give the same bytes
    (tmp_path / "again").mkdir()
    again = results.plot_profiles(runs, tmp_path / "again" / "profiles")
    assert [p.read_bytes() for p in again] == [p.read_bytes() for p in profiles]
