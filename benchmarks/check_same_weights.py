"""Seeded short runs of every algorithm, fingerprinted: the check that a restructuring changed no arithmetic.

Each case trains a few hundred samples from a fixed seed (off-policy cases with an early first update, so every
update path runs) and hashes the weights of every module the algorithm saves, plus its greedy and sampled actions
on fixed observations. Run it on the commit before a restructuring and after it; the two files must be equal:

    python benchmarks/check_same_weights.py --out before.json        # on the old commit
    python benchmarks/check_same_weights.py --compare before.json    # on the new one: exit 1 on a difference

The fingerprints depend on the PyTorch build and the machine (float rounding of BLAS), so compare on one machine.

Where a change reassociates sums (a different but equivalent order of float32 operations), the fingerprints differ;
``--save DIR`` keeps each case's weights and ``--diff DIR`` prints how far the new ones are from them (the largest
absolute difference, and relative to the largest weight), which says whether the difference is rounding:

    python benchmarks/check_same_weights.py --cases mpdqn-platform --save old_weights   # on the old commit
    python benchmarks/check_same_weights.py --cases mpdqn-platform --diff old_weights   # on the new one
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path

import numpy as np
import torch

import pamdp  # noqa: F401  (registers the envs)
from pamdp.algos import algorithm_class

OFF = {"learning_starts": 100, "epoch_steps": 100, "batch_size": 16}
HYAR = {"epoch_steps": 100, "batch_size": 16}  # HyAR's first update comes after its warm-up
CASES: dict[str, tuple[str, str, str | None, dict, int]] = {
    # name: (algorithm, env id, preset, settings, samples)
    "patrpo-platform": ("patrpo", "pamdp/Platform-v0", "tuned", {"batch_size": 200, "num_envs": 4}, 400),
    "patrpo-hfo": ("patrpo", "pamdp/HalfFieldOffense-v0", "hfo", {"batch_size": 200, "num_envs": 2}, 400),
    "pappo-platform": ("pappo", "pamdp/Platform-v0", "tuned", {"batch_size": 128, "minibatch_size": 32}, 256),
    "pasvg0-platform": ("pasvg0", "pamdp/Platform-v0", "tuned", OFF, 300),
    "paddpg-platform": ("paddpg", "pamdp/Platform-v0", "paper", OFF, 300),
    "pdqn-platform": ("pdqn", "pamdp/Platform-v0", "tuned", OFF, 300),
    "mpdqn-platform": ("pdqn", "pamdp/Platform-v0", "tuned", {**OFF, "multi_pass": True}, 300),
    "pdqn-goal": ("pdqn", "pamdp/Goal-v0", "goal", OFF, 300),
    "hyar-platform": ("hyar", "pamdp/Platform-v0", "cpu", {**HYAR, "warmup_steps": 100, "warmup_updates": 20}, 300),
    "hsac-flat-platform": ("hsac", "pamdp/Platform-v0", "tuned", {**OFF, "form": "flat"}, 300),
    "hsac-hier-catch": ("hsac", "pamdp/CatchPoint-v0", "tuned", {**OFF, "form": "hierarchical"}, 300),
}


def fingerprint(
    algo: str, env_id: str, preset: str | None, settings: dict, samples: int, weights: dict | None = None
) -> dict:
    """The case's fingerprint; with ``weights`` (a dict), its weights are put there too, by module and key."""
    cls = algorithm_class(algo)
    try:  # the route of issue 48: Config.preset answers for the env's presets too
        base = cls.config_class.preset(preset, env_id)
    except TypeError:  # before it: the registry's table
        from pamdp.algos import preset_config

        base = preset_config(cls.config_class, preset)
    config = cls.config_class.from_dict({"seed": 3, "torch_threads": 1, **settings}, base=base)
    model = cls(env_id, config)
    model.learn(samples, progress_bar=False)
    digest = hashlib.sha256()
    for name, module in sorted(model._modules().items()):
        for key, tensor in module.state_dict().items():
            digest.update(f"{name}.{key}".encode())
            digest.update(tensor.detach().cpu().contiguous().numpy().tobytes())
            if weights is not None and tensor.is_floating_point():
                weights[f"{name}.{key}"] = tensor.detach().cpu().clone()
    obs_size = model.observation_space.shape[0]
    obs = np.random.default_rng(0).uniform(-1, 1, size=(16, obs_size)).astype(np.float32)
    torch.manual_seed(0)
    out = {}
    for deterministic in (True, False):
        a, params = model.predict(obs, deterministic=deterministic)
        h = hashlib.sha256(np.asarray(a).tobytes())
        for p in params:
            h.update(np.asarray(p).tobytes())
        out["greedy" if deterministic else "sampled"] = h.hexdigest()[:16]
    return {"weights": digest.hexdigest()[:16], "timesteps": int(model.num_timesteps), **out}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", help="write the fingerprints to this JSON file")
    parser.add_argument("--compare", help="compare with the fingerprints in this JSON file")
    parser.add_argument("--cases", help="comma-separated case names (default: all)")
    parser.add_argument("--save", metavar="DIR", help="save each case's weights in this directory")
    parser.add_argument("--diff", metavar="DIR", help="print how far each case's weights are from those saved here")
    args = parser.parse_args(argv)
    names = args.cases.split(",") if args.cases else list(CASES)
    result = {}
    for name in names:
        weights: dict[str, torch.Tensor] = {}
        result[name] = fingerprint(*CASES[name], weights=weights)
        print(name, result[name], flush=True)
        if args.save:
            Path(args.save).mkdir(parents=True, exist_ok=True)
            torch.save(weights, Path(args.save) / f"{name}.pt")
        if args.diff:
            saved = torch.load(Path(args.diff) / f"{name}.pt")
            diff = max((weights[k] - saved[k]).abs().max().item() for k in saved)
            scale = max(t.abs().max().item() for t in saved.values())
            print(f"  {name}: largest weight difference {diff:.3g} ({diff / scale:.3g} of the largest weight)")
    if args.out:
        with open(args.out, "w") as f:
            json.dump(result, f, indent=1)
    if args.compare:
        with open(args.compare) as f:
            before = json.load(f)
        differ = [n for n in names if before.get(n) != result[n]]
        for n in differ:
            print(f"DIFFERENT {n}: before {before.get(n)}, now {result[n]}")
        print("same weights" if not differ else f"{len(differ)} of {len(names)} cases differ")
        return 1 if differ else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
