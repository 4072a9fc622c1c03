"""Checkpoints: reading and writing them, and starting a model's networks from another's.

A checkpoint is one file written atomically (:func:`pamdp.atomic.atomic_write`) holding tensors and plain data
only; it is read back with ``torch.load(weights_only=True)``, so loading never executes code. Loading a model whichever
algorithm wrote it is the registry's :func:`pamdp.algos.load_model`.
"""

from __future__ import annotations

import os
from pathlib import Path

import torch

from pamdp.atomic import atomic_write

__all__ = [
    "FINAL_MODEL",
    "CHECKPOINT",
    "FORMAT",
    "atomic_save",
    "read_checkpoint",
    "transfer_weights",
]

FINAL_MODEL = "final_model.pt"
CHECKPOINT = "checkpoint.pt"
FORMAT = "pamdp-checkpoint"
"""The ``format`` entry of every checkpoint, which tells a pamdp checkpoint from any other torch file."""
RENAMED = {
    # PASVG(0)'s critics became one TwinQ (its second critic with twin_critics only)
    "PASVG0": {
        "critic.net.": "critic.q1.",
        "critic2.net.": "critic.q2.",
        "critic_target.net.": "critic_target.q1.",
        "critic2_target.net.": "critic_target.q2.",
    },
    # PADDPG's critic became a TwinQ of one critic
    "PADDPG": {"critic.net.": "critic.q1.", "critic_target.net.": "critic_target.q1."},
}
"""Per algorithm, the tensors its checkpoints once held under other names, ``{old prefix: new prefix}`` of
``network.key``: :func:`read_checkpoint` moves them, so that files written before still load."""


def atomic_save(payload: dict, path: str | os.PathLike) -> None:
    """``torch.save`` to a temporary file beside ``path``, fsync, then rename over it."""
    atomic_write(path, lambda f: torch.save(payload, f), "model.pt")


def _resolve_model_path(path: str | os.PathLike) -> Path:
    path = Path(path)
    if path.is_dir():
        for name in (FINAL_MODEL, CHECKPOINT):
            if (path / name).is_file():
                return path / name
        raise FileNotFoundError(f"run directory {path} holds neither {FINAL_MODEL} nor {CHECKPOINT}")
    if not path.is_file():
        raise FileNotFoundError(f"no pamdp model at {path}: expected a checkpoint file or a run directory")
    return path


def _load_failure(exc: Exception) -> str:
    """What ``torch.load`` found wrong, without its advice to retry with ``weights_only=False``: that would run
    whatever code the file holds."""
    advice = ("weights_only", "Weights only", "file an issue", "documentation of torch.load")
    lines = [line.strip() for line in str(exc).splitlines()]
    found = [line for line in lines if line and not any(a in line for a in advice)]
    return f"{type(exc).__name__}: {found[0].split('. ')[0]}" if found else type(exc).__name__


def read_checkpoint(path: str | os.PathLike) -> dict:
    """Read a checkpoint with ``weights_only=True``, its tensors on the CPU (whatever device saved them, so a model
    trained on a GPU reads where there is none); a file that is not one raises a clear ``ValueError``."""
    path = _resolve_model_path(path)
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:
        raise ValueError(
            f"{path} is not a readable pamdp checkpoint ({_load_failure(exc)}); expected a file written by pamdp's "
            "save, which holds tensors and plain data only"
        ) from exc
    if not isinstance(payload, dict) or payload.get("format") != FORMAT:
        raise ValueError(f"{path} is not a pamdp checkpoint (no '{FORMAT}' header)")
    renamed = RENAMED.get(payload["algo"], {})
    if renamed:
        modules: dict[str, dict] = {}
        for name, state in payload["modules"].items():
            for key, tensor in state.items():
                full = f"{name}.{key}"
                old = next((old for old in renamed if full.startswith(old)), None)
                module, _, key = (full if old is None else renamed[old] + full[len(old) :]).partition(".")
                modules.setdefault(module, {})[key] = tensor
        payload["modules"] = modules
    return payload


def transfer_weights(
    model,
    source: str | os.PathLike,
    input_columns: list[int | None] | None = None,
    keep: tuple[str, ...] = (),
    widen: tuple[str, ...] = (),
) -> dict[str, str]:
    """Start ``model``'s networks from those of ``source`` (a model file or run directory of the same algorithm and
    action space), trained on an env whose observation may differ: a warm start, not a resumption (optimisers,
    counters and random states stay ``model``'s own).

    ``input_columns``: for each feature of ``model``'s observation, the index of the same feature in ``source``'s
    observation, or ``None`` for a feature ``source`` never saw, whose input weights start at zero (so the network
    first computes what ``source``'s did, ignoring the new features). ``None``: the same observation. A network
    reads the observation first and what follows it (an action's one-hot, a parameter vector) after, so a weight
    matrix whose input width differs from ``source``'s by the observations' difference has its observation columns
    mapped and the rest copied; so are the rows of a layer that predicts the observation (HyAR's dynamics head).
    ``keep``: tensors (``network.name``, e.g. ``policy.log_std``: the exploration of PATRPO's parameters) that stay
    ``model``'s own, as its settings initialise them; ``widen``: tensors that take, entry by entry, the larger of the
    source's and ``model``'s own (``policy.log_std``: the source's exploration where it is wider, the new settings'
    ``init_log_std`` where the source's had narrowed below it). A name may select one row of a tensor,
    ``policy.log_std[2]`` (the third action's parameters); a row named in ``keep`` is kept even where its tensor is
    widened. Returns ``{tensor: "copied", "inputs mapped", "kept", "widened" or, for a tensor whose rows differ,
    "kept rows [2], widened"}``; any other mismatch is a ``ValueError`` naming the tensor, before ``model`` is
    changed.
    """
    payload = read_checkpoint(source)
    if payload["algo"] != type(model).__name__:
        raise ValueError(f"{source} holds a {payload['algo']} model; expected a {type(model).__name__} one")
    shapes, own = payload.get("shapes") or {}, model._shapes()
    if shapes.get("parameters") != own["parameters"]:
        raise ValueError(
            f"{source}'s actions have parameter counts {shapes.get('parameters')}, this env's {own['parameters']}; "
            "expected the same action space"
        )
    old, new = int(shapes["observation"][0]), int(own["observation"][0])
    columns = list(range(new)) if input_columns is None else list(input_columns)
    if len(columns) != new or any(c is not None and not 0 <= c < old for c in columns):
        raise ValueError(
            f"input_columns = {input_columns!r:.80}; expected {new} entries, each an index below {old} or None"
        )
    if old == new and columns != list(range(new)):  # the input layers would not be told from the hidden ones
        raise ValueError(f"input_columns = {input_columns!r:.80}; expected None: both observations have {new} features")
    own = {f"{name}.{key}": t for name, module in model._modules().items() for key, t in module.state_dict().items()}
    keep_rows, widen_rows = _selection("keep", keep, own), _selection("widen", widen, own)
    states, report = {}, {}
    for name, module in model._modules().items():
        saved = payload["modules"].get(name)
        if saved is None:
            raise ValueError(f"{source} has no network {name!r}; expected a model made with the same settings")
        states[name] = {}
        for key, target in module.state_dict().items():
            tensor, weight = f"{name}.{key}", saved.get(key)
            kept, widened = keep_rows.get(tensor, []), widen_rows.get(tensor, [])
            rows = len(target) if target.ndim else 1
            if kept == list(range(rows)):  # the whole tensor stays the model's own
                states[name][key], report[tensor] = target, "kept"
                continue
            fits = weight is not None and weight.ndim == target.ndim
            mapped = _map_observation(weight, target, columns, old) if fits else None
            if mapped is None:
                raise ValueError(
                    f"{tensor} is {tuple(target.shape)} here and "
                    f"{None if weight is None else tuple(weight.shape)} in {source}; expected the same settings"
                )
            if (kept or widened) and mapped is not weight:  # an observation's axis: no exploration tensor has one
                argument = "widen" if widened else "keep"
                raise ValueError(
                    f"{argument} names rows of {tensor}, which depends on the observation; expected one that does not"
                )
            start = mapped
            if kept or widened:  # a copy, so that the source's tensor is left as it was read
                start = mapped.clone()
                by_row, own_rows = start.view(rows, -1), target.reshape(rows, -1)
                by_row[widened] = torch.maximum(by_row[widened], own_rows[widened])
                by_row[kept] = own_rows[kept]
            states[name][key] = start
            report[tensor] = _outcome(mapped is weight, kept, widened, rows)
    for name, module in model._modules().items():
        module.load_state_dict(states[name])
    return report


def _selection(argument: str, names: tuple[str, ...], own: dict[str, torch.Tensor]) -> dict[str, list[int]]:
    """``{tensor: its rows}`` that ``names`` select: ``policy.log_std`` all its rows, ``policy.log_std[2]`` one."""
    rows: dict[str, list[int]] = {}
    for name in names:
        base, _, index = name.partition("[")
        tensor = own.get(base)
        if tensor is None:
            raise ValueError(f"{argument} names {name}; expected tensors of the model, such as {min(own)}")
        if not index:
            picked = list(range(len(tensor) if tensor.ndim else 1))
        elif index.endswith("]") and index[:-1].isdigit() and tensor.ndim and int(index[:-1]) < len(tensor):
            picked = [int(index[:-1])]
        else:
            raise ValueError(
                f"{argument} names {name}; expected {base} or one of its rows, {base}[0] to "
                f"{base}[{len(tensor) - 1 if tensor.ndim else 0}]"
            )
        rows[base] = sorted({*rows.get(base, []), *picked})
    return rows


def _outcome(same_shape: bool, kept: list, widened: list, n_rows: int) -> str:
    """What :func:`transfer_weights` did to one tensor, for its report."""
    everything = list(range(n_rows))
    if widened == everything and not kept:
        return "widened"
    if not kept and not widened:
        return "copied" if same_shape else "inputs mapped"
    parts = [f"kept rows {kept}"] if kept else []
    widened_only = [row for row in widened if row not in kept]
    if widened_only:
        parts.append("widened" if widened == everything else f"widened rows {widened_only}")
    return ", ".join(parts + ([] if widened else ["copied"]))


def _map_observation(weight: torch.Tensor, target: torch.Tensor, columns: list[int | None], old: int):
    """``weight`` reshaped to ``target``'s shape along the axis where the two differ by the observations'
    difference (its first ``old`` entries the observation's, mapped by ``columns``, the rest kept); ``weight``
    itself where the shapes agree; ``None`` where they differ otherwise."""
    if weight.shape == target.shape:
        return weight
    new = len(columns)
    differing = [axis for axis in range(weight.ndim) if weight.shape[axis] != target.shape[axis]]
    axis = differing[0]
    if len(differing) > 1 or weight.shape[axis] - old != target.shape[axis] - new or weight.shape[axis] < old:
        return None
    mapped = torch.zeros_like(target).movedim(axis, 0)
    source = weight.movedim(axis, 0)
    for j, i in enumerate(columns):
        if i is not None:
            mapped[j] = source[i]
    mapped[new:] = source[old:]
    return mapped.movedim(0, axis).contiguous()
