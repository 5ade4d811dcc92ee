"""How sharp is success around the policy's decision? Each decision executed again, slightly changed.

    python -m primitives.research.sensitivity spin --starts 100 --params random
    python -m primitives.research.sensitivity push --starts 100 --params none --json --plot push_sensitivity.png

A frame search (:mod:`primitives.frames`) ranks one start's options by its success model, and
``python -m primitives.research.frame_ceiling`` shows that a perfect ranking would gain much: the question this
benchmark answers is whether the outcomes it would have to predict are predictable at all. For each held-out start
(:func:`primitives.training.evaluate.evaluate`'s starts for the same ``--seed``) it
draws ``--options`` of the options the
shipped frame search rates, and executes the policy's decision in each from the start (**base**), then again:

- **motion +-a**: the same contact, the motion turned by ``a`` (default 3 deg) about the vertical;
- **contact +-d**: the same motion from a contact ``d`` (default 2 mm) along the surface, horizontally;
- **scene shift**: object and decision moved together by ``d`` along x: the same push on a table shifted by
  ``d``, which a deterministic, non-chaotic simulation answers as the base (a check of the physics).

It reports each variant's **flip rate** (how often its outcome differs from the base), and two within-start
AUROCs over the starts where the drawn options' base outcomes differ (the scale frame searches need):

- of the **success model's ratings** (calibrated for their kind, as the search compares them), and
- of the **neighbours' mean**: each option scored by the share of its four decision variants (not itself) that
  succeed: a rater that knows the physics around each decision, smooth at the scale of ``a`` and ``d``. It is a
  reference for what a model of (cloud, decision) could reach, not a bound.

A flip rate near 0 with a high neighbours' AUROC says the outcomes are smooth and predictable, and a
low model AUROC then points at the model; flip rates near those of a coin say no rater can rank the options.
Outcomes are judged as the skill judges them (a stand-in request by the seed's objective); a guarded (invalid)
execution counts as a failure, as in ``evaluate``.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass

import numpy as np
import torch
from tqdm import tqdm

from affordplan.errors import InputError
from affordplan.log import cli_logging, one_line_errors
from primitives.frames import FrameSearch, load_frame_search
from primitives.networks import HybridActorCritic
from primitives.research.frame_ceiling import add_held_out_arguments
from primitives.training.env import PrimitiveEnv
from primitives.training.evaluate import greedy_action, held_out_config, load_policy
from primitives.training.neighbours import CONTACT_M, MOTION_RAD, judged_execution, neighbour_outcomes
from primitives.training.success import SuccessModel, auroc, load_success_net

VARIANTS = ("motion +a", "motion -a", "contact +d", "contact -d", "scene shift")
_NEIGHBOURS = slice(0, 4)  # the decision variants of VARIANTS (not the scene shift)


@dataclass(frozen=True)
class StartDecisions:
    """The drawn options of one start: ``row`` (each one's index in the start's options and frames, in the order
    :mod:`primitives.research.frame_ceiling` lists them, ``(k,)``), ``rating`` (calibrated for its kind, ``(k,)``),
    the base outcomes ``base (k,)`` and the variants' outcomes ``variants (k, len(VARIANTS))``."""

    row: np.ndarray
    rating: np.ndarray
    base: np.ndarray
    variants: np.ndarray

    @property
    def mixed(self) -> bool:
        """Whether some drawn options succeed and others fail."""
        return bool(self.base.any() and not self.base.all())


@dataclass
class Sensitivity:
    """The decisions of each start (:class:`StartDecisions`) and the figures of the module docstring."""

    skill: str
    params: str
    motion_rad: float
    contact_m: float
    starts: list[StartDecisions]

    def flip_rates(self) -> dict[str, float]:
        """Per variant, the share of decisions whose outcome differs from the base's."""
        base = np.concatenate([s.base for s in self.starts])
        variants = np.concatenate([s.variants for s in self.starts])
        return {name: float(np.mean(variants[:, i] != base)) for i, name in enumerate(VARIANTS)}

    def within_start_auroc(self) -> dict[str, float | None]:
        """Within-start AUROC of the model's ratings and of the neighbours' mean, averaged over the mixed starts
        (None without any)."""
        mixed = [s for s in self.starts if s.mixed]
        if not mixed:
            return {"success model": None, "neighbours' mean": None}
        return {"success model": float(np.mean([auroc(s.rating, s.base) for s in mixed])),
                "neighbours' mean": float(np.mean([auroc(s.variants[:, _NEIGHBOURS].mean(axis=1), s.base)
                                                   for s in mixed]))}

    def as_dict(self) -> dict:
        return dict(skill=self.skill, params=self.params, starts=len(self.starts),
                    decisions=int(sum(len(s.base) for s in self.starts)),
                    motion_deg=float(np.degrees(self.motion_rad)), contact_mm=1e3 * self.contact_m,
                    base_success=float(np.mean(np.concatenate([s.base for s in self.starts]))),
                    flip_rates=self.flip_rates(), mixed_starts=int(sum(s.mixed for s in self.starts)),
                    within_start_auroc=self.within_start_auroc())

    def report(self) -> str:
        d = self.as_dict()
        lines = [f"{self.skill}, params {self.params}: {d['decisions']} decisions on {d['starts']} held-out starts, "
                 f"base success {d['base_success']:.3f}; a = {d['motion_deg']:g} deg, d = {d['contact_mm']:g} mm",
                 "  outcome differs from the base's:"]
        lines += [f"    {name:<12} {rate:.3f}" for name, rate in d["flip_rates"].items()]
        lines.append(f"  within-start AUROC over {d['mixed_starts']} starts with mixed outcomes:")
        lines += [f"    {name:<16} " + ("n/a" if v is None else f"{v:.3f}")
                  for name, v in d["within_start_auroc"].items()]
        return "\n".join(lines)

    def plot(self, path) -> None:
        """Bar charts of :meth:`flip_rates` and :meth:`within_start_auroc`."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        flips, aucs = self.flip_rates(), self.within_start_auroc()
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.6), gridspec_kw=dict(width_ratios=[5, 2]))
        ax1.bar_label(ax1.bar(range(len(flips)), list(flips.values()), color="#8fb3d9"), fmt="%.3f")
        ax1.set_xticks(range(len(flips)), list(flips), rotation=15)
        ax1.set_ylim(0, max(0.5, max(flips.values()) * 1.2))
        ax1.set_ylabel("outcome differs from the base's")
        values = [np.nan if v is None else v for v in aucs.values()]
        ax2.bar_label(ax2.bar(range(len(aucs)), values, color=["#d98c2b", "#5a9e5a"]), fmt="%.2f")
        ax2.set_xticks(range(len(aucs)), list(aucs), rotation=15)
        ax2.set_ylim(0.5, 1.0)
        ax2.set_ylabel("within-start AUROC")
        fig.suptitle(f"{self.skill}, params {self.params}: {len(self.starts)} starts; motion turned "
                     f"{np.degrees(self.motion_rad):g} deg, contact moved {1e3 * self.contact_m:g} mm")
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)


@torch.no_grad()
def start_decisions(env: PrimitiveEnv, policy: HybridActorCritic, search: FrameSearch, predict, n_options: int,
                    rng: np.random.Generator, motion_rad: float, contact_m: float) -> StartDecisions:
    """Execute ``n_options`` drawn options of ``search`` on ``env``'s current start and their variants, restoring
    the start before each execution (and after the last)."""
    skill, sim, seen = env.config.primitive, env.sim, env.seen
    start = sim.snapshot()
    T_world_object = sim.object_pose()
    options = search.options(skill, seen, sim)
    ratings = search.rate(options, predict)
    rows = [(k, j) for k, (_, frames) in enumerate(options) for j in range(len(frames))]
    drawn = rng.choice(len(rows), size=min(n_options, len(rows)), replace=False)
    rating, base, variants = [], [], []
    for r in drawn:
        k, j = rows[r]
        acting = search.acting(options, k, j)
        idx, motion, _ = greedy_action(policy, acting.obs)
        contact, normal = acting.points[idx], acting.normals[idx]
        motion_world = acting.motion_to_world(motion)
        sim.restore(start)
        outcomes = [judged_execution(sim, skill, acting.params, contact, motion_world, normal)]
        outcomes += neighbour_outcomes(sim, start, skill, acting.params, contact, normal, motion_world, motion_rad,
                                       contact_m)
        shift = np.array([contact_m, 0.0, 0.0])  # the scene shift: object and decision moved together along x
        sim.restore(start)
        T = T_world_object.copy()
        T[:3, 3] += shift
        sim.set_object_pose(T, settle=False)
        outcomes.append(judged_execution(sim, skill, acting.params, contact + shift, motion_world, normal))
        parameterised = options[k][0].params is not None
        rating.append(float(search.calibrate_kind(ratings[k][j], parameterised)))
        base.append(outcomes[0])
        variants.append(outcomes[1:])
    sim.restore(start)
    env.seen = seen
    return StartDecisions(np.asarray(drawn), np.array(rating), np.array(base, dtype=bool),
                          np.array(variants, dtype=bool))


def sensitivity(skill: str, starts: int = 100, params: str = "random", options: int = 3, seed: int = 1234,
                motion_rad: float = MOTION_RAD, contact_m: float = CONTACT_M, weights=None, model=None,
                frames: str = "shipped", progress: bool = True) -> Sensitivity:
    """The decisions of ``starts`` held-out starts of ``skill``, ``options`` drawn options each, and their variants
    (module docstring); ``params``: ``"random"`` asks for a random parameter, ``"none"`` the seed's objective.
    ``motion_rad`` (rad) and ``contact_m`` (metres, also the scene shift) size the variants; the policy, success
    model and frame search default to the shipped ones."""
    if starts < 1 or options < 1:
        raise InputError(f"starts and options must be positive, got {starts} and {options}")
    if not (np.isfinite(motion_rad) and np.isfinite(contact_m)) or motion_rad < 0 or contact_m < 0:
        raise InputError(f"the variants' sizes must be finite and >= 0, got {motion_rad} rad and {contact_m} m")
    policy = load_policy(weights, skill)
    predict = SuccessModel(policy, load_success_net(skill, model)).predict
    search = load_frame_search(skill, frames)
    env = PrimitiveEnv(held_out_config(skill, 1.0 if params == "random" else 0.0), seed=seed)
    rng = np.random.default_rng([seed, 7])  # the drawn options; apart from the environment's stream
    out = Sensitivity(skill, params, float(motion_rad), float(contact_m), [])
    for _ in tqdm(range(starts), desc=f"{skill} sensitivity", disable=not progress, unit="start", mininterval=2.0):
        env.reset()
        out.starts.append(start_decisions(env, policy, search, predict, options, rng, motion_rad, contact_m))
    env.close()
    return out


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m primitives.research.sensitivity", description=__doc__.split("\n\n")[0],
        epilog="examples:\n  python -m primitives.research.sensitivity spin --starts 100 --params random\n"
               "  python -m primitives.research.sensitivity push --starts 100 --params none --json",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    add_held_out_arguments(p)
    p.add_argument("--options", type=int, default=3, help="options drawn per start (default: 3)")
    p.add_argument("--motion-deg", type=float, default=3.0, help="turn of the motion variants, deg (default: 3)")
    p.add_argument("--contact-mm", type=float, default=2.0,
                   help="move of the contact variants and the scene shift, mm (default: 2)")
    return p


@one_line_errors("primitives.research.sensitivity")  # bad sizes, broken weights, an unreadable frames file, ...
def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    cli_logging()
    torch.set_num_threads(1)
    result = sensitivity(args.skill, args.starts, args.params, args.options, args.seed,
                         np.radians(args.motion_deg), 1e-3 * args.contact_mm, args.weights, args.model,
                         args.frames, progress=not args.json)
    print(json.dumps(result.as_dict(), indent=2) if args.json else result.report())
    if args.plot:
        result.plot(args.plot)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
