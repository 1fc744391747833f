"""Spawn a predefined planning scene with a FixedState stage.

As MTC's ``demo/scripts/fixed_state.py``: the task loads the robot model first, so that a
``PlanningScene`` can be built from it, and the ``FixedState`` generator spawns that scene
(the robot at its default joint values, an empty world). Expected outcome: 1 solution of cost 0.
Run: ``python examples/fixed_state.py [--view]``
"""

from __future__ import annotations

import argparse
import mtc
from mtc import PlanningScene, core, stages


def make_task() -> core.Task:
    """The task: one FixedState stage holding a scene built from the task's robot model."""
    task = core.Task()
    task.name = "fixed state"
    task.loadRobotModel()  # usually done by init(); needed here to build the scene
    scene = PlanningScene(task.getRobotModel())

    fixed = stages.FixedState("fixed state")
    fixed.setState(scene)
    task.add(fixed)
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
