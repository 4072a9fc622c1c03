"""Checkpoints, run.json and evaluation.json are replaced whole or not at all."""

import os

import pytest
import torch

from pamdp.algos.checkpoints import atomic_save
from pamdp.atomic import atomic_write_text


class Interrupted(Exception):
    pass


def test_a_write_interrupted_midway_leaves_the_old_file_and_no_temporary(tmp_path, monkeypatch):
    path = tmp_path / "run.json"
    atomic_write_text(path, '{"old": 1}')

    def half_a_checkpoint(obj, f):
        f.write(b"PK\x03\x04 half a zip")
        raise Interrupted  # as a run killed (KeyboardInterrupt, disk full) in the middle of torch.save

    monkeypatch.setattr(torch, "save", half_a_checkpoint)
    ckpt = tmp_path / "checkpoint.pt"
    ckpt.write_bytes(b"the previous checkpoint")
    with pytest.raises(Interrupted):
        atomic_save({"w": torch.zeros(3)}, ckpt)
    assert ckpt.read_bytes() == b"the previous checkpoint"
    assert path.read_text() == '{"old": 1}'
    assert sorted(p.name for p in tmp_path.iterdir()) == ["checkpoint.pt", "run.json"]


def test_a_completed_write_replaces_the_file_with_open_s_permissions(tmp_path):
    path = tmp_path / "sub" / "evaluation.json"
    atomic_write_text(path, "first")
    atomic_write_text(path, "second, longer than the first")
    assert path.read_text() == "second, longer than the first"
    mask = os.umask(0)
    os.umask(mask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~mask  # not mkstemp's private 0600
    with pytest.raises(ValueError, match=r"cannot save to .*sub: it is a directory; expected a file path"):
        atomic_write_text(tmp_path / "sub", "text")
