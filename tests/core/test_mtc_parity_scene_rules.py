"""MTC test scenarios that rest on MoveIt's planning-scene message rules (test_stage.cpp).

Each test is upstream's, with upstream's expectation; the docstring names the MoveIt rule.
"""

from __future__ import annotations

from mockups import ConnectMockup, new_scene

from mtc import msgs
from mtc.core import InterfaceState


def _spawn_object(scene, name, kind, pos=(0.0, 0.0, 0.0)):
    """MTC's spawnObject: one primitive at ``pos`` in the planning frame (ADD)."""
    o = msgs.CollisionObject()
    o.id = name
    o.header.frame_id = scene.planning_frame
    pose = msgs.Pose()
    pose.position.x, pose.position.y, pose.position.z = pos
    pose.orientation.w = 1.0
    o.primitive_poses = [pose]
    prim = msgs.SolidPrimitive()
    prim.type = kind
    prim.dimensions = {
        msgs.SolidPrimitive.CYLINDER: [0.1, 0.02],
        msgs.SolidPrimitive.BOX: [0.1, 0.2, 0.3],
        msgs.SolidPrimitive.SPHERE: [0.05],
    }[kind]
    o.primitives = [prim]
    o.operation = msgs.CollisionObject.ADD
    scene.apply_collision_object(o)


def _attach_object(scene, obj, link, attach):
    """MTC's attachObject: an AttachedCollisionObject message with the id only (ADD or REMOVE)."""
    aco = msgs.AttachedCollisionObject()
    aco.link_name = link
    aco.object.operation = msgs.CollisionObject.ADD if attach else msgs.CollisionObject.REMOVE
    aco.object.id = obj
    scene.apply_attached_collision_object(aco)


def test_connect_compatible():
    """test_stage.cpp Connect.compatible: upstream's exact sequence of scene edits.

    The last step ADDs a world object whose id is attached: MoveIt's processCollisionObjectAdd
    accepts that (it only replaces a *world* object of that id), and attaching it by id then
    replaces the attached body.
    """
    connect = ConnectMockup()

    def compatible(a, b):
        return connect.compatible(InterfaceState(a), InterfaceState(b))

    scene = new_scene()
    state = scene.current_state
    state.set_to_default_values()
    _spawn_object(scene, "object", msgs.SolidPrimitive.CYLINDER)

    other = scene.diff()
    assert compatible(scene, other), "identical scenes"

    _spawn_object(other, "object", msgs.SolidPrimitive.BOX)
    # upstream leaves this check commented out: shapes are not compared

    _spawn_object(other, "object", msgs.SolidPrimitive.CYLINDER, (0.1, 0, 0))
    assert not compatible(scene, other), "different pose"

    _spawn_object(other, "object", msgs.SolidPrimitive.CYLINDER)
    assert compatible(scene, other), "same objects"

    # attached objects
    other = scene.diff()
    _attach_object(scene, "object", "tip", True)
    assert not compatible(scene, other), "detached and attached object"

    other = scene.diff()
    assert compatible(scene, other), "identical scenes, attached object"

    # as MoveIt: ADD of an id that is attached adds a world object; attaching it replaces the attached body
    _spawn_object(other, "object", msgs.SolidPrimitive.CYLINDER, (0.1, 0, 0))
    _attach_object(other, "object", "tip", True)
    assert not compatible(scene, other), "different pose"


def test_object_given_by_its_primitive_pose_has_its_frame_there():
    """test_stage.cpp's spawnObject (and test_plan_generate_grasp_pose.cpp's) place a one-shape
    object through ``primitive_poses`` only and leave ``pose`` empty.

    MoveIt (PlanningScene::shapesAndPosesFromCollisionObjectMessage): with exactly one shape and
    an empty object pose, the shape's pose becomes the object's pose (the shape sits at identity
    in it), so the object's frame - what GenerateGraspPose and ik frames use - is at the shape.
    """
    scene = new_scene()
    o = msgs.CollisionObject()
    o.id = "object"
    o.header.frame_id = scene.planning_frame
    pose = msgs.Pose()
    pose.position.x, pose.position.y, pose.position.z = 0.53, 0.55, 0.84
    pose.orientation.w = 1.0
    o.primitive_poses = [pose]
    o.primitives = [msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[0.03])]
    o.operation = msgs.CollisionObject.ADD
    scene.apply_collision_object(o)

    assert list(scene.get_frame_transform("object")[:3, 3]) == [0.53, 0.55, 0.84]
