"""Learned success models: ``P(success | point cloud, params)`` for a skill's own policy.

    python -m primitives.success train push --rollouts 6000 --out runs/push_success
    python -m primitives.success evaluate push --rollouts 1500 --plot push_reliability.png

A success model answers "if this skill acts now, with this parameter, will it succeed?" for the
planner, which asks it often. Choices and why:

- **Same input as the policy, plus what the policy would do.** The model sees the observation the
  policy sees (points, normals, goal flow) through a small PointNet (per-point MLP, max- and
  mean-pool), and a summary of the policy's own decision on it: the chosen contact's critic value,
  the spread of the critic map, the contact's position and normal and the chosen motion. These are
  functions of the cloud and the parameter (the policy is deterministic at evaluation), and they
  carry the critic's estimate of the outcome, which the model only has to calibrate and correct.
- **Encoder.** ``--encoder cloud`` (the default, every shipped file): the members' point MLP reads the
  observation. ``--encoder contact``: it reads the cloud as the policy's fingertip meets it, relative to the
  chosen contact with x along the motion (:func:`contact_frame_input`), so that pooling over points can weigh
  the geometry ahead of and beside the push; whether one start succeeds in one frame and fails in another
  hangs on that geometry (``python -m primitives.research.sensitivity``).
- **Ensemble.** ``--members K`` trains K such PointNets from different initialisations and batch
  orders on the same data and averages their logits before calibration: a deep ensemble ranks
  outcomes better than its members (their errors differ), at K times the query cost of the nets,
  which is small beside the policy's decision.
- **Data** are greedy rollouts of the policy on the procedural training split (85 % with a random
  parameter, 15 % the seed's objective); physics-guard failures are dropped as in training. With
  ``--contrast K`` each start is executed in K of the goal frames its request leaves free
  (:func:`collect_contrast`), so the model sees one start succeed in some frames and fail in others: what a
  frame search (:mod:`primitives.frames`) asks of it is to rank one start's frames. With ``--neighbours`` each
  such rollout's label is smoothed: the share of it and its four neighbours (:mod:`primitives.training.neighbours`) that
  succeed, the part of a knife-edge outcome that the cloud and the decision can predict.
- **Ranking.** ``--rank-weight W`` adds W times a pairwise logistic loss over each frame-contrast start's
  (success, failure) pairs to the cross-entropy, on batches of whole starts (:func:`fit`). A frame search picks
  the option its model rates highest, so only the order within one start counts there; ``--rollouts-from`` fits
  on rollouts that earlier runs saved, several files at once.
- **Calibration.** After fitting (binary cross-entropy), Platt scaling (``sigmoid(a z + b)``) is fitted
  on rollouts from held-out *training* objects; figures are reported on the procedural *test* split,
  never seen by the policy or the model: ECE over 10 equal-width bins, Brier score, AUROC.
"""

from __future__ import annotations

import argparse
import json
import os
import textwrap
import time
import zipfile
import zlib
from dataclasses import MISSING, dataclass, fields, replace
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from tqdm import tqdm

from affordplan.errors import InputError
from affordplan.log import cli_logging, one_line_errors
from affordplan.sim.sensor import SENSORS
from primitives import weights_file
from primitives.frames import FrameSearch, load_frame_search, rating_logit, reframe, reframe_obs
from primitives.networks import HybridActorCritic
from primitives.success_model import (  # noqa: F401 (re-exported for training and research code)
    CONTRAST_TURNS,
    ENCODERS,
    N_DECISION,
    SuccessModel,
    SuccessNet,
    contact_frame_input,
    decision_features,
    load_success_net,
    member_input,
)
from primitives.training.env import PRIMITIVES, EnvConfig, PrimitiveEnv, check_objects
from primitives.training.neighbours import neighbour_outcomes
from primitives.training.provenance import recorded_path, recorded_paths


# --------------------------------------------------------------------------------- data
@dataclass
class Rollouts:
    obs: np.ndarray  # (n, N, 9) float16
    decision: np.ndarray  # (n, 13) float32
    success: np.ndarray  # (n,) bool
    group: np.ndarray  # (n,) int: object id (for splits by object)
    parameterised: np.ndarray  # (n,) bool
    # (n,) float32 in [0, 1]: a smoothed label, the share of the decision and its neighbours that succeed
    # (primitives.training.neighbours); None: the outcome itself is the label
    target: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.success)

    def _arrays(self) -> tuple:
        """The columns, in field order (``target`` may be None)."""
        return tuple(getattr(self, f.name) for f in fields(self))

    def subset(self, mask: np.ndarray) -> Rollouts:
        return Rollouts(*(None if a is None else a[mask] for a in self._arrays()))

    def labels(self) -> np.ndarray:
        """What a model is fitted to, float32: the smoothed label where there is one, else the outcome."""
        return (self.success if self.target is None else self.target).astype(np.float32)

    def save(self, path: str | os.PathLike) -> None:
        extra = {} if self.target is None else {"target": self.target}
        np.savez_compressed(path, obs=self.obs, decision=self.decision, success=self.success, group=self.group,
                            parameterised=self.parameterised, **extra)

    @classmethod
    def load(cls, path: str | os.PathLike) -> Rollouts:
        """Rollouts saved by :meth:`save`; a file that is not one raises :class:`InputError`."""
        def refused(why: object) -> InputError:
            return InputError(f"{path} is not a rollouts file saved by success train ({why})")

        try:
            archive = np.load(path)
        except (OSError, ValueError, zipfile.BadZipFile) as exc:  # unreadable, not numpy's, or pickled objects
            raise refused(exc) from exc
        if not isinstance(archive, np.lib.npyio.NpzFile):
            raise refused("a single array, not an archive of columns")
        with archive:
            missing = [f.name for f in fields(cls) if f.default is MISSING and f.name not in archive.files]
            if missing:
                raise refused(f"no {', '.join(missing)}")
            try:
                return cls(*(archive[f.name] if f.name in archive.files else None for f in fields(cls)))
            except (OSError, ValueError, zipfile.BadZipFile, zlib.error) as exc:  # a damaged column
                raise refused(exc) from exc

    @classmethod
    def concat(cls, parts: list[Rollouts]) -> Rollouts:
        """The rollouts of ``parts``, in order (smoothed labels only where every part has them)."""
        columns = list(zip(*(r._arrays() for r in parts)))
        return cls(*(None if any(a is None for a in col) else np.concatenate(col) for col in columns))


def contrast_starts(obs: np.ndarray) -> np.ndarray:
    """The start each rollout of ``obs`` ``(n, N, 9)`` was executed from, as an index ``(n,)`` counting up from 0.

    :func:`collect_contrast` stores one start's rollouts one after another, and every option it executes a start
    in is a turn about the vertical or a mirror of the goal frame, which keeps each point's height (column 2). So a
    start is a run of consecutive rows whose clouds have the same sorted heights; rollouts collected one per start
    (:func:`collect`) are each a start of their own. Needs no extra column, so it reads every cache file written
    before it.
    """
    heights = np.sort(np.asarray(obs[:, :, 2], dtype=np.float32), axis=1)
    new_start = np.r_[True, np.any(heights[1:] != heights[:-1], axis=1)] if len(heights) else np.zeros(0, bool)
    return np.cumsum(new_start) - 1


class _RolloutRows:
    """Rollouts as a collector gathers them, one valid rollout at a time (:meth:`add`), then :meth:`rollouts`."""

    def __init__(self):
        self.obs, self.decision, self.success, self.group, self.parameterised = [], [], [], [], []
        self.target: list[float] = []

    def __len__(self) -> int:
        return len(self.success)

    def add(self, obs: np.ndarray, decision: np.ndarray, success: bool, object_key, parameterised: bool,
            target: float | None = None) -> None:
        """One rollout: the observation acted on ``(N, 9)``, the decision features ``(13,)``, its outcome, the
        object it was on (grouped by a stable hash of the key, for splits by object), whether it had a
        parameter, and optionally its smoothed label (:attr:`Rollouts.target`: give one for every rollout or none)."""
        if target is not None:
            self.target.append(target)
        self.obs.append(obs.astype(np.float16))
        self.decision.append(decision)
        self.success.append(success)
        self.group.append(zlib.crc32(repr(object_key).encode()))
        self.parameterised.append(parameterised)

    def rollouts(self) -> Rollouts:
        if self.target and len(self.target) != len(self.success):
            raise ValueError("a smoothed label must be given for every rollout or for none")
        target = np.array(self.target, dtype=np.float32) if self.target else None
        return Rollouts(np.stack(self.obs), np.stack(self.decision).astype(np.float32), np.array(self.success),
                        np.array(self.group), np.array(self.parameterised), target)


@torch.no_grad()
def collect(policy: HybridActorCritic, skill: str, n: int, split: str = "train", n_objects: int = 500,
            seed: int = 0, p_params: float = 0.85, progress: bool = True, sensor: str = "cameras",
            full_motion: bool = False) -> Rollouts:
    """``n`` valid greedy rollouts of ``policy`` on the objects ``split`` (:attr:`EnvConfig.objects`: a procedural
    split, ``housekeep:SPLIT``, or several joined by ``+``), seen by ``sensor``; ``full_motion``:
    :attr:`EnvConfig.full_motion`."""
    env = PrimitiveEnv(EnvConfig(skill, objects=split, n_objects=n_objects, p_params=p_params,
                                 episodes_per_object=4, sensor=sensor, full_motion=full_motion), seed=seed)
    rows = _RolloutRows()
    bar = tqdm(total=n, desc=f"rollouts {skill} ({split})", disable=not progress, unit="rollout", mininterval=2.0)
    while len(rows) < n:
        obs = env.reset()
        x = torch.from_numpy(obs)[None]
        idx, motion, dec = decision_features(policy, x)
        res = env.step(int(idx[0]), motion[0].numpy().astype(np.float64))
        if not res.valid:
            continue
        rows.add(obs, dec[0].numpy(), res.success, env.object_key, res.params is not None)
        bar.update(1)
    bar.close()
    env.close()
    return rows.rollouts()


@torch.no_grad()
def collect_frame_search(model: SuccessModel, skill: str, n: int, search, split: str = "train",
                         n_objects: int = 500, seed: int = 0, p_params: float = 0.85,
                         progress: bool = True, sensor: str = "cameras",
                         full_motion: bool = False) -> tuple[np.ndarray, Rollouts]:
    """``n`` valid greedy rollouts acting in the frame of ``search`` (:class:`primitives.frames.FrameSearch`)
    that ``model`` rates likeliest.

    Returns the chosen frames' raw ratings ``(n,)`` and the rollouts as seen *in the goal frame* (observation and
    the policy's decision there) with the frame-searched outcome: the data of a searched success model, which
    rates the searched skill from the goal frame alone (:func:`fit`).
    """
    from primitives.policy import greedy_action
    env = PrimitiveEnv(EnvConfig(skill, objects=split, n_objects=n_objects, p_params=p_params,
                                 episodes_per_object=4, sensor=sensor, full_motion=full_motion), seed=seed)
    rating, rows = [], _RolloutRows()
    bar = tqdm(total=n, desc=f"frame-search rollouts {skill} ({split})", disable=not progress, unit="rollout",
               mininterval=2.0)
    while len(rows) < n:
        obs = env.reset()
        env.seen, p = search.select(skill, env.seen, model.predict, env.sim, decide=model.rate_and_decide)
        idx, motion, _ = greedy_action(model.policy, env.seen.obs)
        res = env.step(idx, motion)
        if not res.valid:
            continue
        rating.append(p)
        rows.add(obs, decision_features(model.policy, torch.from_numpy(obs)[None])[2][0].numpy(), res.success,
                 env.object_key, res.params is not None)
        bar.update(1)
    bar.close()
    env.close()
    return np.array(rating), rows.rollouts()


@torch.no_grad()
def collect_contrast(policy: HybridActorCritic, skill: str, n: int, search, per_start: int, split: str = "train",
                     n_objects: int = 500, seed: int = 0, p_params: float = 0.85,
                     progress: bool = True, neighbours: bool = False, sensor: str = "cameras",
                     full_motion: bool = False) -> Rollouts:
    """``n`` valid greedy rollouts of ``policy``, ``per_start`` from each start: the start seen in that many of the
    options ``search`` rates for its request (:meth:`primitives.frames.FrameSearch.options`: its free frames, and
    for the seed's objective with stand-ins each stand-in request in its own free frames), drawn without
    replacement, each executed from the same simulator state (*frame-contrast* rollouts).

    A frame search acts in the option its success model rates likeliest, so what it needs from the model is a
    ranking of one start's options. Goal-frame rollouts show each start once (:func:`collect`); these show the
    model the same start succeeding in some options and failing in others. Every rollout is still a greedy
    rollout of the policy on a start it could meet with that request (each free frame is one, primitives.frames),
    judged by that request's criterion (a stand-in request's own, not the seed's), so the model keeps its
    meaning, ``P(success | observation)``, and its calibration.

    ``neighbours``: also execute each rollout's four neighbours
    (:func:`primitives.training.neighbours.neighbour_decisions`) from the same state and store the share of the
    five that succeed (a guarded execution fails) as the rollout's smoothed label (:attr:`Rollouts.target`).
    One decision's outcome can hang on a few millimetres; the share of its neighbours is what a model of the cloud
    and the decision can predict, so a model fitted to it learns the ranking of one start's options with less
    noise, at five simulations a rollout.
    """
    env = PrimitiveEnv(EnvConfig(skill, objects=split, n_objects=n_objects, p_params=p_params,
                                 episodes_per_object=4, sensor=sensor, full_motion=full_motion), seed=seed)
    rng = np.random.default_rng([seed, 1])  # the options drawn; apart from the environment's own stream
    rows = _RolloutRows()
    bar = tqdm(total=n, desc=f"frame-contrast rollouts {skill} ({split})", disable=not progress, unit="rollout",
               mininterval=2.0)
    while len(rows) < n:
        env.reset()
        sim = env.sim
        start = sim.snapshot()
        options = [(asked, B) for asked, frames in search.options(skill, env.seen, sim) for B in frames]
        for i in rng.choice(len(options), size=min(per_start, len(options)), replace=False):
            if len(rows) == n:
                break
            sim.restore(start)
            env.seen = reframe(*options[i])  # what env.step executes and judges (as collect_frame_search)
            idx, motion, dec = decision_features(policy, torch.from_numpy(env.seen.obs)[None])
            res = env.step(int(idx[0]), motion[0].numpy().astype(np.float64))
            if not res.valid:
                continue
            target = _neighbour_share(env, int(idx[0]), motion[0].numpy(), start, res.success) if neighbours else None
            rows.add(env.seen.obs, dec[0].numpy(), res.success, env.object_key, res.params is not None, target)
            bar.update(1)
    bar.close()
    env.close()
    return rows.rollouts()


def _neighbour_share(env: PrimitiveEnv, index: int, motion: np.ndarray, start, success: bool) -> float:
    """The share of the decision (``index``, goal-frame ``motion``; its outcome ``success``) and its four neighbours
    that succeed, each executed from the simulator state ``start`` and judged as ``env.step`` judges."""
    seen = env.seen
    wins = neighbour_outcomes(env.sim, start, env.config.primitive, seen.params, seen.points[index],
                              seen.normals[index], seen.motion_to_world(motion))
    return (int(success) + sum(wins)) / 5.0


def worker_seed(seed: int, worker: int) -> int:
    """The environment seed of collection worker ``worker``: worker 0 keeps ``seed``, so one worker collects
    exactly what the in-process collector does."""
    return seed + 100_003 * worker


def _collect_share(fn, args: tuple, kwargs: dict):
    torch.set_num_threads(1)
    return fn(*args, **kwargs)


def collect_parallel(fn, args: tuple, n: int, seed: int, workers: int = 1, progress: bool = True, **kwargs):
    """``fn(*args, n_w, seed=worker_seed(seed, w), progress=..., **kwargs)`` (:func:`collect`,
    :func:`collect_contrast` or :func:`collect_frame_search`) for ``w < workers`` in as many processes, their
    shares of ``n`` adding up to ``n``; returns the shares' results in worker order. ``workers=1`` runs in this
    process. A given ``(seed, workers)`` collects the same rollouts every time; another ``workers`` collects
    others."""
    if workers < 1:
        raise InputError(f"workers must be a positive integer, got {workers}")
    shares = [n // workers + (w < n % workers) for w in range(workers)]
    if workers == 1:
        return [fn(*args, n, seed=seed, progress=progress, **kwargs)]
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(workers, mp_context=mp.get_context("spawn")) as pool:
        futures = [pool.submit(_collect_share, fn, (*args, k),
                               dict(kwargs, seed=worker_seed(seed, w), progress=progress and w == 0))
                   for w, k in enumerate(shares) if k > 0]
        return [f.result() for f in futures]


def fit_frame_calibration(rating: np.ndarray, success: np.ndarray) -> tuple[float, float]:
    """``(a, b)`` of the Platt scaling ``sigmoid(a logit(p) + b)`` of the chosen frames' ratings ``p``."""
    z = torch.from_numpy(rating_logit(rating).astype(np.float32))
    a, b = _platt(z, torch.from_numpy(np.asarray(success, dtype=np.float32))).tolist()
    return float(a), float(b)


# ------------------------------------------------------------------------------ metrics
def ece(p: np.ndarray, y: np.ndarray, bins: int = 10) -> float:
    """Expected calibration error over ``bins`` equal-width bins."""
    p, y = np.asarray(p, float), np.asarray(y, float)
    which = np.minimum((p * bins).astype(int), bins - 1)
    total = 0.0
    for b in range(bins):
        m = which == b
        if m.any():
            total += m.mean() * abs(p[m].mean() - y[m].mean())
    return float(total)


def brier(p: np.ndarray, y: np.ndarray) -> float:
    return float(np.mean((np.asarray(p, float) - np.asarray(y, float)) ** 2))


def auroc(p: np.ndarray, y: np.ndarray) -> float:
    """Area under the ROC curve (the Mann-Whitney statistic, ties counted half)."""
    from scipy.stats import rankdata

    y = np.asarray(y, bool)
    n_pos, n_neg = int(y.sum()), int((~y).sum())
    if n_pos == 0 or n_neg == 0:
        return float("nan")
    ranks = rankdata(p)
    return float((ranks[y].sum() - n_pos * (n_pos + 1) / 2) / (n_pos * n_neg))


def metrics(p: np.ndarray, y: np.ndarray) -> dict:
    return dict(n=int(len(y)), success_rate=float(np.mean(y)), mean_prediction=float(np.mean(p)), ece=ece(p, y),
                brier=brier(p, y), auroc=auroc(p, y))


RELIABILITY_TITLE_CHARS = 44  # characters of a reliability diagram's title per line: what its 4.5-inch width holds


def plot_reliability(p: np.ndarray, y: np.ndarray, path: str | os.PathLike, title: str, bins: int = 10) -> str:
    """Reliability diagram: measured success rate per predicted-probability bin, and the bin counts; returns the
    title drawn (``title`` wrapped to the figure's width, then the metrics)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    which = np.minimum((np.asarray(p) * bins).astype(int), bins - 1)
    centres = (np.arange(bins) + 0.5) / bins
    rate = np.array([np.mean(y[which == b]) if np.any(which == b) else np.nan for b in range(bins)])
    count = np.array([np.sum(which == b) for b in range(bins)])
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(4.5, 5.5), sharex=True, gridspec_kw=dict(height_ratios=[3, 1]))
    ax.plot([0, 1], [0, 1], color="grey", linestyle="--", label="perfect calibration")
    ax.bar(centres, rate, width=1 / bins, edgecolor="black", color="#d98c2b", alpha=0.8, label="measured")
    ax.set_ylabel("measured success rate")
    ax.set_ylim(0, 1)
    m = metrics(p, y)
    heading = (f"{textwrap.fill(title, RELIABILITY_TITLE_CHARS)}\n"
               f"ECE {m['ece']:.3f}  Brier {m['brier']:.3f}  AUROC {m['auroc']:.3f}  (n={m['n']})")
    ax.set_title(heading, fontsize=9)
    ax.legend(fontsize=8, loc="upper left")
    ax2.bar(centres, count, width=1 / bins, edgecolor="black", color="#888888")
    ax2.set_xlabel("predicted P(success)")
    ax2.set_ylabel("rollouts")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return heading


# ----------------------------------------------------------------------------- training
@dataclass
class FrameViews:
    """Every rollout seen in each frame of a group its outcome does not depend on.

    A frame-searched skill tries the same set of frames from any of them (:func:`primitives.frames.free_frames`
    returns a group: the turns about the vertical by multiples of 360/n deg, the mirror), picks the same one and
    does the same thing, so a rollout's outcome holds for its cloud seen in any frame of the set. A searched
    success model trained on the rollouts in all of them (``fit(..., views=...)``) learns that invariance from
    the data instead of from 12 times as many rollouts.

    ``frames`` ``(n, m, 3, 3)``: rollout ``i``'s frames, the first ``count[i]`` of them valid (the identity
    first); ``decision`` ``(n, m, 13)``: the policy's decision features in each.
    """

    frames: np.ndarray
    decision: np.ndarray
    count: np.ndarray

    @classmethod
    @torch.no_grad()
    def of(cls, data: Rollouts, policy: HybridActorCritic, skill: str, search,
           progress: bool = True) -> FrameViews:
        """The views of ``data`` (goal-frame rollouts of ``skill`` acting with ``search``)."""
        sets = {par: search.frames(skill, {} if par else None) for par in (True, False)}
        m = max(len(f) for f in sets.values())
        n = len(data)
        frames = np.tile(np.eye(3, dtype=np.float32), (n, m, 1, 1))
        decision = np.zeros((n, m, N_DECISION), np.float32)
        count = np.zeros(n, np.int64)
        for i in tqdm(range(n), desc="frame views", disable=not progress, unit="rollout", mininterval=2.0):
            f = sets[bool(data.parameterised[i])]
            obs = torch.from_numpy(reframe_obs(data.obs[i].astype(np.float32), f))
            frames[i, :len(f)], decision[i, :len(f)], count[i] = f, decision_features(policy, obs)[2].numpy(), len(f)
        return cls(frames, decision, count)

    def subset(self, mask: np.ndarray) -> FrameViews:
        return FrameViews(self.frames[mask], self.decision[mask], self.count[mask])


def fit(data: Rollouts, seed: int = 0, epochs: int = 40, batch_size: int = 128, lr: float = 1e-3,
        calib_fraction: float = 0.2, members: int = 1, progress: bool = True,
        views: FrameViews | None = None, encoder: str = "cloud", rank_weight: float = 0.0) -> tuple[SuccessNet, dict]:
    """Train a :class:`SuccessNet` of ``members`` PointNets (reading the ``encoder``'s input) on rollouts; Platt-scale
    it on a held-out share of their objects. Every member sees the same training split, from its own
    initialisation and batch order.

    ``views``: each training sample is seen in one of its frames drawn anew every epoch (:class:`FrameViews`);
    the calibration share is taken in the goal frame, as the model will be asked.

    ``rank_weight``: for frame-contrast rollouts, add ``rank_weight`` times a within-start ranking loss to the
    binary cross-entropy: each batch holds whole starts (:func:`contrast_starts`; as many as make about
    ``batch_size`` rollouts), and every pair of one start's rollouts where one succeeded and the other failed costs
    ``softplus(z_fail - z_success)`` (a pairwise logistic loss on the logits, averaged over the batch's pairs). A
    frame search needs the model to rank one start's options; cross-entropy alone fits the level across starts,
    which the share of starts that succeed dominates."""
    if not (np.isfinite(rank_weight) and rank_weight >= 0):
        raise InputError(f"rank_weight must be a finite number >= 0, got {rank_weight}")
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    groups = np.unique(data.group)
    calib_groups = rng.choice(groups, size=max(1, int(calib_fraction * len(groups))), replace=False)
    calib_mask = np.isin(data.group, calib_groups)
    train, calib = data.subset(~calib_mask), data.subset(calib_mask)
    net = SuccessNet(members=members, n_decision=data.decision.shape[1], encoder=encoder)
    x = torch.from_numpy(train.obs.astype(np.float32))
    per_batch = encoder != "cloud"  # the contact frame depends on the decision, so on the view: built per batch
    if not per_batch:
        x = SuccessNet.scaled(x)  # scaling commutes with a view's rotation (uniform within each 3-vector)
    dec = torch.from_numpy(train.decision)
    y = torch.from_numpy(train.labels())  # the outcomes, or their smoothed labels where the data carry them
    if views is not None:
        views = views.subset(~calib_mask)
        view_frames = torch.from_numpy(views.frames)
        view_dec = torch.from_numpy(views.decision[..., :net.n_decision])  # as many as the rollouts carry
        view_count = torch.from_numpy(views.count)
    if rank_weight > 0:  # batches of whole starts
        start = torch.from_numpy(contrast_starts(train.obs))
        rows_of = np.split(np.arange(len(start)), np.flatnonzero(np.diff(start.numpy())) + 1)
        starts_per_batch = max(1, round(batch_size * len(rows_of) / max(len(start), 1)))
    bar = tqdm(total=members * epochs, desc="fit success model", disable=not progress, unit="epoch")
    for k, member in enumerate(net.members):
        opt = torch.optim.Adam(member.parameters(), lr=lr, weight_decay=1e-5)
        sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=epochs)
        gen = torch.Generator().manual_seed(seed + 1000 * k)
        member.train()
        for _ in range(epochs):
            if rank_weight > 0:
                order = torch.randperm(len(rows_of), generator=gen).numpy()
                batches = [torch.from_numpy(np.concatenate([rows_of[j] for j in order[i:i + starts_per_batch]]))
                           for i in range(0, len(order), starts_per_batch)]
            else:
                perm = torch.randperm(len(y), generator=gen)
                batches = [perm[i:i + batch_size] for i in range(0, len(y), batch_size)]
            for b in batches:
                xb, db = x[b], dec[b]
                if views is not None:  # each sample in a random frame of its group
                    k = (torch.rand(len(b), generator=gen) * view_count[b]).long()
                    B = view_frames[b, k]
                    xb = torch.einsum("bij,bnkj->bnki", B, xb.view(*xb.shape[:2], -1, 3)).reshape(xb.shape)
                    db = view_dec[b, k]
                if per_batch:
                    xb = net.member_input(xb, db)
                logit = member(xb, db)
                loss = F.binary_cross_entropy_with_logits(logit, y[b])
                if rank_weight > 0:
                    loss = loss + rank_weight * pairwise_rank_loss(logit, y[b], start[b])
                opt.zero_grad()
                loss.backward()
                opt.step()
            sched.step()
            bar.update(1)
    bar.close()
    net.eval()
    with torch.no_grad():
        z = net.logit(torch.from_numpy(calib.obs.astype(np.float32)), torch.from_numpy(calib.decision))
    a_b = _platt(z, torch.from_numpy(calib.success.astype(np.float32)))
    net.platt.copy_(a_b)
    p_cal = torch.sigmoid(a_b[0] * z + a_b[1]).numpy()  # what net(...) now returns on the calibration set
    return net, dict(train=len(train), calibration=len(calib), members=members, encoder=encoder, platt=a_b.tolist(),
                     calibration_metrics=metrics(p_cal, calib.success), frame_views=views is not None,
                     rank_weight=rank_weight)


def pairwise_rank_loss(logit: torch.Tensor, label: torch.Tensor, start: torch.Tensor) -> torch.Tensor:
    """The mean of ``softplus(z_j - z_i)`` over pairs ``(i, j)`` of one start with ``label_i > label_j``: zero when
    no start in the batch has two different labels."""
    pair = (start[:, None] == start[None, :]) & (label[:, None] > label[None, :])
    if not pair.any():
        return logit.new_zeros(())
    return F.softplus(logit[None, :] - logit[:, None])[pair].mean()


def _platt(z: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
    """``(a, b)`` minimising the log-loss of ``sigmoid(a z + b)``."""
    ab = torch.tensor([1.0, 0.0], requires_grad=True)
    opt = torch.optim.LBFGS([ab], lr=0.5, max_iter=200)

    def closure():
        opt.zero_grad()
        loss = F.binary_cross_entropy_with_logits(ab[0] * z + ab[1], y)
        loss.backward()
        return loss

    opt.step(closure)
    return ab.detach()


# ------------------------------------------------------------------------ save and load
def save(net: SuccessNet, path: str | os.PathLike, info: dict, skill: str | None = None,
         sensor: str | None = None) -> None:
    """Write a success net in the safe weights format (:mod:`primitives.weights_file`), for ``skill`` (default:
    ``info["skill"]``) and the clouds of ``sensor`` (default: ``info["sensor"]``, else the depth cameras)."""
    skill = skill or info.get("skill")
    if skill not in PRIMITIVES:
        raise InputError(f"a success model is saved for a skill in {PRIMITIVES}, got {str(skill)[:40]}")
    meta = weights_file.make_meta(skill, "success", sensor=sensor or info.get("sensor", "cameras"))
    weights_file.save(Path(path), dict(model=net.state_dict(), info=info), meta)


def time_calls(predict, obs: np.ndarray, repeats: int, warm_up: int = 1) -> np.ndarray:
    """Seconds of each of ``repeats`` calls ``predict(obs)``, after ``warm_up`` untimed ones (lazy loading, the
    allocator)."""
    for _ in range(warm_up):
        predict(obs)
    times = np.empty(repeats)
    for i in range(repeats):
        t = time.perf_counter()
        predict(obs)
        times[i] = time.perf_counter() - t
    return times


def bench_query(predict, obs: np.ndarray, repeats: int = 200, warm_up: int = 1) -> float:
    """Median seconds of ``predict(obs)`` (e.g. :meth:`SuccessModel.predict`: policy decision + success net) over
    ``repeats`` calls (:func:`time_calls`)."""
    return float(np.median(time_calls(predict, obs, repeats, warm_up)))


# ----------------------------------------------------------------------------------- CLI
def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m primitives.success", description="Train and evaluate a skill's success model.",
        epilog="examples:\n"
               "  python -m primitives.success train push --rollouts 6000 --out runs/push_success\n"
               "  python -m primitives.success evaluate push --rollouts 1500 --plot reliability_push.png",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    for name in ("train", "evaluate"):
        s = sub.add_parser(name)
        s.add_argument("skill", choices=PRIMITIVES)
        s.add_argument("--policy", default=None, help="policy weights (default: the shipped ones)")
        s.add_argument("--rollouts", type=int, default=6000 if name == "train" else 1500)
        s.add_argument("--seed", type=int, default=0 if name == "train" else 4321)
        s.add_argument("--out", default=None, help="folder for rollouts, model, figures (default: runs/SKILL_success)")
        s.add_argument("--json", action="store_true")
    f = sub.add_parser("frames", help="calibrate a frame search (primitives.frames) on training objects")
    f.add_argument("skill", choices=PRIMITIVES)
    f.add_argument("--policy", default=None, help="policy weights (default: the shipped ones)")
    f.add_argument("--model", default=None, help="success model rating the frames (default: shipped)")
    f.add_argument("--turns", type=int, default=12, help="turns about the vertical, where free (default: 12)")
    f.add_argument("--mirror", action="store_true", help="also the mirrored frames, where free")
    f.add_argument("--stand-ins", type=int, default=0, metavar="N",
                   help="for the seed's objective, also try the stand-in requests (primitives.frames): push N "
                        "directions (a multiple of --turns), spin 40 and 45 deg each way, roll every state one roll "
                        "away (N > 0); calibrated on --stand-in-rollouts more rollouts, all for the seed's "
                        "objective; default: none")
    f.add_argument("--stand-in-rollouts", type=int, default=1500)
    f.add_argument("--rollouts", type=int, default=2000)
    f.add_argument("--seed", type=int, default=0)
    f.add_argument("--out", default=None, help="folder for frames.json (default: runs/SKILL_frames)")
    f.add_argument("--json", action="store_true")
    for name in ("train", "frames", "evaluate"):
        default = "test" if name == "evaluate" else "train"
        sub.choices[name].add_argument(
            "--objects", default=default, metavar="OBJECTS",
            help="objects the rollouts are drawn from: train | test (the procedural splits), housekeep:SPLIT (e.g. "
                 "housekeep:training, housekeep:unseen), or several joined by + (each episode draws a group "
                 f"uniformly) (default: {default})")
        sub.choices[name].add_argument(
            "--sensor", choices=SENSORS, default="cameras",
            help="how the skill sees the object (surface: the privileged sample, for ablations) "
                 "(default: %(default)s)")
        sub.choices[name].add_argument(
            "--full-motion", action="store_true",
            help="every stroke runs its commanded motion open-loop: spins by an angle do not stop at the angle and "
                 "pushes are not steered against the object's turn (as every file fitted before 2026-12-06 was "
                 "collected; pushes until 2026-12-07)")
    for name in ("train", "frames"):
        sub.choices[name].add_argument(
            "--workers", type=int, default=1,
            help="processes collecting the rollouts, one torch thread each (default: 1); the rollouts depend on "
                 "--seed and --workers")
    sub.choices["evaluate"].add_argument("--model", default=None, help="success model (default: shipped)")
    sub.choices["evaluate"].add_argument("--frames", default=None, metavar="shipped|PATH",
                                         help="judge the skill acting with this frame search (frames.json, or the "
                                              "shipped one): its calibrated ratings, and the searched success "
                                              "model's beside them")
    sub.choices["evaluate"].add_argument("--searched", default=None, metavar="PATH", nargs="+",
                                         help="with --frames: the searched success model to judge (default: the "
                                              "shipped one, if any); more paths judge others on the same rollouts "
                                              "(reported under other_searched_models; with --plot, a diagram each)")
    sub.choices["train"].add_argument("--frames", default=None, metavar="shipped|PATH",
                                      help="train a searched success model: the skill acts with this frame search "
                                           "(frames.json, or the shipped one), the model rates it from the goal "
                                           "frame")
    sub.choices["train"].add_argument("--views", action="store_true",
                                      help="with --frames: train on every rollout in each frame the search tries "
                                           "(its outcome is the same in all; FrameViews)")
    sub.choices["train"].add_argument("--contrast", type=int, default=0, metavar="K",
                                      help="frame-contrast rollouts (collect_contrast): execute each start in K of "
                                           "the free frames of its request (12 turns about the vertical and the "
                                           "mirror, where free), so the model learns to rank one start's frames "
                                           "as a frame search asks it to; --rollouts counts them all "
                                           "(default: 0, one goal-frame rollout per start)")
    sub.choices["train"].add_argument("--contrast-stand-ins", type=int, default=0, metavar="N",
                                      help="with --contrast: for starts with the seed's objective, also draw from "
                                           "the stand-in requests a frame search with --stand-ins N tries (push: N "
                                           "directions, a multiple of 12; spin, roll: any N > 0), each judged by its "
                                           "own criterion (default: 0, the seed's own frames only)")
    sub.choices["train"].add_argument("--neighbours", action="store_true",
                                      help="with --contrast: also execute each rollout's four neighbours (motion "
                                           "turned 3 deg either way, contact moved 2 mm either way; "
                                           "primitives.training.neighbours) and fit the model to the share of the five "
                                           "that succeed; calibrated on the outcomes themselves")
    sub.choices["train"].add_argument("--rank-weight", type=float, default=0.0, metavar="W",
                                      help="add W times a within-start pairwise ranking loss to the cross-entropy "
                                           "(fit: batches of whole frame-contrast starts); needs --contrast or "
                                           "--rollouts-from (default: 0, cross-entropy alone)")
    sub.choices["train"].add_argument("--rollouts-from", nargs="+", default=None, metavar="NPZ",
                                      help="fit on these saved rollouts (the train_*.npz files earlier train runs "
                                           "wrote), concatenated, instead of collecting; --rollouts and --workers "
                                           "are then not used, and --seed seeds the fit")
    sub.choices["train"].add_argument("--model", default=None,
                                      help="with --frames: the success model that picks the frames (default: shipped)")
    sub.choices["evaluate"].add_argument("--plot", default=None, help="reliability diagram PNG")
    sub.choices["train"].add_argument("--epochs", type=int, default=40)
    sub.choices["train"].add_argument("--encoder", choices=ENCODERS, default="cloud",
                                      help="what the members' point MLP reads: the observation (cloud) or the cloud "
                                           "seen from the policy's contact along its motion (contact; "
                                           "contact_frame_input) (default: %(default)s)")
    sub.choices["train"].add_argument("--members", type=int, default=1,
                                      help="PointNets in the ensemble, their logits averaged (default: %(default)s)")
    return p


@one_line_errors("primitives.training.success")  # missing or broken policy or success model, ...
def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    cli_logging()
    if args.rollouts < 1:
        parser.error(f"--rollouts must be a positive integer, got {args.rollouts}")
    if getattr(args, "views", False) and args.frames is None:
        parser.error("--views needs --frames")
    if getattr(args, "contrast", 0) < 0:
        parser.error(f"--contrast must be a whole number >= 0, got {args.contrast}")
    if getattr(args, "contrast", 0) and args.frames is not None:
        parser.error("--contrast trains a goal-frame success model; --frames a searched one: give one")
    if getattr(args, "contrast_stand_ins", 0) and not args.contrast:
        parser.error("--contrast-stand-ins needs --contrast")
    if getattr(args, "neighbours", False) and not args.contrast:
        parser.error("--neighbours needs --contrast")
    if getattr(args, "rank_weight", 0.0) and not (args.contrast or args.rollouts_from):
        parser.error("--rank-weight needs frame-contrast rollouts: give --contrast or --rollouts-from")
    if not np.isfinite(getattr(args, "rank_weight", 0.0)) or getattr(args, "rank_weight", 0.0) < 0:
        parser.error(f"--rank-weight must be a finite number >= 0, got {args.rank_weight}")
    for path in getattr(args, "rollouts_from", None) or ():
        if not Path(path).is_file():
            parser.error(f"--rollouts-from: no file {path}")
    if getattr(args, "workers", 1) < 1:
        parser.error(f"--workers must be a positive integer, got {args.workers}")
    if getattr(args, "members", 1) < 1:
        parser.error(f"--members must be a positive integer, got {args.members}")
    if getattr(args, "stand_ins", 0) and args.stand_in_rollouts < 1:
        parser.error(f"--stand-in-rollouts must be a positive integer, got {args.stand_in_rollouts}")
    torch.set_num_threads(1)
    return _run(args)


def _run(args: argparse.Namespace) -> int:
    from primitives.policy import load_policy

    check_objects(args.objects, fitting=args.command != "evaluate")
    if args.command == "frames":
        return _run_frames(args)
    contrast = None  # the options a frame-contrast start is executed in (checks --contrast-stand-ins first)
    if args.command == "train" and args.contrast:
        contrast = FrameSearch(CONTRAST_TURNS, mirror=True, stand_ins=args.contrast_stand_ins)
    out = Path(args.out or f"runs/{args.skill}_success")
    out.mkdir(parents=True, exist_ok=True)
    policy = load_policy(args.policy, args.skill, sensor=args.sensor)
    if args.command == "train":
        searched = args.frames is not None
        search = load_frame_search(args.skill, args.frames, sensor=args.sensor) if searched else None
        workers = f"_w{args.workers}" if args.workers > 1 else ""
        stand_ins = f"s{args.contrast_stand_ins}" if args.contrast_stand_ins else ""
        stand_ins += "n" if args.neighbours else ""
        kind = "searched_" if searched else f"contrast{args.contrast}{stand_ins}_" if args.contrast else ""
        cache = out / f"train_{kind}rollouts_{args.rollouts}_{args.seed}{workers}.npz"
        if args.rollouts_from:
            data = Rollouts.concat([Rollouts.load(path) for path in args.rollouts_from])
        elif cache.exists():
            data = Rollouts.load(cache)
        elif contrast is not None:
            data = Rollouts.concat(collect_parallel(
                collect_contrast, (policy, args.skill), args.rollouts, args.seed, args.workers,
                progress=not args.json, search=contrast, per_start=args.contrast, split=args.objects,
                neighbours=args.neighbours, sensor=args.sensor, full_motion=args.full_motion))
        elif searched:
            rater = SuccessModel(policy, load_success_net(args.skill, args.model, sensor=args.sensor))
            data = Rollouts.concat([part[1] for part in collect_parallel(
                collect_frame_search, (rater, args.skill), args.rollouts, args.seed, args.workers,
                progress=not args.json, search=search, split=args.objects, sensor=args.sensor,
                full_motion=args.full_motion)])
        else:
            data = Rollouts.concat(collect_parallel(collect, (policy, args.skill), args.rollouts, args.seed,
                                                    args.workers, progress=not args.json, split=args.objects,
                                                    sensor=args.sensor, full_motion=args.full_motion))
        if not args.rollouts_from:
            data.save(cache)
        views = FrameViews.of(data, policy, args.skill, search, progress=not args.json) if args.views else None
        net, info = fit(data, seed=args.seed, epochs=args.epochs, members=args.members, progress=not args.json,
                        views=views, encoder=args.encoder, rank_weight=args.rank_weight)
        info.update(skill=args.skill, rollouts=len(data) if args.rollouts_from else args.rollouts, seed=args.seed,
                    workers=args.workers, policy=recorded_path(args.policy or "shipped"), objects=args.objects,
                    sensor=args.sensor, full_motion=args.full_motion)
        if args.rollouts_from:
            info.update(rollouts_from=recorded_paths(args.rollouts_from))
        if searched:
            info.update(frames=recorded_path(args.frames), model=recorded_path(args.model or "shipped"))
        if args.contrast:
            info.update(contrast=args.contrast, contrast_stand_ins=args.contrast_stand_ins, neighbours=args.neighbours)
        info["command"] = ("python -m primitives.success train " + args.skill
                           + (f" --policy {recorded_path(args.policy)}" if args.policy else "")
                           + ("" if args.rollouts_from else f" --rollouts {args.rollouts}")
                           + f" --seed {args.seed} --epochs {args.epochs} --members {args.members}"
                           + (f" --contrast {args.contrast}" if args.contrast else "")
                           + (f" --contrast-stand-ins {args.contrast_stand_ins}" if args.contrast_stand_ins else "")
                           + (" --neighbours" if args.neighbours else "")
                           + (f" --frames {recorded_path(args.frames)}" if searched else "")
                           + (" --views" if views else "")
                           + (f" --model {recorded_path(args.model)}" if searched and args.model else "")
                           + (f" --workers {args.workers}" if args.workers > 1 else "")
                           + (f" --encoder {args.encoder}" if args.encoder != "cloud" else "")
                           + (f" --rank-weight {args.rank_weight:g}" if args.rank_weight else "")
                           + (" --rollouts-from " + " ".join(recorded_paths(args.rollouts_from))
                              if args.rollouts_from else "")
                           + _objects_args(args))
        save(net, out / "success.pt", info)
        print(json.dumps(info, indent=2))
        return 0
    net = load_success_net(args.skill, args.model, sensor=args.sensor)  # by default the ratings for those clouds
    model = SuccessModel(policy, net)
    if args.frames is not None:
        return _evaluate_frames(args, model)
    data = collect(policy, args.skill, args.rollouts, args.objects, n_objects=200, seed=args.seed,
                   progress=not args.json, sensor=args.sensor, full_motion=args.full_motion)
    with torch.no_grad():
        p = net(torch.from_numpy(data.obs.astype(np.float32)), torch.from_numpy(data.decision)).numpy()
    result = dict(skill=args.skill, objects=_objects_label(args.objects), sensor=args.sensor,
                  all=metrics(p, data.success),
                  parameterised=metrics(p[data.parameterised], data.success[data.parameterised]),
                  query_ms=1e3 * bench_query(model.predict, data.obs[0].astype(np.float32)))
    if args.plot:
        plot_reliability(p, data.success, args.plot, f"{args.skill} success model, {args.objects}, {args.sensor}")
    print(json.dumps(result, indent=2))
    return 0


def _objects_args(args: argparse.Namespace) -> str:
    """The ``--objects`` / ``--sensor`` / ``--full-motion`` part of a recorded command (empty where they are the
    defaults)."""
    return ((f" --objects {args.objects}" if args.objects != "train" else "")
            + (f" --sensor {args.sensor}" if args.sensor != "cameras" else "")
            + (" --full-motion" if args.full_motion else ""))


def _objects_label(objects: str) -> str:
    """How a report names the objects its rollouts came from."""
    return "test split (never trained on)" if objects == "test" else objects


def _run_frames(args: argparse.Namespace) -> int:
    """``frames``: frame-searched rollouts on training objects, and the Platt scaling of the chosen ratings."""
    from primitives.policy import load_policy

    asked = FrameSearch(args.turns, args.mirror, stand_ins=args.stand_ins)  # checks --turns / --stand-ins first
    search = replace(asked, stand_ins=0)  # the first pass calibrates the frames alone
    out = Path(args.out or f"runs/{args.skill}_frames")
    out.mkdir(parents=True, exist_ok=True)
    model = SuccessModel(load_policy(args.policy, args.skill), load_success_net(args.skill, args.model))
    t0 = time.perf_counter()
    parts = collect_parallel(collect_frame_search, (model, args.skill), args.rollouts, args.seed, args.workers,
                             progress=not args.json, search=search, split=args.objects, sensor=args.sensor,
                             full_motion=args.full_motion)
    rating, data = np.concatenate([r for r, _ in parts]), Rollouts.concat([d for _, d in parts])
    success, par = data.success, data.parameterised
    platt = fit_frame_calibration(rating[par], success[par])
    platt_seed = fit_frame_calibration(rating[~par], success[~par]) if (~par).sum() >= 50 else (1.0, 0.0)
    search = replace(search, platt=platt, platt_unparameterised=platt_seed)
    p = search.calibrate(rating, par)
    info = dict(skill=args.skill, rollouts=args.rollouts, seed=args.seed, workers=args.workers,
                policy=recorded_path(args.policy or "shipped"), objects=args.objects, sensor=args.sensor,
                model=recorded_path(args.model or "shipped"), frames_parameterised=len(search.frames(args.skill, {})),
                frames_seed_objective=len(search.frames(args.skill, None)),
                success_rate=float(success.mean()), parameterised=int(par.sum()), raw=metrics(rating, success),
                calibrated=metrics(p, success), calibrated_parameterised=metrics(p[par], success[par]))
    if asked.stand_ins:  # the seed's objective alone, acting through the stand-ins as well: their own calibration
        search = replace(search, stand_ins=asked.stand_ins)
        parts = collect_parallel(collect_frame_search, (model, args.skill), args.stand_in_rollouts, args.seed,
                                 args.workers, progress=not args.json, search=search, split=args.objects, p_params=0.0,
                                 sensor=args.sensor, full_motion=args.full_motion)
        score, seed_data = np.concatenate([r for r, _ in parts]), Rollouts.concat([d for _, d in parts])
        search = replace(search, platt_stand_ins=fit_frame_calibration(score, seed_data.success))
        info.update(stand_ins=args.stand_ins, stand_in_rollouts=args.stand_in_rollouts,
                    stand_in_success_rate=float(seed_data.success.mean()),
                    stand_in_score=metrics(score, seed_data.success),
                    stand_in_calibrated=metrics(search.calibrate(score, False), seed_data.success))
    info.update(minutes=(time.perf_counter() - t0) / 60,
                command=f"python -m primitives.success frames {args.skill}"
                        f"{f' --policy {recorded_path(args.policy)}' if args.policy else ''}"
                        f"{f' --model {recorded_path(args.model)}' if args.model else ''} --turns {args.turns}"
                        f"{' --mirror' if args.mirror else ''} --rollouts {args.rollouts}"
                        + (f" --stand-ins {args.stand_ins} --stand-in-rollouts {args.stand_in_rollouts}"
                           if args.stand_ins else "") +
                        f" --seed {args.seed}{f' --workers {args.workers}' if args.workers > 1 else ''}"
                        + _objects_args(args))
    search = replace(search, info=info)
    search.save(out / "frames.json")
    print((out / "frames.json").read_text())
    return 0


def _evaluate_frames(args: argparse.Namespace, model: SuccessModel) -> int:
    """``evaluate --frames``: the skill acting with a frame search on unseen objects, judged by two raters on the
    same rollouts: the calibrated rating of the chosen frame, and the searched success model, which rates the
    searched skill from the goal frame alone (the shipped ``{skill}_success_searched.pt``, or ``--searched``)."""
    search = load_frame_search(args.skill, args.frames, sensor=args.sensor)
    rating, data = collect_frame_search(model, args.skill, args.rollouts, search, args.objects, n_objects=200,
                                        seed=args.seed, progress=not args.json, sensor=args.sensor,
                                        full_motion=args.full_motion)
    success, par = data.success, data.parameterised
    p = search.calibrate(rating, par)
    obs = data.obs[0].astype(np.float32)
    frames = search.frames(args.skill, {})
    result = dict(skill=args.skill, objects=_objects_label(args.objects), sensor=args.sensor, frames=args.frames,
                  all=metrics(p, success), parameterised=metrics(p[par], success[par]),
                  seed_objective=metrics(p[~par], success[~par]) if (~par).any() else None,
                  query_ms=1e3 * bench_query(model.predict, reframe_obs(obs, frames)),
                  frames_per_query=len(frames))
    # The skill reports the searched model shipped for the sensor, or, where its search says so, the search's own
    # rating ("all" above): then no searched model is judged unless one is asked for.
    result["reported"] = "frame search" if search.reports_rating else "searched model"
    searched_paths = ([Path(path) for path in args.searched] if args.searched
                      else [] if search.reports_rating
                      else [weights_file.rating_path(args.skill, "searched", args.sensor)])
    obs_all, decision = torch.from_numpy(data.obs.astype(np.float32)), torch.from_numpy(data.decision)
    for i, searched_path in enumerate(searched_paths):
        if not (args.searched or searched_path.exists()):
            break
        searched = SuccessModel(model.policy, load_success_net(args.skill, searched_path))
        with torch.no_grad():
            q_i = searched.net(obs_all, decision).numpy()
        report = dict(path=str(searched_path if i else searched_path.name), all=metrics(q_i, success),
                      parameterised=metrics(q_i[par], success[par]))
        if i == 0:
            result["searched_model"] = dict(report, query_ms=1e3 * bench_query(searched.predict, obs))
        else:
            result.setdefault("other_searched_models", []).append(report)
        if args.plot:  # P_searched.png, then P_searched2.png, ... for the others
            path = Path(args.plot)
            plot_reliability(q_i, success, path.with_name(f"{path.stem}_searched{i + 1 if i else ''}{path.suffix}"),
                             f"{args.skill} searched success model{f' {i + 1}' if i else ''}, {args.objects}, "
                             f"{args.sensor}")
    if args.plot:
        plot_reliability(p, success, args.plot,
                         f"{args.skill} success model, frame search, {args.objects}, {args.sensor}")
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
