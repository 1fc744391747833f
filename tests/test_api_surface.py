"""Every name that ../shared/spec/api.md promises exists where it says (the contract of user scripts)."""

from __future__ import annotations

import pytest

import mtc
from mtc import core, msgs, stages

TOP_LEVEL = [
    "core", "stages", "msgs", "RobotModel", "RobotState", "PlanningScene", "PlanningSceneInterface",
    "current_scene", "reset_current_scene", "Introspection", "RobotTrajectory", "roscpp_init", "robots",
]
ROBOT_MODEL = [
    "name", "model_frame", "joint_model_group_names", "get_joint_model_group", "end_effectors",
    "get_end_effector", "group_state_names", "pinocchio_model", "collision_model", "visual_model",
]
JOINT_MODEL_GROUP = ["name", "active_joint_model_names", "link_model_names", "variable_count"]
END_EFFECTOR = ["group", "parent_link", "parent_group"]
ROBOT_STATE = [
    "robot_model", "joint_positions", "positions", "set_joint_group_positions", "get_joint_group_positions",
    "set_to_default_values", "set_to_random_positions", "get_global_link_transform", "get_frame_transform",
    "get_pose", "get_jacobian", "set_from_ik", "satisfies_bounds", "distance", "copy",
]
PLANNING_SCENE = [
    "robot_model", "planning_frame", "current_state", "diff", "apply_collision_object", "world_object_names",
    "attach_object", "detach_object", "attached_object_names", "allowed_collision_matrix", "is_state_colliding",
    "get_collisions", "distance_to_collision", "get_frame_transform", "knows_frame_transform", "is_path_valid",
]
ACM = ["set_entry", "get_entry", "set_default_entry"]
PSI = [
    "add_box", "add_sphere", "add_cylinder", "add_mesh", "add_object", "remove_world_object", "attach_box",
    "remove_attached_object", "get_known_object_names", "get_objects", "get_attached_objects",
]
INTROSPECTION = ["save", "load", "serve", "stop"]
MSGS = [
    "Header", "Point", "Quaternion", "Pose", "PoseStamped", "PointStamped", "Vector3", "Vector3Stamped", "Twist",
    "TwistStamped", "JointState", "RobotState", "SolidPrimitive", "Mesh", "CollisionObject",
    "AttachedCollisionObject", "JointConstraint", "PositionConstraint", "OrientationConstraint", "Constraints",
    "JointTrajectory", "JointTrajectoryPoint", "RobotTrajectory", "Solution", "SubTrajectory",
    "pose_to_matrix", "matrix_to_pose", "pose_to_se3", "se3_to_pose",
]
CORE = [
    "Stage", "Generator", "MonitoringGenerator", "PropagatingEitherWay", "PropagatingForward", "PropagatingBackward",
    "Connecting", "ContainerBase", "SerialContainer", "ParallelContainerBase", "Alternatives", "Fallbacks", "Merger",
    "WrapperBase", "Task", "InterfaceState", "Solution", "SubTrajectory", "SolutionSequence", "WrappedSolution",
    "Solutions", "Property", "PropertyMap", "PropertyError", "InitStageError", "PlannerInterface", "PipelinePlanner",
    "JointInterpolationPlanner", "CartesianPath", "CartesianPrecision", "MultiPlanner", "CostTerm",
    "TrajectoryCostTerm", "LambdaCostTerm", "Constant", "PathLength", "DistanceToReference", "TrajectoryDuration",
    "LinkMotion", "LinkRotation", "Clearance", "MoveItErrorCode",
]
STAGES = [
    "CurrentState", "FixedState", "ComputeIK", "MoveTo", "MoveRelative", "Connect", "ModifyPlanningScene",
    "FixCollisionObjects", "GeneratePose", "GenerateGraspPose", "GeneratePlacePose", "GenerateRandomPose",
    "FixedCartesianPoses", "LimitSolutions", "NoOp", "PassThrough", "PredicateFilter", "SimpleGrasp",
    "SimpleUnGrasp", "Pick", "Place", "MergeMode", "PoseDimension",
]
TASK = [
    "timeout", "pruning", "printState", "explainFailure", "numSolutions", "failures", "execute", "publish",
    "introspection", "plan", "preempt", "reset", "clear", "add", "insert", "solutions", "setRobotModel",
    "getRobotModel", "loadRobotModel", "enableIntrospection", "setCostTerm", "init", "properties", "name",
]
TRAJECTORY = [
    "joint_model_group_name", "joint_names", "duration", "positions", "times", "velocities", "accelerations",
    "reverse", "append", "get_robot_trajectory_msg",
]


@pytest.fixture(scope="module")
def panda():
    return mtc.robots.panda()


@pytest.mark.parametrize(("module", "names"), [(mtc, TOP_LEVEL), (msgs, MSGS), (core, CORE), (stages, STAGES)])
def test_modules_export_the_promised_names(module, names):
    """mtc, mtc.msgs, mtc.core and mtc.stages have every name api.md lists."""
    missing = [n for n in names if not hasattr(module, n)]
    assert missing == []


def test_robot_model_state_and_scene_members(panda):
    """RobotModel, groups, end effectors, RobotState, PlanningScene, ACM and trajectories: api.md's members."""
    scene = mtc.PlanningScene(panda)
    trajectory = mtc.RobotTrajectory(panda, "panda_arm")
    task = core.Task()
    objects = [
        (panda, ROBOT_MODEL), (panda.get_joint_model_group("panda_arm"), JOINT_MODEL_GROUP),
        (panda.get_end_effector("hand"), END_EFFECTOR), (scene.current_state, ROBOT_STATE),
        (scene, PLANNING_SCENE), (scene.allowed_collision_matrix, ACM), (mtc.PlanningSceneInterface(), PSI),
        (task.introspection(), INTROSPECTION), (task, TASK), (trajectory, TRAJECTORY),
    ]
    missing = [f"{type(obj).__name__}.{n}" for obj, names in objects for n in names if not hasattr(obj, n)]
    assert missing == []
    assert len(task) == 0 and len(trajectory) == 0


def test_enums_and_nested_names():
    """The nested enums api.md names."""
    assert core.Stage.PropertyInitializerSource.PARENT and core.Stage.PropertyInitializerSource.INTERFACE
    assert {"AUTO", "FORWARD", "BACKWARD"} <= set(dir(core.PropagatingEitherWay.Direction))
    assert {"AUTO", "START_INTERFACE", "END_INTERFACE", "TRAJECTORY"} <= set(dir(core.TrajectoryCostTerm.Mode))
    assert {"SEQUENTIAL", "WAYPOINTS"} <= set(dir(stages.MergeMode))
    assert {"X", "Y", "Z", "ROLL", "PITCH", "YAW"} <= set(dir(stages.PoseDimension))
    assert (msgs.CollisionObject.ADD, msgs.CollisionObject.REMOVE, msgs.CollisionObject.APPEND, msgs.CollisionObject.MOVE) == (0, 1, 2, 3)
    assert (msgs.SolidPrimitive.BOX, msgs.SolidPrimitive.SPHERE, msgs.SolidPrimitive.CYLINDER, msgs.SolidPrimitive.CONE) == (1, 2, 3, 4)


def test_enums_print_as_pybind_prints_mtcs():
    """str() and format() give 'Class.MEMBER' (Python 3.11's IntEnum would print the number),
    repr() the class's public name; the values stay numbers."""
    Source = core.Stage.PropertyInitializerSource
    assert str(stages.MergeMode.WAYPOINTS) == f"{stages.MergeMode.WAYPOINTS}" == "MergeMode.WAYPOINTS"
    assert stages.Connect("c", []).merge_mode == 1 and str(stages.Connect("c", []).merge_mode) == "MergeMode.WAYPOINTS"
    assert repr(core.PropagatingEitherWay.Direction.FORWARD) == "<Direction.FORWARD: 1>"
    assert str(core.TrajectoryCostTerm.Mode.AUTO) == "Mode.AUTO"
    assert str(stages.PoseDimension.YAW) == "PoseDimension.YAW"
    assert str(Source.PARENT) == "PropertyInitializerSource.PARENT"
    assert int(Source.PARENT | Source.INTERFACE) == 6 and stages.PoseDimension.Z + 1 == 3


def test_error_codes_and_constructor_defaults():
    """MoveItErrorCode values and truthiness; constructors with MTC's C++ defaults (api.md)."""
    assert core.MoveItErrorCode(1) and not core.MoveItErrorCode(-1)
    assert (core.MoveItErrorCode.SUCCESS, core.MoveItErrorCode.PLANNING_FAILED,
            core.MoveItErrorCode.TIMED_OUT, core.MoveItErrorCode.PREEMPTED) == (1, -1, -6, -7)
    assert stages.FixedState().name == "fixed state"
    assert stages.ComputeIK().name == "IK"
    assert core.Task(ns="", introspection=False) is not None
    assert issubclass(core.PropertyError, RuntimeError) and issubclass(core.InitStageError, Exception)
