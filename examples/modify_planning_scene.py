"""Add a collision object to the planning scene within a task.

As MTC's ``demo/scripts/modify_planning_scene.py``: ``CurrentState`` followed by a
``ModifyPlanningScene`` stage that adds a sphere ``grasp_object`` to the world. The task's
solution is a scene change without motion. Expected outcome: 1 solution of cost 0, whose end
scene contains ``grasp_object``. Run: ``python examples/modify_planning_scene.py [--view]``
"""

from __future__ import annotations

from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view
from mtc.msgs import CollisionObject, Pose, SolidPrimitive


def make_task() -> core.Task:
    """The task: current state, then add a sphere in front of the robot."""
    task = core.Task()
    task.name = "modify planning scene"
    task.add(stages.CurrentState("current state"))

    sphere = SolidPrimitive()
    sphere.type = SolidPrimitive.SPHERE
    sphere.dimensions = [0.05]  # radius [m]
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = 0.5, 0.3, 0.3
    pose.orientation.w = 1.0

    obj = CollisionObject()
    obj.header.frame_id = "world"
    obj.id = "grasp_object"
    obj.primitives.append(sphere)
    obj.primitive_poses.append(pose)
    obj.operation = CollisionObject.ADD

    modify = stages.ModifyPlanningScene("modify planning scene")
    modify.addObject(obj)
    task.add(modify)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
