"""The primitive benches (affordplan.app.bench.primitive): physics steps and time, finger-vs-arm comparisons."""

from __future__ import annotations

import numpy as np

from affordplan.app.bench.primitive import bench_sim


def test_bench_sim_counts_steps_and_time():
    r = bench_sim("cube", n=6, progress=False)
    assert r.primitives == 6 and r.steps > 6 * 500  # each primitive simulates >= 1 s
    assert r.wall_s >= r.in_loop_physics_s > 0  # wall time includes the physics it measures
    assert r.ratio >= 1.0


def test_bench_sim2sim_compares_identical_primitives():
    from affordplan.app.bench.primitive import bench_sim2sim

    r = bench_sim2sim("cube", n=4, progress=False)
    assert r.compared + r.skipped == 4
    assert len(r.displacement_diff_m) == r.compared
    assert np.all(r.displacement_diff_m >= 0) and np.all(r.rotation_diff_rad >= 0)
    assert "p90" in r.report()
