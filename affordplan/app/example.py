"""Shared by the planning examples in examples/: plan, print, execute in the arm sim, save a plot and frames."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import affordplan as ap
from planner.plot import plot_plan, save_frames
from planner.predict import Predictor


def run_example(name: str, obj, goal, start, obstacles, description: str) -> int:
    """Parse the example's command line (``--sim``, ``--out``, ``--seed``, ``--max-primitives``, ``--no-render``,
    ``--weights-dir``), plan, execute, print the outcome and write ``plan.png`` and ``frames.png``; returns the exit
    status (0: goal reached)."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--sim", default="arm", choices=["arm", "finger"])
    parser.add_argument("--out", default=f"affordplan-examples/{name}")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--max-primitives", type=int, default=60)
    parser.add_argument("--no-render", action="store_true")
    parser.add_argument("--weights-dir", default=None, metavar="DIR",
                        help="run the skills from this folder's files (laid out like primitives/weights/, e.g. a "
                             "candidate set) instead of the shipped ones")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    predictor = Predictor(obj, seed=args.seed, weights_dir=args.weights_dir)  # as plan() makes one, but for the folder
    plan = ap.plan(obj, goal, start=start, obstacles=obstacles, seed=args.seed, predictor=predictor)
    print(plan)
    ex = plan.execute(sim=args.sim, max_primitives=args.max_primitives, seed=args.seed,
                      render=None if args.no_render else "overview")
    print(ex)
    d, yaw_err, state_ok = goal.errors(obj, ex.final_pose)
    print(f"final: {100 * d:.1f} cm from the goal, yaw error {math.degrees(yaw_err):.0f} deg, "
          f"resting state {'right' if state_ok else 'wrong'}")
    plot_plan(plan, out / "plan.png", execution=ex)
    save_frames(ex.frames, out / "frames.png")
    print(f"wrote {out / 'plan.png'} and {out / 'frames.png'}")
    return 0 if ex.success else 1
