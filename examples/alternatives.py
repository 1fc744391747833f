"""Plan alternative paths with an Alternatives container.

As MTC's ``demo/scripts/alternatives.py`` (the howto's "Alternatives" snippet): two
``MoveTo`` stages in an ``Alternatives`` container, each to a joint-space goal, both by joint
interpolation. Goal 2 sets ``panda_joint1 = -3.0``, outside its limit of +-2.8973, so only
goal 1 is reachable. Expected outcome: 1 solution, through "Move To Goal Configuration 1";
"Move To Goal Configuration 2" fails. Run: ``python examples/alternatives.py [--view]``
"""

from __future__ import annotations

import argparse
import mtc
from mtc import core, stages


def make_task() -> core.Task:
    """The task: current state, then Alternatives of two joint-space goals."""
    jointPlanner = core.JointInterpolationPlanner()

    task = core.Task()
    task.name = "alternatives"
    task.add(stages.CurrentState("current state"))

    # the alternatives stage supports multiple execution paths
    alternatives = core.Alternatives("Alternatives")

    goalConfig1 = {
        "panda_joint1": 1.0,
        "panda_joint2": -1.0,
        "panda_joint3": 0.0,
        "panda_joint4": -2.5,
        "panda_joint5": 1.0,
        "panda_joint6": 1.0,
        "panda_joint7": 1.0,
    }
    goalConfig2 = {
        "panda_joint1": -3.0,  # beyond the joint's limit (+-2.8973): this goal is invalid
        "panda_joint2": -1.0,
        "panda_joint3": 0.0,
        "panda_joint4": -2.0,
        "panda_joint5": 1.0,
        "panda_joint6": 2.0,
        "panda_joint7": 0.5,
    }

    moveTo1 = stages.MoveTo("Move To Goal Configuration 1", jointPlanner)
    moveTo1.group = "panda_arm"
    moveTo1.setGoal(goalConfig1)
    alternatives.insert(moveTo1)

    moveTo2 = stages.MoveTo("Move To Goal Configuration 2", jointPlanner)
    moveTo2.group = "panda_arm"
    moveTo2.setGoal(goalConfig2)
    alternatives.insert(moveTo2)

    task.add(alternatives)
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
