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
#   done: platform's PATRPO and PADDPG arms, PADDPG with Hausknecht & Stone's preset, step-size,
#         kl-estimators (records and figures committed; docs/results.md has the commands)
#   1. platform's PASVG(0) arm, paper preset, 5 x 1M, unstacked (stacking gains ~1.06x, seed_stacking.md):
#      40-45 s of CPU an epoch, ~1.2 h a run                                       ~6 core-hours
#   2. the platform figure from all three arms                                     minutes
#   3. soccer, as far as the sessions allow (issue 7 asks for "as far as the machine allows"): PATRPO seed 2
#      (66-90 s of CPU an epoch, ~2.3 h; seeds 0 and 1 are recorded in docs/results.md) and the PADDPG arm
#      (3.3 ms a sample on an idle core, ~4.6 h of CPU a run; seeds 0-1 stacked, seed 2 alone)
#                                                                                  ~16 core-hours
# One queue, in that order, on both cores.
set -euo pipefail
cd "$(dirname "$0")"
RUNS=${PAMDP_RUNS:-/root/pamdp-runs}

# All in one function, which bash reads whole before running any of it: editing this file while it runs
# changes nothing in the running copy.
main() {
    pamdp reproduce platform --runs "PASVG(0)" --workers 2 --out "$RUNS/repro"
    pamdp reproduce platform --workers 2 --out "$RUNS/repro"  # every run done by now: the figure (issue 7)
    # seeds 0 and 1 of PATRPO ran on an earlier machine; their results are in docs/results.md
    # Three processes on the two cores: PATRPO's seed 2 (~2.3 h), PADDPG's seeds 0-1 stacked (~7.7 h of CPU) and
    # its seed 2 alone (~4.6 h); the stack ends last, so none of the cores idles for long.
    pamdp reproduce soccer --runs PATRPO --seeds 2 --workers 1 --out "$RUNS/repro" &
    pamdp reproduce soccer --runs PADDPG --workers 2 --stack 2 --out "$RUNS/repro"
    wait
}

main "$@"
exit
