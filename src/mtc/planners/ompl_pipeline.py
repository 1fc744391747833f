"""The "ompl" planning pipeline: OMPL's geometric planners on a planning scene.

This is the only module that imports ``ompl``. :class:`OMPLPipeline` answers MoveIt-style
motion plan requests (a joint goal or a pose goal, path constraints, a time budget, a number
of attempts) with a geometric :class:`~mtc.scene.robot_trajectory.RobotTrajectory`: simplified,
interpolated, collision-free and inside the path constraints at every state between its
waypoints (proven, not sampled: see step 4). Time parameterization is the caller's business
(``PipelinePlanner``).

How a request is answered (MoveIt's ``ompl_interface`` with its default request adapters):

1. The start state is checked: variables slightly outside their bounds (up to
   :data:`START_STATE_MAX_BOUNDS_ERROR`) are moved onto them, as MoveIt's
   ``FixStartStateBounds`` does, and the original start becomes the first waypoint; farther
   out is ``START_STATE_INVALID``. A start in collision or violating the path constraints
   fails with the colliding bodies or the violated constraint in the message.
2. The goal is checked for collisions and path constraints (``GOAL_IN_COLLISION``,
   ``GOAL_VIOLATES_PATH_CONSTRAINTS``). A joint goal beyond its bounds is moved onto them with a
   warning, as MoveIt's joint constraint does ("Assuming maximum bounds instead"). Pose goals
   are turned into goal states by inverse kinematics (several distinct, valid solutions; the
   planner may reach any of them). A start or goal that touches an obstacle (closer than
   :data:`CERTIFY_MIN_MARGIN`, so that no motion from or to it can be proven free, see 4.)
   fails at once with ``START_STATE_IN_COLLISION`` or ``GOAL_IN_COLLISION`` instead of at the
   timeout; pose goals skip such IK solutions.
3. The straight joint-space segment is tried first; a free one is the answer.
4. Otherwise OMPL's planner searches the group's joint space. Motions are validated by
   :class:`_EdgeChecker` in numpy batches: states interpolated along the edge, checked end
   first and then by bisection (so a blocked edge is usually found out after a few checks),
   with the scene's broad-phase collision check and the path constraints. The search checks
   every :data:`DEFAULT_SEARCH_RATIO`-th state (0.06 rad apart). Every edge of the answer is
   then proven collision-free at every state on it
   (:meth:`~mtc.scene.planning_scene.MotionChecker.motion_free`: around a checked state, no
   pair of bodies can close a gap larger than a bound on how far they move, so the check of
   a state with that gap as coal's security margin covers a whole stretch of the edge;
   stretches not covered are halved). So the path is free at any interpolation resolution,
   as long as the robot's joints are revolute or prismatic (others: checked at every
   :data:`DEFAULT_RESOLUTION` state, 0.015 rad). Position and orientation path constraints
   are proven likewise (:meth:`_EdgeChecker._certify_constraints`: from a state, a
   constraint's margins shrink at first at the rates they have there, from the velocities of
   its point or link, and those rates grow at a bounded pace), as long as the joints are
   revolute or prismatic (others: checked at every :data:`DEFAULT_RESOLUTION` state).
   Joint constraints bound each joint to an interval, which a straight motion between two
   states inside it never leaves. An edge that fails is replanned (sub-searches of at most
   :data:`REPAIR_CHECKS` checks whose paths are then proven); where that fails too, the whole
   search runs again, checking its edges in full, while there is time. Start and goal are
   exact; the goal tolerance
   only admits goals already that close. RRTConnect (the default) that has not found a path
   after :data:`FALLBACK_CHECKS` state checks takes turns with :data:`FALLBACK_PLANNER`
   (LBKPIECE1, which checks lazily: only the edges of paths that join start and goal), both
   going on with their trees and the budgets growing each turn: a start or goal in a trap
   keeps RRTConnect's trees stuck for seconds. Where the goal is the trapped end (RRTConnect's
   goal tree stayed small), the fallback is :data:`TRAPPED_PLANNER` (KPIECE1) grown from the
   goal towards the start. From its second turn on the fallback keeps the
   free part of a blocked motion (OMPL's own motion validator then). A search still without
   a path after :data:`RACE_TURN` turns races a second one with other seeds (on another core
   where the process can fork); the first to find a path, counted in state checks, wins.
   Planners that grid a projection of the space (the KPIECE family) project onto the group's
   first two joints, as MoveIt's Panda configuration does (``projection_evaluator:
   joints(panda_joint1,panda_joint2)``); the fallback, where the goal is wedged, onto the tip
   link's position near the goal.
5. The path is shortened in numpy (greedy vertex shortcuts, then random shortcuts between
   points on the path, bounded by counts so that a seed gives one result), then
   interpolated to waypoints at most ``maximum extent / 100`` apart (at least
   :data:`MIN_WAYPOINT_COUNT`), as MoveIt does. Every waypoint lies on a proven edge.

Path constraints: joint constraints narrow the planner's joint bounds. Position and
orientation constraints make a constrained problem that a state sampler cannot reach through
OMPL's Python bindings (they cannot install samplers or set constrained-space states), so such
requests are planned by :func:`_constrained_rrt_connect`, a projection-based bidirectional RRT
(CBiRRT, Berenson et al. 2009) that steps along the constraint manifold by Jacobian
projection; edges are checked exactly as above, constraints included. The planner id is then
reported in the log but not used.

Reproducibility: each attempt seeds OMPL's random generators (``ompl.util.RNG.setSeed``,
before any planner object is made) and numpy's from ``seed`` + attempt number, so the same
request with the same seed gives the same path; a run cut short by its timeout can differ.

Failure messages are MoveIt's error code names, with details after a colon:
``"START_STATE_IN_COLLISION: start state is in collision: panda_hand - box"``,
``"TIMED_OUT: no solution found in 1 s (RRTConnect)"``, ``"PLANNING_FAILED: ..."``.
"""

from __future__ import annotations

import copy
import itertools
import logging
import math
import threading
import time
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass, replace

import numpy as np
import ompl.base as ob
import ompl.geometric as og
import ompl.util as ou

from mtc import msgs
from mtc.planners._race import race
from mtc.planners.constraints import ConstraintEvaluator, KinematicConstraintSet
from mtc.planners.planner_interface import invalid_constraints
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import JointModelGroup, RobotModel, check_same_model, shortest_delta, wrap_angle
from mtc.scene.robot_state import RobotState
from mtc.scene.robot_trajectory import RobotTrajectory

log = logging.getLogger(__name__)

__all__ = [
    "OMPLPipeline",
    "KNOWN_PLANNERS",
    "DEFAULT_PLANNER",
    "PlanStats",
    "resolve_planner_id",
]

#: Largest change of any joint between two states checked along an edge [rad or m] for path
#: constraints, and for collisions on robots whose joints have no motion bound (collisions are
#: otherwise proven between the sampled states, see :meth:`_EdgeChecker._certify`). The search
#: samples :data:`DEFAULT_SEARCH_RATIO` times coarser. MoveIt's default
#: (``longest_valid_segment_fraction`` 0.005 of the maximum extent) is about 0.065 rad in the
#: Euclidean norm for the Panda.
DEFAULT_RESOLUTION = 0.015
#: A stretch of a motion in which bodies can close in by less than this [m] and that is still
#: not proven free counts as colliding (see :meth:`_EdgeChecker._certify`): the motion grazes
#: an obstacle closer than that.
CERTIFY_MIN_MARGIN = 1e-6
#: Stretches in which bodies can close in by less than this [m] and that are not proven free
#: have their middle states checked for a collision (the edge fails); longer ones are just
#: halved (a collision between the sampled states of an answer's edge is rare). On the
#: MotionBenchMaker box and bookshelf problems 1 mm, 3 mm, 1 cm and 3 cm all needed within 2%
#: of the same state checks.
CERTIFY_FREE_CHECK = 1e-2
#: An interval of a motion over which the position and orientation constraints can change by
#: less than this [m or rad] and that is still not proven to keep them fails (see
#: :meth:`_EdgeChecker._certify_constraints`): the motion runs along a constraint's boundary.
CONSTRAINT_MIN_CHANGE = 1e-12
#: A proof of path constraints that would check more states than this along one edge gives the
#: edge up (see :meth:`_EdgeChecker._certify_constraints`): about 0.4 s of checks. A motion
#: that keeps a zero tolerance (up to rounding) needs about 40 000.
CONSTRAINT_PROOF_STATES = 50_000
#: Start states outside the bounds by at most this much are moved onto them [rad or m]
#: (``start_state_max_bounds_error`` of MoveIt's Panda configuration).
START_STATE_MAX_BOUNDS_ERROR = 0.1
#: Random shortcuts stop after this many tries in a row without a gain; the greedy pass before
#: them tries every vertex once. Each random shortcut adds two vertices that hug the obstacles,
#: and every edge of the result is proven collision-free in full: on the MotionBenchMaker box
#: and bookshelf problems (seeds 0, 1) 5 tries (at least one per vertex) took 224 000 state
#: checks, 2 tries 181 000, none 171 000, for median path lengths of 4.87, 5.06 and 5.02 rad.
SHORTCUT_FAILURES = 2
#: Sub-searches with the search's own (sampled) checks that replace an edge failing the full
#: check, before one with full checks of every edge it tries.
REPAIR_TRIES = 2
#: Levels of repairs of a repairing sub-search's own path (see OMPLPipeline._repair).
REPAIR_DEPTH = 1
#: State checks one repairing sub-search may make. A sub-search that needs more is between
#: states in narrow places that the search's resolution let it pass and the full check does not
#: (on a MotionBenchMaker-like shelf problem such sub-searches took 20 000 - 110 000 checks and
#: their paths failed the full check again): a new search does better (see OMPLPipeline._solve).
REPAIR_CHECKS = 10000
#: Fewest waypoints of a returned path (MoveIt's ``minimum_waypoint_count``).
MIN_WAYPOINT_COUNT = 10
#: IK solutions sampled as goal states of a pose goal.
POSE_GOAL_SAMPLES = 4
#: States drawn within the tolerance of an invalid joint goal (MoveIt's goal region) to find
#: valid goals in its place.
GOAL_REGION_SAMPLES = 200
#: A pose goal whose tolerances are wider than this (MoveIt's defaults, 1e-4 m and rad) is
#: also sampled within its region when IK finds no solution for the exact target at all.
REGION_WIDER_THAN = 1e-4
#: Extension step of RRT-family planners [rad, Euclidean]. OMPL's default (0.2 of the maximum
#: extent, about 2.6 rad for the Panda) makes long edges that are mostly blocked. On the
#: MotionBenchMaker problems (bench/motion_bench.py, seeds 0 and 1) 0.5 needed the fewest
#: collision checks: median 760 / 902 / 392 per problem on bookshelf_small / box / table_pick,
#: against 1518 / 906 / 468 with 1.0 and about twice as many with OMPL's default.
DEFAULT_RANGE = 0.5
#: Continuous joints whose goal is also given the long way round (2^n combinations per goal).
MAX_TURNED_JOINTS = 3
#: The search checks every 4th state along its edges (0.06 rad apart); the returned path is
#: then checked at every state (:data:`DEFAULT_RESOLUTION`).
DEFAULT_SEARCH_RATIO = 4
#: State checks of RRTConnect's first run before :data:`FALLBACK_PLANNER` takes over (see
#: :meth:`OMPLPipeline._run_ompl`). RRTConnect (or the straight line) solved 66-88% of the
#: problems of each MotionBenchMaker family in the data (3 seeds), few of the cage problems.
FALLBACK_CHECKS = 600
#: The planner that takes turns with RRTConnect when that is stuck: lazy, so it checks only
#: the edges of paths that reach from start to goal in its trees.
FALLBACK_PLANNER = "LBKPIECE1"
#: Where RRTConnect's first turn ends with its goal tree at most 1 / ``TRAPPED_RATIO`` the size
#: of its start tree, and the start tree has at least ``TRAPPED_MIN_START`` vertices (the goal
#: lies in a trap, the start does not), the fallback's turns go to ``TRAPPED_PLANNER`` growing
#: one tree from the goal towards the start (goal bias ``TRAPPED_GOAL_BIAS``) instead of
#: :data:`FALLBACK_PLANNER`: on generated cage problems (a goal between bars) 36% fewer checks,
#: where LBKPIECE1 spends most of its checks on the start tree's edges, validated again on
#: every connection that then fails on the goal's side.
TRAPPED_RATIO = 1.5
TRAPPED_MIN_START = 30
TRAPPED_PLANNER = "KPIECE1"
TRAPPED_GOAL_BIAS = 0.1
#: Each turn of :data:`FALLBACK_PLANNER` may check this many times as many states as the
#: RRTConnect turn before it.
FALLBACK_SHARE = 8
#: From this turn of :data:`FALLBACK_PLANNER` on (0: its first) its motions are checked by
#: OMPL's own validator, which tells how far a blocked motion is free, and LBKPIECE1 keeps
#: that part (see :meth:`_OMPLRun.solve`). A tree then creeps along a narrow passage, such as
#: the way to a goal deep in a shelf or under a table: the eight slowest generated problems
#: known (bench/motion_bench.py --generated, 6 seeds) took 45% fewer checks. From the first
#: turn on it also cost 60-100% more checks on the generated cage problems, which that turn
#: mostly solves.
FALLBACK_PARTIAL_TURN = 1
#: A goal is wedged when at most :data:`WEDGED_GOAL_FREE` of :data:`WEDGED_GOAL_PROBES` random
#: moves of :data:`WEDGED_GOAL_STEP` rad (Euclidean) from it are valid (the moves are drawn from
#: a fixed seed: whether a goal is wedged belongs to the problem, not to the planner's seed).
#: The fallback then projects onto the tip link's position as it moves near the goal (the
#: group's position Jacobian there: MoveIt's ``link(...)`` projection, linearised) instead of
#: the first two joints, so its goal tree spreads over the hand's positions and finds the few
#: ways out of a shelf or from under a table. The eight slowest generated problems known took
#: 18% fewer checks (12 seeds), and the one failure among those 96 runs was gone; on 1,164
#: held-out runs the largest cases shrank (63k to 13k checks) and some mid-sized ones grew
#: (4k to 11k), 1.8% fewer checks in all. For every goal it cost 46% more on the generated
#: cage problems, where the joints project better.
WEDGED_GOAL_PROBES = 32
WEDGED_GOAL_STEP = 0.2
WEDGED_GOAL_FREE = 2

#: A search that has not found a path after this many turns (RRTConnect's first, the
#: fallback's first: 5,400 state checks, about 80 ms on the Panda) races a second search with
#: other seeds (see :meth:`OMPLPipeline._race_second_search`): run times are heavy-tailed
#: over seeds, and a second search often ends a long run early. On the eight slowest
#: generated problems known, 12 seeds each, racing on two cores took 18% less time in all
#: than one search, and 9 of the 96 runs took more than 1 s instead of 14; in turns in one
#: process it took 21% more (18 runs).
#: None of the benchmark's 198 MotionBenchMaker and table-and-shelf problems gets this far.
RACE_TURN = 2
#: The second search's seed is the first one's plus this.
RACE_SEED_OFFSET = 15485863

#: How far [rad, m] the ends of OMPL's path may be from our start and goal states (OMPL copies
#: them; a goal state is reached within 1e-9).
_ENDS_TOLERANCE = 1e-8
#: How long [s] past the request's deadline a planner of :data:`_MAY_RUN_ON` may go on checking
#: states before the check raises :class:`_Overrun` to end it.
OVERRUN_GRACE = 0.5
#: OMPL planners that can stop asking OMPL's termination condition and run on for good (AORRTC's
#: tree growth, ompl/ompl#1420). Others may return late (BITstar prunes its graph in one step
#: that does not ask), but they do return, with a path worth keeping.
_MAY_RUN_ON = {"AORRTC"}
#: Time budget [s] of a request whose timeout is infinite (MoveIt's default planning time).
UNBOUNDED_TIMEOUT = 5.0

DEFAULT_PLANNER = "RRTConnectkConfigDefault"

# MoveIt's planner names (ompl_planning.yaml's "type: geometric::X" and the "XkConfigDefault"
# ids) -> the class in ompl.geometric; only those the installed OMPL offers are known.
_MOVEIT_NAMES = {
    "RRTConnect": "RRTConnect",
    "RRT": "RRT",
    "RRTstar": "RRTstar",
    "PRM": "PRM",
    "PRMstar": "PRMstar",
    "BITstar": "BITstar",
    "KPIECE": "KPIECE1",
    "BKPIECE": "BKPIECE1",
    "LBKPIECE": "LBKPIECE1",
    "FMT": "FMT",
    "BFMT": "BFMT",
    "InformedRRTstar": "InformedRRTstar",
    "SORRTstar": "SORRTstar",
    "AORRTC": "AORRTC",
    "EST": "EST",
    "BiEST": "BiEST",
    "ProjEST": "ProjEST",
    "SBL": "SBL",
    "TRRT": "TRRT",
    "BiTRRT": "BiTRRT",
    "LazyPRM": "LazyPRM",
    "LazyPRMstar": "LazyPRMstar",
    "SPARS": "SPARS",
    "SPARStwo": "SPARStwo",
    "STRIDE": "STRIDE",
    "PDST": "PDST",
    "LazyRRT": "LazyRRT",
    "ABITstar": "ABITstar",
    "AITstar": "AITstar",
}
#: OMPL planners whose solve runs a second thread that looks for a solution while the roadmap
#: grows. That thread must not call into Python (the state checks, a goal state's check, a
#: termination condition counting checks): the solving thread holds the GIL while it waits for
#: the thread to end, so such a call would never return. They get one goal state (the goal, or
#: the nearest valid state of a goal region) and a time limit, not a count of checks; the thread's
#: timing decides when they stop, so the same seed need not give the same path.
_THREADED = {"PRM", "PRMstar", "SPARS", "SPARStwo"}
#: Share of the remaining time an optimizing planner (which searches until its time is up) gets
#: for its searches; the rest is kept for proving its path collision-free in full and repairing
#: the edges that fail (MoveIt returns such a path after its planner's time; mtc must prove it).
OPTIMIZING_SEARCH_SHARE = 0.75
# planners that keep improving until the time is up (MoveIt gives them the whole budget)
_OPTIMIZING = {"RRTstar", "PRMstar", "BITstar", "InformedRRTstar", "SORRTstar", "AORRTC", "ABITstar", "AITstar"}


def _planner_table() -> dict[str, str]:
    table: dict[str, str] = {}
    for moveit_name, cls_name in _MOVEIT_NAMES.items():
        if hasattr(og, cls_name):
            table[moveit_name] = cls_name
            table[f"{moveit_name}kConfigDefault"] = cls_name
            table[f"geometric::{moveit_name}"] = cls_name
            table[cls_name] = cls_name
    return table


_PLANNERS = _planner_table()
#: Planner ids this pipeline accepts: MoveIt's ``XkConfigDefault`` ids, ``geometric::X`` and
#: the plain OMPL class names, for every planner the installed OMPL offers.
KNOWN_PLANNERS: tuple[str, ...] = tuple(sorted(_PLANNERS))


def resolve_planner_id(planner_id: str | None) -> str:
    """The ``ompl.geometric`` class name for a planner id ("" or None: the default).

    Raises:
        ValueError: unknown id, listing the known ones.
    """
    if planner_id is None or planner_id == "":
        planner_id = DEFAULT_PLANNER
    if not isinstance(planner_id, str):
        raise TypeError(f"planner id must be a string, not {type(planner_id).__name__}")
    if planner_id.endswith("]") and "[" in planner_id:
        # MoveIt's per-group configuration name, "panda_arm[RRTConnectkConfigDefault]"
        planner_id = planner_id[planner_id.index("[") + 1 : -1]
    try:
        return _PLANNERS[planner_id]
    except KeyError:
        ids = sorted(k for k in _PLANNERS if k.endswith("kConfigDefault"))
        base = planner_id.removeprefix("geometric::").removesuffix("kConfigDefault")
        if base in _MOVEIT_NAMES:
            raise ValueError(
                f"OMPL planner '{planner_id}' is one of MoveIt's, but the installed OMPL Python bindings "
                f"do not offer {_MOVEIT_NAMES[base]} (available: {', '.join(ids)})"
            ) from None
        raise ValueError(
            f"unknown OMPL planner id '{planner_id}' (known: {', '.join(ids)}; the plain OMPL names "
            f"such as 'RRTConnect' work too)"
        ) from None


def _result(success: bool, message: str = ""):
    from mtc.planners.planner_interface import PlannerResult  # owner A's seam, imported lazily

    return PlannerResult(success, message)


def _out_of_checks(max_checks: int, planner: str) -> str:
    return f"PLANNING_FAILED: no solution found in {max_checks} state checks ({planner})"


#: OMPL's log level is one setting for the process: plans running at once (in threads) share
#: one silence, which the first to start begins and the last to end lifts
_QUIET_LOCK = threading.Lock()
_quiet = {"count": 0, "level": None}


@contextmanager
def _quiet_ompl():
    """Silence OMPL's console output (results are reported as data and through logging)."""
    with _QUIET_LOCK:
        if _quiet["count"] == 0:
            _quiet["level"] = ou.getLogLevel()
            ou.setLogLevel(ou.LOG_NONE)
        _quiet["count"] += 1
    try:
        yield
    finally:
        with _QUIET_LOCK:
            _quiet["count"] -= 1
            if _quiet["count"] == 0:
                ou.setLogLevel(_quiet["level"])


def _check_seed(seed) -> int:
    if seed is None:
        return 0
    if not isinstance(seed, (int, np.integer)) or isinstance(seed, bool):
        raise TypeError(f"seed must be an integer, not {type(seed).__name__}")
    if seed < 0:
        raise ValueError(f"seed must be an integer >= 0, got {seed}")
    return int(seed)


def _ompl_seed(seed: int) -> int:
    # OMPL ignores seed 0; keep seeds positive 32-bit and distinct for distinct inputs
    return (int(seed) % 0xFFFFFFFE) + 1


# ---------------------------------------------------------------------------------------------
# Statistics


@dataclass
class PlanStats:
    """What the last request cost (read by bench/motion_bench.py).

    Attributes:
        planner: OMPL class (or internal planner) that produced the path.
        states_checked: collision (and constraint) checks of single states.
        check_time: time spent in those checks [s].
        plan_time: time of the search [s].
        simplify_time: time of shortcutting and interpolation [s].
        total_time: time of the whole request [s].
        raw_waypoints: vertices of the planner's path before simplification.
        path_length: joint-space length (Euclidean per segment) of the returned path [rad].
        attempts: attempts run.
        search_checks: state checks made by the search (the rest: shortcutting and the
            full check of the result).
        fine_retries: edges of a search's path that failed the full check (collision-free at
            every state on them) and were replanned.
        certify_checks: state checks spent proving edges collision-free between their
            sampled states (part of ``states_checked``).
        race_won_by_second: a search raced a second one (see :data:`RACE_TURN`) and the
            second one's path was taken.
    """

    planner: str = ""
    states_checked: int = 0
    check_time: float = 0.0
    plan_time: float = 0.0
    simplify_time: float = 0.0
    total_time: float = 0.0
    raw_waypoints: int = 0
    path_length: float = float("nan")
    attempts: int = 0
    search_checks: int = 0
    fine_retries: int = 0
    certify_checks: int = 0
    race_won_by_second: bool = False


# ---------------------------------------------------------------------------------------------
# State and edge checking


_ORDERS: dict[int, np.ndarray] = {}


def _bisection_order(n: int) -> np.ndarray:
    """Indices 1..n with n first and then the midpoints of ever finer halves (so states far
    from both checked ends come first: a blocked edge is found out after few checks)."""
    cached = _ORDERS.get(n)
    if cached is not None:
        return cached
    order = [n]
    seen = {0, n}
    step = n
    while step > 1:
        half = step / 2.0
        k = half
        while k < n:
            i = int(round(k))
            if i not in seen:
                seen.add(i)
                order.append(i)
            k += step
        step = half
    order.extend(i for i in range(1, n) if i not in seen)
    out = np.asarray(order, dtype=int)
    out.flags.writeable = False
    if len(_ORDERS) < 4096:
        _ORDERS[n] = out
    return out


class _EdgeChecker:
    """Validity of group configurations (collision-free, constraints hold) and of straight
    edges between them.

    Works on the group's variables ``x`` (k-vectors); the other variables stay at ``base``.
    An edge whose largest joint change is ``d`` is cut into ``n = ceil(d / coarse) * ratio``
    segments of at most ``resolution`` (= ``coarse / ratio``) per joint. The search checks
    only every ``ratio``-th of those states (:meth:`edge_ok`); a path is accepted after all
    of them are checked (:meth:`edge_ok_fine`, which skips the ones already checked). Most
    edges the search tries are never part of the answer, so they never pay for the fine
    check.
    """

    def __init__(
        self,
        scene: PlanningScene,
        group: JointModelGroup,
        base: np.ndarray,
        constraints: ConstraintEvaluator | None,
        resolution: float,
        ratio: int = 1,
    ):
        model = scene.robot_model
        self._motion = scene.motion_checker(group.name, np.array(base, dtype=float))
        self._collision_free = self._motion.free
        self._first_colliding = self._motion.first_colliding
        self._constraints = None if constraints is None or constraints.empty else constraints
        self._idx = group.variable_indices
        idx = self._idx
        if len(idx) and np.array_equal(idx, np.arange(idx[0], idx[0] + len(idx))):
            self._cols = slice(int(idx[0]), int(idx[0]) + len(idx))  # contiguous: a cheap slice
        else:
            self._cols = idx
        self._base = np.array(base, dtype=float)
        # mimic followers only need updating when the group moves one of their masters
        self._mimic = any(master in set(self._idx.tolist()) for _, master, *_ in model.mimic_followers)
        self._model = model
        self.resolution = float(resolution)
        self.ratio = max(1, int(ratio))
        self.coarse = self.resolution * self.ratio
        self.search_fine = self.ratio == 1  # True: the search checks edges fully
        self.states_checked = 0
        self.certify_checks = 0
        self.check_time = 0.0
        self._valid_states: set[bytes] = set()  # states known valid (tree vertices, ends)
        self._coarse_edges: set[bytes] = set()  # edges valid at the search resolution
        self._fine_edges: set[bytes] = set()  # edges valid at the full resolution
        # edges that failed the full check (a failing proof is the costliest check there is,
        # and the repair of a path asks again for the edge that made the path fail)
        self._bad_fine: set[bytes] = set()
        self._contiguous = isinstance(self._cols, slice)
        self._buf = np.repeat(self._base[None, :], 64, axis=0)  # states of one edge
        self._coarse_t: dict[int, np.ndarray] = {}
        self._fine_t: dict[int, np.ndarray] = {}
        # collisions between the sampled states are ruled out by motion bounds where the
        # robot's joints have them (revolute, prismatic), else edges are sampled finely
        self.certified = self._motion.certifiable
        self._touch_margins: np.ndarray | None = None  # see touching()
        # position and orientation constraints are proven between the sampled states where
        # their motion is bounded (see _certify_constraints), else only sampled
        self._constraint_rates = None if self._constraints is None else self._constraints.motion_rates()
        self.deadline = math.inf  # past it, proofs of path constraints give up (the edge fails)

    def caches(self) -> tuple[set[bytes], ...]:
        """Copies of what is known valid or invalid so far (see :meth:`restore_caches`)."""
        return tuple(set(c) for c in (self._valid_states, self._coarse_edges, self._fine_edges, self._bad_fine))

    def restore_caches(self, caches: tuple[set[bytes], ...]) -> None:
        """Know valid or invalid what :meth:`caches` returned (copies of it), nothing else."""
        self._valid_states, self._coarse_edges, self._fine_edges, self._bad_fine = (set(c) for c in caches)

    def branch(self) -> _EdgeChecker:
        """A checker for a second search racing this one: the same scene and settings, copies
        of what is known valid or not so far, and its own counts."""
        other = copy.copy(self)
        other.restore_caches(self.caches())
        other._buf = self._buf.copy()
        other.states_checked = other.certify_checks = 0
        other.check_time = 0.0
        return other

    def full(self, x: np.ndarray) -> np.ndarray:
        q = self._base.copy()
        q[self._cols] = x
        if self._mimic:
            self._model.enforce_mimic(q)
        return q

    def _check_full(self, q: np.ndarray) -> bool:
        self.states_checked += 1
        if not self._collision_free(q):
            return False
        return self._constraints is None or self._constraints(q)

    def state_ok(self, x: np.ndarray) -> bool:
        """Whether the group configuration ``x`` is valid (cached for exact repeats)."""
        key = x.tobytes()
        if key in self._valid_states:
            return True
        t0 = time.perf_counter()
        ok = self._check_full(self.full(x))
        self.check_time += time.perf_counter() - t0
        if ok:
            self._valid_states.add(key)
        return ok

    def touching(self, x: np.ndarray) -> bool:
        """Whether the (valid) group configuration ``x`` lies within :data:`CERTIFY_MIN_MARGIN`
        of a collision between bodies the group can move towards each other: no motion from
        or to it can then be proven collision-free (see :meth:`_certify`), so planning to or
        from it would only run out of time. False where the joints allow no proof."""
        if not self.certified:
            return False
        margins = self._touch_margins
        if margins is None:
            dq = np.zeros(len(self._base))
            dq[self._cols] = 1.0
            margins = self._touch_margins = np.where(self._motion.margins(dq) > 0.0, CERTIFY_MIN_MARGIN, 0.0)
        return not self._motion.clear(self.full(x), margins)

    def segments(self, a: np.ndarray, b: np.ndarray) -> int:
        """Number of (fine) segments an edge is checked and interpolated in."""
        return self._coarse_segments(b - a) * self.ratio

    def _coarse_segments(self, d: np.ndarray) -> int:
        dl = d.tolist()  # a handful of floats: Python's max beats two numpy reductions
        dmax = max(max(dl), -min(dl)) if dl else 0.0
        return max(1, math.ceil(dmax / self.coarse - 1e-9))

    _order = staticmethod(_bisection_order)

    def _coarse_params(self, n: int) -> np.ndarray:
        """Edge parameters of the search's states of an edge in ``n`` coarse segments, end
        first and then by bisection (cached: the per-edge numpy work is most of the Python
        overhead of a check)."""
        t = self._coarse_t.get(n)
        if t is None:
            t = (self._order(n) / n)[:, None]
            if len(self._coarse_t) < 4096:
                self._coarse_t[n] = t
        return t

    def _fine_params(self, n: int) -> np.ndarray:
        """Edge parameters of the fine states the search skipped, for ``n`` coarse segments."""
        t = self._fine_t.get(n)
        if t is None:
            m = n * self.ratio
            order = self._order(m)
            t = (order[order % self.ratio != 0] / m)[:, None]
            if len(self._fine_t) < 4096:
                self._fine_t[n] = t
        return t

    def _check_params(self, a: np.ndarray, d: np.ndarray, t: np.ndarray, constraints: bool = True) -> bool:
        """Whether the states ``a + t_i d`` are valid (collision-free, and where ``constraints``
        the path constraints hold), checked in the order of ``t`` (a column: ``m x 1``)."""
        t0 = time.perf_counter()
        m = len(t)
        # the states are written into a buffer holding the base state (the other variables)
        if m > len(self._buf):
            self._buf = np.repeat(self._base[None, :], max(m, 2 * len(self._buf)), axis=0)
        Q = self._buf[:m]
        if self._contiguous:
            view = Q[:, self._cols]
            np.multiply(t, d, out=view)
            view += a
        else:
            Q[:, self._cols] = a + t * d
        if self._mimic:
            self._model.enforce_mimic(Q)
        cons = self._constraints if constraints else None
        if cons is None:
            # the loop over the states runs in the motion checker (one Python call per edge)
            bad = self._first_colliding(Q)
            ok = bad < 0
            checked = m if ok else bad + 1
        else:
            ok = True
            cf = self._collision_free
            checked = m
            for i, q in enumerate(Q):
                if not cf(q) or not cons(q):
                    ok = False
                    checked = i + 1
                    break
        self.states_checked += checked
        self.check_time += time.perf_counter() - t0
        return ok

    def edge_ok(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Whether the edge from ``a`` (assumed valid) to ``b`` is valid at the search
        resolution (``b`` included)."""
        if self.search_fine:
            return self.edge_ok_fine(a, b)
        return self._edge_ok_coarse(a, b)

    def _edge_ok_coarse(self, a: np.ndarray, b: np.ndarray, key: bytes | None = None) -> bool:
        kb = b.tobytes()
        if key is None:
            key = a.tobytes() + kb
        if key in self._coarse_edges or key in self._fine_edges:
            return True
        d = b - a
        # (the search's hot path: _coarse_segments and _coarse_params inlined)
        dl = d.tolist()
        n = max(1, math.ceil(max(max(dl), -min(dl)) / self.coarse - 1e-9))
        t = self._coarse_t.get(n)
        if t is None:
            t = self._coarse_params(n)
        if kb in self._valid_states:
            t = t[1:]  # the end is known valid
        ok = self._check_params(a, d, t)
        if ok:
            self._coarse_edges.add(key)
            self._coarse_edges.add(kb + a.tobytes())
            self._valid_states.add(kb)
        return ok

    def edge_ok_fine(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Whether the edge is valid: collision-free and inside the path constraints at every
        state on it (proven, see :meth:`_certify` and :meth:`_certify_constraints`; where the
        robot's joints or a constraint allow no such bound, checked at every one of its
        :meth:`segments` states)."""
        key = a.tobytes() + b.tobytes()
        if key in self._fine_edges:
            return True
        if key in self._bad_fine:
            return False
        ok = self._edge_ok_coarse(a, b, key)
        if ok:
            d = b - a
            n = self._coarse_segments(d)
            sampled = self._constraints is not None and self._constraint_rates is None
            if self.ratio > 1 and (sampled or not self.certified):
                rest = self._fine_params(n)  # the others were checked by edge_ok
                ok = not rest.size or self._check_params(a, d, rest, sampled)
            if ok and self._constraint_rates is not None:
                ok = self._certify_constraints(a, d, n)
            if ok and self.certified:
                ok = self._certify(a, d, n)
        reverse = b.tobytes() + a.tobytes()
        if ok:
            self._fine_edges.add(key)
            self._fine_edges.add(reverse)
        else:
            self._bad_fine.add(key)
            self._bad_fine.add(reverse)
        return ok

    def _certify(self, a: np.ndarray, d: np.ndarray, n: int) -> bool:
        """Whether the motion ``a + t d``, t in [0, 1], is collision-free at every t, given
        that the states at t = j / n are.

        An interval of the motion is covered by a ball around its middle state: if that
        state is clear of every pair of bodies by more than the two can close in within half
        the interval (:meth:`~mtc.scene.planning_scene.MotionChecker.motion_free`), no state
        of the interval collides. Otherwise both halves are covered in turn; once the bodies
        move less than :data:`CERTIFY_FREE_CHECK` within an interval its middle state is
        checked for a collision (the motion fails), and an interval whose bodies move less
        than :data:`CERTIFY_MIN_MARGIN` without being covered fails: the motion grazes an
        obstacle closer than any sampled check could tell."""
        t0 = time.perf_counter()
        ok, checks = self._motion.motion_free(
            self.full(a), self.full(a + d), n, CERTIFY_MIN_MARGIN, CERTIFY_FREE_CHECK
        )
        self.states_checked += checks
        self.certify_checks += checks
        self.check_time += time.perf_counter() - t0
        return ok

    def _certify_constraints(self, a: np.ndarray, d: np.ndarray, m: int) -> bool:
        """Whether the position and orientation constraints hold at every state of the motion
        ``a + t d``, t in [0, 1]; the states t = j / m are checked first.

        Each constraint holds within a reach of a state where it holds
        (:meth:`ConstraintEvaluator.reaches`: its slack shrinks at first at the rate it has
        there, a rate that grows at a bounded pace along the motion), so an interval is
        covered when its two ends' reaches add up to its length. The others are
        halved, a level at a time, their middle states checked (the motion fails where a
        constraint is violated there); an interval over which the constraints could
        change by less than :data:`CONSTRAINT_MIN_CHANGE` and is still not covered fails: the
        motion runs along a constraint's boundary. So does a proof still running at
        :attr:`deadline` or due to check more than :data:`CONSTRAINT_PROOF_STATES` states."""
        t0 = time.perf_counter()
        qa = self.full(a)
        D = self.full(a + d) - qa
        L = self._constraint_rates @ np.abs(D)
        if not L.any():
            return True
        reaches = self._constraints.reaches

        def reach(ts: np.ndarray) -> np.ndarray:
            return np.array([reaches(qa + t * D, D, L) for t in ts.tolist()])

        # intervals (lo, hi) with their ends' reaches, halved level by level until covered
        t = np.arange(m + 1) / m
        R = reach(t)
        checks = m + 1
        lo, hi, r0, r1 = t[:-1], t[1:], R[:-1], R[1:]
        ok = bool(R.min() >= 0.0)
        while ok:
            h = (hi - lo)[:, None]
            uncovered = r0 + r1 <= h
            keep = uncovered.any(axis=1)
            if not keep.any():
                break
            if time.perf_counter() > self.deadline:
                ok = False
                break
            lo, hi, r0, r1, h, uncovered = lo[keep], hi[keep], r0[keep], r1[keep], h[keep], uncovered[keep]
            if (np.where(uncovered, L * h, 0.0).max(axis=1) < CONSTRAINT_MIN_CHANGE).any():
                ok = False
                break
            mid = 0.5 * (lo + hi)
            if checks + len(mid) > CONSTRAINT_PROOF_STATES:
                ok = False
                break
            rm = reach(mid)
            checks += len(mid)
            ok = bool(rm.min() >= 0.0)
            lo, hi = np.concatenate([lo, mid]), np.concatenate([mid, hi])
            r0, r1 = np.concatenate([r0, rm]), np.concatenate([rm, r1])
        self.states_checked += checks
        self.check_time += time.perf_counter() - t0
        return ok

    def edge_ok_direct(self, a: np.ndarray, b: np.ndarray) -> bool:
        """:meth:`edge_ok_fine` for an edge none of whose states were checked (the straight
        line to the goal): the first balls of the proof (:meth:`_certify`) are checked in
        bisection order, each not clear one also for a collision, so a blocked edge is found
        out after a few checks; the sampled states need no checks of their own (the balls
        cover them). With path constraints, as :meth:`edge_ok_fine`."""
        if self._constraints is not None or not self.certified:
            return self.edge_ok_fine(a, b)
        key = a.tobytes() + b.tobytes()
        if key in self._fine_edges:
            return True
        t0 = time.perf_counter()
        motion = self._motion
        d = b - a
        n = self._coarse_segments(d)
        qa, qb = self.full(a), self.full(b)
        margins = motion.margins(qb - qa) * (0.5 / n)
        order = self._order(n) - 1  # intervals j = n-1 (at b) first, then by bisection
        rows, colliding, checks = motion.sort_out(qa + ((order + 0.5) / n)[:, None] * (qb - qa), margins)
        ok = colliding < 0
        pending = sorted(order[rows].tolist())
        if ok and pending:
            # the intervals not covered yet are halved, with the bounds along the motion there
            # (MotionChecker.motion_margins): worked out only for those, as a straight line is
            # mostly found blocked, or clear of everything, by the balls above
            rates = motion.motion_margins(qa, qb - qa, (np.asarray(pending) + 0.5) / n, 0.5 / n)
            children = [c for j in pending for c in (2 * j, 2 * j + 1)]
            ok, more = motion.motion_free(qa, qb, 2 * n, CERTIFY_MIN_MARGIN, CERTIFY_FREE_CHECK, children, rates)
            checks += more
        self.states_checked += checks
        self.certify_checks += checks
        self.check_time += time.perf_counter() - t0
        if ok:
            self._fine_edges.add(key)
            self._fine_edges.add(b.tobytes() + a.tobytes())
            self._valid_states.add(b.tobytes())
        return ok

    def motion_ok(self, qa: np.ndarray, qb: np.ndarray) -> bool:
        """Whether the state ``qa`` (a full variable vector) and the straight motion from it to
        ``qb`` (continuous joints the short way) are collision-free at every state
        (:meth:`_certify`; sampled at the resolution where the joints allow no proof)."""
        model = self._model
        delta = shortest_delta(np.asarray(qb, dtype=float) - qa, model.continuous_mask)
        self.states_checked += 1
        if not self._collision_free(qa):
            return False
        if self.certified:
            ok, checks = self._motion.motion_free(qa, qa + delta, 1, CERTIFY_MIN_MARGIN, CERTIFY_FREE_CHECK)
            self.states_checked += checks
            self.certify_checks += checks
            return ok
        n = max(1, math.ceil(float(np.abs(delta).max(initial=0.0)) / self.resolution - 1e-9))
        self.states_checked += n - 1
        return all(self._collision_free(qa + (k / n) * delta) for k in range(1, n))

    def split(self, a: np.ndarray, b: np.ndarray, f: float) -> tuple[np.ndarray, float]:
        """The state of the edge ``a -> b`` the search samples (see :meth:`segments`) nearest to
        ``a + f (b - a)``, and its parameter (``a`` or ``b`` itself at the ends).

        A piece of the edge between such states is sampled at states of the edge: ``k`` of the
        edge's ``n`` segments make ``ceil(k dmax / n / coarse) = k`` segments of the piece, as
        ``dmax / coarse`` lies in ``(n - 1, n]``."""
        n = self._coarse_segments(b - a)
        k = int(round(f * n))
        if k <= 0:
            return a, 0.0
        if k >= n:
            return b, 1.0
        t = k / n
        return a + t * (b - a), t

    def inherit(self, a: np.ndarray, b: np.ndarray, pa: np.ndarray, pb: np.ndarray) -> None:
        """Record the piece ``pa -> pb`` of the edge ``a -> b``, cut at states of :meth:`split`,
        as valid as far as the edge is known to be: its sampled states are the edge's, and a
        piece of a motion proven collision-free is."""
        key = a.tobytes() + b.tobytes()
        piece, reverse = pa.tobytes() + pb.tobytes(), pb.tobytes() + pa.tobytes()
        if key in self._fine_edges:
            self._fine_edges.add(piece)
            self._fine_edges.add(reverse)
        elif key in self._coarse_edges:
            self._coarse_edges.add(piece)
            self._coarse_edges.add(reverse)
        else:
            return
        self._valid_states.add(pa.tobytes())
        self._valid_states.add(pb.tobytes())

    def path_ok(self, path: np.ndarray, fine: bool = False) -> bool:
        check = self.edge_ok_fine if fine else self.edge_ok
        return all(check(path[i], path[i + 1]) for i in range(len(path) - 1))

    def first_bad_edge(self, path: np.ndarray) -> int:
        """Index of the first edge that fails the fine check, or -1."""
        for i in range(len(path) - 1):
            if not self.edge_ok_fine(path[i], path[i + 1]):
                return i
        return -1


class _Overrun(Exception):
    """Raised by a state or motion check :data:`OVERRUN_GRACE` past the request's deadline: it
    unwinds the OMPL planner that went on past its termination condition."""


class _MotionValidator(ob.MotionValidator):
    """OMPL motion validator calling :class:`_EdgeChecker` (edges checked in numpy batches at
    the joint resolution instead of one Python callback per interpolated state)."""

    def __init__(self, si, checker: _EdgeChecker, k: int):
        super().__init__(si)
        self._checker = checker
        self._k = range(k)

    def checkMotion(self, s1, s2, *_last_valid) -> bool:  # noqa: N802 (OMPL's name)
        k = self._k
        a = np.array(list(map(s1.__getitem__, k)))
        b = np.array(list(map(s2.__getitem__, k)))
        return self._checker.edge_ok(a, b)


class _GuardedMotionValidator(_MotionValidator):
    """:class:`_MotionValidator` for a planner of :data:`_MAY_RUN_ON`: past ``stop_at``
    (``time.perf_counter()``) a check raises :class:`_Overrun` (the other planners do not pay
    for the clock)."""

    def __init__(self, si, checker: _EdgeChecker, k: int, stop_at: float):
        super().__init__(si, checker, k)
        self._stop_at = stop_at

    def checkMotion(self, s1, s2, *last_valid) -> bool:  # noqa: N802 (OMPL's name)
        if time.perf_counter() > self._stop_at:
            raise _Overrun
        return super().checkMotion(s1, s2, *last_valid)


# ---------------------------------------------------------------------------------------------
# Path post-processing (numpy)


def _path_length(path: np.ndarray) -> float:
    if len(path) < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def _shortcut(path: np.ndarray, check: Callable[[np.ndarray, np.ndarray], bool], rng: np.random.Generator,
              deadline: float, checker: _EdgeChecker | None = None) -> np.ndarray:
    """Shorten a valid path: greedy vertex shortcuts, then random shortcuts between points on
    the path until :data:`SHORTCUT_FAILURES` tries in a row brought
    nothing. The work is bounded by counts, not time, so a seed gives one result; ``deadline``
    (the request's) only stops it early. Every edge of the result passed ``check``.

    With ``checker`` (whose method ``check`` is), the points of a random shortcut lie on the
    states the checker samples along their edges (see :meth:`_EdgeChecker.split`): the pieces
    of an edge that a shortcut leaves in the path are sampled at the edge's own states, so
    they are valid as far as the edge is, and are not checked again."""
    path = [np.asarray(p, dtype=float) for p in path]
    # 1) greedy: from each vertex jump to the farthest vertex it sees
    out = [path[0]]
    i = 0
    while i < len(path) - 1:
        j = len(path) - 1
        while j > i + 1:
            if time.perf_counter() > deadline:
                j = i + 1
                break
            if check(path[i], path[j]):
                break
            j -= 1
        out.append(path[j])
        i = j
    path = out
    # 2) random shortcuts between points on two different edges
    failures = 0
    max_failures = SHORTCUT_FAILURES
    while len(path) > 2 and failures < max_failures and time.perf_counter() < deadline:
        seg = np.linalg.norm(np.diff(np.asarray(path), axis=0), axis=1)
        total = float(seg.sum())
        if total <= 1e-9:
            break
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        s1, s2 = np.sort(rng.uniform(0.0, total, 2))
        e1 = int(np.searchsorted(cum, s1, side="right") - 1)
        e2 = int(np.searchsorted(cum, s2, side="right") - 1)
        e1, e2 = min(e1, len(seg) - 1), min(e2, len(seg) - 1)
        if e1 == e2:
            failures += 1
            continue
        f1 = (s1 - cum[e1]) / seg[e1] if seg[e1] > 0 else 0.0
        f2 = (s2 - cum[e2]) / seg[e2] if seg[e2] > 0 else 0.0
        if checker is not None:
            p1, f1 = checker.split(path[e1], path[e1 + 1], f1)
            p2, f2 = checker.split(path[e2], path[e2 + 1], f2)
        else:
            p1 = path[e1] + f1 * (path[e1 + 1] - path[e1])
            p2 = path[e2] + f2 * (path[e2 + 1] - path[e2])
        new_len = float(np.linalg.norm(p2 - p1))
        old_len = (1.0 - f1) * seg[e1] + (cum[e2] - cum[e1 + 1]) + f2 * seg[e2]
        if new_len >= old_len - 1e-6:
            failures += 1
            continue
        if check(p1, p2):
            # the pieces p[e1] -> p1 and p2 -> p[e2+1] lie on edges already checked (with
            # ``checker``, at their own sampled states; the caller checks the result in full)
            head = path[: e1 + 1] if f1 > 0.0 else path[:e1]
            tail = path[e2 + 1 :] if f2 < 1.0 else path[e2 + 2 :]
            if checker is not None:
                if 0.0 < f1 < 1.0:
                    checker.inherit(path[e1], path[e1 + 1], path[e1], p1)
                if 0.0 < f2 < 1.0:
                    checker.inherit(path[e2], path[e2 + 1], p2, path[e2 + 1])
            path = head + [p1, p2] + tail
            failures = 0
        else:
            failures += 1
    return np.asarray(path)


def _interpolate(path: np.ndarray, checker: _EdgeChecker, max_segment: float, min_count: int) -> np.ndarray:
    """Waypoints along ``path``: each edge in ``ceil(length / max_segment)`` pieces (more if the
    whole path would have fewer than ``min_count`` waypoints), each waypoint one of the states
    the checker sampled on that edge."""
    if len(path) < 2:
        return np.asarray(path)
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    pieces = np.maximum(1, np.ceil(seg / max_segment - 1e-9)).astype(int)
    total = float(seg.sum())
    while pieces.sum() + 1 < min_count and total > 0:
        # add pieces to the longest edge per piece until the count is reached
        k = int(np.argmax(seg / pieces))
        pieces[k] += 1
    out = [np.asarray(path[:1], dtype=float)]
    for i in range(len(path) - 1):
        a, b = path[i], path[i + 1]
        n_check = checker.segments(a, b)
        # pieces of at most `stride` checked steps each: waypoints are checked states and no
        # piece is longer than the requested one
        stride = max(1, n_check // int(pieces[i]))
        m = math.ceil(n_check / stride)
        t = np.ceil(np.arange(1, m + 1) * n_check / m) / n_check
        states = a + t[:, None] * (b - a)
        states[-1] = b
        out.append(states)
    return np.concatenate(out)


# ---------------------------------------------------------------------------------------------
# The pipeline


@dataclass
class _Request:
    scene: PlanningScene
    group: JointModelGroup
    start: RobotState
    base: np.ndarray  # full start vector (after bound fixing)
    x_start: np.ndarray
    original_start: np.ndarray | None  # set when the start was moved onto its bounds
    lower: np.ndarray
    upper: np.ndarray
    constraints: KinematicConstraintSet
    evaluator: ConstraintEvaluator | None
    checker: _EdgeChecker
    deadline: float
    t0: float
    turns: np.ndarray  # per group variable: what wrapping continuous joints into [-pi, pi) removed
    free_turning: np.ndarray  # per group variable: a continuous joint planned a turn either way

    def within(self, x: np.ndarray) -> bool:
        """Whether the group variables ``x`` lie inside ``lower``/``upper`` (the joint bounds
        narrowed by the path's joint constraints)."""
        return bool(np.all(x >= self.lower - 1e-12) and np.all(x <= self.upper + 1e-12))


class OMPLPipeline:
    """OMPL planners behind MoveIt's request semantics (see the module docstring).

    Args:
        resolution: largest joint change between checked states along an edge [rad or m].
        planner_range: extension step of feasibility planners (RRTConnect, RRT, the KPIECEs)
            [rad]; 0 keeps OMPL's default, which the optimizing planners always use.
        search_ratio: the search checks every ``search_ratio``-th state of an edge; the
            returned path has all of them checked (1: the search checks every state).

    Attributes:
        last_stats: :class:`PlanStats` of the most recent request.
    """

    def __init__(
        self,
        resolution: float = DEFAULT_RESOLUTION,
        planner_range: float = DEFAULT_RANGE,
        search_ratio: int = DEFAULT_SEARCH_RATIO,
    ):
        if not resolution > 0:
            raise ValueError(f"resolution must be > 0, got {resolution}")
        if not (isinstance(search_ratio, (int, np.integer)) and search_ratio >= 1):
            raise ValueError(f"search_ratio must be an integer >= 1, got {search_ratio!r}")
        self.search_ratio = int(search_ratio)
        if planner_range < 0:
            raise ValueError(f"planner_range must be >= 0, got {planner_range}")
        self.resolution = float(resolution)
        self.planner_range = float(planner_range)
        self.last_stats = PlanStats()

    known_planners = KNOWN_PLANNERS
    default_planner = DEFAULT_PLANNER

    # ------------------------------------------------------------------ public API
    def plan_joint(
        self,
        scene: PlanningScene,
        start: RobotState,
        goal: RobotState,
        group: str,
        planner_id: str = "",
        timeout: float = 1.0,
        attempts: int = 1,
        path_constraints: msgs.Constraints | None = None,
        goal_joint_tolerance: float = 1e-4,
        seed: int = 0,
    ):
        """Plan from ``start`` to the group's variables of ``goal``.

        Args:
            scene: the scene to plan in (its world, attached objects and ACM).
            start: start state (variables outside ``group`` stay as they are).
            goal: goal state (only the group's variables are used).
            group: planning group.
            planner_id: MoveIt or OMPL planner id ("" = :data:`DEFAULT_PLANNER`).
            timeout: time budget of the whole request [s].
            attempts: planning attempts (MoveIt's ``num_planning_attempts``); the shortest
                path of the successful ones is returned.
            path_constraints: constraints every waypoint must satisfy.
            goal_joint_tolerance: a start this close to the goal (every variable) is already
                there [rad or m].
            seed: seed of every random choice.

        Returns:
            ``(PlannerResult, RobotTrajectory | None)``.

        Raises:
            ValueError: unknown planner id, bad timeout/attempts/tolerance.
            KeyError: unknown group.
        """
        cls_name = resolve_planner_id(planner_id)
        self._check_args(timeout, attempts, goal_joint_tolerance, "goal_joint_tolerance")
        seed = _check_seed(seed)
        if not isinstance(goal, RobotState):
            raise TypeError(f"goal must be a RobotState, not {type(goal).__name__}")
        req, failure = self._prepare(scene, start, group, timeout, path_constraints)
        if failure is not None:
            return failure
        x_goal = goal.positions[req.group.variable_indices].astype(float)
        failure = self._check_goal(req, x_goal, "goal state", goal_joint_tolerance)
        goals = [x_goal]
        if failure is not None:
            # as MoveIt, whose joint goal is the region within the tolerance of every joint:
            # an invalid goal state is replaced by valid ones sampled in that region
            goals = self._joint_goal_region(req, x_goal, goal_joint_tolerance, seed)
            if not goals:
                return self._fail(req, failure)
        return self._solve(req, goals, cls_name, attempts, goal_joint_tolerance, seed)

    def _joint_goal_region(self, req: _Request, x_goal: np.ndarray, tolerance: float, seed: int) -> list[np.ndarray]:
        """Up to :data:`POSE_GOAL_SAMPLES` valid states within ``tolerance`` of every joint of
        ``x_goal`` (and its bounds), closest first, from :data:`GOAL_REGION_SAMPLES` seeded
        draws; none if the region holds no valid state there."""
        lo, hi = self._group_bounds(req.scene.robot_model, req.group.variable_indices)
        lo, hi = np.maximum(lo, x_goal - tolerance), np.minimum(hi, x_goal + tolerance)
        if not np.all(hi > lo):
            return []
        rng = np.random.default_rng([int(seed), 3])
        draws = rng.uniform(lo, hi, (GOAL_REGION_SAMPLES, len(x_goal)))
        # closest first, checked only until enough are valid
        order = np.argsort(np.abs(draws - x_goal).max(axis=1), kind="stable")
        found = []
        for x in draws[order]:
            if req.within(x) and req.checker.state_ok(x):
                found.append(x)
                if len(found) == POSE_GOAL_SAMPLES:
                    break
        return found

    def plan_pose(
        self,
        scene: PlanningScene,
        start: RobotState,
        link: str,
        offset: np.ndarray,
        target: np.ndarray,
        group: str,
        planner_id: str = "",
        timeout: float = 1.0,
        attempts: int = 1,
        path_constraints: msgs.Constraints | None = None,
        goal_position_tolerance: float = 1e-4,
        goal_orientation_tolerance: float = 1e-4,
        seed: int = 0,
    ):
        """Plan from ``start`` until ``pose(link) · offset == target`` (target in the planning
        frame), within the position [m] and orientation [rad] tolerances.

        Goal states are inverse-kinematics solutions (collision-free, inside the path
        constraints) sampled with ``seed``; the planner may end at any of them.

        Returns:
            ``(PlannerResult, RobotTrajectory | None)``; ``NO_IK_SOLUTION`` when no valid goal
            state was found.
        """
        cls_name = resolve_planner_id(planner_id)
        self._check_args(timeout, attempts, goal_position_tolerance, "goal_position_tolerance")
        seed = _check_seed(seed)
        self._check_args(timeout, attempts, goal_orientation_tolerance, "goal_orientation_tolerance")
        offset = np.eye(4) if offset is None else np.asarray(offset, dtype=float)
        target = np.asarray(target, dtype=float)
        for name, T in (("offset", offset), ("target", target)):
            if T.shape != (4, 4) or not np.all(np.isfinite(T)):
                raise ValueError(f"{name} must be a finite 4x4 pose, got shape {T.shape}")
        req, failure = self._prepare(scene, start, group, timeout, path_constraints)
        if failure is not None:
            return failure
        goals, message = self._pose_goals(
            req, link, offset, target, goal_position_tolerance, goal_orientation_tolerance, seed
        )
        if not goals:
            return self._fail(req, message)
        return self._solve(req, goals, cls_name, attempts, 0.0, seed)

    # ------------------------------------------------------------------ preparation
    @staticmethod
    def _check_args(timeout, attempts, tolerance, tolerance_name) -> None:
        if not (isinstance(timeout, (int, float, np.floating)) and timeout >= 0):
            raise ValueError(f"timeout must be >= 0 [s], got {timeout!r}")
        if not (isinstance(attempts, (int, np.integer)) and attempts >= 1):
            raise ValueError(f"attempts (num_planning_attempts) must be an integer >= 1, got {attempts!r}")
        if not (msgs.is_number(tolerance) and tolerance >= 0):
            raise ValueError(f"{tolerance_name} must be >= 0, got {tolerance!r}")

    def _prepare(self, scene, start, group, timeout, path_constraints):
        t0 = time.perf_counter()
        self.last_stats = PlanStats()
        if timeout == 0:
            # as MoveIt's OMPL interface: "The timeout for planning must be positive (0 specified).
            # Assuming one second instead."
            log.info("OMPL pipeline: a timeout of 0 s; planning for 1 s instead, as MoveIt does")
            timeout = 1.0
        if not math.isfinite(timeout):
            # an unbounded request (MTC's default timeout is infinite) still has to end when
            # the problem has no solution: MoveIt's default allowed_planning_time
            timeout = UNBOUNDED_TIMEOUT
        if not isinstance(scene, PlanningScene):
            raise TypeError(f"scene must be a PlanningScene, not {type(scene).__name__}")
        if not isinstance(start, RobotState):
            raise TypeError(f"start must be a RobotState, not {type(start).__name__}")
        model: RobotModel = scene.robot_model
        check_same_model(model, start.robot_model, "the start state", "the scene's")
        jmg = model.get_joint_model_group(group)  # KeyError names the groups
        if jmg.variable_count == 0:
            raise ValueError(f"group '{jmg.name}' has no active variables to plan for")
        idx = jmg.variable_indices
        lower, upper = self._group_bounds(model, idx)
        try:
            constraints = KinematicConstraintSet(model, path_constraints)
        except (KeyError, ValueError) as e:  # (a failed request, as MoveIt's: not an exception)
            return None, self._fail(None, invalid_constraints(e))
        # joint constraints narrow the bounds the planner samples in (they are still checked)
        cont = model.continuous_mask[idx]
        free_turning = cont.copy()  # continuous joints no constraint narrows
        for var, (lo, hi) in constraints.joint_bounds().items():
            where = np.nonzero(idx == var)[0]
            if where.size:
                lower[where[0]] = max(lower[where[0]], lo)
                upper[where[0]] = min(upper[where[0]], hi)
                free_turning[where[0]] = False
        base = start.positions.copy()
        original = None
        x = base[idx].copy()
        unwrapped = x.copy()
        x[cont] = wrap_angle(x[cont])
        turns = unwrapped - x  # multiples of 2 pi, added back to the path
        # a continuous joint may turn a whole turn either way from the start (as on MoveIt's SO(2)
        # spaces a path may cross +-pi): its goal is given in both directions (see _turned_goals)
        lower[free_turning] = x[free_turning] - 2 * np.pi
        upper[free_turning] = x[free_turning] + 2 * np.pi
        model_lo, model_hi = self._group_bounds(model, idx)
        below, above = model_lo - x, x - model_hi
        worst = np.maximum(below, above)
        req = None
        if np.any(worst > 0):
            k = int(np.argmax(worst))
            name = jmg.variable_names[k]
            if worst[k] > START_STATE_MAX_BOUNDS_ERROR:
                return None, (
                    _result(
                        False,
                        f"START_STATE_INVALID: joint '{name}' = {x[k]:.6g} is outside its bounds "
                        f"[{model_lo[k]:.6g}, {model_hi[k]:.6g}]",
                    ),
                    None,
                )
            original = base.copy()
            x = np.clip(x, model_lo, model_hi)
            log.info("start state moved onto its bounds (joint '%s' was %.3g outside)", name, worst[k])
        base[idx] = x
        model.enforce_mimic(base)
        try:
            evaluator = constraints.bind(scene) if not constraints.empty else None
        except (KeyError, ValueError) as e:
            return None, self._fail(None, invalid_constraints(e))
        checker = _EdgeChecker(scene, jmg, base, evaluator, self.resolution, self.search_ratio)
        checker.deadline = t0 + timeout
        req = _Request(
            scene, jmg, start, base, x, original, lower, upper, constraints, evaluator, checker, t0 + timeout, t0,
            turns, free_turning,
        )
        # start validity: collision (with the bodies named), then path constraints
        start_state = RobotState(model, base)
        if not checker.state_ok(x):
            collisions = scene.get_collisions(start_state, jmg.name)
            if collisions:
                pairs = ", ".join(f"{a} - {b}" for a, b in collisions)
                return None, self._fail(req, f"START_STATE_IN_COLLISION: start state is in collision: {pairs}")
            return None, self._fail(
                req,
                "START_STATE_VIOLATES_PATH_CONSTRAINTS: start state violates the path constraints: "
                + "; ".join(evaluator.describe(base)),
            )
        if original is not None and not checker.motion_ok(original, base):
            # the returned path begins with the original start: its way onto the bounds counts
            collisions = scene.get_collisions(RobotState(model, original), jmg.name)
            pairs = ", ".join(f"{a} - {b}" for a, b in collisions)
            return None, self._fail(
                req,
                "START_STATE_IN_COLLISION: " + (
                    f"start state is in collision: {pairs}" if pairs
                    else "the motion from the start state onto its joint bounds collides"
                ),
            )
        if np.any(x < lower - 1e-12) or np.any(x > upper + 1e-12):
            return None, self._fail(
                req,
                "START_STATE_VIOLATES_PATH_CONSTRAINTS: start state violates the path constraints: "
                + "; ".join(evaluator.describe(base) if evaluator else []),
            )
        return req, None

    @staticmethod
    def _group_bounds(model: RobotModel, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lo = model.lower_bounds[idx].astype(float)
        hi = model.upper_bounds[idx].astype(float)
        # continuous joints: one turn, wrapped
        lo = np.where(np.isfinite(lo), lo, -np.pi)
        hi = np.where(np.isfinite(hi), hi, np.pi)
        return lo, hi

    def _check_goal(self, req: _Request, x_goal: np.ndarray, what: str, tolerance: float = 0.0) -> str | None:
        """None when ``x_goal`` is a valid goal, else the failure message. A joint value beyond
        its bound is moved onto the bound, as MoveIt's joint constraint does: within ``tolerance``
        (the goal's joint tolerance) the goal region reaches into the bounds; beyond it MoveIt
        warns and assumes the bound instead (so do we)."""
        model = req.scene.robot_model
        jmg = req.group
        cont = model.continuous_mask[jmg.variable_indices]
        x_goal[cont] = wrap_angle(x_goal[cont])
        lo, hi = self._group_bounds(model, jmg.variable_indices)
        slack = max(1e-9, float(tolerance))
        for k in np.nonzero((x_goal < lo - slack) | (x_goal > hi + slack))[0].tolist():
            side, bound = ("below", "minimum") if x_goal[k] < lo[k] else ("above", "maximum")
            log.warning("%s: joint %s = %.6g is constrained to be %s the %s bounds [%.6g, %.6g]. Assuming %s "
                        "bounds instead.", what, jmg.variable_names[k], x_goal[k], side, bound, lo[k], hi[k], bound)
        np.clip(x_goal, lo, hi, out=x_goal)
        if not req.checker.state_ok(x_goal):
            why = self._why_invalid(req, x_goal)
            code = "GOAL_IN_COLLISION" if why.startswith("is in collision") else "GOAL_VIOLATES_PATH_CONSTRAINTS"
            return f"{code}: {what} {why}"
        if not req.within(x_goal):
            q = req.checker.full(x_goal)
            return (
                f"GOAL_VIOLATES_PATH_CONSTRAINTS: {what} violates the path constraints: "
                + "; ".join(req.evaluator.describe(q) if req.evaluator else [])
            )
        return None

    @staticmethod
    def _why_invalid(req: _Request, x: np.ndarray) -> str:
        """Why the group configuration ``x`` is no valid state: ``"is in collision: a - b, ..."``,
        ``"violates the path constraints: ..."`` or ``"touches an obstacle (...)"`` (valid, but
        closer to one than any motion can be proven free, see :meth:`_EdgeChecker.touching`)."""
        q = req.checker.full(x)
        collisions = req.scene.get_collisions(RobotState(req.scene.robot_model, q), req.group.name)
        if collisions:
            return "is in collision: " + ", ".join(f"{a} - {b}" for a, b in collisions)
        if not req.checker.state_ok(x):
            return "violates the path constraints: " + "; ".join(req.evaluator.describe(q) if req.evaluator else [])
        return f"touches an obstacle (closer than {CERTIFY_MIN_MARGIN:g} m)"

    def _pose_goals(self, req, link, offset, target, pos_tol, rot_tol, seed):
        """Valid IK goal states for a pose goal, or ([], failure message)."""
        from mtc.planners import ik  # owner A's solver, imported lazily

        scene = req.scene
        state = scene.current_state.copy()  # knows the scene's attached frames
        state.positions = req.base
        try:
            tip, tip_offset = ik.resolve_tip(state, req.group.name, link)
        except (KeyError, ValueError) as e:
            raise KeyError(f"pose goal: {msgs.error_text(e)}") from None
        link_target = target @ np.linalg.inv(tip_offset @ offset)
        try:
            solver = ik.get_ik_solver(scene.robot_model, req.group.name, tip)
        except ik.UnmovedLinkError as e:  # (a pose goal for a link the group does not move)
            return [], f"NO_IK_SOLUTION: {e}"
        checker = req.checker
        idx = req.group.variable_indices
        rejected = {"invalid": 0, "bounds": 0}
        first_invalid = []  # the first IK solution rejected as invalid, to say why

        def is_valid(q: np.ndarray) -> bool:
            x = q[idx]
            if not req.within(x):
                rejected["bounds"] += 1
                return False
            if not checker.state_ok(x) or checker.touching(x):
                rejected["invalid"] += 1
                if not first_invalid:
                    first_invalid.append(x.copy())
                return False
            return True

        rng = np.random.default_rng([int(seed), 1])
        tolerance = min(pos_tol, rot_tol, 1e-6) if min(pos_tol, rot_tol) > 0 else 1e-9

        def sample(attempts: int, wanted: int, aim: np.ndarray = link_target) -> list[np.ndarray]:
            solutions = solver.solve(
                aim, req.base, timeout=max(0.0, req.deadline - time.perf_counter()), rng=rng,
                is_valid=is_valid, max_solutions=wanted, max_attempts=attempts, tolerance=tolerance,
            )
            goals = []
            for q in solutions:
                reached = solver.forward(q).homogeneous
                err_p = float(np.linalg.norm(reached[:3, 3] - link_target[:3, 3]))
                err_r = msgs.rotation_angle(link_target[:3, :3].T @ reached[:3, :3])
                if err_p <= pos_tol + 1e-12 and err_r <= rot_tol + 1e-12:
                    goals.append(q[idx].astype(float))
            return goals

        goals = sample(ik.POSE_GOAL_IK_ATTEMPTS, POSE_GOAL_SAMPLES)
        if not goals and (rejected["invalid"] or rejected["bounds"]):
            # IK solutions, but none valid (a goal in a narrow place): one valid goal from more
            goals = sample(ik.POSE_GOAL_IK_MORE_ATTEMPTS, 1)
        if not goals and (rejected["invalid"] or max(pos_tol, rot_tol) > REGION_WIDER_THAN):
            # as MoveIt, whose pose goal is the region within the position and orientation
            # tolerances: poses drawn in it, one IK descent each, until one has a valid solution
            # (also where the exact target is out of reach but part of a wider region is not)
            for aim in _poses_within(link_target, pos_tol, rot_tol, GOAL_REGION_SAMPLES, rng):
                goals = sample(1, 1, aim)
                if goals or time.perf_counter() > req.deadline:
                    break
        if goals:
            return goals, ""
        if rejected["invalid"] or rejected["bounds"]:
            first = f"; the first {self._why_invalid(req, first_invalid[0])}" if first_invalid else ""
            return [], (
                f"NO_IK_SOLUTION: no valid goal state for '{link}' ({rejected['invalid']} IK solutions in "
                f"collision, touching an obstacle or violating the path constraints, {rejected['bounds']} "
                f"outside the joint constraints{first})"
            )
        return [], f"NO_IK_SOLUTION: no inverse kinematics solution for '{link}' at the target pose"

    # ------------------------------------------------------------------ solving
    def _fail(self, req: _Request | None, message: str):
        if req is not None:
            self._finish_stats(req)
        log.debug("OMPL pipeline: %s", message)
        return _result(False, message), None

    def _finish_stats(self, req: _Request) -> None:
        st = self.last_stats
        st.states_checked = req.checker.states_checked
        st.certify_checks = req.checker.certify_checks
        st.check_time = req.checker.check_time
        st.total_time = time.perf_counter() - req.t0

    @staticmethod
    def _turned_goals(req: _Request, goals: list[np.ndarray]) -> list[np.ndarray]:
        """The goals with their freely turning continuous joints at the value nearest the start
        (the short way round), then the same goals reached the long way round in one, two or
        all of those joints (the first :data:`MAX_TURNED_JOINTS` of them that move)."""
        turning = req.free_turning
        if not turning.any():
            return goals
        x = req.x_start
        short = []
        for g in goals:
            g = np.array(g, dtype=float)
            g[turning] = x[turning] + wrap_angle(g[turning] - x[turning])
            short.append(g)
        out = list(short)
        for g in short:
            moving = np.nonzero(turning & (np.abs(g - x) > 1e-12))[0][:MAX_TURNED_JOINTS]
            for r in range(1, len(moving) + 1):
                for joints in itertools.combinations(moving, r):
                    j = list(joints)
                    other = g.copy()
                    other[j] -= 2 * np.pi * np.sign(g[j] - x[j])
                    out.append(other)
        return out

    def _solve(self, req: _Request, goals: list[np.ndarray], cls_name: str, attempts: int, goal_tol: float, seed: int):
        checker = req.checker
        stats = self.last_stats
        stats.planner = cls_name
        goals = self._turned_goals(req, goals)
        # already there: the start lies within the goal's tolerance. Move on to the goal where that
        # motion is free, else stay (a jump to the goal state unchecked could pass an obstacle)
        for g in goals:
            if np.all(np.abs(g - req.x_start) <= goal_tol):
                path = np.array([req.x_start, g]) if checker.edge_ok_direct(req.x_start, g) else np.array([req.x_start])
                return self._success(req, path, path)
        # a start or goal closer to an obstacle than the proof can resolve: fail now, not at the timeout
        if checker.touching(req.x_start):
            return self._fail(req, f"START_STATE_IN_COLLISION: start state touches an obstacle (closer than "
                                   f"{CERTIFY_MIN_MARGIN:g} m): no motion from it can be proven collision-free")
        goals = [g for g in goals if not checker.touching(g)]
        if not goals:
            return self._fail(req, f"GOAL_IN_COLLISION: goal state touches an obstacle (closer than "
                                   f"{CERTIFY_MIN_MARGIN:g} m): no motion to it can be proven collision-free")
        # the straight segment (to the nearest goal first)
        order = sorted(range(len(goals)), key=lambda i: float(np.abs(goals[i] - req.x_start).sum()))
        t_plan = time.perf_counter()
        for i in order:
            if checker.edge_ok_direct(req.x_start, goals[i]):
                stats.plan_time = time.perf_counter() - t_plan
                stats.planner = "straight line"
                path = np.array([req.x_start, goals[i]])
                return self._success(req, path, _interpolate(path, checker, self._max_segment(req), MIN_WAYPOINT_COUNT))
        if req.evaluator is not None and req.constraints.has_link_constraints:
            runner = self._run_constrained
            stats.planner = "CBiRRT"
            log.info("position/orientation path constraints: planning with projection (CBiRRT), not %s", cls_name)
        else:
            runner = self._run_ompl
        best = None
        last_message = ""
        attempt = 0
        renewed = 0  # searches run again because their path could not be made valid in full
        while attempt < attempts:
            if time.perf_counter() >= req.deadline:
                break
            stats.attempts += 1
            t_plan = time.perf_counter()
            # optimizing planners use all the time they get: share it between the attempts, with
            # time kept back to prove and repair the path they find
            share = None
            if cls_name in _OPTIMIZING:
                share = OPTIMIZING_SEARCH_SHARE * (req.deadline - t_plan) / (attempts - attempt)
            before = checker.states_checked
            run_seed = seed + attempt + 1000003 * renewed
            if renewed:
                checker.search_fine = True  # (a renewed search checks its edges in full)
            if runner == self._run_ompl:  # (the runner names the planner whose path it took)
                stats.planner, stats.race_won_by_second = cls_name, False
            path, message = runner(req, req.x_start, goals, cls_name, run_seed, share)
            stats.plan_time += time.perf_counter() - t_plan
            stats.search_checks += checker.states_checked - before
            if path is None:
                last_message = message
                attempt += 1
                continue
            stats.raw_waypoints = len(path)
            final = self._finalize(req, path, runner, cls_name, run_seed)
            if final is None:
                last_message = "TIMED_OUT: no collision-free path at the checking resolution within the time"
                if best is None:
                    # the search went through a place only its coarser checks let it pass: a
                    # new search (new seed, every edge checked in full) while there is time,
                    # before any further attempt (more attempts only add searches after these)
                    renewed += 1
                    continue
                attempt += 1
                continue
            if best is None or _path_length(final) < _path_length(best):
                best, kept = final, (stats.planner, stats.race_won_by_second)
            attempt += 1
        if best is None:
            if not last_message:
                last_message = f"TIMED_OUT: no attempt could start within {req.deadline - req.t0:.3g} s"
            return self._fail(req, last_message)
        stats.planner, stats.race_won_by_second = kept  # the kept attempt's
        t_simp = time.perf_counter()
        dense = _interpolate(best, checker, self._max_segment(req), MIN_WAYPOINT_COUNT)
        stats.simplify_time += time.perf_counter() - t_simp
        return self._success(req, best, dense)

    def _max_segment(self, req: _Request) -> float:
        # MoveIt: max_solution_segment_length = maximum extent of the space / 100 (a continuous
        # joint's extent is pi there, on SO(2))
        extent = np.where(req.free_turning, np.pi, req.upper - req.lower)
        return float(np.linalg.norm(extent)) / 100.0

    def _finalize(self, req: _Request, path: np.ndarray, runner, cls_name: str, seed: int):
        """Shortcut a path the search found (its edges valid at the search resolution) with
        shortcuts valid in full (:meth:`_EdgeChecker.edge_ok_fine`: collision-free at every
        state) and make sure the result is valid in full. Edges of the shortened path that
        fail the full check (the search's own) are replanned (a short sub-search each; the
        search's own path is repaired that way if this fails), and the result shortened again.
        None if that does not succeed in time."""
        t0 = time.perf_counter()
        checker = req.checker
        deadline = req.deadline
        rng = np.random.default_rng([int(seed), 2])
        # shortcuts are taken only when they pass the full check: a shortcut checked at the
        # search's resolution often grazes an obstacle between its sampled states (it cuts the
        # corners the search went around), and replanning it costs more than its proof
        out = _shortcut(path, checker.edge_ok_fine, rng, deadline, checker)
        if not checker.path_ok(out, fine=True):
            # replan the failing edges of the shortened path (edges of the search's path that
            # no shortcut replaced); the search's own path would need every one of its edges
            # checked in full
            repaired = self._repair(req, out, runner, cls_name, seed)
            if repaired is None:
                repaired = self._repair(req, path, runner, cls_name, seed)
            out = repaired
            if repaired is not None:
                again = _shortcut(repaired, checker.edge_ok_fine, rng, deadline, checker)
                if checker.path_ok(again, fine=True):
                    out = again
        self.last_stats.simplify_time += time.perf_counter() - t0
        return out

    def _repair(self, req: _Request, path: np.ndarray, runner, cls_name: str, seed: int, depth: int = 0):
        """``path`` with every edge that fails the full check replaced by a path searched anew
        (:data:`REPAIR_TRIES` sub-searches with the search's checks whose paths are then
        checked in full, the failing edges of such a path repaired in turn up to
        :data:`REPAIR_DEPTH` levels, then one with full checks); None if none is found in time."""
        checker = req.checker
        out = [path[0]]
        fine_before = checker.search_fine
        try:
            for i in range(len(path) - 1):
                a, b = path[i], path[i + 1]
                if checker.edge_ok_fine(a, b):
                    out.append(b)
                    continue
                self.last_stats.fine_retries += 1
                sub = None
                # sub-searches with the search's checks, their paths then proven in full (proving
                # every edge a sub-search tries would cost far more); the last with full checks
                for k in range(REPAIR_TRIES + 1):
                    checker.search_fine = k == REPAIR_TRIES
                    sub_seed = seed + 7919 * (i + 1) + 104729 * k
                    sub, _ = runner(req, a, [b], cls_name, sub_seed, None, REPAIR_CHECKS)
                    if sub is None or checker.path_ok(sub, fine=True):
                        break
                    if depth < REPAIR_DEPTH:
                        # most of such a path holds: replan only its failing edges
                        checker.search_fine = fine_before
                        sub = self._repair(req, sub, runner, cls_name, sub_seed + 1, depth + 1)
                        if sub is not None:
                            break
                    sub = None
                checker.search_fine = fine_before
                if sub is None:
                    return None
                out.extend(sub[1:])
        finally:
            checker.search_fine = fine_before
        return np.asarray(out)

    def _success(self, req: _Request, path: np.ndarray, dense: np.ndarray):
        model = req.scene.robot_model
        # continuous joints were planned in [-pi, pi): shift the whole path by the turns the
        # start had, so it starts at the start's own values (the goal is reached modulo 2 pi)
        positions = np.asarray(dense, dtype=float) + req.turns
        base = req.base.copy()
        base[req.group.variable_indices] = positions[0]
        # waypoints are the start state's copies: they carry its attached objects
        reference = req.start._with_positions(base)
        traj = RobotTrajectory.from_positions(model, req.group.name, reference, positions)
        if req.original_start is not None:
            traj.add_prefix_waypoint(req.start._with_positions(np.array(req.original_start, dtype=float)))
        self.last_stats.path_length = _path_length(np.asarray(path))
        self._finish_stats(req)
        return _result(True, ""), traj

    # ------------------------------------------------------------------ OMPL
    def _run_ompl(self, req: _Request, x_start: np.ndarray, goals: list[np.ndarray], cls_name: str, seed: int,
                  share=None, max_checks: int | None = None):
        """One attempt with an OMPL planner: (path as n x k array, "") or (None, message);
        at most ``max_checks`` state checks where given.

        RRTConnect's run time is heavy-tailed: a start or goal in a trap (a narrow way out,
        joints near their limits) keeps its tree stuck for seconds, most of its checks spent
        on extensions that end at an obstacle. So RRTConnect takes turns with
        :data:`FALLBACK_PLANNER` (see :class:`_TurnSearch`). A search (not a repair's
        sub-search) that has not found a path after :data:`RACE_TURN` turns races a second
        such search with other seeds (:func:`mtc.planners._race.race`: on another core where
        the process can fork); the one that finds a path with fewer state checks wins. Budgets
        count state checks, not time, so a seed still gives one result."""
        if cls_name != "RRTConnect" or FALLBACK_PLANNER not in _PLANNERS.values():
            run = _OMPLRun(req, x_start, goals, cls_name, seed, self.planner_range)
            try:
                path, message, cut = run.solve(share, max_checks)
            finally:
                run.release()
            return path, (_out_of_checks(max_checks, cls_name) if cut else message)
        search = _TurnSearch(req, x_start, goals, cls_name, seed, self.planner_range, share, max_checks)
        try:
            end = None
            while end is None and (max_checks is not None or search.turn < RACE_TURN):
                end = search.step()
            if end is None:
                end = self._race_second_search(req, search, x_start, goals, cls_name, seed, share)
        finally:
            search.release()
        path, message, planner = end
        if path is not None and planner != cls_name and max_checks is None:  # (not a repair's)
            self.last_stats.planner = planner
        return path, message

    def _race_second_search(self, req: _Request, first: _TurnSearch, x_start, goals, cls_name: str, seed: int,
                            share):
        """Race ``first`` against a second search with the seed ``seed +``
        :data:`RACE_SEED_OFFSET` that starts with ``first``'s caches as they are now; then go on
        with those caches (whichever search won, and however far the other got), and count
        the checks both made up to the winner's end, so that what follows does not depend on
        where the race ran."""
        checker = req.checker
        saved = checker.caches()
        second = _TurnSearch(replace(req, checker=checker.branch()), x_start, goals, cls_name,
                             seed + RACE_SEED_OFFSET, self.planner_range, share)
        offset = first.checks
        try:
            winner, end, checks = race(first, second, offset, req.deadline)
        finally:
            second.release()
        checker.restore_caches(saved)
        checker.states_checked += checks - first.checks
        self.last_stats.race_won_by_second = winner == 1
        log.debug("search raced a second one after %d checks: the %s ended first", offset,
                  "second" if winner else "first")
        return end

    # ------------------------------------------------------------------ constrained
    def _run_constrained(self, req: _Request, x_start: np.ndarray, goals: list[np.ndarray], cls_name: str, seed: int,
                         share=None, max_checks: int | None = None):
        return _constrained_rrt_connect(req, x_start, goals, np.random.default_rng([int(seed), 3]), self.resolution,
                                        max_checks)


def _poses_within(T: np.ndarray, pos_tol: float, rot_tol: float, n: int, rng: np.random.Generator):
    """``n`` poses within ``pos_tol`` [m] (a ball) and ``rot_tol`` [rad] (about a random
    axis) of the 4x4 pose ``T``, drawn uniformly in distance and angle (as MoveIt's pose-goal
    sampling around the target)."""
    for _ in range(n):
        out = T.copy()
        axis = rng.normal(size=3)
        out[:3, 3] += pos_tol * rng.uniform() * axis / max(np.linalg.norm(axis), 1e-12)
        out[:3, :3] = T[:3, :3] @ msgs.axis_angle_matrix(rng.normal(size=3), rot_tol * rng.uniform())
        yield out


def _wedged_goal_projection(req: _Request, goal: np.ndarray) -> np.ndarray | None:
    """The fallback's projection for a wedged ``goal`` (see :data:`WEDGED_GOAL_FREE`): the
    position Jacobian (3 x k, world axes) of the group's IK tip at the goal. None (the first two
    joints) where the goal is not wedged, the group has no tip or at most three variables, or
    the tip cannot move in all three directions there. The probes count as state checks."""
    group = req.group
    k = group.variable_count
    if k <= 3 or not group.ik_tips:
        return None
    moves = np.random.default_rng(0).normal(size=(WEDGED_GOAL_PROBES, k))
    moves *= WEDGED_GOAL_STEP / np.linalg.norm(moves, axis=1)[:, None]
    free = 0
    for move in moves:
        free += req.checker.state_ok(np.clip(goal + move, req.lower, req.upper))
        if free > WEDGED_GOAL_FREE:
            return None
    at_goal = req.start.copy()
    at_goal.positions = req.checker.full(goal)
    position = np.ascontiguousarray(at_goal.get_jacobian(group.name, group.ik_tips[0])[:3])
    return position if np.linalg.matrix_rank(position) == 3 else None


class _OMPLRun:
    """One OMPL planner on one request, set up once: :meth:`solve` may be called again (with a
    new budget) and goes on with the planner's trees. :meth:`release` frees the OMPL objects
    (nanobind reports those still alive at exit).

    ``from_goal``: the planner grows from the (one) goal towards the start; :meth:`solve` still
    returns the path from the start."""

    def __init__(self, req: _Request, x_start: np.ndarray, goals: list[np.ndarray], cls_name: str, seed: int,
                 planner_range: float, projection: np.ndarray | None = None, goal_bias: float | None = None,
                 from_goal: bool = False):
        self.req = req
        self.cls_name = cls_name
        k = req.group.variable_count
        self._k = range(k)
        if cls_name in _THREADED:
            goals = goals[:1]
        self._from_goal = from_goal
        if from_goal:
            x_start, goals = goals[0], [x_start]
        self._start, self._goals = np.asarray(x_start, dtype=float), np.asarray(goals, dtype=float)
        with _quiet_ompl():
            ou.RNG.setSeed(_ompl_seed(seed))  # before any OMPL object draws its own seed
            space = ob.RealVectorStateSpace(k)
            bounds = ob.RealVectorBounds(k)
            for i in range(k):
                lo, hi = float(req.lower[i]), float(req.upper[i])
                if hi - lo < 1e-9:  # OMPL needs a non-empty interval
                    hi = lo + 1e-9
                bounds.setLow(i, lo)
                bounds.setHigh(i, hi)
            space.setBounds(bounds)
            ss = og.SimpleSetup(space)
            si = ss.getSpaceInformation()
            checker = req.checker
            rng_k = self._k

            def is_valid(state) -> bool:
                return checker.state_ok(np.array(list(map(state.__getitem__, rng_k))))

            if cls_name in _MAY_RUN_ON:
                stop_at = req.deadline + OVERRUN_GRACE
                unguarded = is_valid

                def is_valid(state) -> bool:
                    if time.perf_counter() > stop_at:
                        raise _Overrun
                    return unguarded(state)

                si.setMotionValidator(_GuardedMotionValidator(si, checker, k, stop_at))
            else:
                si.setMotionValidator(_MotionValidator(si, checker, k))
            ss.setStateValidityChecker(is_valid)
            self._is_valid = is_valid
            ss.setStartState(self._state(space, x_start))
            if len(goals) == 1:
                ss.setGoalState(self._state(space, goals[0]), 1e-9)
            else:
                goal_states = ob.GoalStates(si)
                for g in goals:
                    goal_states.addState(self._state(space, g))
                ss.setGoal(goal_states)
            planner = getattr(og, cls_name)(si)
            if projection is not None and hasattr(planner, "setProjectionEvaluator"):
                # a linear map of the group's variables (see _wedged_goal_projection)
                planner.setProjectionEvaluator(ob.RealVectorLinearProjectionEvaluator(space, projection))
            elif k > 2 and hasattr(planner, "setProjectionEvaluator"):
                # the KPIECE family and the other planners that grid a projection of the space:
                # the group's first two joints, as MoveIt's Panda configuration has it (for an
                # arm the ones that move the most; OMPL's default is a random linear projection)
                planner.setProjectionEvaluator(ob.RealVectorOrthogonalProjectionEvaluator(space, [0, 1]))
            # the short extension suits feasibility planners; asymptotically optimal ones keep
            # OMPL's default (their rewiring needs the long reach to find a first path in time)
            if planner_range > 0 and cls_name not in _OPTIMIZING and hasattr(planner, "setRange"):
                planner.setRange(planner_range)
            if goal_bias is not None:
                planner.setGoalBias(goal_bias)
            ss.setPlanner(planner)
            ss.setup()
        self._objects = (ss, planner, si, space)
        self._partial = None  # (space information, its motion validator) once solve(partial=True)

    def tree_sizes(self) -> tuple[int, int]:
        """Vertices of the start tree and of the goal tree so far (planners that tag them 1
        and 2 in their planner data, as RRTConnect does; no state is checked)."""
        _, planner, si, _ = self._objects
        with _quiet_ompl():
            data = ob.PlannerData(si)
            planner.getPlannerData(data)
            tags = [data.getVertex(i).getTag() for i in range(data.numVertices())]
        return tags.count(1), tags.count(2)

    def _state(self, space, x: np.ndarray):
        state = space.allocState()
        for i in self._k:
            state[i] = float(x[i])
        return state

    def release(self) -> None:
        with _quiet_ompl():
            self._objects = self._partial = None

    def _check_partial_motions(self) -> None:
        """Have the planner's motions checked by OMPL's own validator from now on (see
        :meth:`solve`). It is made on a space information of its own, on the planner's space
        and with its state validity checker, at the search's spacing (in the Euclidean norm, so
        no sparser than the batched checks); made only now, so the turns before draw the same
        random numbers as without it."""
        if self._partial is not None:
            return
        _, _, si, space = self._objects
        with _quiet_ompl():
            own = ob.SpaceInformation(space)
            own.setStateValidityChecker(self._is_valid)
            own.setStateValidityCheckingResolution(self.req.checker.coarse / space.getMaximumExtent())
            own.setup()
            self._partial = (own, own.getMotionValidator())
            si.setMotionValidator(self._partial[1])

    def solve(self, share, budget: int | None, partial: bool = False, halt: Callable[[], bool] | None = None):
        """Run (on): (path, message, cut); ``cut`` is True when the run stopped because it
        checked ``budget`` states (the caller goes on with another run) or ``halt()`` (asked
        between the planner's iterations) returned True, not because of the time.

        ``partial``: from now on motions are checked by OMPL's own validator, one state at a
        time from their start, so a blocked motion tells how far it is free. The KPIECE
        planners keep that part of it: a tree creeps along a narrow passage instead of losing
        every extension that does not get through whole. The batched checks (end first, then
        by bisection) find a blocked motion out with fewer checks, so they are the default.
        Ignored when the search checks its edges in full (``search_fine``), which only the
        batched validator does."""
        req, cls_name = self.req, self.cls_name
        if partial and not req.checker.search_fine:
            self._check_partial_motions()
        remaining = req.deadline - time.perf_counter()
        if share is not None:
            remaining = min(remaining, share)
        if remaining <= 0:
            return None, f"TIMED_OUT: no solution found in {req.deadline - req.t0:.3g} s ({cls_name})", False
        ss = self._objects[0]
        checker = req.checker
        rng_k = self._k
        cut = [False]
        with _quiet_ompl():
            try:
                if budget is None or cls_name in _THREADED:
                    status = ss.solve(remaining)
                else:
                    stop_at = time.perf_counter() + remaining
                    limit = checker.states_checked + budget

                    def stop() -> bool:
                        if checker.states_checked >= limit or (halt is not None and halt()):
                            cut[0] = True
                            return True
                        return time.perf_counter() >= stop_at

                    status = ss.solve(ob.PlannerTerminationCondition(stop))
            except _Overrun:
                log.warning("OMPL's %s went on checking states %.1f s past the request's deadline: stopped",
                            cls_name, OVERRUN_GRACE)
                return None, f"TIMED_OUT: no solution found in {req.deadline - req.t0:.3g} s ({cls_name})", False
            status_type = status.getStatus()
            path = None
            if ss.haveExactSolutionPath():
                p = ss.getSolutionPath()
                path = np.array([[p.getState(j)[i] for i in rng_k] for j in range(p.getStateCount())])
            status_text = status.asString()
        if path is not None and not self._joins_start_and_goal(path):
            # (AORRTC can report a path from a goal to itself as an exact solution)
            return None, f"PLANNING_FAILED: {cls_name} returned a path that does not run from the start to a goal", False
        if path is not None:
            # OMPL's path must start and end exactly at our states; every edge was validated
            # by the motion validator, checked again only if not (e.g. a planner's own edges);
            # edges OMPL's validator checked at its own states are left to the full check of
            # the result (see OMPLPipeline._finalize)
            if self._partial is None and not checker.path_ok(path):
                return None, f"PLANNING_FAILED: {cls_name} returned a path that fails validation", False
            return (path[::-1].copy() if self._from_goal else path), "", False
        timed_out = f"TIMED_OUT: no solution found in {req.deadline - req.t0:.3g} s ({cls_name})"
        if time.perf_counter() >= req.deadline:
            return None, timed_out, False
        if cut[0]:
            return None, "", True
        if status_type == ob.PlannerStatus.TIMEOUT:
            return None, timed_out, False
        return None, f"PLANNING_FAILED: {cls_name}: {status_text}", False


    def _joins_start_and_goal(self, path: np.ndarray) -> bool:
        """Whether ``path`` starts at the start and ends at one of the goals (to OMPL's 1e-9)."""
        if len(path) == 0 or np.abs(path[0] - self._start).max(initial=0.0) > _ENDS_TOLERANCE:
            return False
        return bool((np.abs(self._goals - path[-1]).max(axis=1, initial=0.0) <= _ENDS_TOLERANCE).any())


class _TurnSearch:
    """RRTConnect and :data:`FALLBACK_PLANNER` in turns on one request (see
    :meth:`OMPLPipeline._run_ompl`); a search for :func:`mtc.planners._race.race`.

    RRTConnect runs until it has checked :data:`FALLBACK_CHECKS` states, then the fallback
    (lazy: it grows its trees unchecked, favouring the least explored cells of a projection,
    and checks only the edges of a path that joins start and goal) gets :data:`FALLBACK_SHARE`
    times as many, then RRTConnect again with four times its first budget, and so on. Both go
    on with their trees from turn to turn; from :data:`FALLBACK_PARTIAL_TURN` on, the fallback
    keeps the free part of its blocked motions, and where the goal is wedged it projects onto
    the tip's position there (:func:`_wedged_goal_projection`). Where RRTConnect's first turn
    left the goal in a trap (its tree there stayed small, :data:`TRAPPED_RATIO`), the fallback
    is :data:`TRAPPED_PLANNER` grown from the goal towards the start instead (its path is
    turned round).

    ``max_checks``: the search ends (without a path) after that many state checks.

    Each planner is made (:class:`_OMPLRun`, which seeds OMPL's generator) right before its
    first turn, where OMPL draws its samplers' seeds; later turns draw none. So what a search
    draws does not depend on other searches run in between: a race in turns draws as a race
    side by side.
    """

    def __init__(self, req: _Request, x_start: np.ndarray, goals: list[np.ndarray], cls_name: str, seed: int,
                 planner_range: float, share=None, max_checks: int | None = None):
        self.req = req
        self._goals = goals
        self._x_start = x_start
        self._range = planner_range
        self._share = share
        self._start_checks = req.checker.states_checked
        self._max_checks = max_checks
        self._limit = None if max_checks is None else self._start_checks + max_checks
        self._seed = seed
        self._runs: list[_OMPLRun] = []
        self._cls_name = cls_name
        self.turn = 0

    @property
    def checks(self) -> int:
        """State checks made by this search so far."""
        return self.req.checker.states_checked - self._start_checks

    def step(self, halt: Callable[[], bool] | None = None):
        """Run the next turn: None when it used up its budget (or ``halt()`` stopped it), else
        (path or None, message, name of the planner that ended the search)."""
        req, turn, cls_name = self.req, self.turn, self._cls_name
        checker = req.checker
        # RRTConnect: B, 4B, 16B, ...; the fallback: S B, 4 S B, ... (B = FALLBACK_CHECKS)
        budget = FALLBACK_CHECKS * 4 ** (turn // 2) * (FALLBACK_SHARE if turn % 2 else 1)
        if self._limit is not None:
            if checker.states_checked >= self._limit:
                return None, _out_of_checks(self._max_checks, f"{cls_name}, {self._fallback_name()}"), cls_name
            budget = min(budget, self._limit - checker.states_checked)
        if turn == 0:
            self._runs.append(_OMPLRun(req, self._x_start, self._goals, cls_name, self._seed, self._range))
        elif turn == 1:
            self._runs.append(self._fallback_run())
        run = self._runs[turn % 2]
        name = run.cls_name
        partial = turn % 2 == 1 and turn // 2 >= FALLBACK_PARTIAL_TURN
        path, message, cut = run.solve(self._share, budget, partial, halt)
        if not cut:
            if turn > 0 and message:
                message = message.replace(f"({name})", f"({cls_name}, {self._fallback_name()})")
            return path, message, name
        self.turn += 1
        if halt is None or not halt():
            log.debug("%s: no path after %d state checks, trying %s", name, budget,
                      self._fallback_name() if name == cls_name else cls_name)
        return None

    def _fallback_name(self) -> str:
        return self._runs[1].cls_name if len(self._runs) > 1 else FALLBACK_PLANNER

    def _fallback_run(self) -> _OMPLRun:
        """The planner of the fallback's turns: :data:`FALLBACK_PLANNER` from both ends, or
        where RRTConnect's first turn left the goal in a trap (see :data:`TRAPPED_RATIO`)
        :data:`TRAPPED_PLANNER` growing one tree from the goal towards the start."""
        req, seed = self.req, self._seed + 104729
        n_start, n_goal = self._runs[0].tree_sizes()
        if len(self._goals) == 1 and n_start >= max(TRAPPED_MIN_START, n_goal * TRAPPED_RATIO):
            return _OMPLRun(req, self._x_start, self._goals, TRAPPED_PLANNER, seed, self._range,
                            goal_bias=TRAPPED_GOAL_BIAS, from_goal=True)
        return _OMPLRun(req, self._x_start, self._goals, FALLBACK_PLANNER, seed, self._range,
                        _wedged_goal_projection(req, self._goals[0]))

    def release(self) -> None:
        for run in self._runs:
            run.release()


# ---------------------------------------------------------------------------------------------
# Projection-based bidirectional RRT for position/orientation path constraints


#: Step of the constrained planner along the manifold [rad, largest joint change].
CONSTRAINED_STEP = 0.1


class _Tree:
    """Vertices (rows of a growing array) and parent indices of one search tree."""

    def __init__(self, roots: list[np.ndarray]):
        k = len(roots[0])
        self._x = np.empty((max(64, 2 * len(roots)), k))
        self.parent: list[int] = []
        self.n = 0
        for r in roots:
            self.add(r, -1)

    def add(self, x: np.ndarray, parent: int) -> int:
        if self.n == len(self._x):
            self._x = np.concatenate([self._x, np.empty_like(self._x)])
        self._x[self.n] = x
        self.parent.append(parent)
        self.n += 1
        return self.n - 1

    def x(self, i: int) -> np.ndarray:
        return self._x[i]

    def nearest(self, x: np.ndarray) -> int:
        d = np.abs(self._x[: self.n] - x).max(axis=1)
        return int(np.argmin(d))

    def branch(self, i: int) -> list[np.ndarray]:
        """Vertices from ``i`` up to its root."""
        out = []
        while i >= 0:
            out.append(self._x[i].copy())
            i = self.parent[i]
        return out


def _constrained_rrt_connect(req: _Request, x_start, goals, rng: np.random.Generator, resolution: float,
                             max_checks: int | None = None):
    """CBiRRT (Berenson et al. 2009): a start tree and a goal tree grown towards random states
    and towards each other in steps of :data:`CONSTRAINED_STEP`, each new state projected onto
    the path constraints (:meth:`ConstraintEvaluator.project`) and checked, with its edge from
    the previous state, by the edge checker. Returns (path, "") or (None, message); gives up
    after ``max_checks`` state checks where given."""
    checker, evaluator = req.checker, req.evaluator
    limit = math.inf if max_checks is None else checker.states_checked + max_checks
    idx = req.group.variable_indices
    lower, upper = req.lower, req.upper
    base = req.base

    def project(x: np.ndarray) -> np.ndarray | None:
        q = base.copy()
        q[idx] = x
        out = evaluator.project(q, idx, lower, upper)
        return None if out is None else out[idx]

    def extend(tree: _Tree, i: int, target: np.ndarray, connect: bool) -> tuple[int, bool]:
        """Grow ``tree`` from vertex ``i`` towards ``target``: (last vertex, reached)."""
        current = tree.x(i).copy()
        while time.perf_counter() < req.deadline:
            gap = target - current
            dist = float(np.max(np.abs(gap)))
            if dist <= CONSTRAINED_STEP:
                if checker.edge_ok(current, target):
                    return tree.add(target.copy(), i), True
                return i, False
            proposal = project(current + gap * (CONSTRAINED_STEP / dist))
            if proposal is None:
                return i, False
            # stop when the projection does not bring us closer (stuck on the manifold)
            if float(np.max(np.abs(target - proposal))) >= dist - 1e-6:
                return i, False
            if not checker.edge_ok(current, proposal):
                return i, False
            i = tree.add(proposal, i)
            current = proposal
            if not connect:
                return i, False
        return i, False

    trees = (_Tree([x_start]), _Tree(goals))
    a, b = 0, 1
    while time.perf_counter() < req.deadline:
        if checker.states_checked >= limit:
            return None, _out_of_checks(max_checks, "constrained RRT-Connect")
        sample = project(rng.uniform(lower, upper))
        if sample is None:
            continue
        ta, tb = trees[a], trees[b]
        new, _ = extend(ta, ta.nearest(sample), sample, connect=False)
        if new >= 0 and new >= (1 if a == 0 else len(goals)):
            x_new = ta.x(new).copy()
            j, reached = extend(tb, tb.nearest(x_new), x_new, connect=True)
            if reached:
                # the branch in ta ends at x_new; the branch in tb ends at its copy of x_new
                left, right = ta.branch(new), tb.branch(j)
                start_side, goal_side = (left, right) if a == 0 else (right, left)
                path = start_side[::-1] + goal_side[1:]
                return np.asarray(path), ""
        a, b = b, a
    return None, f"TIMED_OUT: no solution found in {req.deadline - req.t0:.3g} s (constrained RRT-Connect)"
