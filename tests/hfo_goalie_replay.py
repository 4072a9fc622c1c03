"""Command replay of the goalie against a recording of the real HFO server.

``tests/data/hfo_goalie_trace_seed42.json.gz`` is a stripped copy of a recording of the real server with its
goalie (LARG/HFO b8b2a1d, mhauskn/rcssserver 82212ee, mhauskn/librcsc d222758; ``--offense-agents 1
--defense-npcs 1 --deterministic --fullstate --seed 42``): per server cycle the true state of ball, agent and
goalie (logged to 1e-4 m and 1e-3 degrees), the body commands both sides sent in that cycle, and the cycles
in which the referee reset the field. The goalie sends the command logged at cycle c after deciding on the
state logged at cycle c, so each recorded command is compared with
:func:`pamdp.envs.hfo.goalie.decide` on that state. The goalie's memory is carried through the whole
recording in cycle order, as the real client carries it across episodes; at each reset the referee's
play_on ends goalie-catch mode.

Run ``python tests/hfo_goalie_replay.py`` for the match rates and a list of the mismatches.
"""

from __future__ import annotations

import gzip
import json
import pathlib
import sys
from collections import Counter
from dataclasses import dataclass

import numpy as np

from pamdp.envs.hfo import goalie

TRACE = pathlib.Path(__file__).parent / "data" / "hfo_goalie_trace_seed42.json.gz"
KINDS = {"turn": goalie.TURN, "dash": goalie.DASH, "catch": goalie.CATCH, "tackle": goalie.TACKLE,
         "kick": goalie.KICK}  # fmt: skip
#: Argument tolerances. The recorded state is rounded to 1e-4 m and 1e-3 degrees, which moves a turn towards a
#: point a few metres away by up to about 0.005 degrees, a dash power computed from a speed by up to about
#: 0.03; a turn moment is also multiplied by up to 3 (1 + 5 |v|).
TOLERANCE = {goalie.TURN: 0.05, goalie.DASH: 0.1, goalie.CATCH: 0.01, goalie.TACKLE: 0.5, goalie.KICK: 0.5}
#: Goalie state flags of the recording: tackling.
TACKLE_FLAG = 0x1000


@dataclass
class Cycle:
    cycle: int
    recorded: tuple[int, float, float]
    predicted: tuple[int, float, float]

    @property
    def kind_matches(self) -> bool:
        return self.recorded[0] == self.predicted[0]

    @property
    def matches(self) -> bool:
        if not self.kind_matches:
            return False
        tol = TOLERANCE[self.recorded[0]]
        return all(abs(a - b) <= tol for a, b in zip(self.recorded[1:], self.predicted[1:]))


def load() -> dict:
    with gzip.open(TRACE, "rt") as f:
        return json.load(f)


def world_of(trace: dict, cycle: int) -> np.ndarray:
    """The ``world`` vector of :mod:`goalie` from the recorded state of ``cycle``."""
    fields = trace["rcg_states_fields"]
    row = dict(zip(fields, trace["rcg_states"][str(cycle)]))
    w = np.zeros(goalie.WORLD_SIZE)
    w[goalie.W_BX : goalie.W_BX + 4] = row["ball_x"], row["ball_y"], row["ball_vx"], row["ball_vy"]
    w[goalie.W_AX : goalie.W_AX + 4] = row["self_x"], row["self_y"], row["self_vx"], row["self_vy"]
    w[goalie.W_ABODY] = row["self_body_deg"]
    w[goalie.W_GX : goalie.W_GX + 4] = row["goalie_x"], row["goalie_y"], row["goalie_vx"], row["goalie_vy"]
    w[goalie.W_GBODY] = row["goalie_body_deg"]
    w[goalie.W_GSTAMINA] = row["goalie_stamina"]
    w[goalie.W_GEFFORT] = row["goalie_effort"]
    w[goalie.W_GRECOVERY] = row["goalie_recovery"]
    # The fullstate's "k": the agent sent a kick in the previous cycle.
    previous = trace["rcl_commands"].get(str(cycle - 1), [[], []])[0]
    w[goalie.W_AGENT_KICKED] = any(c[0] == "kick" for c in previous)
    w[goalie.W_AGENT_TACKLING] = bool(int(row["self_state"]) & TACKLE_FLAG)
    w[goalie.W_GOALIE_FREEZE] = 0.0  # no goalie tackle in the recording
    w[goalie.W_CYCLE] = cycle
    return w


def recorded_command(commands: list) -> tuple[int, float, float] | None:
    """The goalie's body command of a cycle as (kind, arg1, arg2); a dash without direction has direction 0."""
    for name, *args in commands:
        if name in KINDS:
            args = [float(a) if not isinstance(a, str) else float(a == "on") for a in args] + [0.0, 0.0]
            return KINDS[name], args[0], args[1]
    return None


def replay(trace: dict) -> list[Cycle]:
    memory = goalie.new_memory()
    resets = set(trace["reset_cycles"])
    cycles = []
    for cycle in sorted(int(c) for c in trace["rcg_states"]):
        if cycle in resets:
            goalie.start_episode(memory)
        predicted = goalie.decide(world_of(trace, cycle), memory)
        recorded = recorded_command(trace["rcl_commands"].get(str(cycle), [[], []])[1])
        if recorded is not None:
            cycles.append(Cycle(cycle, recorded, (int(predicted[0]), float(predicted[1]), float(predicted[2]))))
    return cycles


def rates(cycles: list[Cycle]) -> dict[str, tuple[int, int]]:
    """(matching, recorded) overall and per recorded command kind."""
    out = {"all": (sum(c.matches for c in cycles), len(cycles))}
    for kind in sorted({c.recorded[0] for c in cycles}):
        sel = [c for c in cycles if c.recorded[0] == kind]
        name = goalie.KIND_NAMES[kind]
        out[name] = (sum(c.matches for c in sel), len(sel))
        turns0 = [c for c in sel if kind == goalie.TURN and c.recorded[1] == 0.0]
        if turns0:
            out["turn 0"] = (sum(c.matches for c in turns0), len(turns0))
    return out


def main() -> None:
    cycles = replay(load())
    for name, (ok, n) in rates(cycles).items():
        print(f"{name:8s} {ok:5d} / {n:5d}  {ok / n:.4f}")
    confusion = Counter((goalie.KIND_NAMES[c.recorded[0]], goalie.KIND_NAMES[c.predicted[0]]) for c in cycles)
    print("recorded -> predicted:", dict(confusion))
    if "-v" in sys.argv:
        for c in cycles:
            if not c.matches:
                print(c.cycle, c.recorded, tuple(round(x, 4) for x in c.predicted))


if __name__ == "__main__":
    main()
