#!/usr/bin/env bash
# The long learning runs still owed to issues 4, 5 and 7 (~60 core-hours), in the order of what each
# CPU-hour buys. Per-run costs from benchmarks/offpolicy_speed.md (updates/s on one idle core).
#
#   nohup benchmarks/backlog.sh > backlog.log 2>&1 &      # at the start of a session, from the repo root
#
# Every step resumes where an earlier, interrupted invocation stopped (finished runs are skipped, partial
# ones continue from their last checkpoint; the off-policy runs keep their replay buffer in it), so a
# session simply starts this again. Two workers use both cores of the project machine. Outputs go to
# $PAMDP_RUNS (default /root/pamdp-runs), outside the work tree; records and figures land in benchmarks/
# and the experiments' directories, to be committed by hand with notes.
#
# Costs on the 2-core Intel Xeon of 2026-11-28, per run with another run on the other core (PATRPO's figures
# predate the Numba Platform backend of 2026-11-29, which takes its ~35 % of env time off an epoch). Done and
# dropped from the queue: PASVG(0) tuned, 5 x 1M (issue 4, benchmarks/pasvg_platform.md).
#   1. step-size (2 x 5) and kl-estimators (3 x 5), PATRPO: ~16 min a run            ~6.5 core-hours
#   2. MP-DQN, P-DQN and PAPPO tuned, 3 x 5 x 300k (beyond the paper): ~9 min a run beside another
#                                                                            ~2.3 core-hours
#      (done on 2026-11-29 with HyAR-TD3's cpu preset; its "HyAR-TD3 remap" arm, 5 x 300k at ~12 min a run
#      beside another, was added that day and runs first at the next start)   ~1 core-hour
#   2b. SB3's SAC and DQN through pamdp's wrappers, 2 x 3 x 100k (a baseline from a mainstream library): a SAC
#       run with SB3's defaults took over 38 min beside another on 2026-11-29 (not resumable mid-run)
#                                                                            ~2 core-hours
#       (these two go before soccer's PATRPO arm because they finish within one session and so give recorded
#       results at its end; a soccer run takes more than a session whatever the order)
#   3. the PATRPO arm of platform (done) and soccer (3 x 5M): a soccer epoch of 50 000 samples with
#      {400, 300, 200} networks took ~95 s of one idle core (the chain-analytic KL's Fisher-vector products
#      pass pi_c over all 3 actions: 1.4 s each per 10 000 samples), so ~2.6 h a run; the Gauss-Newton
#      products of 2026-11-29 take about a quarter off (benchmarks/fvp_speed.md)      ~7 core-hours
#   4. platform's PADDPG arm, paper preset, 5 x 1M (~3 h a run alone, ~5 h beside another): also issue 5's
#      benchmark, so it goes before PASVG(0)'s arm to close that issue first    ~25 core-hours
#   5. PADDPG with Hausknecht & Stone's preset on Platform, 1 seed x 300k (issue 5), beside step 4  ~4 core-hours
#   6. platform's PASVG(0) arm, paper preset, 5 x 1M (~5 h a run alone)          ~40 core-hours
#   7. soccer's PADDPG arm: 3 x 5M at one update per sample is ~15 core-hours a run here, so it runs as far
#      as the sessions allow (issue 7 asks for "as far as the machine allows")
# Steps 3 (seed 2), 5 and 7 run in a side queue beside steps 4 and 6 (below), step 7 at the lowest priority.
# The off-policy arms run as seed stacks (pamdp reproduce --stack, since 2026-11-29): the core-hours above are
# per run alone, and a stack of three trains ~1.3x the seeds an hour.
set -euo pipefail
cd "$(dirname "$0")"
RUNS=${PAMDP_RUNS:-/root/pamdp-runs}

# All in one function, which bash reads whole before running any of it: editing this file while it runs
# changes nothing in the running copy.
main() {
    pamdp reproduce step-size --workers 2 --out "$RUNS/repro"
    pamdp reproduce kl-estimators --workers 2 --out "$RUNS/repro"
    pamdp reproduce platform --runs PATRPO --workers 2 --out "$RUNS/repro"
    python bench_later_platform.py --workers 2 --out "$RUNS/bench"
    # Stable-Baselines3 (not a pamdp dependency) into its own directory, for the mainstream-library baseline
    pip install -q --target "$RUNS/sb3" --no-deps stable-baselines3
    PYTHONPATH="$RUNS/sb3" python bench_mainstream_platform.py --workers 2 --out "$RUNS/bench"
    # Soccer's PATRPO seeds 0 and 1 on both cores; seed 2 then runs beside platform's PADDPG arm (three processes on
    # two cores), so that no core idles while an arm is down to its last run. The side queue goes on with the H&S run
    # and then the rest of soccer (its PADDPG arm) at the lowest priority: it takes only the cycles the platform arms
    # leave, because those close issues 5 and 7 and soccer is to run "as far as the machine allows".
    pamdp reproduce soccer --runs PATRPO --seeds 0,1 --workers 2 --out "$RUNS/repro"
    set -m  # the side queue gets its own process group, so that it can be stopped as a whole
    (
        pamdp reproduce soccer --runs PATRPO --seeds 2 --workers 1 --out "$RUNS/repro"
        python bench_paddpg_hausknecht_stone.py --workers 1 --out "$RUNS/bench"    # issue 5
        nice -n 19 pamdp reproduce soccer --workers 2 --stack 3 --out "$RUNS/repro"
    ) &
    side=$!
    set +m
    # If the main queue fails (set -e) the side queue must not run on alone: a new start of this script would
    # then train the same runs in two processes at once.
    trap 'kill -TERM -- "-$side" 2>/dev/null || true' EXIT
    # The two platform arms side by side, each one process of its five seeds stacked (pamdp reproduce --stack):
    # in the update, a stack of five PASVG(0) seeds does 1.8x the seed-updates of one seed on a core, a stack of
    # three 1.5x (profiled 2026-11-29; end-to-end figures in benchmarks/seed_stacking.md), so one arm a core beats
    # each arm in turn on both cores.
    python bench_paddpg_platform.py --workers 1 --stack 5 --out "$RUNS/repro" &  # = platform --runs PADDPG + record (issue 5)
    paddpg=$!
    trap 'kill -TERM -- "-$side" 2>/dev/null || true; kill -TERM "$paddpg" 2>/dev/null || true' EXIT
    pamdp reproduce platform --runs "PASVG(0)" --workers 1 --stack 5 --out "$RUNS/repro"
    wait "$paddpg"
    pamdp reproduce platform --workers 2 --stack 5 --out "$RUNS/repro"  # every run done by now: the figure (issue 7)
    wait "$side"
    trap - EXIT
}

main "$@"
exit
