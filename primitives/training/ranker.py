"""Fitting a frame search's option ranker: every option of training starts executed, then a small MLP.

    python -m primitives.training.ranker collect spin --starts 400 --params none --out runs/spin_opts_none
    python -m primitives.training.ranker collect spin --starts 800 --params random --out runs/spin_opts_random
    python -m primitives.training.ranker fit spin runs/spin_opts_none runs/spin_opts_random --out runs/spin_ranker.pt
    python -m primitives.training.ranker attach spin --ranker runs/spin_ranker.pt --out candidates/spin_ranked
    python -m primitives.training.ranker calibrate spin --rollouts 2400 --workers 2 --out candidates/spin_rank_reported

**collect** draws stable starts of training objects (``--objects``, never held-out ones) and, for each, executes
the policy in *every* option the frame search rates (each free frame of the request and of each stand-in request,
:meth:`primitives.frames.FrameSearch.options`), restoring the simulator to the start before each. It records per
option what the ranker reads (:func:`primitives.option_ranker.option_features`' inputs), whether it succeeded,
and the start's object (its catalogue key; empty in chunks collected before it was recorded).
Starts come in chunks of ``--chunk``, each from an environment seeded by ``(seed, chunk)`` and written to its own
``chunk_NNNN.npz`` when done: a collection killed at any moment resumes at its first missing chunk, and gives the
same data as one never stopped.

**fit** trains :class:`primitives.option_ranker.OptionRanker` (an ensemble of ``--members`` MLPs) with a binary
cross-entropy on the options of the collected starts, a fifth of the starts (drawn with ``--seed``) held out; it
chooses the epoch whose held-out *pick* (the success of the option it would act in, averaged over the held-out
starts) is highest, reports that pick beside the success model's pick, the best option and an option at random,
and saves a ranker trained afresh on every start for that many epochs (``--no-refit``: the chosen epoch's own).
The training is a few minutes of one core; nothing of it is checkpointed.

**attach** writes a frame search that acts on a ranker: the shipped frame search for ``--sensor`` (or ``--frames``)
with the ranker's file named in it, both into the folder ``--out`` (``{skill}_frames.json``, ``{skill}_ranker.pt``),
ready for ``--frames`` of the evaluation commands or for ``weights/{sensor}/``.

**calibrate** makes a ranked frame search report its ranker's score of the option it picks as the skill's success
probability: it collects ``--rollouts`` frame-searched rollouts of training objects with the search (``--frames``,
default the shipped one for ``--sensor``), records the ranker's raw score of each pick, fits the Platt scaling
``ranker_platt`` of those scores to the outcomes (:attr:`primitives.frames.FrameSearch.ranker_platt`), and writes the
search with it and ``reports_rating`` set (and its ranker) into ``--out``, as **attach** does. The ranker reads the
policy's decision in every option, so it tells one start's options apart where a searched model, which sees the goal
frame alone, cannot. A few minutes of two cores; nothing of it is checkpointed.
"""

from __future__ import annotations

import argparse
import json
import shutil
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import torch
from torch import nn
from tqdm import tqdm

from affordplan.checks import is_whole
from affordplan.errors import InputError
from affordplan.log import cli_logging, one_line_errors
from affordplan.sim.sensor import SENSORS
from primitives.frames import FrameSearch, load_frame_search
from primitives.option_ranker import (
    N_FEATURES,
    OptionRanker,
    cloud_extents,
    load_ranker,
    option_features,
    request_size,
    save_ranker,
)
from primitives.training.env import PRIMITIVES, EnvConfig, PrimitiveEnv, check_objects
from primitives.training.evaluate import load_policy
from primitives.training.options import execute_every_option
from primitives.training.provenance import recorded_path, recorded_paths
from primitives.training.success import (
    SuccessModel,
    auroc,
    collect_frame_search,
    collect_parallel,
    fit_frame_calibration,
    load_success_net,
    metrics,
)
from primitives.weights_file import rating_path

COLUMNS = ("start", "object", "decision", "rating", "request", "parameterised", "stand_in", "extents", "success",
           "chosen")


def start_rows(env: PrimitiveEnv, model: SuccessModel, search: FrameSearch) -> dict[str, np.ndarray]:
    """Every option of ``env``'s current start executed from it (:func:`execute_every_option`): the per-option
    columns of :data:`COLUMNS` but ``start`` and ``object``. ``chosen`` marks the option the search without a
    ranker acts in."""
    skill, seen = env.config.primitive, env.seen
    done = execute_every_option(env, model.policy, search)
    ratings = search.rate(done.options, model.predict)
    chosen = np.zeros(len(done), dtype=bool)
    chosen[done.row(*search.choose(done.options, ratings)[:2])] = True
    return dict(decision=done.decision, rating=np.concatenate(ratings),
                request=np.array([request_size(skill, done.options[k][0].params) for k in done.option]),
                parameterised=done.parameterised, stand_in=done.option > 0,
                extents=np.tile(cloud_extents(seen.obs[:, :3]), (len(done), 1)),
                success=done.success, chosen=chosen)


def collect(skill: str, out: str | Path, starts: int, params: str = "none", objects: str = "train+housekeep:training",
            sensor: str = "cameras", seed: int = 0, chunk: int = 25, progress: bool = True) -> Path:
    """Collect ``starts`` starts (module docstring) into the folder ``out``; returns it. ``params``: ``"none"``
    (the seed's objective) or ``"random"`` (a random request each start)."""
    if starts < 1 or chunk < 1:
        raise InputError(f"--starts and --chunk must be positive whole numbers, got {starts} and {chunk}")
    if params not in ("none", "random"):
        raise InputError(f"--params must be none or random, got {params!r}")
    check_objects(objects, fitting=True)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    policy = load_policy(None, skill, sensor)
    model = SuccessModel(policy, load_success_net(skill, None, sensor))
    search = load_frame_search(skill, "shipped", sensor)
    config = EnvConfig(skill, objects=objects, episodes_per_object=1, p_params=1.0 if params == "random" else 0.0,
                       sensor=sensor)
    n_chunks = -(-starts // chunk)
    done = sum(chunk for c in range(n_chunks) if (out / f"chunk_{c:04d}.npz").exists())
    bar = tqdm(total=starts, initial=min(done, starts), desc=f"{skill} options", unit="start", disable=not progress,
               mininterval=2.0)
    for c in range(n_chunks):
        path = out / f"chunk_{c:04d}.npz"
        if path.exists():
            continue
        env = PrimitiveEnv(config, seed=int(np.random.SeedSequence([seed, c]).generate_state(1)[0]))
        rows: dict[str, list] = {key: [] for key in COLUMNS}
        for s in range(c * chunk, min((c + 1) * chunk, starts)):
            env.reset()
            got = start_rows(env, model, search)
            for key, value in got.items():
                rows[key].append(value)
            rows["start"].append(np.full(len(got["success"]), s))
            rows["object"].append(np.full(len(got["success"]), str(env.object_key)))
            bar.update(1)
        env.close()
        tmp = path.with_name(path.name + ".tmp")  # not chunk_*.npz: a write killed half-way is never read
        with open(tmp, "wb") as f:
            np.savez(f, **{key: np.concatenate(v) for key, v in rows.items()},
                     meta=np.array(json.dumps(dict(skill=skill, params=params, objects=objects, sensor=sensor,
                                                   seed=seed, chunk=chunk))))
        tmp.replace(path)
    bar.close()
    return out


def read_collections(skill: str, folders: list[str | Path]) -> tuple[dict[str, np.ndarray], str]:
    """The rows of every chunk in ``folders`` (each start numbered apart across folders) and their sensor.

    Raises:
        InputError: a folder without chunks, chunks of another skill, or of different sensors.
    """
    rows: dict[str, list] = {key: [] for key in COLUMNS}
    sensors, offset = set(), 0
    for folder in folders:
        chunks = sorted(Path(folder).glob("chunk_*.npz"))
        if not chunks:
            raise InputError(f"{folder}: no collected chunks (chunk_NNNN.npz) there")
        for path in chunks:
            with np.load(path) as d:
                meta = json.loads(str(d["meta"]))
                if meta["skill"] != skill:
                    raise InputError(f"{path} holds {meta['skill']} options, not {skill}")
                sensors.add(meta["sensor"])
                for key in COLUMNS:
                    if key == "object" and key not in d.files:  # chunks collected before objects were recorded
                        rows[key].append(np.full(len(d["start"]), ""))
                    else:
                        rows[key].append(d[key] + offset if key == "start" else d[key])
        offset = int(max(r.max() for r in rows["start"])) + 1
    if len(sensors) != 1:
        raise InputError(f"the collections mix sensors ({', '.join(sorted(sensors))}); fit one ranker per sensor")
    return {key: np.concatenate(v) for key, v in rows.items()}, sensors.pop()


def features_of(rows: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(features, success, start)`` of collected rows, the features made start by start
    (:func:`option_features`)."""
    starts = rows["start"]
    features = np.zeros((len(starts), N_FEATURES), dtype=np.float32)
    for s in np.unique(starts):
        m = starts == s
        features[m] = option_features(rows["decision"][m], rows["rating"][m], rows["request"][m],
                                      rows["parameterised"][m], rows["stand_in"][m], rows["extents"][m][0])
    return features, rows["success"].astype(np.float32), starts


def pick_figures(score: np.ndarray, success: np.ndarray, starts: np.ndarray) -> dict[str, float]:
    """Over the starts: the success of the option ``score`` ranks highest (``pick``), of the best and of a random
    option, and the within-start AUROC of ``score`` over the starts whose options both succeed and fail."""
    picks, best, rand, aucs = [], [], [], []
    for s in np.unique(starts):
        m = starts == s
        y, p = success[m], score[m]
        picks.append(y[int(np.argmax(p))]), best.append(y.max()), rand.append(y.mean())
        if 0 < y.sum() < len(y):
            aucs.append(auroc(p, y.astype(bool)))
    return dict(starts=len(picks), pick=float(np.mean(picks)), best=float(np.mean(best)),
                random=float(np.mean(rand)), within_start_auroc=float(np.mean(aucs)) if aucs else float("nan"))


def _train(x: np.ndarray, y: np.ndarray, epochs: int, width: int, members: int, weight_decay: float, seed: int,
           progress: bool, desc: str, judge=None) -> tuple[OptionRanker, list[float]]:
    """An :class:`OptionRanker` of ``members`` MLPs trained side by side for ``epochs`` epochs of a binary
    cross-entropy on ``(x, y)`` (each member its own initialisation and batch order, from ``seed``), and
    ``judge(ranker)`` after each epoch where given."""
    torch.manual_seed(seed)
    ranker = OptionRanker(width, members)
    ranker.mean.copy_(torch.from_numpy(x.mean(axis=0)))
    ranker.scale.copy_(torch.from_numpy(x.std(axis=0) + 1e-6))
    xt, yt = ranker.standardise(torch.from_numpy(x)), torch.from_numpy(y)  # once, not per batch
    opts = [torch.optim.AdamW(net.parameters(), lr=1e-3, weight_decay=weight_decay) for net in ranker.nets]
    loss_fn = nn.BCEWithLogitsLoss()
    judged = []
    for _ in tqdm(range(epochs), desc=desc, disable=not progress):
        ranker.train()
        for net, opt in zip(ranker.nets, opts):
            for batch in torch.randperm(len(xt)).split(256):
                opt.zero_grad()
                loss_fn(net(xt[batch]).squeeze(-1), yt[batch]).backward()
                opt.step()
        ranker.eval()
        if judge is not None:
            judged.append(judge(ranker))
    return ranker, judged


def fit(skill: str, folders: list[str | Path], out: str | Path, seed: int = 0, epochs: int = 20, width: int = 64,
        members: int = 5, weight_decay: float = 1e-4, refit: bool = True, progress: bool = True) -> dict:
    """Fit and save an option ranker on collected options (module docstring); returns what it printed.

    A fifth of the starts (drawn with ``seed``) is held out to choose the number of epochs (the one whose held-out
    pick is highest) and to report the figures; with ``refit`` the saved ranker is then trained afresh on every
    start for that many epochs, otherwise it is the ranker of the chosen epoch, fitted without the held-out starts.
    """
    t0 = time.perf_counter()
    rows, sensor = read_collections(skill, folders)
    x, y, starts = features_of(rows)
    rng = np.random.default_rng(seed)
    ids = np.unique(starts)
    if len(ids) < 2:
        raise InputError(f"fitting a ranker needs at least 2 collected starts (one is held out), got {len(ids)}")
    if epochs < 1 or width < 1 or members < 1:
        raise InputError(f"--epochs, --width and --members must be positive, got {epochs}, {width} and {members}")
    held = np.isin(starts, rng.choice(ids, size=max(1, len(ids) // 5), replace=False))
    states: list[dict] = []

    def judge(ranker: OptionRanker) -> float:
        states.append({k: v.clone() for k, v in ranker.state_dict().items()})
        return pick_figures(ranker.score(x[held]), y[held], starts[held])["pick"]

    ranker, picks = _train(x[~held], y[~held], epochs, width, members, weight_decay, seed, progress,
                           f"{skill} ranker", judge)
    best_epoch = int(np.argmax(picks)) + 1
    ranker.load_state_dict(states[best_epoch - 1])
    figures = dict(held_out=pick_figures(ranker.score(x[held]), y[held], starts[held]),
                   ratings_held_out=pick_figures(rows["rating"][held], y[held], starts[held]),
                   search_pick_held_out=float(np.mean([rows["success"][held & (starts == s) & rows["chosen"]].any()
                                                       for s in np.unique(starts[held])])),
                   train=pick_figures(ranker.score(x[~held]), y[~held], starts[~held]))
    if refit:
        ranker, _ = _train(x, y, best_epoch, width, members, weight_decay, seed, progress, f"{skill} refit")
    info = dict(command=" ".join(["python -m primitives.training.ranker fit", skill, *recorded_paths(folders),
                                  "--out", recorded_path(out), "--seed", str(seed), "--epochs", str(epochs),
                                  "--width", str(width), "--members", str(members),
                                  *([] if refit else ["--no-refit"])]),
                starts=int(len(ids)), options=int(len(y)), epoch=best_epoch, members=members, refit=refit,
                sensor=sensor, minutes=round((time.perf_counter() - t0) / 60.0, 2), **figures)
    save_ranker(out, ranker, skill, sensor, info)
    return info


def attach(skill: str, ranker: str | Path, out: str | Path, frames: str = "shipped",
           sensor: str = "cameras") -> Path:
    """Write ``frames`` (``"shipped"``: the shipped frame search for ``sensor``'s clouds, or a frames.json path)
    acting on ``ranker`` into the folder ``out`` (module docstring); returns the frames file written."""
    load_ranker(ranker, skill)  # refuses a file that is not a ranker for skill before anything is written
    search = load_frame_search(skill, frames, sensor, ranked=False)  # the ranker it names, if any, is replaced
    return _write_search(skill, search, Path(ranker), out)


def calibrate(skill: str, out: str | Path, rollouts: int = 2400, objects: str = "train+housekeep:training",
              seed: int = 0, workers: int = 1, frames: str = "shipped", sensor: str = "cameras",
              progress: bool = True) -> tuple[Path, dict]:
    """Write ``frames`` (``"shipped"``: the shipped frame search for ``sensor``'s clouds, or a frames.json path; it
    must carry a ranker) reporting its ranker's calibrated score into the folder ``out`` (module docstring); returns
    the frames file written and what the calibration measured (also in the file's ``info["ranker_calibration"]``)."""
    if not (is_whole(rollouts) and rollouts >= 1 and is_whole(workers) and workers >= 1):
        raise InputError(f"--rollouts and --workers must be positive whole numbers, got {rollouts!r} and {workers!r}")
    check_objects(objects, fitting=True)
    search = load_frame_search(skill, frames, sensor)
    if search.ranker is None:
        raise InputError(f"{skill}'s frame search {frames!r} ({sensor}) has no option ranker to calibrate")
    t0 = time.perf_counter()
    raw = replace(search, ranker_platt=(1.0, 0.0))  # scores each pick by the ranker's raw score
    model = SuccessModel(load_policy(None, skill, sensor=sensor), load_success_net(skill, None, sensor=sensor))
    parts = collect_parallel(collect_frame_search, (model, skill), rollouts, seed, workers, progress=progress,
                             search=raw, split=objects, sensor=sensor)
    score = np.concatenate([q for q, _ in parts])
    success = np.concatenate([data.success for _, data in parts])
    a, b = fit_frame_calibration(score, success)
    calibrated = replace(search, ranker_platt=(a, b), reports_rating=True)
    info = dict(rollouts=rollouts, objects=objects, seed=seed, workers=workers, sensor=sensor,
                success_rate=float(success.mean()), raw=metrics(score, success),
                calibrated=metrics(calibrated.calibrate(score), success),
                minutes=(time.perf_counter() - t0) / 60,
                command=f"python -m primitives.training.ranker calibrate {skill} --rollouts {rollouts} --seed {seed}"
                        + (f" --workers {workers}" if workers > 1 else "")
                        + (f" --objects {objects}" if objects != "train+housekeep:training" else "")
                        + (f" --frames {recorded_path(frames)}" if frames != "shipped" else "")
                        + (f" --sensor {sensor}" if sensor != "cameras" else ""))
    calibrated = replace(calibrated, info=dict(search.info, ranker_calibration=info))
    beside = rating_path(skill, "frames", sensor) if frames == "shipped" else Path(frames)  # where its ranker is
    return _write_search(skill, calibrated, beside.parent / search.ranker_file, out), info


def _write_search(skill: str, search: FrameSearch, ranker: Path, out: str | Path) -> Path:
    """Write ``search`` into the folder ``out`` as ``{skill}_frames.json``, acting on a copy of the ranker file
    ``ranker`` beside it (``{skill}_ranker.pt``); returns the frames file written."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    name = f"{skill}_ranker.pt"
    if ranker.resolve() != (out / name).resolve():
        shutil.copyfile(ranker, out / name)
    path = out / f"{skill}_frames.json"
    replace(search, ranker_file=name, ranker=load_ranker(out / name, skill)).save(path)
    return path


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m primitives.training.ranker", description=__doc__.split("\n\n")[0],
                                epilog="\n".join(__doc__.split("\n\n")[1].splitlines()),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    c = sub.add_parser("collect", help="execute every option of training starts")
    c.add_argument("skill", choices=PRIMITIVES)
    c.add_argument("--starts", type=int, default=400, help="starts (default: 400)")
    c.add_argument("--params", choices=["none", "random"], default="none",
                   help="none: the seed's objective; random: a random request each start (default: none)")
    c.add_argument("--objects", default="train+housekeep:training",
                   help="training objects (default: train+housekeep:training)")
    c.add_argument("--sensor", choices=SENSORS, default="cameras", help="the clouds seen (default: cameras)")
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--chunk", type=int, default=25, help="starts per saved chunk (default: 25)")
    c.add_argument("--out", required=True, help="folder of the chunks (resumed where it holds some)")
    f = sub.add_parser("fit", help="fit an option ranker on collected options")
    f.add_argument("skill", choices=PRIMITIVES)
    f.add_argument("folders", nargs="+", help="collect's --out folders")
    f.add_argument("--out", required=True, help="the ranker file to write")
    f.add_argument("--seed", type=int, default=0)
    f.add_argument("--epochs", type=int, default=20, help="most epochs; the held-out pick chooses (default: 20)")
    f.add_argument("--width", type=int, default=64, help="hidden units per layer (default: 64)")
    f.add_argument("--members", type=int, default=5, help="MLPs in the ensemble (default: 5)")
    f.add_argument("--no-refit", dest="refit", action="store_false",
                   help="save the chosen epoch's ranker fitted without the held-out starts, not one refitted on all")
    f.add_argument("--json", action="store_true")
    a = sub.add_parser("attach", help="write a frame search that acts on a ranker")
    a.add_argument("skill", choices=PRIMITIVES)
    a.add_argument("--ranker", required=True, help="the ranker file (fit's --out)")
    a.add_argument("--frames", default="shipped", help="the frame search to extend (default: the shipped one)")
    a.add_argument("--sensor", choices=SENSORS, default="cameras",
                   help="whose shipped frame search (default: cameras)")
    a.add_argument("--out", required=True, help="folder to write {skill}_frames.json and {skill}_ranker.pt into")
    k = sub.add_parser("calibrate", help="make a ranked frame search report its ranker's calibrated score")
    k.add_argument("skill", choices=PRIMITIVES)
    k.add_argument("--rollouts", type=int, default=2400, help="frame-searched rollouts (default: 2400)")
    k.add_argument("--objects", default="train+housekeep:training",
                   help="training objects (default: train+housekeep:training)")
    k.add_argument("--seed", type=int, default=0)
    k.add_argument("--workers", type=int, default=1, help="processes collecting the rollouts (default: 1)")
    k.add_argument("--frames", default="shipped", help="the ranked frame search (default: the shipped one)")
    k.add_argument("--sensor", choices=SENSORS, default="cameras",
                   help="whose shipped frame search, and the clouds seen (default: cameras)")
    k.add_argument("--out", required=True, help="folder to write {skill}_frames.json and {skill}_ranker.pt into")
    k.add_argument("--json", action="store_true")
    return p


@one_line_errors("python -m primitives.training.ranker")
def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    cli_logging()
    torch.set_num_threads(1)
    if args.command == "collect":
        out = collect(args.skill, args.out, args.starts, args.params, args.objects, args.sensor, args.seed,
                      args.chunk)
        print(f"collected {args.starts} starts of {args.skill} into {out}")
        return 0
    if args.command == "attach":
        print(f"wrote {attach(args.skill, args.ranker, args.out, args.frames, args.sensor)}")
        return 0
    if args.command == "calibrate":
        path, info = calibrate(args.skill, args.out, args.rollouts, args.objects, args.seed, args.workers, args.frames,
                               args.sensor, progress=not args.json)
        if args.json:
            print(json.dumps(info, indent=2))
        else:
            c, r = info["calibrated"], info["raw"]
            print(f"wrote {path}: {info['rollouts']} rollouts, success {info['success_rate']:.3f}; the ranker's "
                  f"score of its pick, raw ECE {r['ece']:.3f}, calibrated ECE {c['ece']:.3f}, Brier {c['brier']:.3f}, "
                  f"AUROC {c['auroc']:.3f}")
        return 0
    info = fit(args.skill, args.folders, args.out, args.seed, args.epochs, args.width, args.members,
               refit=args.refit, progress=not args.json)
    if args.json:
        print(json.dumps(info, indent=2))
    else:
        h, r = info["held_out"], info["ratings_held_out"]
        refitted = ", refitted on every start" if info["refit"] else ""
        print(f"{args.skill} ranker -> {args.out}: {info['starts']} starts, {info['options']} options, epoch "
              f"{info['epoch']}, {info['members']} members{refitted}\n  held-out starts: ranker's pick "
              f"{h['pick']:.3f} (within-start AUROC "
              f"{h['within_start_auroc']:.3f}); the search's pick {info['search_pick_held_out']:.3f}; the ratings' "
              f"best {r['pick']:.3f} ({r['within_start_auroc']:.3f}); best option {h['best']:.3f}, random "
              f"{h['random']:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
