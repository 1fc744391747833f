"""The solvers that fill in trajectories (MTC's ``solvers/``), re-exported by :mod:`mtc.core`.

* :class:`PlannerInterface` and :class:`PlannerResult`: the base of all planners.
* :class:`JointInterpolationPlanner`: a straight line in joint space.
* :class:`CartesianPath` with :class:`CartesianPrecision`: a straight line in Cartesian space.
* :class:`PipelinePlanner`: ``"ompl"`` (sampling-based planners) and
  ``"pilz_industrial_motion_planner"`` (PTP, LIN, CIRC).
* :class:`MultiPlanner`: several planners tried in turn.
* :mod:`mtc.planners.ik` (inverse kinematics) and :mod:`mtc.planners.time_parameterization`
  (:class:`TimeOptimalTrajectoryGeneration`).
"""

from __future__ import annotations

from mtc.planners.cartesian_path import CartesianPath, CartesianPrecision
from mtc.planners.joint_interpolation import JointInterpolationPlanner
from mtc.planners.multi_planner import MultiPlanner
from mtc.planners.pipeline_planner import KNOWN_PIPELINES, PipelinePlanner
from mtc.planners.planner_interface import PlannerInterface, PlannerResult
from mtc.planners.time_parameterization import (
    TimeOptimalTrajectoryGeneration,
    TimeParameterization,
    limit_cartesian_speed,
    time_parameterize,
)

__all__ = [
    "CartesianPath",
    "CartesianPrecision",
    "JointInterpolationPlanner",
    "KNOWN_PIPELINES",
    "MultiPlanner",
    "PipelinePlanner",
    "PlannerInterface",
    "PlannerResult",
    "TimeOptimalTrajectoryGeneration",
    "TimeParameterization",
    "limit_cartesian_speed",
    "time_parameterize",
]
