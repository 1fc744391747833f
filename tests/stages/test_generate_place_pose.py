"""Tests of stages.GeneratePlacePose: place poses of an attached object, turned about the vertical."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mtc import core, msgs, stages
from mtc.stages.generate_place_pose import place_pose_turns, place_poses

PLACE = (0.5, -0.3, 0.4)


def _prim(kind, dims):
    return msgs.SolidPrimitive(type=kind, dimensions=list(dims))


def _object_msg(name, primitive):
    return msgs.CollisionObject(
        id=name,
        header=msgs.Header(frame_id="panda_hand"),
        primitives=[primitive],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        pose=msgs.Pose(position=msgs.Point(z=0.1034), orientation=msgs.Quaternion(w=1.0)),
        operation=msgs.CollisionObject.ADD,
    )


@pytest.fixture
def holding(ready_scene):
    """``holding(primitive, attached=True)``: the ready scene with an object "object" held in the hand."""

    def make(primitive=None, attached=True):
        scene = ready_scene.diff()
        primitive = primitive or _prim(msgs.SolidPrimitive.CYLINDER, [0.1, 0.02])
        scene.apply_collision_object(_object_msg("object", primitive))
        if attached:
            scene.attach_object("object", "panda_hand", ["panda_leftfinger", "panda_rightfinger"])
        return scene

    return make


def _place_pose(frame="world"):
    x, y, z = PLACE
    return msgs.PoseStamped(
        header=msgs.Header(frame_id=frame),
        pose=msgs.Pose(position=msgs.Point(x=x, y=y, z=z), orientation=msgs.Quaternion(w=1.0)),
    )


def _task(make_task, scene, generator, introspection=True):
    fixed = stages.FixedState("holding", scene)
    fixed.ignore_collisions = True  # a not attached object overlaps the fingers
    generator.setMonitoredStage(fixed)
    connect = stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())])
    return make_task(fixed, connect, generator, introspection=introspection)


def _generator(**props):
    g = stages.GeneratePlacePose("place pose")
    g.object = "object"
    g.pose = _place_pose()
    for k, v in props.items():
        setattr(g, k, v)
    return g


def test_defaults():
    """Name "Generate Place Pose" (the Python binding's), allow_z_flip False, object/pose undefined, eef settable."""
    g = stages.GeneratePlacePose()
    assert g.name == "Generate Place Pose"
    assert g.allow_z_flip is False
    assert g.properties.get("object", None) is None
    g.eef = "hand"
    g.setObject("thing")
    assert (g.eef, g.object) == ("hand", "thing")


@pytest.mark.parametrize(
    "shape, turns",
    [
        (_prim(msgs.SolidPrimitive.CYLINDER, [0.1, 0.02]), (10, None)),
        (_prim(msgs.SolidPrimitive.SPHERE, [0.02]), (10, None)),
        (_prim(msgs.SolidPrimitive.BOX, [0.05, 0.05, 0.1]), (4, None)),
        (_prim(msgs.SolidPrimitive.BOX, [0.05, 0.03, 0.1]), (2, None)),
        (_prim(msgs.SolidPrimitive.CONE, [0.1, 0.02]), (1, 1)),
    ],
)
def test_turns_per_shape(shape, turns):
    """Cylinder/sphere 10 turns, square box 4, other box 2, anything else: nominal + flipped."""
    assert place_pose_turns([shape]) == turns


def test_two_shapes_are_other():
    """An object of several shapes: nominal and flipped only."""
    box = _prim(msgs.SolidPrimitive.BOX, [0.05, 0.05, 0.1])
    assert place_pose_turns([box, box]) == (1, 1)


def test_turns_are_evenly_spaced():
    """Fix of MTC's cumulative rotation: the i-th pose is turned by exactly i * 2pi/n about world z,
    through the pose's own origin."""
    nominal = np.eye(4)
    nominal[:3, 3] = PLACE
    poses = place_poses(nominal, 0, 10)
    assert len(poses) == 10
    for i, T in enumerate(poses):
        angle = i * 2 * math.pi / 10
        np.testing.assert_allclose(T[:3, 3], PLACE)
        np.testing.assert_allclose(T[:3, :3], [[math.cos(angle), -math.sin(angle), 0],
                                               [math.sin(angle), math.cos(angle), 0], [0, 0, 1]], atol=1e-12)
    flipped = place_poses(nominal, 1, 4)
    assert len(flipped) == 8
    np.testing.assert_allclose(flipped[4][:3, :3], np.diag([1.0, -1.0, -1.0]), atol=1e-12)


@pytest.mark.parametrize(
    "primitive, flip, count",
    [
        (_prim(msgs.SolidPrimitive.CYLINDER, [0.1, 0.02]), False, 10),
        (_prim(msgs.SolidPrimitive.CYLINDER, [0.1, 0.02]), True, 20),
        (_prim(msgs.SolidPrimitive.BOX, [0.05, 0.03, 0.1]), False, 2),
        (_prim(msgs.SolidPrimitive.CONE, [0.1, 0.02]), False, 2),
    ],
)
def test_spawned_states(make_task, holding, primitive, flip, count):
    """One state per pose; target_pose in the planning frame, ik_frame = the object's frame."""
    g = _generator(allow_z_flip=flip)
    task = _task(make_task, holding(primitive), g)
    assert task.plan()
    assert len(g.solutions) == count
    for solution in g.solutions:
        props = solution.end.properties
        target = props["target_pose"]
        assert target.header.frame_id == "world"
        np.testing.assert_allclose(msgs.pose_to_matrix(target.pose)[:3, 3], PLACE, atol=1e-12)
        assert props["ik_frame"].header.frame_id == "object"
        assert solution.cost == 0.0


def test_pose_in_another_frame(make_task, holding):
    """A pose given in a link frame is converted to the planning frame."""
    g = _generator()
    g.pose = msgs.PoseStamped(header=msgs.Header(frame_id="panda_link0"),
                              pose=msgs.Pose(position=msgs.Point(x=0.4), orientation=msgs.Quaternion(w=1.0)))
    task = _task(make_task, holding(), g)
    assert task.plan()
    target = g.solutions[0].end.properties["target_pose"]
    assert target.header.frame_id == "world"
    assert target.pose.position.x == pytest.approx(0.4)


@pytest.mark.parametrize(
    "attached, obj, message",
    [
        (True, "ghost", "frame 'ghost' is not known"),
        (False, "object", "frame 'object' is not attached to the robot"),
    ],
)
def test_object_must_be_attached(make_task, holding, attached, obj, message):
    """Unknown or not attached object: a failure naming it."""
    g = _generator(object=obj)
    task = _task(make_task, holding(attached=attached), g)
    assert not task.plan()
    assert [f.comment for f in g.failures] == [message]


def test_subframe_or_robot_link_as_object(make_task, holding):
    """MTC takes any frame on the robot: a subframe of the held object or a robot link. Only an
    attached object named itself has a shape to turn by, so the others get the fallback: the
    pose and its flip, with ik_frame at that frame."""
    scene = holding()
    msg = _object_msg("object", _prim(msgs.SolidPrimitive.CYLINDER, [0.1, 0.02]))
    msg.subframe_names = ["tip"]
    msg.subframe_poses = [msgs.Pose(position=msgs.Point(z=0.05), orientation=msgs.Quaternion(w=1.0))]
    scene.apply_collision_object(msg)
    scene.attach_object("object", "panda_hand", ["panda_leftfinger", "panda_rightfinger"])
    for obj, count in [("object", 10), ("object/tip", 2), ("panda_hand", 2)]:
        g = _generator(object=obj)
        task = _task(make_task, scene, g)
        task.plan()
        assert len(g.solutions) == count, obj
        assert not g.failures
        frames = {s.end.properties["ik_frame"].header.frame_id for s in g.solutions}
        assert frames == {obj}
        if count == 2:  # the nominal pose, then flipped half a turn about x
            second = msgs.pose_to_matrix(g.solutions[1].end.properties["target_pose"].pose)
            np.testing.assert_allclose(second[:3, :3], np.diag([1.0, -1.0, -1.0]), atol=1e-12)


def test_unknown_pose_frame(make_task, holding):
    """The place pose in an unknown frame: failure "Unknown frame: 'X'"."""
    g = _generator()
    g.pose = _place_pose("nowhere")
    task = _task(make_task, holding(), g)
    assert not task.plan()
    assert [f.comment for f in g.failures] == ["Unknown frame: 'nowhere'"]


def test_init_errors(make_task, holding):
    """object and pose undefined: both named at init."""
    g = stages.GeneratePlacePose("place pose")
    task = _task(make_task, holding(), g)
    with pytest.raises(core.InitStageError) as e:
        task.init()
    assert "place pose: Property 'object': undefined" in str(e.value)
    assert "place pose: Property 'pose': undefined" in str(e.value)
