"""The device setting (issue 31): its checks, ``--device``, where a built algorithm's tensors are, and checkpoints
loaded on another device than the one that saved them (as far as a machine without CUDA can check it)."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from conftest import ENV, module_bytes, small_config

from pamdp.algos import ALGORITHMS, algorithm_class, load_model
from pamdp.algos.base import resolve_device
from pamdp.algos.checkpoints import read_checkpoint
from pamdp.cli import main

CUDA = pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")


def small(name: str, **settings):
    """Algorithm ``name`` with small networks and epochs, so that a test builds and trains it in a second."""
    return algorithm_class(name)(ENV, small_config(name, **settings))


def tensors_of(algo) -> dict[str, torch.Tensor]:
    """Every parameter, buffer and optimiser-state tensor of ``algo``, by name."""
    found = {}
    for name, module in algo._modules().items():
        found.update({f"{name}.{k}": v for k, v in module.state_dict(keep_vars=True).items()})
    for name, opt in algo._optimizers().items():
        for i, state in enumerate(opt.state.values()):
            found.update({f"{name}.state{i}.{k}": v for k, v in state.items() if isinstance(v, torch.Tensor)})
    if hasattr(algo, "replay"):  # the off-policy algorithms' replay contents live on the device too
        found.update({f"replay.{k}": v for k, v in algo.replay.data.items()})
    return found


@pytest.mark.parametrize("bad", ["gpu", "CUDA", "cuda:", "cuda:x", "cpu:0", "mps", ""])
def test_a_bad_device_is_refused_naming_it(bad):
    for name in ALGORITHMS:
        config_class = algorithm_class(name).config_class
        with pytest.raises(ValueError, match=rf"device = {bad!r}; expected 'auto', 'cpu', 'cuda' or 'cuda:N'"):
            config_class(device=bad)


@pytest.mark.skipif(torch.cuda.is_available(), reason="checks a machine without CUDA")
def test_cuda_where_there_is_none_is_refused_and_auto_is_the_cpu():
    assert resolve_device("auto") == torch.device("cpu")
    for name in ("cuda", "cuda:0", "cuda:3"):
        with pytest.raises(ValueError, match=rf"device = {name!r}, but CUDA is not available"):
            resolve_device(name)
    with pytest.raises(ValueError, match="CUDA is not available"):
        small("patrpo", device="cuda")


def test_a_cuda_index_beyond_the_machine_is_refused(monkeypatch):
    monkeypatch.setattr(torch.cuda, "is_available", lambda: True)
    monkeypatch.setattr(torch.cuda, "device_count", lambda: 2)
    assert resolve_device("cuda:1") == torch.device("cuda:1")
    assert resolve_device("auto") == torch.device("cuda")
    with pytest.raises(ValueError, match=r"device = 'cuda:2', but this machine has 2 CUDA device\(s\)"):
        resolve_device("cuda:2")


def test_the_cli_takes_device(tmp_path, capsys):
    out = tmp_path / "run"
    argv = ["train", "patrpo", "--total-steps", "200", "--batch-size", "100", "--num-envs", "2", "--no-progress"]
    assert main([*argv, "--hidden-sizes", "8", "--device", "cpu", "--out", str(out), "--eval-episodes", "0"]) == 0
    assert read_checkpoint(out)["config"]["device"] == "cpu"
    assert main([*argv, "--device", "gpu", "--out", str(tmp_path / "bad")]) == 2
    assert "device = 'gpu'; expected 'auto', 'cpu', 'cuda' or 'cuda:N'" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()


@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_every_tensor_of_a_built_algorithm_is_on_the_device_asked_for(name):
    algo = small(name, device="cpu")
    found = tensors_of(algo)
    assert found  # a model with no tensors would pass the check below trivially
    assert {k: v.device for k, v in found.items() if v.device != torch.device("cpu")} == {}
    assert algo.torch_gen.device == torch.device("cpu")


@pytest.mark.skipif(torch.cuda.is_available(), reason="checks a machine without CUDA")
@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_a_model_saved_for_cuda_loads_on_the_cpu(name, tmp_path):
    """A checkpoint whose settings say ``cuda`` (as one saved on a GPU machine does) loads on a machine without
    CUDA: onto the CPU by default, the same weights and the same greedy actions; asking for CUDA there is refused."""
    algo = small(name, device="cpu").learn(128, progress_bar=False)
    path = tmp_path / "model.pt"
    algo.save(path)
    payload = read_checkpoint(path)
    payload["config"]["device"] = "cuda"
    payload["rng"].update(torch_device="cuda", torch=torch.zeros(16, dtype=torch.uint8))  # Philox's state size
    torch.save(payload, path)

    loaded = load_model(path)
    assert loaded.device == torch.device("cpu") and loaded.config.device == "cpu"
    with pytest.raises(ValueError, match="CUDA is not available"):
        type(algo).load(path, device="cuda")
    assert module_bytes(loaded) == module_bytes(algo)
    obs = np.random.default_rng(0).uniform(-1, 1, size=(32, algo.obs_dim)).astype(np.float32)
    np.testing.assert_array_equal(algo.predict(obs)[0], loaded.predict(obs)[0])
    # the CUDA generator's state cannot seed the CPU's: the loaded model draws the seed's own stream
    fresh = torch.Generator().manual_seed(algo.config.seed)
    assert torch.equal(loaded.torch_gen.get_state(), fresh.get_state())


@CUDA
@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_on_cuda_every_tensor_is_there_and_training_runs(name):
    algo = small(name, device="cuda")
    cpu = small(name, device="cpu")
    for key, value in tensors_of(cpu).items():  # built on the CPU, then moved: the same initial weights
        assert torch.equal(tensors_of(algo)[key].cpu(), value), key
    algo.learn(200, progress_bar=False)
    assert {k: v.device.type for k, v in tensors_of(algo).items() if v.device.type != "cuda"} == {}
    if hasattr(algo, "replay"):  # sampled on the device from contents held there
        assert algo.replay.sample(4, algo.np_rng)["obs"].device.type == "cuda"


@CUDA
@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_a_cuda_checkpoint_loads_on_the_cpu(name, tmp_path):
    algo = small(name, device="cuda").learn(128, progress_bar=False)
    algo.save(tmp_path / "model.pt")
    loaded = type(algo).load(tmp_path / "model.pt", device="cpu")
    assert {v.device.type for v in tensors_of(loaded).values()} == {"cpu"}
    assert module_bytes(loaded) == module_bytes(algo)
    assert type(algo).load(tmp_path / "model.pt").device.type == "cuda"
