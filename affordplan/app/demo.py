"""``affordplan demo`` and ``affordplan plan SCENE``: plan, execute in the arm sim, film, report.

:func:`run_scene` takes a :class:`affordplan.app.scene_file.Scene`, plans with :func:`affordplan.plan`,
prints the plan, executes it closed-loop (``Plan.execute``, re-observing and replanning after every
primitive) in a MuJoCo simulator with the 7-DOF arm (or the finger), and writes to ``out_dir``:

- ``video.mp4`` (``video.gif`` when ffmpeg is unavailable): the execution rendered offscreen, one
  frame every ``frame_interval`` simulated seconds, played at ``fps``;
- ``plan.png``: a top-down plot of the obstacles, the planned footprints and steps, and the executed path;
- ``frames.png``: a strip of frames taken after primitives (start and end included);
- ``summary.json``: the scene, the plan, the execution log and the final errors.

It prints honestly whether the goal was reached, with the position, yaw and resting-state errors.
:func:`run_demo` runs the embedded demo scene (:data:`affordplan.app.scene_file.DEMO_SCENE`): the mug on
its side behind a wall with a gap, to be flipped upright, pushed through the gap and turned to 90 deg.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from affordplan import versions
from affordplan.app.scene_file import Scene, demo_scene
from affordplan.app.video import FrameRecorder, chain_hooks, save_strip, write_video
from affordplan.checks import require_whole
from affordplan.errors import InputError
from affordplan.geometry import transform_points
from affordplan.goal import Goal
from affordplan.objects.model import ObjectModel
from affordplan.sim.simulator import Simulator

DEMO_MAX_PRIMITIVES = 30  # bounds the demo's time: ~1-3 s per arm primitive with frames on 2 cores
END_HOLD_S = 1.0  # the video holds its last frame this long
OFF_TABLE_HEIGHT = 0.01  # metres: a settled object whose lowest point is higher than this is not on the table

if TYPE_CHECKING:  # the planner is imported lazily (affordplan core <- primitives <- planner)
    from planner.execute import Execution, LogEntry
    from planner.plan import Plan


class _Watch:
    """Bookkeeping after every primitive (a push of several strides is one): the progress bar, key frames, and
    whether the object left the table.

    Key frames (for ``frames.png``) are taken after primitives that simulated anything: a call the
    arm could not reach adds none.
    """

    def __init__(self, obj: ObjectModel, sim: Simulator, recorder: FrameRecorder | None, max_primitives: int,
                 label: str, progress: bool):
        from tqdm import tqdm

        self.sim = sim
        self.recorder = recorder
        self.hull = obj.hull.vertices
        self.executed = 0
        self.off_table: list[tuple[int, float]] = []
        self.keyframes: list[tuple[str, Callable[[], np.ndarray | None]]] = []  # drawn in the background
        self._steps_seen = sim.physics_steps
        self.bar = tqdm(total=max_primitives, desc=f"executing ({label})", unit="prim", disable=not progress)
        if recorder is not None and (f := recorder.take()) is not None:
            self.keyframes.append(("start", f))

    def after_primitive(self, entry: LogEntry) -> None:
        """What :func:`planner.execute.execute_plan` calls after each primitive (``entry``: its log line)."""
        sim = self.sim
        self.executed += 1
        lowest = float(np.min(transform_points(sim.object_pose(), self.hull)[:, 2]))
        if lowest > OFF_TABLE_HEIGHT:
            self.off_table.append((self.executed, lowest))
        if self.recorder is not None:
            if sim.physics_steps > self._steps_seen and (f := self.recorder.take()) is not None:
                strokes = f", {entry.strokes} strokes" if entry.strokes > 1 else ""
                self.keyframes.append((f"after primitive {self.executed}{strokes}", f))
            self.bar.set_postfix(frames=len(self.recorder.frames), refresh=False)
        self._steps_seen = sim.physics_steps
        self.bar.update(1)

    def close(self) -> None:
        self.bar.close()


@dataclass
class SceneRun:
    """What :func:`run_scene` did.

    Attributes:
        scene: the scene run.
        plan: the first plan.
        execution: what executing it did (success, final pose, primitives, replans, log).
        xy_error: final distance of the object's centre from the goal, metres.
        yaw_error: final |yaw error|, radians (0 when the goal has no yaw).
        state_ok: the final resting state is the goal's (or the goal names none).
        final_state: the final resting state.
        files: what was written, by kind (``video``, ``plan``, ``frames``, ``summary``).
        wall_time: seconds, from loading the object to the last file written.
        off_table: ``(primitive number from 1, lowest point of the object above the table in metres)``
            after each primitive that left the object off the table (lifted by the pusher, or lying on an
            obstacle): the off_table guard then stops execution; reported rather than hidden.
    """

    scene: Scene
    plan: Plan
    execution: Execution
    xy_error: float
    yaw_error: float
    state_ok: bool
    final_state: int
    files: dict[str, Path] = field(default_factory=dict)
    wall_time: float = 0.0
    off_table: list[tuple[int, float]] = field(default_factory=list)
    weights_dir: str | None = None

    @property
    def success(self) -> bool:
        """The goal was reached (position, yaw and resting state within the goal's tolerances)."""
        return bool(self.execution.success)


def run_scene(scene: Scene, out_dir: str | Path, *, sim: str = "arm", planner: str = "affordplan",
              max_primitives: int = DEMO_MAX_PRIMITIVES, seed: int = 0, time_limit: float = 5.0,
              video: bool = True, width: int = 480, height: int = 360, fps: float = 10.0,
              frame_interval: float = 0.5, camera: str | None = None, viewer: bool = False,
              quality: str = "standard", progress: bool = True, echo: Callable[[str], None] = print,
              weights_dir: str | Path | None = None) -> SceneRun:
    """Plan and execute ``scene``, print the plan and the outcome, write the outputs to ``out_dir``.

    Args:
        scene: what to do.
        out_dir: output folder (created).
        sim: ``"arm"`` (7-DOF arm, mink IK) or ``"finger"`` (the faster fingertip).
        planner: ``"affordplan"`` or ``"greedy"`` (the reactive baseline).
        max_primitives: execution stops after this many skill calls.
        seed: seeds the planner and the simulator's point clouds.
        time_limit: seconds per planning call.
        video: render frames and write the video and the frame strip.
        width, height: frame size, pixels.
        fps: video frame rate (frames are ``frame_interval`` simulated seconds apart).
        frame_interval: simulated seconds between video frames.
        camera: ``"arm"`` (the whole arm), or a scene camera: ``"overview"`` (closer), ``"wide"``, ``"top"``;
            ``None``: ``"arm"`` with the arm, ``"overview"`` with the finger.
        viewer: also show MuJoCo's interactive viewer when a display exists.
        quality: how the video's frames are drawn (:class:`~affordplan.app.video.FrameRecorder`): ``"standard"``,
            ``"full"`` (shadows and reflections; about three times the drawing time) or ``"fast"``.
        progress: show a progress bar (primitives executed, frames rendered) on stderr.
        echo: where the report lines go.
        weights_dir: run the skills from this folder's files instead of the shipped ones, e.g. a candidate set
            under ``candidates/`` (:func:`primitives.skills.load_skills`; a skill without
            files there stays shipped).

    Raises:
        AffordplanError: bad scene or options (an unusable ``weights_dir`` included, before anything is planned),
            or no first plan (PlanningError / GoalError).
    """
    import affordplan as ap

    if sim not in ("arm", "finger"):
        raise InputError(f"sim must be 'arm' or 'finger', got {sim!r}")
    require_whole("max_primitives", max_primitives, 1)
    if not fps > 0:
        raise InputError(f"fps must be positive, got {fps!r}")
    t_start = time.perf_counter()
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {str(out)[:120]} is a file, not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create the output folder {str(out)[:120]} ({exc.strerror})") from None
    echo(f"scene {scene.name}: {scene.description}" if scene.description else f"scene {scene.name}")
    obj = scene.load_object()
    echo(f"object: {obj.name}; resting states: " + ", ".join(
        f"#{s.index} p={s.probability:.2f}" for s in obj.resting_states))
    echo(f"start: {_describe_start(scene.start)}; goal: {_describe_goal(scene.goal)}; "
         f"{len(scene.obstacles)} obstacles")

    t_plan = time.perf_counter()
    predictor = None
    if weights_dir is not None:
        from planner.predict import Predictor

        echo(f"skills: the files in {weights_dir} where it has them, else the shipped ones")
        predictor = Predictor(obj, seed=seed, weights_dir=weights_dir)  # the seed plan() would give its own
    echo(f"planning ({planner}; loading the skills and success models first) ...")
    plan = ap.plan(obj, scene.goal, start=scene.start, obstacles=scene.obstacles, time_limit=time_limit,
                   planner=planner, seed=seed, predictor=predictor)
    echo(str(plan))

    t_exec = time.perf_counter()
    from primitives.skills import skills_sensor

    sensor = skills_sensor(plan.planner.predictor.skills)  # the clouds the shipped skills were trained on
    simulator = Simulator(obj, obstacles=scene.obstacles, pusher=sim, seed=seed, sensor=sensor)
    simulator.set_object_pose(plan.start_pose)
    camera = camera or ("arm" if sim == "arm" else "overview")
    recorder = FrameRecorder(simulator, width, height, camera, frame_interval, quality=quality) if video else None
    live = None
    if viewer:
        from affordplan.app.viewer import open_viewer

        live = open_viewer(simulator, echo=echo)
    simulator.on_chunk = chain_hooks(recorder.on_chunk if recorder else None, live.on_chunk if live else None)
    echo(f"executing in the {sim} sim (at most {max_primitives} primitives) ...")
    watch = _Watch(obj, simulator, recorder, max_primitives, sim, progress)
    try:
        execution = plan.execute(sim=simulator, max_primitives=max_primitives, seed=seed,
                                 on_primitive=watch.after_primitive)
    finally:
        watch.close()
        simulator.on_chunk = None
    t_out = time.perf_counter()
    echo(str(execution))
    if plan.kind == "affordplan":
        odds = plan.odds(max_primitives)
        echo(f"predicted: the goal reached with p_success {odds.p_success:.2f} within {max_primitives} primitives, "
             f"about {odds.expected_primitives:.1f} of them; happened: "
             f"{'reached' if execution.success else 'not reached'} after {execution.n_primitives}")

    xy_error, yaw_error, state_ok = scene.goal.errors(obj, execution.final_pose)
    run = SceneRun(scene, plan, execution, xy_error, yaw_error, state_ok, obj.classify(execution.final_pose),
                   off_table=watch.off_table, weights_dir=None if weights_dir is None else str(weights_dir))
    for line in outcome_lines(run, obj):
        echo(line)
    _write_outputs(run, obj, out, recorder, watch.keyframes, fps, t_start)
    if live is not None:
        echo("viewer: close its window to exit")
        live.wait_closed()
    if recorder is not None:
        recorder.close()
        if len(recorder.frames) >= recorder.max_frames:
            echo(f"video: stopped recording at its budget of {recorder.max_frames} frames")
        if recorder.failed:
            echo(f"no video: rendering failed ({recorder.failed})")
    simulator.close()
    n_frames = len(recorder.frames) if recorder else 0
    echo(f"wrote {', '.join(str(p) for p in run.files.values())}"
         + (f" ({n_frames} frames at {fps:g} fps)" if n_frames else ""))
    echo(f"finished in {time.perf_counter() - t_start:.1f} s (loading the object {t_plan - t_start:.1f} s, "
         f"skills + planning {t_exec - t_plan:.1f} s, execution {t_out - t_exec:.1f} s, pictures and video "
         f"{time.perf_counter() - t_out:.1f} s)")
    return run


def _write_outputs(run: SceneRun, obj: ObjectModel, out: Path, recorder: FrameRecorder | None,
                   keyframes: list[tuple[str, Callable[[], np.ndarray | None]]], fps: float,
                   t_start: float) -> None:
    """summary.json, then plan.png, frames.png and the video (when frames were rendered), then summary.json again
    with every file and the whole time; fills ``run.files``."""
    from planner.plot import plot_plan

    ex = run.execution
    # The results first: whatever goes wrong with the pictures or the video, summary.json is on disk.
    run.files["summary"] = out / "summary.json"
    run.wall_time = time.perf_counter() - t_start
    run.files["summary"].write_text(json.dumps(summary(run, obj), indent=2) + "\n", encoding="utf-8")
    run.files["plan"] = out / "plan.png"
    plot_plan(run.plan, run.files["plan"], execution=ex,
              title=f"{run.scene.name}: {obj.name}, {'goal reached' if ex.success else 'goal NOT reached'} "
                    f"after {ex.n_primitives} primitives, {ex.replans} replans")
    if recorder is not None and recorder.frames:
        drawn = [(label, frame) for label, take in keyframes if (frame := take()) is not None]
        run.files["frames"] = save_strip(drawn, out / "frames.png", n=6)
        hold = [recorder.frames[-1]] * max(1, round(END_HOLD_S * fps))
        run.files["video"] = write_video(recorder.frames + hold, out / "video.mp4", fps=fps)
    run.files["summary"] = out / "summary.json"
    run.wall_time = time.perf_counter() - t_start
    run.files["summary"].write_text(json.dumps(summary(run, obj), indent=2) + "\n", encoding="utf-8")


def run_demo(out_dir: str | Path = "affordplan-demo", **kwargs) -> SceneRun:
    """Run the embedded demo scene; keyword arguments as :func:`run_scene`."""
    return run_scene(demo_scene(), out_dir, **kwargs)


# ------------------------------------------------------------------------------- report
def _describe_start(start: dict) -> str:
    x, y = start["xy"]
    return f"state {start['resting_state']} at ({x:.3f}, {y:.3f}) m, yaw {math.degrees(start['yaw']):.0f} deg"


def _describe_goal(goal: Goal) -> str:
    parts = [] if goal.resting_state is None else [f"state {goal.resting_state}"]
    parts.append(f"({goal.xy[0]:.3f}, {goal.xy[1]:.3f}) m +- {100 * goal.xy_tol:.1f} cm")
    if goal.yaw is not None:
        parts.append(f"yaw {math.degrees(goal.yaw):.0f} +- {math.degrees(goal.yaw_tol):.0f} deg")
    return ", ".join(parts)


def outcome_lines(run: SceneRun, obj: ObjectModel) -> list[str]:
    """The outcome, honestly: reached or not, and each error against its tolerance."""
    g, ex = run.scene.goal, run.execution

    def verdict(ok: bool) -> str:
        return "ok" if ok else "NOT met"

    lines = [f"outcome: goal {'REACHED' if ex.success else 'NOT reached'} after {ex.n_primitives} primitives "
             f"({ex.strokes} fingertip strokes), {ex.replans} replans ({ex.reason})",
             f"  position error {100 * run.xy_error:.1f} cm (tolerance {100 * g.xy_tol:.1f} cm): "
             f"{verdict(run.xy_error <= g.xy_tol)}"]
    if g.yaw is not None:
        lines.append(f"  yaw error {math.degrees(run.yaw_error):.0f} deg "
                     f"(tolerance {math.degrees(g.yaw_tol):.0f} deg): {verdict(run.yaw_error <= g.yaw_tol)}")
    if g.resting_state is not None:
        lines.append(f"  resting state {run.final_state} (goal {g.resting_state}): {verdict(run.state_ok)}")
    if run.off_table:
        first, height = run.off_table[0]
        top = max(h for _, h in run.off_table)
        lines.append(f"  warning: after primitive {first} the {obj.name} was off the table, {100 * height:.0f} cm up "
                     f"(at most {100 * top:.0f} cm; off the table after {len(run.off_table)} primitives in all): "
                     "lifted by the pusher or left on an obstacle (the off_table guard)")
    return lines


def summary(run: SceneRun, obj: ObjectModel) -> dict:
    """Plain-data record of a run (for ``summary.json``)."""
    ex, plan = run.execution, run.plan
    state, x, y, yaw = obj.planar_pose(ex.final_pose)
    return {
        "scene": run.scene.as_dict(),
        "plan": {"kind": plan.kind, "route": [int(r) for r in plan.route], "p_success": _finite(plan.p_success),
                 "expected_primitives": _finite(plan.expected_primitives), "p_steps": _finite(plan.p_steps),
                 "planning_time_s": plan.planning_time,
                 "steps": [{"skill": s.skill, "params": _plain(s.params), "p_success": _finite(s.p_success),
                            "strides": s.strides} for s in plan.steps]},
        "execution": {"success": bool(ex.success), "n_primitives": ex.n_primitives, "strokes": ex.strokes,
                      "replans": ex.replans,
                      "reason": ex.reason,
                      "log": [{"skill": e.skill, "params": _plain(e.params), "success": e.success, "valid": e.valid,
                               "replanned": e.replanned, "note": e.note, "strokes": e.strokes} for e in ex.log]},
        "final": {"resting_state": int(state), "xy": [float(x), float(y)], "yaw": float(yaw),
                  "xy_error_m": run.xy_error, "yaw_error_rad": run.yaw_error, "state_ok": bool(run.state_ok)},
        "off_table": [{"after_primitive": k, "lowest_point_m": h} for k, h in run.off_table],
        "files": {k: p.name for k, p in run.files.items()},
        "wall_time_s": run.wall_time,
        "weights": run.weights_dir or "shipped",
        "versions": versions(),
    }


def _plain(params: dict) -> dict:
    return {k: (int(v) if isinstance(v, (int, np.integer)) else float(v)) for k, v in params.items()}


def _finite(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


__all__ = ["DEMO_MAX_PRIMITIVES", "SceneRun", "outcome_lines", "run_demo", "run_scene", "summary"]
