"""mtc: MoveIt Task Constructor in pure Python.

``from mtc import core, stages`` gives the task constructor (MTC's Python API);
``RobotModel``, ``RobotState``, ``PlanningScene`` and ``PlanningSceneInterface`` mirror
moveit_py and moveit_commander; ``mtc.msgs`` holds ROS-shaped messages.
Heavy modules load on first use, so ``import mtc`` stays cheap.
"""

from __future__ import annotations

import importlib

# No handler of our own (not even a NullHandler): until the application configures logging,
# Python's last-resort handler prints mtc's warnings and errors to stderr, as MoveIt's console
# shows its ROS_WARN/ROS_ERROR (a misspelled object to attach, a stale solution to execute).

__version__ = "0.1.0"

# public name -> module that defines it
_EXPORTS = {
    "RobotModel": "mtc.scene.robot_model",
    "RobotState": "mtc.scene.robot_state",
    "RobotTrajectory": "mtc.scene.robot_trajectory",
    "PlanningScene": "mtc.scene.planning_scene",
    "PlanningSceneInterface": "mtc.scene.current_scene",
    "current_scene": "mtc.scene.current_scene",
    "reset_current_scene": "mtc.scene.current_scene",
    "Introspection": "mtc.core.introspection",
}
_SUBMODULES = ("core", "stages", "msgs", "robots", "scene", "planners", "viewer", "rclcpp")

__all__ = sorted([*_EXPORTS, *_SUBMODULES, "roscpp_init"])


def roscpp_init(name: str = "", *args) -> None:
    """Accepted and ignored: ``mtc`` needs no ROS node (kept so MTC scripts run unchanged)."""


def __getattr__(name: str):
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name]), name)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        module = importlib.import_module(f"mtc.{name}")
        globals()[name] = module
        return module
    raise AttributeError(f"module 'mtc' has no attribute '{name}'")


def __dir__():
    return __all__
