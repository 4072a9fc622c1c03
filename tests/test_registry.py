"""One registry of algorithms behind the command line and behind ``load_model`` (the package's layers:
``test_imports.py``)."""

from __future__ import annotations

import pytest

from pamdp.algos import ALGORITHMS, AlgoEntry, algorithm_class
from pamdp.cli import build_parser


def test_the_command_line_offers_each_registered_algorithm_with_its_help_and_budget(monkeypatch, capsys):
    monkeypatch.setitem(ALGORITHMS, "patrpo-copy", AlgoEntry("pamdp.algos.patrpo:PATRPO", "a registered copy", 1234))
    parser = build_parser()
    with pytest.raises(SystemExit):
        parser.parse_args(["train", "--help"])
    listing = capsys.readouterr().out
    for name, entry in ALGORITHMS.items():
        assert name in listing and entry.help.split()[0] in listing
    with pytest.raises(SystemExit):
        parser.parse_args(["train", "patrpo-copy", "--help"])
    assert "(default: 1,234)" in " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_each_entry_names_its_class(name):
    cls = algorithm_class(name)
    assert cls.__name__ == ALGORITHMS[name].class_name and cls.__module__ == ALGORITHMS[name].module


def test_load_model_takes_the_class_from_the_registry(tmp_path):
    from pamdp.algos import load_model
    from pamdp.algos.checkpoints import FORMAT, atomic_save
    from pamdp.algos.pdqn import PDQN, PDQNConfig

    model = PDQN("pamdp/Platform-v0", PDQNConfig(num_envs=1, hidden_sizes=(8,), seed=5))
    model.save(tmp_path / "m.pt")
    loaded = load_model(tmp_path / "m.pt")
    assert type(loaded) is PDQN and loaded.config == model.config
    atomic_save({"format": FORMAT, "algo": "NoSuchAlgo"}, tmp_path / "other.pt")
    with pytest.raises(ValueError, match=r"written by unknown algorithm 'NoSuchAlgo'; expected one of PATRPO, PAPPO"):
        load_model(tmp_path / "other.pt")
