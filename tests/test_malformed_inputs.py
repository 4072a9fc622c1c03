"""The new user's classes of malformed input not covered elsewhere (issue 46): each is refused with one line naming
the bad value and what is expected, and loses nothing. Env arguments, reset options and seeds are in
``test_env_contract.py``; flags, config files and output directories in ``test_hardening.py``; here, malformed actions
of every shape on every registered env, and the command line's counts, presets and models."""

from __future__ import annotations

import hashlib
from pathlib import Path

import gymnasium
import numpy as np
import pytest
from test_hardening import refusal  # one line on stderr, exit status 2

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs import _REGISTRATIONS

IDS = list(_REGISTRATIONS)


def make_vec(env_id, n):
    return gymnasium.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point")


def one_line_refusal(step, action) -> str:
    with pytest.raises(ValueError) as raised:
        step(action)
    message = str(raised.value)
    assert "\n" not in message and "expected" in message, message
    return message


def middle(box, lead=()):
    return np.broadcast_to((box.low + box.high) / 2, lead + box.shape).astype(box.dtype)


@pytest.mark.parametrize("env_id", IDS, ids=[i.removeprefix("pamdp/") for i in IDS])
def test_malformed_actions_are_refused_in_one_line_before_anything_moves(env_id):
    env, venv = gymnasium.make(env_id).unwrapped, make_vec(env_id, 2)
    env.reset(seed=0)
    venv.reset(seed=0)
    boxes = env.action_space[1]
    k = len(boxes)
    used = next(j for j, box in enumerate(boxes) if box.shape != (0,))  # an action with a parameter
    params = [middle(box) for box in boxes]
    batched = [middle(box, (2,)) for box in boxes]
    before, vbefore = env._states.copy(), venv.unwrapped._states.copy()

    def but(values, j, value):
        return tuple(value if i == j else v for i, v in enumerate(values))

    for bad in (
        (used, but(params, used, np.full(boxes[used].shape, np.nan, boxes[used].dtype))),  # NaN in the chosen one
        (used, but(params, used, np.full(boxes[used].shape, -np.inf, boxes[used].dtype))),
        (used, but(params, used, np.zeros(boxes[used].shape[0] + 2, boxes[used].dtype))),  # a wrong shape
        (used, but(params, used, np.array(["x"] * boxes[used].shape[0]))),  # not numbers
        (-1, tuple(params)),  # a negative index
        (0.5, tuple(params)),  # a fractional one
        ((used, tuple(params), None)),  # a triple
    ):
        one_line_refusal(env.step, bad)
    a = np.full(2, used)
    for bad in (
        (a, but(batched, used, np.full((2,) + boxes[used].shape, np.nan, boxes[used].dtype))),
        (a, but(batched, used, np.zeros((3,) + boxes[used].shape, boxes[used].dtype))),  # three copies' parameters
        (np.full(3, used), tuple(batched)),  # three copies' actions
        (np.array([used, -1]), tuple(batched)),
        (a.astype(str), tuple(batched)),
        (a, tuple(batched) + (batched[0],) if k > 1 else ()),  # one parameter too many
    ):
        one_line_refusal(venv.step, bad)
    np.testing.assert_array_equal(env._states, before)
    np.testing.assert_array_equal(venv.unwrapped._states, vbefore)


@pytest.mark.parametrize("env_id", ["pamdp/HalfFieldOffense-v0", "pamdp/HalfFieldOffenseGoalie-v0"])
def test_a_reset_option_of_the_wrong_shape_is_one_line_and_resets_nothing(env_id):
    venv = make_vec(env_id, 2)
    venv.reset(seed=0)
    before = venv.unwrapped._states.copy()
    for bad in ({"ball": np.zeros((3, 2))}, {"body": np.zeros((2, 2))}, {"player": "centre"}):
        with pytest.raises(ValueError) as raised:
            venv.reset(options=bad)
        assert "\n" not in str(raised.value) and "expected" in str(raised.value), raised.value
    np.testing.assert_array_equal(venv.unwrapped._states, before)


# -- the command line ---------------------------------------------------------------------------------------------
def fingerprint(root: Path) -> dict[str, str]:
    files = [p for p in root.rglob("*") if p.is_file()]
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest() for p in files}


@pytest.mark.parametrize(
    "flags, expected",
    [
        (["--total-steps", "-5"], "--total-steps: '-5'; expected a number of steps from 1"),
        (["--num-envs", "0"], "num_envs"),
        (["--num-envs", "-2"], "num_envs"),
        (["--preset", "no_such_preset"], "no_such_preset"),
        (["--env-kwargs", "{'n': 4}"], "--env-kwargs: \"{'n': 4}\" is not valid JSON"),
    ],
)
def test_bad_train_values_are_one_line_and_an_existing_run_is_untouched(flags, expected, tmp_path, capsys):
    run = tmp_path / "run"
    run.mkdir()
    (run / "progress.csv").write_text("time/total_timesteps,charts/episodic_return\n100,0.5\n")
    (run / "run.json").write_text('{"algo": "patrpo"}')
    kept = fingerprint(run)
    argv = ["train", "patrpo", "--total-steps", "300", "--eval-episodes", "0", "--no-progress", "--out", str(run)]
    assert expected in refusal([*argv, *flags], capsys)
    assert fingerprint(run) == kept


def test_evaluating_a_model_that_is_not_there_is_one_line_naming_it(tmp_path, capsys):
    missing = tmp_path / "no_such_run"
    assert str(missing) in refusal(["evaluate", str(missing)], capsys)
    assert not missing.exists()
