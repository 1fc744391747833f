"""Start a task from the current state of the robot: the smallest MTC task.

``CurrentState`` copies the process-wide current scene (arm at ``ready``, hand ``open``,
empty world: the stand-in for ``move_group``'s monitored scene) into the task. Expected
outcome: 1 solution of cost 0. Run: ``python examples/current_state.py [--view]``
"""

from __future__ import annotations


from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view


def make_task() -> core.Task:
    """The task: a single CurrentState stage."""
    task = core.Task()
    task.name = "current state"
    task.add(stages.CurrentState("current state"))
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
