"""The contract every registered env keeps, one parametrized test each over the registry: copy i of the batched
env equals the scalar env seeded ``seed + i`` step for step (next-step autoresets and the time limit included),
an ended copy's next step is its reset, the registration's time limit truncates, malformed actions are refused
before anything moves, and the scalar env is the batched one at one copy."""

import inspect
import re
import typing

import gymnasium
import numpy as np
import pytest
from gymnasium.vector import SyncVectorEnv

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs import _REGISTRATIONS

CASES = [(env_id, {}) for env_id in _REGISTRATIONS] + [("pamdp/HardMove-v0", {"n": 8})]
IDS = [env_id.removeprefix("pamdp/") + "".join(f"-{k}{v}" for k, v in kw.items()) for env_id, kw in CASES]


def make_vec(env_id, kwargs, n, **extra):
    return gymnasium.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kwargs, **extra)


def shared_info_keys(got: dict, want: dict) -> list[str]:
    return [k for k in want if not k.startswith("_") and k in got]


@pytest.mark.parametrize("env_id, kwargs", CASES, ids=IDS)
def test_copy_i_equals_a_scalar_env_seeded_seed_plus_i(env_id, kwargs):
    n, seed = 3, 11
    venv = make_vec(env_id, kwargs, n, max_episode_steps=9)  # short episodes: autoresets and truncations
    ref = SyncVectorEnv([lambda: gymnasium.make(env_id, max_episode_steps=9, **kwargs) for _ in range(n)])
    got, want = venv.reset(seed=seed), ref.reset(seed=seed)
    np.testing.assert_array_equal(got[0], want[0])
    venv.action_space.seed(seed)
    ended = 0
    for t in range(30):
        action = venv.action_space.sample()
        got, want = venv.step(action), ref.step(action)
        for k in range(4):
            np.testing.assert_array_equal(got[k], want[k], err_msg=f"t={t}, output {k}")
        for key in shared_info_keys(got[4], want[4]):
            np.testing.assert_array_equal(got[4][key], want[4][key], err_msg=f"t={t}, info {key}")
        ended += int(np.sum(got[2] | got[3]))
    assert ended > 0  # the comparison went through autoresets


@pytest.mark.parametrize("env_id, kwargs", CASES, ids=IDS)
def test_an_ended_copy_is_reset_on_its_next_step_and_the_time_limit_truncates(env_id, kwargs):
    venv = make_vec(env_id, kwargs, 4, max_episode_steps=2)
    obs, _ = venv.reset(seed=0)
    venv.action_space.seed(0)
    _, _, terminated, truncated, _ = venv.step(venv.action_space.sample())
    assert not truncated.any()
    _, _, terminated2, truncated2, _ = venv.step(venv.action_space.sample())
    assert (truncated2 | terminated2 | terminated).all()  # at step 2 every copy still running is truncated
    ended = terminated2 | truncated2
    obs, rewards, terminated3, truncated3, _ = venv.step(venv.action_space.sample())
    assert (rewards[ended] == 0).all() and not (terminated3[ended] | truncated3[ended]).any()


@pytest.mark.parametrize("env_id, kwargs", CASES, ids=IDS)
def test_the_scalar_env_is_the_batched_one_at_one_copy(env_id, kwargs):
    env, venv = gymnasium.make(env_id, **kwargs).unwrapped, make_vec(env_id, kwargs, 1, max_episode_steps=None)
    obs, _ = env.reset(seed=5)
    vobs, _ = venv.reset(seed=5)
    np.testing.assert_array_equal(vobs[0], obs)
    venv.action_space.seed(5)
    for _ in range(20):
        batch = venv.action_space.sample()
        action = (int(batch[0][0]), tuple(p[0] for p in batch[1]))
        step, vstep = env.step(action), venv.step(batch)
        if vstep[2][0] or vstep[3][0]:
            break
        np.testing.assert_array_equal(vstep[0][0], step[0])
        assert (vstep[1][0], vstep[2][0], vstep[3][0]) == step[1:4]


@pytest.mark.parametrize("env_id, kwargs", CASES, ids=IDS)
def test_malformed_actions_are_refused_before_anything_moves(env_id, kwargs):
    env, venv = gymnasium.make(env_id, **kwargs).unwrapped, make_vec(env_id, kwargs, 2)
    env.reset(seed=0)
    venv.reset(seed=0)
    k = env.action_space[0].n
    params = tuple(np.zeros(box.shape, box.dtype) for box in env.action_space[1])
    batched = tuple(np.zeros((2,) + box.shape, box.dtype) for box in env.action_space[1])
    before, vbefore = env.unwrapped._states.copy(), venv.unwrapped._states.copy()
    for bad in (5, (0, 1, 2), (k, params), (0, params[:-1])):
        with pytest.raises(ValueError, match="expected"):
            env.step(bad)
    for bad in (5, (np.array([0, k]), batched), (np.array([0, 0]), batched[:-1]), (np.full(2, 0.5), batched)):
        with pytest.raises(ValueError, match="expected"):
            venv.step(bad)
    np.testing.assert_array_equal(env.unwrapped._states, before)
    np.testing.assert_array_equal(venv.unwrapped._states, vbefore)


@pytest.mark.parametrize("env_id, kwargs", CASES, ids=IDS)
def test_the_shells_arguments_and_order_are_checked(env_id, kwargs):
    batched = entry_of(gymnasium.spec(env_id).vector_entry_point)
    for bad in (dict(num_envs=0), dict(num_envs=2.5), dict(max_episode_steps=0), dict(max_episode_steps=True)):
        with pytest.raises(ValueError, match="must be a positive integer"):
            batched(**{"num_envs": 2, **bad}, **gymnasium.spec(env_id).kwargs, **kwargs)
    scalar = entry_of(gymnasium.spec(env_id).entry_point)
    for make in (scalar, batched):
        with pytest.raises(ValueError, match="render_mode='human' is not supported"):
            make(render_mode="human", **gymnasium.spec(env_id).kwargs, **kwargs)
    env, venv = gymnasium.make(env_id, **kwargs).unwrapped, make_vec(env_id, kwargs, 2)
    with pytest.raises(gymnasium.error.ResetNeeded):
        env.step(env.action_space.sample())
    with pytest.raises(gymnasium.error.ResetNeeded):
        venv.step(venv.action_space.sample())


def entry_of(entry):
    return gymnasium.envs.registration.load_env_creator(entry) if isinstance(entry, str) else entry


@pytest.mark.parametrize("env_id, kwargs", CASES, ids=IDS)
def test_seeds_generators_and_reset_mask(env_id, kwargs):
    venv = make_vec(env_id, kwargs, 3)
    venv.reset(seed=None)  # fresh entropy for every copy: fine
    assert all(isinstance(g, np.random.Generator) for g in venv.np_randoms)
    for seed in (3.5, [1, 2], [1, 2, "x"], True):
        with pytest.raises(ValueError, match="expected None, an int, or a list of 3 ints"):
            venv.reset(seed=seed)
    with pytest.raises(AttributeError, match="np_randoms"):
        venv.np_random = np.random.default_rng(0)
    with pytest.raises(AttributeError, match="np_randoms"):
        _ = venv.unwrapped.np_random
    with pytest.raises(ValueError, match="expected one per copy"):
        venv.np_randoms = [np.random.default_rng(0)]
    with pytest.raises(ValueError, match="has no"):
        venv.np_randoms = [np.random.default_rng(0), np.random.default_rng(1), object()]
    reset_obs, _ = venv.reset(seed=0)
    venv.action_space.seed(0)
    moved, *_ = venv.step(venv.action_space.sample())
    obs, _ = venv.reset(seed=[None, 1, None], options={"reset_mask": np.array([False, True, False])})
    np.testing.assert_array_equal(obs, [moved[0], reset_obs[1], moved[2]])


# -- issue 46: constructor arguments, reset options and seeds, one rule in the shell for every id --------------------
def domain_arguments(env_id):
    """The domain's constructor arguments and their annotations (what the registered entry point's signature lists
    beyond the shell's own)."""
    from pamdp.envs.vector import DomainVectorEnv

    batched = entry_of(gymnasium.spec(env_id).vector_entry_point)
    shell = set(inspect.signature(DomainVectorEnv.__init__).parameters)
    hints = typing.get_type_hints(batched.domain_class.__init__)
    return {name: hints[name] for name in inspect.signature(batched).parameters if name not in shell}


WRONG = {bool: ["no", 1, 0.0, None], int: [True, 4.0, "4", None], float: [True, "0.5", None], str: [2016, None]}


@pytest.mark.parametrize("env_id", list(_REGISTRATIONS), ids=[i.removeprefix("pamdp/") for i in _REGISTRATIONS])
def test_domain_arguments_of_the_wrong_type_or_name_are_refused_naming_them(env_id):
    arguments = domain_arguments(env_id)
    for name, hint in arguments.items():
        for value in WRONG[hint]:
            shown = re.escape(f"argument {name}={value!r}; expected {hint.__name__}")
            with pytest.raises(ValueError, match=shown):
                gymnasium.make(env_id, **{name: value})
            with pytest.raises(ValueError, match=shown):
                make_vec(env_id, {name: value}, 2)
    with pytest.raises(ValueError, match="takes no argument 'noise'; expected some of"):
        gymnasium.make(env_id, noise=True)


@pytest.mark.parametrize("env_id, kwargs", CASES, ids=IDS)
def test_reset_options_must_be_a_dict_of_the_domains_keys_and_a_refusal_changes_nothing(env_id, kwargs):
    env, venv = gymnasium.make(env_id, **kwargs), make_vec(env_id, kwargs, 2)
    for e in (env, venv):
        e.reset(seed=0)
        e.action_space.seed(0)
        e.step(e.action_space.sample())
    states, vstates = env.unwrapped._states.copy(), venv.unwrapped._states.copy()
    draws, vdraws = env.unwrapped.np_random.bit_generator.state, [g.bit_generator.state for g in venv.np_randoms]
    for bad, shown in (
        ([("ball", (1, 2))], "expected None or a dict"),
        ("reset_mask", "expected None or a dict"),
        ({"speed": 1.0}, r"takes no reset option\(s\) \['speed'\]; expected any of"),
        ({"n": 3}, r"takes no reset option\(s\) \['n'\]"),
    ):
        for e in (env, venv):
            with pytest.raises(ValueError, match=shown):
                e.reset(seed=7, options=bad)
    with pytest.raises(ValueError, match=r"\['reset_mask'\]"):  # the batched env's own key
        env.reset(options={"reset_mask": np.array([True])})
    np.testing.assert_array_equal(env.unwrapped._states, states)
    np.testing.assert_array_equal(venv.unwrapped._states, vstates)
    assert env.unwrapped.np_random.bit_generator.state == draws
    assert [g.bit_generator.state for g in venv.np_randoms] == vdraws
    env.reset(options={})
    venv.reset(options={"reset_mask": np.array([True, False])})


def test_hard_moves_n_as_a_reset_option_says_it_is_a_constructor_argument():
    with pytest.raises(ValueError, match="n is a constructor argument"):
        gymnasium.make("pamdp/HardMove-v0").reset(options={"n": 3})


@pytest.mark.parametrize("env_id, kwargs", CASES, ids=IDS)
def test_a_bad_seed_is_pamdps_value_error_and_a_bad_entry_reseeds_no_copy(env_id, kwargs):
    env, venv = gymnasium.make(env_id, **kwargs), make_vec(env_id, kwargs, 3)
    env.reset(seed=1)
    venv.reset(seed=1)
    draws, vdraws = env.unwrapped.np_random.bit_generator.state, [g.bit_generator.state for g in venv.np_randoms]
    generators = venv.np_randoms
    for seed in ("x", -1, True, 2.5, [3]):
        with pytest.raises(ValueError, match=re.escape(f"seed={seed!r}; expected None or an int >= 0")):
            env.reset(seed=seed)
    for seed in ([4, 5, -1], [4, "x", 6], -2):
        with pytest.raises(ValueError, match=re.escape(f"seed={seed!r}; expected None, an int, or a list of 3")):
            venv.reset(seed=seed)
    assert env.unwrapped.np_random.bit_generator.state == draws
    assert venv.np_randoms == generators and [g.bit_generator.state for g in venv.np_randoms] == vdraws


@pytest.mark.parametrize("env_id, kwargs", CASES, ids=IDS)
def test_a_refused_reset_keeps_the_step_count_and_the_episode_truncates_at_the_limit(env_id, kwargs):
    """The envs count their own time limit (no Gymnasium ``TimeLimit``, which zeroes its count before the env can
    refuse the reset): steps, a refused reset, and the episode still ends at the limit counted from its start."""
    scalar = entry_of(gymnasium.spec(env_id).entry_point)
    made = gymnasium.make(env_id, **kwargs)
    assert not any(isinstance(w, gymnasium.wrappers.TimeLimit) for w in wrappers_of(made))
    for env in (scalar(max_episode_steps=4, **gymnasium.spec(env_id).kwargs, **kwargs), made):
        limit = env.unwrapped.max_episode_steps
        if limit is None:
            continue
        env.reset(seed=3)
        env.action_space.seed(3)
        for t in range(1, limit + 1):
            if t == 2:
                with pytest.raises(ValueError):
                    env.reset(options={"no such option": 1})
                with pytest.raises(ValueError):
                    env.reset(seed="x")
            _, _, terminated, truncated, _ = env.step(env.action_space.sample())
            if terminated:
                break
            assert truncated == (t == limit), f"t={t}, limit={limit}"


def wrappers_of(env):
    while isinstance(env, gymnasium.Wrapper):
        yield env
        env = env.env


def unused_nan_cases():
    """(env_id, kwargs, action k, box j) for every box j that action k does not use: all boxes but k's own where each
    action has its box, every box for a parameterless action."""
    for env_id, kwargs in CASES:
        space = gymnasium.make(env_id, **kwargs).action_space
        for k in range(min(space[0].n, 4)):
            for j, box in enumerate(space[1][:4]):
                if j != k and box.shape != (0,):
                    yield pytest.param(env_id, kwargs, k, j, id=f"{env_id[6:]}-{kwargs}-a{k}-p{j}")


@pytest.mark.parametrize("env_id, kwargs, k, j", list(unused_nan_cases()))
def test_a_nan_in_an_unused_parameter_is_refused_on_every_domain(env_id, kwargs, k, j):
    """The rule: every parameter of an action must be finite, used or not (a NaN anywhere is a bug upstream)."""
    env = gymnasium.make(env_id, **kwargs).unwrapped
    env.reset(seed=0)
    before = env._states.copy()
    params = [((box.low + box.high) / 2).astype(box.dtype) for box in env.action_space[1]]
    params[j] = np.full(params[j].shape, np.nan, params[j].dtype)
    with pytest.raises(ValueError, match="finite"):
        env.step((k, tuple(params)))
    np.testing.assert_array_equal(env._states, before)


@pytest.mark.parametrize("env_id", ["pamdp/HalfFieldOffense-v0", "pamdp/HalfFieldOffenseGoalie-v0"])
def test_hfos_option_values_are_checked_before_any_copy_is_reseeded(env_id):
    venv = make_vec(env_id, {}, 2)
    venv.reset(seed=1)
    vdraws = [g.bit_generator.state for g in venv.np_randoms]
    with pytest.raises(ValueError, match="reset option ball"):
        venv.reset(seed=[5, 6], options={"ball": (99.0, 0.0)})
    assert [g.bit_generator.state for g in venv.np_randoms] == vdraws
    obs, _ = venv.reset(options={"ball": (10.0, 0.0), "body": 0.0})  # the replay options still work
    assert obs.shape[0] == 2
