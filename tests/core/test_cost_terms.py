"""Cost terms (mtc_semantics.md §5), ported from MTC's test_cost_terms.cpp, plus the trajectory terms."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from mockups import (
    BackwardMockup,
    ConnectMockup,
    ForwardMockup,
    GeneratorMockup,
    PredefinedCosts,
    new_scene,
    toy_model,
)

import mtc
from mtc import core
from mtc.core.storage import Interface, Priority

STAGE_COST = 7.0
TERM_COST = 1.0
TRAJECTORY_DURATION = 9.0


def GeneratorCostMockup():
    return GeneratorMockup(PredefinedCosts([STAGE_COST]))


def ConnectCostMockup():
    return ConnectMockup(PredefinedCosts.constant(STAGE_COST))


def ForwardCostMockup():
    return ForwardMockup(PredefinedCosts.constant(STAGE_COST))


def BackwardCostMockup():
    return BackwardMockup(PredefinedCosts.constant(STAGE_COST))


class ForwardTrajectoryMockup(ForwardMockup):
    """Sends a 2-waypoint trajectory of duration TRAJECTORY_DURATION with cost STAGE_COST."""

    def computeForward(self, from_state):
        self.runs += 1
        state = from_state.scene.current_state
        traj = mtc.RobotTrajectory(from_state.scene.robot_model, "")
        traj.add_suffix_waypoint(state.copy(), 0.0)
        traj.add_suffix_waypoint(state.copy(), TRAJECTORY_DURATION)
        self.sendForward(from_state, core.InterfaceState(from_state.scene.diff()),
                         core.SubTrajectory(traj, STAGE_COST))


def _flags_of(stage, first: bool):
    while isinstance(stage, core.ContainerBase):
        stage = stage[0] if first else stage[-1]
    return stage.requiredInterface()


def compute_with_stages(container, stages):
    """MTC's Standalone<T>: run one compute step of ``container`` fed with one state per open end."""
    from mtc.core.stage import END_IF_MASK, READS_END, READS_START, START_IF_MASK, WRITES_NEXT_START, WRITES_PREV_END

    container.clear()
    for s in stages:
        container.add(s)
    container._resetStage()
    flags = (_flags_of(container, True) & START_IF_MASK) | (_flags_of(container, False) & END_IF_MASK)
    dummy = Interface()
    container._prev_ends = dummy if flags & WRITES_PREV_END else None
    container._next_starts = dummy if flags & WRITES_NEXT_START else None
    container._initStage(toy_model())
    container._resolveInterface(flags)
    scene = new_scene()
    states = {}
    if flags & READS_START:
        states["start"] = core.InterfaceState(scene, Priority(1, 0.0))
        container.starts.add(states["start"])
    if flags & READS_END:
        states["end"] = core.InterfaceState(scene, Priority(1, 0.0))
        container.ends.add(states["end"])
    container._runCompute()
    return states


def test_solution_connected():
    """A cost term sees the solution connected to its states and creator."""
    container = core.SerialContainer()
    stage = ConnectCostMockup()
    seen = {}

    def term(s):
        seen["start"], seen["end"], seen["creator"] = s.start, s.end, s.creator
        return TERM_COST

    stage.setCostTerm(term)
    states = compute_with_stages(container, [stage])
    assert container.solutions[0].cost == TERM_COST, "custom CostTerm overwrites stage cost"
    assert container.internalToExternalMap()[seen["start"]] is states["start"]
    assert container.internalToExternalMap()[seen["end"]] is states["end"]
    assert seen["creator"] is stage


def test_lambda_cost_term():
    container = core.SerialContainer()
    stage = GeneratorCostMockup()
    stage.setCostTerm(lambda s: TERM_COST)
    compute_with_stages(container, [stage])
    assert container.solutions[0].cost == TERM_COST
    comment = "I want the user to see this"
    stage = GeneratorCostMockup()
    stage.setCostTerm(lambda s: (1.0, comment))
    compute_with_stages(container, [stage])
    sol = container.solutions[0]
    assert sol.cost == 1.0
    assert sol.solutions[0].comment == comment, "a cost term's comment reaches the solution"


def test_lambda_cost_term_with_comment_argument():
    # MTC's second overload: fn(sub_trajectory, comment) -> cost. The comment argument is the
    # term's (empty) output comment; a comment reaches the solution only through a returned pair.
    container = core.SerialContainer()
    stage = GeneratorCostMockup()
    seen = []

    def term(sub, comment):
        seen.append((sub.creator, comment))
        return 2.0 * TERM_COST

    stage.setCostTerm(term)
    compute_with_stages(container, [stage])
    assert container.solutions[0].cost == 2.0 * TERM_COST
    assert seen == [(stage, "")]
    stage = GeneratorCostMockup()
    stage.setCostTerm(lambda sub, comment: (1.0, "two-argument term"))
    compute_with_stages(container, [stage])
    assert container.solutions[0].solutions[0].comment == "two-argument term"


def test_lambda_cost_term_with_wrong_arity_fails_at_set():
    stage = GeneratorCostMockup()
    with pytest.raises(TypeError, match=r"\(sub_trajectory\) or \(sub_trajectory, comment\)"):
        stage.setCostTerm(lambda a, b, c: 0.0)
    with pytest.raises(TypeError, match=r"\(sub_trajectory\) or \(sub_trajectory, comment\)"):
        stage.setCostTerm(lambda: 0.0)


def test_cost_overwrite():
    container = core.SerialContainer()
    compute_with_stages(container, [GeneratorCostMockup()])
    assert container.solutions[0].cost == STAGE_COST, "return cost of stage by default"
    for term in (None, core.CostTerm()):
        stage = GeneratorCostMockup()
        stage.setCostTerm(term)
        compute_with_stages(container, [stage])
        assert container.solutions[0].cost == STAGE_COST, "None/plain cost term forwards cost"
    stage = GeneratorCostMockup()
    stage.setCostTerm(core.Constant(1.0))
    compute_with_stages(container, [stage])
    assert container.solutions[0].cost == 1.0, "custom cost overwrites stage cost"
    with pytest.raises(TypeError, match="setCostTerm"):
        stage.setCostTerm(42)
    # a cost term class (callable, but not a cost function) is named at the call, with the fix
    with pytest.raises(TypeError, match=r"got the class PathLength: write PathLength\(\)"):
        stage.setCostTerm(core.PathLength)
    assert isinstance(stage.costTerm(), core.Constant)  # the stage keeps its cost term


@pytest.mark.parametrize("make", [ConnectCostMockup, ForwardCostMockup, BackwardCostMockup])
def test_stage_types(make):
    container = core.SerialContainer()
    stage = make()
    stage.setCostTerm(core.Constant(1.0))
    compute_with_stages(container, [stage])
    assert container.solutions[0].cost == 1.0


class PassThrough(core.WrapperBase):
    def __init__(self, child=None):
        super().__init__("PassThrough", child)

    def onNewSolution(self, s):
        self.liftSolution(s)


def test_pass_through_uses_cost():
    container = PassThrough()
    stage = BackwardCostMockup()
    stage.setCostTerm(core.Constant(84.0))
    compute_with_stages(container, [stage])
    wrapped = container.solutions[0]
    assert isinstance(wrapped, core.WrappedSolution)
    assert wrapped.cost == 84.0 and wrapped.wrapped.cost == 84.0


def test_pass_through_overwrites_cost():
    container = PassThrough()
    stage = BackwardCostMockup()
    stage.setCostTerm(core.Constant(84.0))
    container.setCostTerm(core.Constant(72.0))
    compute_with_stages(container, [stage])
    wrapped = container.solutions[0]
    assert wrapped.cost == 72.0, "the wrapper can apply its own cost"
    assert wrapped.wrapped.cost == 84.0, "the child's cost is not affected"


def test_pass_through_can_modify_cost():
    container = PassThrough()
    stage = BackwardCostMockup()
    stage.setCostTerm(core.Constant(8.0))
    container.setCostTerm(lambda s: s.cost * s.cost)
    compute_with_stages(container, [stage])
    wrapped = container.solutions[0]
    assert wrapped.cost == 64.0 and wrapped.wrapped.cost == 8.0


def test_composite_solutions():
    container = core.SerialContainer()
    compute_with_stages(container, [ForwardCostMockup(), ForwardCostMockup()])
    assert container.solutions[0].cost == 2 * STAGE_COST, "by default stage costs are added"

    s1 = ForwardCostMockup()
    s1.setCostTerm(core.Constant(1.0))
    compute_with_stages(container, [s1, ForwardCostMockup()])
    assert container.solutions[0].cost == STAGE_COST + 1.0, "mix of explicit and implicit cost terms"

    s1, s2, s3 = ForwardCostMockup(), ForwardCostMockup(), ForwardCostMockup()
    s1.setCostTerm(core.Constant(1.0))
    s2.setCostTerm(core.Constant(1.0))
    s3.setCostTerm(core.Constant(9.0))
    c1 = core.SerialContainer()
    c1.add(s1, s2)
    compute_with_stages(container, [c1, s3])
    assert container.solutions[0].cost == 2 * 1.0 + 9.0, "cost aggregation across levels"


def test_composite_solutions_container_cost():
    """A TrajectoryCostTerm on a container sums over all leaves of nested sequences."""
    container = core.SerialContainer()
    s1, s2, s3 = ForwardTrajectoryMockup(), ForwardTrajectoryMockup(), ForwardTrajectoryMockup()
    c1 = core.SerialContainer()
    c1.add(s1, s2)
    container.setCostTerm(core.TrajectoryDuration())
    compute_with_stages(container, [c1, s3])
    assert container.solutions[0].cost == 3 * TRAJECTORY_DURATION
    assert s1.solutions[0].cost == STAGE_COST, "child cost is not affected"


def test_python_cost_term_subclass():
    """A Python CostTerm receives the whole solution; a TrajectoryCostTerm only the leaves."""
    container = core.SerialContainer()
    kinds = []

    class Whole(core.CostTerm):
        def __call__(self, solution):
            kinds.append(type(solution).__name__)
            return 3.0, "whole"

    class Leaves(core.TrajectoryCostTerm):
        def __call__(self, solution):
            kinds.append(type(solution).__name__)
            return 2.0, "leaf"

    container.setCostTerm(Whole())
    compute_with_stages(container, [ForwardCostMockup(), ForwardCostMockup()])
    assert kinds == ["SolutionSequence"]
    assert container.solutions[0].cost == 3.0 and container.solutions[0].comment == "whole"
    kinds.clear()
    container.setCostTerm(Leaves())
    compute_with_stages(container, [ForwardCostMockup(), ForwardCostMockup()])
    assert kinds == ["SubTrajectory", "SubTrajectory"]
    assert container.solutions[0].cost == 4.0
    assert container.solutions[0].comment == "leaf, leaf"


def test_infinite_cost_term_makes_failure(t):
    t.add(GeneratorMockup([1.0]))
    fwd = ForwardMockup([1.0])
    fwd.setCostTerm(lambda s: math.inf)
    t.add(fwd)
    assert not t.plan()
    assert fwd.numFailures() == 1


# --- trajectory cost terms on hand-built trajectories ---------------------------------------


def _traj(points, group="", times=None):
    model = toy_model()
    ref = mtc.RobotState(model)
    return mtc.RobotTrajectory.from_positions(model, group, ref, np.asarray(points, dtype=float), times)


def _sub(traj, start=None, end=None):
    s = core.SubTrajectory(traj)
    scene = new_scene()
    s._start = core.InterfaceState(scene) if start is None else start
    s._end = core.InterfaceState(scene) if end is None else end
    return s


def test_path_length():
    traj = _traj([[0, 0, 0], [0.5, 0, 0], [0.5, 0.25, 0.1]])
    assert core.PathLength()(_sub(traj)) == pytest.approx(0.5 + 0.25 + 0.1)
    assert core.PathLength(["base-link1-joint"])(_sub(traj)) == pytest.approx(0.5)
    assert core.PathLength({"link1-link2-joint": 2.0, "unknown": 5.0})(_sub(traj)) == pytest.approx(0.5)
    assert core.PathLength()(_sub(None)) == 0.0


def test_path_length_wraps_continuous_joints():
    traj = _traj([[3.0, 0, 0], [-3.0, 0, 0]])
    assert core.PathLength(["base-link1-joint"])(_sub(traj)) == pytest.approx(2 * math.pi - 6.0)


def test_path_length_sums_sequences():
    a = _sub(_traj([[0, 0, 0], [1, 0, 0]]))
    b = _sub(_traj([[1, 0, 0], [1, 0.5, 0]]))
    seq = core.SolutionSequence([a, b])
    cost, _ = core.PathLength()._evaluate(seq)
    assert cost == pytest.approx(1.5)
    cost, _ = core.PathLength()._evaluate(core.WrappedSolution(None, seq))
    assert cost == pytest.approx(1.5)


def test_trajectory_duration():
    traj = _traj([[0, 0, 0], [1, 0, 0]], times=[0.0, 2.5])
    assert core.TrajectoryDuration()(_sub(traj)) == pytest.approx(2.5)
    assert core.TrajectoryDuration()(_sub(None)) == 0.0


def test_distance_to_reference():
    ref = {"base-link1-joint": 1.0}
    traj = _traj([[0, 0, 0], [1, 0, 0]])
    # trajectory mode: mean over waypoints (distances 1 and 0)
    assert core.DistanceToReference(ref)(_sub(traj)) == pytest.approx(0.5)
    # start interface: the start state (all zero)
    term = core.DistanceToReference(ref, core.TrajectoryCostTerm.Mode.START_INTERFACE)
    assert term(_sub(traj)) == pytest.approx(1.0)
    weighted = core.DistanceToReference(ref, weights={"base-link1-joint": 3.0})
    assert weighted(_sub(traj)) == pytest.approx(1.5)


def test_link_motion_and_rotation():
    # the toy joints rotate about x and the links have identity origins: the tip does not move
    traj = _traj([[0, 0, 0], [0.5, 0, 0]])
    assert core.LinkMotion("tip")(_sub(traj)) == pytest.approx(0.0, abs=1e-9)
    assert core.LinkRotation("tip")(_sub(traj)) == pytest.approx(0.5)
    cost, comment = core.LinkMotion("nowhere")(_sub(traj))
    assert cost == math.inf and comment == "LinkMotionCost: frame 'nowhere' unknown in trajectory"
    cost, comment = core.LinkRotation("nowhere")(_sub(traj))
    assert cost == math.inf and comment == "LinkRotationCost: frame 'nowhere' unknown in trajectory"


def test_clearance_on_the_panda():
    """Clearance: 1 / (d + 1e-5) of the distance to the world, with a comment naming the pair."""
    from mtc import msgs

    panda = mtc.robots.panda()
    scene = mtc.PlanningScene(panda)
    scene.current_state.set_to_default_values("panda_arm", "ready")
    box = msgs.CollisionObject(id="box", header=msgs.Header(frame_id="world"), operation=msgs.CollisionObject.ADD)
    box.primitives = [msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.1, 0.1, 0.1])]
    box.primitive_poses = [msgs.Pose(position=msgs.Point(x=0.6, y=0.0, z=0.3), orientation=msgs.Quaternion(w=1.0))]
    scene.apply_collision_object(box)
    sol = _sub(None, start=core.InterfaceState(scene), end=core.InterfaceState(scene))
    cost, comment = core.Clearance()(sol)
    d = scene.distance_to_collision()
    assert 0 < d < 1
    assert cost == pytest.approx(1.0 / (d + 1e-5))
    assert comment.startswith(f"Clearance: distance {d!r} between '") and "'box'" in comment
    cost, comment = core.Clearance(cumulative=True)(sol)
    assert comment.startswith("Clearance: cumulative distance")


def test_clearance_of_a_colliding_state_is_a_failure_in_every_mode():
    """As MTC: a penetrating pair makes the cost infinite with the collision comment, also when
    the distances are summed (the sum of all pairs can stay positive), and a group property
    naming no group measures the whole robot."""
    from mtc import msgs

    panda = mtc.robots.panda()
    scene = mtc.PlanningScene(panda)
    scene.current_state.set_to_default_values("panda_arm", "extended")
    ball = msgs.CollisionObject(id="ball", header=msgs.Header(frame_id="world"), operation=msgs.CollisionObject.ADD)
    ball.primitives = [msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[0.1])]
    ball.primitive_poses = [msgs.Pose(position=msgs.Point(z=0.85), orientation=msgs.Quaternion(w=1.0))]
    scene.apply_collision_object(ball)
    pairs = scene.collision_distances(group="panda_arm")
    assert pairs[0][0] < 0 < sum(p[0] for p in pairs)  # summed, the penetration would hide
    state = core.InterfaceState(scene)
    sol = _sub(None, start=state, end=state)
    for cumulative in (False, True):
        cost, comment = core.Clearance(cumulative=cumulative)(sol)
        assert cost == math.inf
        assert comment == f"Clearance: allegedly valid solution collides between '{pairs[0][1]}' and '{pairs[0][2]}'"
    traj = mtc.RobotTrajectory(panda, "panda_arm")
    traj.add_suffix_waypoint(scene.current_state)
    cost, _ = core.Clearance(cumulative=True)(_sub(traj, start=state, end=state))
    assert cost == math.inf
    state.properties["group"] = "no_such_group"
    cost, comment = core.Clearance()(sol)
    assert cost == math.inf and "'ball'" in comment


def test_solution_to_msg(t):
    """toMsg(): one SubTrajectory message per leaf in execution order, with costs and comments."""
    t.add(BackwardMockup([10.0]))
    t.add(GeneratorMockup([1.0]))
    t.add(ForwardMockup([100.0]))
    assert t.plan()
    msg = t.solutions[0].toMsg()
    assert [s.info.cost for s in msg.sub_trajectory] == [10.0, 1.0, 100.0]
    # as MTC: a diff where the end scene derives from the start scene (generator: the same
    # scene; forward: a diff), else the full end scene (backward: the start derives from the end)
    assert [s.scene_diff.is_diff for s in msg.sub_trajectory] == [False, True, True]


def test_clearance_with_nothing_to_measure_is_infinite_distance_and_no_cost():
    """An empty world leaves Clearance nothing to measure: the distance reads as infinite and
    the cost as 0, summed or not (porting.md: MTC's cumulative sum over no pairs gives 1e5)."""
    panda = mtc.robots.panda()
    scene = mtc.PlanningScene(panda)
    state = core.InterfaceState(scene)
    sol = _sub(None, start=state, end=state)
    assert core.Clearance()(sol) == (0.0, "Clearance: distance inf between '' and ''")
    assert core.Clearance(cumulative=True)(sol) == (0.0, "Clearance: cumulative distance inf")


def test_clearance_along_no_trajectory_is_no_cost():
    """Trajectory mode on a solution without waypoints (a generator's) measures nothing: cost 0
    with a comment, as DistanceToReference gives 0 there (MTC would divide by zero), and a task
    with that cost term still plans."""
    panda = mtc.robots.panda()
    scene = mtc.PlanningScene(panda)
    state = core.InterfaceState(scene)
    term = core.Clearance(mode=core.TrajectoryCostTerm.Mode.TRAJECTORY)
    for traj in (None, mtc.RobotTrajectory(panda, "panda_arm")):
        assert term(_sub(traj, start=state, end=state)) == (0.0, "Clearance: no trajectory waypoints to measure")
    reference = core.DistanceToReference({"panda_joint1": 1.0}, core.TrajectoryCostTerm.Mode.TRAJECTORY)
    assert reference(_sub(None, start=state, end=state)) == 0.0
    task = core.Task()
    task.loadRobotModel(panda)
    current = mtc.stages.CurrentState("current")
    current.setCostTerm(term)
    task.add(current)
    assert task.plan() and task.solutions[0].cost == 0.0


def test_cost_term_arguments_of_the_wrong_kind_are_named():
    """Arguments the terms would turn into something else silently ('no' into True, 5 into the
    property '5', None into the link 'None') or fail on later are refused when the term is made."""
    cases = [
        (lambda: core.Clearance(with_world="no"), "Clearance with_world must be True or False, got 'no'"),
        (lambda: core.Clearance(group_property=5), "Clearance group_property must be a property name"),
        (lambda: core.LinkMotion(None), "LinkMotion: link_name must be a link name"),
        (lambda: core.PathLength(5), "PathLength takes joint names or {joint: weight}, got 5"),
        (lambda: core.SerialContainer("s").findChild(None), "findChild() takes a stage name or path"),
    ]
    for make, text in cases:
        with pytest.raises(TypeError, match=re.escape(text)):
            make()
    assert core.Clearance(with_world=0).with_world is False  # a number reads as a flag, as pybind11's caster
