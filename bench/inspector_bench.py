"""Inspector data benchmark: save and load the introspection of a task with many solutions.

The task (toy robot of MTC's tests): a generator of S + F states, then a propagator that
moves the robot along a short time-parameterized trajectory (W waypoints) from each state;
S of its solutions succeed and F fail with a comment (failures keep their trajectory, as
MTC's stages store them for display). Every solution ends in its own scene.

Target (issue 6): with 1,000 solutions and 5,000 failures, ``task.introspection().save(path)``
(snapshot + JSON file) and ``mtc.Introspection.load(path)`` each under 1 s.

Usage: python bench/inspector_bench.py [--solutions S] [--failures F] [--waypoints W]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import mtc  # noqa: E402
from mtc import core  # noqa: E402
from mockups import GeneratorMockup, toy_model  # noqa: E402


class TrajectoryPropagator(core.PropagatingForward):
    """Moves every incoming state along a short trajectory; every ``period``-th one succeeds."""

    def __init__(self, period: int, waypoints: int):
        super().__init__("move")
        self.period = period
        self.waypoints = waypoints
        self.count = 0

    def computeForward(self, from_state):
        model = from_state.scene.robot_model
        scene = from_state.scene.diff()
        start = scene.current_state.get_joint_group_positions("group")
        goal = start + 0.001 * (self.count + 1)
        path = np.linspace(start, goal, self.waypoints)
        times = np.linspace(0.0, 1.0, self.waypoints)
        traj = mtc.RobotTrajectory.from_positions(model, "group", scene.current_state, path, times)
        traj.velocities = np.tile((goal - start) / times[-1], (self.waypoints, 1))
        scene.current_state.set_joint_group_positions("group", goal)
        solution = core.SubTrajectory(traj, cost=float(self.count % 17))
        if self.count % self.period:
            solution.markAsFailure(f"state {self.count}: path in collision at waypoint {self.count % self.waypoints}")
        self.count += 1
        self.sendForward(from_state, core.InterfaceState(scene), solution)


def run(solutions: int = 1000, failures: int = 5000, waypoints: int = 10, repeat: int = 3) -> dict:
    """Plan the task, then time save and load; return the figures."""
    if failures % solutions:
        raise ValueError("failures must be a multiple of solutions (every k-th propagation succeeds)")
    task = core.Task()
    task.setRobotModel(toy_model())
    task.add(GeneratorMockup([float(i % 7) for i in range(solutions + failures)]))
    task.add(TrajectoryPropagator(period=failures // solutions + 1, waypoints=waypoints))
    start = time.perf_counter()
    assert task.plan()
    plan_s = time.perf_counter() - start
    assert task.numSolutions() == solutions, task.numSolutions()
    assert task["move"].numFailures() == failures

    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "task.json")
        # best of a few runs: other processes on a shared machine inflate single timings
        save_s = save_cpu = load_s = load_cpu = float("inf")
        for _ in range(repeat):
            wall, cpu = time.perf_counter(), time.process_time()
            task.introspection().save(path)
            save_s = min(save_s, time.perf_counter() - wall)
            save_cpu = min(save_cpu, time.process_time() - cpu)
            size = os.path.getsize(path)
            wall, cpu = time.perf_counter(), time.process_time()
            loaded = mtc.Introspection.load(path)
            load_s = min(load_s, time.perf_counter() - wall)
            load_cpu = min(load_cpu, time.process_time() - cpu)
    data = loaded.data
    stored = len(data.solutions)
    return {
        "solutions": solutions,
        "failures": failures,
        "waypoints": waypoints,
        "stored_solution_entries": stored,
        "scenes": len(data.scenes),
        "environments": len(data.environments),
        "plan_s": plan_s,
        "save_s": save_s,
        "save_cpu_s": save_cpu,
        "load_s": load_s,
        "load_cpu_s": load_cpu,
        "file_mb": size / 1e6,
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--solutions", type=int, default=1000)
    parser.add_argument("--failures", type=int, default=5000)
    parser.add_argument("--waypoints", type=int, default=10)
    parser.add_argument("--repeat", type=int, default=3, help="best of this many save/load runs")
    args = parser.parse_args(argv)
    r = run(args.solutions, args.failures, args.waypoints, args.repeat)
    for key, value in r.items():
        print(f"{key:>24}: {value:.3f}" if isinstance(value, float) else f"{key:>24}: {value}")
    ok = r["save_s"] < 1.0 and r["load_s"] < 1.0
    print("target (save and load under 1 s each, wall time):", "met" if ok else "MISSED")
    if hasattr(os, "getloadavg"):
        print(f"{'load average':>24}: {os.getloadavg()[0]:.2f} (on {os.cpu_count()} cores)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
