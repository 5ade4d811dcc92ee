"""How often can a push succeed at all? The best of scripted pushes, with privileged knowledge.

    python -m primitives.research.ceiling --starts 100 --params random
    python -m primitives.research.ceiling --starts 100 --params none --json

A push-straight must move the object >= 5 cm and turn it < 5 deg. A point fingertip pushing a flat face
turns the object unless the push line passes within a few millimetres of the centre of mass (a 10 cm
cube pushed 1 cm off its centre line turns ~7 deg over 6 cm), and lying cylinders, capsules and
ellipsoids roll whichever way they are pushed. This benchmark measures how much of the held-out
family any push can move straight, so that a policy's success reads against what the pusher and the
protocol allow.

For each start of the evaluation (:func:`primitives.training.evaluate.evaluate`'s starts: the same objects,
states and poses for the same ``--seed``), the simulator is restored to the start before each of
``CANDIDATES`` scripted pushes (that many for each aim):

- **contacts** from a dense cloud (2048 points; the policy sees 256): on the surface facing the push
  (normal against it by > 60 deg), the two nearest the line through the **centre of mass** along the
  push (which no policy sees) in each of four height bands;
- **motions**: along the push, 0.6-1.0 of the full 9 cm stroke, level or pressing down;
- **directions**: the asked one (``--params random``), or eight around the circle (``--params none``,
  where the seed's objective takes any direction; fewer contacts and strokes per direction);
- **aims** (``--aim-deg 5 10``, with a direction only): the same pushes also along the asked direction turned
  by each of these angles either way, contacts nearest the line through the centre of mass along the turned
  push. A push is judged by the *asked* direction (within 15 deg), so a push aimed a little to one side may
  meet it where the straight one turns the object.

A start counts when any candidate meets the criterion. This is a bound from below on what a policy
could reach with this fingertip and protocol (a cleverer candidate may exist), and the shipped policy's
greedy success on the same starts is printed beside it. It is a bound in hindsight: each start keeps whichever
candidate worked. So the report also gives each **rule** on its own (a candidate's aim, height band, rank from the
line, stroke and press, the same on every start): the best single rule is what the same privileged pusher reaches
when it has to commit to one push before seeing the outcome.
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import asdict, dataclass, field

import numpy as np
import torch
from tqdm import tqdm

from affordplan.errors import InputError
from affordplan.log import cli_logging, one_line_errors
from affordplan.sim.simulator import Simulator
from primitives.training.env import PrimitiveEnv
from primitives.training.evaluate import greedy_action, held_out_config, load_policy
from primitives.training.neighbours import judged_execution
from primitives.training.scripted import facing_and_offset

CLOUD_POINTS = 2048
HEIGHT_BANDS = ((0.05, 0.3), (0.3, 0.5), (0.5, 0.7), (0.7, 0.95))  # fractions of the object's height
CANDIDATES = 64  # per start and aim, at most (fewer where a height band has no facing points)


@dataclass(frozen=True)
class Candidate:
    contact: np.ndarray  # (3,) world, metres
    normal: np.ndarray  # (3,) world, outward unit normal
    motion: np.ndarray  # (3,) world, in [-1, 1] (x 3 cm per control step)
    rule: str = ""  # what picked it, the same on every start: aim, height band, rank from the line, stroke, press


def push_candidates(points: np.ndarray, normals: np.ndarray, com: np.ndarray, direction: float,
                    per_band: int, strokes: tuple[float, ...], presses: tuple[float, ...],
                    rule: str = "") -> list[Candidate]:
    """Scripted pushes along the world yaw ``direction`` (radians) of an object whose centre of mass is ``com``.

    ``points``, ``normals``: a dense world-frame cloud. In each height band, the ``per_band`` facing points
    nearest the line through ``com`` along the push, each with every stroke (fraction of the full stroke)
    and press (downward motion component). Each candidate's ``rule`` is ``rule`` (what chose the direction)
    followed by its band, rank from the line, stroke and press.
    """
    d = np.array([math.cos(direction), math.sin(direction), 0.0])
    facing, lateral = facing_and_offset(points, normals, com, d)  # lateral: from the push line through the COM
    z0, z1 = points[:, 2].min(), points[:, 2].max()
    out = []
    for band_index, (lo, hi) in enumerate(HEIGHT_BANDS):
        band = facing & (points[:, 2] >= z0 + lo * (z1 - z0)) & (points[:, 2] <= z0 + hi * (z1 - z0))
        idx = np.flatnonzero(band)
        for rank, i in enumerate(idx[np.argsort(lateral[idx])[:per_band]]):
            for s in strokes:
                for press in presses:
                    label = f"{rule}band {band_index}, rank {rank}, stroke {s:g}, press {press:g}"
                    out.append(Candidate(points[i], normals[i], s * d + np.array([0.0, 0.0, -press]), label))
    return out


def candidates_for(sim: Simulator, params: dict | None, rng: np.random.Generator,
                   aims: tuple[float, ...] = ()) -> list[Candidate]:
    """The scripted pushes tried from the simulator's current state (see the module docstring).

    ``aims``: with a direction, also push along it turned by each of these angles (radians, > 0) either way.
    """
    points, normals = sim.point_cloud(CLOUD_POINTS)
    com = sim.object_pose()[:3, 3]  # the object's body frame sits at its centre of mass
    if params is not None:
        turns = (0.0,) + tuple(sign * a for a in aims for sign in (1.0, -1.0))
        return [c for turn in turns
                for c in push_candidates(points, normals, com, params["direction"] + turn, 2, (0.6, 0.7, 0.85, 1.0),
                                         (0.0, 0.5), f"aim {math.degrees(turn):+.4g} deg, ")]
    offset = rng.uniform(0.0, math.pi / 4)
    return [c for k in range(8)
            for c in push_candidates(points, normals, com, offset + k * math.pi / 4, 1, (0.7, 1.0), (0.0,),
                                     f"direction {45 * k} deg + a random offset, ")]


@dataclass
class CeilingResult:
    starts: int
    params: str
    aims_deg: list[float] = field(default_factory=list)  # turns of the asked direction also pushed along, either way
    any_success: int = 0  # starts where some candidate succeeded
    policy_success: int = 0  # starts where the shipped policy's greedy push succeeded
    candidate_success: list[float] = field(default_factory=list)  # per start, share of candidates that succeeded
    rule_success: dict = field(default_factory=dict)  # candidate rule -> starts where that rule's push succeeded
    per_kind: dict = field(default_factory=dict)  # object kind -> [starts, any_success, policy_success]

    @property
    def ceiling(self) -> float:
        return self.any_success / max(1, self.starts)

    @property
    def policy(self) -> float:
        return self.policy_success / max(1, self.starts)

    @property
    def mean_candidate_success(self) -> float:
        """The share of scripted pushes that succeed, mean over the starts: a push drawn at random."""
        return float(np.mean(self.candidate_success)) if self.candidate_success else 0.0

    def rules_ranked(self) -> list[tuple[str, float]]:
        """Each rule's success over all the starts (a start where the rule found no contact counts as a
        failure), best first; ties in the order the rules were first tried."""
        return sorted(((r, n / max(1, self.starts)) for r, n in self.rule_success.items()), key=lambda t: -t[1])

    def as_dict(self) -> dict:
        d = asdict(self)
        ranked = self.rules_ranked()
        d.update(ceiling=self.ceiling, policy=self.policy,
                 mean_candidate_success=self.mean_candidate_success,
                 best_rule=ranked[0][0] if ranked else None, best_rule_success=ranked[0][1] if ranked else 0.0,
                 rule_success=dict(ranked))
        del d["candidate_success"]
        return d

    def report(self) -> str:
        aims = f", also aimed {', '.join(f'+-{a:g}' for a in self.aims_deg)} deg" if self.aims_deg else ""
        lines = [f"push ({self.params}): {self.starts} held-out starts{aims}",
                 f"  best of scripted pushes (privileged COM, dense cloud): {self.ceiling:.3f}",
                 f"  shipped policy, greedy, same starts:                   {self.policy:.3f}",
                 f"  share of scripted pushes that succeed, mean over starts: {self.mean_candidate_success:.3f}",
                 "  the best single rules, each the same push on every start:"]
        lines += [f"    {rate:.3f}  {rule}" for rule, rate in self.rules_ranked()[:3]]
        lines.append("  per object kind (starts: ceiling / policy):")
        for kind, (n, a, p) in sorted(self.per_kind.items()):
            lines.append(f"    {kind:10s} {n:4d}: {a / n:.2f} / {p / n:.2f}")
        return "\n".join(lines)


def push_ceiling(starts: int = 100, params: str = "random", seed: int = 1234, weights=None,
                 progress: bool = True, aims: tuple[float, ...] = ()) -> CeilingResult:
    """Best-of-scripted-pushes success on the evaluation's held-out starts (module docstring); ``aims``: the
    turns of the asked direction also pushed along, radians (:func:`candidates_for`)."""
    if any(not (0.0 < a < math.radians(15.0)) for a in aims):
        raise InputError(f"aims must lie strictly between 0 and 15 deg (the criterion's tolerance), got "
                         f"{[round(math.degrees(a), 3) for a in aims]} deg")
    p_params = 1.0 if params == "random" else 0.0
    env = PrimitiveEnv(held_out_config("push", p_params), seed=seed)  # the evaluation's starts
    model = load_policy(weights, "push")
    rng = np.random.default_rng(seed)
    result = CeilingResult(starts, params, [math.degrees(a) for a in aims] if params == "random" else [])
    for _ in tqdm(range(starts), desc="push ceiling", disable=not progress, unit="start", mininterval=2.0):
        obs = env.reset()
        sim, prm = env.sim, env.params
        start = sim.snapshot()
        wins = 0
        cands = candidates_for(sim, prm, rng, aims)  # aims apply to a direction only
        for c in cands:
            sim.restore(start)
            ok = judged_execution(sim, "push", prm, c.contact, c.motion, c.normal)
            wins += ok
            result.rule_success[c.rule] = result.rule_success.get(c.rule, 0) + ok
        sim.restore(start)
        idx, motion, _ = greedy_action(model, obs)
        policy_ok = env.step(idx, motion).success
        kind = sim.obj.name.rsplit("_", 1)[-1]
        tally = result.per_kind.setdefault(kind, [0, 0, 0])
        tally[0] += 1
        tally[1] += wins > 0
        tally[2] += policy_ok
        result.any_success += wins > 0
        result.policy_success += policy_ok
        result.candidate_success.append(wins / max(1, len(cands)))
    env.close()
    return result


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m primitives.research.ceiling", description=__doc__.split("\n\n")[0],
        epilog="examples:\n  python -m primitives.research.ceiling --starts 100 --params random\n"
               "  python -m primitives.research.ceiling --starts 100 --params none --json",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--starts", type=int, default=100, help="held-out starts (default: 100)")
    p.add_argument("--params", choices=["none", "random"], default="random",
                   help="random: a push direction is asked (default); none: the seed's objective, any direction")
    p.add_argument("--seed", type=int, default=1234, help="the evaluation's seed: same starts (default: 1234)")
    p.add_argument("--weights", default=None, help="push policy to compare with (default: shipped)")
    p.add_argument("--aim-deg", type=float, nargs="*", default=[], metavar="DEG",
                   help="with a direction, also push along it turned by each of these angles either way, "
                        "deg in (0, 15) (default: none)")
    p.add_argument("--json", action="store_true")
    return p


@one_line_errors("primitives.research.ceiling")  # missing or broken weights, ...
def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    cli_logging()
    if args.starts < 1:
        parser.error(f"--starts must be a positive integer, got {args.starts}")
    torch.set_num_threads(1)
    result = push_ceiling(args.starts, args.params, args.seed, args.weights, progress=not args.json,
                          aims=tuple(math.radians(a) for a in args.aim_deg))
    print(json.dumps(result.as_dict(), indent=2) if args.json else result.report())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
