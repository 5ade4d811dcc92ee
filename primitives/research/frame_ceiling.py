"""How much could a frame search gain? Every option it rates, executed from the same start.

    python -m primitives.research.frame_ceiling spin --starts 100 --params random
    python -m primitives.research.frame_ceiling push --starts 100 --params none --json --plot push_frame_ceiling.png

A frame search (:mod:`primitives.frames`) sees a start in every frame its request leaves free (and, for the
seed's objective, as each stand-in request) and acts in the option its success model rates likeliest. For each
start of the evaluation (:func:`primitives.training.evaluate.evaluate`'s starts for the same ``--seed``), this benchmark
restores the simulator to the start before executing the policy in *every* option, and reports the success of

- **goal frame**: the policy as trained, no search;
- **random option**: an option drawn at random (the mean over a start's options);
- **critic's pick**: the option where the critic's value at its chosen contact is highest;
- **search's pick**: the option the frame search acts in (the skill as shipped; the outcomes of
  ``primitives.training.evaluate --frames`` on the same starts);
- **best option**: some option succeeds, what a perfect ranking of the same options would reach;

and how well the success model ranks one start's options: the **within-start AUROC** of the ratings (each
option's rating calibrated for its kind, the scale the search compares on), averaged over the starts where
some options succeed and others fail. The gap between the search's pick and the best option is what a better
ranker could gain with the same policy; the gap between the best option and 1 is the policy's.

Options are judged as the skill judges them: by the request, or by the seed's objective for a stand-in.
The simulator is restored with :meth:`Simulator.snapshot` / :meth:`Simulator.restore`.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass

import numpy as np
import torch
from tqdm import tqdm

from affordplan.log import cli_logging, one_line_errors
from affordplan.sim.sensor import SENSORS
from primitives.frames import FrameSearch, load_frame_search
from primitives.networks import HybridActorCritic
from primitives.training.env import PRIMITIVES, PrimitiveEnv
from primitives.training.evaluate import (
    held_out_config,
    load_policy,
    named_objects_config,
    object_list,
)
from primitives.training.options import execute_every_option
from primitives.training.success import SuccessModel, auroc, load_success_net


@dataclass(frozen=True)
class StartOptions:
    """Every option of one start, in the order :meth:`FrameSearch.options` lists them (the goal frame first).

    ``option``: the option each row belongs to (0: the request itself, ``k > 0``: the k-th stand-in); ``frame``:
    its frame's index in that option; ``rating``: what the search compares options on, the success model's rating
    calibrated for its kind (:meth:`FrameSearch.calibrate_kind`) or, for a search with an option ranker, the
    ranker's probability; ``q_max``: the critic's value at the policy's contact; ``success``: the
    outcome of executing it from the start; ``pick``: the row the search acts in.
    """

    params: dict | None
    option: np.ndarray
    frame: np.ndarray
    rating: np.ndarray
    q_max: np.ndarray
    success: np.ndarray
    pick: int

    @property
    def mixed(self) -> bool:
        """Whether some options succeed and others fail."""
        return bool(self.success.any() and not self.success.all())


@dataclass
class FrameCeiling:
    """The options of each start (:class:`StartOptions`) and the figures of the module docstring."""

    skill: str
    params: str
    starts: list[StartOptions]
    objects: str = "random"
    sensor: str = "cameras"

    def rates(self) -> dict[str, float]:
        s = self.starts
        return {"goal frame": float(np.mean([o.success[0] for o in s])),
                "random option": float(np.mean([o.success.mean() for o in s])),
                "critic's pick": float(np.mean([o.success[np.argmax(o.q_max)] for o in s])),
                "search's pick": float(np.mean([o.success[o.pick] for o in s])),
                "best option": float(np.mean([o.success.any() for o in s]))}

    def within_start_auroc(self) -> float | None:
        """The model's AUROC within one start's options, averaged over the mixed starts (None without any)."""
        values = [auroc(o.rating, o.success) for o in self.starts if o.mixed]
        return float(np.mean(values)) if values else None

    def as_dict(self) -> dict:
        return dict(skill=self.skill, params=self.params, objects=self.objects, sensor=self.sensor,
                    starts=len(self.starts),
                    options_per_start=float(np.mean([len(o.success) for o in self.starts])),
                    success=self.rates(), mixed_share=float(np.mean([o.mixed for o in self.starts])),
                    within_start_auroc=self.within_start_auroc())

    def report(self) -> str:
        d = self.as_dict()
        lines = [f"{self.skill}, params {self.params}, {self.objects} objects, {self.sensor}: {d['starts']} starts, "
                 f"{d['options_per_start']:.1f} options each, every one executed from the start"]
        lines += [f"  {name:<15} {rate:.3f}" for name, rate in d["success"].items()]
        auc = d["within_start_auroc"]
        lines.append(f"  some options succeed and others fail on {d['mixed_share']:.2f} of the starts; the "
                     f"success model ranks them with a within-start AUROC of "
                     + ("n/a" if auc is None else f"{auc:.3f}"))
        return "\n".join(lines)

    def plot(self, path) -> None:
        """A bar chart of :meth:`rates`."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        rates = self.rates()
        fig, ax = plt.subplots(figsize=(6, 3.6))
        colours = ["#bbbbbb", "#bbbbbb", "#8fb3d9", "#d98c2b", "#5a9e5a"]
        bars = ax.bar(range(len(rates)), list(rates.values()), color=colours)
        ax.bar_label(bars, fmt="%.2f")
        ax.set_xticks(range(len(rates)), list(rates), rotation=15)
        ax.set_ylim(0, 1.05)
        ax.set_ylabel("success rate")
        ax.set_title(f"{self.skill}, params {self.params}: every option executed from {len(self.starts)} starts\n"
                     f"({self.objects} objects, {self.sensor})", fontsize=10)
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)


def start_options(env: PrimitiveEnv, policy: HybridActorCritic, search: FrameSearch,
                  rater: SuccessModel) -> StartOptions:
    """Execute every option of ``search`` on ``env``'s current start (:func:`execute_every_option`); ``rater``
    rates the options (and gives the policy's decisions to a ranker)."""
    skill, seen = env.config.primitive, env.seen
    done = execute_every_option(env, policy, search)
    ratings, decision = search.rate_and_decide(done.options, rater.rate_and_decide)
    ranking = search.rank(skill, done.options, ratings, decision) if search.ranks(seen.params) else None
    k_pick, j_pick, _ = search.choose(done.options, ratings, ranking)
    compared = (np.concatenate(ranking) if ranking is not None
                else search.calibrate_kind(np.concatenate(ratings), done.parameterised))
    return StartOptions(seen.params, done.option, done.frame, compared, done.decision[:, 0].astype(float),
                        done.success, done.row(k_pick, j_pick))


def frame_ceiling(skill: str, starts: int = 100, params: str = "random", seed: int = 1234,
                  weights=None, model=None, frames: str = "shipped", progress: bool = True,
                  objects: str = "random", sensor: str = "cameras") -> FrameCeiling:
    """Every option of ``starts`` held-out starts of ``skill`` (``params``: ``"random"`` asks for a random
    parameter, ``"none"`` the seed's objective), with the policy ``weights``, the success model ``model`` and the
    frame search ``frames`` (``"shipped"`` or a frames.json path; defaults: the shipped ones).

    ``objects``: ``"random"`` (the procedural test split, the evaluation's starts) or what
    :func:`primitives.training.evaluate.object_list` takes (e.g. ``"housekeep:validation"``), the starts then
    cycling through its objects; ``sensor``: the clouds the policy and the ratings see."""
    policy = load_policy(weights, skill)
    rater = SuccessModel(policy, load_success_net(skill, model, sensor))
    search = load_frame_search(skill, frames, sensor)
    p_params = 1.0 if params == "random" else 0.0
    if objects == "random":
        env, keys = PrimitiveEnv(held_out_config(skill, p_params, sensor), seed=seed), [None] * starts
    else:
        names = object_list(objects)
        env = PrimitiveEnv(named_objects_config(skill, names, p_params, sensor), seed=seed)
        keys = [names[i % len(names)] for i in range(starts)]
    out = FrameCeiling(skill, params, [], objects, sensor)
    for key in tqdm(keys, desc=f"{skill} frame ceiling", disable=not progress, unit="start", mininterval=2.0):
        env.reset(object_key=key)
        out.starts.append(start_options(env, policy, search, rater))
    env.close()
    return out


def add_held_out_arguments(p: argparse.ArgumentParser) -> None:
    """The arguments of a benchmark that acts on the evaluation's held-out starts with a frame search (this one
    and :mod:`primitives.research.sensitivity`): the skill, ``--starts``, ``--params``, ``--seed``, the files,
    ``--plot`` and ``--json``."""
    p.add_argument("skill", choices=PRIMITIVES)
    p.add_argument("--starts", type=int, default=100, help="held-out starts (default: 100)")
    p.add_argument("--params", choices=["none", "random"], default="random",
                   help="random: each start asks for a random parameter; none: the seed's objective")
    p.add_argument("--seed", type=int, default=1234, help="the evaluation's seed: same starts (default: 1234)")
    p.add_argument("--weights", default=None, help="policy (default: shipped)")
    p.add_argument("--model", default=None, help="goal-frame success model rating the options (default: shipped)")
    p.add_argument("--frames", default="shipped", metavar="shipped|PATH", help="frame search (default: shipped)")
    p.add_argument("--plot", default=None, help="bar chart PNG")
    p.add_argument("--json", action="store_true")


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m primitives.research.frame_ceiling", description=__doc__.split("\n\n")[0],
        epilog="examples:\n  python -m primitives.research.frame_ceiling spin --starts 100 --params random\n"
               "  python -m primitives.research.frame_ceiling push --starts 100 --params none --json",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    add_held_out_arguments(p)
    p.add_argument("--objects", default="random",
                   help="random (the procedural test split) or e.g. housekeep:validation (default: random)")
    p.add_argument("--sensor", choices=SENSORS, default="cameras", help="the clouds seen (default: cameras)")
    return p


@one_line_errors("primitives.research.frame_ceiling")  # missing or broken weights, an unreadable frames file, ...
def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    cli_logging()
    if args.starts < 1:
        parser.error(f"--starts must be a positive integer, got {args.starts}")
    torch.set_num_threads(1)
    result = frame_ceiling(args.skill, args.starts, args.params, args.seed, args.weights, args.model,
                           args.frames, progress=not args.json, objects=args.objects, sensor=args.sensor)
    print(json.dumps(result.as_dict(), indent=2) if args.json else result.report())
    if args.plot:
        result.plot(args.plot)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
