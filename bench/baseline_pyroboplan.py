"""Baseline planner for the benchmark: pyroboplan's RRT on the Panda of example-robot-data.

pyroboplan (``pip install --no-deps pyroboplan``: its pinned ``pin==4.0.0`` would downgrade
Pinocchio, and only the RRT's plain numpy/pinocchio/meshcat imports are needed) plans on a
Pinocchio model with a coal collision model. Here that model is example-robot-data's Panda with
both finger joints locked (the problems keep the fingers fixed), so the planner samples the
seven arm joints only.

Collision pairs follow MoveIt's setup for these problems: every robot link against every
obstacle, and robot self-collision for all link pairs except the ones the Panda SRDF disables
and the ones the problem's allowed collision matrix allows.

pyroboplan's default flow (``RRTPlanner.plan``) returns the raw tree path; it does not shorten
it (its Panda example keeps ``shortcut_path`` switched off), so neither does this baseline unless
``shortcut=True``.

Run ``python bench/baseline_pyroboplan.py --first 10 --timeout 10`` for a table per family.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import io
import logging
import statistics
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

import numpy as np

if __package__ in (None, ""):
    # Run as a script: make the repository root importable so `bench.problems` resolves.
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import coal
import pinocchio as pin

from bench.problems import (
    ARM_JOINTS,
    FINGER_JOINTS,
    Obstacle,
    Problem,
    example_robot_data_share,
    families,
    invalid_status,
    is_planned,
    limit_violations,
    load_family,
    panda_joint_limits,
    panda_srdf_path,
    panda_urdf_path,
    table_shelf_problems,
    table_shelf_world,
)

log = logging.getLogger(__name__)

# The prefix keeps obstacle names apart from the robot's geometry names (panda_link0_0, ...).
_OBSTACLE_PREFIX = "obstacle:"

# Planner settings for the Panda. The collision-check resolution (0.05 rad between checked
# states along an edge) is the one of pyroboplan's own Panda example; the extension step bounds
# how far one RRT extension reaches [rad, Euclidean in joint space].
DEFAULT_STEP_SIZE = 0.05
DEFAULT_CONNECTION_DIST = 1.0
DEFAULT_GOAL_BIAS = 0.15


def _import_rrt():
    """pyroboplan's RRT, or an ImportError that says how to install it."""
    try:
        from pyroboplan.planning.rrt import RRTPlanner, RRTPlannerOptions
    except ImportError as exc:  # bench-only extra, not an mtc dependency
        raise ImportError(
            "the pyroboplan baseline needs pyroboplan: 'pip install --no-deps pyroboplan' "
            "(--no-deps: it pins pin==4.0.0 and drake, which the RRT does not use)"
        ) from exc
    return RRTPlanner, RRTPlannerOptions


def _finger_value(problem: Problem | None, finger: float | None) -> float:
    """Opening of each finger [m]: the given value, else the start state's, clamped to the URDF limits.

    The MotionBenchMaker starts say 0.065 m, beyond example-robot-data's 0.04 m limit, so they
    are clamped to the widest opening this Panda has.
    """
    limits = panda_joint_limits()
    lo, hi = limits[FINGER_JOINTS[0]]
    if finger is None:
        finger = problem.start.get(FINGER_JOINTS[0], hi) if problem is not None else hi
    return float(min(max(finger, lo), hi))


@functools.lru_cache(maxsize=4)
def _arm_models(finger: float) -> tuple[pin.Model, pin.GeometryModel]:
    """The Panda with its fingers locked at ``finger`` [m]: a 7-joint model and its collision model."""
    urdf = str(panda_urdf_path())
    full = pin.buildModelFromUrdf(urdf)
    geom = pin.buildGeomFromUrdf(
        full, urdf, pin.GeometryType.COLLISION, package_dirs=[str(example_robot_data_share())]
    )
    q_ref = pin.neutral(full)
    locked = [full.getJointId(name) for name in FINGER_JOINTS]
    for jid in locked:
        q_ref[full.idx_qs[jid]] = finger
    model, (geom,) = pin.buildReducedModel(full, [geom], locked, q_ref)
    names = [model.names[i] for i in range(1, model.njoints)]
    if names != list(ARM_JOINTS):
        raise RuntimeError(f"reduced Panda model has joints {names}, expected {list(ARM_JOINTS)}")
    return model, geom


def _coal_shape(obstacle: Obstacle) -> coal.CollisionGeometry:
    if obstacle.kind == "box":
        return coal.Box(*obstacle.dims)  # full extents, as coal's Box takes them
    if obstacle.kind in ("cylinder", "cone"):
        height, radius = obstacle.dims
        shape = coal.Cylinder if obstacle.kind == "cylinder" else coal.Cone
        return shape(radius, height)  # coal takes (radius, full length along z)
    if obstacle.kind == "mesh":
        mesh = coal.BVHModelOBBRSS()
        mesh.beginModel(len(obstacle.triangles), len(obstacle.vertices))
        mesh.addVertices(obstacle.vertices)
        mesh.addTriangles(obstacle.triangles)
        mesh.endModel()
        return mesh
    return coal.Sphere(obstacle.dims[0])


def build_collision_model(
    obstacles: Iterable[Obstacle],
    finger: float = 0.04,
    allowed_collisions: Iterable[tuple[str, str]] = (),
) -> tuple[pin.Model, pin.GeometryModel]:
    """The arm model and a collision model with the obstacles and active pairs set up.

    Args:
        obstacles: World shapes, fixed to the universe.
        finger: Finger opening [m] at which the fingers are locked.
        allowed_collisions: Extra link pairs never checked (a scene's allowed collision matrix).

    Returns:
        ``(model, collision_model)`` as pyroboplan's planners take them.
    """
    from pyroboplan.core.utils import set_collisions

    model, robot_geom = _arm_models(finger)
    geom = robot_geom.copy()
    robot_links = sorted({model.frames[g.parentFrame].name for g in geom.geometryObjects})

    # Self-collision: all pairs on different joints, minus the SRDF's disabled pairs (as
    # pyroboplan's own Panda setup does), added before the obstacles so they stay robot-only.
    geom.addAllCollisionPairs()
    pin.removeCollisionPairs(model, geom, str(panda_srdf_path()))

    obstacle_names = []
    for obstacle in obstacles:
        name = _OBSTACLE_PREFIX + obstacle.name
        placement = pin.SE3(obstacle.pose[:3, :3], obstacle.pose[:3, 3])
        geom.addGeometryObject(pin.GeometryObject(name, 0, 0, placement, _coal_shape(obstacle)))
        obstacle_names.append(name)
    for name in obstacle_names:
        for link in robot_links:
            set_collisions(model, geom, name, link, True)

    # The scene's allowed collision matrix switches pairs off, as MoveIt's would.
    for a, b in allowed_collisions:
        if a in robot_links and b in robot_links:
            set_collisions(model, geom, a, b, False)
    return model, geom


def validity_checker(
    obstacles: Iterable[Obstacle],
    finger: float = 0.04,
    allowed_collisions: Iterable[tuple[str, str]] = (),
) -> Callable[[np.ndarray], bool]:
    """``is_valid(q7) -> bool`` with the baseline's collision model (for ``table_shelf_problems``)."""
    from pyroboplan.core.utils import check_collisions_at_state

    model, geom = build_collision_model(obstacles, finger, allowed_collisions)
    data, geom_data = model.createData(), geom.createData()

    def is_valid(q7: np.ndarray) -> bool:
        return not check_collisions_at_state(model, geom, np.asarray(q7, dtype=float), data, geom_data)

    return is_valid


def path_length(path: Sequence[np.ndarray]) -> float:
    """Joint-space length of a waypoint path: the sum of ``|q[i+1] - q[i]|`` [rad]."""
    return float(sum(np.linalg.norm(np.asarray(b) - np.asarray(a)) for a, b in zip(path[:-1], path[1:])))


def plan_pyroboplan(
    problem: Problem,
    timeout: float = 10.0,
    seed: int = 0,
    *,
    step_size: float = DEFAULT_STEP_SIZE,
    connection_dist: float = DEFAULT_CONNECTION_DIST,
    goal_bias: float = DEFAULT_GOAL_BIAS,
    shortcut: bool = False,
    finger: float | None = None,
) -> dict:
    """Plan one problem with pyroboplan's bidirectional RRT-Connect.

    Args:
        problem: The problem; its obstacles, start, goal and allowed collisions are used.
        timeout: pyroboplan's ``max_planning_time`` [s]. It is checked once per iteration, so
            a run can overshoot by one extension.
        seed: pyroboplan's ``rng_seed`` (it seeds numpy's global generator).
        step_size: Collision-check resolution along edges [rad].
        connection_dist: Longest single extension, and longest edge tried to join the trees [rad].
        goal_bias: Probability of sampling the other tree's root.
        shortcut: Run pyroboplan's ``shortcut_path`` after a success (not in its default flow);
            its time is included in ``time_s``.
        finger: Finger opening [m]; the start state's (clamped to the URDF limit) when None.

    Returns:
        ``success`` (bool), ``time_s`` (planning time [s], ``time.perf_counter``),
        ``path_length`` (joint-space length [rad], NaN on failure), ``n_waypoints`` (0 on
        failure), ``status`` (``"solved"``, ``"timeout"``, ``"start in collision"``, ``"goal in
        collision"``, ``"invalid: ..."`` for states outside the joint limits, which are not
        planned), ``setup_s`` (model building [s]) and ``path`` (list of 7-vectors).
    """
    RRTPlanner, RRTPlannerOptions = _import_rrt()
    result = {
        "problem": problem.name,
        "success": False,
        "time_s": 0.0,
        "path_length": float("nan"),
        "n_waypoints": 0,
        "status": "",
        "setup_s": 0.0,
        "path": [],
    }
    violations = limit_violations(problem)
    if violations:
        result["status"] = invalid_status(violations)
        return result

    t0 = time.perf_counter()
    model, geom = build_collision_model(
        problem.obstacles, _finger_value(problem, finger), problem.allowed_collisions
    )
    options = RRTPlannerOptions(
        max_step_size=step_size,
        max_connection_dist=connection_dist,
        rrt_connect=True,
        bidirectional_rrt=True,
        rrt_star=False,
        max_planning_time=timeout,
        rng_seed=seed,
        fast_return=True,
        goal_biasing_probability=goal_bias,
        collision_distance_padding=0.0,
    )
    planner = RRTPlanner(model, geom, options=options)
    q_start, q_goal = problem.start_arm(), problem.goal_arm()
    result["setup_s"] = time.perf_counter() - t0

    chatter = io.StringIO()  # pyroboplan prints its outcome; keep it for the status instead
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(chatter):
        path = planner.plan(q_start, q_goal)
        if path and shortcut:
            from pyroboplan.planning.path_shortcutting import shortcut_path

            path = shortcut_path(model, geom, path, max_step_size=step_size)
    result["time_s"] = time.perf_counter() - t0

    said = chatter.getvalue()
    if path:
        if not (np.allclose(path[0], q_start) and np.allclose(path[-1], q_goal)):
            raise RuntimeError(f"{problem.name}: pyroboplan's path does not join start and goal")
        result.update(
            success=True,
            status="solved",
            path_length=path_length(path),
            n_waypoints=len(path),
            path=[np.asarray(q) for q in path],
        )
    elif "Start configuration in collision" in said:
        result["status"] = "start in collision"
    elif "Goal configuration in collision" in said:
        result["status"] = "goal in collision"
    else:
        result["status"] = "timeout"
    log.debug("%s: %s", problem.name, said.strip())
    return result


def summarize(results: Sequence[dict]) -> dict:
    """Success rate over plannable problems, median time and length of the successes."""
    planned = [r for r in results if is_planned(r)]
    solved = [r for r in planned if r["success"]]
    return {
        "n": len(results),
        "invalid": len(results) - len(planned),
        "solved": len(solved),
        "success_rate": len(solved) / len(planned) if planned else float("nan"),
        "median_time_s": statistics.median(r["time_s"] for r in solved) if solved else float("nan"),
        "median_length": statistics.median(r["path_length"] for r in solved) if solved else float("nan"),
        "collision": sum(1 for r in planned if "collision" in r["status"]),
    }


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--families", nargs="*", default=None,
                        help="MotionBenchMaker families (default: every family folder under the problem root)")
    parser.add_argument("--first", type=int, default=10, help="problems per family")
    parser.add_argument("--timeout", type=float, default=10.0, help="planning time per problem [s]")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--connection-dist", type=float, default=DEFAULT_CONNECTION_DIST)
    parser.add_argument("--shortcut", action="store_true", help="add pyroboplan's path shortcutting")
    parser.add_argument("--table-shelf", type=int, default=0, help="also run N table-shelf problems")
    parser.add_argument("-v", "--verbose", action="store_true", help="one line per problem")
    args = parser.parse_args(argv)

    suites: list[tuple[str, list[Problem]]] = [
        (f, load_family(f, keep_unreadable=True)[: args.first])
        for f in (families() if args.families is None else args.families)
    ]
    if args.table_shelf:
        is_valid = validity_checker(table_shelf_world())
        suites.append(("table_shelf", table_shelf_problems(args.table_shelf, args.seed, is_valid=is_valid)))

    print(f"pyroboplan RRT-Connect (bidirectional), timeout {args.timeout:g} s, seed {args.seed}, "
          f"connection {args.connection_dist:g} rad, shortcut {args.shortcut}")
    print(f"{'family':<16}{'n':>4}{'invalid':>8}{'solved':>8}{'rate':>7}{'med t [s]':>11}"
          f"{'med len':>9}{'in coll':>8}")
    for family, problems in suites:
        results = []
        for p in problems:
            r = plan_pyroboplan(p, args.timeout, args.seed, connection_dist=args.connection_dist,
                                shortcut=args.shortcut)
            results.append(r)
            if args.verbose:
                print(f"  {p.name:<22}{r['status']:<24}{r['time_s']:8.3f} s {r['path_length']:7.2f} rad"
                      f" {r['n_waypoints']:4d} wp", flush=True)
        s = summarize(results)
        print(f"{family:<16}{s['n']:>4}{s['invalid']:>8}{s['solved']:>8}{s['success_rate']:>7.0%}"
              f"{s['median_time_s']:>11.3f}{s['median_length']:>9.2f}{s['collision']:>8}", flush=True)


if __name__ == "__main__":
    main()
