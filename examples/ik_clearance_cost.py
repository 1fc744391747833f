"""Order IK solutions by their clearance from an obstacle.

A port of MTC's ``demo/src/ik_clearance_cost.cpp``. A ``FixedState`` holds the arm at
``extended`` with a sphere (radius 0.1 m) at z = 0.85 m, colliding with the arm
(``ignore_collisions``, so the state is spawned anyway). ``ComputeIK`` wraps it and looks for
up to 100 arm configurations (1 s) that put ``panda_link8`` at (0.3, 0, 0.35), turned by pi
about y (pointing down); the ``Clearance`` cost term (with the world, not cumulative) rates
each by its distance to collision, so the solutions come out ordered by clearance.
Expected outcome: many distinct IK solutions, ordered by clearance cost.
Run: ``python examples/ik_clearance_cost.py [--view]``
"""

from __future__ import annotations

import math

from mtc import PlanningScene, core, stages
from mtc.msgs import CollisionObject, Header, Pose, PoseStamped, SolidPrimitive

from _demo import run_example  # examples/_demo.py: plan, report, --view


def make_task(cumulative: bool = False, with_world: bool = True) -> core.Task:
    """The task: ComputeIK(FixedState with an obstacle) with a Clearance cost term."""
    task = core.Task()
    task.name = "clearance IK"
    task.loadRobotModel()

    scene = PlanningScene(task.getRobotModel())
    scene.current_state.set_to_default_values()
    scene.current_state.set_to_default_values("panda_arm", "extended")

    sphere = CollisionObject()
    sphere.header.frame_id = scene.planning_frame
    sphere.id = "obstacle"
    sphere.primitives.append(SolidPrimitive(type=SolidPrimitive.SPHERE, dimensions=[0.1]))
    pose = Pose()
    pose.position.z = 0.85
    pose.orientation.w = 1.0
    sphere.primitive_poses.append(pose)
    sphere.operation = CollisionObject.ADD
    scene.apply_collision_object(sphere)

    initial = stages.FixedState()
    initial.setState(scene)
    initial.setIgnoreCollisions(True)

    ik = stages.ComputeIK()
    ik.insert(initial)
    ik.setGroup("panda_arm")
    target = PoseStamped(header=Header(frame_id=scene.planning_frame))
    target.pose.position.x, target.pose.position.z = 0.3, 0.35
    # a half turn about y: the flange points down
    target.pose.orientation.y, target.pose.orientation.w = math.sin(math.pi / 2), math.cos(math.pi / 2)
    ik.setTargetPose(target)
    ik.setTimeout(1.0)
    ik.setMaxIKSolutions(100)

    clearance = core.Clearance()
    clearance.cumulative = cumulative
    clearance.with_world = with_world
    ik.setCostTerm(clearance)
    task.add(ik)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
