"""The command line and what it stands on: scene files, the demo run, videos, renders, the bench."""

from __future__ import annotations

import copy
import json
import math
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import affordplan as ap
from affordplan.app import cli
from affordplan.app.bench.primitive import bench_sim
from affordplan.app.scene_file import DEMO_SCENE, demo_scene, load_scene, parse_scene
from affordplan.app.video import write_video
from affordplan.errors import InputError, MeshError

SCENES = Path(__file__).parents[1] / "examples" / "scenes"


# ----------------------------------------------------------------------------- scene files
def test_example_json_scene_is_the_demo_scene():
    scene = load_scene(SCENES / "mug_wall.json")
    assert scene == demo_scene()
    assert scene.name == "mug_wall" and scene.object == "mug"
    assert scene.start == {"resting_state": 0, "xy": (0.45, -0.05), "yaw": pytest.approx(math.radians(29.0))}
    assert scene.goal.resting_state == 1 and scene.goal.yaw == pytest.approx(math.pi / 2)
    assert [b.center for b in scene.obstacles] == [(0.6, -0.21), (0.6, 0.21)]


def test_yaml_scenes_parse_with_degrees_and_tolerances():
    corridor = load_scene(SCENES / "box_corridor.yaml")
    assert corridor.object == "lunch_box"
    assert corridor.goal.yaw == pytest.approx(math.pi) and corridor.goal.yaw_tol == pytest.approx(math.radians(15))
    assert corridor.start["yaw"] == 0.0 and len(corridor.obstacles) == 2
    assert not corridor.goal.yaw_symmetric  # the labelled box's two ends differ
    die = load_scene(SCENES / "die_two_blocks.yaml")
    assert die.goal.resting_state == 2 and die.goal.yaw == pytest.approx(math.radians(30))
    assert not die.goal.yaw_symmetric and load_scene(SCENES / "mug_wall.json").goal.yaw_symmetric  # the default
    # a scene survives a round trip through its plain-data form
    assert parse_scene(json.loads(json.dumps(die.as_dict()))) == die


def _mutated(path: tuple, value):
    data = copy.deepcopy(DEMO_SCENE)
    d = data
    for key in path[:-1]:
        d = d[key]
    if value is _DELETE:
        del d[path[-1]]
    else:
        d[path[-1]] = value
    return data


_DELETE = object()


@pytest.mark.parametrize("path, value, error, words", [
    (("goal", "xy"), [0.69], InputError, "goal.xy must be a list of 2 numbers"),
    (("goal", "xy"), [0.69, "a"], InputError, "goal.xy[1] must be a finite number"),
    (("goal", "xy_tol"), 0.0, InputError, "goal.xy_tol must be positive"),
    (("goal", "yaw"), 1.0, InputError, "give yaw (radians) or yaw_deg (degrees), not both"),
    (("goal", "resting_state"), -1, InputError, "goal.resting_state must be a resting-state index"),
    (("goal", "colour"), "red", InputError, "goal: unknown field(s) ['colour']"),
    (("goal", "yaw_symmetric"), "no", InputError, "goal.yaw_symmetric must be true or false"),
    (("start", "xy"), _DELETE, InputError, "start: missing field 'xy'"),
    (("start", "resting_state"), 1.5, InputError, "start.resting_state must be a resting-state index"),
    (("obstacles",), {"center": [0.6, 0.0]}, InputError, "obstacles must be a list"),
    (("obstacles", 1, "size"), [0.02, -0.2, 0.1], InputError, "obstacles[1].size must be positive"),
    (("obstacles", 0, "centre"), [0.6, 0.0], InputError, "obstacles[0]: unknown field(s) ['centre']"),
    (("goal",), _DELETE, InputError, "missing field 'goal'"),
    (("object",), 3, InputError, "object must be a catalogue name or a mesh path"),
    (("obstacle",), [], InputError, "unknown field(s) ['obstacle']"),
])
def test_bad_scene_fields_are_named(path, value, error, words):
    with pytest.raises(error) as info:
        parse_scene(_mutated(path, value), source="s.json")
    assert str(info.value).startswith("s.json: ") and words in str(info.value)


def test_resting_states_are_checked_against_the_object():
    scene = parse_scene(_mutated(("goal", "resting_state"), 7), source="s.json")
    with pytest.raises(InputError, match=r"s.json: goal.resting_state: mug has 3 resting states"):
        scene.load_object()
    with pytest.raises(MeshError, match="s.json: object: unknown object 'teapot'"):
        parse_scene(_mutated(("object",), "teapot"), source="s.json").load_object()


def test_scene_files_on_disk(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        load_scene(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{\"object\": \"mug\",")
    with pytest.raises(InputError, match="bad.json: not valid JSON"):
        load_scene(bad)
    yml = tmp_path / "bad.yaml"
    yml.write_text("object: [mug\n")
    with pytest.raises(InputError, match="bad.yaml: not valid YAML"):
        load_scene(yml)
    txt = tmp_path / "scene.txt"
    txt.write_text("{}")
    with pytest.raises(InputError, match="must end in .json, .yaml or .yml"):
        load_scene(txt)
    # a relative mesh path is resolved against the scene file's folder; the name defaults to the stem
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "part.stl").write_text("solid part\nendsolid part\n")
    data = _mutated(("object",), "meshes/part.stl")
    del data["name"]
    (tmp_path / "part_scene.json").write_text(json.dumps(data))
    scene = load_scene(tmp_path / "part_scene.json")
    assert Path(scene.object) == tmp_path / "meshes" / "part.stl" and scene.name == "part_scene"


# ------------------------------------------------------------------------------------ help
SUBCOMMANDS = [["demo"], ["plan"], ["render"], ["affordances"], ["bench"], ["bench", "sim"],
               ["bench", "sim2sim"], ["bench", "query"], ["bench", "plan"]]


def test_cli_help_has_examples(capsys):
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    out = capsys.readouterr().out
    assert "examples:" in out
    assert all(name in out for name in ("demo", "plan", "render", "affordances", "bench"))


def test_version_names_the_physics_and_learning_libraries(capsys):
    import mujoco

    import affordplan

    with pytest.raises(SystemExit) as info:
        cli.main(["--version"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith(f"affordplan {affordplan.__version__} (") and f"mujoco {mujoco.__version__}" in out
    assert "torch " in out and "ompl " in out


@pytest.mark.parametrize("argv", SUBCOMMANDS, ids=" ".join)
def test_every_subcommand_help_shows_an_example(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv + ["--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert "example" in out and f"affordplan {' '.join(argv)}" in out


def test_bench_registers_robustness_when_it_exists(monkeypatch, capsys):
    module = types.ModuleType("affordplan.app.robustness")

    def register_cli(bench_sub):
        p = bench_sub.add_parser("robustness", help="fake", epilog="example:\n  affordplan bench robustness")
        p.set_defaults(func=lambda args: print("robustness ran") or 0)

    module.register_cli = register_cli
    monkeypatch.setitem(sys.modules, "affordplan.app.robustness", module)
    monkeypatch.setattr("affordplan.app.robustness", module, raising=False)
    assert cli.main(["bench", "robustness"]) == 0
    assert "robustness ran" in capsys.readouterr().out


# ---------------------------------------------------------------------------------- errors
@pytest.mark.parametrize("argv", [["bench", "sim", "-n", "0"], ["bench", "sim2sim", "--skill", "roll", "-n", "0"],
                                  ["bench", "plan", "--tasks", "-3"]])
def test_benchmark_counts_must_be_positive(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    assert info.value.code == 2 and "expected a positive integer" in capsys.readouterr().err


def test_bench_plan_task_indices_must_not_be_negative(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["bench", "plan", "--task", "2", "-1"])
    assert info.value.code == 2 and "expected a non-negative integer, got -1" in capsys.readouterr().err


def test_bench_plan_refuses_a_weights_folder_that_is_not_there_before_any_task(capsys, tmp_path):
    assert cli.main(["bench", "plan", "--tasks", "1", "--planner", "affordplan", "--json",
                     "--weights-dir", str(tmp_path / "nowhere")]) == 2
    captured = capsys.readouterr()
    assert "is not a folder" in captured.err and captured.out == ""


def test_cli_reports_library_errors_cleanly(capsys, tmp_path):
    assert cli.main(["render", "teapot"]) == 2
    assert "unknown object 'teapot'" in capsys.readouterr().err
    scene = tmp_path / "s.json"
    scene.write_text(json.dumps(_mutated(("obstacles", 0, "size"), [0.02, 0.2])))
    assert cli.main(["plan", str(scene), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("affordplan: error: ") and "obstacles[0].size must be a list of 3 numbers" in err
    assert not (tmp_path / "out").exists()


# ------------------------------------------------------------------------- render, video
def test_render_writes_one_tile_per_state(tmp_path, capsys):
    out = tmp_path / "cube.png"
    assert cli.main(["render", "cube", "--state", "0", "2", "--width", "64", "--height", "48",
                     "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "cube: 6 resting states" in text and f"wrote {out}" in text
    image = np.asarray(Image.open(out).convert("RGB"))
    assert image.shape == (48, 128, 3)
    assert image[20:, :64].std() > 5 and image[20:, 64:].std() > 5  # rendered scenes, not blank tiles
    assert cli.main(["render", "cube", "--state", "6", "--width", "64", "--height", "48"]) == 2
    assert "cube has 6 resting states (0..5), got state 6" in capsys.readouterr().err


def _frames(n=5, h=36, w=48):
    rng = np.random.default_rng(0)
    return [rng.integers(0, 255, (h, w, 3), dtype=np.uint8) for _ in range(n)]


def test_write_video_mp4_and_gif(tmp_path):
    import imageio.v2 as imageio

    mp4 = write_video(_frames(), tmp_path / "v.mp4", fps=5)
    assert mp4.suffix == ".mp4" and len(imageio.mimread(mp4)) == 5
    gif = write_video(_frames(4), tmp_path / "v.gif", fps=5)
    assert Image.open(gif).n_frames == 4
    with pytest.raises(InputError, match="no frames"):
        write_video([], tmp_path / "x.mp4")


def test_write_video_falls_back_to_gif_without_ffmpeg(tmp_path, monkeypatch):
    def no_ffmpeg(*args, **kwargs):
        raise ImportError("no module named imageio_ffmpeg")

    monkeypatch.setattr("affordplan.app.video._write_mp4", no_ffmpeg)
    with pytest.warns(UserWarning, match="writing a GIF instead"):
        path = write_video(_frames(3), tmp_path / "v.mp4", fps=5)
    assert path == tmp_path / "v.gif" and Image.open(path).n_frames == 3


def test_viewer_without_a_display_carries_on_headless(monkeypatch):
    from affordplan.app.viewer import open_viewer

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    lines: list[str] = []
    assert open_viewer(object(), echo=lines.append) is None
    assert "no display" in lines[0] and "headless" in lines[0]


# ------------------------------------------------------------------------------------ demo
def test_demo_one_primitive_in_the_arm_sim_writes_every_output(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    out = tmp_path / "demo"
    argv = ["demo", "--max-primitives", "1", "--out", str(out), "--width", "96", "--height", "72",
            "--frame-interval", "0.2", "--viewer", "-q"]
    assert cli.main(argv) == 0
    text = capsys.readouterr().out
    assert "plan:" in text and "roll target=state 1" in text  # the plan starts by flipping the mug upright
    assert "no display" in text  # --viewer without a display: said, and carried on
    assert "outcome: goal" in text and "position error" in text and "yaw error" in text and "resting state" in text
    summary = json.loads((out / "summary.json").read_text())
    assert summary["execution"]["n_primitives"] == 1 and summary["plan"]["route"] == [0, 1]
    assert summary["files"] == {"plan": "plan.png", "frames": "frames.png", "video": "video.mp4",
                                "summary": "summary.json"}
    assert summary["weights"] == "shipped" and summary["versions"]["affordplan"] == ap.__version__
    assert Image.open(out / "plan.png").size[0] > 300 and Image.open(out / "frames.png").size[0] > 96
    import imageio.v2 as imageio

    frames = imageio.mimread(out / "video.mp4")
    assert len(frames) >= 3 and frames[0].shape == (72, 96, 3)


def test_a_finished_run_exits_0_and_check_makes_a_missed_goal_exit_1(monkeypatch):
    seen = []

    def fake_run_demo(out, **kwargs):
        seen.append(kwargs)
        return types.SimpleNamespace(success=False)

    monkeypatch.setattr("affordplan.app.demo.run_demo", fake_run_demo)
    assert cli.main(["demo"]) == 0
    assert cli.main(["demo", "--check", "--sim", "finger", "--no-video", "--weights-dir", "cand"]) == 1
    assert seen[0]["sim"] == "arm" and seen[0]["max_primitives"] == 30 and seen[0]["video"]
    assert seen[0]["weights_dir"] is None
    assert seen[1]["sim"] == "finger" and not seen[1]["video"] and seen[1]["weights_dir"] == "cand"


def test_a_scene_runs_the_skills_of_a_weights_folder(tmp_path):
    from affordplan.app.demo import run_scene
    from primitives.weights_file import SHIPPED_DIR as WEIGHTS_DIR

    kept = Path(__file__).resolve().parents[1] / "candidates" / "push_0.18"
    lines: list[str] = []
    run = run_scene(demo_scene(), tmp_path, sim="finger", max_primitives=1, video=False, progress=False,
                    echo=lines.append, weights_dir=kept)
    skills = run.plan.planner.predictor.skills
    assert skills["push"].success_model.net.n_decision == 13  # the folder's push, fitted before the lever arm
    assert skills["roll"]._searched_weights == WEIGHTS_DIR / "roll_success_searched.pt"  # none there: shipped
    assert run.execution.n_primitives == 1
    assert any(str(kept) in line for line in lines)
    assert json.loads((tmp_path / "summary.json").read_text())["weights"] == str(kept)
    with pytest.raises(InputError, match="not a folder"):  # refused before anything is planned
        run_scene(demo_scene(), tmp_path / "other", sim="finger", video=False, progress=False,
                  echo=lines.append, weights_dir=tmp_path / "missing")
    assert not (tmp_path / "other" / "summary.json").exists()


# ----------------------------------------------------------------------------------- bench
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


@pytest.mark.slow
def test_bench_query_times_each_rater_of_each_skill(capsys):
    import torch

    before = torch.get_num_threads()
    assert cli.main(["bench", "query", "--skill", "spin", "roll", "--repeats", "2", "--batch", "3", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    raters = {(r["skill"], r["rater"]) for r in rows}
    assert raters == {("spin", "searched model"), ("spin", "frame search (12 frames)"),
                      ("roll", "searched model"), ("roll", "frame search (2 frames)")}
    assert {r["threads"] for r in rows} == {1, 2} and all(r["single_ms"] > 0 and r["batch"] == 3 for r in rows)
    assert torch.get_num_threads() == before  # the thread count is put back


def test_bench_sim2sim_compares_identical_primitives():
    from affordplan.app.bench.primitive import bench_sim2sim

    r = bench_sim2sim("cube", n=4, progress=False)
    assert r.compared + r.skipped == 4
    assert len(r.displacement_diff_m) == r.compared
    assert np.all(r.displacement_diff_m >= 0) and np.all(r.rotation_diff_rad >= 0)
    assert "p90" in r.report()


@pytest.mark.parametrize("max_primitives", [0, 1.5, True])
def test_run_scene_refuses_a_primitive_budget_that_is_not_a_whole_number(max_primitives, tmp_path):
    from affordplan.app.demo import run_scene

    with pytest.raises(InputError, match="max_primitives must be a whole number >= 1"):
        run_scene(demo_scene(), tmp_path, max_primitives=max_primitives, video=False, progress=False)
    assert not any(tmp_path.iterdir())  # refused before anything was written


@pytest.mark.slow
def test_bench_query_times_a_candidate_folder_and_refuses_a_missing_one(capsys, tmp_path):
    from primitives.skills import WEIGHTS_DIR

    for name in ("spin.pt", "spin_success.pt"):  # a set without a frame search or a searched model
        (tmp_path / name).write_bytes((WEIGHTS_DIR / name).read_bytes())
    assert cli.main(["bench", "query", "--skill", "spin", "--repeats", "2", "--batch", "2", "--json",
                     "--weights-dir", str(tmp_path)]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert {r["rater"] for r in rows} == {"success model (goal frame)"}  # the shipped spin has both
    assert cli.main(["bench", "query", "--weights-dir", str(tmp_path / "nowhere")]) == 2
    captured = capsys.readouterr()
    assert "is not a folder" in captured.err and captured.out == ""


def test_bench_query_puts_the_thread_count_back_when_it_refuses_a_folder(tmp_path):
    import torch

    from affordplan.app.bench.query import bench_queries
    from primitives.skills import WEIGHTS_DIR

    for name in ("spin.pt", "spin_success.pt", "push.pt"):  # spin loads (and caps the threads); push has no model
        (tmp_path / name).write_bytes((WEIGHTS_DIR / name).read_bytes())
    before = torch.get_num_threads()
    torch.set_num_threads(3)  # more than loading a skill allows
    try:
        with pytest.raises(InputError, match="no success model beside it"):
            bench_queries(("spin", "push"), weights_dir=tmp_path)
        assert torch.get_num_threads() == 3
    finally:
        torch.set_num_threads(before)


@pytest.mark.slow
def test_bench_query_interleaves_the_skills_in_rounds(monkeypatch):
    import affordplan.app.bench.query as qb

    order = []
    real = qb.time_calls

    def recording(query, x, n, warm_up=1):
        order.append(query.__self__.name)
        return real(query, x, n, warm_up)

    monkeypatch.setattr(qb, "time_calls", recording)
    rows = qb.bench_queries(("spin", "push"), repeats=3, batch=2, threads=(1,), rounds=3)
    # each round times every cell (2 raters x one and a batch) of spin, then of push; three rounds
    assert order == (["spin"] * 4 + ["push"] * 4) * 3
    assert len(rows) == 4 and {r.skill for r in rows} == {"spin", "push"}
    for r in rows:  # the median of all calls lies between the fastest and the slowest round's median
        lo, hi = r.single_ms_rounds
        assert 0 < lo <= r.single_ms <= hi
    with pytest.raises(InputError, match="rounds"):
        qb.bench_queries(("spin",), rounds=0)
