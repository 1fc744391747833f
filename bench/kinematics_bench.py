"""Kinematics benchmark: inverse kinematics, time parameterization and Cartesian paths on the Panda.

Measures:
* IK (:func:`bench_ik`): targets are the ``panda_link8`` poses of random collision-free arm
  states (so every target is reachable); each is solved from the ``ready`` state (what
  ``ComputeIK`` starts from) and, separately, from a random state, with the group's default
  time budget. Success rate and solve times [ms].
* Time parameterization (:func:`bench_time_parameterization`): curved 50-waypoint joint paths
  timed by TOTG under the Panda's limits; times [ms] and the largest ratio of a waypoint's
  velocity or acceleration to its (scaled) limit (must not exceed 1).
* Cartesian paths (:func:`bench_cartesian_path`): 15 cm straight lines in random directions
  from random collision-free states well inside the workspace (joints 0.2 rad from their
  bounds, Jacobian's smallest singular value >= 0.05); achieved fraction and planning time [ms].
  A line may still legitimately stop (workspace boundary, joint limit, singularity on the way).

``bench/motion_bench.py`` imports these functions and includes their results.

Times are wall-clock (``*_ms``) and this process's CPU time (``median_cpu_ms``), which other
processes on a busy machine do not inflate.

Run: ``python bench/kinematics_bench.py [--ik N] [--totg N] [--cartesian N] [--seed S]``
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import mtc
from mtc.planners import CartesianPath, ik
from mtc.planners.time_parameterization import time_parameterize
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_state import RobotState
from mtc.scene.robot_trajectory import RobotTrajectory

GROUP = "panda_arm"
TIP = "panda_link8"


def _valid_random_states(model, n: int, rng: np.random.Generator) -> list[RobotState]:
    """``n`` random arm states (hand open) that do not collide with the robot itself."""
    scene = PlanningScene(model)
    scene.current_state.set_to_default_values("hand", "open")
    valid = scene.state_validity_checker(GROUP)
    states = []
    while len(states) < n:
        state = scene.current_state.copy()
        state.set_to_random_positions(GROUP, rng)
        if valid(state.positions):
            states.append(state)
    return states


def _dexterous_states(model, n: int, rng: np.random.Generator, margin: float = 0.2,
                      min_singular_value: float = 0.05) -> list[RobotState]:
    """Valid random states well inside the workspace: every joint at least ``margin`` [rad] from
    its bounds and the Jacobian's smallest singular value at least ``min_singular_value``
    (straight lines from near-singular or joint-limit states legitimately stop after a few mm)."""
    lo = model.lower_bounds[:7] + margin
    hi = model.upper_bounds[:7] - margin
    states = []
    while len(states) < n:
        for state in _valid_random_states(model, n, rng):
            q = state.positions[:7]
            if np.any(q < lo) or np.any(q > hi):
                continue
            if np.linalg.svd(state.get_jacobian(GROUP, TIP), compute_uv=False).min() < min_singular_value:
                continue
            states.append(state)
            if len(states) == n:
                break
    return states


def _ready(model) -> RobotState:
    state = RobotState(model)
    state.set_to_default_values(GROUP, "ready")
    state.set_to_default_values("hand", "open")
    return state


class _Clock:
    """Wall-clock and CPU time of a block (CPU time: this process only, so other processes on
    a busy machine do not count)."""

    def __init__(self):
        self.wall: list[float] = []
        self.cpu: list[float] = []

    def __enter__(self):
        self._w, self._c = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc):
        self.wall.append(time.perf_counter() - self._w)
        self.cpu.append(time.process_time() - self._c)

    def stats(self) -> dict:
        wall = np.asarray(self.wall) * 1e3
        cpu = np.asarray(self.cpu) * 1e3
        return {
            "median_ms": float(np.median(wall)),
            "p90_ms": float(np.percentile(wall, 90)),
            "max_ms": float(wall.max()),
            "median_cpu_ms": float(np.median(cpu)),
        }


def bench_ik(n: int = 500, seed: int = 0) -> dict:
    """IK success and speed on reachable poses (FK of random valid states).

    Returns:
        ``{"n", "from_ready": {"success_rate", "median_ms", "p90_ms", "max_ms", "median_cpu_ms"},
        "from_random": {...}, "max_position_error_m", "max_rotation_error_rad"}``.
    """
    model = mtc.robots.panda()
    rng = np.random.default_rng(seed)
    goals = _valid_random_states(model, n, rng)
    targets = [g.get_global_link_transform(TIP) for g in goals]
    random_seeds = _valid_random_states(model, n, rng)
    out: dict = {"n": n}
    worst_p, worst_r = 0.0, 0.0
    for label, seeds in (("from_ready", [_ready(model)] * n), ("from_random", random_seeds)):
        ok, clock = 0, _Clock()
        for i, (target, seed_state) in enumerate(zip(targets, seeds)):
            with clock:
                solutions = ik.solve_ik(seed_state, GROUP, target, tip=TIP, rng=seed * 100003 + i)
            if solutions:
                ok += 1
                reached = solutions[0].get_global_link_transform(TIP)
                worst_p = max(worst_p, float(np.linalg.norm(reached[:3, 3] - target[:3, 3])))
                c = (np.trace(reached[:3, :3].T @ target[:3, :3]) - 1) / 2
                worst_r = max(worst_r, float(np.arccos(np.clip(c, -1, 1))))
        out[label] = {"success_rate": ok / n, **clock.stats()}
    out["max_position_error_m"] = worst_p
    out["max_rotation_error_rad"] = worst_r
    return out


def _curved_path(model, rng, waypoints: int) -> RobotTrajectory:
    qs = []
    for _ in range(3):
        s = RobotState(model)
        s.set_to_random_positions(GROUP, rng)
        qs.append(s.get_joint_group_positions(GROUP))
    t = np.linspace(0, 1, waypoints)[:, None]
    P = (1 - t) ** 2 * qs[0] + 2 * t * (1 - t) * qs[1] + t**2 * qs[2]
    return RobotTrajectory.from_positions(model, GROUP, _ready(model), P)


def bench_time_parameterization(n: int = 200, waypoints: int = 50, seed: int = 0,
                                velocity_scaling: float = 0.5, acceleration_scaling: float = 0.5) -> dict:
    """TOTG on curved paths of ``waypoints`` waypoints.

    Returns:
        ``{"n", "waypoints", "median_ms", "p90_ms", "max_ms", "median_cpu_ms", "max_velocity_ratio",
        "max_acceleration_ratio", "median_duration_s"}`` (ratios: largest |value| / scaled limit
        at any waypoint).
    """
    model = mtc.robots.panda()
    rng = np.random.default_rng(seed)
    idx = model.get_joint_model_group(GROUP).variable_indices
    vmax = model.velocity_limits[idx] * velocity_scaling
    amax = model.acceleration_limits[idx] * acceleration_scaling
    paths = [_curved_path(model, rng, waypoints) for _ in range(n)]
    time_parameterize(paths[0].copy(), velocity_scaling, acceleration_scaling)  # warm-up (imports, caches)
    clock, vr, ar, durations = _Clock(), 0.0, 0.0, []
    for traj in paths:
        with clock:
            time_parameterize(traj, velocity_scaling, acceleration_scaling)
        vr = max(vr, float(np.max(np.abs(traj.velocities) / vmax)))
        ar = max(ar, float(np.max(np.abs(traj.accelerations) / amax)))
        durations.append(traj.duration)
    return {
        "n": n,
        "waypoints": waypoints,
        **clock.stats(),
        "max_velocity_ratio": vr,
        "max_acceleration_ratio": ar,
        "median_duration_s": float(np.median(durations)),
    }


def bench_cartesian_path(n: int = 50, seed: int = 0, length: float = 0.15) -> dict:
    """Straight lines of ``length`` [m] in random directions from random dexterous valid states.

    Returns:
        ``{"n", "full_rate", "median_fraction", "median_ms", "p90_ms", "max_ms", "median_cpu_ms"}``.
    """
    model = mtc.robots.panda()
    rng = np.random.default_rng(seed)
    planner = CartesianPath()
    full, fractions, clock = 0, [], _Clock()
    for state in _dexterous_states(model, n, rng):
        scene = PlanningScene(model)
        scene.current_state = state
        direction = rng.normal(size=3)
        target = state.get_global_link_transform(TIP)
        target[:3, 3] += length * direction / np.linalg.norm(direction)
        with clock:
            result, traj = planner.plan_to_pose(scene, TIP, np.eye(4), target, GROUP, 5.0)
        fraction = float(result.message.rsplit(" ", 1)[1])
        fractions.append(fraction)
        full += fraction == 1.0
    return {"n": n, "full_rate": full / n, "median_fraction": float(np.median(fractions)), **clock.stats()}


def _row(name: str, d: dict, keys: list[str]) -> str:
    cells = []
    for k in keys:
        v = d.get(k, "")
        cells.append(f"{v:.3f}" if isinstance(v, float) else str(v))
    return f"| {name:<28} | " + " | ".join(f"{c:>9}" for c in cells) + " |"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ik", type=int, default=500, help="IK targets")
    parser.add_argument("--totg", type=int, default=200, help="paths to time")
    parser.add_argument("--cartesian", type=int, default=50, help="Cartesian lines")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    ik_result = bench_ik(args.ik, args.seed)
    tp = bench_time_parameterization(args.totg, seed=args.seed)
    cp = bench_cartesian_path(args.cartesian, seed=args.seed)
    keys = ["success_rate", "median_ms", "median_cpu_ms", "p90_ms", "max_ms"]
    print(f"| {'IK (panda_arm, panda_link8)':<28} | " + " | ".join(f"{k:>9}" for k in keys) + " |")
    print(_row(f"from ready (n={args.ik})", ik_result["from_ready"], keys))
    print(_row(f"from random (n={args.ik})", ik_result["from_random"], keys))
    print(f"largest pose error of a solution: {ik_result['max_position_error_m']:.2e} m, "
          f"{ik_result['max_rotation_error_rad']:.2e} rad")
    print()
    keys = ["median_ms", "median_cpu_ms", "p90_ms", "max_ms", "max_velocity_ratio", "max_acceleration_ratio"]
    print(f"| {'TOTG (50 waypoints, 0.5/0.5)':<28} | " + " | ".join(f"{k:>9}" for k in keys) + " |")
    print(_row(f"n={args.totg}", tp, keys))
    print()
    keys = ["full_rate", "median_fraction", "median_ms", "median_cpu_ms", "p90_ms", "max_ms"]
    print(f"| {'CartesianPath (15 cm lines)':<28} | " + " | ".join(f"{k:>9}" for k in keys) + " |")
    print(_row(f"n={args.cartesian}", cp, keys))


if __name__ == "__main__":
    main()
