"""Tests of stages.ComputeIK: IK solutions for the target poses of a wrapped generator."""

from __future__ import annotations

import math

import numpy as np
import pytest

import mtc
from mtc import core, msgs, stages

TCP_OFFSET = 0.1034  # panda_hand -> finger tip centre


def _pose(frame="panda_link8", x=0.0, y=0.0, z=0.0, q=(0.0, 0.0, 0.0, 1.0)):
    return msgs.PoseStamped(
        header=msgs.Header(frame_id=frame),
        pose=msgs.Pose(position=msgs.Point(x=x, y=y, z=z), orientation=msgs.Quaternion(x=q[0], y=q[1], z=q[2], w=q[3])),
    )


def _ik_task(make_task, pose, configure=None, introspection=True, **ik_props):
    """The seed's compute_ik.py: CurrentState -> Connect -> ComputeIK(GeneratePose(pose))."""
    current = stages.CurrentState("current state")
    connect = stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())])
    generator = stages.GeneratePose("cartesian pose")
    generator.setMonitoredStage(current)
    generator.pose = pose
    ik = stages.ComputeIK("compute IK", generator)
    ik.group = "panda_arm"
    for k, v in ik_props.items():
        setattr(ik, k, v)
    ik.properties.configureInitFrom(core.Stage.PropertyInitializerSource.INTERFACE, ["target_pose"])
    if configure:
        configure(ik)
    return make_task(current, connect, ik, introspection=introspection), ik


def _grasp_ik_task(make_task):
    """CurrentState -> Connect -> ComputeIK(GenerateGraspPose) for eef ``hand`` around the world
    object ``object``, one grasp per half turn (comments ``3.141593`` and ``6.283185``)."""
    current = stages.CurrentState("current")
    g = stages.GenerateGraspPose("grasp")
    g.eef, g.object, g.pregrasp, g.angle_delta = "hand", "object", "open", math.pi
    g.setMonitoredStage(current)
    ik = stages.ComputeIK("ik", g)
    ik.eef = "hand"
    return make_task(current, stages.Connect("c", [("panda_arm", core.JointInterpolationPlanner())]), ik), ik


def _frame(solution, frame):
    return solution.end.scene.get_frame_transform(frame)


def _target(scene, pose):
    return scene.get_frame_transform(pose.header.frame_id) @ msgs.pose_to_matrix(pose.pose)


def test_defaults():
    """MTC's properties and defaults, plus seed and max_ik_attempts."""
    ik = stages.ComputeIK()
    assert ik.name == "IK" and ik.wrapped() is None
    assert ik.default_pose == ""
    assert ik.max_ik_solutions == 1
    assert ik.ignore_collisions is False
    assert ik.min_solution_distance == 0.1
    assert ik.constraints == msgs.Constraints()
    assert ik.seed == 0 and ik.max_ik_attempts == 20
    for name in ("eef", "group", "ik_frame", "target_pose", "timeout"):
        assert ik.properties.get(name, None) is None
    with pytest.raises(TypeError):
        ik.max_ik_solutions = -1
    with pytest.raises(TypeError):
        ik.ik_frame = 3


def test_target_pose_initialization_is_the_users_to_configure(make_task):
    """As in MTC, the constructor configures no source for target_pose, so a script may take it
    from the parent (or configure all properties from it); without any configuration the
    child's target_pose is still used (beyond MTC, which fails with "undefined")."""
    Source = core.Stage.PropertyInitializerSource
    ik = stages.ComputeIK("ik", stages.GeneratePose("gen"))
    assert not ik.properties.property("target_pose").initsFrom(Source.PARENT | Source.INTERFACE)
    ik.properties.configureInitFrom(Source.PARENT)  # every property from the parent
    assert ik.properties.property("target_pose").initsFrom(Source.PARENT)

    # PARENT: the container's target wins over the generator's
    reachable = _pose("panda_link8")
    parent_target = _pose("world", x=0.4, y=0.1, z=0.5, q=(1.0, 0.0, 0.0, 0.0))

    def from_parent(stage):
        stage.properties.property("target_pose").configureInitFrom(Source.PARENT)

    task, ik = _ik_task_without_interface(make_task, reachable, from_parent)
    task.properties.declare("target_pose", parent_target, "")
    assert task.plan()
    np.testing.assert_allclose(_frame(ik.solutions[0], "panda_link8")[:3, 3], [0.4, 0.1, 0.5], atol=1e-4)

    # no configuration: the generator's target
    task, ik = _ik_task_without_interface(make_task, reachable, None)
    assert task.plan()
    start = mtc.current_scene().get_frame_transform("panda_link8")
    np.testing.assert_allclose(_frame(ik.solutions[0], "panda_link8"), start, atol=1e-4)


def _ik_task_without_interface(make_task, pose, configure):
    current = stages.CurrentState("current state")
    generator = stages.GeneratePose("cartesian pose")
    generator.setMonitoredStage(current)
    generator.pose = pose
    ik = stages.ComputeIK("compute IK", generator)
    ik.group = "panda_arm"
    if configure:
        configure(ik)
    connect = stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())])
    return make_task(current, connect, ik), ik


def test_setters():
    """C++ setters: setIKFrame and setTargetPose overloads, and the scalar ones."""
    ik = stages.ComputeIK("ik", stages.GeneratePose())
    ik.setEndEffector("hand")
    ik.setGroup("panda_arm")
    ik.setMaxIKSolutions(3)
    ik.setIgnoreCollisions(True)
    ik.setMinSolutionDistance(0.5)
    assert (ik.eef, ik.group, ik.max_ik_solutions, ik.ignore_collisions, ik.min_solution_distance) == (
        "hand", "panda_arm", 3, True, 0.5)
    ik.setIKFrame("panda_hand")
    assert ik.ik_frame.header.frame_id == "panda_hand" and ik.ik_frame.pose.orientation.w == 1.0
    T = np.eye(4)
    T[2, 3] = TCP_OFFSET
    ik.setIKFrame(T, "panda_hand")
    assert ik.ik_frame.pose.position.z == pytest.approx(TCP_OFFSET)
    ik.setIKFrame(_pose("panda_link8", z=0.1))
    assert ik.ik_frame.header.frame_id == "panda_link8"
    ik.setTargetPose(T)
    assert ik.target_pose.header.frame_id == "" and ik.target_pose.pose.position.z == pytest.approx(TCP_OFFSET)
    ik.setTargetPose(T, "world")
    assert ik.target_pose.header.frame_id == "world"
    with pytest.raises(TypeError):
        ik.setIKFrame(1, 2, 3)


@pytest.mark.parametrize("props, message", [({"eef": "claw"}, "Unknown end effector: claw"),
                                            ({"group": "legs"}, "Unknown group: legs")])
def test_init_errors(make_task, props, message):
    """A defined but unknown eef / group is an init error naming the stage."""
    task, _ = _ik_task(make_task, _pose(z=0.1), **props)
    with pytest.raises(core.InitStageError, match=f"compute IK: {message}"):
        task.init()


def test_unknown_eef_and_group_are_two_init_errors(make_task):
    """MTC pushes one entry per problem."""
    task, _ = _ik_task(make_task, _pose(z=0.1), eef="claw", group="legs")
    with pytest.raises(core.InitStageError) as e:
        task.init()
    assert str(e.value).endswith("compute IK: Unknown end effector: claw\ncompute IK: Unknown group: legs\n")


def test_seed_compute_ik(make_task):
    """The seed's compute_ik.py (pose 0.2 m along panda_link8's z, 4 IK solutions): the IK frame
    reaches the target in every solution, the solutions are distinct and cost-ordered."""
    pose = _pose(z=0.2)
    task, ik = _ik_task(make_task, pose, ik_frame=_pose(), max_ik_solutions=4)
    assert task.plan()
    assert len(ik.solutions) == 4
    start = task["current state"].solutions[0].end.scene
    target = _target(start, pose)
    for s in ik.solutions:
        np.testing.assert_allclose(_frame(s, "panda_link8"), target, atol=1e-5)
    q = [s.end.scene.current_state.get_joint_group_positions("panda_arm") for s in ik.solutions]
    for i in range(4):
        for j in range(i):
            assert np.abs(q[i] - q[j]).sum() >= 0.1
    costs = [s.cost for s in ik.solutions]
    assert costs == sorted(costs)
    # cost = joint distance to the start state
    q0 = start.current_state.get_joint_group_positions("panda_arm")
    assert costs[0] == pytest.approx(np.abs(q[0] - q0).sum())
    assert task.numSolutions() == 4
    # timeout default: the group's IK timeout per allowed descent (4 solutions x 20 descents)
    ik_timeout = mtc.robots.panda().get_joint_model_group("panda_arm").default_ik_timeout
    assert ik.properties.get("timeout") == pytest.approx(ik_timeout * 80)


def test_eef_derives_group_and_link(make_task):
    """Only eef set: group = its parent group, IK link = its parent link (panda_link8)."""
    pose = _pose(z=0.1)
    task, ik = _ik_task(make_task, pose)
    ik.properties.set("group", None)  # (C++: set("group", boost::any()))
    ik.eef = "hand"
    assert task.plan()
    start = task["current state"].solutions[0].end.scene
    np.testing.assert_allclose(_frame(ik.solutions[0], "panda_link8"), _target(start, pose), atol=1e-5)


def test_ik_frame_with_offset(make_task):
    """ik_frame = the TCP (an offset on panda_hand): the TCP, not the link, reaches the target."""
    target = _pose("world", x=0.45, y=0.1, z=0.3, q=(1.0, 0.0, 0.0, 0.0))
    task, ik = _ik_task(make_task, target)
    ik.setIKFrame(_pose("panda_hand", z=TCP_OFFSET))
    assert task.plan()
    np.testing.assert_allclose(_frame(ik.solutions[0], "panda_hand_tcp"), _target(ik.solutions[0].end.scene, target),
                               atol=1e-5)


def test_ik_frame_on_attached_object_subframe(make_task):
    """ik_frame = a subframe of an object attached to the hand: that subframe reaches the target."""
    scene = mtc.current_scene()
    scene.apply_collision_object(msgs.CollisionObject(
        id="tool", header=msgs.Header(frame_id="panda_hand"),
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.02, 0.02, 0.1])],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        pose=msgs.Pose(position=msgs.Point(z=0.15), orientation=msgs.Quaternion(w=1.0)),
        subframe_names=["tip"],
        subframe_poses=[msgs.Pose(position=msgs.Point(z=0.05), orientation=msgs.Quaternion(w=1.0))],
        operation=msgs.CollisionObject.ADD))
    scene.attach_object("tool", "panda_hand", ["panda_leftfinger", "panda_rightfinger"])
    target = _pose("world", x=0.4, y=-0.1, z=0.3, q=(1.0, 0.0, 0.0, 0.0))
    task, ik = _ik_task(make_task, target, ik_frame=_pose("tool/tip"))
    assert task.plan()
    s = ik.solutions[0]
    np.testing.assert_allclose(_frame(s, "tool/tip"), _target(s.end.scene, target), atol=1e-5)


def test_default_pose_is_the_cost_reference(make_task):
    """default_pose 'extended': the cost is the joint distance to that named state."""
    task, ik = _ik_task(make_task, _pose(z=0.1), default_pose="extended")
    assert task.plan()
    model = mtc.robots.panda()
    ref = np.array([model.get_group_state("panda_arm", "extended")[f"panda_joint{i}"] for i in range(1, 8)])
    q = ik.solutions[0].end.scene.current_state.get_joint_group_positions("panda_arm")
    assert ik.solutions[0].cost == pytest.approx(np.abs(q - ref).sum())


def test_same_task_same_solutions(make_task):
    """Seeded restarts: the same task finds the same IK solutions."""

    def run():
        task, ik = _ik_task(make_task, _pose(z=0.2), max_ik_solutions=3)
        assert task.plan()
        return [s.end.scene.current_state.positions for s in ik.solutions]

    a, b = run(), run()
    assert len(a) == len(b) == 3
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)


def test_eef_in_collision(make_task, box):
    """An obstacle at the target: failure " eef in collision: a - b, c - d" (semantics §2.3,
    after the generator's empty comment; each pair's names in alphabetical order), no IK is tried."""
    mtc.current_scene().apply_collision_object(box("obstacle", (0.5, 0.0, 0.4), size=(0.12, 0.12, 0.12)))
    task, ik = _ik_task(make_task, _pose("world", x=0.5, y=0.0, z=0.4, q=(1.0, 0.0, 0.0, 0.0)),
                        ik_frame=_pose("panda_hand", z=TCP_OFFSET))
    assert not task.plan()
    (failure,) = ik.failures
    assert failure.comment.startswith(" eef in collision: obstacle - panda_hand")
    assert "obstacle - panda_leftfinger" in failure.comment
    assert [m.get("color") for m in failure.markers if m["type"] == "links"] == ["red"]


def test_eef_in_collision_comment_starts_with_the_upstream_comment(make_task, box):
    """The generator's comment (here GenerateGraspPose's angle) prefixes ComputeIK's failure comment."""
    mtc.current_scene().apply_collision_object(box("object", (0.5, 0.0, 0.4), size=(0.2, 0.2, 0.2)))
    task, ik = _grasp_ik_task(make_task)
    assert not task.plan()
    assert sorted(f.comment.split(" eef in collision: ")[0] for f in ik.failures) == ["3.141593", "6.283185"]


def test_eef_check_leaves_out_the_ik_link_moved_by_a_joint(make_task, sphere):
    """MTC's end-effector check allows the collisions of the IK link's rigid parent when a joint
    moves it (panda_link7 for the hand): an obstacle touching only link7 at the target passes
    that check, and the IK candidates reaching the target fail on it instead."""
    scene = mtc.current_scene()
    at_link7 = scene.current_state.get_global_link_transform("panda_link7")[:3, 3] + (0.05, 0.0, -0.07)
    scene.apply_collision_object(sphere("obstacle", tuple(at_link7), radius=0.015))
    assert scene.get_collisions() == [("panda_link7", "obstacle")]
    task, ik = _ik_task(make_task, _pose(), max_ik_attempts=3)  # the current pose of panda_link8
    assert not task.plan()
    comments = [f.comment for f in ik.failures]
    assert comments and not any("eef in collision" in c for c in comments), comments
    assert all(c.startswith("Collision between obstacle - panda_link") for c in comments), comments


def test_ignore_collisions_skips_the_checks(make_task, box):
    """ignore_collisions: the same blocked target is solved."""
    mtc.current_scene().apply_collision_object(box("obstacle", (0.5, 0.0, 0.4), size=(0.12, 0.12, 0.12)))
    task, ik = _ik_task(make_task, _pose("world", x=0.5, y=0.0, z=0.4, q=(1.0, 0.0, 0.0, 0.0)),
                        ik_frame=_pose("panda_hand", z=TCP_OFFSET), ignore_collisions=True)
    task.plan()  # Connect cannot reach a colliding state, but ComputeIK spawns it
    assert len(ik.solutions) == 1 and ik.numFailures() == 0
    assert ik.solutions[0].end.scene.is_state_colliding()


def test_no_ik_found(make_task):
    """An unreachable target (2 m away): failure " no IK found" (MTC's ``s.comment() + " no IK
    found"`` with the generator's empty comment)."""
    task, ik = _ik_task(make_task, _pose("world", x=2.0, z=0.5))
    assert not task.plan()
    assert [f.comment for f in ik.failures] == [" no IK found"]
    # as MTC, the end effector placed at the target is drawn red
    (eef,) = [m for m in ik.failures[0].markers if m["type"] == "links"]
    assert eef["ns"] == "ik target" and eef["color"] == "red"


def test_end_effector_marker_at_the_target(make_task):
    """Every solution carries MTC's "ik target" marker: the IK link's rigid parent and the
    links below it (panda_link7 down, for an ik_frame on panda_link8) placed as the solution
    has them, half transparent; besides the target and ik frames."""
    task, ik = _ik_task(make_task, _pose("world", x=0.4, z=0.4, q=(1.0, 0.0, 0.0, 0.0)))
    assert task.plan()
    solution = ik.solutions[0]
    names = [(m["ns"], m["name"]) for m in solution.markers]
    assert names[:2] == [(ik.markerNS(), "target frame"), (ik.markerNS(), "ik frame")]
    (eef,) = [m for m in solution.markers if m["type"] == "links"]
    assert eef["ns"] == "ik target" and eef["opacity"] == 0.5 and "color" not in eef
    state = solution.end.scene.current_state
    assert set(eef["links"]) == set(state.robot_model.descendant_link_names("panda_link7"))
    for link, T in eef["links"].items():
        np.testing.assert_allclose(T, state.get_global_link_transform(link), atol=1e-6)


def test_colliding_solution(make_task, sphere):
    """A sphere around the elbow of the start state: the candidate found from the start state is
    spawned as a failure "Collision between obstacle - <link>" (one contact)."""
    start = mtc.current_scene().current_state
    elbow = start.get_global_link_transform("panda_link4")[:3, 3]
    mtc.current_scene().apply_collision_object(sphere("obstacle", tuple(elbow), radius=0.08))
    task, ik = _ik_task(make_task, _pose(), max_ik_attempts=3)  # the current pose of panda_link8
    task.plan()
    comments = [f.comment for f in ik.failures]
    assert any(c.startswith("Collision between obstacle - panda_") for c in comments), comments


def test_constraints_violated(make_task):
    """A joint constraint the start configuration violates: failure "Constraints violated"."""
    constraints = msgs.Constraints(joint_constraints=[
        msgs.JointConstraint(joint_name="panda_joint1", position=1.0, tolerance_above=0.01, tolerance_below=0.01,
                             weight=1.0)])
    task, ik = _ik_task(make_task, _pose(), constraints=constraints, max_ik_attempts=3)
    assert not task.plan()
    assert "Constraints violated" in [f.comment for f in ik.failures]


@pytest.mark.parametrize(
    "pose, ik_frame, message",
    [
        (_pose("nowhere"), None, "Unknown reference frame for target pose: 'nowhere'"),
        (_pose(z=0.1), _pose("nowhere"), "ik frame unknown in robot: 'nowhere'"),
    ],
)
def test_unknown_frames(make_task, pose, ik_frame, message):
    """Unknown frames of the target pose or the IK frame are failures with MTC's words."""
    extra = {} if ik_frame is None else {"ik_frame": ik_frame}
    task, ik = _ik_task(make_task, pose, **extra)
    if pose.header.frame_id == "nowhere":
        # GeneratePose already fails on the unknown frame; give ComputeIK the pose directly
        ik.wrapped().pose = _pose(z=0.1)
        ik.setTargetPose(pose)
    assert not task.plan()
    assert [f.comment for f in ik.failures] == [message]


def test_ik_frame_in_the_planning_frame_is_the_root_link(make_task):
    """An ik_frame in the planning frame ("world"): a MoveIt robot state knows that frame as its
    root link, whose pose no arm joint moves, so the target finds no IK (not an unknown frame)."""
    task, ik = _ik_task(make_task, _pose(z=0.1), ik_frame=_pose("world"))
    assert not task.plan()
    assert [f.comment for f in ik.failures] == [" no IK found"]


def test_neither_eef_nor_group(make_task):
    """Without eef and group: failure "Neither eef nor group are well defined"."""
    task, ik = _ik_task(make_task, _pose(z=0.1))
    ik.properties.set("group", None)  # (C++: set("group", boost::any()))
    assert not task.plan()
    assert [f.comment for f in ik.failures] == ["Neither eef nor group are well defined"]


def test_group_without_end_effector_tip_fails_to_derive_the_link(make_task):
    """No eef and no ik_frame: the link is the group's one end-effector tip. "hand" holds no end
    effector's parent link (MoveIt attaches "hand" to the groups holding panda_link8), so MTC's
    failure; panda_arm_hand holds it and solves for panda_link8."""
    task, ik = _ik_task(make_task, _pose(z=0.1), group="hand")
    assert not task.plan()
    assert [f.comment for f in ik.failures] == ["Failed to derive IK target link"]
    task, ik = _ik_task(make_task, _pose(z=0.05), group="panda_arm_hand")
    assert task.plan()
    reached = ik.solutions[0].end.scene.current_state.get_global_link_transform("panda_link8")
    start = task["current state"].solutions[0].end.scene.current_state.get_global_link_transform("panda_link8")
    assert reached[:3, 3] == pytest.approx((start @ np.array([0, 0, 0.05, 1.0]))[:3], abs=1e-4)


def test_forwarded_properties_reach_the_ik_states(make_task):
    """ComputeIK copies its forwarded properties from the generator's state to its own states."""
    task, ik = _ik_task(make_task, _pose(z=0.1))
    ik.wrapped().setForwardedProperties(["extra"])
    ik.setForwardedProperties(["target_pose"])
    assert task.plan()
    assert ik.solutions[0].end.properties["target_pose"].pose.position.z == pytest.approx(0.1)


def test_unreachable_target_is_given_up_after_max_ik_attempts(make_task, monkeypatch):
    """A target none of the first max_ik_attempts descents reaches fails after those descents,
    not after max_ik_solutions x max_ik_attempts of them."""
    from mtc.planners import ik as ik_module

    descents = []
    solve = ik_module.IKSolver.solve

    def counting_solve(self, *args, **kwargs):
        descents.append(1)
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(ik_module.IKSolver, "solve", counting_solve)
    task, ik = _ik_task(make_task, _pose("world", x=2.0, z=0.5), max_ik_solutions=8, max_ik_attempts=3)
    assert not task.plan()
    assert [f.comment for f in ik.failures] == [" no IK found"]
    assert len(descents) == 3
