#!/usr/bin/env bash
# The long learning runs still owed to issues 26, 27, 43 and 44, as resumable queues, one core each.
#
#   nohup benchmarks/backlog.sh > backlog.log 2>&1 &      # at the start of a session, from the repo root
#   nohup benchmarks/backlog.sh goalie > goalie.log 2>&1 &   # only the named queues (soccer, suite, goalie, seeds)
#
# Every step resumes where an earlier, interrupted invocation stopped (finished runs are skipped, partial
# ones continue from their last checkpoint; the off-policy runs keep their replay buffer in it), so a
# session simply starts this again. Outputs go outside the work tree: the soccer figure's runs under
# $SOCCER_OUT, the benchmark suite's under $SUITE_OUT, HFO's other algorithms under $HFO_OUT (defaults under
# $PAMDP_RUNS, itself ~/pamdp-runs by default). On 2026-12-02 they were $PAMDP_RUNS/soccer/results,
# $PAMDP_RUNS/suite/results and $PAMDP_RUNS/hfo/results: set the three variables to go on with those runs.
# A session that starts on a new machine has none of them: everything starts from scratch.
#
# Costs on this 2-core machine (CPU time a sample; docs/results.md, benchmarks/hfo_learning.md):
#   soccer: PADDPG 3.3 ms (~4.6 h a run, 3 seeds), PATRPO ~1.4 h a run (3 seeds: their directories were lost
#           with earlier machines, their results are recorded)                          ~18 core-hours
#   suite:  Hybrid SAC tuned 0.4-2 ms (7-33 min per 1M), P-DQN hard_move_large 3.5-6 ms (1-1.7 h per 1M),
#           MP-DQN hard_move 10.6 ms (n = 4) and 33 ms (n = 6): 3 and 9 h per 1M          ~45 core-hours
#   HFO:    PAPPO 0.46 ms (~40 min a run)
#   goalie: PATRPO, 1v0 stage 5M (0.25 ms a sample, ~21 min) then HFO 1v1 (0.12 ms a sample, 15M: ~30 min) a seed
set -euo pipefail
cd "$(dirname "$0")"
RUNS=${PAMDP_RUNS:-$HOME/pamdp-runs}
SOCCER_OUT=${SOCCER_OUT:-$RUNS/repro}
SUITE_OUT=${SUITE_OUT:-$RUNS/suite}
HFO_OUT=${HFO_OUT:-$RUNS/hfo}
GOALIE_OUT=${GOALIE_OUT:-$RUNS/goalie}
RECORDED=${RECORDED:-$(cd .. && pwd)/docs/results/summaries}  # the committed run summaries (seeds: --recorded)

# All in functions, which bash reads whole before running any of them: editing this file while it runs
# changes nothing in the running copy.
soccer() {  # issue 27: the paper's soccer figure, one run at a time
    for seed in 0 1 2; do pamdp reproduce soccer --runs PADDPG --seeds "$seed" --out "$SOCCER_OUT"; done
    for seed in 0 1 2; do pamdp reproduce soccer --runs PATRPO --seeds "$seed" --out "$SOCCER_OUT"; done
}

suite() {  # issue 26: the suite's missing cells, the cheapest first, then the other seeds; then HFO's PAPPO
    local s="pamdp reproduce benchmark-suite --out $SUITE_OUT"
    # Done by 2026-12-03 (docs/results.md): MP-DQN on Platform, Goal, Hard Goal and Catch Point; HyAR-TD3 and PATRPO
    # everywhere (HyAR-TD3 on Hard Move with the hard_move preset of HyAR's script, ~22 CPU minutes a run); Hybrid SAC
    # on Platform and Catch Point (3 seeds each), on Goal, Hard Goal and Hard Move n = 4 (seed 0).
    $s --seeds 1,2 --runs "Hybrid_SAC_on_Hard_Move_n=4,Hybrid_SAC_on_Goal,Hybrid_SAC_on_Hard_Goal"
    $s --seeds 0,1,2 --runs "Hybrid_SAC_on_Hard_Move_n=6,Hybrid_SAC_on_Hard_Move_n=8"
    $s --seeds 0,1,2 --runs P-DQN_on_Hard_Move_n=8,P-DQN_on_Hard_Move_n=10
    $s --seeds 0,1,2 --runs MP-DQN_on_Hard_Move_n=4,P-DQN_on_Hard_Move_n=6
    for seed in 1 2; do pamdp reproduce hfo_learning.toml --runs PAPPO --seeds "$seed" --out "$HFO_OUT"; done
}

goalie() {  # issue 43: the recipe (pamdp reproduce hfo-goalie, done 2026-12-04), then the arms tried on the way
    pamdp reproduce hfo-goalie --out "$GOALIE_OUT" --workers 2
    python bench_hfo_goalie_learning.py --out "$GOALIE_OUT"
}

seeds() {  # issue 44: 5 seeds a cell, 10 where a run costs under 10 CPU minutes; both cores, two runs of like cost at once
    # docs/results.md's statistics table counts what each cell still owes, the cells never run included. The runs
    # whose summaries are committed (docs/results/summaries/benchmark-suite) are not trained again (--recorded), on a
    # new machine too: each line names whole cells, and `pamdp reproduce benchmark-suite --status --recorded ...`
    # lists what is left. Cells still owing runs on 2026-12-05, CPU minutes a run in brackets (measured in the
    # queue, or priced in benchmarks/large_k_cost.md): never run before 2026-12-05, HyAR's PDQN column at n = 6, 8
    # and 10 (P-DQN's single pass), Hybrid SAC at n = 8, MP-DQN at n = 4. HyAR's PDQN column first (issue 44 asks 5
    # seeds of each method of HyAR's table), then Hybrid SAC, neither HyAR's nor pamdp's best at n = 8. Hybrid SAC
    # left n = 10 on 2026-12-05: its critics diverged at n = 8 on every seed (the suite's config says why).
    local s="pamdp reproduce benchmark-suite --out $SUITE_OUT --workers 2 --recorded $RECORDED/benchmark-suite"
    $s --seeds 0-4 --runs "P-DQN_on_Hard_Move_n=6,P-DQN_on_Hard_Move_n=8"             # 16, 21
    $s --seeds 0-4 --runs "P-DQN_on_Hard_Move_n=10,MP-DQN_on_Hard_Move_n=4"           # 47, 68
    $s --seeds 0-4 --runs "Hybrid_SAC_on_Hard_Move_n=8"                                # 16
}

queues=("${@:-soccer}" ) && [ $# -eq 0 ] && queues=(soccer suite seeds)
for name in "${queues[@]}"; do
    case $name in
        soccer | suite | goalie | seeds) ;;
        *) echo "backlog.sh: unknown queue '$name'; expected some of soccer, suite, goalie, seeds" >&2 && exit 2 ;;
    esac
done
for name in "${queues[@]}"; do "$name" & done
wait
exit
