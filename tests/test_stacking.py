"""Seed stacking (pamdp.algos.stacking): stacked seeds train as they would alone, save alone, and fail alone."""

import csv
import dataclasses

import pytest
import torch

from pamdp import PADDPG, PATRPO
from pamdp.algos.paddpg import PADDPGConfig
from pamdp.algos.pasvg import PASVG0, PASVG0Config
from pamdp.algos.stacking import ALIGNED_STEPS, SeedStack, clip_per_member, step_class
from pamdp.experiments.runner import RunSpec, group_jobs, train_stack

TINY = PADDPGConfig(hidden_sizes=(16, 8), learning_starts=100, epoch_steps=300, num_envs=4, batch_size=16)


def tiny(seed, **changes):
    return PADDPG("pamdp/Platform-v0", dataclasses.replace(TINY, seed=seed, **changes))


def trained_together(members, steps):
    def job(m):
        def run(leave):
            m.learn(steps, progress_bar=False)
            leave()
            return m.num_timesteps

        return run

    stack = SeedStack(members)
    outcomes = stack.run([job(m) for m in members])
    return stack, outcomes


def max_difference(a, b):
    return max(
        (p - q).abs().max().item()
        for name in a._modules()
        for p, q in zip(a._modules()[name].parameters(), b._modules()[name].parameters())
    )


@pytest.mark.parametrize("bound", ["invert", "squash"])
def test_stacked_seeds_train_as_they_would_alone(bound):
    seeds = range(3 if bound == "invert" else 2)
    alone = [tiny(seed, bound=bound).learn(600, progress_bar=False) for seed in seeds]
    members = [tiny(seed, bound=bound) for seed in seeds]
    stack, outcomes = trained_together(members, 600)
    assert outcomes == [m.num_timesteps for m in alone]  # the same env steps: same actions all along
    assert stack.rounds >= 450
    for a, m in zip(alone, members):
        # the same batches and updates; only batched products round differently from single ones
        assert max_difference(a, m) < 1e-4
        assert (
            m.critic_optimizer.state_dict()["state"][0]["step"] == a.critic_optimizer.state_dict()["state"][0]["step"]
        )
        assert m.epoch == a.epoch and m.replay.added == a.replay.added
        # once out of the stack, its tensors are its own again
        assert all(p.untyped_storage().nbytes() == p.nbytes for p in m.actor.parameters())


def test_a_stack_learns_as_its_members_would_and_again_only_when_their_steps_align(tmp_path, monkeypatch):
    alone = [tiny(seed).learn(600, progress_bar=False) for seed in range(2)]
    members = [tiny(seed) for seed in range(2)]
    stack = SeedStack(members)
    assert stack.learn(600, run_dirs=[tmp_path / "a", tmp_path / "b"]) == members
    for a, m in zip(alone, members):
        assert m.num_timesteps == a.num_timesteps and max_difference(a, m) < 1e-4
    assert (tmp_path / "b" / "checkpoint.pt").exists()
    with pytest.raises(ValueError, match="1 run_dirs for 2 members"):
        stack.learn(300, run_dirs=[tmp_path / "a"])
    # the members left the stack at different updates: a second part would change one's Adam bias correction
    assert len({m.critic_optimizer.state_dict()["state"][0]["step"].item() for m in members}) == 2
    with pytest.raises(ValueError, match="members at Adam steps"):
        stack.learn(300)
    monkeypatch.setattr("pamdp.algos.stacking.ALIGNED_STEPS", 0)  # as if past it: the stack runs again
    stack.learn(300)
    assert all(m.num_timesteps >= 900 for m in members)


@pytest.mark.parametrize("discrete_gradient", ["gumbel", "expected"])
def test_stacked_pasvg0_seeds_train_as_they_would_alone(discrete_gradient):
    config = PASVG0Config(
        hidden_sizes=(16, 8),
        learning_starts=100,
        epoch_steps=300,
        num_envs=4,
        batch_size=16,
        discrete_gradient=discrete_gradient,
        entropy_coef=0.05,
        explore_epsilon=0.1,  # draws from the same torch generator as the update's noise
    )

    def run(seed):
        return PASVG0("pamdp/Platform-v0", dataclasses.replace(config, seed=seed))

    alone = [run(seed).learn(600, progress_bar=False) for seed in range(2)]
    members = [run(seed) for seed in range(2)]
    _, outcomes = trained_together(members, 600)
    assert outcomes == [m.num_timesteps for m in alone]
    for a, m in zip(alone, members):
        assert max_difference(a, m) < 1e-4
        assert m.critic_updates == a.critic_updates > 400
        assert torch.equal(m.torch_gen.get_state(), a.torch_gen.get_state())  # the same noise drawn


def test_a_stacked_member_saves_its_own_weights_and_optimiser_state(tmp_path):
    members = [tiny(seed) for seed in range(2)]
    saved = {}

    def job(m):
        def run(leave):
            m.learn(600, progress_bar=False)
            m.save(tmp_path / f"seed{m.config.seed}.pt")  # while still in the stack: its tensors are views
            saved[m.config.seed] = {k: v.clone() for k, v in m.actor.state_dict().items()}
            leave()

        return run

    SeedStack(members).run([job(m) for m in members])
    alone = tiny(0).learn(600, progress_bar=False)
    alone.save(tmp_path / "alone.pt")
    # a file holds one seed's tensors, not the whole stack's
    assert (tmp_path / "seed0.pt").stat().st_size < 1.2 * (tmp_path / "alone.pt").stat().st_size
    loaded = PADDPG.load(tmp_path / "seed1.pt")
    for k, v in loaded.actor.state_dict().items():
        assert torch.equal(v, saved[1][k])
    state = loaded.critic_optimizer.state_dict()["state"]
    assert state[0]["exp_avg"].shape == loaded.critic.net[0].weight.shape and state[0]["exp_avg"].abs().sum() > 0


def test_clipping_per_member_is_each_members_own_clip_grad_norm():
    gen = torch.Generator().manual_seed(0)
    stacked = [
        torch.randn(3, 4, 5, generator=gen, requires_grad=True),
        torch.randn(3, 5, generator=gen, requires_grad=True),
    ]
    for p, scale in zip(stacked, (10.0, 0.1)):
        p.grad = torch.randn(p.shape, generator=gen) * scale
    member_grads = [[p.grad[j].clone() for p in stacked] for j in range(3)]
    member_grads[1] = [g * 1e-3 for g in member_grads[1]]  # a member below the threshold keeps its gradient
    for p in stacked:
        p.grad[1] *= 1e-3
    clip_per_member([p.grad for p in stacked], 1.0)
    for j, grads in enumerate(member_grads):
        params = [torch.zeros_like(g, requires_grad=True) for g in grads]
        for p, g in zip(params, grads):
            p.grad = g
        torch.nn.utils.clip_grad_norm_(params, 1.0)
        for p, s in zip(params, stacked):
            torch.testing.assert_close(s.grad[j], p.grad)
    norm1 = torch.linalg.vector_norm(torch.cat([p.grad[1].flatten() for p in stacked]))
    assert norm1 < 0.1  # untouched


def test_a_stack_refuses_what_it_cannot_batch():
    with pytest.raises(ValueError, match="differ in their seed only; they differ in batch_size"):
        SeedStack([tiny(0), tiny(1, batch_size=8)])
    with pytest.raises(ValueError, match="PASVG0 cannot stack seeds with target_entropy"):
        SeedStack([PASVG0("pamdp/Platform-v0", PASVG0Config.preset("tuned"))])
    with pytest.raises(ValueError, match="PATRPO does not support seed stacking"):
        SeedStack([PATRPO("pamdp/Platform-v0", {"hidden_sizes": (8,)})])
    resumed = [tiny(seed) for seed in range(2)]
    for m, step in zip(resumed, (500, 700)):  # as if resumed from checkpoints written at different updates
        m.learn(300, progress_bar=False)
        m._update()
        for opt in m._optimizers().values():
            for state in opt.state.values():
                state["step"].fill_(step)
    with pytest.raises(ValueError, match=r"Adam steps \[500, 700\]"):
        SeedStack(resumed)
    assert step_class(resumed[0]) == 500
    for opt in resumed[0]._optimizers().values():
        for state in opt.state.values():
            state["step"].fill_(ALIGNED_STEPS)
    assert step_class(resumed[0]) == -1  # past it, Adam's bias corrections are 1 to float precision


def test_a_failing_member_fails_alone():
    members = [tiny(seed) for seed in range(3)]

    def job(m):
        def run(leave):
            if m.config.seed == 1:
                m.learn(300, progress_bar=False)
                raise RuntimeError("disk full")
            m.learn(600, progress_bar=False)
            return m.num_timesteps

        return run

    outcomes = SeedStack(members).run([job(m) for m in members])
    assert isinstance(outcomes[1], RuntimeError) and str(outcomes[1]) == "disk full"
    assert outcomes[0] >= 600 and outcomes[2] >= 600


def test_jobs_are_grouped_by_setting_evenly_and_in_order():
    def spec(algo, seed, **settings):
        return (RunSpec(algo, "pamdp/Platform-v0", 1000, seed, settings=tuple(settings.items())), f"{algo}{seed}")

    jobs = [spec("patrpo", s) for s in range(2)] + [spec("paddpg", s) for s in range(5)]
    jobs += [spec("paddpg", s, tau=0.01) for s in range(2)]
    jobs += [(RunSpec("pasvg0", "pamdp/Platform-v0", 1000, s, preset="tuned"), f"tuned{s}") for s in range(2)]
    groups = [[out for _, out in g] for g in group_jobs(jobs, 3)]
    assert groups == [
        ["patrpo0"],
        ["patrpo1"],
        ["paddpg0", "paddpg1", "paddpg2"],
        ["paddpg3", "paddpg4"],
        ["paddpg0", "paddpg1"],
        ["tuned0"],  # settings a stack cannot take run alone
        ["tuned1"],
    ]
    assert all(len(g) == 1 for g in group_jobs(jobs, 1))
    with pytest.raises(ValueError, match="stack = 0; expected an integer >= 1"):
        group_jobs(jobs, 0)


def test_runs_resumed_at_different_steps_train_in_stacks_of_their_own(tmp_path):
    settings = tuple({"hidden_sizes": (16,), "learning_starts": 100, "epoch_steps": 300, "num_envs": 4}.items())

    def spec(seed, steps):
        return RunSpec("paddpg", "pamdp/Platform-v0", steps, seed, preset="paper", settings=settings, eval_episodes=5)

    outs = [tmp_path / f"seed{s}" for s in range(3)]
    logs = {s: [] for s in range(3)}
    first = train_stack([spec(0, 600)], [outs[0]], [logs[0].append])  # seed 0 resumes, seeds 1 and 2 start
    assert "mean_return" in first[0]
    (outs[0] / "final_model.pt").unlink()
    results = train_stack([spec(s, 900) for s in range(3)], outs, [logs[s].append for s in range(3)])
    assert all("mean_return" in r for r in results), results
    assert any("stack of its own" in line for line in logs[0])
    assert any("stacked with seeds [1, 2]" in line for line in logs[1])
    for s in range(3):
        assert PADDPG.load(outs[s] / "final_model.pt").num_timesteps >= 900
    # The process's CPU time is divided among the runs training in it, three at seed 1's first epoch. Undivided
    # it would exceed the wall time: torch ops release the GIL, so the stack's threads use up to ~2 cores.
    with open(outs[1] / "progress.csv", newline="") as f:
        first_epoch = next(csv.DictReader(f))
    assert float(first_epoch["time/epoch_cpu_seconds"]) < float(first_epoch["time/epoch_seconds"])


def test_a_stack_that_fails_as_a_whole_fails_each_of_its_runs(tmp_path, monkeypatch):
    def broken(self, jobs):
        raise RuntimeError("stack broke")

    monkeypatch.setattr(SeedStack, "run", broken)
    spec = RunSpec("paddpg", "pamdp/Platform-v0", 300, 0, preset="paper", settings=(("hidden_sizes", (8,)),))
    specs = [dataclasses.replace(spec, seed=s) for s in range(2)]
    results = train_stack(specs, [tmp_path / "a", tmp_path / "b"], [print, print])
    assert all(isinstance(r, RuntimeError) and str(r) == "stack broke" for r in results)  # not reported as done


def test_stacked_updates_flush_subnormals_as_the_members_learn_would(monkeypatch):
    """The stacked update runs in the stack's own thread, outside the members' learn(); it flushes subnormals
    (``flush_denormal``) all the same, and the thread gets IEEE subnormals back afterwards."""
    subnormal = torch.tensor(1e-39, dtype=torch.float32)  # subnormal in float32
    seen = []
    stacked_update = PADDPG._stacked_update.__func__

    def spy(cls, stack, batch):
        seen.append(float(subnormal * 1.5))
        return stacked_update(cls, stack, batch)

    monkeypatch.setattr(PADDPG, "_stacked_update", classmethod(spy))
    trained_together([tiny(0), tiny(1)], 300)
    assert seen and set(seen) == {0.0}
    assert float(subnormal * 1.5) == pytest.approx(1.5e-39)
