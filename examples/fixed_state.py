"""Spawn a predefined planning scene with a FixedState stage.

As MTC's ``demo/scripts/fixed_state.py``: the task loads the robot model first, so that a
``PlanningScene`` can be built from it, and the ``FixedState`` generator spawns that scene
(the robot at its default joint values, an empty world). Expected outcome: 1 solution of cost 0.
Run: ``python examples/fixed_state.py [--view]``
"""

from __future__ import annotations

from mtc import PlanningScene, core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view


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
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
