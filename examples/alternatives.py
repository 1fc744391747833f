"""Plan alternative paths with an Alternatives container.

As MTC's ``demo/scripts/alternatives.py`` (the howto's "Alternatives" snippet): two
``MoveTo`` stages in an ``Alternatives`` container, each to a joint-space goal, both by joint
interpolation. Goal 2 sets ``panda_joint1 = -3.0``, outside its limit of +-2.8973, so only
goal 1 is reachable. Expected outcome: 1 solution, through "Move To Goal Configuration 1";
"Move To Goal Configuration 2" fails. Run: ``python examples/alternatives.py [--view]``
"""

from __future__ import annotations

from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view


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
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
