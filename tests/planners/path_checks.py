"""Dense re-checks of planned paths, shared by the planner tests."""

from __future__ import annotations

import math

import numpy as np

from mtc.scene.planning_scene import PlanningScene


def dense(positions: np.ndarray, step: float) -> np.ndarray:
    """The polyline through ``positions`` sampled at most ``step`` apart in every joint."""
    out = [positions[0]]
    for a, b in zip(positions[:-1], positions[1:]):
        n = max(1, math.ceil(np.max(np.abs(b - a)) / step))
        out.extend(a + (b - a) * (k / n) for k in range(1, n + 1))
    return np.asarray(out)


def free_along(scene: PlanningScene, traj, step: float = 1e-3) -> np.ndarray:
    """Whether each state of the straight lines between ``traj``'s waypoints (all variables),
    ``step`` apart in every joint, is collision-free in ``scene`` (every link, attached
    objects included)."""
    return scene.check_states(dense(np.array([traj[i].positions for i in range(len(traj))]), step))
