"""Compute inverse kinematics for a generated pose and connect to it.

As MTC's ``demo/scripts/compute_ik.py``: ``GeneratePose`` spawns a Cartesian pose 0.2 m in
front of the flange (``panda_link8`` z + 0.2) whenever the monitored "current state" has a
solution; ``ComputeIK`` wraps it and finds up to 4 arm configurations that put ``panda_link8``
there (its ``target_pose`` comes from the generator's interface: ``configureInitFrom(INTERFACE,
["target_pose"])``); ``Connect`` plans (OMPL) from the current state to each of them.
Expected outcome: at least 1 solution. Run: ``python examples/compute_ik.py [--view]``
"""

from __future__ import annotations

from mtc import core, stages

from _demo import run_example  # examples/_demo.py: plan, report, --view
from mtc.msgs import Header, PoseStamped


def make_task() -> core.Task:
    """The task: current state -> Connect -> ComputeIK(GeneratePose)."""
    task = core.Task()
    task.name = "compute IK"
    task.add(stages.CurrentState("current state"))

    planner = core.PipelinePlanner()
    task.add(stages.Connect("connect", [("panda_arm", planner)]))

    # a pose 0.2 m along the flange's z axis, relative to the flange
    pose = PoseStamped()
    pose.header.frame_id = "panda_link8"
    pose.pose.position.z = 0.2
    pose.pose.orientation.w = 1.0

    generator = stages.GeneratePose("cartesian pose")
    generator.setMonitoredStage(task["current state"])
    generator.pose = pose

    computeIK = stages.ComputeIK("compute IK", generator)
    computeIK.group = "panda_arm"
    computeIK.ik_frame = PoseStamped(header=Header(frame_id="panda_link8"))
    computeIK.max_ik_solutions = 4
    computeIK.properties.configureInitFrom(core.Stage.PropertyInitializerSource.INTERFACE, ["target_pose"])
    task.add(computeIK)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
