#!/usr/bin/env bash
# The long learning runs still owed to issues 5 and 7, in the order of what each CPU-hour buys.
#
#   nohup benchmarks/backlog.sh > backlog.log 2>&1 &      # at the start of a session, from the repo root
#
# Every step resumes where an earlier, interrupted invocation stopped (finished runs are skipped, partial
# ones continue from their last checkpoint; the off-policy runs keep their replay buffer in it), so a
# session simply starts this again. Outputs go to $PAMDP_RUNS (default /root/pamdp-runs), outside the work
# tree; records and figures land in benchmarks/ and the experiments' directories, to be committed by hand.
# A session that starts on a new machine has no $PAMDP_RUNS: everything starts from scratch.
#
# Costs on the 2-core Intel Xeon of 2026-11-29, after the hand-written off-policy updates (offpolicy_speed.md),
# per run with other runs beside it:
#   1. platform's PADDPG arm, paper preset, 5 x 1M, two seed stacks (3 + 2): ~20-25 s of CPU per run-epoch,
#      ~2.8 core-hours in all (issue 5's benchmark and one arm of issue 7's figure)
#   2. platform's PATRPO arm, paper preset, 5 x 1M: 4 to 10 min a run                ~0.5 core-hours
#   3. PADDPG with Hausknecht & Stone's preset on Platform, 1 seed x 300k (issue 5): ~107 s of CPU an epoch
#      beside other runs                                                           ~0.9 core-hours
#   4. platform's PASVG(0) arm, paper preset, 5 x 1M, unstacked (stacking no longer pays for it): ~4 ms an
#      update on an idle core with subnormals flushed (denormals.md; ~7 ms before), 40-45 s of CPU an epoch
#      with two runs side by side                                                  ~6 core-hours
#   5. soccer's PADDPG arm (3 x 5M) and PATRPO seed 2: as far as the sessions allow (issue 7 asks for "as far
#      as the machine allows"); PATRPO seeds 0 and 1 are recorded in docs/results.md
# Steps 3 and 5 run in a side queue beside the main one (2, 1, 4, then the figure), step 5 at the lowest
# priority. The experiments
# done earlier (step-size, kl-estimators, the later methods, the mainstream baseline, PASVG(0) tuned) have
# their records and figures committed; `pamdp reproduce step-size` etc. re-create them (see docs/results.md).
set -euo pipefail
cd "$(dirname "$0")"
RUNS=${PAMDP_RUNS:-/root/pamdp-runs}

# All in one function, which bash reads whole before running any of it: editing this file while it runs
# changes nothing in the running copy.
main() {
    set -m  # the side queue gets its own process group, so that it can be stopped as a whole
    (
        python bench_paddpg_hausknecht_stone.py --workers 1 --out "$RUNS/bench"    # issue 5
        nice -n 19 pamdp reproduce soccer --workers 1 --stack 3 --out "$RUNS/repro"
    ) &
    side=$!
    set +m
    # If the main queue fails (set -e) the side queue must not run on alone: a new start of this script would
    # then train the same runs in two processes at once.
    trap 'kill -TERM -- "-$side" 2>/dev/null || true' EXIT
    pamdp reproduce platform --runs PATRPO --workers 2 --out "$RUNS/repro"
    python bench_paddpg_platform.py --workers 2 --stack 3 --out "$RUNS/repro"  # = platform --runs PADDPG + record
    pamdp reproduce platform --runs "PASVG(0)" --workers 2 --out "$RUNS/repro"
    pamdp reproduce platform --workers 2 --out "$RUNS/repro"  # every run done by now: the figure (issue 7)
    wait "$side"
    trap - EXIT
}

main "$@"
exit
