"""Tests of stages.SimpleGrasp / SimpleUnGrasp: children, inherited and forwarded properties, effects."""

from __future__ import annotations

import math

import numpy as np
import pytest

import mtc
from mtc import core, msgs, stages

HAND_LINKS = ["panda_hand", "panda_leftfinger", "panda_rightfinger"]


def _top_grasp_frame():
    """The seed's ik frame: between the fingers, grasping from the top."""
    ik_frame = msgs.PoseStamped()
    ik_frame.header.frame_id = "panda_hand"
    ik_frame.pose.position.z = 0.1034
    ik_frame.pose.orientation.x = 1.0
    return ik_frame


@pytest.fixture
def box_object(box):
    """The seed's box "object" floating in front of the robot."""
    mtc.current_scene().apply_collision_object(box("object", (0.307, 0.0, 0.285), size=(0.1, 0.05, 0.03)))


def _grasp_generator(monitored):
    g = stages.GenerateGraspPose("grasp pose")
    g.angle_delta = math.pi / 2
    g.pregrasp, g.grasp = "open", "close"
    g.setMonitoredStage(monitored)
    return g


def test_children_of_simple_grasp():
    """ComputeIK 'compute ik' (wrapping the generator) first, then allow collision, close, attach."""
    g = stages.GenerateGraspPose("gen")
    grasp = stages.SimpleGrasp(g, "Grasp")
    assert grasp.name == "Grasp"
    assert [c.name for c in grasp] == ["compute ik", "allow object collision", "close gripper", "attach object"]
    assert isinstance(grasp["compute ik"], stages.ComputeIK)
    assert grasp["compute ik"].wrapped() is g
    assert isinstance(grasp["close gripper"], stages.MoveTo)
    assert stages.SimpleGrasp().name == "grasp"


def test_without_generator_there_is_no_compute_ik():
    """As MTC: ComputeIK "compute ik" wraps a given generator only. Without one the container
    grasps (releases) at the states that reach it, and exposes no IK properties."""
    assert [c.name for c in stages.SimpleGrasp()] == ["allow object collision", "close gripper", "attach object"]
    assert [c.name for c in stages.SimpleUnGrasp()] == ["detach object", "open gripper", "forbid object collision"]
    for cls in (stages.SimpleGrasp, stages.SimpleUnGrasp):
        container = cls()
        for name in ("max_ik_solutions", "ik_frame"):  # ("timeout" is every stage's)
            assert not container.properties.hasProperty(name), (cls.__name__, name)
        for name in ("eef", "object", "group", "goal"):
            assert container.properties.hasProperty(name), (cls.__name__, name)


def test_children_of_simple_ungrasp():
    """Releasing runs the grasping steps in reverse, after ComputeIK."""
    ungrasp = stages.SimpleUnGrasp(stages.GeneratePlacePose("gen"), "UnGrasp")
    assert [c.name for c in ungrasp] == ["compute ik", "detach object", "open gripper", "forbid object collision"]
    assert stages.SimpleUnGrasp().name == "ungrasp"


def test_simple_grasp_base_is_abstract():
    """Semantics §4.6: SimpleGraspBase is abstract; its subclasses are the stages to use."""
    with pytest.raises(TypeError, match="SimpleGraspBase is abstract.*SimpleGrasp or SimpleUnGrasp"):
        stages.SimpleGraspBase("x")

    class Mine(stages.SimpleGraspBase):
        def __init__(self):
            super().__init__("mine")
            self._setup(None, True)

    assert [c.name for c in Mine()] == [c.name for c in stages.SimpleGrasp(None)]


def test_properties():
    """eef/object declared; ComputeIK's max_ik_solutions, timeout, ik_frame and the MoveTo's
    group, goal exposed; the grasp properties are forwarded by every child."""
    grasp = stages.SimpleGrasp(stages.GenerateGraspPose("gen"))
    for name in ("eef", "object", "max_ik_solutions", "timeout", "ik_frame", "group", "goal", "pregrasp", "grasp"):
        assert grasp.properties.hasProperty(name), name
    assert grasp.max_ik_solutions == 1
    grasp.setMaxIKSolutions(4)
    grasp.setIKFrame(_top_grasp_frame())
    assert grasp.ik_frame.pose.position.z == pytest.approx(0.1034)
    grasp.setIKFrame("panda_hand")
    assert grasp.ik_frame.header.frame_id == "panda_hand"
    grasp.setEndEffector("hand")
    grasp.setObject("object")
    assert (grasp.eef, grasp.object) == ("hand", "object")
    names = ["eef", "grasp", "object", "pregrasp"]
    assert grasp.forwarded_properties == names
    for child in [grasp["compute ik"], grasp["compute ik"].wrapped(), *list(grasp)[1:]]:
        assert child.forwarded_properties == names, child.name


def test_unknown_eef_is_an_init_error(make_task, box_object):
    """An unknown end effector on the container is named at init."""
    current = stages.CurrentState("current")
    grasp = stages.SimpleGrasp(_grasp_generator(current), "Grasp")
    grasp.eef, grasp.object = "claw", "object"
    task = make_task(current, stages.Connect("c", [("panda_arm", core.JointInterpolationPlanner())]), grasp)
    with pytest.raises(core.InitStageError, match="Grasp: unknown end effector: claw"):
        task.init()


def test_grasp_reaches_closes_and_attaches(make_task, box_object):
    """The seed's SimpleGrasp set-up: the TCP is at the box, the hand closed, the box attached to
    the eef's parent link and allowed to touch the hand links; the properties reach ComputeIK."""
    current = stages.CurrentState("current")
    grasp = stages.SimpleGrasp(_grasp_generator(current), "Grasp")
    grasp.setIKFrame(_top_grasp_frame())
    grasp.eef, grasp.object = "hand", "object"
    task = make_task(current, stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())]), grasp)
    assert task.plan()
    ik = grasp["compute ik"]
    assert ik.eef == "hand" and ik.object == "object" and ik.ik_frame.header.frame_id == "panda_hand"
    assert grasp["compute ik"].wrapped().object == "object"  # generator inherits from ComputeIK
    # the two grasps across the box's long side collide with it
    assert len(ik.solutions) == 2
    assert all("eef in collision" in f.comment for f in ik.failures)

    end = grasp.solutions[0].end
    scene = end.scene
    assert scene.attached_object_names == ["object"]
    assert scene.get_attached_object("object").link == "panda_link8"
    assert scene.current_state.joint_positions["panda_finger_joint1"] == pytest.approx(0.0)
    acm = scene.allowed_collision_matrix
    assert all(acm.get_entry("object", link) for link in HAND_LINKS)
    # the object did not move relative to the start: the TCP was at its centre when grasping
    tcp = scene.current_state.get_global_link_transform("panda_hand_tcp")
    np.testing.assert_allclose(tcp[:3, 3], [0.307, 0.0, 0.285], atol=1e-5)
    np.testing.assert_allclose(scene.get_frame_transform("object")[:3, 3], [0.307, 0.0, 0.285], atol=1e-6)
    # grasp properties travel with the state to the end of the container
    assert end.properties["grasp"] == "close" and end.properties["pregrasp"] == "open"


def test_ungrasp_detaches_and_opens(make_task, ready_scene):
    """SimpleUnGrasp at a place pose: object detached where it was placed, hand open, collisions
    between hand and object forbidden again; the posture comes from the container."""
    scene = ready_scene.diff()
    scene.current_state.set_to_default_values("hand", "close")
    scene.apply_collision_object(msgs.CollisionObject(
        id="object", header=msgs.Header(frame_id="panda_hand"),
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.02, 0.02, 0.04])],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        pose=msgs.Pose(position=msgs.Point(z=0.1034), orientation=msgs.Quaternion(w=1.0)),
        operation=msgs.CollisionObject.ADD))
    scene.attach_object("object", "panda_link8")
    scene.allowed_collision_matrix.set_entry("object", HAND_LINKS, True)
    holding = stages.FixedState("holding", scene)

    place_pose = msgs.PoseStamped(header=msgs.Header(frame_id="world"))
    place_pose.pose.position.x, place_pose.pose.position.y, place_pose.pose.position.z = 0.4, -0.2, 0.3
    place_pose.pose.orientation.w = 1.0
    gen = stages.GeneratePlacePose("place pose")
    gen.setMonitoredStage(holding)
    gen.object, gen.pose = "object", place_pose
    ungrasp = stages.SimpleUnGrasp(gen, "UnGrasp")
    ungrasp.eef, ungrasp.object = "hand", "object"
    ungrasp.pregrasp = "open"
    task = make_task(holding, stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())]), ungrasp)
    assert task.plan()
    end_scene = ungrasp.solutions[0].end.scene
    assert end_scene.attached_object_names == []
    np.testing.assert_allclose(end_scene.get_frame_transform("object")[:3, 3], [0.4, -0.2, 0.3], atol=1e-5)
    assert end_scene.current_state.joint_positions["panda_finger_joint1"] == pytest.approx(0.035)
    acm = end_scene.allowed_collision_matrix
    assert not any(acm.get_entry("object", link) for link in HAND_LINKS)


def _hand_around_object_scene(ready_scene, closed: bool):
    """The ready pose with a 2 cm cube "object" between the fingers (at the TCP), the hand
    open or closed."""
    scene = ready_scene.diff()
    scene.current_state.set_to_default_values("hand", "close" if closed else "open")
    tcp = scene.current_state.get_global_link_transform("panda_hand_tcp")[:3, 3]
    scene.apply_collision_object(msgs.CollisionObject(
        id="object", header=msgs.Header(frame_id="world"),
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.02, 0.02, 0.02])],
        primitive_poses=[msgs.Pose(position=msgs.Point(x=tcp[0], y=tcp[1], z=tcp[2]),
                                   orientation=msgs.Quaternion(w=1.0))],
        operation=msgs.CollisionObject.ADD))
    return scene


def test_grasp_without_generator_closes_and_attaches_where_the_hand_is(make_task, ready_scene):
    """SimpleGrasp(None) after a state with the object between the open fingers: as MTC, it
    propagates that state, closes the gripper and attaches the object; the arm does not move."""
    start = _hand_around_object_scene(ready_scene, closed=False)
    grasp = stages.SimpleGrasp(None, "Grasp")
    grasp.eef, grasp.object = "hand", "object"
    grasp.properties.set("grasp", "close")
    task = make_task(stages.FixedState("start", start), grasp)
    assert task.plan()
    end = grasp.solutions[0].end.scene
    assert end.attached_object_names == ["object"]
    assert end.get_attached_object("object").link == "panda_link8"
    assert end.current_state.joint_positions["panda_finger_joint1"] == pytest.approx(0.0)
    arm = start.robot_model.get_joint_model_group("panda_arm").variable_names
    np.testing.assert_allclose([end.current_state.joint_positions[j] for j in arm],
                               [start.current_state.joint_positions[j] for j in arm])


def test_ungrasp_of_an_object_that_is_not_attached_goes_on(make_task, ready_scene):
    """As MTC, whose detach callback ignores MoveIt's refusal: releasing an object that is not
    attached leaves it where it is, and the hand still opens."""
    start = _hand_around_object_scene(ready_scene, closed=True)
    start.allowed_collision_matrix.set_entry("object", HAND_LINKS, True)
    ungrasp = stages.SimpleUnGrasp(None, "UnGrasp")
    ungrasp.eef, ungrasp.object = "hand", "object"
    ungrasp.pregrasp = "open"
    task = make_task(stages.FixedState("start", start), ungrasp)
    assert task.plan()
    end = ungrasp.solutions[0].end.scene
    assert end.attached_object_names == [] and "object" in end.world_object_names
    assert end.current_state.joint_positions["panda_finger_joint1"] == pytest.approx(0.035)
    assert not any(end.allowed_collision_matrix.get_entry("object", link) for link in HAND_LINKS)
