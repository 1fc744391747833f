"""Fall back to another planner when the first one fails: a Fallbacks container.

As MTC's ``demo/scripts/fallbacks.py`` (the howto's "Fallbacks" snippet): two ``MoveTo``
stages to the named pose ``extended``, the first with ``CartesianPath`` (a straight line of the
hand), the second with joint interpolation. ``Fallbacks`` tries its children in order and
keeps the first that succeeds. Expected outcome: 1 solution, from whichever child succeeds
first. Run: ``python examples/fallbacks.py [--view]``
"""

from __future__ import annotations

from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view


def make_task() -> core.Task:
    """The task: current state, then Fallbacks(Cartesian MoveTo, joint-interpolation MoveTo)."""
    jointPlanner = core.JointInterpolationPlanner()
    cartesianPlanner = core.CartesianPath()

    task = core.Task()
    task.name = "fallbacks"
    task.add(stages.CurrentState("current state"))

    # fall back to a different planner if motion generation fails with the primary one
    fallbacks = core.Fallbacks("Fallbacks")

    moveTo1 = stages.MoveTo("Move To Goal Configuration 1", cartesianPlanner)
    moveTo1.group = "panda_arm"
    moveTo1.setGoal("extended")
    fallbacks.insert(moveTo1)

    moveTo2 = stages.MoveTo("Move To Goal Configuration 2", jointPlanner)
    moveTo2.group = "panda_arm"
    moveTo2.setGoal("extended")
    fallbacks.insert(moveTo2)

    task.add(fallbacks)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
