"""Pick a cylinder from a table and place it nearby: MTC's pick-and-place demo.

A port of MTC's ``demo/src/pick_place_demo.cpp`` and ``pick_place_task.cpp`` with the values
of ``config/panda_config.yaml``. The scene: a table (0.4 x 0.5 x 0.1, top at z = 0) and a
cylinder "object" (height 0.25, radius 0.02) standing on it at (0.5, -0.25). The task:

* "applicability test": a ``PredicateFilter`` around ``CurrentState`` that rejects a start
  where the object is already attached;
* "open hand" (``MoveTo``), "move to pick" (``Connect``, OMPL, 5 s);
* "pick object" (``SerialContainer``): "approach object" (0.10-0.15 m along the hand's z),
  "grasp pose IK" (``ComputeIK`` of ``GenerateGraspPose``, every 15 degrees about the object,
  8 IK solutions each), allow hand-object collisions, "close hand", "attach object", allow
  object-table collisions, "lift object" (0.01-0.1 m up), forbid object-table collisions;
* "move to place" (``Connect``, OMPL, 5 s);
* "place object": "lower object" (0.03-0.13 m down), "place pose IK" (``ComputeIK`` of
  ``GeneratePlacePose`` at (0.6, -0.15), 2 IK solutions each), "open hand", forbid
  hand-object collisions, "detach object", "retreat after place" (0.12-0.25 m back);
* "move home" (``MoveTo`` ``ready``, forward only).

Task properties (``group``, ``eef``, ``hand``, ``hand_grasping_frame``, ``ik_frame``) reach
the stages through ``exposeTo`` and ``configureInitFrom(PARENT, ...)``. Expected outcome (MTC's
``pick_place_test``): ``init()`` works and ``plan(max_solutions=10)`` finds at least 1
solution, which ``task.execute`` plays on the current scene (SUCCESS): the cylinder then stands
at the place pose. Run: ``python examples/pick_place_demo.py [--view]``
"""

from __future__ import annotations

import argparse
import math

import numpy as np

import mtc
from mtc import PlanningSceneInterface, core, stages
from mtc.msgs import Header, PoseStamped, Vector3, Vector3Stamped


MAX_SOLUTIONS = 10

# config/panda_config.yaml
ARM_GROUP = "panda_arm"
HAND_GROUP = "hand"
EEF = "hand"
HAND_FRAME = "panda_link8"
WORLD_FRAME = "world"
GRASP_FRAME_TRANSFORM = [0.0, 0.0, 0.1, 1.571, 0.785, 1.571]  # x y z roll pitch yaw
HAND_OPEN_POSE = "open"
HAND_CLOSE_POSE = "close"
ARM_HOME_POSE = "ready"
OBJECT_NAME = "object"
OBJECT_DIMENSIONS = (0.25, 0.02)  # height, radius
OBJECT_POSE = (0.5, -0.25, 0.0)
TABLE_NAME = "table"
TABLE_DIMENSIONS = (0.4, 0.5, 0.1)
TABLE_POSE = (0.5, -0.25, 0.0)
PLACE_POSE = (0.6, -0.15, 0.0)
SUPPORT_SURFACES = [TABLE_NAME]
APPROACH_OBJECT_MIN_DIST, APPROACH_OBJECT_MAX_DIST = 0.1, 0.15
LIFT_OBJECT_MIN_DIST, LIFT_OBJECT_MAX_DIST = 0.01, 0.1


def rpy_transform(x: float, y: float, z: float, roll: float, pitch: float, yaw: float) -> np.ndarray:
    """A 4x4 transform as the demo's ``vectorToEigen``: translation * Rx(roll) * Ry(pitch) * Rz(yaw)."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    T = np.eye(4)
    T[:3, :3] = rx @ ry @ rz
    T[:3, 3] = (x, y, z)
    return T


def world_pose(x: float, y: float, z: float) -> PoseStamped:
    """An axis-aligned pose in the world frame."""
    pose = PoseStamped(header=Header(frame_id=WORLD_FRAME))
    pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = x, y, z
    pose.pose.orientation.w = 1.0
    return pose


def setup_demo_scene() -> None:
    """Put the table and the cylinder into the current scene (pick_place_demo.cpp)."""
    psi = PlanningSceneInterface(synchronous=True)
    psi.remove_world_object()
    x, y, z = TABLE_POSE
    psi.add_box(TABLE_NAME, world_pose(x, y, z - 0.5 * TABLE_DIMENSIONS[2]), size=TABLE_DIMENSIONS)  # top at z
    x, y, z = OBJECT_POSE
    height, radius = OBJECT_DIMENSIONS
    # MTC stands the cylinder exactly on the table top (z + h/2); with coal the exact contact
    # counts as a collision (distance ~ -1e-17) once the object is attached, so "attach object"
    # would fail. 0.1 mm of air, as the demo's own place pose has, avoids it.
    psi.add_cylinder(OBJECT_NAME, world_pose(x, y, z + 0.5 * height + 0.0001), height, radius)


def make_task() -> core.Task:
    """The pick-and-place task of pick_place_task.cpp."""
    setup_demo_scene()
    task = core.Task()
    task.name = "demo task"
    task.loadRobotModel()
    robot = task.getRobotModel()
    hand_links = robot.get_joint_model_group(HAND_GROUP)
    grasp_frame_transform = rpy_transform(*GRASP_FRAME_TRANSFORM)
    parent = core.Stage.PropertyInitializerSource.PARENT
    interface = core.Stage.PropertyInitializerSource.INTERFACE

    sampling_planner = core.PipelinePlanner()
    sampling_planner.goal_joint_tolerance = 1e-5
    cartesian_planner = core.CartesianPath()
    cartesian_planner.max_velocity_scaling_factor = 1.0
    cartesian_planner.max_acceleration_scaling_factor = 1.0
    cartesian_planner.setStepSize(0.01)

    task.setProperty("group", ARM_GROUP)
    task.setProperty("eef", EEF)
    task.setProperty("hand", HAND_GROUP)
    task.setProperty("hand_grasping_frame", HAND_FRAME)
    task.setProperty("ik_frame", HAND_FRAME)

    # current state, unless the object is already held
    def not_attached(solution):
        if OBJECT_NAME in solution.start.scene.attached_object_names:
            return False, f"object with id '{OBJECT_NAME}' is already attached and cannot be picked"
        return True

    applicability_filter = stages.PredicateFilter("applicability test", stages.CurrentState("current state"))
    applicability_filter.setPredicate(not_attached)
    task.add(applicability_filter)
    current_state = applicability_filter

    stage = stages.MoveTo("open hand", sampling_planner)
    stage.group = HAND_GROUP
    stage.setGoal(HAND_OPEN_POSE)
    task.add(stage)

    stage = stages.Connect("move to pick", [(ARM_GROUP, sampling_planner)])
    stage.setTimeout(5.0)
    stage.properties.configureInitFrom(parent)
    task.add(stage)

    # ---- pick object ----
    grasp = core.SerialContainer("pick object")
    task.properties.exposeTo(grasp.properties, ["eef", "hand", "group", "ik_frame"])
    grasp.properties.configureInitFrom(parent, ["eef", "hand", "group", "ik_frame"])

    stage = stages.MoveRelative("approach object", cartesian_planner)
    stage.properties.set("marker_ns", "approach_object")
    stage.setIKFrame(HAND_FRAME)
    stage.properties.configureInitFrom(parent, ["group"])
    stage.setMinMaxDistance(APPROACH_OBJECT_MIN_DIST, APPROACH_OBJECT_MAX_DIST)
    stage.setDirection(Vector3Stamped(header=Header(frame_id=HAND_FRAME), vector=Vector3(0, 0, 1.0)))
    grasp.insert(stage)

    generator = stages.GenerateGraspPose("generate grasp pose")
    generator.properties.configureInitFrom(parent)
    generator.properties.set("marker_ns", "grasp_pose")
    generator.setPreGraspPose(HAND_OPEN_POSE)
    generator.setObject(OBJECT_NAME)
    generator.setAngleDelta(math.pi / 12)
    generator.setMonitoredStage(current_state)
    wrapper = stages.ComputeIK("grasp pose IK", generator)
    wrapper.setMaxIKSolutions(8)
    wrapper.setMinSolutionDistance(1.0)
    wrapper.setIKFrame(grasp_frame_transform, HAND_FRAME)
    wrapper.properties.configureInitFrom(parent, ["eef", "group"])
    wrapper.properties.configureInitFrom(interface, ["target_pose"])
    grasp.insert(wrapper)

    stage = stages.ModifyPlanningScene("allow collision (hand,object)")
    stage.allowCollisions(OBJECT_NAME, hand_links, True)
    grasp.insert(stage)

    stage = stages.MoveTo("close hand", sampling_planner)
    stage.group = HAND_GROUP
    stage.setGoal(HAND_CLOSE_POSE)
    grasp.insert(stage)

    stage = stages.ModifyPlanningScene("attach object")
    stage.attachObject(OBJECT_NAME, HAND_FRAME)
    grasp.insert(stage)

    stage = stages.ModifyPlanningScene("allow collision (object,support)")
    stage.allowCollisions([OBJECT_NAME], SUPPORT_SURFACES, True)
    grasp.insert(stage)

    stage = stages.MoveRelative("lift object", cartesian_planner)
    stage.properties.configureInitFrom(parent, ["group"])
    stage.setMinMaxDistance(LIFT_OBJECT_MIN_DIST, LIFT_OBJECT_MAX_DIST)
    stage.setIKFrame(HAND_FRAME)
    stage.properties.set("marker_ns", "lift_object")
    stage.setDirection(Vector3Stamped(header=Header(frame_id=WORLD_FRAME), vector=Vector3(0, 0, 1.0)))
    grasp.insert(stage)

    stage = stages.ModifyPlanningScene("forbid collision (object,support)")
    stage.allowCollisions([OBJECT_NAME], SUPPORT_SURFACES, False)
    grasp.insert(stage)

    pick_stage = grasp
    task.add(grasp)

    stage = stages.Connect("move to place", [(ARM_GROUP, sampling_planner)])
    stage.setTimeout(5.0)
    stage.properties.configureInitFrom(parent)
    task.add(stage)

    # ---- place object ----
    place = core.SerialContainer("place object")
    task.properties.exposeTo(place.properties, ["eef", "hand", "group"])
    place.properties.configureInitFrom(parent, ["eef", "hand", "group"])

    stage = stages.MoveRelative("lower object", cartesian_planner)
    stage.properties.set("marker_ns", "lower_object")
    stage.setIKFrame(HAND_FRAME)
    stage.properties.configureInitFrom(parent, ["group"])
    stage.setMinMaxDistance(0.03, 0.13)
    stage.setDirection(Vector3Stamped(header=Header(frame_id=WORLD_FRAME), vector=Vector3(0, 0, -1.0)))
    place.insert(stage)

    generator = stages.GeneratePlacePose("generate place pose")
    generator.properties.set("marker_ns", "place_pose")
    generator.setObject(OBJECT_NAME)
    x, y, _ = PLACE_POSE
    generator.pose = world_pose(x, y, 0.5 * OBJECT_DIMENSIONS[0] + 0.0001)  # just above the table
    generator.setMonitoredStage(pick_stage)
    wrapper = stages.ComputeIK("place pose IK", generator)
    wrapper.setMaxIKSolutions(2)
    wrapper.setIKFrame(grasp_frame_transform, HAND_FRAME)
    wrapper.properties.configureInitFrom(parent, ["eef", "group"])
    wrapper.properties.configureInitFrom(interface, ["target_pose"])
    place.insert(wrapper)

    stage = stages.MoveTo("open hand", sampling_planner)
    stage.group = HAND_GROUP
    stage.setGoal(HAND_OPEN_POSE)
    place.insert(stage)

    stage = stages.ModifyPlanningScene("forbid collision (hand,object)")
    stage.allowCollisions(OBJECT_NAME, hand_links, False)
    place.insert(stage)

    stage = stages.ModifyPlanningScene("detach object")
    stage.detachObject(OBJECT_NAME, HAND_FRAME)
    place.insert(stage)

    stage = stages.MoveRelative("retreat after place", cartesian_planner)
    stage.properties.configureInitFrom(parent, ["group"])
    stage.setMinMaxDistance(0.12, 0.25)
    stage.setIKFrame(HAND_FRAME)
    stage.properties.set("marker_ns", "retreat")
    stage.setDirection(Vector3Stamped(header=Header(frame_id=HAND_FRAME), vector=Vector3(0, 0, -1.0)))
    place.insert(stage)

    task.add(place)

    stage = stages.MoveTo("move home", sampling_planner)
    stage.properties.configureInitFrom(parent, ["group"])
    stage.setGoal(ARM_HOME_POSE)
    stage.restrictDirection(stages.MoveTo.Direction.FORWARD)
    task.add(stage)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--view", action="store_true", help="show the solution in a meshcat viewer")
    args = parser.parse_args(argv)

    viewer = None
    if args.view:
        from mtc.viewer import Viewer

        viewer = Viewer(mtc.robots.panda())
        print("viewer at", viewer.url)

    task = make_task()
    result = task.plan(max_solutions=MAX_SOLUTIONS)
    task.printState()
    if not result:
        task.explainFailure()  # which stages failed, and why
    print(f"plan: {result}, {len(task.solutions)} solution(s), costs:",
          [round(s.cost, 4) for s in task.solutions])
    if task.solutions:
        # as pick_place_demo.cpp with execute:=true: play the best solution on the current scene
        executed = task.execute(task.solutions[0])
        placed = mtc.current_scene().get_frame_transform(OBJECT_NAME)[:3, 3]
        print(f"execute: {executed}, '{OBJECT_NAME}' now at", [round(float(v), 4) for v in placed])
    if viewer is not None and task.solutions:
        task.publish(task.solutions[0])
        viewer.hold()
    return task


if __name__ == "__main__":
    main()
