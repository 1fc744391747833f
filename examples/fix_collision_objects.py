"""Push world objects out of the robot with a FixCollisionObjects stage.

As MTC's ``demo/scripts/fix_collision_objects.py``: ``CurrentState`` followed by
``FixCollisionObjects`` with ``max_penetration = 0.01``. To show the stage at work, this
version first puts a box into the current scene that the hand's fingers penetrate by a few
millimetres; the stage moves it out of collision. Expected outcome: 1 solution, whose end
scene is collision free. Run: ``python examples/fix_collision_objects.py [--view]``
"""

from __future__ import annotations

import mtc
from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view
from mtc.msgs import Header, PoseStamped


def add_penetrating_box() -> None:
    """Put a thin box into the current scene, just touching the fingertips from below."""
    scene = mtc.current_scene(mtc.robots.panda())
    tcp = scene.current_state.get_global_link_transform("panda_hand_tcp")
    pose = PoseStamped(header=Header(frame_id="world"))
    pose.pose.position.x, pose.pose.position.y = tcp[0, 3], tcp[1, 3]
    # the box's top face lies 5 mm above the fingertips (0.02 m box, centred 5 mm lower)
    pose.pose.position.z = tcp[2, 3] - 0.005
    pose.pose.orientation.w = 1.0
    mtc.PlanningSceneInterface().add_box("box", pose, size=(0.2, 0.2, 0.02))


def make_task() -> core.Task:
    """The task: current state (with the box in it), then fix the collision."""
    add_penetrating_box()
    task = core.Task()
    task.name = "fix collision objects"
    task.add(stages.CurrentState("current state"))

    fix = stages.FixCollisionObjects("fix collision objects")
    fix.max_penetration = 0.01
    task.add(fix)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
