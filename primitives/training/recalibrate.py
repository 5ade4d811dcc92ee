"""A searched success model recalibrated on the objects it is to be trusted on.

    python -m primitives.training.recalibrate push --objects housekeep:validation --out runs/push_recal
    python -m primitives.training.recalibrate spin --objects housekeep:validation --sensor surface --out runs/spin_recal

A searched success model (what :meth:`primitives.skills.Skill.success_probability` reports) is an ensemble's mean
logit ``z`` turned into a probability by a Platt scaling, ``sigmoid(a z + b)``, fitted when the model was trained
on its own calibration rollouts. Where a skill meets other objects or another sensor than those, its probabilities
can drift from the outcomes while still ranking starts as well (the AUROC does not depend on ``a > 0`` and ``b``).

:func:`recalibrate` refits ``(a, b)`` alone, by log-loss, on frame-searched rollouts of the skill as it acts
(:func:`primitives.training.success.collect_frame_search`: the frame search and ratings for the sensor, as a user's
call acts), leaving the ensemble as it is. Because the rollouts that fit the scaling cannot also judge it, it
reports a **leave-one-object-out** estimate: each object's rollouts scored by the scaling fitted on the other
objects' (:class:`Recalibration`). The command writes the recalibrated model beside its rollouts and that report;
nothing is shipped by it. Fitting on held-out test objects is refused (:func:`primitives.training.env.check_objects`).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from affordplan.errors import InputError
from affordplan.log import cli_logging, one_line_errors
from affordplan.sim.sensor import SENSORS
from primitives import weights_file
from primitives.frames import load_frame_search
from primitives.success_model import SuccessModel, SuccessNet, load_success_net
from primitives.training.env import PRIMITIVES, check_objects
from primitives.training.provenance import recorded_path
from primitives.training.success import Rollouts, _platt, collect_frame_search, metrics, save

MIN_OBJECTS = 2  # a leave-one-object-out estimate needs another object to fit on


@dataclass(frozen=True)
class Recalibration:
    """A Platt scaling refitted on rollouts, and how it does there.

    ``platt``: the new ``(a, b)``; ``before``: the model's own probabilities on the rollouts; ``in_sample``: the new
    scaling's on the rollouts it was fitted to; ``leave_one_object_out``: each object's rollouts scored by the
    scaling fitted without them (the estimate to judge it by). Each is ``(n,)``, in the rollouts' order.
    """

    platt: tuple[float, float]
    before: np.ndarray
    in_sample: np.ndarray
    leave_one_object_out: np.ndarray

    def report(self, success: np.ndarray) -> dict:
        """:func:`~primitives.training.success.metrics` (ECE, AUROC, Brier, ...) of each, against ``success``."""
        return dict(platt=list(self.platt), before=metrics(self.before, success),
                    in_sample=metrics(self.in_sample, success),
                    leave_one_object_out=metrics(self.leave_one_object_out, success))


def recalibrate(net: SuccessNet, data: Rollouts) -> Recalibration:
    """Refit ``net``'s Platt scaling on ``data`` (module docstring); ``net`` is left unchanged.

    Raises:
        InputError: rollouts of fewer than :data:`MIN_OBJECTS` objects.
    """
    groups = np.unique(data.group)
    if len(groups) < MIN_OBJECTS:
        raise InputError(f"recalibrating needs rollouts of at least {MIN_OBJECTS} objects, got {len(groups)}")
    with torch.no_grad():
        obs, decision = torch.from_numpy(data.obs.astype(np.float32)), torch.from_numpy(data.decision)
        z = net.logit(obs, decision)  # the ensemble once; each scaling below is applied to these logits
    y = torch.from_numpy(data.success.astype(np.float32))

    def scaled(ab: torch.Tensor, z: torch.Tensor) -> np.ndarray:
        return torch.sigmoid(ab[0] * z + ab[1]).numpy()

    ab = _platt(z, y)
    loo = np.zeros(len(data), dtype=np.float32)
    for g in groups:
        held = torch.from_numpy(data.group == g)
        loo[held.numpy()] = scaled(_platt(z[~held], y[~held]), z[held])
    return Recalibration((float(ab[0]), float(ab[1])), scaled(net.platt, z), scaled(ab, z), loo)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m primitives.training.recalibrate",
        description="Refit a searched success model's Platt scaling on frame-searched rollouts of other objects.",
        epilog="example:\n  python -m primitives.training.recalibrate push --objects housekeep:validation "
               "--out runs/push_recal", formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("skill", choices=PRIMITIVES)
    p.add_argument("--objects", default="housekeep:validation", metavar="OBJECTS",
                   help="objects the rollouts are drawn from, as --objects of python -m primitives.success takes "
                        "them; never held-out test objects (default: %(default)s)")
    p.add_argument("--sensor", choices=SENSORS, default="cameras", help="the clouds seen (default: %(default)s)")
    p.add_argument("--frames", default="shipped", metavar="shipped|PATH",
                   help="the frame search the skill acts with (default: the shipped one for --sensor)")
    p.add_argument("--searched", default=None, metavar="PATH",
                   help="the searched success model to recalibrate (default: the shipped one for --sensor)")
    p.add_argument("--policy", default=None, help="policy weights (default: the shipped ones)")
    p.add_argument("--rollouts", type=int, default=600, help="frame-searched rollouts (default: 600)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", required=True, help="folder for the rollouts (reused when there), the model "
                                                "(success_searched.pt) and calibrate.json")
    p.add_argument("--json", action="store_true", help="no progress bar")
    return p


@one_line_errors("primitives.training.recalibrate")  # held-out objects, a missing or broken model, ...
def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    cli_logging()
    if args.rollouts < 1:
        parser.error(f"--rollouts must be a positive integer, got {args.rollouts}")
    torch.set_num_threads(1)
    check_objects(args.objects, fitting=True)
    return run(args)


def run(args: argparse.Namespace) -> int:
    """Collect (or reuse) the rollouts, refit, write the model and its report into ``args.out``, print it."""
    from primitives.policy import load_policy

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    searched_path = Path(args.searched) if args.searched else weights_file.rating_path(args.skill, "searched",
                                                                                          args.sensor)
    net = load_success_net(args.skill, searched_path)
    cache = out / f"calibrate_rollouts_{args.rollouts}_{args.seed}.npz"
    if cache.exists():  # a run killed after collecting resumes here
        data = Rollouts.load(cache)
    else:
        rater = SuccessModel(load_policy(args.policy, args.skill, sensor=args.sensor),
                             load_success_net(args.skill, None, sensor=args.sensor))
        search = load_frame_search(args.skill, args.frames, sensor=args.sensor)
        _, data = collect_frame_search(rater, args.skill, args.rollouts, search, args.objects, n_objects=200,
                                       seed=args.seed, progress=not args.json, sensor=args.sensor)
        data.save(cache)
    result = recalibrate(net, data)
    platt_before = [float(v) for v in net.platt]
    net.platt.copy_(torch.tensor(result.platt))
    info = dict(skill=args.skill, sensor=args.sensor, objects=args.objects, rollouts=len(data), seed=args.seed,
                frames=recorded_path(args.frames), searched=recorded_path(searched_path), platt_before=platt_before,
                objects_seen=int(len(np.unique(data.group))), **result.report(data.success),
                command=" ".join(["python -m primitives.training.recalibrate", args.skill, "--objects", args.objects,
                                  "--sensor", args.sensor, "--rollouts", str(args.rollouts), "--seed",
                                  str(args.seed), "--out", recorded_path(args.out),
                                  *(["--frames", recorded_path(args.frames)] if args.frames != "shipped" else []),
                                  *(["--searched", recorded_path(args.searched)] if args.searched else []),
                                  *(["--policy", recorded_path(args.policy)] if args.policy else [])]))
    save(net, out / "success_searched.pt", info)
    (out / "calibrate.json").write_text(json.dumps(info, indent=2))
    print(json.dumps(info, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
