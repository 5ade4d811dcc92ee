"""The ``affordplan`` command line."""

from __future__ import annotations

import argparse
import json
import sys

EXAMPLES = """\
examples:
  affordplan demo                          # the mug, three primitives, ./affordplan-demo/demo.png
  affordplan demo --object cube --out /tmp/demo
  affordplan bench sim                     # primitives per second and overhead over raw physics
  affordplan bench sim --object mug -n 1000 --json
  affordplan bench sim --pusher arm        # the 7-DOF arm through mink IK
  affordplan bench sim2sim -n 100          # the same primitives by finger and arm: outcome gap
  affordplan bench plan --tasks 50 --sim arm   # plan-and-execute success, affordplan vs greedy
  affordplan affordances lunch_box --plot lunch_box.png   # predicted vs measured success per state
"""


def _cmd_demo(args: argparse.Namespace) -> int:
    from affordplan.demo import run_demo

    run_demo(args.out, object_name=args.object, seed=args.seed, render=not args.no_render)
    return 0


def _cmd_bench_sim(args: argparse.Namespace) -> int:
    from affordplan.bench import bench_sim

    results = [bench_sim(name, args.n, pusher=args.pusher, seed=args.seed, progress=not args.json)
               for name in args.object]
    if args.json:
        print(json.dumps([r.as_dict() for r in results], indent=2))
    else:
        for r in results:
            print(r.report())
    return 0


def _cmd_bench_sim2sim(args: argparse.Namespace) -> int:
    from affordplan.bench import bench_sim2sim

    for name in args.object:
        print(bench_sim2sim(name, args.n, seed=args.seed, progress=True).report())
    return 0


def _cmd_bench_plan(args: argparse.Namespace) -> int:
    from planner.bench import bench_plan

    report = bench_plan(args.tasks, sim=args.sim, seed=args.seed, planners=tuple(args.planner),
                        max_primitives=args.max_primitives, progress=not args.json)
    print(json.dumps(report.as_dict(), indent=2) if args.json else report.report())
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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="affordplan",
        description="Plan non-prehensile manipulation (push, roll, spin) with learned primitives.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="command", required=True)

    demo = sub.add_parser(
        "demo", help="run the demo and save pictures",
        description="Load an object, execute a push, a roll and a spin in the MuJoCo finger sim, print "
                    "their outcomes and the seed paper's losses, and save a before/after picture.",
        epilog="example:\n  affordplan demo --out ./affordplan-demo",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    demo.add_argument("--out", default="affordplan-demo", help="output folder (default: %(default)s)")
    demo.add_argument("--object", default="mug", help="catalogue name or mesh path (default: %(default)s)")
    demo.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    demo.add_argument("--no-render", action="store_true", help="skip the rendered picture")
    demo.set_defaults(func=_cmd_demo)

    bench = sub.add_parser("bench", help="benchmarks that print figures")
    bench_sub = bench.add_subparsers(dest="bench", required=True)
    sim = bench_sub.add_parser(
        "sim", help="primitive cost against raw physics",
        description="Execute N random primitives and compare their wall time with the raw mj_step time "
                    "of the same steps.",
        epilog="examples:\n  affordplan bench sim\n  affordplan bench sim --object cube mug -n 1000 --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sim.add_argument("--object", nargs="+", default=["cube"], help="catalogue names (default: cube)")
    sim.add_argument("-n", type=int, default=500, help="primitives per object (default: %(default)s)")
    sim.add_argument("--pusher", default="finger", choices=["finger", "arm"], help="pusher (default: finger)")
    sim.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    sim.add_argument("--json", action="store_true", help="print JSON instead of a report")
    sim.set_defaults(func=_cmd_bench_sim)

    s2s = bench_sub.add_parser(
        "sim2sim", help="finger vs arm on the same random primitives",
        description="Run the same random primitives with the finger and with the arm and print how far "
                    "the object's final poses differ (mean and 90th percentile).",
        epilog="example:\n  affordplan bench sim2sim --object cube mug -n 100",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    s2s.add_argument("--object", nargs="+", default=["cube"], help="catalogue names (default: cube)")
    s2s.add_argument("-n", type=int, default=100, help="primitives per object (default: %(default)s)")
    s2s.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    s2s.set_defaults(func=_cmd_bench_sim2sim)

    bp = bench_sub.add_parser(
        "plan", help="plan-and-execute success on random tasks, affordplan vs greedy",
        description="Random tasks (walls with gaps, blocks, face changes, goal yaw) on objects never trained "
                    "on; prints success, median planning time, primitives and replans per task for each planner.",
        epilog="example:\n  affordplan bench plan --tasks 50 --sim arm --seed 0",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    bp.add_argument("--tasks", type=int, default=50, help="number of tasks (default: %(default)s)")
    bp.add_argument("--sim", default="arm", choices=["arm", "finger"], help="pusher (default: arm)")
    bp.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    bp.add_argument("--planner", nargs="+", default=["affordplan", "greedy"], choices=["affordplan", "greedy"])
    bp.add_argument("--max-primitives", type=int, default=40, help="per task (default: %(default)s)")
    bp.add_argument("--json", action="store_true", help="print JSON instead of a table")
    bp.set_defaults(func=_cmd_bench_plan)

    aff = sub.add_parser(
        "affordances", help="predicted vs measured success of each skill in each resting state",
        description="For every resting state of OBJECT: the success model's prediction for push (per "
                    "direction sector, relative to the object's heading), spin (30 deg each way) and roll "
                    "(to each state one roll away), next to the rate measured by executing in the finger sim.",
        epilog="examples:\n  affordplan affordances lunch_box\n  affordplan affordances pill_bottle --trials 20 "
               "--plot pill.png --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    aff.add_argument("object", help="catalogue name or mesh path")
    aff.add_argument("--trials", type=int, default=10, help="starts per action (default: %(default)s)")
    aff.add_argument("--sectors", type=int, default=8, help="push direction sectors (default: %(default)s)")
    aff.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    aff.add_argument("--plot", default=None, help="write a bar chart per resting state here")
    aff.add_argument("--json", action="store_true", help="print JSON instead of a table")
    aff.set_defaults(func=_cmd_affordances)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    from affordplan.errors import AffordplanError

    try:
        return args.func(args)
    except AffordplanError as exc:
        print(f"affordplan: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
