"""Training (primitives.training.train): checkpoints that resume, a tiny run that learns, bf16 updates, settings
refused before anything runs, and the command line's errors (a damaged checkpoint, bad settings)."""

from __future__ import annotations

import json
import logging
from dataclasses import replace

import numpy as np
import pytest
import torch

from primitives import weights_file
from primitives.networks import HybridActorCritic
from primitives.training import checkpoint as ckpt
from primitives.training import train as train_mod
from primitives.training.env import EnvConfig, PrimitiveEnv
from primitives.training.evaluate import greedy_action, load_policy
from primitives.training.replay import ReplayBuffer
from primitives.training.train import TrainConfig, bf16_is_fast, train, update


def _cube_config(out, steps: int) -> TrainConfig:
    return TrainConfig(primitive="push", steps=steps, workers=0, seed=0, out=str(out), objects=("cube",),
                       learning_starts=100, replay_size=1000, n_points=128, replay_ratio=48.0,
                       checkpoint_minutes=60.0, p_params=0.0)


@pytest.mark.slow
def test_checkpoint_resume_round_trips(tmp_path):
    summary = train(_cube_config(tmp_path, 120), progress=False)
    saved = ckpt.load(tmp_path / "checkpoint.pt")
    policy = weights_file.load(tmp_path / "policy.pt", kind="policy", skill="push")[0]["model"]
    assert all(torch.equal(saved["model"][k], v) for k, v in policy.items())
    assert saved["state"]["global_step"] == summary["steps"] == 120
    replay = ReplayBuffer(1000, 128)
    replay.load_state(saved["replay"])
    assert replay.size == 120 - saved["state"]["invalid"]
    resumed = train(_cube_config(tmp_path, 160), resume=True, progress=False)
    assert resumed["steps"] == 160 and resumed["updates"] >= saved["state"]["n_updates"]
    rows = (tmp_path / "log.csv").read_text().splitlines()
    assert rows[0].startswith("step,")
    config = (tmp_path / "config.json").read_text()  # shipped beside the weights: no folder of this machine
    assert json.loads(config)["steps"] == 160 and json.loads(config)["out"] == tmp_path.name
    assert str(tmp_path.parent) not in config


@pytest.mark.slow
def test_resume_lets_go_of_the_loaded_checkpoint(tmp_path, monkeypatch):
    """After --resume restores the replay into its preallocated buffer, the loaded checkpoint's copy of the
    replay is freed before training goes on (else a resumed run holds the replay twice: +250 MB on spin's
    one-hour run)."""
    import gc
    import weakref

    train(_cube_config(tmp_path, 120), progress=False)
    held, load = [], ckpt.load

    def load_and_watch(path, **kwargs):
        saved = load(path, **kwargs)
        held.append(weakref.ref(saved["replay"]["obs"]))
        return saved

    def update_and_check(*args, **kwargs):
        gc.collect()
        assert held and held[0]() is None, "the checkpoint's replay is still referenced during training"
        return update(*args, **kwargs)

    monkeypatch.setattr(train_mod.ckpt, "load", load_and_watch)
    monkeypatch.setattr(train_mod, "update", update_and_check)
    assert train(_cube_config(tmp_path, 140), resume=True, progress=False)["steps"] == 140


def _greedy_push(model, n=40):
    env = PrimitiveEnv(EnvConfig("push", objects=("cube",), n_points=128, episodes_per_object=1), seed=99)
    rewards_, successes = [], []
    for _ in range(n):
        obs = env.reset(object_key="cube")
        idx, motion, _ = greedy_action(model, obs)
        res = env.step(idx, motion)
        rewards_.append(res.reward)
        successes.append(res.success)
    return float(np.mean(rewards_)), float(np.mean(successes))


def _random_push(n=40):
    env = PrimitiveEnv(EnvConfig("push", objects=("cube",), n_points=128, episodes_per_object=1), seed=99)
    rng = np.random.default_rng(3)
    rewards_, successes = [], []
    for _ in range(n):
        env.reset(object_key="cube")
        res = env.step(int(rng.integers(128)), rng.uniform(-1, 1, size=3))
        rewards_.append(res.reward)
        successes.append(res.success)
    return float(np.mean(rewards_)), float(np.mean(successes))


@pytest.mark.parametrize("precision", ["fp32", pytest.param("bf16", marks=pytest.mark.skipif(
    not bf16_is_fast(), reason="no native bfloat16 on this CPU: emulated, too slow for the suite"))])
@pytest.mark.slow
def test_tiny_run_on_the_cube_learns_to_push(tmp_path, precision):
    """500 primitives on the cube: the greedy policy beats a random one by >= 0.3 in mean reward
    (the seed's push loss) and by >= 5 points of push success, with the learner in float32 or bf16."""
    torch.set_num_threads(1)
    train(replace(_cube_config(tmp_path, 500), precision=precision), progress=False)
    trained_reward, trained_success = _greedy_push(load_policy(tmp_path / "policy.pt", "push"))
    random_reward, random_success = _random_push()
    assert trained_reward >= random_reward + 0.3
    assert trained_success >= random_success + 0.05


def test_a_bf16_update_is_the_float32_update_up_to_rounding():
    """From the same weights and batch, one critic + actor update under bf16 autocast moves the weights
    the way the float32 update does (cosine of the two weight changes > 0.9, per network part), and the
    weights and optimiser state stay float32."""
    rng = np.random.default_rng(0)
    batch = dict(obs=rng.standard_normal((32, 128, 9)).astype(np.float32), index=rng.integers(0, 128, 32),
                 motion=rng.uniform(-1, 1, (32, 3)).astype(np.float32),
                 reward=rng.uniform(-2, 0, 32).astype(np.float32))
    torch.manual_seed(0)
    start = HybridActorCritic().state_dict()
    steps = {}
    for precision in ("fp32", "bf16"):
        model = HybridActorCritic()
        model.load_state_dict(start)
        critic = [*model.backbone.parameters(), *model.q1.parameters(), *model.q2.parameters()]
        opt_c, opt_a = torch.optim.SGD(critic, lr=1e-2), torch.optim.SGD(model.actor.parameters(), lr=1e-2)
        critic_loss, actor_loss = update(model, opt_c, opt_a, batch, TrainConfig(precision=precision), n_updates=2)
        assert np.isfinite(critic_loss) and actor_loss is not None and np.isfinite(actor_loss)
        assert all(p.dtype == torch.float32 for p in model.parameters())
        steps[precision] = {k: (v - start[k]).flatten() for k, v in model.state_dict().items()}
    for part in ("backbone.", "q1.", "q2.", "actor."):
        a = torch.cat([v for k, v in steps["fp32"].items() if k.startswith(part)])
        b = torch.cat([v for k, v in steps["bf16"].items() if k.startswith(part)])
        assert float(torch.nn.functional.cosine_similarity(a, b, dim=0)) > 0.9, part


@pytest.mark.parametrize("field, value, words", [
    ("steps", 0, "--steps must be a whole number >= 1"),
    ("steps", 10.5, "--steps must be a whole number"),
    ("workers", -1, "--workers must be a whole number >= 0"),
    ("batch_size", 0, "--batch-size must be a whole number >= 1"),
    ("replay_size", 8, "--replay-size must be a whole number >= 32"),
    ("n_points", 4, "--n-points must be a whole number >= 16"),
    ("max_minutes", float("nan"), "--max-minutes must be a positive number"),
    ("max_minutes", -5.0, "--max-minutes must be a positive number"),
    ("lr", 0.0, "--lr must be a positive number"),
    ("checkpoint_minutes", float("inf"), "--checkpoint-minutes must be a positive number"),
    ("p_params", 1.2, "--p-params is a probability in [0, 1]"),
    ("p_params", float("nan"), "--p-params is a probability in [0, 1]"),
    ("primitive", "jump", "unknown primitive 'jump'"),
    ("init", "no/such/weights.pt", "--init: no weights file at no/such/weights.pt"),
    # settings without a flag are named as TrainConfig fields
    ("epsilon", -0.1, "TrainConfig.epsilon is a probability in [0, 1]"),
    ("replay_ratio", 0.0, "--replay-ratio must be a positive number"),
    ("precision", "fp16", "--precision must be one of ('fp32', 'bf16'), got 'fp16'"),
    ("actor_delay", 0, "TrainConfig.actor_delay must be a whole number >= 1"),
    ("sim_cache", 0, "TrainConfig.sim_cache must be a whole number >= 1"),
    # test objects never train a policy, whether a split or one mesh of it
    ("objects", "train+housekeep:unseen", "housekeep:unseen is held out for evaluation"),
    ("objects", "test", "test is held out for evaluation"),
    ("objects", "housekeep/clamp_050_medium_clamp_M+train", "clamp_050_medium_clamp_M is held out for evaluation"),
    ("objects", ("cube", "housekeep/clamp_050_medium_clamp_M"), "clamp_050_medium_clamp_M is held out for evaluation"),
    ("objects", ("cube", ("test", 3)), "test is held out for evaluation"),
])
def test_bad_training_settings_are_refused_before_anything_runs(tmp_path, field, value, words):

    from affordplan.errors import InputError
    from primitives.training.train import TrainConfig, check_config, train

    cfg = replace(TrainConfig(out=str(tmp_path / "run")), **{field: value})
    with pytest.raises(InputError) as info:
        check_config(cfg)
    assert words in str(info.value)
    with pytest.raises(InputError):
        train(cfg, progress=False)
    assert not (tmp_path / "run").exists()  # nothing written: refused before the run folder is made


def test_the_cli_reports_bad_settings_as_usage_errors(capsys):
    from primitives.training.train import main

    with pytest.raises(SystemExit) as info:
        main(["push", "--p-params", "2", "--out", "/nonexistent/run"])
    assert info.value.code == 2
    assert "--p-params is a probability in [0, 1], got 2.0" in capsys.readouterr().err


def test_resume_without_a_checkpoint_says_it_starts_a_new_run(tmp_path, caplog):
    from primitives.training.train import TrainConfig, train

    cfg = TrainConfig(primitive="push", steps=2, workers=0, out=str(tmp_path), objects=("cube",), n_points=64,
                      replay_size=64, checkpoint_minutes=60.0)
    with caplog.at_level(logging.WARNING, logger="primitives.training.train"):
        summary = train(cfg, resume=True, progress=False)
    assert summary["steps"] == 2 and (tmp_path / "checkpoint.pt").exists()
    assert f"no checkpoint in {tmp_path} yet (the run stopped before its first): starting it again from step 0" \
        in caplog.messages


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
