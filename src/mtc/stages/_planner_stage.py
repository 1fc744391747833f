"""What MoveTo and MoveRelative share: a propagator that plans with a planner for a group.

Both are MTC ``PropagatingEitherWay`` stages with the same planner handling, the properties
``timeout`` (default 1.0 s), ``group``, ``ik_frame`` and ``path_constraints``, and the
``PathLength`` cost term.
"""

from __future__ import annotations

from mtc import msgs
from mtc.core.cost_terms import PathLength
from mtc.core.properties import valid_message
from mtc.core.stage import InitStageError, PropagatingEitherWay
from mtc.core.storage import InterfaceState, SubTrajectory
from mtc.planners.planner_interface import PlannerResult, not_a_planner
from mtc.stages._common import ik_frame_from_args

__all__ = [
    "PlannerStage", "check_planner", "init_planner", "plan_to_ik_frame", "planner_message", "synthesized_trajectory",
]


def planner_message(result) -> str:
    """The message of a planner result (``PlannerResult.message``), "" if it has none."""
    return str(getattr(result, "message", "") or "")


def plan_to_ik_frame(planner, scene, ik, target, group: str, timeout: float, path_constraints):
    """``planner.plan_to_pose`` for a resolved IK frame (``mtc.scene.frames.IKFrame``); a
    failure message names the frame the user set, not the link the planners move with it
    (``'panda_hand_tcp'``, not ``'panda_link7'``)."""
    result, trajectory = planner.plan_to_pose(scene, ik.link, ik.offset, target, group, timeout, path_constraints)
    message = planner_message(result)
    if not result and ik.name and ik.name != ik.link:
        # the planners' "for '<link>'" / "of '<link>'" / "link '<link>' is not moved" (not, say,
        # a constraint "on '<link>'")
        for word in ("for", "of", "link"):
            message = message.replace(f"{word} '{ik.link}'", f"{word} '{ik.name}'")
        if message != planner_message(result):
            result = PlannerResult(False, message)
    return result, trajectory


def synthesized_trajectory(robot_model, group: str, start, goal):
    """A 2-waypoint trajectory start -> goal, shown for a failure without a planned path (as MTC)."""
    from mtc.scene.robot_trajectory import RobotTrajectory

    traj = RobotTrajectory(robot_model, group)
    traj.add_suffix_waypoint(start, 0.0)
    traj.add_suffix_waypoint(goal, 1.0)
    return traj


def check_planner(stage, planner) -> None:
    """Raise ``TypeError`` unless ``planner`` looks like a PlannerInterface (or is None)."""
    if planner is None:
        return
    looks_like_one = callable(getattr(planner, "plan", None)) and callable(getattr(planner, "init", None))
    if isinstance(planner, type) or not looks_like_one:
        raise TypeError(
            f"{type(stage).__name__} '{stage.name}': planner must be a PlannerInterface "
            f"(e.g. core.JointInterpolationPlanner()), got {not_a_planner(planner)}"
        )


def init_planner(stage, planner, robot_model) -> None:
    """``planner.init(robot_model)``, its configuration errors (an unknown pipeline or planner
    id: ``ValueError`` with the known ones) raised as the stage's ``InitStageError``, so that
    ``Task.init`` collects them with every other problem of the tree."""
    try:
        planner.init(robot_model)
    except ValueError as e:
        raise InitStageError(stage, str(e)) from None


class PlannerStage(PropagatingEitherWay):
    """A propagator planning with one planner for one group (base of MoveTo, MoveRelative).

    Args:
        name: Stage name.
        planner: The planner (a ``PlannerInterface``).
        ik_frame_description: How the stage uses its ``ik_frame`` (property description).
    """

    def __init__(self, name: str, planner, ik_frame_description: str):
        super().__init__(name)
        check_planner(self, planner)
        self._planner = planner
        self.setCostTerm(PathLength())
        p = self.properties
        p.property("timeout").setDefaultValue(1.0)
        p.declare("group", None, "name of planning group", type=str)
        p.declare("ik_frame", None, ik_frame_description, type=msgs.PoseStamped, convert=valid_message("ik_frame"))

    def _declare_path_constraints(self) -> None:
        # declared after the stage's own properties, in MTC's order
        self.properties.declare("path_constraints", msgs.Constraints(), "constraints to maintain during trajectory")

    @property
    def planner(self):
        """The planner."""
        return self._planner

    def setPlanner(self, planner) -> None:
        """Replace the planner."""
        check_planner(self, planner)
        self._planner = planner

    def setGroup(self, group: str) -> None:
        """Set the planning group."""
        self.properties.set("group", group)

    def setIKFrame(self, *args) -> None:
        """``setIKFrame(PoseStamped)``, ``setIKFrame(pose, link)`` or ``setIKFrame(link)``."""
        self.properties.set("ik_frame", ik_frame_from_args(*args))

    def setPathConstraints(self, constraints: msgs.Constraints) -> None:
        """Set the path constraints."""
        self.properties.set("path_constraints", constraints)

    def init(self, robot_model) -> None:
        super().init(robot_model)
        if self._planner is None:
            raise InitStageError(self, "no planner specified (pass one to the constructor or use setPlanner())")
        init_planner(self, self._planner, robot_model)

    def _sceneAndGroup(self, state: InterfaceState, goal_property: str, undefined: str):
        """The diff of ``state``'s scene to plan in, the group, and the goal property's value;
        or, where the group is unknown or the goal undefined, ``(scene, None, failure)``."""
        scene = state.scene.diff()
        model = scene.robot_model
        group = self.properties.get("group")
        if not model.has_joint_model_group(group):
            return scene, None, SubTrajectory.failure(f"invalid joint model group: {group}")
        goal = self.properties.get(goal_property, None)
        if goal is None:
            return scene, None, SubTrajectory.failure(undefined)
        return scene, model.get_joint_model_group(group), goal
