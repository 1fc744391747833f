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


def test_without_generator_compute_ik_is_still_the_first_child():
    """MTC creates ComputeIK "compute ik" with or without a generator, so the IK properties are
    exposed on the container either way and the generator can be inserted into it later."""
    for cls in (stages.SimpleGrasp, stages.SimpleUnGrasp):
        container = cls()
        ik = container["compute ik"]
        assert isinstance(ik, stages.ComputeIK) and list(container)[0] is ik
        assert ik.wrapped() is None
        for name in ("max_ik_solutions", "timeout", "ik_frame"):
            assert container.properties.hasProperty(name), (cls.__name__, name)
        container.max_ik_solutions = 3
        container.timeout = 0.5
        assert (container.max_ik_solutions, container.timeout) == (3, 0.5)


def test_children_of_simple_ungrasp():
    """Releasing runs the grasping steps in reverse, after ComputeIK."""
    ungrasp = stages.SimpleUnGrasp(stages.GeneratePlacePose("gen"), "UnGrasp")
    assert [c.name for c in ungrasp] == ["compute ik", "detach object", "open gripper", "forbid object collision"]
    assert stages.SimpleUnGrasp().name == "ungrasp"
    assert [c.name for c in stages.SimpleUnGrasp()] == ["compute ik", "detach object", "open gripper",
                                                        "forbid object collision"]


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


def test_generator_inserted_into_compute_ik_later(make_task, box_object):
    """SimpleGrasp() without a generator plans once one is inserted into its "compute ik"."""
    current = stages.CurrentState("current")
    grasp = stages.SimpleGrasp(name="Grasp")
    generator = _grasp_generator(current)
    generator.eef, generator.object = "hand", "object"  # not inherited: MTC configures only a given one
    grasp["compute ik"].insert(generator)
    grasp.setIKFrame(_top_grasp_frame())
    grasp.eef, grasp.object = "hand", "object"
    task = make_task(current, stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())]), grasp)
    assert task.plan()
    assert grasp["compute ik"].wrapped() is generator
    assert grasp.solutions[0].end.scene.attached_object_names == ["object"]
