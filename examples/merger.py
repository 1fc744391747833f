"""Move two groups at the same time: a Merger container.

As MTC's ``demo/scripts/merger.py`` (the howto's "Merger" snippet): a ``Merger`` of two
``MoveTo`` stages, the hand to ``close`` and the arm to ``extended``, both by joint
interpolation. The merger joins the two trajectories, which use disjoint joints, into one that
moves hand and arm together. Expected outcome: 1 merged solution, whose trajectory moves the
arm and the fingers. Run: ``python examples/merger.py [--view]``
"""

from __future__ import annotations

from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view


def make_task() -> core.Task:
    """The task: current state, then Merger(hand -> close, arm -> extended)."""
    planner = core.JointInterpolationPlanner()

    task = core.Task()
    task.name = "merger"
    task.add(stages.CurrentState("current state"))

    # the merger plans for two parallel execution paths
    merger = core.Merger("Merger")

    moveTo1 = stages.MoveTo("Move To Home", planner)
    moveTo1.group = "hand"
    moveTo1.setGoal("close")
    merger.insert(moveTo1)

    moveTo2 = stages.MoveTo("Move To Ready", planner)
    moveTo2.group = "panda_arm"
    moveTo2.setGoal("extended")
    merger.insert(moveTo2)

    task.add(merger)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
