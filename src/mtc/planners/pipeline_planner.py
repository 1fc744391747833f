"""Planning through a named pipeline (MTC's ``solvers/pipeline_planner.h``).

Pipelines are registered by name, each implemented in one module and imported on first use:

* ``"ompl"``: OMPL's sampling-based planners (:mod:`mtc.planners.ompl_pipeline`); planner ids
  as MoveIt's (``"RRTConnectkConfigDefault"``) or OMPL's (``"RRTConnect"``). Its geometric path
  is timed here with the planner's scaling factors.
* ``"pilz_industrial_motion_planner"``: ``"PTP"``, ``"LIN"``, ``"CIRC"``
  (:mod:`mtc.planners.pilz`), which time their motions themselves (slowed down as a whole where
  the link would move faster than ``max_cartesian_speed``, never sped up).

An unknown pipeline or planner id makes ``init()`` raise ``ValueError`` listing the known ones.
"""

from __future__ import annotations

import importlib
import math

import numpy as np

from mtc import msgs
from mtc.core.properties import non_negative, unsigned_int
from mtc.planners.planner_interface import PlannerInterface, PlannerResult, error_message, pose_argument
from mtc.planners.time_parameterization import slow_to_cartesian_speed
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import RobotModel
from mtc.scene.robot_trajectory import RobotTrajectory

__all__ = ["PipelinePlanner", "KNOWN_PIPELINES", "known_planners"]

#: pipeline name -> module implementing it
_PIPELINE_MODULES = {
    "ompl": "mtc.planners.ompl_pipeline",
    "pilz_industrial_motion_planner": "mtc.planners.pilz",
}
KNOWN_PIPELINES = tuple(_PIPELINE_MODULES)


def _pipeline_module(pipeline: str):
    if pipeline not in _PIPELINE_MODULES:
        raise ValueError(f"unknown planning pipeline '{pipeline}' (known: {', '.join(KNOWN_PIPELINES)})")
    return importlib.import_module(_PIPELINE_MODULES[pipeline])


def known_planners(pipeline: str) -> tuple[str, ...]:
    """Planner ids the pipeline accepts.

    Raises:
        ValueError: unknown pipeline.
    """
    return tuple(_pipeline_module(pipeline).KNOWN_PLANNERS)


class PipelinePlanner(PlannerInterface):
    """Plan with a pipeline's planner.

    Args:
        pipeline: ``"ompl"`` or ``"pilz_industrial_motion_planner"``.
        planner_id: the ``planner`` property's value (MTC's ROS 2 constructor takes it too).

    Properties:
        planner: planner id ("" = the pipeline's default: ``RRTConnectkConfigDefault``, ``PTP``).
        num_planning_attempts: attempts per request; the best (shortest) result counts (OMPL).
        workspace_parameters: accepted for API parity (no floating joints to bound).
        goal_joint_tolerance: joint goal tolerance [rad or m] (OMPL).
        goal_position_tolerance: pose goal position tolerance [m] (OMPL).
        goal_orientation_tolerance: pose goal orientation tolerance [rad] (OMPL).
        display_motion_plans, publish_planning_requests: accepted for API parity (no ROS).
        seed: random seed of each request (``mtc``: plans are reproducible).
        (and those of :class:`PlannerInterface`)
    """

    def __init__(self, *args, **kwargs):
        """``PipelinePlanner(pipeline="ompl", planner_id="")``, or ROS 2's
        ``PipelinePlanner(node, pipeline="ompl", planner_id="")`` with an :class:`mtc.rclcpp.Node`
        first (accepted and ignored)."""
        from mtc.rclcpp import Node

        if args and isinstance(args[0], Node):
            args = args[1:]
        if len(args) > 2:
            raise TypeError("PipelinePlanner takes (pipeline, planner_id) or ROS 2's (node, pipeline, planner_id), "
                            f"got {len(args)} arguments after the node")
        self._configure(*args, **kwargs)

    def _configure(self, pipeline: str = "ompl", planner_id: str = "") -> None:
        super().__init__()
        if not isinstance(pipeline, str):
            raise TypeError(f"pipeline must be a name ({', '.join(KNOWN_PIPELINES)}), not {type(pipeline).__name__}")
        if not isinstance(planner_id, str):
            raise TypeError(f"planner_id must be a planner id (a str), not {type(planner_id).__name__}")
        self._pipeline_id = pipeline
        self._pipeline = None
        p = self.properties
        p.declare("planner", planner_id, "planner id")
        p.declare("num_planning_attempts", 1, "number of planning attempts", type=unsigned_int)
        p.declare("workspace_parameters", msgs.WorkspaceParameters(), "allowed workspace of mobile base?")
        p.declare("goal_joint_tolerance", 1e-4, "tolerance for reaching joint goals",
                  convert=non_negative("goal_joint_tolerance"))
        p.declare("goal_position_tolerance", 1e-4, "tolerance for reaching position goals",
                  convert=non_negative("goal_position_tolerance"))
        p.declare("goal_orientation_tolerance", 1e-4, "tolerance for reaching orientation goals",
                  convert=non_negative("goal_orientation_tolerance"))
        p.declare("display_motion_plans", False, "publish generated solutions on topic display_planned_path")
        p.declare("publish_planning_requests", False, "publish motion planning requests on topic motion_plan_request")
        p.declare("seed", 0, "random seed of the planning requests", convert=non_negative("seed"))

    @property
    def pipeline_id(self) -> str:
        """The pipeline's name."""
        return self._pipeline_id

    def setPlannerId(self, planner: str) -> None:
        self.properties.set("planner", planner)

    def init(self, robot_model: RobotModel) -> None:
        """Create the pipeline and check the planner id.

        Raises:
            ValueError: unknown pipeline or planner id (the message lists the known ones).
        """
        super().init(robot_model)
        module = _pipeline_module(self._pipeline_id)
        self._check_planner_id(module)
        if self._pipeline_id == "ompl":
            self._pipeline = module.OMPLPipeline()
        else:
            self._pipeline = module.PilzPipeline(robot_model)

    def _check_planner_id(self, module) -> str:
        planner = self.properties.get("planner")
        if planner and hasattr(module, "resolve_planner_id"):
            # OMPL: MoveIt's ids, "group[id]" and OMPL's names; its error lists MoveIt's ids
            module.resolve_planner_id(planner)
        elif planner and planner not in module.KNOWN_PLANNERS:
            raise ValueError(
                f"unknown planner '{planner}' for pipeline '{self._pipeline_id}' "
                f"(known: {', '.join(module.KNOWN_PLANNERS)})"
            )
        return planner or module.DEFAULT_PLANNER

    def _ready(self, scene: PlanningScene) -> str | None:
        """Initialize on first use and re-check the planner id; an error message (after an
        error-code name, as every failure of the pipelines) or None."""
        try:
            if self._pipeline is None or self._robot_model is not scene.robot_model:
                self.init(scene.robot_model)
            else:
                self._check_planner_id(_pipeline_module(self._pipeline_id))
        except ValueError as e:
            # as Pilz's "No ContextLoader for planner_id ...": the request fails, it does not raise
            return error_message("PLANNING_FAILED", str(e))
        return None

    def plan(
        self,
        from_scene: PlanningScene,
        to_scene: PlanningScene,
        group: str,
        timeout: float,
        path_constraints: msgs.Constraints | None = None,
    ) -> tuple[PlannerResult, RobotTrajectory | None]:
        """Plan from ``from_scene``'s state to the group's variables in ``to_scene``'s."""
        jmg = self._group(from_scene, group)
        error = self._ready(from_scene)
        if error:
            return PlannerResult(False, error), None
        props = self.properties
        timeout = self._effective_timeout(timeout)
        if self._pipeline_id == "ompl":
            result, traj = self._pipeline.plan_joint(
                from_scene,
                from_scene.current_state,
                to_scene.current_state,
                jmg.name,
                planner_id=props.get("planner"),
                timeout=timeout,
                attempts=max(1, props.get("num_planning_attempts")),
                path_constraints=path_constraints,
                goal_joint_tolerance=props.get("goal_joint_tolerance"),
                seed=props.get("seed"),
            )
            return self._timed(result, traj)
        return self._cartesian_speed(*self._pipeline.plan_joint(
            from_scene,
            from_scene.current_state,
            to_scene.current_state,
            jmg.name,
            props.get("planner"),
            timeout,
            props.get("max_velocity_scaling_factor"),
            props.get("max_acceleration_scaling_factor"),
            path_constraints,
        ))

    def plan_to_pose(
        self,
        from_scene: PlanningScene,
        link: str,
        offset: np.ndarray,
        target: np.ndarray,
        group: str,
        timeout: float,
        path_constraints: msgs.Constraints | None = None,
    ) -> tuple[PlannerResult, RobotTrajectory | None]:
        """Plan until ``pose(link) · offset == target`` (planning frame)."""
        jmg = self._group(from_scene, group)
        offset, target = pose_argument(offset, "offset"), pose_argument(target, "target")
        error = self._ready(from_scene)
        if error:
            return PlannerResult(False, error), None
        props = self.properties
        timeout = self._effective_timeout(timeout)
        if self._pipeline_id == "ompl":
            result, traj = self._pipeline.plan_pose(
                from_scene,
                from_scene.current_state,
                link,
                offset,
                target,
                jmg.name,
                planner_id=props.get("planner"),
                timeout=timeout,
                attempts=max(1, props.get("num_planning_attempts")),
                path_constraints=path_constraints,
                goal_position_tolerance=props.get("goal_position_tolerance"),
                goal_orientation_tolerance=props.get("goal_orientation_tolerance"),
                seed=props.get("seed"),
            )
            return self._timed(result, traj)
        return self._cartesian_speed(*self._pipeline.plan_pose(
            from_scene,
            from_scene.current_state,
            link,
            offset,
            target,
            jmg.name,
            props.get("planner"),
            timeout if math.isfinite(timeout) else 1e9,
            props.get("max_velocity_scaling_factor"),
            props.get("max_acceleration_scaling_factor"),
            path_constraints,
            seed=props.get("seed"),
        ))

    def _cartesian_speed(self, result, traj):
        # Pilz times its own motions under its Cartesian and joint limits; a Cartesian speed
        # limit (applied after planning, as MoveIt's pipeline does) only ever slows one down:
        # stretched in time as a whole, its profile keeps its shape and every limit it kept
        if result and traj is not None and len(traj) > 0:
            speed, link, error = self._speed_limit(traj)
            if error:
                return PlannerResult(False, error), traj
            if speed > 0 and link:
                slow_to_cartesian_speed(traj, speed, link)
        return result, traj

    def _timed(self, result, traj):
        # OMPL's paths are geometric: time them with this planner's settings
        if traj is not None and len(traj) > 0:
            return self._timing_result(result, traj)
        return result, traj

    def _timing_result(self, result, traj):
        error = self._apply_timing(traj)
        if error and result:
            return PlannerResult(False, error), traj
        return result, traj

    def __repr__(self) -> str:
        planner = self.properties.get("planner")
        return f"PipelinePlanner({self._pipeline_id!r}" + (f", planner={planner!r})" if planner else ")")
