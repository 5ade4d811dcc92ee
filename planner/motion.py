"""SE(2) motion planning of an object's footprint among box obstacles: OMPL plans, python-fcl checks.

Kept apart in OMPL's way:

* :class:`FootprintChecker`: state validity. The footprint (a convex polygon, object-centred, see
  :mod:`planner.footprint`) is an ``fcl.Convex`` prism, each obstacle an ``fcl.Box`` with its yaw.
  Both span the same z range, so the test is the 2-D overlap of the footprint and the obstacles'
  table footprints (an object standing on the table meets every obstacle it overlaps in plan).
* :func:`make_space`: the SE(2) state space (``ob.SE2StateSpace``) bounded by the workspace.
* :func:`make_setup`: an ``og.SimpleSetup`` with the checker and an ``og.RRTConnect`` planner.
* :func:`plan_path`: start/goal checks, the straight way when it is free, else solve, simplify, hold
  one yaw where that is free (:func:`single_turn_path`), densify, final check.

Distances in SE(2) are OMPL's compound metric ``|dxy| + yaw_weight |dyaw|`` (metres; ``dyaw`` in
radians, the shorter way round): ``SE2StateSpace`` weighs its SO(2) subspace by 0.5 by default, and
:func:`make_space` sets that weight to ``yaw_weight``. A good weight is the footprint's radius: a turn
by ``dyaw`` then moves the footprint's far corner about as far as the metric says.

OMPL 2.0.1 notes (nanobind bindings, measured here):

* ``SE2StateSpace.allocState()`` returns a Python-owned ``SE2StateType``; calling ``freeState`` on it
  as well crashed the process (segfault, apparently a double free once the Python object dies), so
  states are never freed by hand (about 100 bytes of each are not returned; 2 per plan).
* ``ompl.util.RNG.setSeed`` seeds the *process-global* seed generator from which every new OMPL RNG
  (planner, samplers, simplifier) draws its seed. Calling it again later still makes the objects
  created afterwards deterministic, but OMPL logs "Random number generation already started"; that
  message is silenced here. Seed 0 is rejected by OMPL, so ``seed`` is passed on as ``seed + 1``.
* OMPL's log level is process-global too; :func:`plan_path` silences its "Info" lines (keeps warnings
  and errors) while it runs and restores the previous level afterwards.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Iterator, Sequence

import fcl
import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from affordplan.checks import is_whole
from affordplan.errors import GoalError, InputError, PlanningError
from affordplan.geometry import rot_z, wrap_angle
from affordplan.world import Box, Workspace
from planner.footprint import as_polygon, convex_hull_2d

PRISM_HEIGHT = 0.2  # z extent (metres) shared by the footprint prism and the obstacle boxes: a 2-D test
MAX_STEP = 0.01  # metres between consecutive states of a returned path
MAX_TURN = math.radians(5.0)  # radians between consecutive states of a returned path
BROAD_PHASE_SLACK = 1e-6  # metres added to the footprint's radius before a box is skipped unchecked
SOLVE_ITERATIONS = 5000  # RRT-Connect iterations per SE(2) attempt (plan_path): 0.1-0.3 s unloaded here


def _prism(polygon: np.ndarray, height: float) -> fcl.Convex:
    """A convex prism over a CCW polygon, z in [-height/2, height/2], outward-facing faces."""
    k = len(polygon)
    half = 0.5 * height
    vertices = np.vstack([np.column_stack([polygon, np.full(k, -half)]),
                          np.column_stack([polygon, np.full(k, half)])])
    faces = [k, *range(k - 1, -1, -1), k, *range(k, 2 * k)]  # bottom (seen from below CCW), top
    for i in range(k):
        j = (i + 1) % k
        faces += [4, i, j, k + j, k + i]
    return fcl.Convex(vertices, 2 + k, faces)


class FootprintChecker:
    """Is an object's footprint at table pose ``(x, y, yaw)`` clear of the obstacles and inside the workspace?

    Args:
        footprint: (k, 2) convex polygon, object-centred, metres, already inflated by whatever clearance
            the caller wants (see :func:`planner.footprint.inflate`); its convex hull is used.
        obstacles: boxes standing on the table (world frame).
        workspace: the region every footprint vertex must stay in (world frame).
        reach: when given, every footprint vertex must also lie within this many metres of the world origin
            (the arm's base): where the fingertip can reach all round the object.

    Poses are the object-centred origin's world ``(x, y)`` in metres and the yaw about world z in
    radians (:func:`planner.footprint.place`). Queries update one fcl object's transform; obstacles farther
    from ``(x, y)`` than the footprint's circumscribed radius are skipped in plain Python (a point-to-box
    distance), and the workspace test runs over the hull's vertices in plain Python where the circumscribed
    disc does not settle it. Measured on the plan bench's scenes: :meth:`is_free` ~2.7 us on average over
    random poses (~0.5 us away from the obstacles and the workspace edge, ~3.5 us per obstacle within reach).
    """

    def __init__(self, footprint: np.ndarray, obstacles: Sequence[Box] = (), workspace: Workspace = Workspace(),
                 reach: float | None = None):
        polygon = convex_hull_2d(as_polygon(footprint, "footprint"))
        obstacles = tuple(obstacles)
        for i, box in enumerate(obstacles):
            if not isinstance(box, Box):
                raise InputError(f"obstacle {i} must be an affordplan.world.Box, got {type(box).__name__}")
        if not isinstance(workspace, Workspace):
            raise InputError(f"workspace must be an affordplan.world.Workspace, got {type(workspace).__name__}")
        if reach is not None and not (math.isfinite(reach) and reach > 0.0):
            raise InputError(f"reach must be a positive number of metres or None, got {reach!r}")
        self.footprint = polygon
        self.obstacles = obstacles
        self.workspace = workspace
        self.reach = reach
        self._vertices = [(float(px), float(py)) for px, py in polygon]
        self._radius = float(np.max(np.hypot(polygon[:, 0], polygon[:, 1])))  # circumscribed about the origin
        near = self._radius + BROAD_PHASE_SLACK
        self._near2 = near * near  # a box farther than this (squared) from the pose is not hit (colliding)
        # Poses whose circumscribed disc lies inside the workspace skip the per-vertex test.
        self._inner = (workspace.x[0] + self._radius, workspace.x[1] - self._radius,
                       workspace.y[0] + self._radius, workspace.y[1] - self._radius)
        self._object = fcl.CollisionObject(_prism(polygon, PRISM_HEIGHT), fcl.Transform())
        self._quat = np.array([1.0, 0.0, 0.0, 0.0])  # fcl order (w, x, y, z), reused per query
        self._translation = np.zeros(3)
        self._obstacle_objects = []
        # broad phase in plain Python, per box: (cx, cy, cos yaw, sin yaw, half x, half y) in the world frame
        self._obstacle_boxes = []
        for box in obstacles:
            sx, sy, _ = box.size
            T_world_box = fcl.Transform(rot_z(box.yaw), np.array([box.center[0], box.center[1], 0.0]))
            self._obstacle_objects.append(fcl.CollisionObject(fcl.Box(sx, sy, PRISM_HEIGHT), T_world_box))
            self._obstacle_boxes.append((float(box.center[0]), float(box.center[1]), math.cos(box.yaw),
                                         math.sin(box.yaw), 0.5 * sx, 0.5 * sy))
        self._request = fcl.CollisionRequest()
        self._distance_request = fcl.DistanceRequest()

    def _set_pose(self, x: float, y: float, yaw: float) -> None:
        q = self._quat
        q[0] = math.cos(0.5 * yaw)
        q[3] = math.sin(0.5 * yaw)
        t = self._translation
        t[0] = x
        t[1] = y
        self._object.setQuatRotation(q)
        self._object.setTranslation(t)

    def in_workspace(self, x: float, y: float, yaw: float) -> bool:
        """Whether every footprint vertex at pose ``(x, y, yaw)`` lies in the workspace (boundary included),
        and within ``reach`` of the origin when one is set."""
        x0, x1, y0, y1 = self._inner
        within_reach = self.reach is None or math.hypot(x, y) + self._radius <= self.reach
        if x0 <= x <= x1 and y0 <= y <= y1 and within_reach:
            return True
        c, s = math.cos(yaw), math.sin(yaw)
        (wx0, wx1), (wy0, wy1) = self.workspace.x, self.workspace.y
        reach2 = None if within_reach else self.reach * self.reach
        for px, py in self._vertices:  # plain Python: ~1 us for a hull of 16, a tenth of numpy's on arrays this small
            vx = c * px - s * py + x
            vy = s * px + c * py + y
            if vx < wx0 or vx > wx1 or vy < wy0 or vy > wy1 or (reach2 is not None and vx * vx + vy * vy > reach2):
                return False
        return True

    def colliding(self, x: float, y: float, yaw: float, *, first: bool = False) -> list[int]:
        """Indices of the obstacles the footprint at ``(x, y, yaw)`` overlaps (only the first if ``first``)."""
        hits = []
        posed = False
        for i, (cx, cy, c, s, hx, hy) in enumerate(self._obstacle_boxes):
            # the footprint lies within its circumscribed radius of (x, y): a box farther than that is not hit
            dx, dy = x - cx, y - cy
            ex = max(abs(c * dx + s * dy) - hx, 0.0)  # (x, y) outside the box, along its axes, metres
            ey = max(abs(c * dy - s * dx) - hy, 0.0)
            if ex * ex + ey * ey > self._near2:
                continue
            if not posed:
                self._set_pose(x, y, yaw)
                posed = True
            if fcl.collide(self._object, self._obstacle_objects[i], self._request, fcl.CollisionResult()):
                hits.append(i)
                if first:
                    break
        return hits

    def is_free(self, x: float, y: float, yaw: float) -> bool:
        """True when the footprint at ``(x, y, yaw)`` (metres, radians, world) is inside the workspace
        and overlaps no obstacle. NaN poses are not free."""
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(yaw)):
            return False
        return self.in_workspace(x, y, yaw) and not self.colliding(x, y, yaw, first=True)

    def why_not_free(self, x: float, y: float, yaw: float) -> str | None:
        """``None`` when the pose is free, else a sentence naming the workspace or the obstacles hit."""
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(yaw)):
            return f"the pose {(x, y, yaw)} is not finite"
        reasons = []
        if not self.in_workspace(x, y, yaw):
            ws = self.workspace
            reach = "" if self.reach is None else f", within {self.reach} m of the arm's base"
            reasons.append(f"the footprint leaves the workspace (x in {list(ws.x)}, y in {list(ws.y)} m{reach})")
        hits = self.colliding(x, y, yaw)
        if hits:
            names = ", ".join(f"{i} ({self.obstacles[i]})" for i in hits)
            reasons.append(f"the footprint overlaps obstacle{'s' if len(hits) > 1 else ''} {names}")
        return "; ".join(reasons) or None

    def clearance(self, x: float, y: float, yaw: float) -> float:
        """Smallest distance (metres) from the footprint at ``(x, y, yaw)`` to any obstacle, 0 when it
        overlaps one; ``inf`` without obstacles. The workspace boundary is not counted."""
        if not self._obstacle_objects:
            return math.inf
        self._set_pose(x, y, yaw)
        best = math.inf
        for other in self._obstacle_objects:
            d = fcl.distance(self._object, other, self._distance_request, fcl.DistanceResult())
            best = min(best, max(d, 0.0))  # fcl reports -1 (or a negative depth) when they overlap
            if best == 0.0:
                break
        return best


@contextlib.contextmanager
def _ompl_log_level(level: ou.LogLevel) -> Iterator[None]:
    """Raise OMPL's (process-global) log threshold to ``level`` for the block, then restore it."""
    previous = ou.getLogLevel()
    if int(previous.value) < int(level.value):
        ou.setLogLevel(level)
    try:
        yield
    finally:
        ou.setLogLevel(previous)


def _seed_ompl(seed: int) -> None:
    """Seed OMPL's process-global seed generator (see the module docstring)."""
    with _ompl_log_level(ou.LOG_NONE):
        ou.RNG.setSeed(int(seed) + 1)  # OMPL ignores seed 0


def make_space(workspace: Workspace, yaw_weight: float) -> ob.SE2StateSpace:
    """SE(2) state space whose (x, y) bounds are the workspace's (metres) and whose yaw weight is ``yaw_weight``."""
    space = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, workspace.x[0])
    bounds.setHigh(0, workspace.x[1])
    bounds.setLow(1, workspace.y[0])
    bounds.setHigh(1, workspace.y[1])
    space.setBounds(bounds)
    space.setSubspaceWeight(1, yaw_weight)  # subspace 0: R^2 (weight 1), subspace 1: SO(2)
    return space


def make_setup(space: ob.SE2StateSpace, checker: FootprintChecker, resolution: float) -> og.SimpleSetup:
    """SimpleSetup with the checker as state validity and RRT-Connect; motions are checked every
    ``resolution`` of SE(2) distance (see the module docstring for the metric)."""
    setup = og.SimpleSetup(space)
    is_free = checker.is_free
    setup.setStateValidityChecker(lambda state: is_free(state.getX(), state.getY(), state.getYaw()))
    si = setup.getSpaceInformation()
    si.setStateValidityCheckingResolution(min(1.0, resolution / space.getMaximumExtent()))
    setup.setPlanner(og.RRTConnect(si))
    return setup


def _state(space: ob.SE2StateSpace, pose: tuple[float, float, float]) -> ob.SE2StateType:
    state = space.allocState()  # Python-owned: never freeState it (see the module docstring)
    state.setX(pose[0])
    state.setY(pose[1])
    state.setYaw(wrap_angle(pose[2]))
    return state


def _check_pose(pose, name: str) -> tuple[float, float, float]:
    arr = np.asarray(pose, dtype=float).reshape(-1)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise InputError(f"{name} must be (x, y, yaw): 3 finite numbers, got {pose!r}")
    return (float(arr[0]), float(arr[1]), float(arr[2]))


def _check_positive(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)) or not (
            math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)


def interpolate_path(path: np.ndarray, max_step: float = MAX_STEP, max_turn: float = MAX_TURN,
                     min_counts: Sequence[int] | None = None) -> np.ndarray:
    """Subdivide an SE(2) path so consecutive states are at most ``max_step`` metres and ``max_turn``
    radians apart.

    Each segment is cut in ``n`` equal parts, with ``n`` a multiple of ``min_counts[i]`` when given (so the
    states OMPL checked along the segment are among the returned ones). Positions move linearly; yaw turns
    the shorter way round and is returned unwrapped (continuous, starting at ``path[0, 2]``).

    Args:
        path: (m, 3) states (x, y, yaw), metres and radians, world frame.

    Returns:
        (n, 3) states, the first and last being ``path``'s (the last's yaw up to a multiple of 2 pi).
    """
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or path.shape[1] != 3 or len(path) < 1 or not np.all(np.isfinite(path)):
        raise InputError(f"path must be an (m, 3) finite array, got shape {path.shape}")
    max_step = _check_positive(max_step, "max_step")
    max_turn = _check_positive(max_turn, "max_turn")
    out = [path[:1].copy()]
    for i in range(len(path) - 1):
        a, b = path[i], path[i + 1]
        dxy = b[:2] - a[:2]
        dyaw = wrap_angle(b[2] - a[2])
        n = max(1, math.ceil(max(math.hypot(*dxy) / max_step, abs(dyaw) / max_turn) - 1e-9))
        if min_counts is not None and min_counts[i] > 1:
            m = int(min_counts[i])
            n = m * math.ceil(n / m)
        t = np.arange(1, n + 1)[:, None] / n
        segment = np.empty((n, 3))
        segment[:, :2] = a[:2] + t * dxy
        segment[:, 2] = out[-1][-1, 2] + t[:, 0] * dyaw
        out.append(segment)
    return np.vstack(out)


def _free_along(checker: FootprintChecker, path: np.ndarray, resolution: float) -> bool:
    """Whether the footprint is free at every state of ``path`` subdivided to ``resolution`` metres and 2 deg."""
    return all(checker.is_free(*pose) for pose in interpolate_path(path, resolution, math.radians(2.0)))


def _turned_once(xy: np.ndarray, held: float, start, goal) -> np.ndarray:
    """``xy`` positions at yaw ``held``, with the one turn in place: at the start when ``held`` is the goal's yaw
    (``goal[2]`` unwrapped next to ``start[2]``), else at the goal."""
    moving = np.column_stack([xy, np.full(len(xy), held)])
    return np.vstack([start, moving]) if held == goal[2] else np.vstack([moving, goal])


def single_turn_path(checker: FootprintChecker, waypoints: np.ndarray, resolution: float = 0.005,
                     turn_first: bool = True) -> np.ndarray | None:
    """``waypoints``' positions at one held yaw with a single turn in place, when that stays free; else ``None``.

    Tried in order (``turn_first``; else the other way round): turn at the first waypoint to the last one's yaw
    and hold it, or hold the first one's yaw and turn at the last waypoint. Every executed turn is a spin,
    which moves objects sideways by centimetres, and every change of heading along a sampled path is one
    more: where one turn will do, this is the path with fewest spins. Checked every ``resolution`` metres
    and every 2 deg; returned densified like :func:`plan_path`'s paths.
    """
    waypoints = np.asarray(waypoints, dtype=float)
    (x0, y0, a0), (x1, y1, a1) = waypoints[0], waypoints[-1]
    a1 = a0 + wrap_angle(a1 - a0)
    for held in ((a1, a0) if turn_first else (a0, a1)):
        path = _turned_once(waypoints[:, :2], held, (x0, y0, a0), (x1, y1, a1))
        if _free_along(checker, path, resolution):
            return interpolate_path(path)
    return None


def plan_at_held_yaw(checker: FootprintChecker, start_xy, goal_xy, yaw: float, *, iterations: int = 1000,
                     time_limit: float = 1.0, seed: int = 0, resolution: float = 0.005) -> np.ndarray | None:
    """Positions ``(m, 2)`` from ``start_xy`` to ``goal_xy`` along which the footprint at ``yaw`` stays free, or
    ``None`` when RRT-Connect (OMPL, in the plane) finds none within ``iterations`` (or, as a safeguard on a
    slow machine, ``time_limit`` seconds).

    An iteration budget, not a time budget, bounds the search, so the same seed gives the same answer however
    loaded the machine is. The waypoints are simplified by OMPL; motions are checked every ``resolution`` metres.
    """
    if not (checker.is_free(start_xy[0], start_xy[1], yaw) and checker.is_free(goal_xy[0], goal_xy[1], yaw)):
        return None
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    for i, (lo, hi) in enumerate((checker.workspace.x, checker.workspace.y)):
        bounds.setLow(i, lo)
        bounds.setHigh(i, hi)
    space.setBounds(bounds)
    setup = planner = None
    try:
        with _ompl_log_level(ou.LOG_WARN):
            _seed_ompl(int(seed))
            setup = og.SimpleSetup(space)
            is_free = checker.is_free
            setup.setStateValidityChecker(lambda state: is_free(state[0], state[1], yaw))
            si = setup.getSpaceInformation()
            si.setStateValidityCheckingResolution(min(1.0, resolution / space.getMaximumExtent()))
            planner = og.RRTConnect(si)
            setup.setPlanner(planner)
            ends = []
            for xy in (start_xy, goal_xy):
                state = space.allocState()  # Python-owned: never freeState it (see the module docstring)
                state[0], state[1] = float(xy[0]), float(xy[1])
                ends.append(state)
            setup.setStartAndGoalStates(*ends)
            result = setup.solve(_budget(iterations, time_limit))
            if result.getStatus() != ob.PlannerStatus.EXACT_SOLUTION or not setup.haveExactSolutionPath():
                return None
            setup.simplifySolution(0.0)  # 0: simplify to the end (no time limit, so deterministic)
            states = setup.getSolutionPath().getStates()
            xy = np.array([(st[0], st[1]) for st in states])
            del states
    finally:
        del planner, setup
    xy[0], xy[-1] = start_xy, goal_xy
    return xy


def _budget(iterations: int, seconds: float) -> ob.PlannerTerminationCondition:
    """Stop a solve after ``iterations`` checks of the condition (RRT-Connect checks it once per iteration), or, as
    a safeguard on a slow machine, after ``seconds``: the same seed then gives the same answer however loaded the
    machine is, as long as the safeguard does not fire."""
    count = [0]

    def spent() -> bool:
        count[0] += 1
        return count[0] > iterations

    return ob.plannerOrTerminationCondition(ob.PlannerTerminationCondition(spent),
                                            ob.timedPlannerTerminationCondition(seconds))


def _turn_once(checker: FootprintChecker, start, goal, *, time_limit: float, seed: int,
               resolution: float, turn_first: bool = True) -> np.ndarray | None:
    """A path that turns once, in place, at the start or at the goal, and moves at one held yaw (or ``None``).

    The straight way first (:func:`single_turn_path`), then a plane path at the goal's yaw after turning at
    the start, then one at the start's yaw before turning at the goal (:func:`plan_at_held_yaw`, each bounded by its
    iterations; ``time_limit`` is each one's safeguard on a slow machine).
    """
    path = single_turn_path(checker, np.array([start, goal], dtype=float), resolution, turn_first)
    if path is not None:
        return path
    (x0, y0, a0), (x1, y1, a1) = start, goal
    a1 = a0 + wrap_angle(a1 - a0)
    for held in dict.fromkeys((a1, a0) if turn_first else (a0, a1)):  # turn at the start, or at the goal
        xy = plan_at_held_yaw(checker, (x0, y0), (x1, y1), held, time_limit=time_limit, seed=seed,
                              resolution=resolution)
        if xy is None:
            continue
        path = _turned_once(xy, held, (x0, y0, a0), (x1, y1, a1))
        if _free_along(checker, path, resolution):
            return interpolate_path(path)
    return None


def path_length(path: np.ndarray, yaw_weight: float = 0.05) -> float:
    """Length of an SE(2) path in OMPL's compound metric: sum of ``|dxy| + yaw_weight |dyaw|`` (metres)."""
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or path.shape[1] != 3:
        raise InputError(f"path must be an (m, 3) array, got shape {path.shape}")
    if len(path) < 2:
        return 0.0
    d = np.diff(path, axis=0)
    dyaw = (d[:, 2] + math.pi) % (2.0 * math.pi) - math.pi
    return float(np.sum(np.hypot(d[:, 0], d[:, 1]) + yaw_weight * np.abs(dyaw)))


def _solution(space: ob.SE2StateSpace, setup: og.SimpleSetup) -> tuple[np.ndarray, list[int]]:
    """The setup's solution path as (m, 3) waypoints and, per segment, OMPL's count of checked steps."""
    solution = setup.getSolutionPath()
    states = solution.getStates()
    waypoints = np.array([(s.getX(), s.getY(), s.getYaw()) for s in states])
    counts = [space.validSegmentCount(states[i], states[i + 1]) for i in range(len(states) - 1)]
    del states, solution
    return waypoints, counts


def plan_path(
    checker: FootprintChecker,
    start: tuple[float, float, float],
    goal: tuple[float, float, float],
    *,
    time_limit: float = 1.0,
    seed: int = 0,
    resolution: float = 0.005,
    yaw_weight: float = 0.05,
    attempts: int = 1,
    iterations: int = SOLVE_ITERATIONS,
    single_turn: bool = True,
    turn_first: bool = True,
) -> np.ndarray:
    """Collision-free SE(2) path of the checker's footprint from ``start`` to ``goal``.

    RRT-Connect (OMPL) on ``SE2StateSpace`` bounded by the workspace, motions checked every
    ``resolution`` of SE(2) distance, then OMPL's simplifier (run until it improves nothing more), then subdivision
    to steps of at most 1 cm and 5 deg. Each attempt is bounded by ``iterations``, not by time, so the same seed
    gives the same path however loaded the machine is; ``time_limit`` is a safeguard for a slow machine. Every
    returned state, and every state OMPL checked along the simplified path, is re-checked with ``checker.is_free``.

    With ``single_turn`` (the default), paths turn once, in place (:func:`single_turn_path`), wherever that
    is free: the straight way is returned without sampling when it is free, and a sampled path's positions
    are kept at one held yaw when they can be. A planner that executes turns as spins then spins least.

    RRT-Connect is not optimising and the simplifier keeps a path's homotopy class, so a path may turn
    a full extra revolution (e.g. pass a gap at yaw + pi): with ``attempts > 1`` the planner restarts
    (while ``time_limit`` is not spent) and keeps the shortest solution (:func:`path_length`).

    Args:
        checker: footprint, obstacles and workspace.
        start, goal: (x, y, yaw) of the object-centred origin, world frame, metres and radians.
        time_limit: seconds after which no further solve starts and a running one stops (a safeguard:
            unloaded, ``iterations`` binds first).
        seed: seeds OMPL's process-global seed generator (see the module docstring); the same seed,
            problem and OMPL build give the same path unless ``time_limit`` cut a solve short.
        resolution: SE(2) distance between checked states along a motion, metres-equivalent.
        yaw_weight: metres that one radian of yaw counts for in the SE(2) metric.
        attempts: independent RRT-Connect runs; the shortest exact solution is returned.
        iterations: RRT-Connect iterations each attempt may take.
        single_turn: prefer paths that turn once (:func:`single_turn_path`).
        turn_first: with ``single_turn``, try turning at the start before turning at the goal.

    Returns:
        (n, 3) array of (x, y, yaw), world frame; ``path[0] == start``; yaw is continuous
        (unwrapped from ``start``'s yaw), so ``path[-1, 2]`` equals ``goal``'s yaw up to a multiple of 2 pi.

    Raises:
        InputError: a malformed argument (NaN, wrong shape, non-positive limits).
        GoalError: the start or the goal is not free; the message says why.
        PlanningError: no exact solution within ``iterations`` per attempt (or ``time_limit``).
    """
    if not isinstance(checker, FootprintChecker):
        raise InputError(f"checker must be a FootprintChecker, got {type(checker).__name__}")
    start = _check_pose(start, "start")
    goal = _check_pose(goal, "goal")
    time_limit = _check_positive(time_limit, "time_limit")
    resolution = _check_positive(resolution, "resolution")
    yaw_weight = _check_positive(yaw_weight, "yaw_weight")
    if not is_whole(seed) or not 0 <= seed < 2**32 - 1:
        raise InputError(f"seed must be an int in [0, 2**32 - 1), got {seed!r}")
    if not is_whole(attempts) or attempts < 1:
        raise InputError(f"attempts must be an int >= 1, got {attempts!r}")
    if not is_whole(iterations) or iterations < 1:
        raise InputError(f"iterations must be an int >= 1, got {iterations!r}")
    for name, pose in (("start", start), ("goal", goal)):
        reason = checker.why_not_free(*pose)
        if reason is not None:
            raise GoalError(f"{name} {pose} is not free: {reason}")
    if single_turn:
        path = _turn_once(checker, start, goal, time_limit=time_limit, seed=int(seed), resolution=resolution,
                          turn_first=turn_first)
        if path is not None:
            return path

    space = make_space(checker.workspace, yaw_weight)
    setup = planner = None
    best = None
    status = "not run"
    try:
        with _ompl_log_level(ou.LOG_WARN):
            _seed_ompl(int(seed))
            setup = make_setup(space, checker, resolution)
            planner = setup.getPlanner()
            setup.setStartAndGoalStates(_state(space, start), _state(space, goal))
            deadline = time.perf_counter() + time_limit
            for attempt in range(int(attempts)):
                remaining = deadline - time.perf_counter()
                if remaining <= 0.0:
                    break
                if attempt:
                    setup.clear()  # forget the trees and the solution; start and goal stay
                result = setup.solve(_budget(int(iterations), remaining))
                status = result.asString()
                if result.getStatus() != ob.PlannerStatus.EXACT_SOLUTION or not setup.haveExactSolutionPath():
                    continue  # approximate solutions count as failures
                setup.simplifySolution(0.0)  # 0: simplify to the end (no time limit, so deterministic)
                waypoints, counts = _solution(space, setup)
                length = path_length(waypoints, yaw_weight)
                if best is None or length < best[0]:
                    best = (length, waypoints, counts)
    finally:
        del planner, setup  # nanobind reports "leaked" objects at exit otherwise
    if best is None:
        raise PlanningError(f"no collision-free path from {start} to {goal} within {int(attempts)} x "
                            f"{int(iterations)} RRT-Connect iterations or {time_limit:.3g} s (OMPL: {status})")

    _, waypoints, counts = best
    waypoints[0] = (start[0], start[1], wrap_angle(start[2]))
    waypoints[-1] = (goal[0], goal[1], wrap_angle(goal[2]))
    if single_turn:  # the sampled way, turning once
        path = single_turn_path(checker, waypoints, resolution, turn_first)
        if path is not None:
            return path
    waypoints[:, 2] = np.unwrap(waypoints[:, 2]) + (start[2] - waypoints[0, 2])  # continuous from start's yaw
    # Re-check every state OMPL's motion validator saw (and the returned ones among them) in Python:
    # the returned path is only as safe as this check.
    for pose in interpolate_path(waypoints, min_counts=counts):
        if not checker.is_free(*pose):
            raise PlanningError(f"the simplified path touches an obstacle at {tuple(pose)}: "
                                f"{checker.why_not_free(*pose)}; try a finer resolution")
    return interpolate_path(waypoints)
