"""Add a collision object to the planning scene within a task.

As MTC's ``demo/scripts/modify_planning_scene.py``: ``CurrentState`` followed by a
``ModifyPlanningScene`` stage that adds a sphere ``grasp_object`` to the world. The task's
solution is a scene change without motion. Expected outcome: 1 solution of cost 0, whose end
scene contains ``grasp_object``. Run: ``python examples/modify_planning_scene.py [--view]``
"""

from __future__ import annotations

import argparse
import mtc
from mtc import core, stages
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
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--view", action="store_true", help="show the solution in a meshcat viewer")
    args = parser.parse_args(argv)

    viewer = None
    if args.view:
        from mtc.viewer import Viewer

        viewer = Viewer(mtc.robots.panda())
        print("viewer at", viewer.url)

    task = make_task()
    result = task.plan()
    task.printState()
    if not result:
        task.explainFailure()  # which stages failed, and why
    print(f"plan: {result}, {len(task.solutions)} solution(s), costs:",
          [round(s.cost, 4) for s in task.solutions])
    if viewer is not None and task.solutions:
        task.publish(task.solutions[0])
        viewer.hold()
    return task


if __name__ == "__main__":
    main()
