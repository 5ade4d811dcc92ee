"""Random primitives on every catalogue object next to a wall, with the seed's success criteria.

    python examples/primitives_near_a_wall.py [--n 20] [--out primitives-near-a-wall.png]

Each object starts in its most likely resting state 10 cm in front of a wall; random contacts from
its point cloud and random motions are executed in the finger sim. The script prints, per object,
how often a random action happens to meet the push / roll / spin criteria (the baseline the learned
primitives must beat) and how often the wall stopped the object, and saves a picture of the last one.
"""

from __future__ import annotations

import argparse
import os

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402

import affordplan as ap  # noqa: E402
from primitives import rewards  # noqa: E402

WALL = ap.Box(center=(0.62, 0.0), size=(0.02, 0.5, 0.12))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--n", type=int, default=20, help="primitives per object")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="primitives-near-a-wall.png")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    print(f"{'object':12s} {'push':>6s} {'roll':>6s} {'spin':>6s} {'at wall':>8s} {'invalid':>8s}")
    for name in ap.catalogue():
        obj = ap.load_object(name)
        sim = ap.Simulator(obj, obstacles=[WALL], seed=args.seed)
        counts = dict(push=0, roll=0, spin=0, wall=0, invalid=0)
        for _ in range(args.n):
            sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=rng.uniform(-np.pi, np.pi))
            points, normals = sim.point_cloud(256)
            i = int(rng.integers(len(points)))
            out = sim.execute(points[i], rng.uniform(-1, 1, size=3), normal=normals[i])
            counts["invalid"] += not out.valid
            for k, ok in rewards.SUCCESSES.items():
                counts[k] += ok(out.pose_before, out.pose_after)
            counts["wall"] += out.pose_after[0, 3] > 0.61 - 0.5 * max(obj.mesh.extents[:2]) - 0.01
        print(f"{name:12s} " + " ".join(f"{counts[k] / args.n:6.2f}" for k in ("push", "roll", "spin"))
              + f" {counts['wall'] / args.n:8.2f} {counts['invalid']:8d}")
    try:
        from PIL import Image

        Image.fromarray(sim.render(640, 480)).save(args.out)
        print(f"wrote {args.out}")
    except Exception as exc:  # no OpenGL: the figures above still stand
        print(f"no picture: {exc}")


if __name__ == "__main__":
    main()
