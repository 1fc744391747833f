"""Fall back from a Cartesian path to PTP to RRTConnect, per start state.

A port of MTC's ``demo/src/fallbacks_move_to.cpp``. Three start states (an ``Alternatives``
of ``FixedState`` stages) each need a different planner to reach ``ready`` with
``panda_joint1 = +tau/8``; a ``Fallbacks`` container tries, for every start state, a
``MoveTo`` with ``CartesianPath``, then with Pilz ``PTP``, then with OMPL ``RRTConnect``:

* (a) ``panda_joint1 = -tau/8``: close to the target in the workspace, a straight line works;
* (b) ``panda_joint1 = +tau/8``, ``panda_joint4`` at its upper limit (arm stretched): the
  line fails, a joint-space PTP motion is free of collisions;
* (c) as (a) plus a box between start and goal: only RRTConnect finds a way around.

Expected outcome: 3 solutions, (a) via "Cartesian path", (b) via "PTP path", (c) via
"RRT path". Run: ``python examples/fallbacks_move_to.py [--view]``
"""

from __future__ import annotations

import math

import mtc
from mtc import PlanningScene, core, stages
from mtc.msgs import CollisionObject, Pose, SolidPrimitive

from _demo import run_example  # examples/_demo.py: plan, report, --view

TAU = 2 * math.pi


def obstacle() -> CollisionObject:
    """A box 0.2 x 0.05 x 0.64 standing at (0.3, 0, 0.32), between the start and the goal."""
    box = CollisionObject()
    box.header.frame_id = "world"
    box.id = "box"
    box.primitives.append(SolidPrimitive(type=SolidPrimitive.BOX, dimensions=[0.2, 0.05, 0.64]))
    pose = Pose()
    pose.position.x, pose.position.z = 0.3, 0.32
    pose.orientation.w = 1.0
    box.primitive_poses.append(pose)
    box.operation = CollisionObject.ADD
    return box


def make_task() -> core.Task:
    """The task: Alternatives of three start states -> Fallbacks(Cartesian, PTP, RRT)."""
    task = core.Task()
    task.name = "fallback strategies in MoveTo"
    task.loadRobotModel()
    robot = task.getRobotModel()

    # planners, from the most constrained to the most general
    cartesian = core.CartesianPath()
    ptp = core.PipelinePlanner("pilz_industrial_motion_planner")
    ptp.planner = "PTP"
    rrtconnect = core.PipelinePlanner("ompl")
    rrtconnect.planner = "RRTConnectkConfigDefault"

    # the target of every Fallbacks child: 'ready' turned by tau/8 about the base
    ready = mtc.RobotState(robot)
    ready.set_to_default_values("panda_arm", "ready")
    target_state = dict(zip(robot.get_joint_model_group("panda_arm").active_joint_model_names,
                            ready.get_joint_group_positions("panda_arm")))
    target_state["panda_joint1"] = +TAU / 8

    # the start states
    initial_scene = PlanningScene(robot)
    initial_scene.current_state.set_to_default_values("panda_arm", "ready")
    initial_scene.current_state.set_to_default_values("hand", "open")

    initial_alternatives = core.Alternatives("initial states")

    scene = initial_scene.diff()
    scene.current_state.joint_positions = {"panda_joint1": -TAU / 8}
    fixed = stages.FixedState("close to target state in workspace")
    fixed.setState(scene)
    initial_alternatives.insert(fixed)

    scene = initial_scene.diff()
    # MTC sets panda_joint4 = 0, just beyond its upper limit (-0.0698), and relies on MoveIt's
    # start-state bounds fixing; mtc's planners refuse a start outside the bounds: use the bound
    scene.current_state.joint_positions = {"panda_joint1": +TAU / 8, "panda_joint4": -0.0698}
    fixed = stages.FixedState("directly reachable without collision")
    fixed.setState(scene)
    initial_alternatives.insert(fixed)

    scene = initial_scene.diff()
    scene.current_state.joint_positions = {"panda_joint1": -TAU / 8}
    scene.apply_collision_object(obstacle())
    fixed = stages.FixedState("getting to target requires collision avoidance")
    fixed.setState(scene)
    initial_alternatives.insert(fixed)

    task.add(initial_alternatives)

    # the fallbacks: each start state goes to the first planner that reaches the target
    fallbacks = core.Fallbacks("move to other side")
    for name, planner in (("Cartesian path", cartesian), ("PTP path", ptp), ("RRT path", rrtconnect)):
        move_to = stages.MoveTo(name, planner)
        move_to.group = "panda_arm"
        move_to.setGoal(target_state)
        fallbacks.insert(move_to)
    task.add(fallbacks)
    return task


def main(argv: list[str] | None = None) -> core.Task:
    """Plan the task headless and print the result; ``--view`` shows it in a browser."""
    return run_example(make_task, __doc__, argv)


if __name__ == "__main__":
    main()
