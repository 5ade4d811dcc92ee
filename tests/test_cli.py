"""The command line: demo and bench sim do real work and report it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from affordplan import cli
from affordplan.bench import bench_sim
from affordplan.demo import run_demo


def test_demo_executes_three_primitives_and_saves_a_picture(tmp_path):
    lines: list[str] = []
    rows = run_demo(tmp_path, echo=lines.append)
    assert [r["primitive"] for r in rows] == ["push", "roll", "spin"]
    assert all(r["valid"] and r["approach_ok"] for r in rows)
    push = rows[0]
    assert push["moved_cm"] > 4.0 and push["turned_deg"] < 5.0
    assert (tmp_path / "demo.png").stat().st_size > 10_000
    assert any("seed losses" in line for line in lines)


def test_bench_sim_counts_steps_and_time():
    r = bench_sim("cube", n=6, progress=False)
    assert r.primitives == 6 and r.steps > 6 * 500  # each primitive simulates >= 1 s
    assert r.wall_s >= r.in_loop_physics_s > 0  # wall time includes the physics it measures
    assert r.ratio >= 1.0


def test_cli_bench_json(capsys):
    assert cli.main(["bench", "sim", "-n", "3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data[0]["object"] == "cube" and data[0]["primitives"] == 3
    assert data[0]["primitives_per_s"] > 0


def test_cli_reports_library_errors_cleanly(capsys):
    assert cli.main(["demo", "--object", "teapot", "--no-render"]) == 2
    assert "unknown object 'teapot'" in capsys.readouterr().err


def test_cli_help_has_examples(capsys):
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    assert "examples:" in capsys.readouterr().out


def test_bench_sim2sim_compares_identical_primitives():
    from affordplan.bench import bench_sim2sim

    r = bench_sim2sim("cube", n=4, progress=False)
    assert r.compared + r.skipped == 4
    assert len(r.displacement_diff_m) == r.compared
    assert np.all(r.displacement_diff_m >= 0) and np.all(r.rotation_diff_rad >= 0)
    assert "p90" in r.report()
