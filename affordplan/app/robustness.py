"""Physics fuzz: random and hostile primitives on every catalogue object, counted by what stopped them.

    affordplan bench robustness --primitives 10000
    affordplan bench robustness --primitives 2000 --sim arm --seed 3 --json

The seed's policies learned from broken physics. This benchmark checks that nothing a policy (or a
user) can ask of :meth:`affordplan.Simulator.execute` crashes it or lets a broken state through as a
valid outcome. Each primitive resets a catalogue object (objects taken in turn) to a random resting
state, anywhere in the workspace (edges included) at a random yaw, makes the start hostile one time
in seven (``sunk`` 1-3 cm into the table, ``dropped`` in any orientation from 5-20 cm, ``thrown``
with up to ~30 m/s and ~100 rad/s; none of them settled), then executes one contact and one motion
drawn from these kinds:

- contacts: ``surface`` (a point of the point cloud with its normal), ``inside`` (a point between
  the centre of mass and the surface, strictly inside the object), ``off`` (a point 1-20 cm off the
  surface, up to 15 cm high or under the table), ``far`` (anywhere within 2 m of the robot, out of
  the workspace too), ``bad_normal`` (a surface point with a random, zero or inward normal),
  ``non_finite`` (a NaN or infinite coordinate in the contact, motion or normal: must be refused
  with :class:`~affordplan.errors.InputError`);
- motions: uniform in [-1, 1]^3, or extreme: a corner of the cube (every axis at +-1), straight
  into the table, or components far beyond the range (clipped to it).

Every outcome is sorted into exactly one bin: ``valid``, ``invalid`` (per guard name, see
:mod:`affordplan.sim.guards`), ``rejected`` (InputError for a non-finite input, as documented),
``unreachable`` (the arm cannot reach: ReachabilityError), or ``crashed`` (any other exception).
Across the bins, two failures are counted: ``nan_escaped``, an outcome marked valid whose poses or
tracking errors are not finite (or whose point cloud afterwards is not), and ``suspect``, an
outcome marked valid whose state is implausible (the object jumped more than ``MAX_JUMP``, started
or ended under the table, or ended floating above it), keyed by the check and the start kind.
"""

from __future__ import annotations

import argparse
import json
import time
import traceback
from collections import Counter
from dataclasses import asdict, dataclass, field

import mujoco
import numpy as np
from tqdm import tqdm

from affordplan.checks import require_whole
from affordplan.errors import InputError, ReachabilityError
from affordplan.geometry import transform_points
from affordplan.objects.model import catalogue, load_object
from affordplan.sim.scene import OBJECT_BODY
from affordplan.sim.simulator import Simulator

CONTACT_KINDS = ("surface", "inside", "off", "far", "bad_normal", "non_finite")
CONTACT_WEIGHTS = (0.35, 0.15, 0.2, 0.1, 0.15, 0.05)
START_KINDS = ("rest", "sunk", "dropped", "thrown")
START_WEIGHTS = (0.85, 0.05, 0.05, 0.05)
MAX_JUMP = 0.5  # metres: the fingertip moves at most ~16 cm per primitive; a valid object cannot jump this far
MAX_FLOAT = 0.01  # metres: a settled object's lowest point may not hover higher than this above the table
MAX_SINK = 0.006  # metres under the table: the guard's own bound (GuardLimits.max_penetration)


@dataclass
class RobustnessResult:
    """Counts of one fuzz run; ``valid + sum(invalid) + rejected + unreachable + crashed == primitives``."""

    sim: str
    seed: int
    primitives: int
    objects: list[str]
    kinds: dict[str, int] = field(default_factory=dict)  # contact kind -> primitives drawn
    starts: dict[str, int] = field(default_factory=dict)  # start kind -> primitives drawn
    valid: int = 0
    invalid: dict[str, int] = field(default_factory=dict)  # guard name -> primitives it flagged valid=False
    rejected: int = 0  # non-finite input refused with InputError
    unreachable: int = 0  # arm only
    crashed: int = 0
    approach_failed: int = 0  # among the valid ones: the tip did not reach the contact cleanly
    nan_escaped: int = 0
    suspect: dict[str, int] = field(default_factory=dict)  # implausible valid outcomes: "check (start kind)"
    invalid_by_kind: dict[str, int] = field(default_factory=dict)  # contact kind -> valid=False outcomes
    invalid_by_start: dict[str, dict[str, int]] = field(default_factory=dict)  # start kind -> guard -> count
    crash_examples: list[str] = field(default_factory=list)
    wall_s: float = 0.0

    @property
    def invalid_total(self) -> int:
        return sum(self.invalid.values())

    @property
    def accounted(self) -> int:
        """Primitives sorted into a bin (equals ``primitives``)."""
        return self.valid + self.invalid_total + self.rejected + self.unreachable + self.crashed

    @property
    def ok(self) -> bool:
        """The guarantees held: no crash and no NaN pose escaped (suspects are reported apart)."""
        return self.crashed == 0 and self.nan_escaped == 0

    def as_dict(self) -> dict:
        d = asdict(self)
        d.update(invalid_total=self.invalid_total, ok=self.ok,
                 primitives_per_s=self.primitives / max(self.wall_s, 1e-9))
        return d

    def report(self) -> str:
        n = self.primitives
        lines = [
            f"physics fuzz: {n} primitives ({self.sim}), seed {self.seed}, {len(self.objects)} objects, "
            f"{self.wall_s:.1f} s ({n / max(self.wall_s, 1e-9):.0f}/s)",
            "  contacts drawn     " + ", ".join(f"{k} {v}" for k, v in self.kinds.items()),
            "  starts drawn       " + ", ".join(f"{k} {v}" for k, v in self.starts.items()),
            f"  valid              {self.valid:6d}   (approach failed in {self.approach_failed} of them)",
            f"  flagged valid=False{self.invalid_total:6d}   "
            + (", ".join(f"{k} {v}" for k, v in sorted(self.invalid.items(), key=lambda kv: -kv[1])) or "-"),
            "    by contact kind  " + (", ".join(f"{k} {v}" for k, v in self.invalid_by_kind.items()) or "-"),
            "    by start kind    " + ("; ".join(f"{k}: " + ", ".join(f"{g} {c}" for g, c in v.items())
                                                 for k, v in self.invalid_by_start.items()) or "-"),
            f"  refused (InputError, non-finite input) {self.rejected}",
            f"  unreachable (arm)  {self.unreachable:6d}",
            f"  crashed            {self.crashed:6d}",
            f"  NaN poses escaped  {self.nan_escaped:6d}",
            "  suspect valid      " + (", ".join(f"{k} {v}" for k, v in self.suspect.items()) or "0"),
            "  " + ("OK: no crash, no NaN pose escaped" if self.ok else "FAILED: a crash or an escaped NaN pose"),
        ]
        lines += [f"  crash: {c}" for c in self.crash_examples]
        return "\n".join(lines)


def _motion(rng: np.random.Generator) -> np.ndarray:
    r = rng.random()
    if r < 0.5:
        return rng.uniform(-1.0, 1.0, size=3)
    if r < 0.75:  # a corner: full speed on every axis
        return rng.choice([-1.0, 1.0], size=3)
    if r < 0.85:  # into the table: straight down, or down at an angle
        xy = rng.uniform(-1.0, 1.0, size=2) if rng.random() < 0.5 else np.zeros(2)
        return np.array([xy[0], xy[1], -1.0])
    return rng.choice([-1.0, 1.0], size=3) * 10.0 ** rng.uniform(0.5, 6.0, size=3)  # far out of range: clipped


def _draw(sim: Simulator, rng: np.random.Generator, kind: str):
    """``(contact, motion, normal or None)`` for one primitive of ``kind``; ``sim`` is already reset."""
    T = sim.object_pose()
    points, normals = sim.point_cloud(64)
    i = int(rng.integers(len(points)))
    p, n = points[i], normals[i]
    motion = _motion(rng)
    if kind == "surface":
        return p, motion, n
    if kind == "inside":
        return T[:3, 3] + rng.uniform(0.05, 0.9) * (p - T[:3, 3]), motion, None
    if kind == "off":
        q = p + rng.uniform(0.01, 0.2) * n
        q[2] = rng.uniform(-0.05, 0.15)
        return q, motion, None
    if kind == "far":
        return rng.uniform([-2.0, -2.0, -0.5], [2.0, 2.0, 2.0]), motion, None
    if kind == "bad_normal":
        choice = rng.integers(3)
        bad = [np.zeros(3), -n, rng.normal(size=3)][int(choice)]
        return p, motion, bad
    # non_finite: one coordinate of the contact, motion or normal
    which = int(rng.integers(3))
    value = [np.nan, np.inf, -np.inf][int(rng.integers(3))]
    arrays = [p.copy(), motion.copy(), n.copy()]
    arrays[which][int(rng.integers(3))] = value
    return arrays[0], arrays[1], arrays[2]


def _reset(sim: Simulator, rng: np.random.Generator, start: str) -> None:
    """A settled random start, then made hostile for ``start`` other than ``"rest"``."""
    ws = sim.workspace
    T = sim.reset(resting_state=int(rng.integers(len(sim.obj.resting_states))),
                  xy=(rng.uniform(*ws.x), rng.uniform(*ws.y)), yaw=rng.uniform(-np.pi, np.pi))
    if start == "sunk":  # pushed 1-3 cm into the table, not settled
        T[2, 3] -= rng.uniform(0.01, 0.03)
        sim.set_object_pose(T, settle=False)
    elif start == "dropped":  # any orientation, 5-20 cm above the table, not settled
        q = rng.normal(size=4)
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, q / np.linalg.norm(q))
        T[:3, :3] = R.reshape(3, 3)
        T[2, 3] += rng.uniform(0.05, 0.2) + float(np.max(np.linalg.norm(sim.obj.hull.vertices, axis=1)))
        sim.set_object_pose(T, settle=False)
    elif start == "thrown":  # at rest, then given a linear (m/s) and angular (rad/s) velocity
        body = sim.model.body(OBJECT_BODY)
        dof = int(sim.model.jnt_dofadr[body.jntadr[0]])
        sim.data.qvel[dof:dof + 3] = rng.normal(size=3) * 10.0 ** rng.uniform(-1.0, 1.5)
        sim.data.qvel[dof + 3:dof + 6] = rng.normal(size=3) * 10.0 ** rng.uniform(-1.0, 2.0)


def _suspect(sim: Simulator, out) -> str | None:
    """Name of the first implausibility of a valid outcome, else ``None``."""
    T0, T1 = out.pose_before, out.pose_after
    if np.linalg.norm(T1[:3, 3] - T0[:3, 3]) > MAX_JUMP:
        return "jump"
    if float(np.min(transform_points(T0, sim.obj.hull.vertices)[:, 2])) < -MAX_SINK:
        return "started_under_table"
    lowest = float(np.min(transform_points(T1, sim.obj.hull.vertices)[:, 2]))
    if lowest < -MAX_SINK:
        return "ended_under_table"
    if lowest > MAX_FLOAT:
        return "floating"
    return None


def _finite_outcome(sim: Simulator, out) -> bool:
    numbers = [out.pose_before, out.pose_after, out.tracking_error_max, out.tracking_error_median]
    if not all(np.all(np.isfinite(x)) for x in numbers):
        return False
    points, normals = sim.point_cloud(16)
    return bool(np.all(np.isfinite(points)) and np.all(np.isfinite(normals)))


def run(primitives: int = 10_000, seed: int = 0, sim: str = "finger", objects: list[str] | None = None,
        progress: bool = True, max_crash_examples: int = 5) -> RobustnessResult:
    """Execute ``primitives`` fuzzed primitives, objects in turn (all of the catalogue by default).

    The run is deterministic for a given ``seed`` (physics is deterministic and every draw comes from
    one seeded generator). See the module docstring for the kinds and the bins.
    """
    require_whole("primitives", primitives, 1)
    if sim not in ("finger", "arm"):
        raise InputError(f"sim must be 'finger' or 'arm', got {sim!r}")
    names = list(objects) if objects else catalogue()
    models = {name: load_object(name) for name in names}
    sims = {name: Simulator(models[name], pusher=sim, seed=seed) for name in names}
    rng = np.random.default_rng(seed)
    result = RobustnessResult(sim=sim, seed=seed, primitives=primitives, objects=names)
    kinds: Counter = Counter()
    starts: Counter = Counter()
    invalid_by_start: Counter = Counter()
    invalid: Counter = Counter()
    invalid_by_kind: Counter = Counter()
    suspect: Counter = Counter()
    t0 = time.perf_counter()
    bar = tqdm(range(primitives), desc=f"bench robustness ({sim})", disable=not progress, unit="prim",
               mininterval=1.0)
    for k in bar:
        name = names[k % len(names)]
        s = sims[name]
        kind = str(rng.choice(CONTACT_KINDS, p=CONTACT_WEIGHTS))
        start = str(rng.choice(START_KINDS, p=START_WEIGHTS))
        kinds[kind] += 1
        starts[start] += 1
        try:
            _reset(s, rng, start)
            contact, motion, normal = _draw(s, rng, kind)
            out = s.execute(contact, motion, normal=normal)
        except InputError:
            if kind == "non_finite":
                result.rejected += 1
            else:  # a finite input refused: not what the documentation promises
                result.crashed += 1
                _note(result, name, kind, max_crash_examples)
                sims[name] = Simulator(models[name], pusher=sim, seed=seed + k)
            continue
        except ReachabilityError:
            result.unreachable += 1
            continue
        except Exception:
            result.crashed += 1
            _note(result, name, kind, max_crash_examples)
            sims[name] = Simulator(models[name], pusher=sim, seed=seed + k)  # a fresh one for the next turn
            continue
        if kind == "non_finite":  # a NaN or inf input accepted: the guarantee is broken
            result.crashed += 1
            _note(result, name, kind, max_crash_examples, "a non-finite input was accepted")
            continue
        if not out.valid:
            invalid[out.invalid_reason or "unnamed"] += 1
            invalid_by_kind[kind] += 1
            invalid_by_start[(start, out.invalid_reason or "unnamed")] += 1
            continue
        result.valid += 1
        result.approach_failed += not out.approach_ok
        if not _finite_outcome(s, out):
            result.nan_escaped += 1
            continue
        why = _suspect(s, out)
        if why is not None:
            suspect[f"{why} ({start} start)"] += 1
        if progress and k % 200 == 0:
            bar.set_postfix(invalid=sum(invalid.values()), crashed=result.crashed, nan=result.nan_escaped)
    bar.close()
    result.wall_s = time.perf_counter() - t0
    result.kinds = {kind: kinds[kind] for kind in CONTACT_KINDS}
    result.starts = {start: starts[start] for start in START_KINDS}
    for (st, guard), count in sorted(invalid_by_start.items(), key=lambda kv: (START_KINDS.index(kv[0][0]), -kv[1])):
        result.invalid_by_start.setdefault(st, {})[guard] = count
    result.invalid = dict(invalid)
    result.invalid_by_kind = {kind: invalid_by_kind[kind] for kind in CONTACT_KINDS if invalid_by_kind[kind]}
    result.suspect = dict(suspect)
    return result


def _note(result: RobustnessResult, name: str, kind: str, limit: int, text: str | None = None) -> None:
    if len(result.crash_examples) < limit:
        last = text or traceback.format_exc().strip().splitlines()[-1]
        result.crash_examples.append(f"{name} / {kind}: {last}")


# ---------------------------------------------------------------------------- command line
def _cmd(args: argparse.Namespace) -> int:
    result = run(args.primitives, seed=args.seed, sim=args.sim, objects=args.object, progress=not args.json)
    print(json.dumps(result.as_dict(), indent=2) if args.json else result.report())
    return 0 if result.ok else 1


def register_cli(bench_subparsers) -> argparse.ArgumentParser:
    """Add ``robustness`` to the ``affordplan bench`` subcommands; returns its parser."""
    p = bench_subparsers.add_parser(
        "robustness", help="physics fuzz: hostile primitives on every catalogue object",
        description="Execute random primitives on every catalogue object (in turn): contacts on the surface,\n"
                    "inside the object, off it, far away, with bad normals or non-finite coordinates; motions\n"
                    "uniform or extreme; one start in seven sunk, dropped or thrown. Prints how many were\n"
                    "flagged valid=False and by which physics guard, how many non-finite inputs were refused,\n"
                    "and valid outcomes whose state is implausible. Exit status 1 when a primitive crashed or\n"
                    "a NaN pose escaped as valid.",
        epilog="examples:\n  affordplan bench robustness --primitives 10000\n"
               "  affordplan bench robustness --primitives 1000 --sim arm --seed 3 --json\n"
               "  affordplan bench robustness --primitives 500 --object mug bowl",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--primitives", type=int, default=10_000, help="primitives in total (default: %(default)s)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    p.add_argument("--sim", default="finger", choices=["finger", "arm"], help="pusher (default: finger)")
    p.add_argument("--object", nargs="+", default=None, help="catalogue names (default: all of them)")
    p.add_argument("--json", action="store_true", help="print JSON instead of a report")
    p.set_defaults(func=_cmd)
    return p
