"""Presets chosen by the env: for each algorithm, env id and env arguments, the preset a run gets when none is named.

``PDQN("pamdp/HalfFieldOffense-v0")`` in Python gets the same preset (:mod:`pamdp.presets` answers for both).

``pamdp train pdqn --env pamdp/HalfFieldOffense-v0`` trains with :data:`DOMAIN_PRESETS`' ``("pdqn",
"pamdp/HalfFieldOffense-v0", ANY)`` entry; an explicit ``--preset`` (or a config file's ``preset``) still wins, and an
env without an entry gets the algorithm's default preset. An entry may ask for some of the env's arguments
(:func:`when`): ``pamdp train pdqn --env pamdp/HardMove-v0 --env-kwargs '{"n": 8}'`` gets the ``when(n=(8, 10))``
entry, the env's default ``n`` the ``ANY`` one; of the entries that fit, the one naming the most arguments wins.

An entry names a preset: either one the algorithm's config already has (``overrides`` empty: the env's choice
among them), or a new one, ``base`` with ``overrides``, each override with the place its value comes from. Values
the sources do not give are marked ``assumed``; a source's settings that pamdp has no setting for are listed in
the entry's ``note``.

Sources:

- MP-DQN's HFO script: Bester et al.'s code, ``run_soccer_pdqn.py`` (cycraig/MP-DQN), the settings of their
  Half Field Offense results, as issue 27 lists them.
- MP-DQN's Goal script: the same repository's ``run_goal_pdqn.py``.
- HyAR: Li et al., "HyAR: Addressing Discrete-Continuous Action Reinforcement Learning via Hybrid Action
  Representation" (ICLR 2022), its budgets. HyAR's Catch Point script:
  ``main_embedding_direction_catch_td3.py`` of HyAR's code (TJU-DRL-LAB/AI-Optimizer's copy), read for ``hyar``'s
  ``catch_point`` preset (``benchmarks/hyar_scripts.md``); HyAR's Hard Move script, ``main_embedding_hard_move_td3.py``
  (Metro1998/HyAR's copy), for its ``hard_move`` preset; its Goal and Hard Goal scripts,
  ``main_embedding_goal_td3.py`` and ``main_embedding_hard_goal_td3.py`` (the same settings), for ``goal`` and
  ``hard_goal``; the other ``hyar`` presets take TD3's settings or say what they assume.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from pamdp.presets.goal_start import MASSON_GOAL_START, MASSON_HARD_GOAL_START

__all__ = [
    "ANY",
    "DomainPreset",
    "DOMAIN_PRESETS",
    "LARGE_K",
    "domain_preset",
    "domain_presets_of",
    "envs_named_by",
    "when",
]

PLATFORM = "pamdp/Platform-v0"
HFO = "pamdp/HalfFieldOffense-v0"
HFO_GOALIE = "pamdp/HalfFieldOffenseGoalie-v0"
HARD_MOVE = "pamdp/HardMove-v0"
MPDQN_HFO = "MP-DQN's HFO script"
MPDQN_GOAL = "MP-DQN's Goal script"


@dataclasses.dataclass(frozen=True)
class DomainPreset:
    """One env's preset for one algorithm."""

    name: str
    """The preset's name, as ``--preset`` takes it."""
    base: str
    """The algorithm's own preset it derives from (``name`` itself for an existing preset chosen as it is)."""
    overrides: tuple[tuple[str, Any, str], ...] = ()
    """``(setting, value, source)`` over ``base``."""
    note: str = ""
    """Why this preset for this env, and what of the source it leaves out."""

    @property
    def settings(self) -> dict[str, Any]:
        return {name: value for name, value, _ in self.overrides}


def when(**values) -> tuple[tuple[str, tuple[Any, ...]], ...]:
    """The env arguments an entry applies to, each with the values it takes: ``when(n=(8, 10))``, n is 8 or 10."""
    return tuple(sorted((name, tuple(allowed)) for name, allowed in values.items()))


ANY = when()
"""An entry for the env whatever its arguments."""


def _derived(name: str, base: str, note: str, *overrides: tuple[str, Any, str]) -> DomainPreset:
    return DomainPreset(name, base, tuple(overrides), note)


_MPDQN_HFO = _derived(
    "hfo",
    "paper",
    "MP-DQN's own Half Field Offense settings (multi-pass on; --multi-pass false gives P-DQN with them). Not "
    "reproduced: the script's n-step return targets mixed with beta are pamdp's Monte-Carlo mixing, and it "
    "makes its updates at the end of each episode rather than spread over it.",
    ("multi_pass", True, MPDQN_HFO),
    ("gamma", 0.99, MPDQN_HFO),
    ("hidden_sizes", (256, 128, 64), MPDQN_HFO),
    ("activation", "leaky_relu", MPDQN_HFO),
    ("q_lr", 1e-3, MPDQN_HFO),
    ("actor_lr", 1e-5, MPDQN_HFO),
    ("batch_size", 32, MPDQN_HFO),
    ("tau_q", 0.001, MPDQN_HFO),
    ("tau_actor", 0.001, MPDQN_HFO),
    ("beta", 0.2, MPDQN_HFO),
    ("epsilon_end", 0.1, MPDQN_HFO),
    ("epsilon_steps", 100_000, f"{MPDQN_HFO}: 1000 episodes, about 100 000 samples"),
    ("explore_params", True, f"{MPDQN_HFO}: epsilon draws uniform random parameters"),
    ("ou_sigma", 0.0, f"{MPDQN_HFO}: no Ornstein-Uhlenbeck noise"),
    ("buffer_size", 500_000, MPDQN_HFO),
    ("updates_per_step", 0.1, MPDQN_HFO),
    ("grad_clip", 1.0, MPDQN_HFO),
    ("learning_starts", 1_000, MPDQN_HFO),
)

_HYAR_HFO = _derived(
    "hfo",
    "cpu",
    "HyAR's paper has no HFO runs: the cpu preset with Half Field Offense's replay and exploration lengths "
    "from MP-DQN's HFO settings.",
    ("buffer_size", 500_000, MPDQN_HFO),
    ("epsilon_steps", 100_000, f"{MPDQN_HFO}: exploration over about 100 000 samples"),
    ("warmup_steps", 20_000, "assumed: HFO's random episodes are long, HyAR's 5000 would be ~10^6 samples"),
)


_TD3_GAMMA = ("gamma", 0.99, "TD3's discount (HyAR's code builds on TD3's)")


HYAR_CATCH = "HyAR's Catch Point script"
HYAR_HARD_MOVE = "HyAR's Hard Move script"
HYAR_GOAL = "HyAR's Goal script"
_HYAR_NOT_EXPRESSIBLE = (
    "over the cpu preset (a quarter of a TD3 update a sample, 128-wide networks: HyAR's ~1 update a sample at 256 "
    "wide would cost several times more); TD3 replays the whole run (HyAR's scripts: TD3's own replay of the newest "
    "1e5 samples, td3_replay, did not help on Goal). Not expressible here: its latent box on the parameters' latent "
    "only, its VAE's multiplicative input fusion and its relabelling tests (benchmarks/hyar_scripts.md)."
)


def _hyar_script(name: str, script: str, note: str, *, latents: int, warmup: tuple[int, str],
                 noise_steps: tuple[int, str], params: int = 1, buffer: int = 1_200_000) -> DomainPreset:  # fmt: skip
    """HyAR-TD3 with the settings of one of HyAR's own scripts where pamdp has them: ``latents`` dimensions for the
    embedding and for the parameters' latent, a VAE that reconstructs ``params`` parameters, ``warmup`` random
    samples (inside the budget; with where the number comes from), a replay of ``buffer`` samples (more than the
    run: HyAR's representation replay keeps it all), exploration noise falling from 1.0 to 0.1 over
    ``noise_steps`` samples (HyAR: over 1000 episodes)."""
    return _derived(
        name,
        "cpu",
        f"{note} {_HYAR_NOT_EXPRESSIBLE}",
        _TD3_GAMMA,
        ("embed_dim", latents, script),
        ("latent_dim", latents, script),
        # HyAR's VAE loss is state change + 2 x reconstruction + 0.5 x KL, each a mean over its dimensions; pamdp's
        # sums the reconstruction and the KL, so HyAR's weights over its reconstruction weight become these.
        ("kl_weight", params / 4 / latents, f"{script}: its KL weight 0.5 over a mean, in pamdp's units"),
        ("dynamics_weight", params / 2, f"{script}: its state-change weight against a reconstruction weight of 2"),
        ("warmup_steps", warmup[0], f"{script}: {warmup[1]}"),
        ("warmup_updates", 5_000, script),
        ("buffer_size", buffer, f"{script}: its representation's replay keeps every sample of the run"),
        ("exploration_noise_start", 1.0, f"{script}: noise std 1.0 to 0.1 over 1000 episodes"),
        ("exploration_noise_steps", noise_steps[0], f"{script}: {noise_steps[1]}"),
        ("epsilon_start", 0.0, f"{script}: no epsilon-greedy"),
        ("epsilon_end", 0.0, f"{script}: no epsilon-greedy"),
        ("target_noise", 0.1, "HyAR's TD3 (P_TD3_relable.py)"),
    )


_HYAR_CATCH_POINT = _hyar_script(
    "catch_point",
    HYAR_CATCH,
    "HyAR's Catch Point script's representation, exploration and replay,",
    latents=4,
    warmup=(100_000, "5000 random episodes (~115 000 samples, not in its budget; in ours)"),
    noise_steps=(25_000, "1000 episodes of at most 25 samples"),
)
"""HyAR-TD3 on Catch Point with the settings of HyAR's own script where pamdp has them (its update rate and network
widths stay the cpu preset's)."""

_HYAR_HARD_MOVE = _hyar_script(
    "hard_move",
    HYAR_HARD_MOVE,
    "HyAR's Hard Move script's representation, exploration and replay (since 2026-12-03; before, the cpu preset "
    "with a 20 000-sample warm-up, 0.263 at n = 8),",
    latents=6,
    warmup=(100_000, "5000 random episodes (up to 150 000 samples, not in its budget; in ours, as on Catch Point)"),
    noise_steps=(30_000, "1000 episodes of at most 30 samples"),
)
"""HyAR-TD3 on Hard Move with the settings of HyAR's own script where pamdp has them, as :data:`_HYAR_CATCH_POINT`."""


def _hyar_goal(name: str, domain: str) -> DomainPreset:
    """HyAR-TD3 on Goal or Hard Goal with the settings of HyAR's Goal script (its Hard Goal script has the same: 6/6
    latents, a VAE over two parameters, 20 000 random episodes, the same noise schedule)."""
    return _hyar_script(
        name,
        HYAR_GOAL,
        f"HyAR's Goal script's representation, exploration and replay on {domain} (since 2026-12-03; before, the cpu "
        "preset with a 5 000-sample warm-up, 0.00 on Goal and 0.04 on Hard Goal over 3 seeds),",
        latents=6,
        params=2,
        warmup=(30_000, "20 000 random episodes (~30 000 samples, not in its budget; in ours)"),
        buffer=400_000,
        noise_steps=(10_000, "1000 episodes, ~10 000 samples at the start of a run"),
    )


def _mpdqn_hybrid(name: str, note: str, *more: tuple[str, Any, str]) -> DomainPreset:
    """MP-DQN on one of HyAR's domains: the tuned preset with multi-pass and a long-horizon discount."""
    return _derived(
        name,
        "tuned",
        note,
        ("multi_pass", True, "MP-DQN (Bester et al.)"),
        ("gamma", 0.99, "assumed: TD3's discount, as HyAR's baselines"),
        *more,
    )


GOAL_NOTE = (
    "The parameter network starts from Masson's hand-set linear weights, as MP-DQN's Goal runs did "
    "(param_passthrough: their fixed passthrough layer; a config file's param_passthrough = [] starts it at "
    "random, the start later work reports MP-DQN failing from). Not reproduced: the std 1e-5 of the script's "
    "output layers (the Q-network's is pamdp's default, the actor's starts at zero)."
)

_MPDQN_GOAL_SETTINGS = (
    ("multi_pass", True, MPDQN_GOAL),
    ("hidden_sizes", (256,), MPDQN_GOAL),
    ("gamma", 0.95, MPDQN_GOAL),
    ("batch_size", 128, MPDQN_GOAL),
    ("q_lr", 1e-3, MPDQN_GOAL),
    ("actor_lr", 1e-5, MPDQN_GOAL),
    ("tau_q", 0.1, MPDQN_GOAL),
    ("tau_actor", 0.001, MPDQN_GOAL),
    ("epsilon_end", 0.01, MPDQN_GOAL),
    ("epsilon_steps", 10_000, f"{MPDQN_GOAL}: 1000 episodes (assumed ~10 samples each)"),
    ("buffer_size", 20_000, MPDQN_GOAL),
    ("learning_starts", 128, MPDQN_GOAL),
    ("grad_clip", 1.0, MPDQN_GOAL),
    ("reward_scale", 1 / 50, f"{MPDQN_GOAL}: a goal's 50 learnt as 1"),
)
"""MP-DQN's Goal script's settings over P-DQN's ``paper`` preset (Goal's and Hard Goal's presets)."""

# Hard Move's networks for its 2^n actions.
_HARD_MOVE_Q = (
    ("hidden_sizes", (256, 256), "assumed: up to 1024 Q outputs at n = 10"),
    ("buffer_size", 200_000, "assumed: a fifth of the 1M budget"),
)
LARGE_K = when(n=(8, 10))
"""Hard Move's two largest sizes, 256 and 1024 actions."""

DOMAIN_PRESETS: dict[tuple[str, str, tuple], DomainPreset] = {
    ("pdqn", HFO, ANY): _MPDQN_HFO,
    ("paddpg", HFO, ANY): DomainPreset(
        "hausknecht_stone", "hausknecht_stone", note="Hausknecht & Stone's own HFO agent: their networks and settings."
    ),
    ("patrpo", PLATFORM, ANY): _derived(
        "platform",
        "tuned",
        "The tuned preset with the paper's initial parameter noise (std 1 instead of 0.61): with the tuned noise, "
        "4 of 10 seeds of the README's main job ended near 0.90, short of the last platform (benchmarks/main_job.md).",
        ("init_log_std", 0.0, "measured: benchmarks/main_job.md (issue 45)"),
    ),
    ("patrpo", HFO, ANY): _derived(
        "hfo",
        "tuned",
        "The tuned preset acting only among the actions that have an effect: KICK is masked while the ball is not "
        "kickable (benchmarks/hfo_learning.md); the paper's soccer settings are 'paper'.",
        ("action_mask", True, "measured: benchmarks/hfo_learning.md (issue 27)"),
    ),
    ("pappo", HFO, ANY): DomainPreset(
        "default",
        "default",
        note="PPO's common settings: the tuned entropy weight was found on Platform's three actions.",
    ),
    ("hyar", HFO, ANY): _HYAR_HFO,
    ("pasvg0", HFO, ANY): DomainPreset(
        "tuned",
        "tuned",
        note="No published HFO settings (the paper runs PASVG(0) on Platform alone): the tuned preset, found on "
        "Platform (benchmarks/pasvg_tuning.md); the paper's 'paper' preset is the other choice.",
    ),
    ("hsac", HFO, ANY): DomainPreset(
        "tuned",
        "tuned",
        note="Delalleau et al.'s HFO settings (their 0.639 goals) were not read here: the "
        "tuned preset, found on Platform (benchmarks/hsac_platform.md).",
    ),
    ("pdqn", "pamdp/Goal-v0", ANY): _derived(
        "goal",
        "paper",
        "MP-DQN's own Goal settings. " + GOAL_NOTE,
        *_MPDQN_GOAL_SETTINGS,
        ("param_passthrough", MASSON_GOAL_START, f"{MPDQN_GOAL}: Masson's initial weights"),
    ),
    ("pdqn", "pamdp/HardGoal-v0", ANY): _derived(
        "hard_goal",
        "paper",
        "MP-DQN's Goal settings with Masson's start carried over to Hard Goal's shots (MASSON_HARD_GOAL_START; "
        "not published: HyAR's P-DQN on Hard Goal started at random and scored 0.0). " + GOAL_NOTE,
        *_MPDQN_GOAL_SETTINGS,
        (
            "param_passthrough",
            MASSON_HARD_GOAL_START,
            "Masson's Goal weights, shots aimed as his (measured: benchmarks/hard_goal_start.md)",
        ),
    ),
    ("patrpo", "pamdp/CatchPoint-v0", ANY): _derived(
        "catch_point",
        "tuned",
        "The tuned preset with less parameter noise and a larger entropy weight: at the tuned noise even the best "
        "heading returns less than ending the episode with 11 failed catches, so pi_d collapses onto catch; and a "
        "larger critic fitted longer, against catches tried too early (benchmarks/catch_point.md, "
        "benchmarks/catch_point_failures.md).",
        ("init_log_std", -1.5, "measured: benchmarks/catch_point.md (issue 26)"),
        ("entropy_coef", 0.05, "measured: benchmarks/catch_point.md (issue 26)"),
        ("vf_hidden_sizes", (256, 256), "measured: benchmarks/catch_point.md (issue 26)"),
        ("vf_epochs", 10, "measured: benchmarks/catch_point.md (issue 26)"),
    ),
    ("patrpo", HARD_MOVE, ANY): _derived(
        "hard_move",
        "tuned",
        "The tuned preset with pi_c on the state alone, a block of outputs per action: the 2^n actions' means in "
        "one pass instead of 2^n passes of pi_c's hidden layers, which made a sample cost grow with 2^n "
        "(benchmarks/large_k_cost.md).",
        ("pi_c_input", "state", "measured: docs/results.md, benchmark suite (issue 26)"),
    ),
    ("pdqn", "pamdp/CatchPoint-v0", ANY): _mpdqn_hybrid(
        "catch_point",
        "HyAR's P-DQN settings were not read here. The heading of a move must be explored (the tuned preset's OU "
        "noise of 1e-4 never varies it, and MP-DQN gave up on moving: 0.125) and a one-layer 64-wide network "
        "learns it too coarsely (benchmarks/catch_point.md).",
        ("explore_params", True, "measured: benchmarks/catch_point.md (issue 26)"),
        ("ou_sigma", 0.1, "measured: benchmarks/catch_point.md (issue 26)"),
        ("ou_theta", 1.0, "measured: benchmarks/catch_point.md (issue 26): i.i.d. Gaussian noise"),
        ("hidden_sizes", (128, 128), "measured: benchmarks/catch_point.md (issue 26)"),
    ),
    ("pdqn", HARD_MOVE, ANY): _mpdqn_hybrid(
        "hard_move", "HyAR's P-DQN settings were not read here; 2^n actions, so a wider Q-network.", *_HARD_MOVE_Q
    ),
    ("pdqn", HARD_MOVE, LARGE_K): _derived(
        "hard_move_large",
        "tuned",
        "P-DQN's single pass of the Q-network over all actions' parameters: MP-DQN's K passes a state are out of "
        "a CPU's reach at this K (benchmarks/large_k_cost.md). Otherwise the hard_move preset.",
        ("multi_pass", False, "HyAR's Table 2 compares P-DQN (Xiong et al.): one pass"),
        ("gamma", 0.99, "assumed: TD3's discount, as HyAR's baselines"),
        *_HARD_MOVE_Q,
    ),
    ("pdqn", "pamdp/Moving-v0", ANY): _mpdqn_hybrid(
        "moving", "No published settings; the tuned preset with multi-pass."
    ),
    ("pdqn", "pamdp/Sliding-v0", ANY): _mpdqn_hybrid(
        "sliding", "No published settings; the tuned preset with multi-pass."
    ),
    ("hyar", "pamdp/Goal-v0", ANY): _hyar_goal("goal", "Goal"),
    ("hyar", "pamdp/HardGoal-v0", ANY): _hyar_goal("hard_goal", "Hard Goal"),
    ("hyar", "pamdp/CatchPoint-v0", ANY): _HYAR_CATCH_POINT,
    ("hyar", HARD_MOVE, ANY): _HYAR_HARD_MOVE,
    ("pasvg0", HARD_MOVE, LARGE_K): _derived(
        "hard_move_large",
        "tuned",
        "The tuned preset with the paper's Gumbel-Softmax gradient of pi_d: the exact expectation over the K "
        "actions costs K critic evaluations a state, out of a CPU's reach at this K (benchmarks/large_k_cost.md).",
        ("discrete_gradient", "gumbel", "PASVG(0)'s paper"),
    ),
}
"""``(algorithm's command-line name, env id, env arguments (:func:`when`)) -> DomainPreset``."""

# Half Field Offense against the goalie, registered as its own id, plays with the presets of HFO (which serve
# ``defense_npcs=1`` too): KICK masked while not kickable. No 1v1 preset of its own has been measured to do better
# (benchmarks/hfo_goalie_learning.md).
DOMAIN_PRESETS.update({(a, HFO_GOALIE, m): p for (a, e, m), p in list(DOMAIN_PRESETS.items()) if e == HFO})


def domain_preset(algo: str, env_id: str | None, env_kwargs: dict | None = None) -> DomainPreset | None:
    """The env's preset for algorithm ``algo`` (its command-line name), or ``None`` where it has none: of the
    entries for ``env_id`` whose arguments fit ``env_kwargs`` (the env's defaults where they leave one out), the
    one naming the most."""
    entries = {match: p for (a, e, match), p in DOMAIN_PRESETS.items() if (a, e) == (algo, env_id)}
    args = _env_arguments(env_id, env_kwargs or {}, {name for match in entries for name, _ in match})
    fitting = sorted((m for m in entries if all(args[name] in values for name, values in m)), key=len, reverse=True)
    if len(fitting) > 1 and len(fitting[0]) == len(fitting[1]):
        raise ValueError(
            f"DOMAIN_PRESETS has two entries for ({algo!r}, {env_id!r}) that fit its arguments {args}: "
            f"{fitting[0]} and {fitting[1]}; expected one naming more arguments than the other"
        )
    return entries[fitting[0]] if fitting else None


def _env_arguments(env_id: str, env_kwargs: dict, names: set[str]) -> dict[str, Any]:
    """The values of the env arguments ``names`` that ``gymnasium.make(env_id, **env_kwargs)`` would pass."""
    if not names:
        return {}
    import inspect

    from pamdp.envs.backends import check_env_kwargs, env_creator, env_spec

    check_env_kwargs(env_id, env_kwargs)
    params = inspect.signature(env_creator(env_id)).parameters
    unknown = sorted(names - set(params))
    if unknown:
        raise ValueError(
            f"DOMAIN_PRESETS names env argument {', '.join(map(repr, unknown))} for {env_id!r}, which takes no such "
            f"argument; expected some of {', '.join(params)}"
        )
    given = {**{n: p.default for n, p in params.items()}, **(env_spec(env_id).kwargs or {}), **env_kwargs}
    return {name: given[name] for name in sorted(names)}


def domain_presets_of(algo: str) -> dict[str, DomainPreset]:
    """``{name: DomainPreset}`` of the new presets (those with a name of their own) of algorithm ``algo``."""
    return {p.name: p for (a, _, _), p in DOMAIN_PRESETS.items() if a == algo and p.name != p.base}


def envs_named_by(algo: str, name: str) -> list[str]:
    """The env ids for which preset ``name`` of algorithm ``algo`` was made (empty for one of the algorithm's own:
    those are for any env)."""
    return sorted({e for (a, e, _), p in DOMAIN_PRESETS.items() if a == algo and p.name == name and p.name != p.base})
