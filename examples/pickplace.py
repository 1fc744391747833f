"""Pick a box and place it elsewhere: MTC's pick-and-place tutorial.

As MTC's ``demo/scripts/pickplace.py`` (the pick-and-place tutorial): a box "grasp_object"
floats in front of the robot. From the current state, ``Connect`` (OMPL RRTConnect) reaches a
``Pick``: it approaches along world -z, grasps with ``SimpleGrasp`` (grasp poses from
``GenerateGraspPose`` every 90 degrees about the object, IK for the point between the fingers
with the hand turned to grasp from the top, fingers ``open`` -> ``close``) and lifts the box.
A second ``Connect`` carries it, keeping it upright (orientation constraint), to a ``Place``
at (-0.2, -0.6, 0): lower along the hand's z, open the fingers (``SimpleUnGrasp`` with poses
from ``GeneratePlacePose``), retract upwards. Expected outcome: at least 1 solution.
Run: ``python examples/pickplace.py [--view]``
"""

from __future__ import annotations

import math

from mtc import PlanningSceneInterface, core, stages
from mtc.msgs import Constraints, OrientationConstraint, PoseStamped, TwistStamped

from _demo import run_example  # examples/_demo.py: plan, report, --view


MAX_SOLUTIONS = 10  # MTC's script plans until the search space is exhausted; 10 suffice here

arm = "panda_arm"
eef = "hand"
object_name = "grasp_object"


#: The tutorial's box position (world frame) [m].
OBJECT_POSITION = (0.30702, 0.0, 0.285)


def add_object(position=OBJECT_POSITION, yaw: float = 0.0) -> PoseStamped:
    """Clear the current scene and add the box to grasp, turned by ``yaw`` about world z;
    returns its pose."""
    psi = PlanningSceneInterface(synchronous=True)
    psi.remove_world_object()

    objectPose = PoseStamped()
    objectPose.header.frame_id = "world"
    objectPose.pose.orientation.z = math.sin(yaw / 2)
    objectPose.pose.orientation.w = math.cos(yaw / 2)
    objectPose.pose.position.x, objectPose.pose.position.y, objectPose.pose.position.z = position
    psi.add_box(object_name, objectPose, size=[0.1, 0.05, 0.03])
    return objectPose


def upright() -> Constraints:
    """Keep the object's orientation within 0.1 rad about world x and y (free about z)."""
    oc = OrientationConstraint()
    oc.header.frame_id = "world"
    oc.link_name = object_name
    oc.orientation.w = 1.0  # the object's orientation as added
    oc.absolute_x_axis_tolerance = 0.1
    oc.absolute_y_axis_tolerance = 0.1
    oc.absolute_z_axis_tolerance = math.pi
    oc.weight = 1.0
    constraints = Constraints()
    constraints.name = "object:upright"
    constraints.orientation_constraints.append(oc)
    return constraints


def make_task(object_position=OBJECT_POSITION, object_yaw: float = 0.0,
              place_position=(-0.2, -0.6, 0.0), seed: int = 0) -> core.Task:
    """The task: current -> connect -> Pick -> connect (upright) -> Place.

    The defaults are the tutorial's; ``examples/dataset.py`` varies the box's position and
    turn, where it is placed, and the planner's ``seed``.
    """
    objectPose = add_object(object_position, object_yaw)

    task = core.Task()
    task.name = "pick + place"
    task.add(stages.CurrentState("current"))

    # a planner that connects the current state to the grasp approach pose
    pipeline = core.PipelinePlanner()
    pipeline.planner = "RRTConnectkConfigDefault"
    pipeline.properties["seed"] = seed
    planners = [(arm, pipeline)]
    task.add(stages.Connect("connect", planners))

    # grasp poses around the object, every 90 degrees
    grasp_generator = stages.GenerateGraspPose("Generate Grasp Pose")
    grasp_generator.angle_delta = math.pi / 2
    grasp_generator.pregrasp = "open"
    grasp_generator.grasp = "close"
    grasp_generator.setMonitoredStage(task["current"])  # solutions for all initial states

    # SimpleGrasp: IK of the arm pose, then closing the fingers
    simpleGrasp = stages.SimpleGrasp(grasp_generator, "Grasp")
    ik_frame = PoseStamped()
    ik_frame.header.frame_id = "panda_hand"
    ik_frame.pose.position.z = 0.1034  # tcp between fingers
    ik_frame.pose.orientation.x = 1.0  # grasp from top
    simpleGrasp.setIKFrame(ik_frame)

    # Pick: approach, grasp, lift
    pick = stages.Pick(simpleGrasp, "Pick")
    pick.eef = eef
    pick.object = object_name
    approach = TwistStamped()
    approach.header.frame_id = "world"
    approach.twist.linear.z = -1.0
    pick.setApproachMotion(approach, 0.03, 0.1)
    pick.cartesian_solver.max_velocity_scaling_factor = 0.1
    lift = TwistStamped()
    lift.header.frame_id = "panda_hand"
    lift.twist.linear.z = -1.0
    pick.setLiftMotion(lift, 0.03, 0.1)
    task.add(pick)

    # carry the object upright to the place pose
    con = stages.Connect("connect", planners)
    con.path_constraints = upright()
    task.add(con)

    # where the object should be after placing
    placePose = objectPose
    placePose.pose.position.x, placePose.pose.position.y, placePose.pose.position.z = place_position

    place_generator = stages.GeneratePlacePose("Generate Place Pose")
    place_generator.setMonitoredStage(task["Pick"])
    place_generator.object = object_name
    place_generator.pose = placePose

    # SimpleUnGrasp: release the object at the place pose
    simpleUnGrasp = stages.SimpleUnGrasp(place_generator, "UnGrasp")

    # Place: lower, release, retract
    place = stages.Place(simpleUnGrasp, "Place")
    place.eef = eef
    place.object = object_name
    place.eef_frame = "panda_link8"
    retract = TwistStamped()
    retract.header.frame_id = "world"
    retract.twist.linear.z = 1.0
    place.setRetractMotion(retract, 0.03, 0.1)
    placeMotion = TwistStamped()
    placeMotion.header.frame_id = "panda_hand"
    placeMotion.twist.linear.z = 1.0
    place.setPlaceMotion(placeMotion, 0.03, 0.1)
    task.add(place)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv, max_solutions=MAX_SOLUTIONS)


if __name__ == "__main__":
    main()
