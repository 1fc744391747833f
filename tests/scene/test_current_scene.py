"""Tests of mtc.scene.current_scene: the process-wide current scene and PlanningSceneInterface."""

from __future__ import annotations

import re

import numpy as np
import pytest
from scene_helpers import pose, snapshot, translation, write_cube_stl

import mtc
from mtc import msgs
from mtc.msgs import Header, PoseStamped, SolidPrimitive
from mtc.scene.current_scene import PlanningSceneInterface, current_scene, reset_current_scene, set_current_scene
from mtc.scene.planning_scene import PlanningScene

READY = [0, -0.785, 0, -2.356, 0, 1.571, 0.785]


@pytest.fixture(autouse=True)
def fresh_current_scene():
    """Each test starts and ends without a current scene."""
    reset_current_scene()
    yield
    reset_current_scene()


def stamped(xyz, frame="world", quat=(0.0, 0.0, 0.0, 1.0)) -> PoseStamped:
    return PoseStamped(header=Header(frame_id=frame), pose=pose(xyz, quat))


# ---------------------------------------------------------------------------- the current scene
def test_current_scene_starts_at_ready_and_open_with_an_empty_world(panda):
    """The default current scene is the Panda at ready with the hand open, no objects."""
    scene = current_scene()
    assert scene.robot_model is panda
    np.testing.assert_allclose(scene.current_state.positions, [*READY, 0.035, 0.035])
    assert scene.world_object_names == [] and scene.attached_object_names == []
    assert not scene.is_state_colliding()


def test_current_scene_is_one_object_until_reset(panda):
    """current_scene() returns the same scene; edits stay; reset_current_scene() starts afresh."""
    scene = current_scene()
    assert current_scene() is scene and current_scene(panda) is scene
    scene.current_state.joint_positions = {"panda_joint1": 1.0}
    assert current_scene().current_state.positions[0] == 1.0
    reset_current_scene()
    fresh = current_scene()
    assert fresh is not scene
    assert fresh.current_state.positions[0] == 0.0


def test_top_level_exports():
    """mtc exports current_scene, reset_current_scene and PlanningSceneInterface."""
    assert mtc.current_scene is current_scene
    assert mtc.reset_current_scene is reset_current_scene
    assert mtc.PlanningSceneInterface is PlanningSceneInterface


def test_another_robot_model_starts_a_new_scene(panda, toy):
    """Asking for another model replaces the current scene; a model without named states starts at defaults."""
    scene = current_scene()
    toy_scene = current_scene(toy)
    assert toy_scene is not scene and toy_scene.robot_model is toy
    np.testing.assert_array_equal(toy_scene.current_state.positions, [0.0, 0.0, 0.0])
    assert current_scene() is toy_scene  # no model: whatever is current
    with pytest.raises(TypeError, match="RobotModel"):
        current_scene("panda")


def test_replacing_a_scene_with_objects_warns(panda, toy, caplog):
    """A new robot model's scene does not carry the old scene's objects: a warning names them
    (a box added before the other robot's scene was asked for would otherwise vanish silently)."""
    PlanningSceneInterface().add_box("crate", stamped((0.5, 0.0, 0.2)), size=(0.1, 0.1, 0.1))
    with caplog.at_level("WARNING"):
        toy_scene = current_scene(toy)
    assert toy_scene.world_object_names == []
    assert "objects of the old one (crate) are not in it" in caplog.text
    caplog.clear()
    with caplog.at_level("WARNING"):
        current_scene(panda)  # the toy's scene had no objects: nothing to warn about
    assert caplog.text == ""


def test_set_current_scene(panda):
    """set_current_scene makes a scene current; only scenes are accepted."""
    scene = PlanningScene(panda)
    set_current_scene(scene)
    assert current_scene() is scene
    with pytest.raises(TypeError, match="PlanningScene"):
        set_current_scene("scene")


# ---------------------------------------------------------------------------- PlanningSceneInterface
def test_add_box_sphere_cylinder_cone():
    """add_* put one primitive of the given size at the given pose into the current scene."""
    psi = PlanningSceneInterface(ns="", synchronous=True)
    psi.add_box("box", stamped((0.5, 0.0, 0.1)), size=(0.1, 0.2, 0.3))
    psi.add_sphere("ball", stamped((0.5, 0.3, 0.1)), radius=0.05)
    psi.add_cylinder("can", stamped((0.5, -0.3, 0.1)), height=0.2, radius=0.04)
    psi.add_cone("cone", stamped((0.6, -0.3, 0.1)), height=0.2, radius=0.04)
    scene = current_scene()
    assert scene.world_object_names == ["ball", "box", "can", "cone"]  # sorted by id, as MoveIt's map
    expected = {
        "box": (SolidPrimitive.BOX, [0.1, 0.2, 0.3], [0.5, 0.0, 0.1]),
        "ball": (SolidPrimitive.SPHERE, [0.05], [0.5, 0.3, 0.1]),
        "can": (SolidPrimitive.CYLINDER, [0.2, 0.04], [0.5, -0.3, 0.1]),
        "cone": (SolidPrimitive.CONE, [0.2, 0.04], [0.6, -0.3, 0.1]),
    }
    for name, (kind, dims, xyz) in expected.items():
        wo = scene.get_world_object(name)
        assert wo.shapes[0].type == kind and wo.shapes[0].dimensions == dims
        np.testing.assert_allclose(translation(wo.pose @ wo.shape_poses[0]), xyz)


def test_add_box_default_size_and_plain_pose():
    """size defaults to a 1 m cube; a Pose without header is in the planning frame."""
    psi = PlanningSceneInterface()
    psi.add_box("big", pose((3.0, 0.0, 0.0)))
    wo = current_scene().get_world_object("big")
    assert wo.shapes[0].dimensions == [1.0, 1.0, 1.0]
    np.testing.assert_allclose(translation(wo.pose), [3.0, 0.0, 0.0])
    with pytest.raises(TypeError, match="PoseStamped"):
        psi.add_box("bad", (1.0, 0.0, 0.0))


def test_add_box_in_a_link_frame():
    """A PoseStamped in a link frame places the box relative to that link."""
    PlanningSceneInterface().add_box("at_tcp", stamped((0.0, 0.0, 0.0), frame="panda_hand_tcp"), size=(0.02, 0.02, 0.02))
    scene = current_scene()
    np.testing.assert_allclose(
        scene.get_frame_transform("at_tcp"), scene.current_state.get_global_link_transform("panda_hand_tcp"), atol=1e-12
    )


def test_add_mesh_from_a_file(tmp_path):
    """add_mesh loads an STL, scaled by size, and it collides where placed."""
    path = write_cube_stl(tmp_path / "cube.stl", 0.02)
    psi = PlanningSceneInterface()
    psi.add_mesh("mesh", stamped((0.307, 0.0, 0.56)), path, size=(2.0, 2.0, 2.0))
    scene = current_scene()
    mesh = scene.get_world_object("mesh").shapes[0]
    assert isinstance(mesh, msgs.Mesh) and len(mesh.triangles) == 12
    assert max(p.x for p in mesh.vertices) == pytest.approx(0.02)
    assert scene.is_state_colliding()
    psi.remove_world_object("mesh")
    psi.add_mesh("mesh", stamped((0.307, 0.3, 0.56)), path)
    assert not scene.is_state_colliding()


def test_add_mesh_missing_file_changes_nothing(tmp_path):
    """A missing mesh file names the file and leaves the scene as it was."""
    psi = PlanningSceneInterface()
    psi.add_box("b", stamped((1.0, 0.0, 0.0)))
    before = snapshot(current_scene())
    with pytest.raises(FileNotFoundError, match=r"object 'mesh': mesh file '.*missing.stl' not found"):
        psi.add_mesh("mesh", stamped((0.0, 0.0, 0.0)), str(tmp_path / "missing.stl"))
    assert snapshot(current_scene()) == before


@pytest.mark.parametrize("size, error, words", [
    (0.001, TypeError, "must be 3 numbers, got 0.001"),
    ((1.0, 1.0), ValueError, "must be 3 finite numbers > 0, got (1.0, 1.0)"),
    ((1.0, -1.0, 1.0), ValueError, "must be 3 finite numbers > 0"),
    ((0.0, 0.0, 0.0), ValueError, "must be 3 finite numbers > 0"),
])
def test_add_mesh_checks_its_scale_as_add_box_its_size(tmp_path, size, error, words):
    """A mesh's size (its scale) is 3 finite numbers > 0: otherwise an error naming the object,
    not a misleading "cannot read mesh file" or Python's "not iterable"; nothing is added."""
    path = write_cube_stl(tmp_path / "cube.stl", 0.02)
    psi = PlanningSceneInterface()
    with pytest.raises(error, match=re.escape(f"object 'mesh': the mesh scale (size) {words}")):
        psi.add_mesh("mesh", stamped((0.3, 0.0, 0.5)), path, size=size)
    with pytest.raises(error, match=re.escape(f"object 'held': the mesh scale (size) {words}")):
        psi.attach_mesh("panda_hand", "held", stamped((0.0, 0.0, 0.1)), path, size=size)
    with pytest.raises(TypeError, match="object 'mesh': the mesh file name must be a path, got None"):
        psi.add_mesh("mesh", stamped((0.3, 0.0, 0.5)), None)
    assert current_scene().world_object_names == [] and current_scene().attached_object_names == []


def test_bad_sizes_name_the_object_and_change_nothing():
    """Non-positive sizes raise ValueError naming the object; nothing is added."""
    psi = PlanningSceneInterface()
    with pytest.raises(ValueError, match=r"'flat'.*box"):
        psi.add_box("flat", stamped((1.0, 0.0, 0.0)), size=(0.1, 0.1, 0.0))
    with pytest.raises(ValueError, match=r"'ball'.*sphere"):
        psi.add_sphere("ball", stamped((1.0, 0.0, 0.0)), radius=-1.0)
    assert current_scene().world_object_names == []


def test_remove_world_object_one_and_all(caplog):
    """remove_world_object(name) removes one; with no name every world object; an unknown name
    is logged and changes nothing (as moveit_commander, which raises nothing)."""
    psi = PlanningSceneInterface()
    for i in range(3):
        psi.add_box(f"b{i}", stamped((1.0 + i, 0.0, 0.0)))
    psi.remove_world_object("b1")
    assert psi.get_known_object_names() == ["b0", "b2"]
    psi.remove_world_object("b1")
    assert psi.get_known_object_names() == ["b0", "b2"]
    assert re.search(r"'b1'.*b0, b2", caplog.text)
    psi.remove_world_object()
    assert psi.get_known_object_names() == []


def test_attach_box_and_remove_attached_object():
    """attach_box attaches a new box to a link (touch links honoured); removing it detaches it into the world."""
    psi = PlanningSceneInterface()
    psi.attach_box("panda_hand", "held", stamped((0.0, 0.0, 0.1034), frame="panda_hand"), size=(0.02, 0.08, 0.02),
                   touch_links=["panda_leftfinger", "panda_rightfinger"])  # fmt: skip
    scene = current_scene()
    assert scene.attached_object_names == ["held"]
    att = scene.get_attached_object("held")
    assert att.link == "panda_hand" and att.touch_links == {"panda_leftfinger", "panda_rightfinger"}
    tcp = scene.current_state.get_global_link_transform("panda_hand_tcp")
    np.testing.assert_allclose(scene.get_frame_transform("held"), tcp, atol=1e-12)
    assert not scene.is_state_colliding()
    # with the arm moved, detaching leaves the box where the hand took it
    scene.current_state.joint_positions = {"panda_joint1": 0.5}
    moved = scene.get_frame_transform("held")
    psi.remove_attached_object("panda_hand", "held")
    assert scene.attached_object_names == [] and scene.world_object_names == ["held"]
    np.testing.assert_allclose(scene.get_frame_transform("held"), moved, atol=1e-12)


def test_names_are_one_name_a_list_or_none():
    """touch_links and object_ids take one name, a list of names or None (attach_box's
    touch_links=None: the link itself); anything else names the argument, and nothing changes."""
    psi = PlanningSceneInterface()
    psi.add_box("box", stamped((0.6, 0.0, 0.0)), size=(0.05, 0.05, 0.05))
    psi.attach_box("panda_hand", "held", stamped((0.0, 0.0, 0.1), frame="panda_hand"), size=(0.02, 0.02, 0.02),
                   touch_links=None)  # fmt: skip
    scene = current_scene()
    assert scene.get_attached_object("held").touch_links == {"panda_hand"}
    assert list(psi.get_objects("box")) == ["box"]  # one name, not its letters
    assert list(psi.get_attached_objects("held")) == ["held"]
    assert list(psi.get_object_poses("box")) == ["box"]
    before = snapshot(scene)
    with pytest.raises(TypeError, match="touch_links must be a name or a list of names, got 5"):
        scene.attach_object("box", "panda_hand", touch_links=5)
    with pytest.raises(TypeError, match=re.escape("touch_links must be a name or a list of names, got 3 in ['panda_hand', 3]")):
        scene.attach_object("box", "panda_hand", touch_links=["panda_hand", 3])
    with pytest.raises(TypeError, match="object_ids must be a name or a list of names, got 7"):
        psi.get_objects(7)
    assert snapshot(scene) == before


def test_attach_box_without_a_pose_attaches_the_existing_object():
    """As moveit_commander: attach_box(link, name) attaches the world object ``name`` where it is,
    with ``[link]`` as touch links; an unknown name changes nothing."""
    psi = PlanningSceneInterface()
    psi.add_box("puck", stamped((0.5, 0.0, 0.1)), size=(0.05, 0.05, 0.01))
    scene = current_scene()
    before = scene.get_frame_transform("puck")
    psi.attach_box("panda_link8", "puck")
    assert scene.attached_object_names == ["puck"] and scene.world_object_names == []
    att = scene.get_attached_object("puck")
    assert att.link == "panda_link8" and att.touch_links == {"panda_link8"}
    assert att.object.shapes[0].dimensions == [0.05, 0.05, 0.01]
    np.testing.assert_allclose(scene.get_frame_transform("puck"), before, atol=1e-12)
    psi.attach_box("panda_link8", "ghost")  # logged, as MoveIt
    assert scene.attached_object_names == ["puck"] and scene.world_object_names == []


def test_attach_box_at_the_link_origin():
    """A pose in the link's frame at its origin puts the box there."""
    psi = PlanningSceneInterface()
    psi.attach_box("panda_link8", "puck", stamped((0.0, 0.0, 0.0), frame="panda_link8"), size=(0.05, 0.05, 0.01))
    scene = current_scene()
    np.testing.assert_allclose(
        scene.get_frame_transform("puck"), scene.current_state.get_global_link_transform("panda_link8"), atol=1e-12
    )


def test_attach_box_to_an_unknown_link_changes_nothing(caplog):
    """Attaching to an unknown link logs it and the links, and adds nothing."""
    psi = PlanningSceneInterface()
    psi.attach_box("panda_palm", "b", stamped((0.0, 0.0, 0.0), frame="panda_palm"), size=(0.1, 0.1, 0.1))
    assert psi.get_known_object_names() == [] and current_scene().attached_object_names == []
    assert re.search(r"'panda_palm'.*panda_hand", caplog.text)


def test_remove_attached_object_of_a_link_and_all(caplog):
    """remove_attached_object(link) detaches that link's objects; () detaches all; a name that
    is not attached is logged and changes nothing."""
    psi = PlanningSceneInterface()
    psi.attach_box("panda_hand", "a", stamped((0.0, 0.0, 0.0), frame="panda_hand"), size=(0.01, 0.01, 0.01))
    psi.attach_box("panda_link5", "b", stamped((0.0, 0.0, 0.0), frame="panda_link5"), size=(0.01, 0.01, 0.01))
    psi.attach_box("panda_link5", "c", stamped((0.0, 0.0, 0.0), frame="panda_link5"), size=(0.01, 0.01, 0.01))
    psi.remove_attached_object("panda_link5")
    scene = current_scene()
    assert scene.attached_object_names == ["a"]
    psi.remove_attached_object(name="zz")
    assert scene.attached_object_names == ["a"] and re.search(r"'zz'.*not attached.*a", caplog.text)
    psi.remove_attached_object()
    assert scene.attached_object_names == []
    assert sorted(scene.world_object_names) == ["a", "b", "c"]


def test_queries():
    """get_known_object_names, get_objects, get_attached_objects and get_object_poses."""
    psi = PlanningSceneInterface()
    psi.add_box("box", stamped((0.5, 0.0, 0.1), quat=(0.0, 0.0, np.sin(0.2), np.cos(0.2))), size=(0.1, 0.2, 0.3))
    psi.add_sphere("ball", stamped((0.5, 0.3, 0.1)), radius=0.05)
    psi.attach_box("panda_hand", "held", stamped((0.0, 0.0, 0.0), frame="panda_hand"), size=(0.01, 0.01, 0.01))
    assert psi.get_known_object_names() == ["ball", "box"]  # world objects only, as MoveIt
    objects = psi.get_objects()
    assert sorted(objects) == ["ball", "box"]
    assert isinstance(objects["box"], msgs.CollisionObject)
    assert objects["box"].primitives[0].dimensions == [0.1, 0.2, 0.3]
    assert objects["box"].header.frame_id == "world"
    assert list(psi.get_objects(["ball", "nothing"])) == ["ball"]
    assert list(psi.get_objects(names=["ball"])) == ["ball"]  # api.md's keyword (moveit_commander's: object_ids)
    attached = psi.get_attached_objects()
    assert list(attached) == ["held"] and attached["held"].link_name == "panda_hand"
    assert psi.get_attached_objects(["box"]) == {}
    assert list(psi.get_attached_objects(names=["held"])) == ["held"]
    poses = psi.get_object_poses(["box", "held", "nothing"])
    assert sorted(poses) == ["box"]  # world objects only, as MoveIt
    np.testing.assert_allclose(msgs.pose_to_matrix(poses["box"]), current_scene().get_frame_transform("box"), atol=1e-9)


def test_moveit_commander_constructor_arguments(toy):
    """(ns, synchronous, service_timeout) as moveit_commander's; robot_model is a keyword."""
    psi = PlanningSceneInterface("", True, 5.0)
    assert psi.service_timeout == 5.0 and PlanningSceneInterface(service_timeout=1.0).service_timeout == 1.0
    with pytest.raises(TypeError, match="robot_model must be a RobotModel, not str"):
        PlanningSceneInterface(robot_model="panda")
    assert PlanningSceneInterface(robot_model=toy).scene.robot_model is toy


def test_clear():
    """clear() detaches everything and removes every world object."""
    psi = PlanningSceneInterface()
    psi.add_box("box", stamped((1.0, 0.0, 0.0)))
    psi.attach_box("panda_hand", "held", stamped((0.0, 0.0, 0.0), frame="panda_hand"), size=(0.01, 0.01, 0.01))
    psi.clear()
    assert psi.get_known_object_names() == []


def test_interface_for_another_robot(toy):
    """An interface built for a robot model edits that robot's current scene."""
    psi = PlanningSceneInterface(robot_model=toy)
    psi.add_box("b", stamped((0.0, 0.0, 0.0), frame="base"))
    assert current_scene(toy).world_object_names == ["b"]
    assert psi.scene.robot_model is toy


def test_add_plane_says_planes_are_not_supported():
    """moveit_commander's add_plane: mtc has no planes, and says what to use instead."""
    with pytest.raises(ValueError, match="planes are not supported.*thin box"):
        PlanningSceneInterface().add_plane("floor", PoseStamped(header=Header(frame_id="world")))
    assert "floor" not in current_scene().world_object_names
