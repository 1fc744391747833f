"""Try several planners in turn with a MultiPlanner.

As MTC's ``demo/scripts/multi_planner.py``: a ``MultiPlanner`` that tries Pilz's PTP planner
first and OMPL's RRTConnect second, used by two ``MoveTo`` stages in an ``Alternatives``
container with the goals of ``alternatives.py``. Goal 2 is beyond panda_joint1's limit: Pilz
refuses it, and OMPL, as MoveIt's joint constraint, plans to the limit instead (with a warning
"Assuming minimum bounds instead"). Expected outcome: 2 solutions, one per goal, goal 2's
ending at the limit. Run: ``python examples/multi_planner.py [--view]``
"""

from __future__ import annotations

from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view


def make_task() -> core.Task:
    """The task: current state, then Alternatives of two MoveTo stages sharing a MultiPlanner."""
    pilz = core.PipelinePlanner("pilz_industrial_motion_planner")
    pilz.planner = "PTP"
    ompl = core.PipelinePlanner("ompl")
    ompl.planner = "RRTConnectkConfigDefault"

    # try PTP first; if it fails, RRTConnect
    multiPlanner = core.MultiPlanner()
    multiPlanner.add(pilz, ompl)

    task = core.Task()
    task.name = "multi planner"
    task.add(stages.CurrentState("current state"))

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
        "panda_joint1": -3.0,  # beyond the joint's limit (+-2.8973): planned to the limit
        "panda_joint2": -1.0,
        "panda_joint3": 0.0,
        "panda_joint4": -2.0,
        "panda_joint5": 1.0,
        "panda_joint6": 2.0,
        "panda_joint7": 0.5,
    }

    moveTo1 = stages.MoveTo("Move To Goal Configuration 1", multiPlanner)
    moveTo1.group = "panda_arm"
    moveTo1.setGoal(goalConfig1)
    alternatives.insert(moveTo1)

    moveTo2 = stages.MoveTo("Move To Goal Configuration 2", multiPlanner)
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
