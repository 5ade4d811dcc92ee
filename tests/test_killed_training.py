"""Killed training: SIGKILL and --resume, atomic checkpoint writes, damaged checkpoints at the CLI.

(``tests/test_training.py`` already checks that ``checkpoint.load`` raises CheckpointError on a
corrupt, a truncated and a missing file.)
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
import torch

from primitives.research import killtest
from primitives.training import checkpoint as ckpt
from primitives.training import train as train_mod


@pytest.mark.slow
def test_one_kill_and_resume_continues_from_the_checkpoint(tmp_path):
    result = killtest.killtest("push", kills=1, out=tmp_path / "kt", steps=250, interval_s=0.5, workers=0,
                               seed=0, window=(1.0, 1.5), check_truncated=False, timeout=120, log=lambda *a: None)
    (kill,) = result.kills
    assert kill.checkpoint_step > 0  # a checkpoint was written before the kill ...
    assert kill.resumed_from == kill.checkpoint_step  # ... and the resumed run started from it
    assert kill.lost_s <= 0.5 + killtest.SLACK_S  # at most one interval (plus one loop iteration) lost
    assert result.completed and result.final_steps == 250
    saved = ckpt.load(tmp_path / "kt" / "run" / "checkpoint.pt")
    assert saved["state"]["global_step"] == 250
    assert (tmp_path / "kt" / "run" / "policy.pt").exists()
    assert result.ok


def _tiny_argv(out) -> list[str]:
    return ["push", "--steps", "20", "--workers", "0", "--out", str(out), "--n-points", "32", "--replay-size", "64",
            "--learning-starts", "8", "--resume"]


@pytest.mark.parametrize("damage", ["truncated", "corrupt"])
def test_resume_from_a_damaged_checkpoint_is_a_clear_error(tmp_path, capsys, damage):
    path = tmp_path / "checkpoint.pt"
    ckpt.save(path, {"model": {"w": torch.ones(1000)}, "state": {"global_step": 3}})
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 3] if damage == "truncated" else b"\x00garbage" + data[8:])
    assert train_mod.main(_tiny_argv(tmp_path)) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("python -m primitives.train: error: checkpoint ") and "damaged or truncated" in err
    assert str(path) in err and "Traceback" not in err and len(err.splitlines()) == 1
    with pytest.raises(ckpt.CheckpointError):
        train_mod.train(train_mod.TrainConfig(out=str(tmp_path), workers=0), resume=True, progress=False)


_WRITER = textwrap.dedent("""
    import sys, torch
    from primitives.training import checkpoint as ckpt
    path, i = sys.argv[1], 0
    while True:
        i += 1
        ckpt.save(path, {"model": {"w": torch.full((2_000_000,), float(i))}, "state": {"i": i}})
        print(i, flush=True)
""")


@pytest.mark.slow
def test_checkpoint_writes_are_atomic_under_sigkill(tmp_path):
    """A writer saving 8 MB checkpoints in a loop is killed mid-stream three times: the file on disk
    always loads, whole, as one of the checkpoints it finished."""
    path = tmp_path / "checkpoint.pt"
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    for delay in (0.15, 0.35, 0.6):
        proc = subprocess.Popen([sys.executable, "-c", _WRITER, str(path)], stdout=subprocess.PIPE, env=env,
                                text=True)
        assert proc.stdout.readline()  # one checkpoint is complete
        time.sleep(delay)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
        finished = [int(line) for line in proc.stdout.read().split()]
        saved = ckpt.load(path)
        i = saved["state"]["i"]
        assert torch.equal(saved["model"]["w"], torch.full((2_000_000,), float(i)))
        last = finished[-1] if finished else 1  # the last save the writer reported finished
        assert i in (last, last + 1)  # that one, or the next if it finished between print and kill
