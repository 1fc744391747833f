"""Tests of mtc.scene.robot_state: positions, named and random states, kinematics, distances."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pinocchio as pin
import pytest
from scene_helpers import TOY_URDF

from mtc import msgs
from mtc.robots import panda_urdf_path
from mtc.scene.robot_state import RobotState

ARM_JOINTS = [f"panda_joint{i}" for i in range(1, 8)]
READY = [0, -0.785, 0, -2.356, 0, 1.571, 0.785]


@pytest.fixture
def state(panda):
    s = RobotState(panda)
    s.set_to_default_values("panda_arm", "ready")
    s.set_to_default_values("hand", "open")
    return s


def random_states(model, n, seed, group=None):
    s = RobotState(model)
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        s.set_to_random_positions(group, rng=rng)
        out.append(s.copy())
    return out


# ---------------------------------------------------------------------------- positions
def test_default_state_is_moveits(panda, toy):
    """As MoveIt's default positions: zero where the joint's bounds allow it, else the middle of
    its bounds (the Panda's joint 4 spans -3.0718..-0.0698); unbounded joints are zero."""
    s = RobotState(panda)
    expected = np.zeros(9)
    expected[3] = (-3.0718 + -0.0698) / 2
    np.testing.assert_allclose(s.positions, expected, atol=1e-12)
    assert s.satisfies_bounds()
    assert s.robot_model is panda
    moved = s.copy()
    moved.set_to_random_positions()
    moved.set_to_default_values()
    np.testing.assert_array_equal(moved.positions, s.positions)
    np.testing.assert_array_equal(RobotState(toy).positions, np.zeros(3))


def test_constructor_checks_its_arguments(panda):
    """A model is required; a positions vector must have one value per variable."""
    with pytest.raises(TypeError, match="RobotModel"):
        RobotState("panda")
    with pytest.raises(ValueError, match=r"9 values.*panda_joint1"):
        RobotState(panda, np.zeros(7))
    s = RobotState(panda, np.arange(9) * 0.01)
    assert s.positions[8] == pytest.approx(0.07)  # the mimic follower follows its master


def test_positions_are_read_only_and_assignable(state):
    """positions is a read-only view; assigning a full vector replaces it."""
    with pytest.raises(ValueError):
        state.positions[0] = 1.0
    q = state.positions.copy()
    q[0] = 0.3
    state.positions = q
    assert state.positions[0] == 0.3
    with pytest.raises(ValueError, match=r"9 values"):
        state.positions = np.zeros(3)
    assert state.positions[0] == 0.3


def test_joint_positions_dict_and_partial_assignment(state):
    """joint_positions is name -> value; assigning a dict changes only the named joints."""
    jp = state.joint_positions
    assert list(jp) == state.robot_model.variable_names
    assert [jp[j] for j in ARM_JOINTS] == pytest.approx(READY)
    before = state.positions.copy()
    state.joint_positions = {"panda_joint2": 0.1, "panda_joint6": 1.0}
    after = state.positions
    assert after[1] == 0.1 and after[5] == 1.0
    changed = np.flatnonzero(after != before)
    assert changed.tolist() == [1, 5]


def test_unknown_joint_changes_nothing(state):
    """A dict with an unknown joint raises KeyError naming it and the joints, and sets nothing."""
    before = state.positions.copy()
    with pytest.raises(KeyError) as e:
        state.joint_positions = {"panda_joint1": 1.0, "panda_joint9": 0.0}
    assert "'panda_joint9'" in str(e.value) and "panda_joint7" in str(e.value)
    np.testing.assert_array_equal(state.positions, before)
    with pytest.raises(TypeError, match="dict"):
        state.joint_positions = [1.0, 2.0]


def test_mimic_joint_follows_its_master(state):
    """Every way of setting panda_finger_joint1 moves panda_finger_joint2 with it."""
    state.joint_positions = {"panda_finger_joint1": 0.02}
    assert state.joint_positions["panda_finger_joint2"] == 0.02
    state.set_joint_group_positions("hand", [0.01])
    assert state.joint_positions["panda_finger_joint2"] == 0.01
    q = state.positions.copy()
    q[7], q[8] = 0.03, 0.0  # a vector that disagrees: the master wins
    state.positions = q
    assert state.positions[8] == 0.03
    state.set_to_default_values("hand", "close")
    assert state.positions[7] == state.positions[8] == 0.0
    # the right finger moves away from the hand's centre as the left does
    state.set_to_default_values("hand", "open")
    left = state.get_global_link_transform("panda_leftfinger")
    right = state.get_global_link_transform("panda_rightfinger")
    assert np.linalg.norm(left[:3, 3] - right[:3, 3]) == pytest.approx(0.07, abs=1e-9)


def test_group_positions(state):
    """set/get_joint_group_positions use the group's active variables in order."""
    np.testing.assert_allclose(state.get_joint_group_positions("panda_arm"), READY)
    assert state.get_joint_group_positions("hand").tolist() == [0.035]
    assert state.get_joint_group_positions("panda_arm_hand").tolist() == pytest.approx([*READY, 0.035])
    state.set_joint_group_positions("panda_arm", np.linspace(0.0, 0.6, 7))
    np.testing.assert_allclose(state.positions[:7], np.linspace(0.0, 0.6, 7))
    assert state.positions[7] == 0.035
    got = state.get_joint_group_positions("panda_arm")
    got[0] = 9.0  # a copy
    assert state.positions[0] == 0.0


def test_group_positions_bad_input(state):
    """Wrong value count names the group and its variables; unknown group names the groups."""
    before = state.positions.copy()
    with pytest.raises(ValueError) as e:
        state.set_joint_group_positions("panda_arm", [0.0] * 6)
    assert "'panda_arm'" in str(e.value) and "7 variables" in str(e.value) and "got 6" in str(e.value)
    with pytest.raises(KeyError, match=r"'arm'.*panda_arm"):
        state.set_joint_group_positions("arm", [0.0] * 7)
    with pytest.raises(KeyError, match=r"'arm'.*panda_arm"):
        state.get_joint_group_positions("arm")
    np.testing.assert_array_equal(state.positions, before)


def test_default_values_and_named_states(panda):
    """set_to_default_values(): zeros in bounds; (group, name): the SRDF state; others unchanged."""
    s = RobotState(panda)
    s.set_to_default_values("panda_arm", "ready")
    np.testing.assert_allclose(s.positions[:7], READY)
    assert s.positions[7] == 0.0
    s.set_to_default_values("hand", "open")
    np.testing.assert_allclose(s.positions, [*READY, 0.035, 0.035])
    s.set_to_default_values("panda_arm", "extended")
    np.testing.assert_allclose(s.positions[:7], [panda.get_group_state("panda_arm", "extended")[j] for j in ARM_JOINTS])
    assert s.positions[7] == 0.035
    s.set_to_default_values()
    np.testing.assert_array_equal(s.positions, RobotState(panda).positions)


def test_default_values_bad_input(state):
    """Unknown state or group raise KeyError naming what exists; one argument is a TypeError."""
    before = state.positions.copy()
    with pytest.raises(KeyError, match=r"'home'.*ready"):
        state.set_to_default_values("panda_arm", "home")
    with pytest.raises(KeyError, match=r"'gripper'.*hand"):
        state.set_to_default_values("gripper", "open")
    with pytest.raises(TypeError):
        state.set_to_default_values("panda_arm")
    np.testing.assert_array_equal(state.positions, before)


def test_random_positions_are_seeded(panda):
    """The same seed gives the same state; another seed another."""
    a, b, c = (RobotState(panda) for _ in range(3))
    a.set_to_random_positions(rng=7)
    b.set_to_random_positions(rng=np.random.default_rng(7))
    c.set_to_random_positions(rng=8)
    np.testing.assert_array_equal(a.positions, b.positions)
    assert not np.array_equal(a.positions, c.positions)
    with pytest.raises(TypeError, match="seed"):
        a.set_to_random_positions(rng="seven")


def test_random_positions_without_rng_differ_per_call_and_repeat_per_run():
    """Without an rng each call draws a new sample (as MoveIt's state RNG: a loop drawing until
    a state is valid ends), and a fresh process draws the same samples again."""
    script = textwrap.dedent("""
        import mtc
        state = mtc.RobotState(mtc.robots.panda())
        samples = []
        for _ in range(3):
            state.set_to_random_positions("panda_arm")
            samples.append(state.get_joint_group_positions("panda_arm").round(12).tolist())
        assert len({tuple(s) for s in samples}) == 3
        print(samples)
    """)
    runs = [subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
            for _ in range(2)]
    assert all(r.returncode == 0 for r in runs), [r.stderr for r in runs]
    assert runs[0].stdout == runs[1].stdout


@pytest.mark.parametrize("bad", [float("nan"), float("inf")])
def test_positions_must_be_finite(panda, bad):
    """A NaN or infinite joint value is refused where it is set, naming the joint; the state
    keeps its values."""
    state = RobotState(panda)
    before = state.positions.copy()
    with pytest.raises(ValueError, match=r"finite numbers, got panda_joint2=(nan|inf)"):
        state.set_joint_group_positions("panda_arm", [0, bad, 0, -2, 0, 2, 0.7])
    with pytest.raises(ValueError, match="finite"):
        state.joint_positions = {"panda_joint1": bad}
    with pytest.raises(ValueError, match="finite"):
        RobotState(panda, np.full(panda.variable_count, bad))
    with pytest.raises(TypeError, match="joint 'panda_joint1': the position must be a number, got 'abc'"):
        state.joint_positions = {"panda_joint1": "abc"}
    np.testing.assert_array_equal(state.positions, before)
    state.update()  # moveit_py's call after changing a state: nothing to do here


def test_random_positions_in_bounds_and_only_the_group(panda, state):
    """Random values lie inside the bounds; a group's random state leaves other joints alone."""
    for s in random_states(panda, 50, seed=3):
        assert s.satisfies_bounds()
        assert s.positions[8] == s.positions[7]
    before = state.positions.copy()
    state.set_to_random_positions("hand", rng=1)
    np.testing.assert_array_equal(state.positions[:7], before[:7])
    assert state.positions[7] != before[7]


def test_random_positions_of_continuous_joints(toy):
    """Continuous joints sample in [-pi, pi)."""
    Q = np.array([s.positions for s in random_states(toy, 200, seed=5)])
    assert Q.min() >= -np.pi and Q.max() < np.pi
    assert Q.max() - Q.min() > 5.0


# ---------------------------------------------------------------------------- kinematics
@pytest.fixture(scope="module")
def direct_panda():
    """The Panda URDF loaded by Pinocchio directly, as the reference for frame transforms."""
    model = pin.buildModelFromUrdf(panda_urdf_path())
    return model, model.createData()


def test_link_transforms_match_pinocchio(panda, direct_panda):
    """Every link's transform equals Pinocchio's own FK of the URDF, at random states."""
    model, data = direct_panda
    for s in random_states(panda, 10, seed=11):
        pin.framesForwardKinematics(model, data, s.positions)
        for link in panda.link_model_names:
            expected = data.oMf[model.getFrameId(link)].homogeneous
            np.testing.assert_allclose(s.get_global_link_transform(link), expected, atol=1e-12, err_msg=link)
        np.testing.assert_allclose(s.get_frame_transform("world"), np.eye(4))


def test_toy_transforms_match_pinocchio_continuous_joints(toy):
    """The toy robot's one-angle continuous joints agree with Pinocchio's cos/sin joints."""
    model = pin.buildModelFromUrdf(str(TOY_URDF))
    data = model.createData()
    # put something off the axis on the tip, so rotations show in positions
    tip_offset = pin.SE3(np.eye(3), np.array([0.0, 0.3, 0.1]))
    for s in random_states(toy, 5, seed=2):
        q = pin.neutral(model)
        for name, angle in s.joint_positions.items():
            idx = model.joints[model.getJointId(name)].idx_q
            q[idx : idx + 2] = np.cos(angle), np.sin(angle)
        pin.framesForwardKinematics(model, data, q)
        for link in ("link1", "link2", "tip"):
            T = data.oMf[model.getFrameId(link)]
            np.testing.assert_allclose(s.get_global_link_transform(link), T.homogeneous, atol=1e-12)
        expected = (data.oMf[model.getFrameId("tip")] * tip_offset).homogeneous
        np.testing.assert_allclose(s.get_global_link_transform("tip") @ tip_offset.homogeneous, expected, atol=1e-12)


def test_hand_frames(state):
    """panda_hand_tcp is 0.1034 m along panda_hand's z; at ready the hand points down."""
    hand = state.get_global_link_transform("panda_hand")
    tcp = state.get_frame_transform("panda_hand_tcp")
    offset = np.eye(4)
    offset[2, 3] = 0.1034
    np.testing.assert_allclose(tcp, hand @ offset, atol=1e-12)
    np.testing.assert_allclose(hand[:3, 2], [0, 0, -1], atol=1e-3)
    np.testing.assert_allclose(hand[:3, 3], [0.307, 0.0, 0.59], atol=2e-3)


def test_fk_cache_tracks_each_state(panda):
    """States share the model's Pinocchio data; each still gets its own FK, in any order."""
    a, b = random_states(panda, 2, seed=4)
    ta = a.get_global_link_transform("panda_hand")
    tb = b.get_global_link_transform("panda_hand")
    assert not np.allclose(ta, tb)
    np.testing.assert_array_equal(a.get_global_link_transform("panda_hand"), ta)
    c = a.copy()
    q = c.positions.copy()
    q[0] += 0.5
    c.positions = q
    assert not np.allclose(c.get_global_link_transform("panda_hand"), ta)
    np.testing.assert_array_equal(a.get_global_link_transform("panda_hand"), ta)
    # the returned matrix is a copy
    ta[0, 3] = 99.0
    assert a.get_global_link_transform("panda_hand")[0, 3] != 99.0


def test_get_pose_is_the_link_transform(state):
    """get_pose returns the link's transform as a msgs.Pose."""
    pose = state.get_pose("panda_hand_tcp")
    assert isinstance(pose, msgs.Pose)
    np.testing.assert_allclose(msgs.pose_to_matrix(pose), state.get_global_link_transform("panda_hand_tcp"), atol=1e-9)


def test_unknown_link_and_frame(state):
    """Unknown links and frames raise KeyError naming them and the links."""
    with pytest.raises(KeyError) as e:
        state.get_global_link_transform("panda_link9")
    assert "'panda_link9'" in str(e.value) and "panda_hand_tcp" in str(e.value)
    with pytest.raises(KeyError) as e:
        state.get_frame_transform("tool0")
    assert "'tool0'" in str(e.value) and "panda_hand" in str(e.value)
    with pytest.raises(KeyError, match="'tool0'"):
        state.get_pose("tool0")
    assert not state.knows_frame_transform("tool0")
    assert state.knows_frame_transform("panda_hand_tcp")


def _numeric_jacobian(state, group, link, h=1e-6, point=None):
    jmg = state.robot_model.get_joint_model_group(group)
    T0 = state.get_global_link_transform(link)
    p = np.zeros(3) if point is None else np.asarray(point)
    x0 = T0[:3, :3] @ p + T0[:3, 3]
    J = np.zeros((6, jmg.variable_count))
    for k, i in enumerate(jmg.variable_indices):
        s = state.copy()
        q = s.positions.copy()
        q[i] += h
        s.positions = q
        T = s.get_global_link_transform(link)
        J[:3, k] = (T[:3, :3] @ p + T[:3, 3] - x0) / h
        J[3:, k] = pin.log3(T[:3, :3] @ T0[:3, :3].T) / h
    return J


@pytest.mark.parametrize(
    "group, link",
    [("panda_arm", "panda_hand_tcp"), ("panda_arm", "panda_link4"), ("panda_arm_hand", "panda_rightfinger"), ("hand", "panda_rightfinger")],
)
def test_jacobian_matches_finite_differences(panda, group, link):
    """get_jacobian is [linear; angular] in world orientation, mimic motion credited to the master."""
    for s in random_states(panda, 3, seed=21):
        J = s.get_jacobian(group, link)
        assert J.shape == (6, panda.get_joint_model_group(group).variable_count)
        np.testing.assert_allclose(J, _numeric_jacobian(s, group, link), atol=2e-5)


def test_jacobian_reference_point(state):
    """A reference point in the link frame adds w x r to the linear part."""
    point = [0.0, 0.0, 0.1034]
    J = state.get_jacobian("panda_arm", "panda_hand", reference_point=point)
    np.testing.assert_allclose(J, _numeric_jacobian(state, "panda_arm", "panda_hand", point=point), atol=2e-5)
    np.testing.assert_allclose(J, state.get_jacobian("panda_arm", "panda_hand_tcp"), atol=1e-9)
    for bad in ([0.1, 0.0], "abc", [0.0, np.nan, 0.0]):
        with pytest.raises(ValueError, match="the reference point must be 3 finite numbers"):
            state.get_jacobian("panda_arm", "panda_hand", reference_point=bad)


def test_jacobian_of_the_toy_robot(toy):
    """Continuous joints: the Jacobian matches finite differences (tip frame; no offset needed)."""
    s = random_states(toy, 1, seed=9)[0]
    np.testing.assert_allclose(s.get_jacobian("group", "link2"), _numeric_jacobian(s, "group", "link2"), atol=2e-5)
    np.testing.assert_allclose(
        s.get_jacobian("group", "link2", reference_point=[0, 0.2, 0.1]),
        _numeric_jacobian(s, "group", "link2", point=[0, 0.2, 0.1]),
        atol=2e-5,
    )


# ---------------------------------------------------------------------------- bounds, distance
def test_satisfies_bounds(state):
    """Outside a limit: False (for all and for the group that holds it); margin widens the bounds."""
    assert state.satisfies_bounds() and state.satisfies_bounds("panda_arm")
    state.joint_positions = {"panda_joint4": 0.0}  # upper limit -0.0698
    assert not state.satisfies_bounds()
    assert not state.satisfies_bounds("panda_arm")
    assert state.satisfies_bounds("hand")
    assert state.satisfies_bounds(margin=0.07)
    state.enforce_bounds()
    assert state.positions[3] == pytest.approx(-0.0698) and state.satisfies_bounds()


def test_distance_sums_active_variables(state):
    """distance is the sum of |delta| over active variables (the mimic follower not counted twice)."""
    other = state.copy()
    other.joint_positions = {"panda_joint1": 0.5, "panda_joint3": -0.25, "panda_finger_joint1": 0.0}
    assert state.distance(other) == pytest.approx(0.5 + 0.25 + 0.035)
    assert other.distance(state) == pytest.approx(0.785)
    assert state.distance(other, "panda_arm") == pytest.approx(0.75)
    assert state.distance(other, "hand") == pytest.approx(0.035)
    assert state.distance(state) == 0.0


def test_distance_wraps_continuous_joints(toy):
    """On continuous joints, 3.1 and -3.1 are 2pi - 6.2 apart, not 6.2."""
    a = RobotState(toy, [3.1, 0.0, 1.0])
    b = RobotState(toy, [-3.1, 0.0, -1.0])
    assert a.distance(b) == pytest.approx((2 * np.pi - 6.2) + 2.0)
    assert a.distance(b, "group") == pytest.approx(2 * np.pi - 6.2)
    assert a.distance(b, "eef_group") == pytest.approx(2.0)


def test_interpolate(toy, state):
    """interpolate goes t of the way, continuous joints the short way, other groups unchanged."""
    a = RobotState(toy, [3.0, 0.0, 0.0])
    b = RobotState(toy, [-3.0, 1.0, 2.0])
    mid = a.interpolate(b, 0.5)
    assert mid.positions[0] == pytest.approx(np.pi) or mid.positions[0] == pytest.approx(-np.pi)
    assert mid.positions[1:].tolist() == pytest.approx([0.5, 1.0])
    only = a.interpolate(b, 0.5, group="eef_group")
    assert only.positions.tolist() == pytest.approx([3.0, 0.0, 1.0])
    other = state.copy()
    other.joint_positions = {"panda_joint1": 1.0, "panda_finger_joint1": 0.0}
    q = state.interpolate(other, 0.25)
    assert q.positions[0] == pytest.approx(0.25)
    assert q.positions[7] == q.positions[8] == pytest.approx(0.035 * 0.75)
    with pytest.raises(ValueError, match="t must be finite, got nan"):
        state.interpolate(other, float("nan"))
    with pytest.raises(TypeError, match="t must be a number"):
        state.interpolate(other, "0.5")


def test_copy_is_independent(state):
    """Changing a copy leaves the original alone and vice versa."""
    c = state.copy()
    assert c == state and c is not state
    c.joint_positions = {"panda_joint1": 1.0}
    assert state.positions[0] == 0.0
    state.joint_positions = {"panda_joint2": 0.3}
    assert c.positions[1] == pytest.approx(-0.785)
    assert c != state
    import copy

    d = copy.deepcopy(state)
    assert d == state and d is not state


MIMIC_URDF = """<robot name="mimic">
  <link name="base"/><link name="a"/><link name="b"/>
  <joint name="master" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <origin xyz="0 0 0.1"/><limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="follower" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/>
    <origin xyz="0.3 0 0"/><limit lower="-5" upper="5" velocity="1" effort="1"/>
    <mimic joint="master" multiplier="-2" offset="0.25"/></joint>
</robot>"""
MIMIC_SRDF = '<robot name="mimic"><group name="g"><joint name="master"/></group></robot>'


def test_mimic_multiplier_and_offset():
    """A follower is multiplier * master + offset; the group holds the follower, exposes only the master;
    the Jacobian credits the follower's motion to the master."""
    from mtc.scene.robot_model import RobotModel

    model = RobotModel(MIMIC_URDF, MIMIC_SRDF)
    assert model.mimic_followers == [(1, 0, -2.0, 0.25)]
    group = model.get_joint_model_group("g")
    assert group.variable_names == ["master"] and "follower" in group.joint_model_names
    s = RobotState(model)
    assert s.positions.tolist() == [0.0, 0.25]
    s.joint_positions = {"master": 0.5}
    assert s.positions.tolist() == pytest.approx([0.5, -0.75])
    s.joint_positions = {"follower": 3.0}  # a follower cannot be set on its own
    assert s.positions.tolist() == pytest.approx([0.5, -0.75])
    point = [0.2, 0.0, 0.1]
    np.testing.assert_allclose(s.get_jacobian("g", "b", reference_point=point), _numeric_jacobian(s, "g", "b", point=point), atol=2e-5)
    other = RobotState(model)
    assert s.distance(other) == pytest.approx(0.5)  # followers do not count


def test_interpolated_and_copied_states_see_attached_objects(panda):
    """As MoveIt's state copies carry attached bodies: a state interpolated from (or copied
    from) a scene's state knows the objects attached in that scene."""
    from mtc.scene.planning_scene import PlanningScene

    scene = PlanningScene(panda)
    box = msgs.CollisionObject(id="held", header=msgs.Header(frame_id="panda_hand"))
    box.primitives = [msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=[0.02, 0.02, 0.02])]
    box.primitive_poses = [msgs.Pose(position=msgs.Point(z=0.1))]
    scene.apply_collision_object(box)
    scene.attach_object("held", "panda_hand")
    a = scene.current_state
    b = a.copy()
    b.set_variable_positions({"panda_joint1": 1.0})
    mid = a.interpolate(b, 0.5)
    for s in (b, mid):
        rel = np.linalg.inv(s.get_frame_transform("panda_hand")) @ s.get_frame_transform("held")
        np.testing.assert_allclose(rel[:3, 3], [0.0, 0.0, 0.1], atol=1e-12)


def test_moveit_py_keyword_forms(panda, state):
    """moveit_py's keywords and overloads: update(type=...) with its three categories,
    set_to_default_values / set_to_random_positions with joint_model_group(_name), and
    get_jacobian(group, reference_point_position) for the group's last link."""
    state.update(force=True, type="links_only")
    with pytest.raises(ValueError, match="Invalid category 'links'"):
        state.update(type="links")
    state.set_to_default_values(joint_model_group_name="panda_arm", name="extended")
    extended = state.get_joint_group_positions("panda_arm").copy()
    state.set_to_default_values(joint_model_group=panda.get_joint_model_group("panda_arm"), name="ready")
    assert not np.allclose(state.get_joint_group_positions("panda_arm"), extended)
    before = state.positions.copy()
    state.set_to_random_positions(joint_model_group=panda.get_joint_model_group("hand"))
    assert np.array_equal(state.positions[:7], before[:7]) and state.satisfies_bounds()
    point = np.array([0.0, 0.0, 0.1])
    np.testing.assert_allclose(state.get_jacobian("panda_arm", point), state.get_jacobian("panda_arm", "panda_link8", point))
    np.testing.assert_allclose(state.get_jacobian(joint_model_group_name="panda_arm", reference_point_position=point),
                               state.get_jacobian("panda_arm", "panda_link8", point))
    with pytest.raises(ValueError, match="use_quaternion_representation is not supported"):
        state.get_jacobian("panda_arm", "panda_link8", point, True)


def test_group_positions_may_cover_mimic_joints(state):
    """As moveit_py (MoveIt's variable count includes mimic joints), set_joint_group_positions
    also takes values for the group's mimic followers, which then follow their master;
    set_joint_group_active_positions takes the active ones only."""
    state.set_joint_group_positions("hand", [0.02, 0.03])
    assert state.joint_positions["panda_finger_joint1"] == state.joint_positions["panda_finger_joint2"] == 0.02
    state.set_joint_group_positions("panda_arm_hand", [*np.linspace(0.0, 0.6, 7), 0.01, 0.01])
    np.testing.assert_allclose(state.positions, [*np.linspace(0.0, 0.6, 7), 0.01, 0.01])
    state.set_joint_group_active_positions("hand", [0.03])
    assert state.positions[8] == 0.03
    with pytest.raises(ValueError, match=r"got 3 values \(or 2 with its mimic joints: panda_finger_joint1, panda_finger_joint2\)"):
        state.set_joint_group_positions("hand", [0.01, 0.01, 0.01])
    with pytest.raises(ValueError, match="has 1 active variables"):
        state.set_joint_group_active_positions("hand", [0.01, 0.01])
    with pytest.raises(ValueError, match="has 7 variables"):
        state.set_joint_group_positions("panda_arm", [0.0] * 8)


def test_enforce_bounds_wraps_continuous_joints(toy):
    """As MoveIt's enforcePositionBounds: a continuous joint (all of the toy's) is wrapped into
    (-pi, pi], pi staying pi (the Panda's bounded joints are clipped: see above)."""
    assert toy.continuous_mask.all()
    for value, wrapped in ((4.0, 4.0 - 2 * np.pi), (-7.0, -7.0 + 2 * np.pi), (np.pi, np.pi), (-np.pi, np.pi), (1.0, 1.0)):
        state = RobotState(toy, np.full(toy.variable_count, value))
        state.enforce_bounds()
        np.testing.assert_allclose(state.positions, wrapped, atol=1e-12)
        state = RobotState(toy, np.full(toy.variable_count, value))
        state.enforce_bounds("group")  # only the group's joints
        assert state.positions[0] == pytest.approx(wrapped, abs=1e-12) and state.positions[-1] == value
