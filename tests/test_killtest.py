"""The kill test (primitives.research.killtest): SIGKILL a training run and --resume it; the command it starts, the
log rows it counts twice and when a kill or a whole test counts as passed.

(``tests/test_checkpoint.py`` checks that checkpoint writes are atomic under SIGKILL and that ``checkpoint.load``
raises CheckpointError on a corrupt, a truncated and a missing file; ``tests/test_training_train.py`` that --resume
from a damaged checkpoint is a one-line error at the command line.)
"""

from __future__ import annotations

import sys

import pytest

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


def test_the_train_command_is_the_training_cli_checkpointing_at_the_interval(tmp_path):
    cmd = killtest.train_command("spin", tmp_path / "run", steps=300, interval_s=1.5, workers=2, seed=7, resume=True)
    assert cmd[:3] == [sys.executable, "-m", "primitives.train"]
    args = train_mod.build_parser().parse_args(cmd[3:])  # the command line the training CLI reads
    assert args.primitive == "spin" and args.steps == 300 and args.workers == 2 and args.seed == 7
    assert args.out == str(tmp_path / "run") and args.resume
    assert args.checkpoint_minutes * 60 == pytest.approx(1.5, abs=1e-4)
    fresh = killtest.train_command("spin", tmp_path / "run", 300, 1.5, 2, 7, resume=False)
    assert not train_mod.build_parser().parse_args(fresh[3:]).resume


def test_log_rows_a_resumed_run_writes_again_are_counted(tmp_path):
    log = tmp_path / "log.csv"
    log.write_text("step,reward\n10,0.1\n20,0.2\n30,0.3\n20,0.2\n30,0.3\n40,0.4\n")  # resumed from step 10
    assert killtest._duplicated_rows(log) == 1  # the row where the steps go back
    log.write_text("step,reward\n10,0.1\n20,0.2\n20,0.2\n20,0.2\n30,0.3\n")
    assert killtest._duplicated_rows(log) == 2
    log.write_text("step,reward\n10,0.1\n20,0.2\n")
    assert killtest._duplicated_rows(log) == 0
    assert killtest._duplicated_rows(tmp_path / "missing.csv") == 0


def _kill(**kw) -> killtest.Kill:
    fields = dict(index=0, after_s=1.0, last_seen_step=40, lost_steps=10, lost_s=0.4, checkpoint_step=30,
                  resumed_from=30)
    return killtest.Kill(**{**fields, **kw})


def test_a_kill_passes_when_the_resumed_run_starts_from_the_checkpoint_and_nothing_outlives_it():
    assert _kill().ok
    assert not _kill(resumed_from=0).ok  # started again from scratch
    assert not _kill(orphans=1).ok  # a worker outlived its learner
    assert not _kill(exit_ok=False).ok


def test_the_test_passes_only_when_every_check_held():
    def result(**kw) -> killtest.KillTestResult:
        fields = dict(primitive="push", steps=100, interval_s=1.0, kills=[_kill()], completed=True, final_steps=100)
        return killtest.KillTestResult(**{**fields, **kw})

    assert result().ok and "OK" in result().report()
    assert not result(completed=False).ok
    assert not result(final_steps=90).ok
    assert not result(kills=[_kill(), _kill(resumed_from=None)]).ok
    assert not result(duplicated_log_rows=1).ok
    assert not result(kills=[_kill(lost_s=1.0 + killtest.SLACK_S + 0.1)]).ok  # more than an interval lost
    assert result(kills=[_kill(lost_s=1.0 + killtest.SLACK_S)]).ok
    assert result(corrupt_checkpoint_ok=None).ok and not result(corrupt_checkpoint_ok=False).ok
    assert result().as_dict()["max_lost_s"] == 0.4 and "FAILED" in result(completed=False).report()
