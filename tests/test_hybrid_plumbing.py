"""Hybrid-action plumbing every algorithm relies on (issues 26, 27, 29): parameterless actions (zero-size
parameter boxes), boxes of different sizes, and the generic action masks (``info["action_mask"]``)."""

from __future__ import annotations

import math

import gymnasium
import numpy as np
import pytest
import torch
from conftest import small_config
from gymnasium import spaces

from pamdp.algos import ALGORITHMS, algorithm_class
from pamdp.algos.offpolicy import uniform_actions
from pamdp.distributions import MASKED, HybridDistribution, kl_divergence, masked_logits
from pamdp.envs.stepping import info_action_masks
from pamdp.policies import HybridPolicy
from pamdp.spaces import HybridActionSpace
from pamdp.wrappers import DiscretizeHybridAction, FlattenHybridAction

EMPTY = spaces.Box(np.zeros(0, np.float32), np.zeros(0, np.float32), dtype=np.float32)


class MaskedLine(gymnasium.Env):
    """A stand-in env with K = 3 actions of box sizes (2, 0, 1): MOVE(step, unused) moves along a line, WAIT (no
    parameters) stays, JUMP(length) jumps forward, and is allowed only left of the middle (``info["action_mask"]``).
    An episode succeeds (``is_success``) on reaching the target zone, else it is cut after 8 steps.

    It counts what it is handed: actions outside its action space, and masked actions chosen.
    """

    def __init__(self):
        self.observation_space = spaces.Box(-2.0, 2.0, (3,), np.float32)
        self.action_space = spaces.Tuple(
            (
                spaces.Discrete(3),
                spaces.Tuple(
                    (
                        spaces.Box(np.array([-1.0, -5.0], np.float32), np.array([1.0, 5.0], np.float32)),
                        EMPTY,
                        spaces.Box(np.array([0.0], np.float32), np.array([2.0], np.float32)),
                    )
                ),
            )
        )
        self.outside = self.masked_picks = self.steps = 0

    def _mask(self) -> np.ndarray:
        return np.array([True, True, self.pos < 0.0])

    def _obs(self) -> np.ndarray:
        return np.array([self.pos, self.t / 8.0, 1.0 if self.pos < 0.0 else -1.0], np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos, self.t = float(self.np_random.uniform(-1.5, 0.5)), 0
        return self._obs(), {"action_mask": self._mask()}

    def step(self, action):
        self.outside += not self.action_space.contains(action)
        a = int(action[0])
        self.masked_picks += not self._mask()[a]
        self.steps += 1
        if a == 0:
            self.pos += 0.3 * float(action[1][0][0])
        elif a == 2:
            self.pos += float(action[1][2][0])
        self.pos, self.t = float(np.clip(self.pos, -2.0, 2.0)), self.t + 1
        success = 0.4 < self.pos < 0.9
        reward = 1.0 if success else -0.1 * abs(self.pos - 0.65)
        truncated = not success and self.t >= 8
        info = {"action_mask": self._mask()}
        if success or truncated:
            info["is_success"] = success
        return self._obs(), reward, success, truncated, info


CASES = [(name, {}) for name in ALGORITHMS] + [
    ("patrpo", {"fvp": "double_backprop"}),
    ("pasvg0", {"discrete_gradient": "expected", "explore_epsilon": 0.2}),
    ("pdqn", {"multi_pass": True, "beta": 0.2, "explore_params": True}),
]


@pytest.mark.parametrize("action_mask", [True, False], ids=["masked", "unmasked"])
@pytest.mark.parametrize("name, extra", CASES, ids=[f"{n}-{'-'.join(map(str, e.values()))}" for n, e in CASES])
def test_every_algorithm_trains_on_boxes_of_sizes_2_0_1_and_honours_the_mask(name, extra, action_mask):
    cls = algorithm_class(name)
    if cls is None:
        pytest.skip(f"{name}'s module is not installed")
    envs = gymnasium.vector.SyncVectorEnv([MaskedLine for _ in range(4)])
    model = cls(envs, small_config(cls, action_mask=action_mask, **extra))
    model.learn(300, progress_bar=False)
    copies = envs.envs
    assert sum(e.outside for e in copies) == 0  # every action handed over lies in the env's action space
    picks = sum(e.masked_picks for e in copies)
    if action_mask:
        assert picks == 0, f"{name} chose a masked action {picks} times in {sum(e.steps for e in copies)} steps"
    else:  # the count can fail: without the setting JUMP is chosen where it is masked
        assert picks > 0

    probe = MaskedLine()
    for seed in range(20):
        obs, info = probe.reset(seed=seed)
        for deterministic in (True, False):
            act = model.predict(obs, deterministic, info["action_mask"] if action_mask else None)
            assert probe.action_space.contains(act)
            assert act[1][1].dtype == np.float32 and act[1][1].shape == (0,)
            assert info["action_mask"][act[0]] or not action_mask
    batch = np.stack([probe.reset(seed=s)[0] for s in range(6)])
    a, params = model.predict(batch, True, np.tile([True, True, False], (6, 1)))
    assert np.all(a != 2) and params[1].shape == (6, 0) and params[1].dtype == np.float32


def test_the_mask_changes_nothing_where_every_action_is_allowed():
    """A mask allowing everything (an env that reports none) acts as no mask, to the bit."""
    cls = algorithm_class("pdqn")
    obs = torch.randn(5, 3)
    model = cls(MaskedLine(), small_config(cls, action_mask=True))
    for deterministic in (True, False):
        model.np_rng = np.random.default_rng(1)
        plain = model._act(obs, deterministic)
        model.np_rng = np.random.default_rng(1)
        allowed = model._act(obs, deterministic, torch.ones(5, 3, dtype=torch.bool))
        if deterministic:  # an epsilon draw among all actions uses other numbers than rng.integers
            assert all(torch.equal(p, q) for p, q in zip(plain, allowed))


def test_an_env_whose_actions_are_all_parameterless_is_refused():
    class Buttons(MaskedLine):
        def __init__(self):
            super().__init__()
            self.action_space = spaces.Tuple((spaces.Discrete(2), spaces.Tuple((EMPTY, EMPTY))))

    for name in ALGORITHMS:
        cls = algorithm_class(name)
        if cls is not None:
            with pytest.raises(ValueError, match="no action has parameters"):
                cls(Buttons(), small_config(cls, action_mask=False))


def test_predict_refuses_a_mask_of_the_wrong_shape():
    cls = algorithm_class("patrpo")
    model = cls(MaskedLine(), small_config(cls, action_mask=True))
    with pytest.raises(ValueError, match=r"expected bool of shape \(3,\)"):
        model.predict(np.zeros(3), True, np.ones(2, dtype=bool))


# -- zero-size boxes: spaces, distributions, wrappers ------------------------------------------------------
def test_spaces_hand_a_parameterless_action_an_empty_float32_array():
    h = HybridActionSpace.from_gym(MaskedLine().action_space)
    assert h.param_sizes == (2, 0, 1) and h.max_param_size == 2 and h.total_param_size == 3
    a, params = h.to_env(1, np.array([0.7, -0.2]))
    assert a == 1 and params[1].dtype == np.float32 and params[1].shape == (0,)
    np.testing.assert_array_equal(params[0], [0.0, 0.0])  # the others get their box's centre
    np.testing.assert_array_equal(params[2], [1.0])
    a, params = h.to_env(2, np.array([0.5, 0.9]))
    np.testing.assert_allclose(params[2], [1.5])  # [-1, 1] -> [0, 2]; the padded entry is ignored
    assert h.from_env((2, params))[0] == 2
    np.testing.assert_allclose(h.from_env((2, params))[1], [0.5, 0.0])
    np.testing.assert_array_equal(h.from_env((1, params))[1], [0.0, 0.0])
    a, params = h.to_env_batch(np.array([0, 1, 2]), np.full((3, 2), -1.0))
    assert [p.shape for p in params] == [(3, 2), (3, 0), (3, 1)] and all(p.dtype == np.float32 for p in params)
    np.testing.assert_array_equal(params[0][0], [-1.0, -5.0])
    np.testing.assert_array_equal(params[2][:, 0], [1.0, 1.0, 0.0])


def test_wrappers_count_a_parameterless_action_once():
    flat = FlattenHybridAction(MaskedLine())
    assert flat.action_space.shape == (3 + 3,)
    a, params = flat.hybrid_action(np.array([0.0, 0.9, 0.1, 0.5, 0.5, -1.0], np.float32))
    assert a == 1 and params[1].shape == (0,)
    a, params = flat.hybrid_action(np.array([0.0, 0.1, 0.9, 0.5, 0.5, -1.0], np.float32))
    assert a == 2 and params[2][0] == 0.0  # its one parameter is the last entry
    grid = DiscretizeHybridAction(MaskedLine(), bins=3)
    assert grid.action_space.n == 3**2 + 1 + 3
    assert grid.hybrid_action(9)[0] == 1 and grid.hybrid_action(10)[0] == 2


def _random_distribution(batch: int, sizes=(2, 0, 1), seed: int = 0) -> HybridDistribution:
    g = torch.Generator().manual_seed(seed)
    k, m = len(sizes), max(sizes)
    mask = torch.tensor([[i < s for i in range(m)] for s in sizes])
    return HybridDistribution(
        torch.randn(batch, k, generator=g, dtype=torch.float64),
        torch.randn(batch, k, m, generator=g, dtype=torch.float64),
        0.3 * torch.randn(batch, k, m, generator=g, dtype=torch.float64),
        mask,
    )


def test_a_parameterless_choice_has_the_categorical_log_probability_alone():
    dist = _random_distribution(4)
    a = torch.full((4,), 1)
    x = torch.randn(4, 2, dtype=torch.float64)  # whatever sits in the padding
    torch.testing.assert_close(dist.log_prob(a, x), torch.log_softmax(dist.logits, -1)[:, 1])
    assert torch.all(dist.entropy_c()[:, 1] == 0)
    other = _random_distribution(4, seed=1)
    assert torch.all(dist.kl_c(other)[:, 1] == 0)
    # action 2 uses one of the two padded entries: its Gaussian density is that entry's alone
    a2 = torch.full((4,), 2)
    mu, std = dist.means[:, 2, 0], dist.log_std[:, 2, 0].exp()
    expected = torch.log_softmax(dist.logits, -1)[:, 2] + torch.distributions.Normal(mu, std).log_prob(x[:, 0])
    torch.testing.assert_close(dist.log_prob(a2, x), expected)
    torch.manual_seed(0)
    samples = [dist.sample() for _ in range(50)]
    assert all(torch.all(xs[a_ == 1] == 0) and torch.all(xs[a_ == 2][:, 1] == 0) for a_, xs in samples)


# -- action masks: the primitives, the masked distribution, uniform draws ---------------------------------
def test_info_action_masks_reads_gymnasiums_vector_infos():
    assert info_action_masks({}, 2, 3).all()
    reported = np.array([[True, False, True], [False, False, False], [False, True, False]])
    masks = info_action_masks({"action_mask": reported, "_action_mask": np.array([True, True, False])}, 3, 3)
    np.testing.assert_array_equal(masks, [[True, False, True], [True, True, True], [True, True, True]])
    envs = gymnasium.vector.SyncVectorEnv([MaskedLine for _ in range(5)])
    obs, info = envs.reset(seed=0)
    np.testing.assert_array_equal(info_action_masks(info, 5, 3)[:, 2], obs[:, 0] < 0)
    with pytest.raises(ValueError, match=r"expected \(5, 4\)"):
        info_action_masks(info, 5, 4)


def test_masked_distribution_is_the_categorical_over_the_allowed_actions():
    base = _random_distribution(6)
    mask = torch.tensor([[1, 1, 0], [1, 0, 1], [0, 1, 0], [1, 1, 1], [0, 0, 1], [1, 0, 0]], dtype=torch.bool)
    dist = HybridDistribution(masked_logits(base.logits, mask), base.means, base.log_std, base.mask)
    other = _random_distribution(6, seed=2)
    other = HybridDistribution(masked_logits(other.logits, mask), other.means, other.log_std, other.mask)
    x = torch.randn(6, 2, dtype=torch.float64)
    for row in range(6):
        allowed = np.flatnonzero(mask[row].numpy())
        z = base.logits[row].numpy()[allowed]
        p = np.exp(z - z.max()) / np.exp(z - z.max()).sum()
        h_c = [
            sum(0.5 * math.log(2 * math.pi * math.e) + float(base.log_std[row, k, i]) for i in range(s))
            for k, s in zip(allowed, np.array([2, 0, 1])[allowed])
        ]
        assert float(dist.entropy()[row]) == pytest.approx(float(-(p * np.log(p)).sum() + (p * h_c).sum()))
        zo = other.logits[row].numpy()[allowed]
        po = np.exp(zo - zo.max()) / np.exp(zo - zo.max()).sum()
        kl_c = dist.kl_c(other)[row].numpy()[allowed]
        kl = float(kl_divergence(dist, other)[row])
        assert kl == pytest.approx(float((p * np.log(p / po)).sum() + (p * kl_c).sum()))
        for j, k in enumerate(allowed):  # the same Gaussian part: the difference is the categorical's
            a = torch.full((6,), int(k))
            logp = float(dist.log_prob(a, x)[row] - base.log_prob(a, x)[row])
            assert logp == pytest.approx(math.log(p[j]) - float(torch.log_softmax(base.logits[row], -1)[k]))
    assert torch.all(dist.probs_d[~mask] == 0) and torch.isfinite(dist.entropy()).all()
    logits = base.logits.clone().requires_grad_(True)
    HybridDistribution(masked_logits(logits, mask), base.means, base.log_std, base.mask).entropy().sum().backward()
    assert torch.isfinite(logits.grad).all() and torch.all(logits.grad[~mask] == 0)
    # Monte-Carlo: samples keep to the allowed actions, with the renormalised frequencies
    draws = torch.stack([dist.sample(torch.Generator().manual_seed(s))[0] for s in range(400)])
    assert mask.gather(1, draws.T).all()
    freq = torch.stack([(draws == k).double().mean(0) for k in range(3)], -1)
    assert (freq - dist.probs_d).abs().max() < 0.1
    assert masked_logits(base.logits, None) is base.logits
    assert torch.equal(masked_logits(base.logits, torch.zeros(6, 3, dtype=torch.bool)), base.logits)
    assert float(masked_logits(base.logits, mask).min()) == MASKED


def test_uniform_actions_draw_among_the_allowed_only():
    mask = torch.tensor([[True, False, True]] * 3000 + [[False, True, False]] * 1000)
    for rng in (np.random.default_rng(0), torch.Generator().manual_seed(0)):
        a = uniform_actions(len(mask), 3, mask, rng, "cpu")
        assert mask.gather(1, a[:, None]).all()
        assert (a[:3000] == 0).float().mean() == pytest.approx(0.5, abs=0.04)
    np.testing.assert_array_equal(
        uniform_actions(7, 3, None, np.random.default_rng(4), "cpu").numpy(),
        np.random.default_rng(4).integers(3, size=7),
    )


def test_hybrid_policy_samples_only_allowed_actions():
    policy = HybridPolicy(3, HybridActionSpace.from_gym(MaskedLine().action_space), (8,))
    obs = torch.randn(200, 3)
    mask = torch.rand(200, 3) < 0.5
    mask[:, 0] |= ~mask.any(-1)
    a, x = policy(obs, mask).sample(torch.Generator().manual_seed(0))
    assert mask.gather(1, a[:, None]).all() and torch.all(x[a == 1] == 0)
    assert mask.gather(1, policy(obs, mask).mode()[0][:, None]).all()


# -- the masked Q target, by hand -------------------------------------------------------------------------
def test_pdqn_target_takes_the_max_over_the_next_states_allowed_actions():
    cls = algorithm_class("pdqn")
    model = cls(MaskedLine(), small_config(cls, action_mask=True, batch_size=4, gamma=0.5))
    assert {"mask", "next_mask"} <= set(model.replay.fields)
    g = np.random.default_rng(3)
    n = 4
    next_mask = np.array([[True, True, False], [False, True, True], [True, False, False], [True, True, True]])
    model.replay.add(
        obs=g.normal(size=(n, 3)).astype(np.float32),
        a=np.array([0, 1, 2, 0]),
        x=np.zeros((n, 2), np.float32),
        reward=np.array([1.0, -1.0, 0.5, 0.0], np.float32),
        next_obs=g.normal(size=(n, 3)).astype(np.float32),
        terminated=np.array([False, False, False, True]),
        mask=np.ones((n, 3), bool),
        next_mask=next_mask,
        params=g.uniform(-1, 1, size=(n, 3)).astype(np.float32),
    )
    data = {k: v.clone() for k, v in model.replay.data.items()}
    idx = np.random.default_rng(5).integers(0, n, size=4)
    with torch.no_grad():
        nxt = data["next_obs"][idx]
        q_next = model.q_target(nxt, model.actor_target(nxt).clamp(-1, 1)).numpy()
        q = model.q_net(data["obs"][idx], data["params"][idx]).numpy()[np.arange(4), data["a"][idx].numpy()]
    best = np.array([max(q_next[i, k] for k in range(3) if next_mask[j, k]) for i, j in enumerate(idx)])
    y = data["reward"][idx].numpy() + 0.5 * (~data["terminated"][idx].numpy()) * best
    model.np_rng = np.random.default_rng(5)
    stats = model._update()
    assert stats["losses/critic_loss"] == pytest.approx(float(np.mean((q - y) ** 2)), rel=1e-5)
    unmasked = data["reward"][idx].numpy() + 0.5 * (~data["terminated"][idx].numpy()) * q_next.max(-1)
    assert not np.allclose(y, unmasked)  # the batch has a masked best action, so the check can fail


# -- Half Field Offense reports KICK's kickability -----------------------------------------------------------
def test_hfo_allows_kick_exactly_when_the_kick_is_sent():
    env = gymnasium.make("pamdp/HalfFieldOffense-v0").unwrapped
    from pamdp.envs.hfo.dynamics import LAST_ACTION_OK_FEATURE

    kick = (2, (np.zeros(2, np.float32), np.zeros(1, np.float32), np.array([50.0, 0.0], np.float32)))
    seen = set()
    for seed in range(60):
        d = 0.6 + seed * 0.01  # the ball from 0.6 m to 1.2 m away, around the kickable distance
        obs, info = env.reset(seed=seed, options={"ball": (30.0, 0.0), "player": (30.0 - d, 0.0)})
        mask = info["action_mask"]
        assert mask.dtype == np.bool_ and mask.shape == (3,) and mask[:2].all()
        obs, *_, info = env.step(kick)
        seen.add(bool(mask[2]))
        assert bool(mask[2]) == bool(obs[LAST_ACTION_OK_FEATURE] > 0)  # HFO drops a KICK it cannot send
    assert seen == {True, False}

    # the batched env's copy i reports what the scalar env seeded with seed + i does
    vec = gymnasium.make_vec("pamdp/HalfFieldOffense-v0", num_envs=3, vectorization_mode="vector_entry_point")
    scalars = [gymnasium.make("pamdp/HalfFieldOffense-v0") for _ in range(3)]
    near = {"ball": (30.0, 0.0), "player": (29.2, 0.0)}
    _, infos = vec.reset(seed=7, options=near)
    masks = np.stack([s.reset(seed=7 + i, options=near)[1]["action_mask"] for i, s in enumerate(scalars)])
    rng, kicks = np.random.default_rng(0), set()
    for _ in range(30):
        np.testing.assert_array_equal(infos["action_mask"], masks)
        assert infos["_action_mask"].all()
        kicks.update(masks[:, 2].tolist())
        a = rng.integers(3, size=3)
        params = (np.tile([20.0, 0.0], (3, 1)), rng.uniform(-30, 30, (3, 1)), np.tile([10.0, 0.0], (3, 1)))
        params = tuple(p.astype(np.float32) for p in params)
        _, _, term, trunc, infos = vec.step((a, params))
        outs = [s.step((int(a[i]), tuple(p[i] for p in params))) for i, s in enumerate(scalars)]
        masks = np.stack([out[4]["action_mask"] for out in outs])
        if (term | trunc).any():
            break
    assert kicks == {True, False}


class CountingLine(MaskedLine):
    """MaskedLine counting masked picks across the copies ``evaluate`` makes itself."""

    picks = 0

    def step(self, action):
        CountingLine.picks += not self._mask()[int(action[0])]
        return super().step(action)


@pytest.mark.parametrize("action_mask", [True, False], ids=["masked", "unmasked"])
def test_evaluation_acts_within_the_mask_when_the_model_was_trained_with_it(action_mask):
    from pamdp.evaluation import evaluate

    cls = algorithm_class("patrpo")
    model = cls(gymnasium.vector.SyncVectorEnv([MaskedLine] * 2), small_config(cls, action_mask=action_mask))
    gymnasium.register("test/CountingLine-v0", entry_point=CountingLine)
    CountingLine.picks = 0
    try:
        result = evaluate(model, episodes=40, seed=1, deterministic=False, num_envs=4, env_id="test/CountingLine-v0")
    finally:
        gymnasium.registry.pop("test/CountingLine-v0")
    assert result["episodes"] == 40
    assert (CountingLine.picks == 0) if action_mask else (CountingLine.picks > 0)
