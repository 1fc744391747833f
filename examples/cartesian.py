"""Cartesian motions: straight lines, a rotation and a joint offset, then back to ``ready``.

As MTC's ``demo/scripts/cartesian.py`` (the Cartesian tutorial): from the current state the
hand moves 0.2 m along world x, 0.3 m along -y, turns 45 degrees about world z, and moves by a
joint offset, all with ``CartesianPath`` (hand speed limited to 0.1 m/s); a ``MoveTo`` then
returns to ``ready`` by joint interpolation. Every stage is deterministic. Expected outcome:
1 solution. Run: ``python examples/cartesian.py [--view]``
"""

from __future__ import annotations

from math import pi

from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view
from mtc.msgs import Header, Twist, TwistStamped, Vector3, Vector3Stamped


def make_task() -> core.Task:
    """The task: current state -> x +0.2 -> y -0.3 -> rz +45deg -> joint offset -> ready."""
    group = "panda_arm"

    # Cartesian and joint-space interpolation planners
    cartesian = core.CartesianPath()
    cartesian.max_cartesian_speed = 0.1  # m/s
    cartesian.cartesian_speed_limited_link = "panda_hand"
    jointspace = core.JointInterpolationPlanner()

    task = core.Task()
    task.name = "cartesian"
    task.add(stages.CurrentState("current state"))

    header = Header(frame_id="world")
    move = stages.MoveRelative("x +0.2", cartesian)
    move.group = group
    move.setDirection(Vector3Stamped(header=header, vector=Vector3(0.2, 0, 0)))
    task.add(move)

    move = stages.MoveRelative("y -0.3", cartesian)
    move.group = group
    move.setDirection(Vector3Stamped(header=header, vector=Vector3(0, -0.3, 0)))
    task.add(move)

    move = stages.MoveRelative("rz +45°", cartesian)
    move.group = group
    move.setDirection(TwistStamped(header=header, twist=Twist(angular=Vector3(0, 0, pi / 4.0))))
    task.add(move)

    # a relative motion given as joint offsets
    move = stages.MoveRelative("joint offset", cartesian)
    move.group = group
    move.setDirection({"panda_joint1": pi / 6, "panda_joint3": -pi / 6})
    task.add(move)

    move = stages.MoveTo("moveTo ready", jointspace)
    move.group = group
    move.setGoal("ready")
    task.add(move)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
