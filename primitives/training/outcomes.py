r"""Collect what skill calls do, for the outcome model (:mod:`primitives.outcome_model`), and check that model.

    python -m primitives.training.outcomes collect push --rollouts 600 --objects train+housekeep:training \
        --seed 0 --out push_outcome.npz
    python -m primitives.training.outcomes check push --model primitives/weights/push_outcome.npz \
        --objects housekeep:unseen --rollouts 150 --seed 1 [--json] [--out rows.npz]

**collect**: each rollout draws an object and a stable start as :mod:`primitives.training.evaluate` does (an object
group of ``--objects`` uniformly, an object in it, a resting state by its probability, a position in the middle of
the workspace and a yaw; :class:`primitives.training.env.EnvConfig`), builds a finger :class:`affordplan.Simulator`
showing the skills' sensor (:func:`primitives.skills.skills_sensor`), draws a parameter as the planner asks them
(push ``{"direction": U(-pi, pi)}``; spin ``{"angle": +-U(SPIN_MIN, SPIN_MAX)}``; roll a target among
:func:`primitives.params.roll_targets`, the start skipped when there is none), asks the shipped skill's success
model ``p = skill.success_probability(sim, params)`` (what the planner knows when it plans) and then executes it as
plans do (a spin's full motion, ``stop_at_angle=False``), recording per row (:data:`COLUMNS`):

- ``p``: the strict success probability; ``param``: the parameter's value (radians, or the target state);
- ``success``: the strict criterion (:func:`primitives.rewards.success`) and a valid sample;
- ``made_progress``: the executor's failure criterion (:func:`primitives.params.made_progress`);
- ``progress``: the share of the asked effect achieved: push, displacement along the asked direction over
  ``PUSH_STEP`` (5 cm); spin, the turn in the asked sense over ``|angle|``; roll, 1 when it ended in the asked
  resting state, else 0. A push or spin that left the object in another resting state has progress 0 (the
  planner must replan from that state; the cost of the detour is not modelled);
- ``dx, dy, dyaw``: the SE(2) displacement (push: in the asked direction's frame, ``dx`` along it; otherwise the
  world frame; metres, radians; ``dyaw`` from the resting state's yaw, 0 when the state changed);
- ``state_before``, ``state_after``, ``state_asked`` (roll's target, else the start state), ``valid``,
  ``object`` (an index into the file's ``objects`` names);
- ``state_probability``: the drop probability of ``state_before`` (what the outcome model's tip rate,
  :meth:`primitives.outcome_model.OutcomeModel.p_tip`, is conditioned on).

**annotate**: adds ``state_probability`` to files collected before it was recorded, from their ``objects`` and
``state_before`` (every other column is kept as it was):

    python -m primitives.training.outcomes annotate primitives/weights/push_outcome.npz

The file is a plain ``.npz`` (``np.load(..., allow_pickle=False)`` reads it): the columns, ``objects``, and the
strings ``skill``, ``objects_spec``, ``command``.

**check**: collects fresh rollouts the same way (on objects never collected on) and reports how well the model
(:class:`primitives.outcome_model.OutcomeModel`) predicts them: the coverage of its 10-90 % progress interval
for each rollout's ``p`` (target 0.8), the mean predicted against measured progress, and the accuracy of
``p_progress`` (Brier score, mean predicted vs measured share that made progress).

**Record** (0.24.0.dev0, the 2-core development machine beside two training jobs, ``nice -n 5``, one torch thread,
``MUJOCO_GL=egl``; the shipped skills with their frame search and searched success models, finger pusher):

    for s in push spin roll; do
      nice -n 5 python -m primitives.training.outcomes collect $s --rollouts 600 \
          --objects train+housekeep:training --seed 0 --out primitives/weights/${s}_outcome.npz
    done

- ``push_outcome.npz``: 600 rows on 318 objects (320 household, 280 procedural rows), 0 skipped, 4 invalid;
  207 s collecting (3 min 33 s with loading), 24.1 kB. Strict success 0.293, mean p 0.352, made progress 0.852,
  mean progress 0.854 (p < 0.05: 195 rows, mean progress 0.60, strict success 0.03).
- ``spin_outcome.npz``: 600 rows on 329 objects (283 household rows), 0 skipped, 1 invalid; 157 s (2 min 43 s),
  24.0 kB. Strict success 0.613, mean p 0.827, made progress 0.865, mean progress 0.906.
- ``roll_outcome.npz``: 600 rows on 294 objects (290 household rows), 203 starts skipped (no state one roll away),
  5 invalid; 179 s (3 min 7 s), 18.8 kB. Strict success 0.497, mean p 0.585, made progress 0.502. Recollected
  (2026-12-03, the same command, alone on the machine) for roll's refitted surface policy (``weights/RECORD.md``):
  600 rows on 294 objects, 203 skipped; 116 s. Strict success 0.543, mean p 0.521, made progress 0.558; it records
  the drop probabilities itself, so it needed no annotating.

The three files were then annotated (``annotate primitives/weights/{push,spin,roll}_outcome.npz``, 77 s for the
three, every other column unchanged): 4.2 % of the pushes and 2.2 % of the spins left their resting state; pushes
in states rarer than 0.13 of drops tipped 25 % of the time (15 of 60), none in states above 0.52.

Checked on objects never collected on (the shipped models, 150 rollouts per skill and split, seed 1):

    for s in push spin roll; do for o in housekeep:unseen test; do
      nice -n 5 python -m primitives.training.outcomes check $s --objects $o --rollouts 150 --seed 1 --json \
          --out /tmp/oc/check_${s}_${o#housekeep:}.npz
    done; done

    skill objects           10-90 % coverage (below, above)  progress pred./meas.  Brier: p_progress (strict p)
    push  housekeep:unseen  0.620 (0.147, 0.233)             0.832 / 0.800         0.152 (0.199)
    push  test              0.833 (0.013, 0.153)             0.894 / 1.058         0.035 (0.138)
    spin  housekeep:unseen  0.593 (0.207, 0.200)             0.944 / 0.942         0.158 (0.438)
    spin  test              0.887 (0.040, 0.073)             0.907 / 0.959         0.043 (0.098)
    roll  housekeep:unseen  0.907 (0.067, 0.027)             0.359 / 0.373         0.230 (0.243), accuracy 0.693
    roll  test              0.980 (0.000, 0.020)             0.654 / 0.780         0.116 (0.099), accuracy 0.827

(wall 21-55 s per check; roll skipped 47 and 37 starts.) Roll's recollected file (its refitted surface policy), the
same checks on 2026-12-03:

    roll  housekeep:unseen  0.953 (0.013, 0.033)             0.496 / 0.593         0.198 (0.220), accuracy 0.733
    roll  test              0.980 (0.013, 0.007)             0.740 / 0.727         0.086 (0.115), accuracy 0.880

The intervals are too narrow on the unseen household meshes
(their outcomes spread wider than the training mix's at the same p) and about right on procedural objects; a roll's
progress is 0 or 1, so its interval covers trivially and ``p_progress``'s Brier score is the measure. "strict p":
the success model's p against the strict success, for comparison.

The demo scene's plan (8 steps: a roll rated 0.61, three spins of +42 deg rated 1.00, four pushes rated
0.02-0.06): ``plan_odds`` p_success 0.07 and 59.1 primitives within 60; ``mc_odds`` through these models 1.00 and
12.7 primitives; closed-loop execution took 21 (issue 47).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shlex
import sys
import time
import warnings
import zipfile
from collections import OrderedDict
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from affordplan.errors import InputError
from affordplan.geometry import wrap_angle
from affordplan.log import cli_logging, one_line_errors
from affordplan.objects.model import ObjectModel, load_object, random_object
from affordplan.sim.simulator import Simulator
from primitives import params as skill_params
from primitives.params import PUSH_STEP, SKILLS, SPIN_MAX, SPIN_MIN, made_progress
from primitives.skills import Skill, load_skills, skills_sensor
from primitives.training.env import EnvConfig, _lru, object_groups
from primitives.training.provenance import recorded_path

COLUMNS = {  # name: dtype
    "p": np.float32, "param": np.float32, "success": bool, "made_progress": bool, "progress": np.float32,
    "dx": np.float32, "dy": np.float32, "dyaw": np.float32, "state_before": np.int16, "state_after": np.int16,
    "state_asked": np.int16, "valid": bool, "object": np.int16, "state_probability": np.float32,
}


def measure(obj: ObjectModel, skill: str, params: Mapping, T_before: np.ndarray, T_after: np.ndarray) -> dict:
    """What a call did: ``progress`` (share of the asked effect), ``dx, dy, dyaw``, the states and ``made_progress``
    (module docstring)."""
    s0, x0, y0, yaw0 = obj.planar_pose(T_before)
    s1, x1, y1, yaw1 = obj.planar_pose(T_after)
    dx, dy = x1 - x0, y1 - y0
    dyaw = float(wrap_angle(yaw1 - yaw0)) if s1 == s0 else 0.0
    asked = s0
    if skill == "push":
        a = params["direction"]
        dx, dy = dx * math.cos(a) + dy * math.sin(a), -dx * math.sin(a) + dy * math.cos(a)
        progress = dx / PUSH_STEP if s1 == s0 else 0.0
    elif skill == "spin":
        progress = dyaw * math.copysign(1.0, params["angle"]) / abs(params["angle"]) if s1 == s0 else 0.0
    else:
        asked = int(params["target"])
        progress = float(s1 == asked)
    return dict(progress=progress, dx=dx, dy=dy, dyaw=dyaw, state_before=s0, state_after=s1, state_asked=asked,
                made_progress=made_progress(obj, skill, params, T_before, T_after))


def draw_params(skill: str, rng: np.random.Generator, obj: ObjectModel, state: int) -> dict | None:
    """A parameter as the planner asks them (module docstring); ``None`` for a roll with no target."""
    if skill == "push":
        return {"direction": float(rng.uniform(-math.pi, math.pi))}
    if skill == "spin":
        return {"angle": float(rng.choice([-1.0, 1.0]) * rng.uniform(SPIN_MIN, SPIN_MAX))}
    targets = skill_params.roll_targets(obj, state)
    return {"target": int(rng.choice(targets))} if targets else None


def object_name(key) -> str:
    return f"{key[0]}/{key[1]}" if isinstance(key, tuple) else str(key)


def object_of(name: str) -> ObjectModel:
    """The object a file's ``objects`` entry names (:func:`object_name`): ``"train/485"`` (a procedural split and
    index) or a catalogue or household name."""
    split, _, index = name.partition("/")
    if split in ("train", "test") and index.isdigit():
        return random_object(int(index), split)
    return load_object(name)


def annotate(path: str, progress: bool = True) -> dict:
    """Add ``state_probability`` (module docstring) to the outcome file ``path``, in place (written to a temporary
    file beside it, then moved over it, so an interrupted run loses nothing). Returns what it wrote."""
    src = Path(path)
    if not src.is_file():
        raise InputError(f"no outcome file at {str(path)!r}")
    try:
        with np.load(src, allow_pickle=False) as f:
            data = {k: np.array(f[k]) for k in f.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise InputError(f"{path} is not a readable outcome file ({type(exc).__name__}: {exc})") from exc
    missing = [c for c in ("objects", "object", "state_before", "state_after") if c not in data]
    if missing:
        raise InputError(f"{path} cannot be annotated: it has no {', '.join(missing)}")
    names = [str(n) for n in data["objects"]]
    probability = np.zeros(len(data["object"]), dtype=np.float32)
    for i in tqdm(range(len(names)), desc=f"annotate {src.name}", disable=not progress, unit="object"):
        rows = np.flatnonzero(data["object"] == i)
        if len(rows):
            with warnings.catch_warnings():  # load_object's "far outside what the skills trained on": not news here
                warnings.simplefilter("ignore", UserWarning)
                obj = object_of(names[i])
            probability[rows] = [obj.resting_states[int(s)].probability for s in data["state_before"][rows]]
    data["state_probability"] = probability
    tmp = src.with_name(src.name + ".tmp.npz")
    np.savez_compressed(tmp, **data)
    tmp.replace(src)
    tipped = data["state_before"] != data["state_after"]
    return dict(file=str(src), rows=int(len(probability)), objects=len(names), tipped=float(tipped.mean()))


def collect(skill: str, skills: Mapping[str, Skill], rollouts: int, objects: str = "train+housekeep:training",
            seed: int = 0, n_objects: int = 500, progress: bool = True, sim_cache: int = 32) -> dict:
    """``rollouts`` rows (skipped starts not counted) of ``skill`` calls, as the columns of :data:`COLUMNS` plus
    ``objects`` (names) and ``skipped`` (roll starts with no target); see the module docstring."""
    if skill not in SKILLS:
        raise InputError(f"unknown skill {skill!r}; expected one of {SKILLS}")
    cfg = EnvConfig(skill, objects=objects, n_objects=n_objects)
    groups = object_groups(objects, n_objects)
    sensor = skills_sensor(dict(skills))
    rng = np.random.default_rng(seed)
    models: OrderedDict = OrderedDict()
    sims: OrderedDict = OrderedDict()
    rows = {k: [] for k in COLUMNS}
    names: dict[str, int] = {}
    skipped = 0
    bar = tqdm(total=rollouts, desc=f"outcomes {skill}", disable=not progress, unit="rollout", mininterval=2.0)
    while len(rows["p"]) < rollouts:
        keys = groups[int(rng.integers(len(groups)))] if len(groups) > 1 else groups[0]
        key = keys[int(rng.integers(len(keys)))]
        obj = _lru(models, key, cfg.model_cache,
                   lambda k=key: random_object(k[1], k[0]) if isinstance(k, tuple) else load_object(k))
        sim = _lru(sims, key, sim_cache,
                   lambda o=obj: Simulator(o, pusher="finger", seed=int(rng.integers(2**31)), sensor=sensor),
                   evict=Simulator.close)
        states = obj.resting_states
        probs = np.array([s.probability for s in states])
        start = int(rng.choice(len(states), p=probs / probs.sum()))
        (x0, x1), (y0, y1) = cfg.xy_range
        sim.reset(resting_state=start, xy=(rng.uniform(x0, x1), rng.uniform(y0, y1)), yaw=rng.uniform(-np.pi, np.pi))
        state = obj.classify(sim.object_pose())
        params = draw_params(skill, rng, obj, state)
        if params is None:
            skipped += 1
            continue
        p = skills[skill].success_probability(sim, params)
        out = skills[skill].execute(sim, params, stop_at_angle=False, steer=False)  # as plans execute their calls
        m = measure(obj, skill, params, out.pose_before, out.pose_after)
        row = dict(m, p=p, param=next(iter(params.values())), success=bool(out.success), valid=bool(out.valid),
                   object=names.setdefault(object_name(key), len(names)),
                   state_probability=states[m["state_before"]].probability)
        for k in COLUMNS:
            rows[k].append(row[k])
        bar.update(1)
    bar.close()
    for s in sims.values():
        s.close()
    data = {k: np.asarray(v, dtype=COLUMNS[k]) for k, v in rows.items()}
    data["objects"] = np.asarray(list(names), dtype=str)
    data["skipped"] = np.asarray(skipped)
    return data


def save(path: str, data: Mapping[str, np.ndarray], skill: str, objects: str, command: str) -> None:
    """Write the rows as a plain compressed ``.npz`` (no pickled objects)."""
    np.savez_compressed(path, **data, skill=np.asarray(skill), objects_spec=np.asarray(objects),
                        command=np.asarray(command))


def check(model, data: Mapping[str, np.ndarray], lo: float = 0.1, hi: float = 0.9) -> dict:
    """How well ``model`` (:class:`primitives.outcome_model.OutcomeModel`) predicts the rows ``data``: coverage of
    its ``lo``-``hi`` progress interval, mean predicted vs measured progress, ``p_progress``'s accuracy, and (push,
    spin) the tip rate predicted against the share of calls that left their resting state."""
    p = np.asarray(data["p"], dtype=float)
    progress = np.asarray(data["progress"], dtype=float)
    made = np.asarray(data["made_progress"], dtype=bool)
    qlo, qhi = model.progress_quantiles(p, (lo, hi)).T
    predicted_mean = model.mean_progress(p)
    pp = model.p_progress(p)
    covered = (progress >= qlo - 1e-9) & (progress <= qhi + 1e-9)
    out = dict(skill=model.skill, rollouts=int(len(p)), interval=[lo, hi], coverage=float(covered.mean()),
               below=float((progress < qlo - 1e-9).mean()), above=float((progress > qhi + 1e-9).mean()),
               predicted_mean_progress=float(predicted_mean.mean()), measured_mean_progress=float(progress.mean()),
               predicted_made_progress=float(pp.mean()), measured_made_progress=float(made.mean()),
               p_progress_brier=float(np.mean((pp - made) ** 2)),
               p_progress_accuracy=float(np.mean((pp >= 0.5) == made)),
               strict_p_mean=float(p.mean()), strict_success=float(np.mean(data["success"])),
               strict_p_brier=float(np.mean((p - np.asarray(data["success"], dtype=float)) ** 2)),
               invalid=int(np.sum(~np.asarray(data["valid"], dtype=bool))))
    if model.knows_tips and model.skill != "roll":  # the tip rate against the calls that left their state
        tipped = np.asarray(data["state_before"]) != np.asarray(data["state_after"])
        pt = model.p_tip(np.asarray(data["state_probability"], dtype=float))
        out.update(predicted_tipped=float(pt.mean()), measured_tipped=float(tipped.mean()),
                   p_tip_brier=float(np.mean((pt - tipped) ** 2)))
    if model.skill == "roll":  # progress is made_progress: report p_progress's calibration in bins
        bins = np.linspace(0.0, 1.0, 6)
        which = np.clip(np.digitize(pp, bins) - 1, 0, len(bins) - 2)
        out["p_progress_bins"] = [dict(range=[float(bins[b]), float(bins[b + 1])], n=int(np.sum(which == b)),
                                       predicted=float(pp[which == b].mean()), measured=float(made[which == b].mean()))
                                  for b in range(len(bins) - 1) if np.any(which == b)]
    return out


def recorded_command(argv: list[str], cwd: str | os.PathLike | None = None) -> str:
    """The command line an outcome file records: ``argv`` with its ``--out`` path as
    :func:`primitives.training.provenance.recorded_path` records it (relative to ``cwd``, default the working
    directory, where it lies inside it, else its file name), so that no machine's own folders go into a file that may
    ship."""
    args = list(argv)
    for i, arg in enumerate(args):
        if arg == "--out" and i + 1 < len(args):
            args[i + 1] = recorded_path(args[i + 1], cwd)
        elif arg.startswith("--out="):
            args[i] = "--out=" + recorded_path(arg.split("=", 1)[1], cwd)
    return "python -m primitives.training.outcomes " + shlex.join(args)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m primitives.training.outcomes", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    a = sub.add_parser("annotate", help="add state_probability to outcome files collected before it was recorded")
    a.add_argument("files", nargs="+")
    for name in ("collect", "check"):
        s = sub.add_parser(name)
        s.add_argument("skill", choices=SKILLS)
        s.add_argument("--rollouts", type=int, default=600 if name == "collect" else 150)
        s.add_argument("--objects", default="train+housekeep:training" if name == "collect" else "housekeep:unseen",
                       help="EnvConfig object groups joined by + (train, test, housekeep:SPLIT, names)")
        s.add_argument("--n-objects", type=int, default=500, help="procedural objects per split")
        s.add_argument("--seed", type=int, default=0 if name == "collect" else 1)
        s.add_argument("--out", default=None, help="write the rows here (.npz)" + ("" if name == "check" else
                                                                                  " (required)"))
        if name == "check":
            s.add_argument("--model", default=None, help="outcome model .npz (default: the shipped one)")
            s.add_argument("--json", action="store_true")
    return p


@one_line_errors("primitives.training.outcomes")
def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    cli_logging()
    if args.command == "annotate":
        try:
            for path in args.files:
                print(json.dumps(annotate(path)))
        except (OSError, ValueError) as exc:  # an unreadable or foreign file, besides bad input
            print(f"primitives.training.outcomes: error: {exc}", file=sys.stderr)
            return 2
        return 0
    if args.rollouts < 1:
        parser.error("--rollouts must be a positive integer")
    if args.command == "collect" and args.out is None:
        parser.error("collect needs --out")
    torch.set_num_threads(1)
    command = recorded_command(sys.argv[1:] if argv is None else argv)
    model = None
    if args.command == "check":
        from primitives.outcome_model import OutcomeModel

        model = OutcomeModel.load(args.skill, args.model)
    skills = load_skills()
    t0 = time.perf_counter()
    data = collect(args.skill, skills, args.rollouts, args.objects, args.seed, args.n_objects,
                   progress=not getattr(args, "json", False))
    wall = time.perf_counter() - t0
    if args.out is not None:
        save(args.out, data, args.skill, args.objects, command)
    summary = dict(rows=int(len(data["p"])), skipped=int(data["skipped"]), objects=int(len(data["objects"])),
                   wall_s=round(wall, 1), success=float(data["success"].mean()),
                   made_progress=float(data["made_progress"].mean()), mean_progress=float(data["progress"].mean()),
                   mean_p=float(data["p"].mean()))
    if model is not None:
        summary.update(check(model, data), objects_spec=args.objects, seed=args.seed)
    if getattr(args, "json", False):
        print(json.dumps(summary, indent=2))
    else:
        for k, v in summary.items():
            print(f"{k:>24s}: {v:.3f}" if isinstance(v, float) else f"{k:>24s}: {v}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
