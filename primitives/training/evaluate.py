"""Evaluate a trained primitive with the seed's protocol.

    python -m primitives.evaluate push --weights runs/push/policy.pt --trials 200 --objects random
    python -m primitives.evaluate push --objects seed7 --plot fig5_push.png --json
    python -m primitives.evaluate push --critic-map critic_map.png
    python -m primitives.evaluate spin --params random --frames shipped --strokes 4 --objects housekeep:unseen

Protocol (the seed's Section IV): each trial starts the object in a stable pose (a resting state
drawn by its probability, a random position in the middle of the workspace and a random yaw), the
policy acts greedily (argmax of the critic map, the actor's motion without noise), and success is the
seed's criterion for that primitive. ``--objects random`` uses the held-out procedural split (never
trained on); ``seed7`` the seed's seven objects (``--trials`` each); paths evaluate mesh files.
``--strokes K`` (spin and roll, with ``--params random``) lets each trial be one call of up to K strokes of
the skill re-observing between them (:func:`primitives.strokes.spin_by`, :func:`~primitives.strokes.roll_to`),
the skill acting as a user's call acts, and reports success within 1..K strokes.
"""

from __future__ import annotations

import argparse
import json
import os
from dataclasses import dataclass, field

import numpy as np
import torch
from tqdm import tqdm

from affordplan.errors import InputError
from affordplan.log import cli_logging, one_line_errors
from affordplan.objects import housekeep
from primitives.frames import FrameSearch
from primitives.networks import HybridActorCritic
from primitives.policy import greedy_action, load_policy  # noqa: F401  (re-exported: older imports)
from primitives.skills import Skill, load_skill
from primitives.strokes import MAX_STROKES, Strokes, roll_to, spin_by
from primitives.training.env import PRIMITIVES, SEED_SEVEN, EnvConfig, PrimitiveEnv

# The seed's Fig. 5 (success per object, push / roll / spin) and Fig. 3 (means over its random objects).
SEED_FIG5 = {
    "cube": (0.955, 0.85, 0.61), "mug": (0.625, 0.825, 0.29), "lunch_box": (0.825, 0.52, 0.485),
    "tape": (0.465, 0.75, 0.56), "pill_bottle": (0.135, 0.845, 0.60), "planter_1": (0.28, 0.74, 0.485),
    "planter_2": (0.245, 0.79, 0.405),
}
SEED_FIG3 = {"push": 0.43, "roll": 0.75, "spin": 0.47}


@dataclass
class EvalResult:
    primitive: str
    objects: str
    per_object: dict[str, list[bool]] = field(default_factory=dict)
    invalid: int = 0
    params: str = "none"
    frames: str = "goal frame"  # or "best of M free frames" (frame search)
    predicted: list[float] = field(default_factory=list)  # the success model's rating of each trial (frame search)
    outcomes: list[bool] = field(default_factory=list)  # every trial's success, in order
    acted_as: list[dict | None] = field(default_factory=list)  # each trial's stand-in request (frame search only)
    sensor: str = "cameras"
    strokes: list[int] = field(default_factory=list)  # each trial's strokes (calls of several strokes only)
    stopped: list[str] = field(default_factory=list)  # why each such call stopped (primitives.strokes.Strokes)

    def within(self) -> dict[int, float]:
        """Success within 1..K strokes (calls of up to K strokes; a call stops where it meets its criterion, so one
        of up to k strokes is this call's first k)."""
        if not self.strokes:
            return {}
        done = np.array(self.outcomes, dtype=bool)
        used = np.array(self.strokes)
        return {k: float(np.mean(done & (used <= k))) for k in range(1, int(used.max()) + 1)}

    @property
    def success_rate(self) -> float:
        allv = [s for v in self.per_object.values() for s in v]
        return float(np.mean(allv)) if allv else 0.0

    def rates(self) -> dict[str, float]:
        return {k: float(np.mean(v)) for k, v in self.per_object.items()}

    def calibration(self) -> dict | None:
        """ECE, Brier, AUROC and mean rating of the success model's ratings (frame search only)."""
        if not self.predicted:
            return None
        from primitives.training.success import metrics

        return metrics(np.array(self.predicted), np.array(self.outcomes, dtype=bool))

    def as_dict(self) -> dict:
        out = dict(primitive=self.primitive, objects=self.objects, sensor=self.sensor, success=self.success_rate,
                   trials=sum(len(v) for v in self.per_object.values()), invalid=self.invalid, params=self.params,
                   per_object=self.rates())
        if self.predicted:
            out.update(frames=self.frames, calibration=self.calibration())
        stand_ins = [a is not None for a in self.acted_as]
        if any(stand_ins):
            out.update(stand_in_share=float(np.mean(stand_ins)),
                       stand_in_success=float(np.mean([o for o, a in zip(self.outcomes, stand_ins) if a])))
        if self.strokes:
            reasons = [r.split(" (")[0].split(":")[0].rstrip("0123456789 ") for r in self.stopped]  # no details
            out.update(mean_strokes=float(np.mean(self.strokes)), success_within=self.within(),
                       stopped={r: reasons.count(r) for r in sorted(set(reasons), key=reasons.index)})
        return out


# The seed's seven objects' real counterparts among HACMan's household meshes (one each; the shared README's map).
SEED_SEVEN_REAL = {
    "cube": "rubiks_cube_077_rubiks_cube_M", "mug": "mug_025_mug_M",
    "tape": "tape_3M_Antislip_Surfacing_Light_Duty_White_M",
    "planter_1": "plant_container_Central_Garden_Flower_Pot_Goo_425_M",
    "planter_2": "plant_container_Sapota_Threshold_4_Ceramic_Round_Planter_Red_M",
    "pill_bottle": "pill_bottle_Beta_Glucan_M", "lunch_box": "lunch_bag_Olive_Kids_Birdie_Munch_n_Lunch_M",
}


def held_out_config(primitive: str, p_params: float, sensor: str = "cameras") -> EnvConfig:
    """The environment of the held-out starts (procedural test split, one episode per drawn object)."""
    return EnvConfig(primitive, objects="test", n_objects=200, episodes_per_object=1, p_params=p_params,
                     sensor=sensor)


def named_objects_config(primitive: str, names: tuple[str, ...], p_params: float,
                         sensor: str = "cameras") -> EnvConfig:
    """The environment of an evaluation on named objects (:func:`object_list`): each reset names its object, one
    episode per draw."""
    return EnvConfig(primitive, objects=names, episodes_per_object=1, p_params=p_params, sensor=sensor)


def object_list(objects: str | tuple[str, ...]) -> tuple[str, ...]:
    """The objects an evaluation runs on: ``seed7`` (the seed's procedural seven), ``seed7:real`` (their real
    counterparts, :data:`SEED_SEVEN_REAL`), ``housekeep:SPLIT`` (e.g. ``housekeep:unseen``), or names / paths."""
    if objects == "seed7":
        return SEED_SEVEN
    if objects == "seed7:real":
        return tuple(housekeep.PREFIX + SEED_SEVEN_REAL[n] for n in SEED_SEVEN)
    if isinstance(objects, str) and objects.startswith("housekeep:"):
        return tuple(housekeep.PREFIX + n for n in housekeep.names(objects.split(":", 1)[1]))
    return (objects,) if isinstance(objects, str) else tuple(objects)


def _trials(primitive: str, objects: str | tuple[str, ...], trials: int, p_params: float,
            sensor: str) -> tuple[EnvConfig, list[str | None]]:
    """The environment of an evaluation and each trial's object key (``None``: drawn from the procedural test
    split), ``trials`` per named object."""
    if objects == "random":
        return held_out_config(primitive, p_params, sensor), [None] * trials
    names = object_list(objects)
    return named_objects_config(primitive, names, p_params, sensor), [n for n in names for _ in range(trials)]


def seed_reference(name: str) -> tuple[float, float, float] | None:
    """The seed's Fig. 5 figures (push, roll, spin) for a seed object or its real counterpart."""
    real = {housekeep.PREFIX + v: k for k, v in SEED_SEVEN_REAL.items()}
    return SEED_FIG5.get(real.get(name, name))


def evaluate(model: HybridActorCritic, primitive: str, objects: str | tuple[str, ...] = "random",
             trials: int = 200, seed: int = 1234, progress: bool = True, p_params: float = 0.0,
             sensor: str = "cameras",
             frame_search: FrameSearch | None = None,
             success_weights: str | os.PathLike | None = None) -> EvalResult:
    """Success over ``trials`` stable starts (per object for ``seed7`` and paths).

    ``p_params``: the share of trials that ask for a random parameter (0: the seed's objective; 1:
    every trial parameterised, judged by the parameterised criterion).
    ``frame_search``: act in the free goal frame the success model (``success_weights``; by default the shipped
    one for ``sensor``'s clouds) rates likeliest (:mod:`primitives.frames`), and record its calibrated ratings.
    """
    predict = decide = None
    if frame_search is not None:
        from primitives.training.success import SuccessModel, load_success_net

        rater = SuccessModel(model, load_success_net(primitive, success_weights, sensor))
        predict, decide = rater.predict, rater.rate_and_decide
    cfg, plan = _trials(primitive, objects, trials, p_params, sensor)
    env = PrimitiveEnv(cfg, seed=seed)
    result = EvalResult(primitive, objects if isinstance(objects, str) else "paths", sensor=sensor,
                        params={0.0: "none", 1.0: "random"}.get(p_params, f"p={p_params:.2f}"))
    for key in tqdm(plan, desc=f"evaluate {primitive}", disable=not progress, unit="trial", mininterval=2.0):
        obs = env.reset(object_key=key)
        if predict is not None:
            params = env.seen.params
            env.seen, rating = frame_search.select(primitive, env.seen, predict, env.sim, decide=decide)
            obs = env.seen.obs
            if frame_search.searches(primitive, params):
                result.frames = (f"best of {len(frame_search.frames(primitive, params))} free frames"
                                 + (" and the stand-in requests' frames" if frame_search.tries_stand_ins(params)
                                    else ""))
                rating = float(frame_search.calibrate(rating, params is not None))
            result.predicted.append(rating)
            result.acted_as.append(env.seen.acted_as)
        idx, motion, _ = greedy_action(model, obs)
        res = env.step(idx, motion)
        result.invalid += not res.valid
        name = "random" if key is None else str(key)
        result.per_object.setdefault(name, []).append(res.success)
        result.outcomes.append(bool(res.success))
    env.close()
    return result


def evaluate_strokes(skill: Skill, objects: str | tuple[str, ...] = "random", trials: int = 200, seed: int = 1234,
                     max_strokes: int = 4, progress: bool = True, sensor: str = "cameras") -> EvalResult:
    """Success of calls of up to ``max_strokes`` strokes (:func:`primitives.strokes.spin_by` for the spin,
    :func:`~primitives.strokes.roll_to` for the roll) on the starts and asked parameters :func:`evaluate` draws
    with ``p_params=1`` (same ``seed``: same starts), ``skill`` acting as a user's call acts (its frame search and
    ratings for ``sensor``'s clouds). Judged by each call's criterion, the asked parameter's; a start with nothing to
    ask (a roll from a state with no state one roll away) is one stroke of the seed's objective, as :func:`evaluate`
    judges it."""
    if skill.name not in ("spin", "roll"):
        raise InputError(f"calls of several strokes are spin_by and roll_to; {skill.name} has none")
    cfg, plan = _trials(skill.name, objects, trials, 1.0, sensor)
    env = PrimitiveEnv(cfg, seed=seed)
    result = EvalResult(skill.name, objects if isinstance(objects, str) else "paths", sensor=sensor, params="random",
                        frames=f"calls of up to {max_strokes} strokes")
    for key in tqdm(plan, desc=f"evaluate {skill.name} x{max_strokes}", disable=not progress, unit="trial",
                    mininterval=2.0):
        env.reset(object_key=key)
        asked = env.params
        if asked is None:  # no state one roll away: one stroke of the seed's objective, as evaluate() judges it
            made = Strokes(skill.execute(env.sim, None), 1, "no parameter to ask (the seed's objective)")
        elif skill.name == "spin":
            made = spin_by(skill, env.sim, asked["angle"], max_strokes)
        else:
            made = roll_to(skill, env.sim, asked["target"], max_strokes)
        result.invalid += not made.outcome.valid
        result.per_object.setdefault("random" if key is None else str(key), []).append(bool(made.outcome.success))
        result.outcomes.append(bool(made.outcome.success))
        result.strokes.append(made.strokes)
        result.stopped.append(made.stopped)
    env.close()
    return result


def plot_results(results: list[EvalResult], path: str | os.PathLike) -> None:
    """Bar charts like the seed's Fig. 3 (mean success per primitive) and Fig. 5 (per object)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    per_obj = [r for r in results if r.objects != "random"]
    fig, axes = plt.subplots(1, 2 if per_obj else 1, figsize=(13 if per_obj else 5, 4), squeeze=False)
    ax = axes[0, 0]
    names = [r.primitive for r in results]
    ours = [r.success_rate for r in results]
    seed = [SEED_FIG3.get(n, np.nan) for n in names]
    x = np.arange(len(names))
    ax.bar(x - 0.2, seed, 0.4, label="seed (HACMan-AFF)", color="#bbbbbb")
    ax.bar(x + 0.2, ours, 0.4, label="affordplan", color="#d98c2b")
    ax.set_xticks(x, names)
    ax.set_ylim(0, 1)
    ax.set_ylabel("success rate")
    ax.set_title(f"mean success ({results[0].objects} objects)")
    ax.legend()
    if per_obj:
        ax = axes[0, 1]
        objs = list(per_obj[0].rates())
        width = 0.8 / (2 * len(per_obj))
        for k, r in enumerate(per_obj):
            col = PRIMITIVES.index(r.primitive)
            xs = np.arange(len(objs))
            ax.bar(xs + (2 * k) * width - 0.4, [(seed_reference(o) or (np.nan,) * 3)[col] for o in objs], width,
                   color="#bbbbbb", label="seed" if k == 0 else None)
            ax.bar(xs + (2 * k + 1) * width - 0.4, [r.rates()[o] for o in objs], width,
                   label=f"affordplan {r.primitive}")
        ax.set_xticks(np.arange(len(objs)), [o.removeprefix(housekeep.PREFIX)[:18] for o in objs], rotation=30,
                      ha="right", fontsize=7)
        ax.set_ylim(0, 1)
        ax.set_title("success per object (grey: seed's Fig. 5)")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_critic_map(model: HybridActorCritic, primitive: str, path: str | os.PathLike, object_name: str = "cube",
                    seed: int = 0) -> None:
    """The seed's Fig. 2: the cloud coloured by critic value, the chosen contact and its motion."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    env = PrimitiveEnv(EnvConfig(primitive, objects=(object_name,), episodes_per_object=1), seed=seed)
    obs = env.reset(object_key=object_name)
    idx, motion, q = greedy_action(model, obs)
    pts, motion = env.points, env.seen.motion_to_world(motion)
    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(projection="3d")
    sc = ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], c=q, cmap="viridis", s=6)
    ax.scatter(*pts[idx], color="red", s=60, label="chosen contact")
    ax.quiver(*pts[idx], *(0.09 * motion), color="red", linewidth=2, label="motion (x 9 cm)")
    fig.colorbar(sc, ax=ax, shrink=0.7, label="critic value Q")
    ax.set_title(f"{primitive} critic map on the {object_name}")
    ax.legend(loc="upper left", fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    env.close()


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m primitives.evaluate", description=__doc__.split("\n\n")[0],
        epilog="examples:\n"
               "  python -m primitives.evaluate push --trials 200 --objects random\n"
               "  python -m primitives.evaluate roll --objects seed7 --trials 50 --plot roll.png --json\n"
               "  python -m primitives.evaluate spin --weights runs/spin/policy.pt --critic-map map.png",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("primitive", choices=PRIMITIVES)
    p.add_argument("--weights", default=None, help="policy.pt or checkpoint.pt (default: shipped weights)")
    p.add_argument("--trials", type=int, default=200)
    p.add_argument("--objects", nargs="+", default=["random"],
                   help="random (procedural test split) | seed7 | seed7:real | housekeep:SPLIT (e.g. housekeep:unseen, "
                        "housekeep:unseen_thick, housekeep:validation) | names or mesh paths; --trials each")
    p.add_argument("--sensor", choices=("cameras", "surface"), default="cameras",
                   help="how the policy sees the object (surface: the privileged sample, for ablations)")
    p.add_argument("--seed", type=int, default=1234)
    p.add_argument("--params", choices=["none", "random"], default="none",
                   help="none: the seed's objective; random: every trial asks for a random parameter")
    p.add_argument("--frames", default=None, metavar="shipped|PATH",
                   help="frame search (primitives.frames): act in the free goal frame the success model rates "
                        "likeliest, as the shipped skill does (shipped) or as a frames.json says; default: the goal "
                        "frame, as trained")
    p.add_argument("--frame-turns", type=int, default=None, metavar="N",
                   help="an uncalibrated frame search over N turns, where the request leaves the turn free")
    p.add_argument("--frame-mirror", action="store_true",
                   help="with --frame-turns: also the mirrored frames, where the request leaves the mirror free")
    p.add_argument("--strokes", type=int, default=1, metavar="K",
                   help="spin or roll with --params random: each trial one call of up to K strokes re-observing "
                        "between them (primitives.strokes), the skill as a user's call has it (with --frames shipped: "
                        "the shipped skill); default 1: the one-stroke protocol")
    p.add_argument("--success-weights", default=None, help="success model for the frame search (default: shipped)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--plot", default=None, help="write bar charts (the seed's Fig. 3 / Fig. 5) here")
    p.add_argument("--critic-map", default=None, help="write the critic map figure (the seed's Fig. 2) here")
    return p


def _frame_search(args: argparse.Namespace, parser: argparse.ArgumentParser) -> FrameSearch | None:
    """The frame search the flags ask for (``--frames`` or ``--frame-turns`` / ``--frame-mirror``), or None."""
    if args.frames is not None and (args.frame_turns is not None or args.frame_mirror):
        parser.error("give --frames or --frame-turns / --frame-mirror, not both")
    if args.frames == "shipped":
        from primitives.skills import shipped_frame_search

        search = shipped_frame_search(args.primitive, sensor=args.sensor)
        if search is None:
            parser.error(f"no frame search is shipped for {args.primitive}")
        return search
    if args.frames is not None:
        return FrameSearch.load(args.frames)
    if args.frame_turns is not None or args.frame_mirror:
        return FrameSearch(1 if args.frame_turns is None else args.frame_turns, args.frame_mirror)
    return None


def _main_strokes(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    """``main`` for ``--strokes K``: calls of several strokes of the skill (:func:`evaluate_strokes`)."""
    search = _frame_search(args, parser)
    if args.frames == "shipped" and args.weights is None and args.success_weights is None:
        skill = load_skill(args.primitive)  # the shipped skill, exactly as a user's load_skill gives it
    else:
        skill = load_skill(args.primitive, args.weights, args.success_weights,
                           frame_search=search if search is not None else False)
    objects = _objects(args)
    result = evaluate_strokes(skill, objects, args.trials, args.seed, args.strokes, progress=not args.json,
                              sensor=args.sensor)
    if args.json:
        print(json.dumps(result.as_dict(), indent=2))
        return 0
    print(f"{args.primitive} (asked parameters, calls of up to {args.strokes} strokes): success "
          f"{result.success_rate:.3f} over {len(result.outcomes)} trials ({result.invalid} invalid), "
          f"{np.mean(result.strokes):.2f} strokes a call")
    print("  within " + ", ".join(f"{k} stroke{'s' * (k > 1)}: {v:.3f}" for k, v in result.within().items()))
    print("  calls stopped: " + ", ".join(f"{r} {n}" for r, n in result.as_dict()["stopped"].items()))
    for name, rate in result.rates().items():
        print(f"  {name:14s} {rate:.3f}")
    return 0


def _objects(args: argparse.Namespace) -> str | tuple[str, ...]:
    """``--objects`` as :func:`evaluate` takes it: one set (``random``, ``seed7``, ``housekeep:SPLIT``) or names."""
    one = args.objects[0]
    return one if len(args.objects) == 1 and (":" in one or one in ("random", "seed7")) else tuple(args.objects)


@one_line_errors("primitives.training.evaluate")  # missing or broken weights, an unreadable mesh, ...
def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    cli_logging()
    if args.trials < 1:
        parser.error(f"--trials must be a positive integer, got {args.trials}")
    if args.strokes != 1 and (args.params != "random" or args.primitive == "push" or args.plot or args.critic_map):
        parser.error("--strokes takes spin or roll with --params random (and neither --plot nor --critic-map)")
    if not 1 <= args.strokes <= MAX_STROKES:
        parser.error(f"--strokes must be from 1 to {MAX_STROKES}, got {args.strokes}")
    torch.set_num_threads(1)
    if args.strokes != 1:
        return _main_strokes(args, parser)
    model = load_policy(args.weights, args.primitive, sensor=args.sensor)
    search = _frame_search(args, parser)
    result = evaluate(model, args.primitive, _objects(args), args.trials, args.seed, progress=not args.json,
                      p_params=1.0 if args.params == "random" else 0.0, frame_search=search,
                      success_weights=args.success_weights, sensor=args.sensor)
    if args.json:
        print(json.dumps(result.as_dict(), indent=2))
    else:
        print(f"{args.primitive}: success {result.success_rate:.3f} over "
              f"{sum(len(v) for v in result.per_object.values())} trials ({result.invalid} invalid)")
        cal = result.calibration()
        if cal is not None:
            print(f"  {result.frames}; success model on the chosen frames: mean rating {cal['mean_prediction']:.3f}, "
                  f"ECE {cal['ece']:.3f}, Brier {cal['brier']:.3f}, AUROC {cal['auroc']:.3f}")
        d = result.as_dict()
        if "stand_in_share" in d:
            print(f"  acted as a stand-in request on {d['stand_in_share']:.3f} of the trials "
                  f"(success there {d['stand_in_success']:.3f})")
        for name, rate in result.rates().items():
            seed = seed_reference(name)
            ref = f"   seed {seed[PRIMITIVES.index(args.primitive)]:.3f}" if seed else ""
            print(f"  {name:14s} {rate:.3f}{ref}")
    if args.plot:
        plot_results([result], args.plot)
    if args.critic_map:
        plot_critic_map(model, args.primitive, args.critic_map)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
