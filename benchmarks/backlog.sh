#!/usr/bin/env bash
# The long learning runs still owed to issues 26 and 27, as two resumable queues, one core each.
#
#   nohup benchmarks/backlog.sh > backlog.log 2>&1 &      # at the start of a session, from the repo root
#
# Every step resumes where an earlier, interrupted invocation stopped (finished runs are skipped, partial
# ones continue from their last checkpoint; the off-policy runs keep their replay buffer in it), so a
# session simply starts this again. Outputs go outside the work tree: the soccer figure's runs under
# $SOCCER_OUT, the benchmark suite's under $SUITE_OUT, HFO's other algorithms under $HFO_OUT (defaults under
# $PAMDP_RUNS, itself /root/pamdp-runs by default). On 2026-12-02 they were /work/runs/soccer/results,
# /work/runs/suite/results and /work/runs/hfo/results: set the three variables to go on with those runs.
# A session that starts on a new machine has none of them: everything starts from scratch.
#
# Costs on this 2-core machine (CPU time a sample; docs/results.md, benchmarks/hfo_learning.md):
#   soccer: PADDPG 3.3 ms (~4.6 h a run, 3 seeds), PATRPO ~1.4 h a run (3 seeds: their directories were lost
#           with earlier machines, their results are recorded)                          ~18 core-hours
#   suite:  HyAR-TD3 hard_move ~1.2 ms (~20 min per 1M), P-DQN hard_move_large 3.5-6 ms (1-1.7 h per 1M)
#                                                                                       ~6 core-hours
#   HFO:    PAPPO 0.46 ms (~40 min a run)
set -euo pipefail
cd "$(dirname "$0")"
RUNS=${PAMDP_RUNS:-/root/pamdp-runs}
SOCCER_OUT=${SOCCER_OUT:-$RUNS/repro}
SUITE_OUT=${SUITE_OUT:-$RUNS/suite}
HFO_OUT=${HFO_OUT:-$RUNS/hfo}

# All in functions, which bash reads whole before running any of them: editing this file while it runs
# changes nothing in the running copy.
soccer() {  # issue 27: the paper's soccer figure, one run at a time
    for seed in 0 1 2; do pamdp reproduce soccer --runs PADDPG --seeds "$seed" --out "$SOCCER_OUT"; done
    for seed in 0 1 2; do pamdp reproduce soccer --runs PATRPO --seeds "$seed" --out "$SOCCER_OUT"; done
}

suite() {  # issue 26: the suite's missing cells, the cheapest first, then the other seeds; then HFO's PAPPO
    local s="pamdp reproduce benchmark-suite --out $SUITE_OUT"
    # Done by 2026-12-03 (docs/results.md): HyAR-TD3 on Catch Point, Goal and Hard Goal, MP-DQN on Goal, Hard Goal and
    # Catch Point, PATRPO everywhere (3 seeds each); HyAR-TD3 on Hard Move n = 4 (3 seeds) and 8 (seed 0) with the
    # hard_move preset of HyAR's script (~20 CPU minutes a run, 1.2 ms a sample)
    $s --seeds 1,2 --runs HyAR-TD3_on_Hard_Move_n=8
    $s --seeds 0,1,2 --runs HyAR-TD3_on_Hard_Move_n=6,HyAR-TD3_on_Hard_Move_n=10
    $s --seeds 0 --runs P-DQN_on_Hard_Move_n=8,P-DQN_on_Hard_Move_n=10
    for seed in 1 2; do pamdp reproduce hfo_learning.toml --runs PAPPO --seeds "$seed" --out "$HFO_OUT"; done
}

soccer &
suite &
wait
exit
