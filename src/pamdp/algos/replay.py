"""The replay buffer shared by the off-policy algorithms: one preallocated tensor per field on the algorithm's
device, written as a ring. Why on the device, and what it costs in memory: docs/algorithms.md, "The off-policy
family"; what a checkpoint keeps of it (``state_dict(include_data=...)``): "Checkpoints and resuming".
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import torch

__all__ = ["ReplayBuffer", "transition_fields"]

FieldSpec = Mapping[str, tuple[tuple[int, ...], type | np.dtype]]


def transition_fields(obs_dim: int, max_param_size: int, mc_returns: bool = False, masks: int = 0, **extra) -> dict:
    """The fields every off-policy algorithm stores, ``obs, a, x, reward, next_obs, terminated``, then ``extra``.

    ``x`` holds the chosen action's parameters, padded to ``max_param_size``. With ``mc_returns`` a field
    ``"mc"`` holds the Monte-Carlo return-to-go, NaN until the episode ends (PADDPG's and P-DQN's mixed
    targets, filled by :class:`pamdp.algos.offpolicy.OffPolicyLoop`). With ``masks = K`` (the number of discrete
    actions) the fields ``"mask"`` and ``"next_mask"`` hold which actions the env allowed at ``obs`` and at
    ``next_obs`` (bool ``(K,)``, from ``info["action_mask"]``), for the ``action_mask`` setting.
    """
    fields = {
        "obs": ((obs_dim,), np.float32),
        "a": ((), np.int64),
        "x": ((max_param_size,), np.float32),
        "reward": ((), np.float32),
        "next_obs": ((obs_dim,), np.float32),
        "terminated": ((), np.bool_),
        **extra,
    }
    if mc_returns:
        fields["mc"] = ((), np.float32)
    if masks:
        fields["mask"] = fields["next_mask"] = ((masks,), np.bool_)
    return fields


class ReplayBuffer:
    """A ring buffer of transitions in preallocated tensors on one device.

    Args:
        capacity: the most transitions held; older ones are overwritten.
        fields: name -> (shape of one item, NumPy dtype).
        device: where the contents live and :meth:`sample`'s batches are drawn (the algorithm's device).
    """

    def __init__(self, capacity: int, fields: FieldSpec, device: torch.device | str = "cpu"):
        if capacity < 1:
            raise ValueError(f"capacity = {capacity!r}; expected an integer >= 1")
        if not fields:
            raise ValueError("a replay buffer needs at least one field")
        self.capacity = int(capacity)
        self.device = torch.device(device)
        self.fields = {name: (tuple(shape), np.dtype(dtype)) for name, (shape, dtype) in fields.items()}
        self.data = {
            name: torch.empty((self.capacity, *shape), dtype=_torch_dtype(dtype), device=self.device)
            for name, (shape, dtype) in self.fields.items()
        }
        # On the CPU, NumPy views of the same memory do the indexing: for the few rows of a step or a minibatch,
        # torch's per-call overhead would cost more than the copy itself.
        self._host = {name: t.numpy() for name, t in self.data.items()} if self.device.type == "cpu" else None
        self.added = 0  # transitions ever added; the next one goes to slot added % capacity

    def __len__(self) -> int:
        return min(self.added, self.capacity)

    def _rows(self, name: str, value, n: int) -> np.ndarray:
        value = np.asarray(value)
        if len(value) != n:
            raise ValueError(f"field {name!r} has {len(value)} rows; expected {n}")
        return value.reshape((n, *self.fields[name][0]))

    def _put(self, name: str, counters: np.ndarray, rows: np.ndarray) -> None:
        slots = np.asarray(counters, dtype=np.int64) % self.capacity
        if self._host is not None:
            self._host[name][slots] = rows
        else:
            rows = torch.from_numpy(np.ascontiguousarray(rows, self.fields[name][1]))
            self.data[name][torch.from_numpy(slots).to(self.device)] = rows.to(self.device)

    def add(self, **batch: np.ndarray) -> np.ndarray:
        """Append a batch (every field, same leading length ``n``); returns the insertion counters used.

        The counter ``c`` of a transition locates it (slot ``c % capacity``) for as long as
        :meth:`holds` says it has not been overwritten.
        """
        if set(batch) != set(self.fields):
            raise ValueError(f"add() got fields {sorted(batch)}; expected {sorted(self.fields)}")
        n = len(next(iter(batch.values())))
        if n > self.capacity:  # only the last `capacity` would survive anyway
            batch = {k: np.asarray(v)[-self.capacity :] for k, v in batch.items()}
            self.added += n - self.capacity
            n = self.capacity
        counters = np.arange(self.added, self.added + n)
        rows = {name: self._rows(name, value, n) for name, value in batch.items()}  # all checked before any write
        for name, value in rows.items():
            self._put(name, counters, value)
        self.added += n
        return counters

    def holds(self, counters: np.ndarray) -> np.ndarray:
        """Which insertion counters still refer to their own transition (not yet overwritten)."""
        return np.asarray(counters) >= self.added - self.capacity

    def write(self, name: str, counters: np.ndarray, values: np.ndarray) -> None:
        """Set field ``name`` of already stored transitions, skipping any that have been overwritten."""
        counters, values = np.asarray(counters), np.asarray(values)
        keep = self.holds(counters)
        self._put(name, counters[keep], self._rows(name, values[keep], int(keep.sum())))

    def sample(self, batch_size: int, rng: np.random.Generator, first: int = 0) -> dict[str, torch.Tensor]:
        """``batch_size`` transitions drawn uniformly with replacement, as tensors on :attr:`device` sharing no memory
        with the buffer (the indices come from ``rng``, so a seeded run draws the same batches on any device).

        ``first`` (an insertion counter, as :meth:`add` returns) restricts the draw to the transitions added since
        it that are still held: a window of the newest, or the data after a warm-up, without a second buffer.
        """
        oldest = self.added - len(self)
        if first > oldest:
            if first >= self.added:
                raise ValueError(
                    f"first = {first!r}: no transition added since it (the buffer has added {self.added}); "
                    f"expected first < {self.added}"
                )
            slots = rng.integers(first, self.added, size=batch_size) % self.capacity
            return self._gather(slots)
        if len(self) == 0:
            raise ValueError("cannot sample from an empty replay buffer")
        return self._gather(rng.integers(0, len(self), size=batch_size))

    def _gather(self, idx: np.ndarray) -> dict[str, torch.Tensor]:
        """The rows at slots ``idx``, copied out of the buffer onto its device."""
        if self._host is not None:
            return {name: torch.from_numpy(arr[idx]) for name, arr in self._host.items()}
        idx = torch.from_numpy(idx).to(self.device)
        return {name: tensor[idx] for name, tensor in self.data.items()}

    # -- checkpoints ------------------------------------------------------------------------------
    def state_dict(self, include_data: bool) -> dict:
        """Plain data for a checkpoint (on the CPU); the contents only with ``include_data`` (they can be
        gigabytes)."""
        state: dict = {"added": self.added, "has_data": bool(include_data)}
        if include_data:
            n = len(self)
            state["data"] = {name: tensor[:n].cpu().clone() for name, tensor in self.data.items()}
        return state

    def load_state_dict(self, state: dict) -> None:
        """Restore contents saved with ``include_data``; otherwise leave the buffer empty (to be refilled)."""
        if not state.get("has_data"):
            self.added = 0
            return
        n = None
        for name, tensor in state["data"].items():
            if name not in self.data:
                raise ValueError(f"replay state has unknown field {name!r}")
            n = len(tensor)
            self.data[name][:n] = tensor.to(self.device, self.data[name].dtype)
        self.added = int(state["added"]) if n == self.capacity else int(n or 0)


def _torch_dtype(dtype) -> torch.dtype:
    """The torch dtype of a NumPy dtype (``np.bool_`` -> ``torch.bool``, ``np.float32`` -> ``torch.float32``)."""
    return torch.from_numpy(np.empty(0, dtype)).dtype
