"""The demo's task from several start yaws: how often the shipped skills reach its goal in the arm sim.

    python examples/demo_start_yaws.py                 # the nine yaws the README quotes
    python examples/demo_start_yaws.py -150 0 90       # yaws of your own, degrees
    python examples/demo_start_yaws.py --weights-dir candidates/push_0.18   # other skill files
"""

import argparse
import math

import affordplan as ap
from affordplan.app.scene_file import demo_scene
from planner.predict import Predictor

MAX_PRIMITIVES = 30
YAWS_DEG = (29.0, -150.0, -105.0, -60.0, -15.0, 30.0, 75.0, 120.0, 165.0)

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("yaws", nargs="*", type=float, metavar="DEG",
                        help="start yaws, degrees (default: the nine the README quotes)")
    parser.add_argument("--weights-dir", default=None, metavar="DIR",
                        help="run the skills from this folder's files instead of the shipped ones")
    args = parser.parse_args()
    scene = demo_scene()
    obj = ap.load_object(scene.object)
    yaws = args.yaws or YAWS_DEG
    predictor = Predictor(obj, seed=0, weights_dir=args.weights_dir)  # as plan() makes one; loaded once for all yaws
    reached, predicted, expected, spent = 0, [], [], []
    for yaw_deg in yaws:
        start = dict(scene.start, yaw=math.radians(yaw_deg))
        try:
            plan = ap.plan(obj, scene.goal, start=start, obstacles=scene.obstacles,
                           predictor=predictor)
            odds = plan.odds(MAX_PRIMITIVES)
            ex = plan.execute(sim="arm", max_primitives=MAX_PRIMITIVES)
            ok, detail = ex.success, f"{ex.n_primitives} primitives: {ex.reason}"
            predicted.append(odds.p_success)
            expected.append(odds.expected_primitives)
            spent.append(ex.n_primitives)
            detail += f"; predicted p_success {odds.p_success:.2f}, about {odds.expected_primitives:.1f} primitives"
        except ap.errors.AffordplanError as exc:
            ok, detail = False, f"no plan: {exc}"
            predicted.append(0.0)
        reached += ok
        print(f"start yaw {yaw_deg:+6.0f} deg: {'REACHED' if ok else 'not reached'} ({detail})", flush=True)
    print(f"reached the goal from {reached} of {len(yaws)} start yaws; predicted p_success "
          f"{sum(predicted) / len(predicted):.2f} on average (a calibrated prediction matches "
          f"{reached / len(yaws):.2f}); primitives: predicted {sum(expected) / max(1, len(expected)):.1f}, "
          f"spent {sum(spent) / max(1, len(spent)):.1f} on average")
