#!/usr/bin/env bash
# The long learning runs still owed to issue 7, in the order of what each CPU-hour buys.
#
#   nohup benchmarks/backlog.sh > backlog.log 2>&1 &      # at the start of a session, from the repo root
#
# Every step resumes where an earlier, interrupted invocation stopped (finished runs are skipped, partial
# ones continue from their last checkpoint; the off-policy runs keep their replay buffer in it), so a
# session simply starts this again. Outputs go to $PAMDP_RUNS (default /root/pamdp-runs), outside the work
# tree; records and figures land in benchmarks/ and the experiments' directories, to be committed by hand.
# A session that starts on a new machine has no $PAMDP_RUNS: everything starts from scratch.
#
# Costs on the 2-core Intel Xeon, measured 2026-11-29/30 (offpolicy_speed.md, denormals.md, denormals_hfo.md),
# per run with another run beside it:
#   done: the whole platform figure (all three arms, 2026-11-30), step-size, kl-estimators, PADDPG with Hausknecht &
#         Stone's preset, soccer's PATRPO seed 2 (records and figures committed; docs/results.md has the commands)
#   1. the platform figure again (minutes; skips every finished run)
#   2. soccer's PATRPO seeds 0 and 1 again, side by side: ~50 s of CPU an epoch, ~1.4 h a run (2026-11-30)
#   3. soccer's PADDPG arm (3.3 ms a sample on an idle core, ~4.6 h of CPU a run, two runs at a time)
#                                                                                  ~14 core-hours
# One queue, in that order, on both cores.
set -euo pipefail
cd "$(dirname "$0")"
RUNS=${PAMDP_RUNS:-/root/pamdp-runs}

# All in one function, which bash reads whole before running any of it: editing this file while it runs
# changes nothing in the running copy.
main() {
    pamdp reproduce platform --workers 2 --out "$RUNS/repro"  # every run is done: draws the figure again (issue 7)
    # Soccer's PATRPO seeds 0 and 1 again: their run directories went with an earlier machine (their results are in
    # docs/results.md), and the figure needs their curves beside seed 2's (done 2026-11-30). ~1.4 h a run.
    pamdp reproduce soccer --runs PATRPO --workers 2 --out "$RUNS/repro"
    # PADDPG's three seeds, two at a time (~4.6 h of CPU a run; seed stacking was removed with issue 28).
    pamdp reproduce soccer --runs PADDPG --workers 2 --out "$RUNS/repro"
}

main "$@"
exit
