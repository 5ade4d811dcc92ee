"""Train a primitive with a HACMan-style hybrid actor-critic, on a CPU.

    python -m primitives.train push --steps 60000 --workers 1 --out runs/push --max-minutes 55

Read top to bottom, CleanRL style. Choices and why:

- **One step, no bootstrapping.** Every primitive is a single action, so the critic regresses the
  immediate reward ``-L`` (a contextual bandit). The seed's SB3 code bootstrapped ``gamma Q(s')`` on
  time-limit truncation, which is wrong for one-step episodes; here there is no ``s'`` at all, and no
  target networks are needed.
- **Hybrid actions (HACMan).** The actor map proposes a motion per point; twin critic maps score
  them; the contact is drawn from ``softmax(min(Q1, Q2) / T)`` with epsilon-uniform exploration, and
  Gaussian noise is added to the chosen motion. The actor maximises the softmax-weighted ``Q1`` over
  all points (HACMan's actor objective), with delayed updates (TD3).
- **Shared backbone, trained by the critic.** One PointNet backbone feeds both heads; the actor sees
  detached features. One backbone pass per cloud halves the cost on a CPU.
- **Parameters as goal flow.** With probability ``p_params`` an episode asks for a parameter (push
  direction, spin angle, roll target) and the observation carries, per point, the displacement it
  asks for (HACMan's goal flow); otherwise the flow is zero and the seed's objective applies. One
  policy serves both. ``--init`` warm-starts from earlier weights (weights without the flow inputs
  are widened with zero weights, so the run starts from what they did).
- **Scripted exploration (push, optional).** ``--p-scripted P`` replaces a share P of the exploring
  actions by a scripted push along the line through the cloud's centre (:mod:`primitives.training.scripted`),
  which succeeds about twice as often as early exploration; the critic regresses rewards, so these
  off-policy samples need no correction.
- **Hindsight relabelling (optional).** ``--hindsight`` also stores each primitive as it scores under
  the request it achieved (a 20 deg spin asked to turn 40 is a successful 20 deg spin) and under the
  seed's objective (:mod:`primitives.training.hindsight`): exact rewards of the same outcome, so the critic sees
  more successes and the unparameterised objective keeps being trained in a parameterised run. The
  copies fill the replay but are not primitives: the step count, the replay ratio and the logged
  success rates count executed primitives only.
- **bf16 learner (optional).** ``--precision bf16`` runs the learner's forward passes under
  ``torch.autocast`` in bfloat16 (weights, gradients and Adam stay float32; losses are taken in
  float32). On a CPU with AMX or AVX512-BF16 an update costs less than half (31 against 71 ms, batch
  32, one thread), so the same hour buys twice the updates (``--replay-ratio 16``); elsewhere it is
  emulated and slower, and the run says so. Workers act in float32 either way.
- **Invalid samples are dropped.** Primitives flagged by the physics guards never enter the replay.
- **Workers.** ``--workers K`` runs K rollout workers (one torch thread each) that act with the
  latest weights and send transitions to this learner (:mod:`primitives.training.rollouts`): processes on
  this machine (``--backend local``) or Ray actors on a local Ray instance or a Ray cluster
  (``--backend ray [--ray-address ADDR]``; ``docs/training.md``). Both seed worker ``w`` the same
  way. ``--workers 0`` collects in-process and is bit-for-bit reproducible for a given ``--seed``.
- **Memory stays flat.** The replay is preallocated (float16 clouds); nothing grows with the run.
- **Checkpoints** are written atomically every ``--checkpoint-minutes`` and at the end, with the
  replay, optimisers and random-generator states; ``--resume`` continues from the last one.
"""

from __future__ import annotations

import argparse
import csv
import json
import logging
import os
import resource
import signal
import time
from collections import deque
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from tqdm import tqdm

from affordplan.checks import is_finite, require_probability, require_whole
from affordplan.errors import InputError
from affordplan.log import cli_logging, one_line_errors
from primitives import weights_file
from primitives.networks import HybridActorCritic
from primitives.training import checkpoint as ckpt
from primitives.training.env import PRIMITIVES, EnvConfig, PrimitiveEnv, check_objects
from primitives.training.hindsight import relabel
from primitives.training.provenance import recorded_path
from primitives.training.replay import ReplayBuffer
from primitives.training.rollouts import BACKENDS, Exploration, act, import_ray, make_source, rss_mb

logger = logging.getLogger(__name__)

PRECISIONS = ("fp32", "bf16")


@dataclass
class TrainConfig:
    primitive: str = "push"
    steps: int = 60_000  # environment steps (primitives executed) in total
    workers: int = 1
    backend: str = "local"  # where the workers run: "local" processes or "ray" actors
    ray_address: str | None = None  # None: start a local Ray instance; "auto" or "ray://host:port": a cluster
    seed: int = 0
    out: str = "runs/push"
    max_minutes: float = 60.0
    n_points: int = 256  # object points per cloud (HACMan: 400); the maps are point-count agnostic
    # What trains: the procedural training split and HACMan's household training meshes (never its unseen ones),
    # each drawn half the time (primitives.training.env.EnvConfig.objects).
    objects: str | tuple[str, ...] = "train+housekeep:training"
    sensor: str = "cameras"  # how the policy sees the object (affordplan.Simulator.point_cloud)
    full_motion: bool = False  # strokes run open-loop, no spin stop or push steering (EnvConfig.full_motion)
    n_objects: int = 500
    p_params: float = 0.75  # share of episodes that ask for a parameter (0: the seed's objective only)
    init: str | None = None  # weights to start from (ignored on --resume)
    batch_size: int = 32
    lr: float = 3e-4
    temperature: float = 0.1  # softmax temperature over the critic map (HACMan: 0.1)
    epsilon: float = 0.1  # uniform contact exploration (HACMan: 0.1)
    motion_noise: float = 0.2  # std of the Gaussian noise on the chosen motion
    p_scripted: float = 0.0  # push only: share of exploring actions replaced by a scripted push
    hindsight: bool = False  # also store each primitive relabelled to other requests (primitives.training.hindsight)
    replay_size: int = 50_000
    learning_starts: int = 1_000
    replay_ratio: float = 8.0  # at most this many sampled transitions per collected one
    actor_delay: int = 2
    weight_sync_updates: int = 50  # send weights to workers every this many updates
    checkpoint_minutes: float = 5.0
    log_every_steps: int = 500
    torch_threads: int = 1
    precision: str = "fp32"  # learner matmuls: "fp32", or "bf16" (autocast; fast where the CPU has AMX)
    # Simulators a rollout environment keeps alive. With 500 training objects a cache of 48 hits ~10 % of the
    # time and saves ~1 ms a step, but holds ~110 MB more and grows as large objects come through: 8 keeps
    # the workers' memory flat (issue 8).
    sim_cache: int = 8


def env_config(cfg: TrainConfig) -> EnvConfig:
    return EnvConfig(cfg.primitive, objects=cfg.objects, n_objects=cfg.n_objects, n_points=cfg.n_points,
                     p_params=cfg.p_params, sim_cache=cfg.sim_cache, sensor=cfg.sensor, full_motion=cfg.full_motion)


def exploration(cfg: TrainConfig) -> Exploration:
    """How the training policy explores (workers and the in-process collector alike)."""
    return Exploration(cfg.temperature, cfg.epsilon, cfg.motion_noise, cfg.p_scripted, cfg.hindsight)


# Settings the command line sets; the others are TrainConfig fields only.
_CLI_SETTINGS = frozenset({"objects", "sensor", "full_motion",
                           "steps", "workers", "max_minutes", "checkpoint_minutes", "lr", "p_params", "p_scripted",
                           "batch_size", "replay_size", "learning_starts", "weight_sync_updates", "n_points",
                           "torch_threads", "replay_ratio", "precision"})


# Settings a resumed run must share with its checkpoint: what it learns, what it sees, what its replay holds.
RESUME_MUST_MATCH = ("primitive", "objects", "n_objects", "sensor", "full_motion", "n_points", "replay_size",
                     "p_params")
# What a checkpoint written before a setting existed ran with (it is missing from its saved configuration).
SETTING_BEFORE_IT_EXISTED = {"full_motion": True}


class RunLock:
    """An exclusive lock on a run folder (``OUT/.lock``, ``fcntl.flock``), held while a run writes there; the
    kernel drops it when the process dies, however it dies, so a killed run never leaves a stale lock."""

    def __init__(self, out: Path):
        import fcntl

        self.path = out / ".lock"
        self._file = open(self.path, "a+")
        try:
            fcntl.flock(self._file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self._file.seek(0)
            holder = self._file.read().strip()[:20]
            self._file.close()
            raise InputError(f"another training run (pid {holder or '?'}) is writing to {out}; wait for it or give "
                             "another --out") from None
        self._file.seek(0)
        self._file.truncate()
        self._file.write(str(os.getpid()))
        self._file.flush()

    def release(self) -> None:
        if not self._file.closed:
            self._file.close()


def check_resume(saved_config: dict, cfg: TrainConfig, path: Path) -> None:
    """Raise :class:`InputError` naming every setting in ``RESUME_MUST_MATCH`` where the checkpoint's run differs."""
    now = asdict(cfg)
    then = {k: saved_config.get(k, SETTING_BEFORE_IT_EXISTED.get(k)) for k in RESUME_MUST_MATCH}
    differ = [f"{_setting(k)} {str(then[k])[:60]} there, {str(now[k])[:60]} now"
              for k in RESUME_MUST_MATCH if _normal(then[k]) != _normal(now[k])]
    if differ:
        raise InputError(f"cannot resume {path}: it is a run with other settings ({'; '.join(differ)}); give "
                         "another --out, or the same settings")


def _normal(value):
    return list(value) if isinstance(value, (list, tuple)) else value


def _setting(name: str) -> str:
    """How to name a setting in an error: its flag where the command line has one, else its field."""
    return f"--{name.replace('_', '-')}" if name in _CLI_SETTINGS else f"TrainConfig.{name}"


def check_config(cfg: TrainConfig) -> None:
    """Raise :class:`InputError` for settings that cannot run: a count or budget out of range, a probability
    outside [0, 1], NaN, missing ``--init`` weights, a backend / workers / address combination, or ``--objects``
    naming held-out objects (:func:`primitives.training.env.check_objects`)."""
    if cfg.primitive not in PRIMITIVES:
        raise InputError(f"unknown primitive {cfg.primitive!r}; expected one of {PRIMITIVES}")
    counts = dict(steps=(cfg.steps, 1), workers=(cfg.workers, 0), batch_size=(cfg.batch_size, 1),
                  replay_size=(cfg.replay_size, cfg.batch_size), learning_starts=(cfg.learning_starts, 0),
                  n_points=(cfg.n_points, 16), torch_threads=(cfg.torch_threads, 1),
                  weight_sync_updates=(cfg.weight_sync_updates, 1), log_every_steps=(cfg.log_every_steps, 1),
                  actor_delay=(cfg.actor_delay, 1), sim_cache=(cfg.sim_cache, 1), n_objects=(cfg.n_objects, 1))
    for name, (value, least) in counts.items():
        require_whole(_setting(name), value, least)
    for name in ("max_minutes", "checkpoint_minutes", "lr", "temperature", "replay_ratio"):
        value = getattr(cfg, name)
        if not is_finite(value) or value <= 0:
            raise InputError(f"{_setting(name)} must be a positive number, got {value!r}")
    for name in ("p_params", "p_scripted", "epsilon"):
        require_probability(_setting(name), getattr(cfg, name))
    if not is_finite(cfg.motion_noise) or cfg.motion_noise < 0:
        raise InputError(f"{_setting('motion_noise')} must be a number >= 0, got {cfg.motion_noise!r}")
    if cfg.init is not None and not Path(cfg.init).is_file():
        raise InputError(f"--init: no weights file at {cfg.init}")
    if cfg.backend not in BACKENDS:
        raise InputError(f"unknown backend {cfg.backend!r}; expected one of {BACKENDS}")
    if cfg.backend == "ray" and cfg.workers < 1:
        raise InputError("the ray backend runs one Ray actor per worker: give --workers 1 or more")
    if cfg.ray_address is not None and cfg.backend != "ray":
        raise InputError("--ray-address needs --backend ray")
    if cfg.precision not in PRECISIONS:
        raise InputError(f"--precision must be one of {PRECISIONS}, got {cfg.precision!r}")
    if cfg.p_scripted > 0.0 and cfg.primitive != "push":
        raise InputError(f"--p-scripted exists for push only (primitives.training.scripted), not {cfg.primitive}")
    check_objects(cfg.objects, fitting=True)


# ---------------------------------------------------------------------------- learning
def bf16_is_fast() -> bool:
    """Whether this CPU runs bfloat16 matmuls natively (AVX512-BF16 or AMX), as oneDNN reports it."""
    try:
        return bool(torch.ops.mkldnn._is_mkldnn_bf16_supported())
    except (AttributeError, RuntimeError):
        return False


def _autocast(cfg: TrainConfig):
    """The learner's forward-pass context: bfloat16 autocast for ``precision="bf16"``, else a no-op."""
    return torch.autocast("cpu", dtype=torch.bfloat16, enabled=cfg.precision == "bf16")


def update(model, opt_critic, opt_actor, batch, cfg: TrainConfig, n_updates: int) -> tuple[float, float | None]:
    obs = torch.from_numpy(batch["obs"])
    idx = torch.from_numpy(batch["index"]).long()
    motion = torch.from_numpy(batch["motion"])
    reward = torch.from_numpy(batch["reward"])
    with _autocast(cfg):
        feats = model.features(obs)  # (B, N, F)
        f_chosen = feats[torch.arange(len(idx)), idx]  # (B, F)
        x = torch.cat([f_chosen, motion.to(f_chosen.dtype)], dim=-1)
        q1, q2 = model.q1(x).squeeze(-1).float(), model.q2(x).squeeze(-1).float()
    critic_loss = F.mse_loss(q1, reward) + F.mse_loss(q2, reward)  # no bootstrapping: one step
    opt_critic.zero_grad()
    critic_loss.backward()
    opt_critic.step()
    actor_loss = None
    if n_updates % cfg.actor_delay == 0:
        with _autocast(cfg):
            f = feats.detach()
            a = model.act_map(f)
            q1_map, q2_map = (q.float() for q in model.q_maps(f, a.to(f.dtype)))
        weights = torch.softmax(torch.minimum(q1_map, q2_map).detach() / cfg.temperature, dim=1)
        loss = -(weights * q1_map).sum(dim=1).mean()  # HACMan: softmax-weighted Q over the map
        opt_actor.zero_grad()
        loss.backward()
        opt_actor.step()
        actor_loss = float(loss.detach())
    return float(critic_loss.detach()), actor_loss


def train(cfg: TrainConfig, resume: bool = False, progress: bool = True) -> dict:
    """Train ``cfg.primitive`` into ``cfg.out`` (see the module docstring); the run holds the folder's lock.

    Raises:
        InputError: bad settings; ``--resume`` into a missing folder or one holding a run with other settings;
            another run holding the folder.
        CheckpointError: a damaged or unsafe checkpoint.
    """
    check_config(cfg)
    out = Path(cfg.out)
    if resume and not out.is_dir():
        raise InputError(f"--resume: no run folder {out} (mistyped?); without --resume a new run starts there")
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} is a file, not a folder")
    out.mkdir(parents=True, exist_ok=True)
    lock = RunLock(out)
    try:
        return _train_locked(cfg, out, resume, progress)
    finally:
        lock.release()


def _train_locked(cfg: TrainConfig, out: Path, resume: bool, progress: bool) -> dict:
    torch.set_num_threads(cfg.torch_threads)
    torch.manual_seed(cfg.seed)
    if cfg.precision == "bf16" and not bf16_is_fast():
        logger.warning("--precision bf16: this CPU has no native bfloat16 (AMX / AVX512-BF16); the learner will be "
                       "slower than with fp32")
    model = HybridActorCritic()
    if cfg.init and not (resume and (out / "checkpoint.pt").exists()):
        from primitives.policy import load_policy

        model.load_state_dict(load_policy(cfg.init, cfg.primitive).state_dict())
    critic_params = [*model.backbone.parameters(), *model.q1.parameters(), *model.q2.parameters()]
    opt_critic = torch.optim.Adam(critic_params, lr=cfg.lr)
    opt_actor = torch.optim.Adam(model.actor.parameters(), lr=cfg.lr)
    replay = ReplayBuffer(cfg.replay_size, cfg.n_points)
    rng = np.random.default_rng(cfg.seed)
    gen = torch.Generator().manual_seed(cfg.seed)
    state = dict(global_step=0, n_updates=0, invalid=0, elapsed=0.0, rss_samples=[])
    ckpt_path = out / "checkpoint.pt"
    if resume and not ckpt_path.exists():
        logger.warning("no checkpoint in %s yet (the run stopped before its first): starting it again from step 0",
                       out)
        resume = False
    elif resume:
        saved = ckpt.load(ckpt_path)  # any skill: check_resume names what differs
        check_resume(saved.get("config", {}), cfg, ckpt_path)
        model.load_state_dict(saved["model"])
        opt_critic.load_state_dict(saved["opt_critic"])
        opt_actor.load_state_dict(saved["opt_actor"])
        replay.load_state(saved["replay"])
        rng.bit_generator.state = saved["rng"]
        gen.set_state(saved["gen"])
        state.update(saved["state"])
        del saved  # its replay copy (~250 MB for 50,000 clouds) is in the buffer now; holding it would add that much
    recorded = dict(asdict(cfg), out=recorded_path(cfg.out), init=cfg.init and recorded_path(cfg.init))
    (out / "config.json").write_text(json.dumps(recorded, indent=2))  # it ships beside the weights: no machine paths

    env, source = None, None
    explore = exploration(cfg)
    if cfg.workers > 0:  # worker seeds are offset by the step count: fresh streams after a resume
        source = make_source(cfg.backend, cfg.workers, env_config(cfg), explore, cfg.seed, state["global_step"],
                             model.state_dict(), ray_address=cfg.ray_address)
    else:
        env = PrimitiveEnv(env_config(cfg), seed=cfg.seed + state["global_step"])

    log_path = out / "log.csv"
    new_log = not log_path.exists() or not resume
    if not new_log:  # rows a killed run logged after its last checkpoint are logged again from there: drop them
        _truncate_log(log_path, state["global_step"])
    log_file = open(log_path, "w" if new_log else "a", newline="")
    log = csv.writer(log_file)
    if new_log:
        log.writerow(["step", "updates", "minutes", "success_recent", "reward_recent", "critic_loss",
                      "actor_loss", "invalid", "steps_per_s", "rss_mb_total"])
    tb = _tensorboard(out)
    recent_success, recent_reward = deque(maxlen=500), deque(maxlen=500)
    critic_loss = actor_loss = float("nan")
    t_start = time.time() - state["elapsed"]
    t_ckpt = time.time()
    last_log_step = state["global_step"]
    t_last_log = time.time()
    bar = tqdm(total=cfg.steps, initial=state["global_step"], disable=not progress, unit="step",
               desc=f"train {cfg.primitive}", mininterval=2.0)

    def add(obs, idx, motion, reward, success, valid, relabelled=False) -> None:
        if relabelled:  # a hindsight copy of the primitive just added: replay only
            replay.add(obs, idx, motion, reward, success)
            return
        state["global_step"] += 1
        bar.update(1)
        if not valid:  # physics guard fired: never learned from
            state["invalid"] += 1
            return
        replay.add(obs, idx, motion, reward, success)
        recent_success.append(success)
        recent_reward.append(reward)

    interrupted = False
    try:
        while state["global_step"] < cfg.steps and (time.time() - t_start) < 60 * cfg.max_minutes:
            # 1. Collect.
            if env is not None:
                obs = env.reset()
                seen = env.seen
                idx, motion = act(model, obs, explore, rng, gen)
                res = env.step(idx, motion)
                add(obs, idx, motion, res.reward, res.success, res.valid)
                if cfg.hindsight:
                    for obs_h, motion_h, reward_h, success_h in relabel(cfg.primitive, env.sim.obj, seen, motion,
                                                                        res.outcome, res.success):
                        add(obs_h, idx, motion_h, reward_h, success_h, True, relabelled=True)
            else:  # whatever the workers have sent; primitives beyond the step budget (and their copies) are dropped
                keep = True
                for transition in source.poll(timeout=0.5 if replay.size < cfg.learning_starts else 0.0):
                    if not transition[6]:
                        keep = state["global_step"] < cfg.steps
                    if keep:
                        add(*transition)
            # 2. Learn, at most replay_ratio samples per collected transition.
            budget = cfg.replay_ratio * (state["global_step"] - state["invalid"]) / cfg.batch_size
            if replay.size >= cfg.learning_starts:
                n = 0
                while state["n_updates"] < budget and n < (4 if env is None else 1 + int(cfg.replay_ratio)):
                    state["n_updates"] += 1
                    n += 1
                    critic_loss, a_loss = update(model, opt_critic, opt_actor,
                                                 replay.sample(cfg.batch_size, rng), cfg, state["n_updates"])
                    actor_loss = a_loss if a_loss is not None else actor_loss
                    if source is not None and state["n_updates"] % cfg.weight_sync_updates == 0:
                        source.push_weights(model.state_dict())
                if n == 0 and env is None:
                    time.sleep(0.01)
            # 3. Log.
            if state["global_step"] - last_log_step >= cfg.log_every_steps:
                minutes = (time.time() - t_start) / 60
                sps = (state["global_step"] - last_log_step) / max(1e-9, time.time() - t_last_log)
                t_last_log = time.time()
                rss = rss_mb() + (source.worker_rss_mb() if source is not None else 0.0)
                state["rss_samples"].append((state["global_step"], minutes, rss))
                succ = float(np.mean(recent_success)) if recent_success else 0.0
                rew = float(np.mean(recent_reward)) if recent_reward else 0.0
                row = [state["global_step"], state["n_updates"], round(minutes, 2), round(succ, 4),
                       round(rew, 4), round(critic_loss, 5), round(actor_loss, 5), state["invalid"],
                       round(sps, 1), round(rss, 1)]
                log.writerow(row)
                log_file.flush()
                if tb is not None:
                    for name, value in zip(["success", "reward", "critic_loss", "actor_loss", "rss_mb"],
                                           [succ, rew, critic_loss, actor_loss, rss]):
                        tb.add_scalar(f"{cfg.primitive}/{name}", value, state["global_step"])
                bar.set_postfix(success=f"{succ:.2f}", reward=f"{rew:.3f}", q_loss=f"{critic_loss:.4f}",
                                rss=f"{rss:.0f}MB", sps=f"{sps:.1f}")
                last_log_step = state["global_step"]
            # 4. Checkpoint.
            if time.time() - t_ckpt >= 60 * cfg.checkpoint_minutes:
                state["elapsed"] = time.time() - t_start
                _save(ckpt_path, model, opt_critic, opt_actor, replay, rng, gen, state, cfg)
                t_ckpt = time.time()
    except KeyboardInterrupt:  # Ctrl-C, or SIGTERM (main turns it into this): keep what was learned
        interrupted = True
    finally:
        # The final checkpoint comes first: whatever else fails on the way out, the run can resume.
        state["elapsed"] = time.time() - t_start
        try:
            _save(ckpt_path, model, opt_critic, opt_actor, replay, rng, gen, state, cfg)
        finally:
            if source is not None:
                source.close()
            bar.close()
            log_file.close()
            if tb is not None:
                tb.close()
            if env is not None:
                env.close()
    trained = state["n_updates"] > 0
    policy_path = out / "policy.pt"
    if trained:
        weights_file.save(policy_path, dict(model=model.state_dict()),
                          weights_file.make_meta(cfg.primitive, "policy", sensor=cfg.sensor, n_points=cfg.n_points,
                                                 steps=state["global_step"], updates=state["n_updates"]))
    else:
        policy_path.unlink(missing_ok=True)
        logger.warning("warning: no updates were made (%s steps, learning starts at %s transitions): no policy.pt "
                       "written; run longer (--steps) or lower --learning-starts",
                       state["global_step"], cfg.learning_starts)
    summary = dict(primitive=cfg.primitive, steps=state["global_step"], updates=state["n_updates"],
                   minutes=state["elapsed"] / 60, invalid=state["invalid"], trained=trained, interrupted=interrupted,
                   peak_rss_mb_learner=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                   rss_samples=state["rss_samples"])
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    return summary


def _truncate_log(path: Path, step: int) -> None:
    """Keep the header and the rows of ``log.csv`` at or before ``step`` (atomic rewrite)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    kept = rows[:1] + [r for r in rows[1:] if r and r[0].isdigit() and int(r[0]) <= step]
    tmp = path.with_suffix(".csv.tmp")
    with open(tmp, "w", newline="") as f:
        csv.writer(f).writerows(kept)
    os.replace(tmp, path)


def _save(path, model, opt_critic, opt_actor, replay, rng, gen, state, cfg) -> None:
    ckpt.save(path, dict(model=model.state_dict(), opt_critic=opt_critic.state_dict(),
                         opt_actor=opt_actor.state_dict(), replay=replay.state(), rng=rng.bit_generator.state,
                         gen=gen.get_state(), state=state, config=asdict(cfg)),
              weights_file.make_meta(cfg.primitive, "checkpoint", sensor=cfg.sensor, n_points=cfg.n_points))


def _tensorboard(out: Path):
    try:
        from torch.utils.tensorboard import SummaryWriter
    except ImportError:  # tensorboard not installed: CSV logs only
        return None
    return SummaryWriter(str(out / "tb"))


class _HelpFormatter(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
    """--help keeps the epilog's layout and shows every default."""


def _raise_interrupt(signum, frame) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m primitives.train",
        description="Train a primitive (push, roll or spin) with a hybrid actor-critic on point clouds.",
        epilog="examples:\n"
               "  python -m primitives.train push --steps 60000 --workers 1 --out runs/push\n"
               "  python -m primitives.train push --out runs/push --resume      # after a crash\n"
               "  python -m primitives.train roll --steps 2000 --workers 0 --out /tmp/roll  # reproducible\n"
               "  python -m primitives.train push --backend ray --workers 4 --out runs/push  # local Ray instance\n"
               "  python -m primitives.train push --backend ray --ray-address auto --workers 32  # Ray cluster\n"
               "see docs/training.md",
        formatter_class=_HelpFormatter,
    )
    d = TrainConfig()
    p.add_argument("primitive", choices=PRIMITIVES)
    p.add_argument("--objects", default=d.objects,
                   help="what trains: train (procedural), housekeep:training (HACMan's household training meshes), "
                        "seed7, joined by +")
    p.add_argument("--sensor", choices=("cameras", "surface"), default=d.sensor,
                   help="how the policy sees the object: depth cameras, or the privileged surface sample")
    p.add_argument("--full-motion", action="store_true",
                   help="every stroke runs its commanded motion open-loop: spins by an angle do not stop at the angle "
                        "and pushes are not steered (as the files trained before 2026-12-06 were)")
    p.add_argument("--steps", type=int, default=d.steps, help="primitives to execute (default: %(default)s)")
    p.add_argument("--workers", type=int, default=d.workers,
                   help="rollout workers (processes, or Ray actors with --backend ray); 0 = in-process")
    p.add_argument("--backend", choices=BACKENDS, default=d.backend,
                   help="where the workers run: local processes or Ray actors (default: %(default)s)")
    p.add_argument("--ray-address", default=None,
                   help="Ray cluster to join: 'auto' (this node ran `ray start`) or 'ray://HOST:10001'; "
                        "default: start a local Ray instance")
    p.add_argument("--seed", type=int, default=d.seed)
    p.add_argument("--out", default=None, help="run folder (default: runs/PRIMITIVE)")
    p.add_argument("--resume", action="store_true", help="continue from OUT/checkpoint.pt")
    p.add_argument("--max-minutes", type=float, default=d.max_minutes,
                   help="wall-time budget of the whole run; a --resume counts the minutes already run")
    p.add_argument("--p-params", type=float, default=d.p_params,
                   help="share of episodes that ask for a parameter (default: %(default)s; 0 = seed objective)")
    p.add_argument("--p-scripted", type=float, default=d.p_scripted,
                   help="push only: share of exploring actions replaced by a scripted push along the line "
                        "through the cloud's centre (primitives.training.scripted; default: %(default)s)")
    p.add_argument("--hindsight", action="store_true",
                   help="also store each primitive relabelled to the request it achieved and to the seed's "
                        "objective (primitives.training.hindsight)")
    p.add_argument("--init", default=None, help="start from these weights (e.g. primitives/weights/push.pt)")
    p.add_argument("--batch-size", type=int, default=d.batch_size)
    p.add_argument("--lr", type=float, default=d.lr)
    p.add_argument("--replay-size", type=int, default=d.replay_size)
    p.add_argument("--learning-starts", type=int, default=d.learning_starts)
    p.add_argument("--checkpoint-minutes", type=float, default=d.checkpoint_minutes)
    p.add_argument("--weight-sync-updates", type=int, default=d.weight_sync_updates,
                   help="send the weights to the workers every this many updates (default: %(default)s)")
    p.add_argument("--n-points", type=int, default=d.n_points)
    p.add_argument("--torch-threads", type=int, default=d.torch_threads, help="learner threads")
    p.add_argument("--replay-ratio", type=float, default=d.replay_ratio,
                   help="sampled transitions per executed primitive; updates = ratio / batch size per "
                        "primitive (default: %(default)s)")
    p.add_argument("--precision", choices=PRECISIONS, default=d.precision,
                   help="learner arithmetic: fp32, or bf16 autocast (about twice as fast on CPUs with AMX; "
                        "default: %(default)s)")
    return p


@one_line_errors("python -m primitives.train")  # a bad configuration or checkpoint: one line, not a traceback
def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    cli_logging()
    cfg = TrainConfig(
        primitive=args.primitive, objects=args.objects, sensor=args.sensor, full_motion=args.full_motion,
        steps=args.steps, workers=args.workers, backend=args.backend,
        ray_address=args.ray_address, seed=args.seed,
        out=args.out or f"runs/{args.primitive}", max_minutes=args.max_minutes, batch_size=args.batch_size,
        lr=args.lr, replay_size=args.replay_size, learning_starts=args.learning_starts,
        checkpoint_minutes=args.checkpoint_minutes, n_points=args.n_points, torch_threads=args.torch_threads,
        p_params=args.p_params, p_scripted=args.p_scripted, hindsight=args.hindsight, init=args.init,
        weight_sync_updates=args.weight_sync_updates, replay_ratio=args.replay_ratio,
        precision=args.precision,
    )
    try:
        check_config(cfg)
        if cfg.backend == "ray":
            import_ray()  # the optional dependency: fail now, saying how to install it
    except (InputError, ImportError) as exc:
        parser.error(str(exc))
    signal.signal(signal.SIGTERM, _raise_interrupt)  # a polite kill stops like Ctrl-C: checkpoint, then exit
    signal.signal(signal.SIGINT, signal.default_int_handler)  # also when started in the background (SIG_IGN)
    summary = train(cfg, resume=args.resume)
    print(json.dumps({k: v for k, v in summary.items() if k != "rss_samples"}, indent=2))
    if summary["interrupted"]:
        logger.warning("interrupted at step %s: checkpoint saved; continue with --resume --out %s",
                       summary["steps"], cfg.out)
        return 130
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
