"""Seed stacking: several seeds of one off-policy setting trained in one process, their updates done as one.

At PADDPG's batch of 32 an update is a string of small matrix products, each paying more in per-call overhead
than in arithmetic. With the weights of S seeds stacked along a new leading axis, each product becomes one
batched product over the S seeds (``baddbmm``) and each optimiser step one fused call: three seeds stacked per
process give 1.4x to 1.6x the seed-updates per second of one seed per process (``benchmarks/seed_batching.md``).

Every member stays a run of its own:

- each member is an ordinary algorithm object, with its own env, replay buffer, random streams, logs and
  checkpoints, and runs its own :meth:`~pamdp.algos.base.Algorithm.learn` in a thread of its own;
- its parameters, its target networks' and its optimisers' moments are *views* into the stacked tensors, so it
  acts with, and saves, its own current weights;
- its update is replaced by a request: it draws its batch from its own buffer with its own generator, exactly
  as alone, and waits. When every member still training is waiting, one stacked update serves them all. A
  member's sequence of env steps, batches and updates is therefore the one it has alone; its numbers differ
  from a solo run's only by the rounding of batched against single products;
- a member that finishes leaves: its tensors become its own again and the stack is rebuilt from the others.

All members share one Adam step count. Fresh members have the same; members resumed from checkpoints written
at different updates do not, and are stacked only when every count is past :data:`ALIGNED_STEPS`, where Adam's
bias corrections equal 1 to float precision, so taking the largest changes nothing (:class:`SeedStack` refuses
others; :func:`step_class` sorts members into those that can share a stack).

An algorithm supports stacking by defining ``_stack_sample(self) -> batch`` (a dict of tensors: what its update
draws from its own random streams) and the class method ``_stacked_update(stack, batch) -> list of per-member
stats``, where ``batch`` holds the members' batches stacked on a new first axis; optionally the class method
``_stack_refusal(config) -> str | None`` names settings it cannot stack. See :class:`~pamdp.algos.paddpg.PADDPG`
and :class:`~pamdp.algos.pasvg.PASVG0`.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from typing import Any

import torch
from torch import nn

from pamdp.algos.dense import Dense
from pamdp.algos.offpolicy import optimizer_step
from pamdp.algos.subnormals import subnormals_flushed

__all__ = ["SeedStack", "can_stack", "ALIGNED_STEPS", "adam_step", "step_class", "clip_per_member"]

# Adam's bias corrections 1 - beta^t equal 1 in float32 once beta2^t < 2^-24: t > 16 600 for beta2 = 0.999.
ALIGNED_STEPS = 20_000


def can_stack(algo_class) -> bool:
    """Whether an algorithm class supports seed stacking."""
    return hasattr(algo_class, "_stacked_update") and hasattr(algo_class, "_stack_sample")


def adam_step(member) -> int:
    """The step count of a member's Adam optimisers (0 before its first update)."""
    for opt in member._optimizers().values():
        for state in opt.state.values():
            if "step" in state:
                return int(state["step"])
    return 0


def step_class(member) -> int:
    """Members of the same class can share a stack: their Adam step, or -1 for every step past ALIGNED_STEPS."""
    step = adam_step(member)
    return -1 if step >= ALIGNED_STEPS else step


def _check_steps(members: Sequence[Any]) -> None:
    steps = [adam_step(m) for m in members]
    if len(set(steps)) > 1 and min(steps) < ALIGNED_STEPS:
        raise ValueError(
            f"members at Adam steps {steps}: stacking shares one step count, which differing counts below "
            f"{ALIGNED_STEPS} would change; train them alone until they pass it"
        )


def clip_per_member(grads: Sequence[torch.Tensor | None], max_norm: float) -> None:
    """``clip_grad_norm_`` applied to each member's slice of stacked gradients on its own (0: no clipping).

    ``grads`` are the gradient tensors themselves (``None`` entries are skipped)."""
    if max_norm <= 0:
        return
    grads = [g for g in grads if g is not None]
    if not grads:
        return
    norms = torch.stack([torch.linalg.vector_norm(g.flatten(1), dim=1) for g in grads])  # (tensors, S)
    total = torch.linalg.vector_norm(norms, dim=0)
    coef = (max_norm / (total + 1e-6)).clamp(max=1.0)  # the formula of torch.nn.utils.clip_grad_norm_
    for g in grads:
        g.mul_(coef.view(-1, *([1] * (g.dim() - 1))))


class SeedStack:
    """Train ``members`` (same algorithm, same settings but the seed) together; see the module docstring.

    :meth:`learn` trains every member for the same number of steps, as each one's own ``learn`` would (once:
    members leave a stack at different updates, so a second call needs their Adam steps past
    :data:`ALIGNED_STEPS`, or it says so)::

        models = [PADDPG("pamdp/Platform-v0", {"seed": seed}) for seed in range(3)]
        SeedStack(models).learn(100_000, run_dirs=[f"runs/seed{seed}" for seed in range(3)])

    :meth:`run` takes one job per member instead: the job trains its member (``learn`` and whatever follows,
    such as saving and evaluating) and returns a result.
    """

    def __init__(self, members: Sequence[Any]):
        if not members:
            raise ValueError("a seed stack needs at least one member")
        cls = type(members[0])
        if not can_stack(cls):
            raise ValueError(f"{cls.__name__} does not support seed stacking")
        refusal = cls._stack_refusal(members[0].config) if hasattr(cls, "_stack_refusal") else None
        if refusal:
            raise ValueError(f"{cls.__name__} cannot stack seeds with {refusal}")
        if any(type(m) is not cls for m in members):
            raise ValueError(f"a seed stack holds one algorithm; got {sorted({type(m).__name__ for m in members})}")
        base = {k: v for k, v in members[0].config.to_dict().items() if k != "seed"}
        for m in members[1:]:
            other = {k: v for k, v in m.config.to_dict().items() if k != "seed"}
            differ = sorted(k for k in base if base[k] != other.get(k))
            if differ:
                raise ValueError(f"stacked members must differ in their seed only; they differ in {', '.join(differ)}")
        _check_steps(members)
        self.members = list(members)
        self.config = members[0].config
        self._cond = threading.Condition()
        self._requests: dict[int, dict] = {}
        self._results: dict[int, Any] = {}
        self._leaving: list[int] = []
        self._left: set[int] = set()
        self._running = 0
        self.active: list[int] = []
        self.params: dict[str, dict[str, torch.Tensor]] = {}
        self.optimizers: dict[str, torch.optim.Optimizer] = {}
        self.rounds = 0

    # -- the stacked tensors ------------------------------------------------------------------------------
    def _build(self) -> None:
        """Stack the active members' tensors and make theirs views of the stack."""
        members = [self.members[i] for i in self.active]
        if not members:
            self.params, self.optimizers = {}, {}
            return
        stacked: dict[int, torch.Tensor] = {}  # id of member 0's parameter -> its stacked tensor
        flip: dict[int, bool] = {}  # whether a parameter is stored transposed in the stack
        self.params = {}
        for name, module in members[0]._modules().items():
            own = {}
            for pname, p in module.named_parameters():
                # A linear layer's weight is stacked as (S, in, out): the forward product needs no transpose
                # and its gradient comes out in the layout of the stack (no copy into the .grad).
                owner = module.get_submodule(pname.rpartition(".")[0]) if "." in pname else module
                t = isinstance(owner, nn.Linear) and pname.endswith("weight")
                views = [m._modules()[name].get_parameter(pname) for m in members]
                s = torch.stack([_t(v.detach(), t) for v in views]).requires_grad_(p.requires_grad)
                for j, v in enumerate(views):
                    v.data = _t(s[j], t)
                own[pname] = stacked[id(p)] = s
                flip[id(p)] = t
            self.params[name] = own
        self.optimizers = {}
        for name, opt in members[0]._optimizers().items():
            opts = [m._optimizers()[name] for m in members]
            group = opt.param_groups[0]
            if len(opt.param_groups) != 1:
                raise ValueError("seed stacking supports optimisers with one parameter group")
            stacks = [stacked[id(p)] for p in group["params"]]
            kwargs = {k: v for k, v in group.items() if k not in ("params", "initial_lr")}
            new = type(opt)(stacks, **kwargs)
            step = max(adam_step(m) for m in members)
            for k, s in enumerate(stacks):
                t = flip[id(group["params"][k])]
                member_params = [o.param_groups[0]["params"][k] for o in opts]
                states = [o.state.get(p, {}) for o, p in zip(opts, member_params)]
                state = {"step": torch.tensor(float(step), dtype=torch.float32)}
                for key in ("exp_avg", "exp_avg_sq"):
                    state[key] = torch.stack(
                        [_t(st[key] if key in st else torch.zeros_like(p), t) for st, p in zip(states, member_params)]
                    )
                new.state[s] = state
                for j, (o, p) in enumerate(zip(opts, member_params)):
                    o.state[p] = {
                        "step": state["step"],
                        "exp_avg": _t(state["exp_avg"][j], t),
                        "exp_avg_sq": _t(state["exp_avg_sq"][j], t),
                    }
            self.optimizers[name] = new

    @staticmethod
    def _detach(member) -> None:
        """Give a member's tensors storage of their own (it leaves the stack)."""
        with torch.no_grad():
            for module in member._modules().values():
                for p in module.parameters():
                    p.data = p.data.clone(memory_format=torch.contiguous_format)
            for opt in member._optimizers().values():
                for p, state in list(opt.state.items()):
                    opt.state[p] = {k: v.clone(memory_format=torch.contiguous_format) for k, v in state.items()}

    def sequential(self, module: str, path: str, x: torch.Tensor) -> torch.Tensor:
        """The members' ``nn.Sequential`` at ``module.path`` on inputs ``x`` of shape ``(S, ..., in)``.

        Linear layers become batched products over the members' stacked weights; parameter-free layers
        (activations) are applied as they are.
        """
        template = self.members[self.active[0]]._modules()[module].get_submodule(path)
        params = self.params[module]
        shape = x.shape[:-1]
        x = x.reshape(shape[0], -1, x.shape[-1])
        for k, layer in template.named_children():
            if isinstance(layer, nn.Linear):
                w, b = params[f"{path}.{k}.weight"], params[f"{path}.{k}.bias"]
                x = torch.baddbmm(b.unsqueeze(1), x, w)  # w stacked as (S, in, out)
            elif next(layer.parameters(), None) is None:
                x = layer(x)
            else:
                raise ValueError(f"seed stacking cannot batch a {type(layer).__name__} layer")
        return x.reshape(*shape, x.shape[-1])

    def dense(self, module: str, path: str) -> Dense:
        """The members' ``nn.Sequential`` at ``module.path`` as one :class:`~pamdp.algos.dense.Dense` over the
        stacked ``(S, in, out)`` weights, for updates that back-propagate by hand."""
        template = self.members[self.active[0]]._modules()[module].get_submodule(path)
        return Dense.of_stack(template, self.params[module], path)

    def gradient_step(self, name: str, max_norm: float) -> Callable[[Sequence[torch.Tensor]], None]:
        """:func:`~pamdp.algos.offpolicy.gradient_step` for the stacked optimizer ``name``: each member's slice
        of the hand-computed gradients clipped on its own (:func:`clip_per_member`), then one fused step."""

        def step(grads: Sequence[torch.Tensor]) -> None:
            clip_per_member(grads, max_norm)
            optimizer_step(self.optimizers[name], grads)

        return step

    def members_active(self) -> list[Any]:
        """The members in the stack, in the order of its leading axis."""
        return [self.members[i] for i in self.active]

    def buffer(self, module: str, name: str) -> torch.Tensor:
        """A buffer of the members' ``module`` (the same in every member: masks, index tables)."""
        return self.members[self.active[0]]._modules()[module].get_buffer(name)

    def soft_update(self, target: str, source: str, tau: float) -> None:
        with torch.no_grad():
            names = list(self.params[source])
            torch._foreach_lerp_([self.params[target][n] for n in names], [self.params[source][n] for n in names], tau)

    # -- running ------------------------------------------------------------------------------------------
    def _request(self, i: int) -> Callable[[], dict[str, float]]:
        member = self.members[i]

        def update() -> dict[str, float]:
            batch = member._stack_sample()
            with self._cond:
                self._requests[i] = batch
                self._running -= 1
                self._cond.notify_all()
                self._cond.wait_for(lambda: i in self._results)
                result = self._results.pop(i)
            if isinstance(result, BaseException):
                raise result
            return result

        return update

    def _leave(self, i: int) -> None:
        with self._cond:
            if i in self._left or i in self._leaving:
                return
            self._leaving.append(i)
            self._running -= 1
            self._cond.notify_all()
            self._cond.wait_for(lambda: i in self._left)

    def learn(self, total_timesteps: int, run_dirs: Sequence[Any] | None = None, **learn_kwargs) -> list[Any]:
        """``member.learn(total_timesteps, run_dir=run_dirs[i], **learn_kwargs)`` for every member, stacked.

        No progress bars (several threads would mix them). Returns the members; the first member's error, if
        any, is raised once every member has stopped.
        """
        if run_dirs is not None and len(run_dirs) != len(self.members):
            raise ValueError(f"{len(run_dirs)} run_dirs for {len(self.members)} members")
        learn_kwargs["progress_bar"] = False

        def job(i: int) -> Callable[[Callable[[], None]], Any]:
            def train(leave: Callable[[], None]) -> Any:
                run_dir = None if run_dirs is None else run_dirs[i]
                return self.members[i].learn(total_timesteps, run_dir=run_dir, **learn_kwargs)

            return train

        outcomes = self.run([job(i) for i in range(len(self.members))])
        for outcome in outcomes:
            if isinstance(outcome, BaseException):
                raise outcome
        return outcomes

    def run(self, jobs: Sequence[Callable[[Callable[[], None]], Any]]) -> list[Any]:
        """Run ``jobs[i](leave)``, member ``i``'s training, in a thread each; returns each job's result or exception.

        A job calls ``leave()`` once its member's training is over (after ``learn``), so the others go on
        without it while it saves or evaluates; a job that does not is taken out when it returns.
        """
        if len(jobs) != len(self.members):
            raise ValueError(f"{len(jobs)} jobs for {len(self.members)} members")
        _check_steps(self.members)  # members that left the stack one by one last time have differing counts
        outcomes: list[Any] = [None] * len(jobs)
        self._requests, self._results, self._leaving, self._left = {}, {}, [], set()  # a stack can run again
        self.active = list(range(len(self.members)))
        self._build()
        for i in self.active:
            self.members[i]._update = self._request(i)

        def body(i: int) -> None:
            try:
                outcomes[i] = jobs[i](lambda: self._leave(i))
            except BaseException as exc:  # noqa: BLE001 - reported to the caller, member by member
                outcomes[i] = exc
            finally:
                self._leave(i)  # a no-op for a member whose job has already left

        threads = [threading.Thread(target=body, args=(i,), name=f"member{i}", daemon=True) for i in self.active]
        self._running = len(threads)
        for t in threads:
            t.start()
        # the stacked updates run in this thread, not in the members' learn(): flush as they would
        with subnormals_flushed(any(m.config.flush_denormal for m in self.members)):
            while True:
                with self._cond:
                    self._cond.wait_for(lambda: self._running == 0)
                    if self._leaving:
                        for i in self._leaving:
                            self.members[i].__dict__.pop("_update", None)
                            self._detach(self.members[i])
                            self.active.remove(i)
                        self._build()
                        self._left.update(self._leaving)
                        self._leaving.clear()
                    if not self.active:
                        self._cond.notify_all()
                        break
                    if len(self._requests) == len(self.active):
                        order = list(self.active)
                        batches = [self._requests.pop(i) for i in order]
                        try:
                            stats = type(self.members[order[0]])._stacked_update(self, _stack(batches))
                        except BaseException as exc:  # noqa: BLE001 - every waiting member raises it
                            stats = [exc] * len(order)
                        self.rounds += 1
                        self._results.update(zip(order, stats))
                        self._running = len(order)
                    self._cond.notify_all()
        for t in threads:
            t.join()
        return outcomes


def _t(x: torch.Tensor, transpose: bool) -> torch.Tensor:
    return x.transpose(-1, -2) if transpose else x


def _stack(batches: list[dict[str, torch.Tensor]]) -> dict[str, torch.Tensor]:
    return {k: torch.stack([b[k] for b in batches]) for k in batches[0]}
