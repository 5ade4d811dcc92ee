"""The ``affordplan`` command line: ``demo``, ``plan``, ``render``, ``affordances``, ``bench``.

Every subcommand has ``--help`` with examples. Library errors (bad input, no plan) print one line
``affordplan: error: ...`` and exit with status 2; a run that finishes exits 0 whether or not the goal
was reached (``--check`` makes an unreached goal exit 1).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import textwrap

from affordplan.log import one_line_errors
from affordplan.robot import SKILLS

VIDEO_QUALITIES = ("standard", "full", "fast")  # affordplan.app.video.QUALITIES, without importing the renderer

EXAMPLES = """\
examples:
  affordplan demo                          # the mug: flip upright, through the gap, turn; ./affordplan-demo/
  affordplan demo --max-primitives 10 --camera overview --out /tmp/demo
  affordplan plan examples/scenes/mug_wall.json --out /tmp/mug_wall
  affordplan plan examples/scenes/box_corridor.yaml --sim finger --planner greedy
  affordplan render mug --out mug_states.png   # the object in each of its resting states
  affordplan affordances lunch_box --plot lunch_box.png   # predicted vs measured success per state
  affordplan bench sim                     # primitives per second and overhead over raw physics
  affordplan bench sim --pusher arm        # the 7-DOF arm through mink IK
  affordplan bench sim2sim -n 100          # the same primitives by finger and arm: outcome gap
  affordplan bench sim2sim --skill roll    # the shipped skills' success, finger vs arm, same starts
  affordplan bench plan --tasks 50 --sim arm   # plan-and-execute success, affordplan vs greedy

Run `affordplan COMMAND --help` for a command's options.
"""

RUN_OUTPUTS = """\
outputs (in --out):
  video.mp4     the execution rendered offscreen (video.gif when ffmpeg is unavailable)
  plan.png      top-down: obstacles, planned footprints and steps, the executed path
  frames.png    frames after primitives, start and end included
  summary.json  the scene, the plan, the execution log, the final errors
"""

SCENE_FORMAT = """\
scene file (JSON, or YAML with PyYAML; metres, radians, or degrees in fields ending in _deg):
  {"object": "mug",                                   # catalogue name or mesh path
   "start": {"resting_state": 0, "xy": [0.45, -0.05], "yaw": 0.5},
   "goal": {"xy": [0.69, 0.0], "resting_state": 1, "yaw_deg": 90},   # yaw, state optional
   "obstacles": [{"center": [0.6, -0.21], "size": [0.02, 0.2, 0.1]}]}
  optional: "name", "description", "size" (object half-extent, m), goal "xy_tol", "yaw_tol(_deg)",
  obstacle "yaw(_deg)". `affordplan render OBJECT` shows the resting-state indices.
"""


def _formatter(prog: str) -> argparse.HelpFormatter:
    return argparse.RawDescriptionHelpFormatter(prog, max_help_position=32)


def _wrap(text: str) -> str:
    """A description wrapped at 100 columns (the raw formatter keeps the epilogs' layout as written)."""
    return textwrap.fill(text, width=100)


# ------------------------------------------------------------------------------ commands
def _run_kwargs(args: argparse.Namespace) -> dict:
    return dict(sim=args.sim, planner=args.planner, max_primitives=args.max_primitives, seed=args.seed,
                time_limit=args.time_limit, video=not args.no_video, width=args.width, height=args.height,
                fps=args.fps, frame_interval=args.frame_interval, camera=args.camera, viewer=args.viewer,
                quality=args.quality, progress=not args.quiet, weights_dir=args.weights_dir)


def _cmd_demo(args: argparse.Namespace) -> int:
    from affordplan.app.demo import run_demo

    run = run_demo(args.out, **_run_kwargs(args))
    return 1 if args.check and not run.success else 0


def _cmd_plan(args: argparse.Namespace) -> int:
    from affordplan.app.demo import run_scene
    from affordplan.app.scene_file import load_scene

    scene = load_scene(args.scene)
    run = run_scene(scene, args.out or f"affordplan-plan/{scene.name}", **_run_kwargs(args))
    return 1 if args.check and not run.success else 0


def _cmd_render(args: argparse.Namespace) -> int:
    from pathlib import Path

    from affordplan.app.render import render_states, save_states_picture, state_label
    from affordplan.errors import InputError
    from affordplan.objects.model import load_object

    if args.out is not None and Path(args.out).suffix.lower() not in (".png", ".jpg", ".jpeg"):
        raise InputError(f"--out {args.out[:80]}: the picture is written as .png or .jpg")
    obj = load_object(args.object, size=args.size)
    print(f"{obj.name}: {len(obj.resting_states)} resting states (most likely first)")
    for s in obj.resting_states:
        print(f"  {state_label(obj, s.index)}  COM height {100 * s.height:.1f} cm")
    images = render_states(obj, args.state, width=args.width, height=args.height)
    out = Path(args.out or f"{Path(obj.name).stem}_states.png")
    save_states_picture(obj, images, out)
    print(f"wrote {out}")
    return 0


def _cmd_bench_sim(args: argparse.Namespace) -> int:
    from affordplan.app.bench.primitive import bench_sim

    results = [bench_sim(name, args.n, pusher=args.pusher, seed=args.seed, progress=not args.json)
               for name in args.object]
    if args.json:
        print(json.dumps([r.as_dict() for r in results], indent=2))
    else:
        for r in results:
            print(r.report())
    return 0


def _cmd_bench_sim2sim(args: argparse.Namespace) -> int:
    if args.skill:
        from primitives.research.sim2sim import skill_sim2sim

        for skill in args.skill:
            print(skill_sim2sim(skill, args.n, seed=args.seed, progress=True).report())
        return 0
    from affordplan.app.bench.primitive import bench_sim2sim

    for name in args.object:
        print(bench_sim2sim(name, args.n, seed=args.seed, progress=True).report())
    return 0


def _cmd_bench_query(args: argparse.Namespace) -> int:
    from affordplan.app.bench.query import bench_queries, report

    rows = bench_queries(tuple(args.skill), repeats=args.repeats, batch=args.batch, seed=args.seed,
                         weights_dir=args.weights_dir, rounds=args.rounds)
    print(json.dumps([r.as_dict() for r in rows], indent=2) if args.json else report(rows))
    return 0


def _cmd_bench_plan(args: argparse.Namespace) -> int:
    from affordplan.app.bench.plan import bench_plan
    from planner.plan import MAX_STRIDES

    log = (lambda text: print(text, file=sys.stderr, flush=True)) if args.log else None
    report = bench_plan(args.tasks, sim=args.sim, seed=args.seed, planners=tuple(args.planner),
                        max_primitives=args.max_primitives, progress=not args.json and not args.log,
                        only=args.task, log=log, weights_dir=args.weights_dir, draw=args.draw,
                        objects=args.objects, max_strides=args.max_strides or MAX_STRIDES,
                        spin_strokes=args.spin_strokes, sensors=args.sensors)
    print(json.dumps(report.as_dict(), indent=2) if args.json else report.report())
    return 0


def _read_runs(paths: list[str]) -> list[dict]:
    """Saved ``affordplan bench plan --json`` runs; an unreadable file raises InputError."""
    from affordplan.errors import InputError

    reports = []
    for path in paths:
        try:
            with open(path, encoding="utf-8") as f:
                reports.append(json.load(f))
        except (OSError, ValueError) as exc:
            raise InputError(f"cannot read bench results {str(path)[:120]}: {exc}") from None
    return reports


def _cmd_bench_pool(args: argparse.Namespace) -> int:
    from affordplan.app.bench.plan import plot_report, pool

    report = pool(_read_runs(args.files))
    if args.plot:
        plot_report(report, args.plot)
    print(json.dumps(dict(runs=len(args.files), summary=[report.summary(n) for n in report.planners]), indent=2)
          if args.json else f"{len(args.files)} runs pooled\n" + report.report())
    if args.plot and not args.json:
        print(f"wrote {args.plot}")
    return 0


def _cmd_bench_compare(args: argparse.Namespace) -> int:
    from affordplan.app.bench.compare import compare

    comparison = compare(_read_runs(args.base), _read_runs(args.candidate))
    print(json.dumps(comparison.summary(), indent=2) if args.json else comparison.report())
    return 0


def _cmd_bench_fit_stuck(args: argparse.Namespace) -> int:
    from affordplan.app.bench.plan import fit_stuck

    fit = fit_stuck(_read_runs(args.files), held_out=_read_runs(args.held_out or []))
    if args.json:
        print(json.dumps(fit, indent=2))
        return 0
    rates = ", ".join(f"{skill} {rate:.1f}" for skill, rate in fit["rates"].items())
    print(f"fitted on {fit['plans']} plans on training objects ({fit['reached']:.2f} reached): stuck rates {rates}; "
          f"fatal tips {fit['tip_fatal']:.1f}; Brier of p_success {fit['brier']:.3f} (without stuck steps or tips "
          f"{fit['brier_without']:.3f})")
    if "held_out" in fit:
        h = fit["held_out"]
        print(f"held out, {h['plans']} plans ({h['reached']:.2f} reached): Brier {h['brier']:.3f} "
              f"(without stuck steps or tips {h['brier_without']:.3f})")
    return 0


def _cmd_affordances(args: argparse.Namespace) -> int:
    # The command line is a facade like affordplan.plan: it reaches the learned skills lazily.
    from affordplan.objects.model import load_object
    from primitives.affordances import affordance_table, as_dicts, format_table, plot_table

    obj = load_object(args.object)
    rows = affordance_table(obj, trials=args.trials, sectors=args.sectors, seed=args.seed, progress=not args.json)
    if args.json:
        print(json.dumps(dict(object=obj.name, rows=as_dicts(rows)), indent=2))
    else:
        print(format_table(obj, rows))
    if args.plot:
        plot_table(obj, rows, args.plot)
        if not args.json:
            print(f"wrote {args.plot}")
    return 0


# -------------------------------------------------------------------------------- parser
def _add_run_options(p: argparse.ArgumentParser, out_default: str | None, max_primitives: int) -> None:
    """Options shared by ``demo`` and ``plan``: execution, video, viewer."""
    p.add_argument("--out", default=out_default, metavar="DIR",
                   help="output folder (default: %s)" % (out_default or "affordplan-plan/<scene name>"))
    p.add_argument("--sim", default="arm", choices=["arm", "finger"],
                   help="pusher: the 7-DOF arm (mink IK) or the faster fingertip (default: %(default)s)")
    p.add_argument("--planner", default="affordplan", choices=["affordplan", "greedy"],
                   help="the planner, or the reactive greedy baseline (default: %(default)s)")
    p.add_argument("--max-primitives", type=_positive_int, default=max_primitives, metavar="N",
                   help="stop executing after N skill calls (default: %(default)s)")
    p.add_argument("--time-limit", type=_bounded_float(0.0, 600.0, "seconds"), default=5.0, metavar="S",
                   help="seconds per planning call (default: %(default)s)")
    p.add_argument("--seed", type=_seed, default=0,
                   help="seeds the planner and the point clouds (default: %(default)s)")
    p.add_argument("--weights-dir", default=None, metavar="DIR",
                   help="run the skills from this folder's files (laid out like primitives/weights/, e.g. a "
                        "candidate set under candidates/) instead of the shipped ones")
    video = p.add_argument_group("video")
    video.add_argument("--no-video", "--no-render", dest="no_video", action="store_true",
                       help="skip rendering: only plan.png and summary.json are written")
    video.add_argument("--camera", default=None, choices=["arm", "overview", "wide", "top"],
                       help="arm: the whole arm; overview: closer on the object (default: arm with --sim arm, "
                            "overview with --sim finger)")
    video.add_argument("--width", type=_pixels(MAX_WIDTH), default=480,
                       help="frame width, pixels (default: %(default)s)")
    video.add_argument("--height", type=_pixels(MAX_HEIGHT), default=360,
                       help="frame height, pixels (default: %(default)s)")
    video.add_argument("--fps", type=_bounded_float(0.0, 240.0, "frames per second"), default=10.0,
                       help="video frame rate (default: %(default)s)")
    video.add_argument("--frame-interval", type=_bounded_float(0.0, 10.0, "seconds"), default=0.5, metavar="S",
                       help="simulated seconds between frames (default: %(default)s)")
    video.add_argument("--quality", choices=VIDEO_QUALITIES, default="standard",
                       help="standard: multisampled, no shadows or reflections; full: as MuJoCo draws the scene "
                            "(about three times the drawing time); fast: standard without multisampling "
                            "(default: %(default)s)")
    p.add_argument("--viewer", action="store_true",
                   help="also show MuJoCo's interactive viewer (needs a display; on macOS run under mjpython)")
    p.add_argument("--check", action="store_true", help="exit with status 1 when the goal is not reached")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")


def _int_at_least(text: str, low: int, what: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a {what} integer, got {text!r}") from None
    if value < low:
        raise argparse.ArgumentTypeError(f"expected a {what} integer, got {value}")
    return value


def _seed(text: str) -> int:
    """A random seed: a whole number in [0, 2**32)."""
    value = _int_at_least(text, 0, "non-negative")
    if value >= 2**32:
        raise argparse.ArgumentTypeError(f"a seed is below 2**32, got {text[:40]}")
    return value


def _bounded_float(low: float, high: float, what: str):
    """An argparse type: a finite number in (``low``, ``high``]."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number ({what}), got {text[:40]!r}") from None
        if not math.isfinite(value) or not low < value <= high:
            raise argparse.ArgumentTypeError(f"{what} must be in ({low:g}, {high:g}], got {text[:40]}")
        return value

    return parse


def _positive_int(text: str) -> int:
    return _int_at_least(text, 1, "positive")


def _skill_sensors(text: str) -> dict[str, str]:
    """``SKILL=SENSOR[,SKILL=SENSOR...]`` as a dict (:func:`planner.execute.check_sensors`)."""
    from affordplan.errors import InputError
    from planner.execute import check_sensors

    pairs = [item.partition("=") for item in text.split(",") if item]
    try:
        return check_sensors({skill.strip(): sensor.strip() for skill, _, sensor in pairs})
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


MAX_WIDTH, MAX_HEIGHT = 1280, 960  # the scene's offscreen buffer (affordplan.sim.scene)


def _pixels(most: int):
    """An argparse type: a whole number of pixels in [1, ``most``]."""
    def parse(text: str) -> int:
        value = _int_at_least(text, 1, "positive")
        if value > most:
            raise argparse.ArgumentTypeError(f"at most {most} pixels, got {text[:40]}")
        return value

    return parse


def _nonnegative_int(text: str) -> int:
    return _int_at_least(text, 0, "non-negative")


def _register_robustness(bench_sub) -> None:
    """``affordplan bench robustness ...`` when :mod:`affordplan.app.robustness` exists (it is optional)."""
    import importlib

    try:
        robustness = importlib.import_module("affordplan.app.robustness")
    except ModuleNotFoundError as exc:
        if exc.name != "affordplan.app.robustness":  # it exists but needs something missing: say so
            raise
        return
    robustness.register_cli(bench_sub)


class _VersionAction(argparse.Action):
    """``--version``: looks the versions up when asked (argparse's own action formats them at parser build,
    which put ~10 ms of package-metadata reads on every command's start-up)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        from affordplan import __version__, versions_text

        print(f"affordplan {__version__} ({versions_text(skip=('affordplan',))})")
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="affordplan",
        description=_wrap("Plan non-prehensile manipulation (push, roll, spin) with learned primitives, execute the "
                          "plans closed-loop in a MuJoCo simulation of a 7-DOF arm, and measure them."),
        epilog=EXAMPLES,
        formatter_class=_formatter,
    )
    parser.add_argument("--version", action=_VersionAction,
                        help="print affordplan's version and those of the libraries its figures depend on")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    demo = sub.add_parser(
        "demo", help="the mug on its side behind a wall: plan, execute with the arm, write a video",
        description=_wrap("The mug lies on its side behind a wall with a gap. Plan (resting-state graph, OMPL paths, "
                          "learned skills) to flip it upright, push it through the gap and turn it to 90 deg; execute "
                          "the plan closed-loop in the arm sim (replanning when the mug goes off plan); print the plan "
                          "and, honestly, whether the goal was reached (position, yaw and resting-state errors). A run "
                          "that finishes exits 0 even when the goal is missed. About 1-3 minutes on 2 cores."),
        epilog="examples:\n"
               "  affordplan demo\n"
               "  affordplan demo --out /tmp/demo --camera overview\n"
               "  affordplan demo --max-primitives 1 --no-video   # a quick smoke test\n"
               "  affordplan demo --viewer                        # also watch it live (needs a display)\n\n"
               + RUN_OUTPUTS + "\nThe scene is examples/scenes/mug_wall.json; run others with `affordplan plan`.",
        formatter_class=_formatter,
    )
    _add_run_options(demo, "affordplan-demo", max_primitives=30)
    demo.set_defaults(func=_cmd_demo)

    plan = sub.add_parser(
        "plan", help="plan and execute a scene file (JSON / YAML), write a video and a plot",
        description=_wrap("Read a scene (object, start, goal, obstacles), plan, execute the plan closed-loop in the "
                          "arm sim, print the plan and the outcome, and write the same outputs as `affordplan demo`."),
        epilog="examples:\n"
               "  affordplan plan examples/scenes/mug_wall.json\n"
               "  affordplan plan examples/scenes/box_corridor.yaml --out /tmp/corridor --sim finger\n"
               "  affordplan plan my_scene.yaml --planner greedy --max-primitives 20 --check\n\n"
               + SCENE_FORMAT + "\n" + RUN_OUTPUTS,
        formatter_class=_formatter,
    )
    plan.add_argument("scene", help="scene file: .json, .yaml or .yml")
    _add_run_options(plan, None, max_primitives=40)
    plan.set_defaults(func=_cmd_plan)

    render = sub.add_parser(
        "render", help="picture an object in its resting states",
        description=_wrap("Load OBJECT (a catalogue name or a mesh file), list its resting states (index, "
                          "probability, up-vector in the object frame, centre-of-mass height) and render each, "
                          "settled on the table, into one PNG. Scene files and goals name resting states by these "
                          "indices."),
        epilog="examples:\n"
               "  affordplan render mug\n"
               "  affordplan render pill_bottle --state 0 2 --out pill.png\n"
               "  affordplan render path/to/mesh.obj --size 0.04 --width 240 --height 180",
        formatter_class=_formatter,
    )
    render.add_argument("object", help="catalogue name (see affordplan.catalogue()) or mesh path")
    render.add_argument("--state", type=int, nargs="+", default=None, metavar="S",
                        help="resting-state indices to render (default: all)")
    render.add_argument("--out", default=None, metavar="PNG", help="picture to write (default: <object>_states.png)")
    render.add_argument("--size", type=_bounded_float(0.0, 1.0, "metres"), default=0.05,
                        help="largest half-extent, metres (default: %(default)s)")
    render.add_argument("--width", type=_pixels(MAX_WIDTH), default=320,
                        help="tile width, pixels (default: %(default)s)")
    render.add_argument("--height", type=_pixels(MAX_HEIGHT), default=240,
                        help="tile height, pixels (default: %(default)s)")
    render.set_defaults(func=_cmd_render)

    aff = sub.add_parser(
        "affordances", help="predicted vs measured success of each skill in each resting state",
        description=_wrap("For every resting state of OBJECT: the success model's prediction for push (per "
                          "direction sector, relative to the object's heading), spin (30 deg each way) and roll "
                          "(to each state one roll away), next to the rate measured by executing in the finger sim."),
        epilog="examples:\n  affordplan affordances lunch_box\n  affordplan affordances pill_bottle --trials 20 "
               "--plot pill.png --json",
        formatter_class=_formatter,
    )
    aff.add_argument("object", help="catalogue name or mesh path")
    aff.add_argument("--trials", type=_positive_int, default=10, help="starts per action (default: %(default)s)")
    aff.add_argument("--sectors", type=_positive_int, default=8, help="push direction sectors (default: %(default)s)")
    aff.add_argument("--seed", type=_seed, default=0, help="random seed (default: %(default)s)")
    aff.add_argument("--plot", default=None, help="write a bar chart per resting state here")
    aff.add_argument("--json", action="store_true", help="print JSON instead of a table")
    aff.set_defaults(func=_cmd_affordances)

    bench = sub.add_parser(
        "bench", help="benchmarks that print figures",
        description=_wrap("Benchmarks with progress bars; each prints a report (or JSON)."),
        epilog="examples:\n"
               "  affordplan bench sim --object cube mug -n 500\n"
               "  affordplan bench sim2sim -n 100\n"
               "  affordplan bench query\n"
               "  affordplan bench plan --tasks 50 --sim arm",
        formatter_class=_formatter,
    )
    bench_sub = bench.add_subparsers(dest="bench", required=True, metavar="BENCHMARK")
    sim = bench_sub.add_parser(
        "sim", help="primitive cost against raw physics",
        description=_wrap("Execute N random primitives and compare their wall time with the raw mj_step time "
                          "of the same steps."),
        epilog="examples:\n  affordplan bench sim\n  affordplan bench sim --object cube mug -n 1000 --json\n"
               "  affordplan bench sim --pusher arm -n 100",
        formatter_class=_formatter,
    )
    sim.add_argument("--object", nargs="+", default=["cube"], help="catalogue names (default: cube)")
    sim.add_argument("-n", type=_positive_int, default=500, help="primitives per object (default: %(default)s)")
    sim.add_argument("--pusher", default="finger", choices=["finger", "arm"], help="pusher (default: finger)")
    sim.add_argument("--seed", type=_seed, default=0, help="random seed (default: %(default)s)")
    sim.add_argument("--json", action="store_true", help="print JSON instead of a report")
    sim.set_defaults(func=_cmd_bench_sim)

    s2s = bench_sub.add_parser(
        "sim2sim", help="finger vs arm on the same random primitives",
        description=_wrap("Run the same random primitives with the finger and with the arm and print how far "
                          "the object's final poses differ (mean and 90th percentile); with --skill, run the "
                          "shipped skills from the same starts with the same parameters in both and print their "
                          "successes."),
        epilog="examples:\n  affordplan bench sim2sim --object cube mug -n 100\n"
               "  affordplan bench sim2sim --skill roll push -n 80 --seed 2",
        formatter_class=_formatter,
    )
    s2s.add_argument("--object", nargs="+", default=["cube"], help="catalogue names (default: cube)")
    s2s.add_argument("-n", type=_positive_int, default=100, help="primitives per object (default: %(default)s)")
    s2s.add_argument("--seed", type=_seed, default=0, help="random seed (default: %(default)s)")
    s2s.add_argument("--skill", nargs="+", choices=SKILLS,
                     help="compare the shipped skills' success instead (on held-out objects; -n draws each)")
    s2s.set_defaults(func=_cmd_bench_sim2sim)

    bq = bench_sub.add_parser(
        "query", help="time the skills' success queries",
        description=_wrap("Median time of one P(success) query per skill, alone and in a batch as the planner "
                          "asks them, with the searched success model and with the frame search's own rating, on "
                          "1 and 2 torch threads; the skills' timings interleaved in rounds."),
        epilog="examples:\n  affordplan bench query\n  affordplan bench query --skill spin --repeats 300 --json\n"
               "  affordplan bench query --skill spin --weights-dir candidates/spin_cframe",
        formatter_class=_formatter,
    )
    bq.add_argument("--skill", nargs="+", default=list(SKILLS), choices=SKILLS,
                    help="skills to time (default: all three)")
    bq.add_argument("--repeats", type=_positive_int, default=100, help="timed queries each (default: %(default)s)")
    bq.add_argument("--batch", type=_positive_int, default=32, help="queries per batch (default: %(default)s)")
    bq.add_argument("--rounds", type=_positive_int, default=10,
                    help="interleave the skills' timings over this many rounds, so that a machine's drift falls on "
                         "all of them alike (default: %(default)s)")
    bq.add_argument("--seed", type=_seed, default=0, help="random seed (default: %(default)s)")
    bq.add_argument("--json", action="store_true", help="print JSON instead of a table")
    bq.add_argument("--weights-dir", default=None, metavar="DIR",
                    help="time the skills of this folder's files (laid out like primitives/weights/, e.g. a "
                         "candidate set) instead of the shipped ones; a skill without files there stays shipped")
    bq.set_defaults(func=_cmd_bench_query)

    bp = bench_sub.add_parser(
        "plan", help="plan-and-execute success on random tasks, affordplan vs greedy",
        description=_wrap("Random tasks (walls with gaps, blocks, face changes, goal yaw) on objects never "
                          "trained on; prints success, planning time (median, max), primitives per task (mean, "
                          "median, p90), replans, and the plan-level calibration of the predicted p_success "
                          "(Brier, bins) for each planner."),
        epilog="examples:\n  affordplan bench plan --tasks 50 --sim arm --seed 0\n"
               "  affordplan bench plan --tasks 10 --sim finger --planner affordplan --json\n"
               "  affordplan bench plan --seed 3 --task 22 42 --planner affordplan --log   # why they failed\n"
               "  affordplan bench plan --planner affordplan --weights-dir candidates/push_60\n"
               "  affordplan bench plan --seed 0 --planner affordplan --draw 1   # the same tasks, other random draws",
        formatter_class=_formatter,
    )
    bp.add_argument("--tasks", type=_positive_int, default=50, help="number of tasks (default: %(default)s)")
    bp.add_argument("--sim", default="arm", choices=["arm", "finger"], help="pusher (default: arm)")
    bp.add_argument("--seed", type=_seed, default=0, help="random seed (default: %(default)s)")
    bp.add_argument("--planner", nargs="+", default=["affordplan", "greedy"], choices=["affordplan", "greedy"],
                    help="planners to compare (default: both)")
    bp.add_argument("--max-primitives", type=_positive_int, default=40, help="per task (default: %(default)s)")
    bp.add_argument("--task", type=_nonnegative_int, nargs="+", default=None, metavar="I",
                    help="run only these tasks of the seed's draw (the same tasks as in the whole run)")
    bp.add_argument("--log", action="store_true",
                    help="print each task's first plan and step-by-step execution log (to stderr)")
    bp.add_argument("--weights-dir", default=None, metavar="DIR",
                    help="run the skills from this folder's files (laid out like primitives/weights/, e.g. "
                         "candidates/push_60) instead of the shipped ones; a skill without "
                         "files there stays shipped")
    bp.add_argument("--draw", type=_nonnegative_int, default=0, metavar="K",
                    help="run the same tasks with the planner's and the simulator's random numbers drawn afresh "
                         "(K > 0; 0, the default, is the standard run): how far outcomes move by chance alone")
    bp.add_argument("--objects", default="procedural",
                    choices=["procedural", "household", "mixed", "training", "validation"],
                    help="the tasks' objects: the procedural test split, HACMan's 25 unseen household meshes, or "
                         "the two by turns; training: the training objects by turns, for fitting the planner's "
                         "stuck rates; validation: the 12 household validation meshes, for choosing settings; "
                         "neither for reporting (default: %(default)s)")
    bp.add_argument("--max-strides", type=_positive_int, default=None, metavar="K",
                    help="5 cm strides one push call may make, correcting its course between strokes; 1: one "
                         "stroke per push, as until 0.24 (default: the planner's, planner.plan.MAX_STRIDES)")
    bp.add_argument("--spin-strokes", type=_positive_int, default=None, metavar="K",
                    help="strokes one spin step may make, asking for the rest of its turn between them "
                         "(primitives.strokes.spin_by); 1: one stroke per spin (default: "
                         "planner.execute.SPIN_STROKES)")
    bp.add_argument("--sensors", type=_skill_sensors, default=None, metavar="SKILL=SENSOR[,...]",
                    help="the clouds a skill of the plans is shown while it acts, e.g. roll=cameras (default: "
                         "planner.execute.EXECUTION_SENSORS; a skill not named sees its policy's own)")
    bp.add_argument("--json", action="store_true", help="print JSON instead of a table")
    bp.set_defaults(func=_cmd_bench_plan)
    bf = bench_sub.add_parser(
        "fit-stuck", help="fit the planner's stuck rates and fatal-tip share to saved `bench plan --objects training "
                          "--json` runs",
        formatter_class=_formatter,
        description=_wrap("Fit planner.odds.STUCK_RATES, per skill the share of a step's predicted failure "
                          "that is systematic (no retry succeeds), and planner.odds.TIP_FATAL, the share of tips "
                          "(a push or spin that leaves the object in another resting state) a run does not recover "
                          "from, to the first plans of saved plan-bench runs on training objects: the values whose "
                          "predicted p_success has the least Brier score."),
        epilog="example:\n  affordplan bench plan --objects training --sim finger --planner affordplan --seed 100 "
               "--json > runs/train100.json\n"
               "  affordplan bench fit-stuck runs/train100.json --held-out runs/train101.json")
    bf.add_argument("files", nargs="+", metavar="JSON", help="bench plan --json outputs")
    bf.add_argument("--held-out", nargs="+", metavar="JSON", default=None,
                    help="other runs, on any objects (scored, never fitted on), scored with the fitted rates")
    bf.add_argument("--json", action="store_true", help="print JSON instead of text")
    bf.set_defaults(func=_cmd_bench_fit_stuck)
    bpo = bench_sub.add_parser(
        "pool", help="one report over the tasks of several saved `bench plan --json` runs (e.g. eight seeds)",
        formatter_class=_formatter,
        description=_wrap("Pool saved plan-bench runs (the same budget, objects and draw) into one report: success, "
                          "primitives per task, planning times, failures and the plan-level calibration over all "
                          "their tasks, as `affordplan bench plan` reports one run."),
        epilog="example:\n  for S in 0 1 2 3 4 5 6 7; do affordplan bench plan --tasks 50 --sim arm --objects mixed "
               "--planner affordplan --seed $S --json > runs/bench_s$S.json; done\n"
               "  affordplan bench pool runs/bench_s*.json --plot runs/bench.png")
    bpo.add_argument("files", nargs="+", metavar="JSON", help="bench plan --json outputs")
    bpo.add_argument("--plot", default=None, metavar="PNG",
                     help="also draw primitives per task and the plan-level calibration to this image")
    bpo.add_argument("--json", action="store_true", help="print JSON instead of text")
    bpo.set_defaults(func=_cmd_bench_pool)
    bco = bench_sub.add_parser(
        "compare", help="two sets of saved `bench plan --json` runs of the same tasks, task by task",
        formatter_class=_formatter,
        description=_wrap("Pair the tasks of a base and a candidate set of saved plan-bench runs (the same seeds "
                          "draw the same tasks) and report success of each, the tasks gained and lost with an exact "
                          "sign test on them, and primitives and strokes per task over the tasks both reached."),
        epilog="example:\n  affordplan bench compare --base runs/before_s*.json --candidate runs/after_s*.json")
    bco.add_argument("--base", nargs="+", required=True, metavar="JSON", help="bench plan --json outputs: the base")
    bco.add_argument("--candidate", nargs="+", required=True, metavar="JSON",
                     help="bench plan --json outputs of the same tasks: the candidate")
    bco.add_argument("--json", action="store_true", help="print JSON instead of text")
    bco.set_defaults(func=_cmd_bench_compare)
    _register_robustness(bench_sub)
    return parser


@one_line_errors("affordplan")
def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
