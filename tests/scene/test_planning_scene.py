"""Tests of mtc.scene.planning_scene: world and attached objects, collision truth, frames, diff()."""

from __future__ import annotations

import numpy as np
import pytest
from scene_helpers import (
    BASE_ONLY_XYZ,
    HAND_ONLY_XYZ,
    box,
    cube_mesh,
    obj,
    pose,
    primitive,
    snapshot,
    sphere,
    translation,
    write_cube_stl,
)

from mtc import msgs
from mtc.msgs import CollisionObject, SolidPrimitive
from mtc.scene.planning_scene import DescriptionError, PlanningScene, mesh_file_to_msg
from mtc.scene.robot_state import RobotState
from mtc.scene.robot_trajectory import RobotTrajectory

#: a self-colliding Panda state: only panda_link1 and panda_link5 touch
SELF_COLLIDING = [-1.726, 1.544, -2.348, -3.057, -1.026, 3.718, -1.363, 0.033, 0.033]
#: a 2 x 8 x 10 cm object between the open fingers, touching the hand and both fingers
HELD = dict(xyz=(0.307, 0.0, 0.487), size=(0.02, 0.08, 0.1))
#: a plate below the fingertips that only the held object reaches
PLATE = dict(xyz=(0.307, 0.0, 0.43), size=(0.3, 0.3, 0.02))
FINGERS = ["panda_leftfinger", "panda_rightfinger"]


def held_scene(scene):
    scene.apply_collision_object(box("obj", HELD["xyz"], HELD["size"]))
    return scene


# ---------------------------------------------------------------------------- basics
def test_new_scene(panda):
    """A new scene: the model, planning frame world, an empty world, default state, SRDF's ACM."""
    ps = PlanningScene(panda)
    assert ps.robot_model is panda
    assert ps.planning_frame == "world"
    assert ps.world_object_names == [] and ps.attached_object_names == []
    np.testing.assert_array_equal(ps.current_state.positions, RobotState(panda).positions)
    assert ps.allowed_collision_matrix.get_entry("panda_link0", "panda_link1")
    assert not ps.allowed_collision_matrix.get_entry("panda_link0", "panda_hand")
    assert ps.parent is None
    with pytest.raises(TypeError, match="RobotModel"):
        PlanningScene("panda")


def test_current_state_is_live_and_assignable(scene, panda, toy):
    """current_state is the scene's own state; assigning copies a state in; a foreign model is refused."""
    scene.current_state.joint_positions = {"panda_joint1": 0.4}
    assert scene.current_state.positions[0] == 0.4
    other = RobotState(panda)
    scene.current_state = other
    other.joint_positions = {"panda_joint1": 1.0}
    assert scene.current_state.positions[0] == 0.0
    with pytest.raises(ValueError, match="current_state belongs to robot .robot., not to the scene.s robot .panda."):
        scene.current_state = RobotState(toy)
    with pytest.raises(TypeError, match="RobotState"):
        scene.current_state = [0.0] * 9


def test_queries_refuse_a_state_of_another_robot(scene, panda, toy):
    """Every query that takes a state names the robot it belongs to when it is not the scene's
    (not Pinocchio's size error, and not a silent answer where there is nothing to measure)."""
    foreign = RobotState(toy)
    trajectory = RobotTrajectory(toy, "")
    trajectory.add_suffix_waypoint(foreign, 0.0)
    queries = {
        "is_state_colliding": lambda: scene.is_state_colliding(foreign),
        "is_state_valid": lambda: scene.is_state_valid(foreign),
        "get_collisions": lambda: scene.get_collisions(foreign),
        "distance_to_collision": lambda: scene.distance_to_collision(foreign),  # (no world: nothing to measure)
        "collision_distances": lambda: scene.collision_distances(foreign, self_collision=True),
        "is_state_constrained": lambda: scene.is_state_constrained(foreign, msgs.Constraints()),
        "get_robot_state_msg": lambda: scene.get_robot_state_msg(foreign),
        "knows_frame_transform": lambda: scene.knows_frame_transform(foreign, "panda_hand"),
        "is_path_valid": lambda: scene.is_path_valid(trajectory),
    }
    for name, query in queries.items():
        with pytest.raises(ValueError, match="belongs to robot 'robot', not to the scene's robot 'panda'"):
            query()
    # another load of the same robot is another model, and the message says so
    from mtc.robots import PANDA_SRDF, panda_urdf_path
    from mtc.scene.robot_model import RobotModel

    again = RobotModel(panda_urdf_path(), PANDA_SRDF)
    with pytest.raises(ValueError, match="robot 'panda' \\(another load of it"):
        scene.is_state_colliding(RobotState(again))
    assert not scene.is_state_colliding(RobotState(panda))


@pytest.mark.parametrize("arm", ["ready", "extended", "transport"])
@pytest.mark.parametrize("hand", ["open", "close"])
def test_no_self_collision_at_named_states(scene, arm, hand):
    """The SRDF's disabled pairs make every named state of the default robot collision-free."""
    scene.current_state.set_to_default_values("panda_arm", arm)
    scene.current_state.set_to_default_values("hand", hand)
    assert scene.get_collisions() == []
    assert not scene.is_state_colliding()


def test_self_collision_and_acm(scene):
    """A folded arm collides with itself; allowing that pair in the ACM clears it."""
    state = scene.current_state
    state.positions = SELF_COLLIDING
    assert scene.get_collisions() == [("panda_link1", "panda_link5")]
    assert scene.is_state_colliding()
    assert scene.is_state_colliding(group="panda_arm")
    assert not scene.is_state_colliding(group="hand")  # the hand group moves neither link
    scene.allowed_collision_matrix.set_entry("panda_link1", "panda_link5", True)
    assert not scene.is_state_colliding()
    assert scene.get_collisions() == []


# ---------------------------------------------------------------------------- collision truth
def test_box_through_the_hand_collides_and_moved_away_does_not(scene):
    """A box at the hand collides with it; MOVEd 30 cm away it does not."""
    scene.apply_collision_object(box("b", (0.307, 0.0, 0.56), (0.04, 0.04, 0.04)))
    assert scene.is_state_colliding()
    assert ("panda_hand", "b") in scene.get_collisions()
    moved = CollisionObject(id="b", header=msgs.Header(frame_id="world"), pose=pose((0.307, 0.3, 0.56)), operation=CollisionObject.MOVE)
    scene.apply_collision_object(moved)
    np.testing.assert_allclose(translation(scene.get_world_object("b").pose), [0.307, 0.3, 0.56])
    assert not scene.is_state_colliding()
    assert scene.get_collisions() == []


def test_moveit_py_call_forms(scene):
    """The calls of moveit_py's planning-scene tutorial: its keyword names, verbose, a group
    name alone for the current state; and RobotState's moveit_py keyword names."""
    scene.apply_collision_object(collision_object_msg=box("b", (0.307, 0.0, 0.56), (0.04, 0.04, 0.04)))
    state = scene.current_state
    assert scene.is_state_colliding(robot_state=state, joint_model_group_name="panda_arm", verbose=True)
    assert scene.is_state_colliding("panda_arm") and scene.is_state_colliding(state, "panda_arm", True)
    # moveit_py's (joint_model_group_name, verbose) by position
    assert scene.is_state_colliding("panda_arm", True) and not scene.is_state_valid("panda_arm", True)
    assert not scene.is_state_colliding("hand", False)
    assert not scene.is_state_valid(robot_state=state, joint_model_group_name="panda_arm")
    with pytest.raises(TypeError, match="got both 'state' and moveit_py's name for it, 'robot_state'"):
        scene.is_state_colliding(state=state, robot_state=state)
    with pytest.raises(TypeError, match="state must be a RobotState \\(or, as in moveit_py, a group name\\), not list"):
        scene.is_state_colliding([0.0] * 9)

    moved = state.copy()
    moved.set_joint_group_positions(joint_model_group_name="panda_arm", position_values=[0, -0.785, 0, -2.356, 0, 1.571, 0.3])
    assert moved.get_joint_group_positions(joint_model_group_name="panda_arm")[6] == pytest.approx(0.3)
    np.testing.assert_allclose(moved.get_pose(link_name="panda_link8").position.z, moved.get_pose("panda_link8").position.z)
    np.testing.assert_allclose(moved.get_frame_transform(frame_id="panda_hand"), moved.get_global_link_transform(link_name="panda_hand"))
    target = moved.get_pose("panda_link8")
    ik = state.copy()
    assert ik.set_from_ik(joint_model_group_name="panda_arm", geometry_pose=target, tip_name="panda_link8")
    np.testing.assert_allclose(ik.get_global_link_transform("panda_link8"), moved.get_global_link_transform("panda_link8"), atol=1e-5)


def test_deepcopy_is_an_independent_scene(scene):
    """copy.deepcopy (also of a scene that has checked collisions) gives an independent scene,
    as moveit_py's clone; no collision set-up is copied."""
    import copy

    scene.apply_collision_object(box("b", (0.307, 0.0, 0.56), (0.04, 0.04, 0.04)))
    assert scene.is_state_colliding()
    other = copy.deepcopy(scene)
    assert other is not scene and other.is_state_colliding() and other.parent is None
    other.apply_collision_object(CollisionObject(id="b", operation=CollisionObject.REMOVE))
    other.current_state.set_to_default_values("panda_arm", "extended")
    assert not other.is_state_colliding()
    assert scene.is_state_colliding() and scene.world_object_names == ["b"]
    with pytest.raises(TypeError, match="is_path_valid takes a RobotTrajectory, not list"):
        scene.is_path_valid([scene.current_state])


def test_allowed_pairs_do_not_collide(scene):
    """ACM entries for every touching link, or a default entry for the object, clear the collision."""
    scene.apply_collision_object(box("b", (0.307, 0.0, 0.6), (0.04, 0.04, 0.04)))
    touching = sorted({a for a, b in scene.get_collisions()})
    assert touching == ["panda_hand", "panda_link7"]
    child = scene.diff()
    child.allowed_collision_matrix.set_entry("b", touching, True)
    assert not child.is_state_colliding() and child.get_collisions() == []
    child = scene.diff()
    child.allowed_collision_matrix.set_entry("b", "panda_hand", True)
    assert child.get_collisions() == [("panda_link7", "b")]
    child = scene.diff()
    child.allowed_collision_matrix.set_default_entry("b", True)
    assert not child.is_state_colliding()
    assert scene.is_state_colliding()


def test_get_collisions_reports_each_body_pair_once(scene):
    """Links with several shapes (the fingers) give one pair each."""
    held_scene(scene)
    pairs = scene.get_collisions()
    assert sorted(pairs) == [("panda_hand", "obj"), ("panda_leftfinger", "obj"), ("panda_rightfinger", "obj")]
    contacts = scene.get_contacts()
    assert {(a, b) for a, b, _ in contacts} == set(pairs)
    for _, _, c in contacts:
        position, normal, depth = c[0]
        assert position.shape == (3,) and normal.shape == (3,) and np.isfinite(depth)


def test_distance_to_collision_decreases_as_a_box_approaches(scene):
    """distance_to_collision shrinks monotonically as a box moves toward the hand, <= 0 in contact."""
    assert scene.distance_to_collision() == float("inf")
    distances = []
    for y in (0.6, 0.45, 0.3, 0.2, 0.12, 0.0):
        scene.apply_collision_object(box("b", (0.307, y, 0.56), (0.04, 0.04, 0.04)))
        distances.append(scene.distance_to_collision())
    assert all(a > b for a, b in zip(distances, distances[1:])), distances
    assert distances[0] > 0.3 and distances[-1] <= 0.0
    assert scene.is_state_colliding()


def test_collision_distances(scene):
    """collision_distances lists world pairs ascending, or self pairs when asked."""
    scene.apply_collision_object(box("b", (0.307, 0.3, 0.56), (0.04, 0.04, 0.04)))
    world = scene.collision_distances()
    assert [d for d, _, _ in world] == sorted(d for d, _, _ in world)
    assert all(b == "b" for _, _, b in world)
    assert world[0][0] == pytest.approx(scene.distance_to_collision())
    selfd = scene.collision_distances(world=False, self_collision=True)
    assert selfd and all("b" not in (a, b) for _, a, b in selfd)
    assert all(d > 0 for d, _, _ in selfd)


def test_group_restriction_ignores_links_the_group_does_not_move(scene):
    """A box at the base collides for the whole robot only: no group moves panda_link0."""
    scene.apply_collision_object(box("base_box", BASE_ONLY_XYZ, (0.04, 0.04, 0.04)))
    assert scene.get_collisions() == [("panda_link0", "base_box")]
    assert scene.is_state_colliding()
    for group in ("hand", "panda_arm", "panda_arm_hand"):
        assert not scene.is_state_colliding(group=group), group
        assert scene.get_collisions(group=group) == []
        assert scene.distance_to_collision(group=group) > 0


@pytest.mark.parametrize("group", [None, "panda_arm_hand", "panda_arm"])
def test_box_touching_only_the_hand_collides_for_groups_that_move_it(scene, group):
    """A box touching only panda_hand collides for every group that moves the hand (the arm, arm
    and hand together)."""
    scene.apply_collision_object(box("b", HAND_ONLY_XYZ, (0.02, 0.02, 0.02)))
    assert scene.get_collisions() == [("panda_hand", "b")]
    assert scene.is_state_colliding(group=group)
    assert scene.get_collisions(group=group) == [("panda_hand", "b")]
    assert scene.distance_to_collision(group=group) < 0
    assert not scene.check_states(scene.current_state.positions[None], group=group)[0]


def test_the_hand_group_moves_only_the_fingers(scene):
    """As MoveIt, a group's check covers the links below its active joints: the hand group's
    finger joints do not move the palm (it hangs on a fixed joint above them), so a box touching
    only panda_hand does not collide for 'hand', as in MoveIt (an open/close-gripper MoveTo with
    the palm on an object plans)."""
    scene.apply_collision_object(box("b", HAND_ONLY_XYZ, (0.02, 0.02, 0.02)))
    assert not scene.is_state_colliding(group="hand")
    assert scene.get_collisions(group="hand") == []
    assert scene.distance_to_collision(group="hand") > 0
    assert scene.check_states(scene.current_state.positions[None], group="hand")[0]


def test_removing_an_object_drops_its_collision_matrix_pairs(scene):
    """As MoveIt 2 (moveit2 #3183): REMOVE, and removing all objects, drop the object's pair
    entries in the ACM, so an object added again under that id collides as a new one; its
    default entry and other objects' entries stay."""
    acm = scene.allowed_collision_matrix
    for operation_removes_all in (False, True):
        scene.apply_collision_object(box("b", HAND_ONLY_XYZ, (0.02, 0.02, 0.02)))
        scene.apply_collision_object(box("far", (2.0, 2.0, 2.0), (0.02, 0.02, 0.02)))
        acm.set_entry("b", "panda_hand", True)
        acm.set_entry("far", "panda_hand", True)
        acm.set_default_entry("b", False)
        assert not scene.is_state_colliding()
        if operation_removes_all:
            scene.remove_all_collision_objects()
        else:
            scene.apply_collision_object(msgs.CollisionObject(id="b", operation=msgs.CollisionObject.REMOVE))
        assert not acm.has_entry("b", "panda_hand")
        assert acm.has_entry("far", "panda_hand") != operation_removes_all
        assert "b" in acm.entry_names  # its default entry
        scene.apply_collision_object(box("b", HAND_ONLY_XYZ, (0.02, 0.02, 0.02)))
        assert scene.get_collisions() == [("panda_hand", "b")]
        scene.remove_all_collision_objects()


def test_moveit_py_frame_forms(scene):
    """knows_frame_transform(robot_state, frame_id) and the frame_id keyword, as moveit_py."""
    state = scene.current_state
    assert scene.knows_frame_transform(state, "panda_hand") and not scene.knows_frame_transform(state, "nope")
    assert scene.knows_frame_transform(frame_id="panda_hand")
    assert scene.knows_frame_transform(robot_state=state, frame_id="panda_hand")
    assert scene.knows_frame_transform(state, frame_id="panda_hand")
    assert not scene.knows_frame_transform(state, frame_id="nope")
    np.testing.assert_array_equal(scene.get_frame_transform(frame_id="panda_hand"), scene.get_frame_transform("panda_hand"))
    with pytest.raises(TypeError, match="robot_state must be a RobotState"):
        scene.knows_frame_transform("panda_hand", "panda_link0")
    with pytest.raises(TypeError, match=r"takes \(frame_id\) or \(robot_state, frame_id\)"):
        scene.knows_frame_transform()


def test_unknown_group_in_checks(scene):
    """Collision queries with an unknown group name it and the groups."""
    for call in (scene.is_state_colliding, scene.get_collisions, scene.distance_to_collision, scene.state_validity_checker):
        with pytest.raises(KeyError, match=r"'arm'.*panda_arm"):
            call(group="arm")


def test_checkers_agree_with_is_state_colliding(scene, panda):
    """state_validity_checker, check_states, is_state_colliding and get_collisions agree on random states."""
    rng = np.random.default_rng(42)
    for i in range(6):
        scene.apply_collision_object(sphere(f"s{i}", (rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6), rng.uniform(0.1, 0.8)), 0.12))
    state = RobotState(panda)
    Q = []
    for _ in range(150):
        state.set_to_random_positions(rng=rng)
        Q.append(state.positions.copy())
    Q = np.array(Q)
    for group in (None, "panda_arm", "hand"):
        valid = scene.check_states(Q, group=group)
        checker = scene.state_validity_checker(group)
        expected = []
        for q in Q:
            s = RobotState(panda, q)
            colliding = scene.is_state_colliding(s, group=group)
            assert colliding == bool(scene.get_collisions(s, group=group))
            expected.append(not colliding)
            assert checker(q) == (not colliding)
        np.testing.assert_array_equal(valid, expected)
        if group is None:
            assert 0.1 < valid.mean() < 0.95  # both outcomes occur
    with pytest.raises(ValueError, match=r"n x 9"):
        scene.check_states(np.zeros((3, 7)))


def test_is_state_valid_is_collision_free_as_moveit(scene):
    """is_state_valid is MoveIt's isStateValid: collision-free; like it, it leaves the joint
    bounds to satisfies_bounds."""
    assert scene.is_state_valid()
    scene.apply_collision_object(box("b", HAND_ONLY_XYZ, (0.02, 0.02, 0.02)))
    assert not scene.is_state_valid() and not scene.is_state_valid(group="panda_arm")
    scene.current_state.joint_positions = {"panda_joint4": 0.0}  # beyond the joint limit, off the box
    assert scene.is_state_valid() and not scene.current_state.satisfies_bounds()


def test_is_path_valid(scene, panda):
    """A trajectory sweeping through a box is invalid; the same away from it, or with the box gone, is valid."""
    start = scene.current_state.copy()
    traj = RobotTrajectory(panda, "panda_arm")
    for angle in np.linspace(0.0, 1.0, 11):
        s = start.copy()
        s.joint_positions = {"panda_joint1": angle}
        traj.append(s, 0.1)
    end = traj[-1].get_global_link_transform("panda_hand")
    mid = traj[5].get_global_link_transform("panda_hand")
    assert scene.is_path_valid(traj)
    scene.apply_collision_object(box("b", tuple(translation(mid) - [0, 0, 0.06]), (0.03, 0.03, 0.03)))
    assert not scene.is_state_colliding(traj[0]) and not scene.is_state_colliding(traj[-1])
    assert not scene.is_path_valid(traj)
    assert not scene.is_path_valid(traj, group="panda_arm")
    assert translation(end)[1] > 0.2
    scene.apply_collision_object(CollisionObject(id="b", operation=CollisionObject.REMOVE))
    assert scene.is_path_valid(traj)
    beyond = traj.copy()
    beyond[3].joint_positions = {"panda_joint4": 0.0}  # beyond the joint limit: MoveIt checks collisions only
    assert scene.is_path_valid(beyond, "panda_arm", True) and not beyond[3].satisfies_bounds()


def test_robot_without_geometry(toy):
    """The toy robot has no geometry: nothing collides until an object is attached to it."""
    ps = PlanningScene(toy)
    assert ps.planning_frame == "base"
    ps.apply_collision_object(box("b", (0.0, 0.0, 0.0), frame="base"))
    assert not ps.is_state_colliding() and ps.get_collisions() == []
    assert ps.distance_to_collision() == float("inf")
    assert ps.check_states(np.zeros((2, 3))).tolist() == [True, True]
    ps.attach_object("b", "tip")
    ps.apply_collision_object(box("c", (0.0, 0.0, 0.0), frame="base"))
    assert ps.get_collisions() == [("c", "b")]
    assert ps.is_state_colliding(group="group")  # the tip, holding b, moves with the group's joints
    assert ps.distance_to_collision(group="eef_group") < 0


# ---------------------------------------------------------------------------- primitives and meshes
@pytest.mark.parametrize(
    "kind, dims, xyz, expected",
    [
        (SolidPrimitive.SPHERE, [0.1], (0.5, 0.0, 0.0), 0.35),
        (SolidPrimitive.BOX, [0.2, 0.4, 0.6], (0.5, 0.0, 0.0), 0.35),  # x is the first dimension
        (SolidPrimitive.BOX, [0.2, 0.4, 0.6], (0.0, 0.7, 0.0), 0.45),  # y the second
        (SolidPrimitive.BOX, [0.2, 0.4, 0.6], (0.0, 0.0, -0.8), 0.45),  # z the third
        (SolidPrimitive.CYLINDER, [0.4, 0.1], (0.5, 0.0, 0.0), 0.35),  # [height, radius], radius sideways
        (SolidPrimitive.CYLINDER, [0.4, 0.1], (0.0, 0.0, -0.8), 0.55),  # height along z
        (SolidPrimitive.CONE, [0.4, 0.1], (0.0, 0.0, -0.8), 0.55),
        (SolidPrimitive.CONE, [0.4, 0.1], (0.5, 0.0, 0.25), 0.35),  # base (radius 0.1) at the bottom
    ],
    ids=["sphere", "box-x", "box-y", "box-z", "cylinder-radius", "cylinder-height", "cone-height", "cone-base"],
)
def test_primitive_dimensions(cube_scene, kind, dims, xyz, expected):
    """Each primitive's dimensions mean what SolidPrimitive says: distances to a 10 cm cube by hand."""
    cube_scene.apply_collision_object(obj("p", kind, dims, xyz))
    assert cube_scene.distance_to_collision() == pytest.approx(expected, abs=1e-6)
    # slide the cube (prismatic joint along x) into objects to its +x
    if xyz[0] > 0:
        cube_scene.current_state.joint_positions = {"slide": expected + 0.01}
        assert cube_scene.is_state_colliding()
        cube_scene.current_state.joint_positions = {"slide": expected - 0.01}
        assert not cube_scene.is_state_colliding()


def test_shape_poses_and_object_pose_compose(cube_scene):
    """A shape's pose is relative to the object's pose (a rotation about z carries it around)."""
    o = obj("p", SolidPrimitive.SPHERE, [0.1], xyz=(0.0, 0.0, 0.0), quat=(0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)))
    o.primitive_poses = [pose((0.5, 0.0, 0.0))]  # after the object's 90 degree turn: at +y
    cube_scene.apply_collision_object(o)
    wo = cube_scene.get_world_object("p")
    np.testing.assert_allclose(translation(wo.pose @ wo.shape_poses[0]), [0.0, 0.5, 0.0], atol=1e-12)
    assert cube_scene.distance_to_collision() == pytest.approx(0.35, abs=1e-6)
    cube_scene.current_state.joint_positions = {"slide": 0.5}  # sliding along x does not reach it
    assert not cube_scene.is_state_colliding()


def test_mesh_from_message(cube_scene):
    """A msgs.Mesh cube collides like the box it describes."""
    o = CollisionObject(id="m", header=msgs.Header(frame_id="world"), pose=pose((0.5, 0.0, 0.0)), meshes=[cube_mesh(0.2)], mesh_poses=[pose()])
    cube_scene.apply_collision_object(o)
    assert cube_scene.get_world_object("m").shapes[0] is not None
    assert cube_scene.distance_to_collision() == pytest.approx(0.35, abs=1e-6)
    cube_scene.current_state.joint_positions = {"slide": 0.36}
    assert cube_scene.is_state_colliding()


def test_mesh_from_file(cube_scene, tmp_path):
    """An STL file loaded (and scaled) into a message collides where it is."""
    path = write_cube_stl(tmp_path / "cube.stl", 0.1)
    mesh = mesh_file_to_msg(path, scale=(2.0, 2.0, 2.0))
    assert len(mesh.triangles) == 12
    xs = [p.x for p in mesh.vertices]
    assert min(xs) == pytest.approx(-0.1) and max(xs) == pytest.approx(0.1)
    o = CollisionObject(id="m", header=msgs.Header(frame_id="world"), pose=pose((0.5, 0.0, 0.0)), meshes=[mesh], mesh_poses=[pose()])
    cube_scene.apply_collision_object(o)
    assert cube_scene.distance_to_collision() == pytest.approx(0.35, abs=1e-6)


def test_mesh_file_errors(tmp_path):
    """A missing mesh file and a file that is no mesh both name the file."""
    with pytest.raises(FileNotFoundError, match="ghost.stl"):
        mesh_file_to_msg(str(tmp_path / "ghost.stl"))
    junk = tmp_path / "junk.stl"
    junk.write_text("not a mesh at all")
    with pytest.raises(DescriptionError, match="junk.stl"):
        mesh_file_to_msg(str(junk))


# ---------------------------------------------------------------------------- object operations
def test_add_replaces_an_object_of_the_same_id(scene):
    """ADD of an existing id replaces it (shapes and pose)."""
    scene.apply_collision_object(box("b", (1.0, 0.0, 0.0)))
    scene.apply_collision_object(sphere("b", (2.0, 0.0, 0.0), 0.1))
    wo = scene.get_world_object("b")
    assert scene.world_object_names == ["b"]
    assert wo.id == "b" and len(wo.shapes) == 1 and wo.shapes[0].type == SolidPrimitive.SPHERE
    np.testing.assert_allclose(translation(wo.pose), [2.0, 0.0, 0.0])


def test_remove_one_and_remove_all(scene):
    """REMOVE with an id removes that object; with an empty id every world object, not attached ones."""
    for i in range(3):
        scene.apply_collision_object(box(f"b{i}", (1.0 + i, 0.0, 0.0)))
    held_scene(scene)
    scene.attach_object("obj", "panda_hand")
    scene.apply_collision_object(CollisionObject(id="b1", operation=CollisionObject.REMOVE))
    assert scene.world_object_names == ["b0", "b2"]
    scene.apply_collision_object(CollisionObject(id="", operation=CollisionObject.REMOVE))
    assert scene.world_object_names == []
    assert scene.attached_object_names == ["obj"]
    scene.apply_collision_object(box("b", (1.0, 0.0, 0.0)))
    scene.remove_all_collision_objects()
    assert scene.world_object_names == []


def test_append_adds_shapes_to_an_object(scene):
    """APPEND adds shapes to an existing object at their shape poses relative to the object's
    own pose (as MoveIt's World::addToObject: the message's pose and header place only a new
    object); the message's subframes replace the object's. To a new id it adds one."""
    first = box("b", (0.307, 0.3, 0.56), (0.04, 0.04, 0.04))
    first.subframe_names, first.subframe_poses = ["old"], [pose((0.0, 0.0, 0.1))]
    scene.apply_collision_object(first)
    assert not scene.is_state_colliding()
    # the message's pose (far away, in another frame) is not used: the shape goes 0.3 m along -y
    # of the object, i.e. to (0.307, 0.0, 0.56), around the hand
    extra = box("b", (5.0, 5.0, 5.0), (0.04, 0.04, 0.04), frame="panda_link3")
    extra.primitive_poses = [pose((0.0, -0.3, 0.0))]
    extra.operation = CollisionObject.APPEND
    extra.subframe_names, extra.subframe_poses = ["top"], [pose((0.0, 0.0, 0.02))]
    scene.apply_collision_object(extra)
    wo = scene.get_world_object("b")
    assert len(wo.shapes) == 2
    np.testing.assert_allclose(translation(wo.pose), [0.307, 0.3, 0.56])
    np.testing.assert_allclose(translation(wo.pose @ wo.shape_poses[1]), [0.307, 0.0, 0.56], atol=1e-12)
    np.testing.assert_allclose(translation(scene.get_frame_transform("b/top")), [0.307, 0.3, 0.58], atol=1e-12)
    assert not scene.knows_frame_transform("b/old")
    assert scene.get_collisions()[0][1] == "b"
    # one shape and no object pose: the shape's pose is the (ignored) object pose, so the shape
    # lands on the object's origin
    single = CollisionObject(id="b", primitives=[primitive(SolidPrimitive.SPHERE, [0.01])],
                             primitive_poses=[pose((1.0, 1.0, 1.0))], operation=CollisionObject.APPEND)
    scene.apply_collision_object(single)
    wo = scene.get_world_object("b")
    np.testing.assert_allclose(translation(wo.pose @ wo.shape_poses[2]), [0.307, 0.3, 0.56], atol=1e-12)
    new = box("c", (2.0, 0.0, 0.0))
    new.operation = CollisionObject.APPEND
    scene.apply_collision_object(new)
    assert scene.world_object_names == ["b", "c"]
    np.testing.assert_allclose(translation(scene.get_world_object("c").pose), [2.0, 0.0, 0.0])


def test_header_frame_of_a_link(scene):
    """An object given in a link frame is placed at that link's pose times the object pose."""
    scene.apply_collision_object(box("b", (0.0, 0.0, 0.1034), frame="panda_hand"))
    np.testing.assert_allclose(
        scene.get_world_object("b").pose, scene.current_state.get_global_link_transform("panda_hand_tcp"), atol=1e-12
    )
    # the object stays in the world when the arm moves afterwards
    before = scene.get_frame_transform("b")
    scene.current_state.joint_positions = {"panda_joint1": 0.5}
    np.testing.assert_array_equal(scene.get_frame_transform("b"), before)


def test_header_frame_of_an_object_subframe(scene):
    """An object may be placed relative to another object's subframe."""
    base = box("base", (1.0, 0.0, 0.0))
    base.subframe_names, base.subframe_poses = ["top"], [pose((0.0, 0.0, 0.5), quat=(0.0, 0.0, 1.0, 0.0))]
    scene.apply_collision_object(base)
    scene.apply_collision_object(box("on_top", (0.1, 0.0, 0.0), frame="base/top"))
    np.testing.assert_allclose(translation(scene.get_frame_transform("on_top")), [0.9, 0.0, 0.5], atol=1e-12)


def test_subframes_of_world_objects(scene):
    """Subframes are frames 'object/subframe' relative to the object's pose."""
    o = box("tool", (0.5, 0.2, 0.3), quat=(0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)))
    o.subframe_names, o.subframe_poses = ["tip", "grip"], [pose((0.1, 0.0, 0.0)), pose((0.0, 0.0, -0.05))]
    scene.apply_collision_object(o)
    assert sorted(scene.get_world_object("tool").subframe_poses) == ["grip", "tip"]
    np.testing.assert_allclose(translation(scene.get_frame_transform("tool/tip")), [0.5, 0.3, 0.3], atol=1e-12)
    np.testing.assert_allclose(translation(scene.get_frame_transform("tool/grip")), [0.5, 0.2, 0.25], atol=1e-12)
    assert scene.knows_frame_transform("tool/tip")
    assert not scene.knows_frame_transform("tool/nose")


def test_object_ids_with_slashes_are_frames(scene):
    """As MoveIt, a frame is looked up as a whole object id first, then as "id/subframe" (so ids
    may contain "/"); links come before objects; a leading "/" is dropped."""
    shelf = box("shelf/board", (0.5, 0.2, 0.3))
    shelf.subframe_names, shelf.subframe_poses = ["edge"], [pose((0.1, 0.0, 0.0))]
    scene.apply_collision_object(shelf)
    np.testing.assert_allclose(translation(scene.get_frame_transform("shelf/board")), [0.5, 0.2, 0.3])
    np.testing.assert_allclose(translation(scene.get_frame_transform("shelf/board/edge")), [0.6, 0.2, 0.3], atol=1e-12)
    np.testing.assert_allclose(translation(scene.get_frame_transform("/shelf/board")), [0.5, 0.2, 0.3])
    assert not scene.knows_frame_transform("shelf") and not scene.knows_frame_transform("shelf/board/nose")
    tool = box("tool/a", (0.0, 0.0, 0.05), frame="panda_hand")
    tool.subframe_names, tool.subframe_poses = ["tip"], [pose((0.0, 0.0, 0.02))]
    scene.apply_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_hand", object=tool))
    hand = scene.current_state.get_global_link_transform("panda_hand")
    np.testing.assert_allclose(translation(scene.get_frame_transform("tool/a/tip")), translation(hand @ msgs.pose_to_matrix(pose((0.0, 0.0, 0.07)))), atol=1e-12)
    np.testing.assert_allclose(scene.current_state.get_frame_transform("tool/a"), scene.get_frame_transform("tool/a"))
    # the ik frame and path constraints find it too
    from mtc.scene.frames import NotALinkFrameError, resolve_frame, resolve_ik_frame

    link, offset = resolve_frame(scene, "tool/a/tip")
    np.testing.assert_allclose(scene.current_state.get_global_link_transform(link) @ offset, scene.get_frame_transform("tool/a/tip"), atol=1e-12)
    # an object named as a link does not hide the link
    scene.apply_collision_object(box("panda_link3", (2.0, 0.0, 0.0)))
    np.testing.assert_allclose(scene.get_frame_transform("panda_link3"), scene.current_state.get_global_link_transform("panda_link3"))
    # a leading "/" is dropped everywhere a frame is resolved; "/" alone is no frame
    link, offset = resolve_frame(scene, "/tool/a/tip")
    np.testing.assert_allclose(scene.current_state.get_global_link_transform(link) @ offset, scene.get_frame_transform("tool/a/tip"), atol=1e-12)
    np.testing.assert_allclose(scene.current_state.get_frame_transform("/panda_hand"), scene.current_state.get_global_link_transform("panda_hand"))
    assert resolve_frame(scene, "/panda_hand")[0] == resolve_frame(scene, "panda_hand")[0]
    arm = scene.robot_model.get_joint_model_group("panda_arm")
    for frame in ("world", "/world"):
        ik = resolve_ik_frame(scene, msgs.PoseStamped(header=msgs.Header(frame_id=frame)), arm)
        assert ik.link == "panda_link8"
    assert not scene.knows_frame_transform("/")
    # the ids before a "/" are tried in MoveIt's (sorted) order until one has the subframe
    a = box("a", (0.0, 1.0, 0.0))
    a.subframe_names, a.subframe_poses = ["b/c"], [pose((0.0, 0.0, 0.5))]
    scene.apply_collision_object(a)
    ab = box("a/b", (0.0, 2.0, 0.0))
    ab.subframe_names, ab.subframe_poses = ["c", "d"], [pose((0.0, 0.0, 0.7)), pose((0.0, 0.0, 0.9))]
    scene.apply_collision_object(ab)
    np.testing.assert_allclose(translation(scene.get_frame_transform("a/b/c")), [0.0, 1.0, 0.5], atol=1e-12)
    np.testing.assert_allclose(translation(scene.get_frame_transform("a/b/d")), [0.0, 2.0, 0.9], atol=1e-12)
    np.testing.assert_allclose(translation(scene.get_frame_transform("//a/b/d")), [0.0, 2.0, 0.9], atol=1e-12)
    # an attached object without the subframe does not hide a world object of that name
    scene.apply_collision_object(box("tool/a/nose", (3.0, 0.0, 0.0)))
    with pytest.raises(NotALinkFrameError):
        resolve_frame(scene, "tool/a/nose")
    from mtc.planners.constraints import _FrameResolver

    resolver = _FrameResolver(scene.robot_model, scene)
    assert resolver.resolve("tool/a/nose", "c")[0] == "fixed"
    assert resolver.resolve("/panda_link8", "c")[0] == "link" and resolver.resolve("//world", "c")[0] == "fixed"


def test_frame_transforms(scene):
    """Frames: the planning frame (and "") are identity; links; objects; unknown ones raise naming what exists."""
    np.testing.assert_array_equal(scene.get_frame_transform("world"), np.eye(4))
    np.testing.assert_array_equal(scene.get_frame_transform(""), np.eye(4))
    np.testing.assert_allclose(
        scene.get_frame_transform("panda_hand_tcp"), scene.current_state.get_global_link_transform("panda_hand_tcp")
    )
    scene.apply_collision_object(box("b", (1.0, 0.0, 0.0)))
    assert scene.knows_frame_transform("b") and scene.knows_frame_transform("panda_link3")
    assert not scene.knows_frame_transform("tool0")
    with pytest.raises(KeyError) as e:
        scene.get_frame_transform("tool0")
    msg = str(e.value)
    assert "'tool0'" in msg and "panda_hand_tcp" in msg and "b" in msg.split("objects:")[1]


# ---------------------------------------------------------------------------- attach / detach
def test_attach_keeps_the_pose_and_moves_with_the_link(scene):
    """Attaching keeps the object's world pose; it then follows its link; detaching leaves it there."""
    held = box("obj", HELD["xyz"], HELD["size"])
    held.subframe_names, held.subframe_poses = ["tip"], [pose((0.0, 0.0, -0.05))]
    scene.apply_collision_object(held)
    world_pose = scene.get_frame_transform("obj")
    scene.attach_object("obj", "panda_hand", touch_links=FINGERS)
    assert scene.world_object_names == [] and scene.attached_object_names == ["obj"]
    att = scene.get_attached_object("obj")
    assert att.link == "panda_hand" and att.id == "obj"
    assert att.touch_links == set(FINGERS)
    np.testing.assert_allclose(scene.get_frame_transform("obj"), world_pose, atol=1e-12)
    # the object's pose is now relative to the link
    hand = scene.current_state.get_global_link_transform("panda_hand")
    np.testing.assert_allclose(hand @ att.object.pose, world_pose, atol=1e-12)

    state = scene.current_state
    state.joint_positions = {"panda_joint1": 0.6, "panda_joint6": 1.2}
    hand = state.get_global_link_transform("panda_hand")
    expected = hand @ att.object.pose
    np.testing.assert_allclose(scene.get_frame_transform("obj"), expected, atol=1e-12)
    np.testing.assert_allclose(state.get_frame_transform("obj"), expected, atol=1e-12)
    tip = expected.copy()
    tip[:3, 3] += expected[:3, 2] * -0.05
    np.testing.assert_allclose(state.get_frame_transform("obj/tip"), tip, atol=1e-12)
    np.testing.assert_allclose(scene.get_frame_transform("obj/tip"), tip, atol=1e-12)
    assert state.knows_frame_transform("obj/tip") and not state.knows_frame_transform("obj/nose")

    scene.detach_object("obj")
    assert scene.world_object_names == ["obj"] and scene.attached_object_names == []
    np.testing.assert_allclose(scene.get_world_object("obj").pose, expected, atol=1e-12)
    state.joint_positions = {"panda_joint1": 0.0}
    np.testing.assert_allclose(scene.get_frame_transform("obj"), expected, atol=1e-12)  # stays put
    np.testing.assert_allclose(scene.get_frame_transform("obj/tip"), tip, atol=1e-12)
    assert not state.knows_frame_transform("obj")


def test_attached_object_collides_with_the_world_not_its_touch_links(scene):
    """Held between the fingers: no collision with hand and fingers (touch links), but with a plate below."""
    held_scene(scene)
    assert len(scene.get_collisions()) == 3
    scene.attach_object("obj", "panda_hand", touch_links=FINGERS)
    assert scene.get_collisions() == [] and not scene.is_state_colliding()
    scene.apply_collision_object(box("plate", PLATE["xyz"], PLATE["size"]))
    assert scene.get_collisions() == [("plate", "obj")]
    assert scene.is_state_colliding()
    assert scene.is_state_colliding(group="panda_arm")  # the arm moves the hand that holds it
    assert scene.distance_to_collision() < 0
    scene.allowed_collision_matrix.set_entry("obj", "plate", True)
    assert not scene.is_state_colliding()


def test_attached_object_counts_for_the_groups_that_move_its_link(scene):
    """An object held by panda_hand moves with the arm, so its world collisions count for the arm
    groups; the hand group does not move panda_hand, so not for 'hand' (as MoveIt's FCL check
    skips attached bodies whose link the group does not move), but an object held by a finger
    does."""
    held_scene(scene)
    scene.attach_object("obj", "panda_hand", touch_links=FINGERS)
    scene.apply_collision_object(box("plate", PLATE["xyz"], PLATE["size"]))
    assert scene.is_state_colliding(group="panda_arm") and scene.is_state_colliding(group="panda_arm_hand")
    assert not scene.is_state_colliding(group="hand")
    scene.detach_object("obj")
    scene.attach_object("obj", "panda_leftfinger", touch_links=[*FINGERS, "panda_hand"])
    assert scene.get_collisions(group="hand") == [("obj", "plate")] or scene.get_collisions(group="hand") == [("plate", "obj")]


def test_attach_link_is_always_a_touch_link(scene):
    """Without touch links only the attach link may touch the object: the fingers still collide."""
    held_scene(scene)
    scene.attach_object("obj", "panda_hand")
    assert scene.get_attached_object("obj").touch_links == frozenset()
    assert sorted(scene.get_collisions()) == [("panda_leftfinger", "obj"), ("panda_rightfinger", "obj")]
    scene.detach_object("obj")
    scene.attach_object("obj", "panda_hand", touch_links="panda_leftfinger")
    assert scene.get_collisions() == [("panda_rightfinger", "obj")]


def test_attached_object_collides_with_links_that_are_not_touch_links(scene):
    """An attached object still collides with robot links other than its link and touch links."""
    link3 = translation(scene.current_state.get_global_link_transform("panda_link3"))
    scene.apply_collision_object(box("b", tuple(link3), (0.04, 0.04, 0.04)))
    assert scene.get_collisions() == [("panda_link3", "b"), ("panda_link4", "b")]
    scene.attach_object("b", "panda_hand")
    assert scene.get_collisions() == [("panda_link3", "b"), ("panda_link4", "b")]
    assert scene.is_state_colliding(group="panda_arm")  # the object moves with the arm
    assert not scene.is_state_colliding(group="hand")  # ... but not with the fingers (as MoveIt)
    scene.detach_object("b")
    scene.attach_object("b", "panda_hand", touch_links=["panda_link3", "panda_link4"])
    assert scene.get_collisions() == []


def test_attached_objects_collide_with_each_other(scene):
    """Two attached objects that overlap collide, unless the ACM allows the pair."""
    scene.apply_collision_object(box("c", (0.307, 0.0, 0.45)))
    scene.apply_collision_object(box("d", (0.307, 0.0, 0.45)))
    scene.attach_object("c", "panda_link0")
    scene.attach_object("d", "panda_hand_tcp")  # a frame without geometry of its own
    assert scene.get_collisions() == [("c", "d")]
    assert scene.is_state_colliding(group="panda_arm")
    np.testing.assert_allclose(translation(scene.get_frame_transform("d")), [0.307, 0.0, 0.45], atol=1e-12)
    scene.current_state.joint_positions = {"panda_joint1": 0.5}  # d moves with the arm, c stays
    assert not scene.is_state_colliding()
    np.testing.assert_allclose(translation(scene.get_frame_transform("c")), [0.307, 0.0, 0.45], atol=1e-12)
    scene.current_state.joint_positions = {"panda_joint1": 0.0}
    scene.allowed_collision_matrix.set_entry("c", "d", True)
    assert not scene.is_state_colliding()


def test_frames_of_attached_objects_follow_each_scene(scene):
    """After diff(), each scene's state sees its own attached objects' frames."""
    held_scene(scene)
    scene.attach_object("obj", "panda_hand")
    child = scene.diff()
    child.detach_object("obj")
    assert scene.current_state.knows_frame_transform("obj")
    assert not child.current_state.knows_frame_transform("obj")
    assert child.knows_frame_transform("obj")  # a world object of the child now
    child.attach_object("obj", "panda_link8")
    child.current_state.joint_positions = {"panda_joint7": 0.0}
    link8 = child.current_state.get_global_link_transform("panda_link8")
    np.testing.assert_allclose(child.current_state.get_frame_transform("obj"), link8 @ child.get_attached_object("obj").object.pose)
    assert scene.get_attached_object("obj").link == "panda_hand"
    hand = scene.current_state.get_global_link_transform("panda_hand")
    np.testing.assert_allclose(scene.current_state.get_frame_transform("obj"), hand @ scene.get_attached_object("obj").object.pose)


def test_attached_collision_object_messages(scene):
    """AttachedCollisionObject ADD attaches a new object given in the link frame; REMOVE detaches."""
    o = box("tool", (0.0, 0.0, 0.05), (0.02, 0.02, 0.02), frame="panda_hand_tcp")
    msg = msgs.AttachedCollisionObject(link_name="panda_hand", object=o, touch_links=FINGERS)
    scene.apply_attached_collision_object(msg)
    assert scene.attached_object_names == ["tool"]
    tcp = scene.current_state.get_global_link_transform("panda_hand_tcp")
    np.testing.assert_allclose(translation(scene.get_frame_transform("tool")), translation(tcp) + tcp[:3, 2] * 0.05, atol=1e-12)
    out = scene.get_attached_collision_object_msg("tool")
    assert out.link_name == "panda_hand" and out.touch_links == FINGERS and out.object.id == "tool"
    # attaching an existing world object by id alone
    scene.apply_collision_object(box("b", (0.307, 0.0, 0.45)))
    scene.apply_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_link8", object=CollisionObject(id="b")))
    assert scene.get_attached_object("b").link == "panda_link8"
    with pytest.raises(KeyError, match=r"'b' is attached to 'panda_link8', not 'panda_hand'"):
        scene.apply_attached_collision_object(
            msgs.AttachedCollisionObject(link_name="panda_hand", object=CollisionObject(id="b", operation=CollisionObject.REMOVE))
        )
    scene.apply_attached_collision_object(
        msgs.AttachedCollisionObject(link_name="panda_hand", object=CollisionObject(operation=CollisionObject.REMOVE))
    )
    assert scene.attached_object_names == ["b"] and "tool" in scene.world_object_names
    scene.apply_attached_collision_object(msgs.AttachedCollisionObject(object=CollisionObject(operation=CollisionObject.REMOVE)))
    assert scene.attached_object_names == []


def test_attached_collision_object_append(scene):
    """AttachedCollisionObject APPEND (as MoveIt's processAttachedCollisionObjectMsg): shapes go
    to the attached object, relative to its pose when the message has none; subframes and touch
    links are merged (a new subframe wins), the detach posture kept; with no object of that id
    attached it attaches a new one, removing a world object of that id."""
    o = box("tool", (0.0, 0.0, 0.05), (0.02, 0.02, 0.02), frame="panda_hand_tcp")
    o.subframe_names, o.subframe_poses = ["tip", "side"], [pose((0.0, 0.0, 0.01)), pose((0.01, 0.0, 0.0))]
    posture = msgs.JointTrajectory(joint_names=["panda_finger_joint1"])
    scene.apply_attached_collision_object(
        msgs.AttachedCollisionObject(link_name="panda_hand", object=o, touch_links=["panda_leftfinger"], detach_posture=posture)
    )
    before = scene.get_frame_transform("tool")
    extra = CollisionObject(
        id="tool", header=msgs.Header(frame_id="panda_hand"), operation=CollisionObject.APPEND,
        primitives=[primitive(SolidPrimitive.SPHERE, [0.01]), primitive(SolidPrimitive.BOX, [0.01, 0.01, 0.01])],
        primitive_poses=[pose((0.0, 0.0, 0.1)), pose((0.0, 0.02, 0.0))],
        subframe_names=["tip"], subframe_poses=[pose((0.0, 0.0, 0.2))],
    )
    scene.apply_attached_collision_object(
        msgs.AttachedCollisionObject(link_name="panda_hand", object=extra, touch_links=["panda_rightfinger"])
    )
    att = scene.get_attached_object("tool")
    assert [s.type for s in att.object.shapes] == [SolidPrimitive.SPHERE, SolidPrimitive.BOX, SolidPrimitive.BOX]
    np.testing.assert_allclose(scene.get_frame_transform("tool"), before, atol=1e-12)  # pose kept
    np.testing.assert_allclose(translation(att.object.shape_poses[0]), [0.0, 0.0, 0.1])
    np.testing.assert_allclose(translation(att.object.shape_poses[2]), [0.0, 0.0, 0.0])
    np.testing.assert_allclose(translation(np.linalg.solve(before, scene.get_frame_transform("tool/tip"))), [0.0, 0.0, 0.2], atol=1e-12)
    np.testing.assert_allclose(translation(np.linalg.solve(before, scene.get_frame_transform("tool/side"))), [0.01, 0.0, 0.0], atol=1e-12)
    assert att.touch_links == {"panda_leftfinger", "panda_rightfinger"} and att.detach_posture is posture
    # the detach posture is part of the object's message, as MoveIt's attached body gives it back
    for out in (scene.get_attached_collision_object_msg("tool"),
                scene.get_planning_scene_msg().robot_state.attached_collision_objects[0]):
        assert out.detach_posture == posture and out.detach_posture is not posture
    # a message pose places the merged object: the old shapes move with it
    moved = CollisionObject(id="tool", header=msgs.Header(frame_id="panda_hand"), operation=CollisionObject.APPEND,
                            pose=pose((0.0, 0.0, 0.3)), primitives=[primitive(SolidPrimitive.SPHERE, [0.01])])
    scene.apply_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_hand", object=moved))
    hand = scene.current_state.get_global_link_transform("panda_hand")
    np.testing.assert_allclose(scene.get_frame_transform("tool"), hand @ msgs.pose_to_matrix(pose((0.0, 0.0, 0.3))), atol=1e-12)
    assert len(scene.get_attached_object("tool").object.shapes) == 4
    # no attached object of that id: APPEND attaches one, and a world object of that id goes
    scene.apply_collision_object(box("cup", (1.0, 0.0, 0.0)))
    new = box("cup", (0.0, 0.0, 0.05), frame="panda_hand")
    new.operation = CollisionObject.APPEND
    scene.apply_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_hand", object=new))
    assert "cup" in scene.attached_object_names and "cup" not in scene.world_object_names
    np.testing.assert_allclose(translation(scene.get_frame_transform("cup")), translation(hand @ msgs.pose_to_matrix(pose((0.0, 0.0, 0.05)))), atol=1e-12)


def test_scene_messages_round_trip(scene):
    """get_planning_scene_msg describes the world; re-applying an object message reproduces it."""
    o = box("b", (0.5, 0.2, 0.3), (0.1, 0.2, 0.3), quat=(0.0, 0.0, np.sin(0.3), np.cos(0.3)))
    o.subframe_names, o.subframe_poses = ["s"], [pose((0.0, 0.0, 0.15))]
    scene.apply_collision_object(o)
    msg = scene.get_planning_scene_msg()
    assert [c.id for c in msg.world.collision_objects] == ["b"]
    assert msg.robot_state.joint_state.name == scene.robot_model.variable_names
    other = PlanningScene(scene.robot_model)
    other.apply_collision_object(scene.get_collision_object_msg("b"))
    np.testing.assert_allclose(other.get_world_object("b").pose, scene.get_world_object("b").pose, atol=1e-9)
    np.testing.assert_allclose(other.get_frame_transform("b/s"), scene.get_frame_transform("b/s"), atol=1e-9)


# ---------------------------------------------------------------------------- ACM
def test_acm_entries(scene):
    """set_entry with names or lists, get_entry, set_default_entry; explicit entries win over defaults."""
    acm = scene.allowed_collision_matrix
    assert acm.get_entry("panda_hand", "panda_link7")  # from the SRDF
    acm.set_entry("a", ["b", "c"], True)
    assert acm.get_entry("a", "b") and acm.get_entry("c", "a") and not acm.get_entry("b", "c")
    acm.set_entry("a", False)  # every entry of a
    assert not acm.get_entry("a", "b") and not acm.get_entry("a", "c")
    acm.set_default_entry("d", True)
    assert acm.get_entry("d", "anything") and acm.get_default_entry("d")
    acm.set_entry("d", "e", False)
    assert not acm.get_entry("d", "e")
    acm.set_default_entry("d", False)
    assert not acm.get_entry("d", "anything")
    with pytest.raises(TypeError, match="allowed"):
        acm.set_entry("a", "b", "yes")
    with pytest.raises(TypeError, match="allowed"):
        acm.set_default_entry("a", "no")


# ---------------------------------------------------------------------------- diff()
def _populate(scene):
    held_scene(scene)
    scene.apply_collision_object(box("far", (1.0, 0.0, 0.0)))
    scene.attach_object("obj", "panda_hand", touch_links=FINGERS)
    scene.allowed_collision_matrix.set_entry("x", "y", True)
    scene.is_state_colliding()  # build the shared collision set-up before diffing
    return scene


def _edit(scene):
    scene.apply_collision_object(box("new", (0.307, 0.0, 0.56), (0.05, 0.05, 0.05)))
    scene.apply_collision_object(
        CollisionObject(id="far", header=msgs.Header(frame_id="world"), pose=pose((2.0, 0.0, 0.0)), operation=CollisionObject.MOVE)
    )
    scene.detach_object("obj")
    scene.attach_object("far", "panda_link8")
    scene.allowed_collision_matrix.set_entry("x", "y", False)
    scene.allowed_collision_matrix.set_default_entry("new", True)
    scene.current_state.joint_positions = {"panda_joint1": 0.7}


def test_diff_starts_equal_and_knows_its_parent(scene):
    """A diff has the parent's world, attached objects, ACM and state, and parent points back."""
    _populate(scene)
    child = scene.diff()
    assert child.parent is scene
    assert snapshot(child) == snapshot(scene)
    assert child.current_state is not scene.current_state
    assert scene.copy().parent is None


def test_child_changes_never_reach_the_parent(scene):
    """World, attached objects, ACM and robot state edits of a diff leave the parent as it was."""
    _populate(scene)
    before = snapshot(scene)
    colliding = scene.is_state_colliding()
    child = scene.diff()
    _edit(child)
    assert snapshot(child) != before
    assert snapshot(scene) == before
    assert scene.is_state_colliding() == colliding
    assert "new" in child.world_object_names and not scene.has_object("new")
    assert not scene.allowed_collision_matrix.get_entry("new", "panda_hand")


def test_parent_changes_after_diff_never_reach_the_child(scene):
    """Edits of the parent after diff() leave the child as it was."""
    _populate(scene)
    child = scene.diff()
    before = snapshot(child)
    colliding = child.is_state_colliding()
    _edit(scene)
    assert snapshot(scene) != before
    assert snapshot(child) == before
    assert child.is_state_colliding() == colliding
    assert child.allowed_collision_matrix.get_entry("x", "y")


def test_siblings_are_independent(scene):
    """Two diffs of one scene do not see each other's changes; a diff of a diff neither."""
    _populate(scene)
    a, b = scene.diff(), scene.diff()
    before = snapshot(b)
    _edit(a)
    assert snapshot(b) == before
    grandchild = b.diff()
    _edit(grandchild)
    assert snapshot(b) == before and grandchild.parent is b


def test_diff_shares_the_collision_setup_until_an_edit(scene):
    """A diff reuses its parent's collision set-up (cheap diffs); an edit of either makes its own."""
    _populate(scene)
    env = scene._collision_env()
    child = scene.diff()
    assert child._collision_env() is env
    child.current_state.joint_positions = {"panda_joint1": 0.3}  # the state is not part of the set-up
    assert child._collision_env() is env
    child.allowed_collision_matrix.set_entry("obj", "far", True)
    assert child._collision_env() is not env
    assert scene._collision_env() is env
    other = scene.diff()
    scene.apply_collision_object(box("extra", (2.0, 0.0, 0.0)))
    assert scene._collision_env() is not env and other._collision_env() is env


def test_acm_held_across_diff_does_not_leak(scene):
    """An ACM reference taken before diff() edits only its own scene, not the child."""
    acm = scene.allowed_collision_matrix
    child = scene.diff()
    acm.set_entry("x", "y", True)
    assert scene.allowed_collision_matrix.get_entry("x", "y")
    assert not child.allowed_collision_matrix.get_entry("x", "y")


# ---------------------------------------------------------------------------- bad input
def _attached(scene):
    held_scene(scene)
    scene.apply_collision_object(box("far", (1.0, 0.0, 0.0)))
    scene.attach_object("obj", "panda_hand")
    return scene


BAD_INPUT = {
    "remove-unknown": (
        lambda s: s.apply_collision_object(CollisionObject(id="ghost", operation=CollisionObject.REMOVE)),
        KeyError, ["'ghost'", "far"],
    ),
    "move-unknown": (
        lambda s: s.apply_collision_object(CollisionObject(id="ghost", operation=CollisionObject.MOVE)),
        KeyError, ["'ghost'", "far"],
    ),
    "unknown-header-frame": (lambda s: s.apply_collision_object(box("b", (0, 0, 0), frame="tool0")), KeyError, ["'b'", "'tool0'", "panda_hand", "far"]),
    "box-two-dims": (lambda s: s.apply_collision_object(obj("b", SolidPrimitive.BOX, [0.1, 0.1])), ValueError, ["'b'", "box", "3", "[0.1, 0.1]"]),
    "sphere-negative": (lambda s: s.apply_collision_object(obj("b", SolidPrimitive.SPHERE, [-0.1])), ValueError, ["'b'", "sphere", "[radius]", "-0.1"]),
    "cylinder-one-dim": (lambda s: s.apply_collision_object(obj("b", SolidPrimitive.CYLINDER, [0.1])), ValueError, ["'b'", "cylinder", "[height, radius]"]),
    "cone-zero": (lambda s: s.apply_collision_object(obj("b", SolidPrimitive.CONE, [0.1, 0.0])), ValueError, ["'b'", "cone", "positive"]),
    "box-nan": (lambda s: s.apply_collision_object(obj("b", SolidPrimitive.BOX, [0.1, float("nan"), 0.1])), ValueError, ["'b'", "box"]),
    # fields of the wrong type are named by their path in the message
    "header-str": (lambda s: s.apply_collision_object(CollisionObject(id="b", header="world", primitives=box("b", (0, 0, 0)).primitives)),
                   TypeError, ["'b'", "CollisionObject.header", "msgs.Header"]),
    "dimensions-scalar": (lambda s: s.apply_collision_object(CollisionObject(id="b", primitives=[SolidPrimitive(type=SolidPrimitive.SPHERE, dimensions=0.05)],
                                                                             primitive_poses=[pose()])),
                          TypeError, ["'b'", "primitives[0].dimensions", "list"]),
    "primitives-none": (lambda s: s.apply_collision_object(CollisionObject(id="b", primitives=None)), TypeError, ["'b'", "primitives", "list"]),
    "pose-as-list": (lambda s: s.apply_collision_object(CollisionObject(id="b", primitives=box("b", (0, 0, 0)).primitives,
                                                                        primitive_poses=[[0, 0, 0]])),
                     TypeError, ["'b'", "primitive_poses[0]", "msgs.Pose"]),
    "attach-msg-touch-links-str": (
        lambda s: s.apply_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_hand", object=box("new", (0, 0, 0)),
                                                                                 touch_links="panda_leftfinger")),
        TypeError, ["'new'", "touch_links", "list"],
    ),
    "mesh-triangle-two-indices": (
        lambda s: s.apply_collision_object(CollisionObject(id="b", meshes=[msgs.Mesh(
            triangles=[msgs.MeshTriangle(vertex_indices=[0, 1])], vertices=[msgs.Point(), msgs.Point(x=1.0), msgs.Point(y=1.0)])],
            mesh_poses=[pose()])),
        ValueError, ["'b'", "triangle 0", "2 vertex indices", "not 3"],
    ),
    "mesh-nan-vertex": (
        lambda s: s.apply_collision_object(CollisionObject(id="b", meshes=[msgs.Mesh(
            triangles=[msgs.MeshTriangle(vertex_indices=[0, 1, 2])], vertices=[msgs.Point(x=float("nan")), msgs.Point(x=1.0), msgs.Point(y=1.0)])],
            mesh_poses=[pose()])),
        ValueError, ["'b'", "vertex 0", "finite"],
    ),
    "unknown-primitive": (lambda s: s.apply_collision_object(obj("b", 7, [0.1])), ValueError, ["'b'", "7", "BOX"]),
    "no-shapes": (lambda s: s.apply_collision_object(CollisionObject(id="b")), ValueError, ["'b'", "primitive or mesh"]),
    "pose-count": (
        lambda s: s.apply_collision_object(
            CollisionObject(id="b", primitives=[SolidPrimitive(type=1, dimensions=[1, 1, 1])], primitive_poses=[pose(), pose()])
        ),
        ValueError, ["'b'", "1 primitives but 2 primitive_poses", "at most one pose per primitive"],
    ),
    "mesh-bad-index": (
        lambda s: s.apply_collision_object(
            CollisionObject(id="b", meshes=[msgs.Mesh(vertices=[msgs.Point()] * 3, triangles=[msgs.MeshTriangle(vertex_indices=[0, 1, 5])])], mesh_poses=[pose()])
        ),
        ValueError, ["'b'", "[0, 2]"],
    ),
    "empty-id": (lambda s: s.apply_collision_object(box("", (0, 0, 0))), ValueError, ["non-empty"]),
    "unknown-operation": (lambda s: s.apply_collision_object(CollisionObject(id="far", operation=9)), ValueError, ["'far'", "9", "ADD"]),
    "append-bad-shape": (
        lambda s: s.apply_collision_object(obj("far", SolidPrimitive.SPHERE, [0.0], op=CollisionObject.APPEND)),
        ValueError, ["'far'", "sphere"],
    ),
    "attach-unknown-object": (lambda s: s.attach_object("ghost", "panda_hand"), KeyError, ["'ghost'", "far"]),
    "attach-unknown-link": (lambda s: s.attach_object("far", "panda_palm"), KeyError, ["'panda_palm'", "panda_hand"]),
    "attach-unknown-touch-link": (lambda s: s.attach_object("far", "panda_hand", ["panda_palm"]), KeyError, ["'panda_palm'", "panda_hand"]),
    "detach-not-attached": (lambda s: s.detach_object("far"), KeyError, ["'far'", "not attached", "obj"]),
    "attach-msg-unknown-link": (
        lambda s: s.apply_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_palm", object=box("new", (0, 0, 0)))),
        KeyError, ["'panda_palm'", "panda_hand"],
    ),
    "attach-msg-unknown-frame": (
        lambda s: s.apply_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_hand", object=box("new", (0, 0, 0), frame="tool0"))),
        KeyError, ["'new'", "'tool0'", "panda_hand"],
    ),
    "attach-msg-bad-shape": (
        lambda s: s.apply_attached_collision_object(
            msgs.AttachedCollisionObject(link_name="panda_hand", object=obj("new", SolidPrimitive.BOX, [0.1, -0.1, 0.1], frame="panda_hand"))
        ),
        ValueError, ["'new'", "box"],
    ),
    "attach-msg-unknown-touch-link": (
        lambda s: s.apply_attached_collision_object(
            msgs.AttachedCollisionObject(link_name="panda_hand", object=box("new", (0, 0, 0)), touch_links=["panda_palm"])
        ),
        KeyError, ["'panda_palm'", "panda_hand"],
    ),
    "attach-msg-move": (
        lambda s: s.apply_attached_collision_object(
            msgs.AttachedCollisionObject(link_name="panda_hand", object=CollisionObject(id="far", operation=CollisionObject.MOVE))
        ),
        ValueError, ["ADD", "REMOVE"],
    ),
    "attach-msg-append-no-shapes": (
        lambda s: s.apply_attached_collision_object(
            msgs.AttachedCollisionObject(link_name="panda_hand", object=CollisionObject(id="obj", operation=CollisionObject.APPEND))
        ),
        ValueError, ["'obj'", "APPEND", "primitive or mesh"],
    ),
    "detach-msg-unknown": (
        lambda s: s.apply_attached_collision_object(msgs.AttachedCollisionObject(object=CollisionObject(id="ghost", operation=CollisionObject.REMOVE))),
        KeyError, ["'ghost'", "obj"],
    ),
    "get-unknown-world-object": (lambda s: s.get_world_object("ghost"), KeyError, ["'ghost'", "far"]),
    "get-attached-as-world-object": (lambda s: s.get_world_object("obj"), KeyError, ["'obj'", "far", "'obj' is attached to 'panda_hand'"]),
    "get-unknown-attached": (lambda s: s.get_attached_object("ghost"), KeyError, ["'ghost'", "obj"]),
    "unknown-frame": (lambda s: s.get_frame_transform("far/ghost"), KeyError, ["'far/ghost'"]),
    "not-a-message": (lambda s: s.apply_collision_object({"id": "b"}), TypeError, ["CollisionObject"]),
    "planes": (
        lambda s: s.apply_collision_object(CollisionObject(id="b", planes=[msgs.Plane()], plane_poses=[pose()])),
        ValueError, ["'b'", "planes"],
    ),
}


@pytest.mark.parametrize("case", list(BAD_INPUT))
def test_bad_input_names_the_item_and_leaves_the_scene_as_it_was(scene, case):
    """Each bad edit raises an error naming the bad item (and what exists) and changes nothing."""
    call, error, words = BAD_INPUT[case]
    _attached(scene)
    before = snapshot(scene)
    colliding = scene.get_collisions()
    with pytest.raises(error) as e:
        call(scene)
    message = str(e.value)
    for word in words:
        assert word in message, (word, message)
    assert snapshot(scene) == before
    assert scene.get_collisions() == colliding


# ---------------------------------------------------------------------------- end effector at a pose
def _tcp_at(scene, xyz):
    """The panda_link8 pose that puts panda_hand_tcp, pointing down, at ``xyz``."""
    state = scene.current_state
    tcp_in_link8 = np.linalg.inv(state.get_global_link_transform("panda_link8")) @ state.get_global_link_transform(
        "panda_hand_tcp"
    )
    target = np.eye(4)
    target[:3, :3] = np.diag([1.0, -1.0, -1.0])
    target[:3, 3] = xyz
    return target @ np.linalg.inv(tcp_in_link8)


def test_link_collisions_at_a_pose_move_only_the_links_below(scene):
    """get_link_collisions_at places link8 and everything below it at the pose; the arm stays."""
    scene.apply_collision_object(box("b", (0.6, 0.0, 0.3), (0.1, 0.1, 0.1)))
    assert not scene.is_state_colliding()
    hits = scene.get_link_collisions_at("panda_link8", _tcp_at(scene, (0.6, 0.0, 0.3)))
    assert ("panda_hand", "b") in hits and ("panda_leftfinger", "b") in hits
    assert all(body in scene.robot_model.descendant_link_names("panda_link8") for body, _ in hits)
    assert scene.get_link_collisions_at("panda_link8", _tcp_at(scene, (0.6, 0.0, 0.8))) == []
    # the robot state is untouched by the query
    assert not scene.is_state_colliding()


def test_link_collisions_at_a_pose_honour_the_acm_and_carry_attached_objects(scene):
    """Allowed pairs are not reported; an object attached below the link moves with it."""
    scene.apply_collision_object(box("b", (0.6, 0.0, 0.3), (0.1, 0.1, 0.1)))
    scene.allowed_collision_matrix.set_entry("b", scene.robot_model.descendant_link_names("panda_link8"), True)
    assert scene.get_link_collisions_at("panda_link8", _tcp_at(scene, (0.6, 0.0, 0.3))) == []
    tcp = scene.current_state.get_global_link_transform("panda_hand_tcp")[:3, 3]
    scene.apply_collision_object(box("tool", tcp, (0.02, 0.02, 0.02)))
    scene.attach_object("tool", "panda_hand", touch_links=FINGERS)
    assert scene.get_link_collisions_at("panda_link8", _tcp_at(scene, (0.6, 0.0, 0.3))) == [("tool", "b")]


def test_link_collisions_at_a_pose_allow_the_moving_links_above(scene, panda):
    """As MTC's end-effector check: the IK link itself (panda_link7, moved by joint 7) and the
    arm above it may collide; only the links below it (and the base, fixed to the root) count."""
    assert panda.links_moved_above("panda_link8") == ["panda_link8", "panda_link7"] + [
        f"panda_link{k}" for k in range(6, 0, -1)
    ]
    assert panda.links_moved_above("panda_link0") == []  # the root: fixed to itself
    l7 = scene.current_state.get_global_link_transform("panda_link7")
    # a small sphere touching link7 only: ignored
    scene.apply_collision_object(sphere("s7", l7[:3, 3] + (0.05, 0.0, -0.07), 0.015))
    assert scene.get_collisions() == [("panda_link7", "s7")]
    assert scene.get_link_collisions_at("panda_link7", l7) == []
    # one at the hand: reported, moved body first
    hand = scene.current_state.get_global_link_transform("panda_hand")[:3, 3]
    scene.apply_collision_object(sphere("sh", hand, 0.02))
    assert scene.get_link_collisions_at("panda_link7", l7) == [("panda_hand", "sh")]


def test_link_collisions_at_a_pose_include_the_base(scene):
    """The hand placed into the robot's base (fixed to the root) collides with it: MTC checks
    the moved links against the links fixed to the root as well as the world."""
    state = scene.current_state
    l7, hand = state.get_global_link_transform("panda_link7"), state.get_global_link_transform("panda_hand")
    hand_at_base = np.eye(4)
    hand_at_base[:3, 3] = (0.0, 0.0, 0.1)
    target = hand_at_base @ np.linalg.solve(hand, l7)  # link7's pose putting the hand there
    assert ("panda_hand", "panda_link0") in scene.get_link_collisions_at("panda_link7", target)
    scene.allowed_collision_matrix.set_entry("panda_hand", "panda_link0", True)
    assert ("panda_hand", "panda_link0") not in scene.get_link_collisions_at("panda_link7", target)


def test_descendant_links(panda):
    """descendant_link_names: the link itself and every link below it; unknown links name the links."""
    assert panda.descendant_link_names("panda_link8") == [
        "panda_link8", "panda_hand", "panda_hand_tcp", "panda_leftfinger", "panda_rightfinger"
    ]
    assert panda.descendant_link_names("panda_leftfinger") == ["panda_leftfinger"]
    with pytest.raises(KeyError, match="unknown link 'nope'.*panda_link0"):
        panda.descendant_link_names("nope")


def test_validity_checker_outlives_its_scene(panda):
    """A checker handed to a planner keeps its collision set-up alive after the scene is gone."""
    import gc

    def make():
        ps = PlanningScene(panda)
        ps.current_state.set_to_default_values("panda_arm", "ready")
        ps.apply_collision_object(box("b", (0.307, 0.0, 0.487), (0.12, 0.12, 0.04)))
        return ps.state_validity_checker("panda_arm"), ps.current_state.positions.copy()

    is_valid, q = make()
    gc.collect()
    assert is_valid(q) is False


def test_state_reports_attached_frames_as_link_and_offset(scene):
    """get_attached_frame: (link, offset) for an attached object and its subframe; None otherwise."""
    msg = box("tool", (0.307, 0.0, 0.45), (0.02, 0.02, 0.02))
    msg.subframe_names, msg.subframe_poses = ["tip"], [pose((0.0, 0.0, 0.05))]
    scene.apply_collision_object(msg)
    scene.attach_object("tool", "panda_hand", touch_links=FINGERS)
    state = scene.current_state
    link, offset = state.get_attached_frame("tool")
    assert link == "panda_hand"
    np.testing.assert_allclose(state.get_global_link_transform(link) @ offset, state.get_frame_transform("tool"))
    link, offset = state.get_attached_frame("tool/tip")
    np.testing.assert_allclose(translation(state.get_global_link_transform(link) @ offset), (0.307, 0.0, 0.5), atol=1e-9)
    assert state.get_attached_frame("panda_hand") is None
    assert RobotState(scene.robot_model).get_attached_frame("tool") is None


# ---------------------------------------------------------------------------- MoveIt's message rules
def test_missing_shape_poses_are_identity(scene):
    """As MoveIt: a shape without a pose sits at the object's frame (identity), not an error."""
    msg = CollisionObject(id="b", primitives=[SolidPrimitive(type=SolidPrimitive.BOX, dimensions=[0.1, 0.1, 0.1])] * 2,
                          primitive_poses=[pose((0.0, 0.0, 0.3))])
    msg.pose = pose((1.0, 0.0, 0.0))
    scene.apply_collision_object(msg)
    o = scene.get_world_object("b")
    np.testing.assert_allclose(o.pose[:3, 3], [1.0, 0.0, 0.0])
    np.testing.assert_allclose([p[:3, 3] for p in o.shape_poses], [[0.0, 0.0, 0.3], [0.0, 0.0, 0.0]])


def test_single_shape_with_unset_object_pose_defines_the_object_frame(scene):
    """As MoveIt: one shape and an unset (all-zero) object pose: the shape's pose becomes the
    object's pose, so the object frame and its subframes are where the shape is."""
    msg = CollisionObject(id="cyl", primitives=[SolidPrimitive(type=SolidPrimitive.CYLINDER, dimensions=[0.2, 0.03])],
                          primitive_poses=[pose((0.53, 0.55, 0.84))])
    assert msg.pose == msgs.Pose()  # unset: all zeros
    msg.subframe_names = ["tip"]
    msg.subframe_poses = [pose((0.0, 0.0, 0.1))]
    scene.apply_collision_object(msg)
    np.testing.assert_allclose(scene.get_frame_transform("cyl")[:3, 3], [0.53, 0.55, 0.84])
    np.testing.assert_allclose(scene.get_frame_transform("cyl/tip")[:3, 3], [0.53, 0.55, 0.94])
    np.testing.assert_allclose(scene.get_world_object("cyl").shape_poses[0], np.eye(4))
    # a set object pose keeps both as given
    msg2 = CollisionObject(id="b2", pose=pose((1.0, 0.0, 0.0)), primitives=[SolidPrimitive(type=SolidPrimitive.BOX, dimensions=[0.1] * 3)],
                           primitive_poses=[pose((0.0, 0.0, 0.2))])
    scene.apply_collision_object(msg2)
    np.testing.assert_allclose(scene.get_frame_transform("b2")[:3, 3], [1.0, 0.0, 0.0])
    np.testing.assert_allclose(scene.get_world_object("b2").shape_poses[0][:3, 3], [0.0, 0.0, 0.2])


def test_add_with_the_id_of_an_attached_object_adds_a_world_object(scene):
    """As MoveIt: ADD only replaces a world object of that id; an attached one of the same id stays."""
    held_scene(scene)
    scene.attach_object("obj", "panda_hand", FINGERS)
    assert scene.get_collisions() == []
    scene.apply_collision_object(box("obj", (1.0, 0.0, 0.0)))
    assert scene.world_object_names == ["obj"] and scene.attached_object_names == ["obj"]
    assert scene.get_collisions() == []  # the attached body keeps its touch links
    # a world object of that id in the hand collides (the touch links are the attached body's)
    scene.apply_collision_object(box("obj", HELD["xyz"], HELD["size"]))
    assert ("panda_hand", "obj") in scene.get_collisions()


def test_attaching_shapes_of_an_attached_id_replaces_it(scene):
    """As MoveIt: attaching an object with shapes under an attached id replaces the attached body."""
    held_scene(scene)
    scene.attach_object("obj", "panda_hand")
    small = box("obj", (0.0, 0.0, 0.1), (0.01, 0.01, 0.01), frame="panda_hand")
    scene.apply_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_hand", object=small))
    att = scene.get_attached_object("obj")
    assert att.link == "panda_hand"
    np.testing.assert_allclose(att.object.shapes[0].dimensions, [0.01, 0.01, 0.01])


def test_objects_attached_to_the_same_link_do_not_collide_with_each_other(scene):
    """As MoveIt ("bodies attached to the same link should not collide"): a tool and the part it
    holds, both attached to the hand and overlapping, leave the state collision-free; objects
    on different links are still checked against each other."""
    from mtc import msgs

    def box(name, x):
        return msgs.CollisionObject(
            id=name, header=msgs.Header(frame_id="panda_hand"), operation=msgs.CollisionObject.ADD,
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.04, 0.04, 0.04])],
            primitive_poses=[msgs.Pose(position=msgs.Point(x=x, z=0.25), orientation=msgs.Quaternion(w=1.0))],
        )

    scene.current_state.set_to_default_values("panda_arm", "ready")
    for name, x in (("tool", 0.0), ("part", 0.01)):
        scene.apply_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_hand", object=box(name, x)))
    assert not scene.is_state_colliding()
    part = scene.get_attached_collision_object_msg("part")
    scene.apply_attached_collision_object(msgs.AttachedCollisionObject(
        link_name="panda_hand", object=msgs.CollisionObject(id="part", operation=msgs.CollisionObject.REMOVE)))
    part.link_name = "panda_link7"
    scene.apply_attached_collision_object(part)  # the same place, now held by another link
    assert scene.is_state_colliding()
    assert ("part", "tool") in {tuple(sorted(p)) for p in scene.get_collisions()}


def test_move_with_shape_poses(scene):
    """MOVE with shape poses moves the shapes too (as MoveIt 2); a MoveIt 1 style MOVE (the new
    place in primitive_poses, the pose unset) of a one-shape object puts it where it says, with
    its frame, instead of at the header frame's origin; a wrong count of shape poses is refused
    and changes nothing."""
    from mtc import msgs

    def box_msg(op, at=None, prims=1, pose=None):
        return msgs.CollisionObject(
            id="box", header=msgs.Header(frame_id="world"), operation=op,
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.1] * 3)] * prims
            if op == msgs.CollisionObject.ADD else [],
            primitive_poses=[msgs.Pose(position=msgs.Point(*p), orientation=msgs.Quaternion(w=1.0)) for p in at or []],
            pose=pose or msgs.Pose())

    scene.apply_collision_object(box_msg(msgs.CollisionObject.ADD, [(1.0, 0.0, 0.5)]))
    scene.apply_collision_object(box_msg(msgs.CollisionObject.MOVE, [(1.0, 0.5, 0.5)]))
    np.testing.assert_allclose(scene.get_frame_transform("box")[:3, 3], [1.0, 0.5, 0.5])
    # two shapes: the pose places the object, the shape poses the shapes within it
    scene.apply_collision_object(box_msg(msgs.CollisionObject.ADD, [(0, 0, 0), (0, 0, 0.2)], prims=2,
                                         pose=msgs.Pose(position=msgs.Point(0.5, 0, 0), orientation=msgs.Quaternion(w=1.0))))
    scene.apply_collision_object(box_msg(msgs.CollisionObject.MOVE, [(0, 0, 0), (0, 0.3, 0)],
                                         pose=msgs.Pose(position=msgs.Point(0.5, 0, 0.1), orientation=msgs.Quaternion(w=1.0))))
    msg = scene.get_collision_object_msg("box")
    assert [round(p.position.y, 9) for p in msg.primitive_poses] == [0.0, 0.3]
    with pytest.raises(ValueError, match="1 shape poses for 2 shapes"):
        scene.apply_collision_object(box_msg(msgs.CollisionObject.MOVE, [(0, 0, 0)]))
    assert scene.get_collision_object_msg("box") == msg


def test_detaching_beside_a_world_object_of_the_same_id_keeps_the_world_one(scene, caplog):
    """As MoveIt ("NOT adding the detached body ... to the collision world"): a world object and
    an attached one may share an id; detaching drops the attached one, with a warning, and the
    world object stays where it is."""
    from mtc import msgs

    def tool(frame, z):
        return msgs.CollisionObject(
            id="tool", header=msgs.Header(frame_id=frame), operation=msgs.CollisionObject.ADD,
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.02] * 3)],
            primitive_poses=[msgs.Pose(position=msgs.Point(z=z), orientation=msgs.Quaternion(w=1.0))])

    scene.apply_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_hand", object=tool("panda_hand", 0.2)))
    scene.apply_collision_object(tool("world", 2.0))
    assert scene.world_object_names == ["tool"] and scene.attached_object_names == ["tool"]
    with caplog.at_level("WARNING", logger="mtc"):
        scene.detach_object("tool")
    assert scene.attached_object_names == [] and "not added" in caplog.text
    np.testing.assert_allclose(scene.get_frame_transform("tool")[:3, 3], [0.0, 0.0, 2.0])


def test_object_colors(scene):
    """Colours as moveit_py: apply_collision_object's ObjectColor (set for its own id),
    set_object_color (for any id), listed in the scene message, kept by diffs, dropped with
    the object; a bad colour raises before the object is applied."""
    red = msgs.ColorRGBA(r=1.0, a=1.0)
    scene.apply_collision_object(box("b", (1.0, 0.0, 0.0)), msgs.ObjectColor(id="b", color=red))
    scene.set_object_color("later", msgs.ColorRGBA(g=1.0, a=0.5))
    assert scene.get_object_color("b") == red
    child = scene.diff()
    assert child.get_object_color("b") == red
    colors = scene.get_planning_scene_msg().object_colors
    assert [(c.id, c.color.r, c.color.g) for c in colors] == [("b", 1.0, 0.0), ("later", 0.0, 1.0)]
    assert scene.planning_scene_message.object_colors == colors
    scene.apply_collision_object(CollisionObject(id="b", operation=CollisionObject.REMOVE))
    assert scene.get_object_color("b") is None and child.get_object_color("b") == red
    with pytest.raises(TypeError, match="ObjectColor"):
        scene.apply_collision_object(box("c", (1.0, 0.0, 0.0)), red)
    assert "c" not in scene.world_object_names
    with pytest.raises(TypeError, match="ColorRGBA"):
        scene.set_object_color("c", msgs.ObjectColor(id="c"))
    with pytest.raises(ValueError, match="non-empty"):
        scene.set_object_color("", red)


def test_process_planning_scene_world_is_all_or_nothing(scene):
    """process_planning_scene_world (also apply_planning_scene_world) applies each object;
    a bad one raises and leaves the scene as it was."""
    world = msgs.PlanningSceneWorld(collision_objects=[box("a", (1.0, 0.0, 0.0)), box("b", (2.0, 0.0, 0.0))])
    scene.process_planning_scene_world(world)
    assert scene.world_object_names == ["a", "b"]
    before = snapshot(scene)
    bad = msgs.PlanningSceneWorld(collision_objects=[box("c", (1.0, 0.0, 0.0)), box("d", (0, 0, 0), frame="nowhere")])
    with pytest.raises(KeyError, match="'d'.*'nowhere'"):
        scene.apply_planning_scene_world(bad)
    assert snapshot(scene) == before
    scene.process_attached_collision_object(msgs.AttachedCollisionObject(link_name="panda_hand", object=CollisionObject(id="a")))
    assert scene.attached_object_names == ["a"]


def test_is_state_constrained(scene):
    """is_state_constrained (moveit_py) checks joint and link constraints on a state."""
    state = scene.current_state
    q1 = state.joint_positions["panda_joint1"]
    inside = msgs.Constraints(joint_constraints=[msgs.JointConstraint(
        joint_name="panda_joint1", position=q1, tolerance_above=0.1, tolerance_below=0.1, weight=1.0)])
    outside = msgs.Constraints(joint_constraints=[msgs.JointConstraint(
        joint_name="panda_joint1", position=q1 + 1.0, tolerance_above=0.1, tolerance_below=0.1, weight=1.0)])
    assert scene.is_state_constrained(state, inside)
    assert not scene.is_state_constrained(state, outside, verbose=True)
    with pytest.raises(TypeError, match="RobotState"):
        scene.is_state_constrained("panda_arm", inside)


def test_acm_clear_checks_every_pair(scene):
    """AllowedCollisionMatrix.clear() (MoveIt's) drops every entry, the SRDF's disabled pairs
    too: adjacent links, which touch, then count as colliding."""
    acm = scene.allowed_collision_matrix
    assert acm.get_entry("panda_link1", "panda_link2") and not scene.is_state_colliding()
    acm.clear()
    assert not acm.get_entry("panda_link1", "panda_link2")
    assert ("panda_link1", "panda_link2") in scene.get_collisions()
