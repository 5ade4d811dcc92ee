"""The command line (affordplan.app.cli): help and version, usage errors, and the commands run through it (render,
demo, bench; videos). Scene files, the demo's run_scene and the benches' functions have their own test files."""

from __future__ import annotations

import copy
import json
import sys
import types

import numpy as np
import pytest
from PIL import Image

import affordplan as ap
from affordplan.app import cli
from affordplan.app.scene_file import DEMO_SCENE
from affordplan.app.video import write_video
from affordplan.errors import InputError

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


@pytest.mark.parametrize("sensors", ["roll=eyes", "lift=cameras", "roll"])
def test_bench_plan_refuses_a_sensor_map_it_cannot_read(sensors, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["bench", "plan", "--sensors", sensors])
    assert info.value.code == 2 and "sensors maps a skill" in capsys.readouterr().err


def test_bench_plan_refuses_a_weights_folder_that_is_not_there_before_any_task(capsys, tmp_path):
    assert cli.main(["bench", "plan", "--tasks", "1", "--planner", "affordplan", "--json",
                     "--weights-dir", str(tmp_path / "nowhere")]) == 2
    captured = capsys.readouterr()
    assert "is not a folder" in captured.err and captured.out == ""


def test_bench_pool_prints_one_report_over_saved_runs_and_refuses_a_bad_file(capsys, tmp_path):
    import json

    from affordplan.app.bench.plan import BenchReport, TaskResult

    paths = []
    for seed, ok in enumerate((True, False)):
        run = BenchReport(results=[TaskResult("affordplan", "open", ok, 0.1, 4, 0, p_success=0.5, task=0)],
                          objects="mixed").as_dict()
        paths.append(tmp_path / f"bench_s{seed}.json")
        paths[-1].write_text(json.dumps(run))
    assert cli.main(["bench", "pool", *map(str, paths), "--plot", str(tmp_path / "b.png")]) == 0
    out = capsys.readouterr().out
    assert "2 runs pooled" in out and "Brier 0.250" in out and (tmp_path / "b.png").exists()
    assert cli.main(["bench", "pool", str(paths[0]), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["summary"][0]["tasks"] == 1
    (tmp_path / "bad.json").write_text("{not json")
    assert cli.main(["bench", "pool", str(tmp_path / "bad.json")]) == 2
    assert "cannot read bench results" in capsys.readouterr().err


def test_cli_reports_library_errors_cleanly(capsys, tmp_path):
    assert cli.main(["render", "teapot"]) == 2
    assert "unknown object 'teapot'" in capsys.readouterr().err
    scene = tmp_path / "s.json"
    data = copy.deepcopy(DEMO_SCENE)
    data["obstacles"][0]["size"] = [0.02, 0.2]
    scene.write_text(json.dumps(data))
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


# ----------------------------------------------------------------------------------- bench
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




def test_video_quality_choices_are_the_recorders():
    from affordplan.app.cli import VIDEO_QUALITIES
    from affordplan.app.video import QUALITIES

    assert VIDEO_QUALITIES == QUALITIES
