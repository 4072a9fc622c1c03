"""Make ``hfo_goalie_episodes_seed42.json.gz`` from the full seed-42 goalie recording (path as argument).

Keeps, per episode, what the observation replay needs: the placement (``initial_wm``), the goalie's body at the
reset cycle, the actions sent (float32 parameters as recorded), the statuses and the 68 features. Features are
stored as integers in units of 1e-5 (the replay's tolerance is 2e-3), each step as its difference from the
previous one, which keeps the file small.
"""

from __future__ import annotations

import gzip
import json
import pathlib
import sys

SCALE = 100_000


def main(source: str) -> None:
    trace = json.load(open(source))
    fields = trace["rcg_states_fields"]
    episodes = []
    for ep in trace["episodes"]:
        row = trace["rcg_states"].get(str(ep["initial_cycle"] - 2))  # none for episode 0 (the replay skips it)
        reset = dict(zip(fields, row)) if row else {"goalie_body_deg": None}
        rows = [ep["initial_features"]] + [s["features"] for s in ep["steps"]]
        q = [[round(x * SCALE) for x in row] for row in rows]
        deltas = [q[0]] + [[a - b for a, b in zip(q[k], q[k - 1])] for k in range(1, len(q))]
        episodes.append({
            "episode": ep["episode"],
            "policy": ep["policy"],
            "outcome": ep["outcome"],
            "initial_wm": ep["initial_wm"],
            "goalie_body_deg": reset["goalie_body_deg"],
            "actions": [[s["action"], s["params"]] for s in ep["steps"]],
            "statuses": [s["status"] for s in ep["steps"]],
            "features": deltas,
        })  # fmt: skip
    out = {
        "source": "LARG/HFO b8b2a1d, mhauskn/rcssserver 82212ee, mhauskn/librcsc d222758; bin/HFO --offense-agents 1 "
        "--defense-npcs 1 --frames-per-trial 500 --untouched-time 100 --seed 42 --deterministic --fullstate",
        "feature_scale": SCALE,
        "episodes": episodes,
    }
    path = pathlib.Path(__file__).parent / "hfo_goalie_episodes_seed42.json.gz"
    with gzip.open(path, "wt", compresslevel=9) as f:
        json.dump(out, f, separators=(",", ":"))


if __name__ == "__main__":
    main(sys.argv[1])
