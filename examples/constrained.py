"""Plan a relative motion under a path constraint: keep a held object upright.

As MTC's ``demo/scripts/constrained.py``: a ``ModifyPlanningScene`` stage adds a sphere
"obstacle" and a box "object" to the scene and attaches the box to ``panda_hand``; a
``MoveRelative`` "y +0.4" (``PipelinePlanner``, OMPL, 5 s) then moves the hand 0.4 m along
world y while an ``OrientationConstraint`` on "object" keeps it upright (tilt below 0.1 rad
about x and y, any turn about z) along the whole path. Expected outcome: 1 solution whose
every waypoint holds the constraint. Run: ``python examples/constrained.py [--view]``
"""

from __future__ import annotations

from math import pi

from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view
from mtc.msgs import (
    CollisionObject,
    Constraints,
    Header,
    OrientationConstraint,
    Pose,
    SolidPrimitive,
    Vector3,
    Vector3Stamped,
)


def collision_object(name: str, shape: int, dimensions: list[float],
                     xyz: tuple[float, float, float]) -> CollisionObject:
    """An ADD message of one primitive at ``xyz`` in the world, axis aligned.

    The object's own frame (``pose``) is its centre, so constraints on it are about the box.
    """
    obj = CollisionObject()
    obj.header.frame_id = "world"
    obj.id = name
    obj.pose.position.x, obj.pose.position.y, obj.pose.position.z = xyz
    obj.pose.orientation.w = 1.0
    obj.primitives.append(SolidPrimitive(type=shape, dimensions=dimensions))
    obj.primitive_poses.append(Pose())  # at the object's frame (an all-zero quaternion is identity)
    obj.operation = CollisionObject.ADD
    return obj


def upright_constraint() -> Constraints:
    """The object's z axis stays vertical within 0.1 rad; it may turn freely about z."""
    oc = OrientationConstraint()
    oc.header.frame_id = "world"
    oc.link_name = "object"
    oc.orientation.w = 1.0
    oc.absolute_x_axis_tolerance = 0.1
    oc.absolute_y_axis_tolerance = 0.1
    oc.absolute_z_axis_tolerance = pi
    oc.weight = 1.0
    constraints = Constraints()
    constraints.name = "upright"
    constraints.orientation_constraints.append(oc)
    return constraints


def make_task() -> core.Task:
    """The task: current state -> add obstacle and object, attach it -> y +0.4 upright."""
    task = core.Task()
    task.name = "constrained"
    task.add(stages.CurrentState("current"))

    # at 'ready' the hand points down; its fingertips are near (0.307, 0, 0.48)
    scene = stages.ModifyPlanningScene("modify planning scene")
    scene.addObject(collision_object("obstacle", SolidPrimitive.SPHERE, [0.08], (0.45, 0.2, 0.35)))
    scene.addObject(collision_object("object", SolidPrimitive.BOX, [0.04, 0.04, 0.1], (0.307, 0.0, 0.44)))
    scene.attachObject("object", "panda_hand")
    task.add(scene)

    planner = core.PipelinePlanner()
    move = stages.MoveRelative("y +0.4", planner)
    move.timeout = 5.0
    move.group = "panda_arm"
    move.setDirection(Vector3Stamped(header=Header(frame_id="world"), vector=Vector3(0, 0.4, 0)))
    move.path_constraints = upright_constraint()
    task.add(move)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
