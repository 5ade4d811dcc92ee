"""Flip the mug upright (it starts on its side), then push it through the gap in a wall.

    python examples/mug_upright_through_gap.py [--sim arm|finger] [--out DIR]
"""

import math
import sys

import numpy as np

import affordplan as ap
from affordplan.app.example import run_example

if __name__ == "__main__":
    mug = ap.load_object("mug")
    # "Upright": the resting state whose up-vector is the mug's axis, opening up.
    upright = max(mug.resting_states, key=lambda s: float(s.up @ np.array([0.0, 0.0, 1.0]))).index
    lying = mug.resting_states[0].index if upright != 0 else 1
    wall = [ap.Box(center=(0.6, -0.21), size=(0.02, 0.2, 0.1)), ap.Box(center=(0.6, 0.21), size=(0.02, 0.2, 0.1))]
    goal = ap.Goal(xy=(0.69, 0.0), resting_state=upright)
    start = {"resting_state": lying, "xy": (0.45, -0.05), "yaw": math.radians(-150.0)}
    sys.exit(run_example("mug_upright_through_gap", mug, goal, start, wall, __doc__))
