"""Tests of mtc.scene.robot_model: the default robot, the toy robot, and bad URDF/SRDF input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scene_helpers import write_cube_stl

from mtc.robots import PANDA_SRDF, panda_urdf_path
from mtc.scene.robot_model import RobotModel
from mtc.scene.srdf import DescriptionError, parse_srdf

ARM_JOINTS = [f"panda_joint{i}" for i in range(1, 8)]
READY = [0, -0.785, 0, -2.356, 0, 1.571, 0.785]


# ---------------------------------------------------------------------------- the default robot
def test_panda_is_cached_and_named(panda):
    """mtc.robots.panda() loads once; planning frame world, root panda_link0."""
    import mtc

    assert mtc.robots.panda() is panda
    assert panda.name == "panda"
    assert panda.model_frame == "world"
    assert panda.root_link_name == "panda_link0"
    assert panda.has_link_model("world")


def test_panda_variables_in_pinocchio_order(panda):
    """Nine variables: seven arm joints and two fingers, in Pinocchio's q order."""
    assert panda.variable_names == [*ARM_JOINTS, "panda_finger_joint1", "panda_finger_joint2"]
    assert panda.variable_count == 9 == panda.pinocchio_model.nq
    for i, name in enumerate(panda.variable_names):
        assert panda.variable_index(name) == i
        jid = panda.pinocchio_model.getJointId(name)
        assert panda.pinocchio_model.joints[jid].idx_q == i


def test_panda_groups(panda):
    """panda_arm (chain link0 -> link8), hand (finger 1; finger 2 mimics it), panda_arm_hand = both."""
    assert panda.joint_model_group_names == ["panda_arm", "hand", "panda_arm_hand"]
    assert [g.name for g in panda.joint_model_groups] == panda.joint_model_group_names
    # moveit_py's keyword name
    assert panda.get_joint_model_group(joint_model_group_name="hand").name == "hand"
    assert panda.has_joint_model_group(joint_model_group_name="hand")
    assert not panda.has_joint_model_group(joint_model_group_name="arm")
    arm = panda.get_joint_model_group("panda_arm")
    assert arm.name == "panda_arm"
    assert arm.active_joint_model_names == ARM_JOINTS
    assert arm.variable_names == ARM_JOINTS
    assert arm.variable_count == 7
    assert arm.variable_indices.tolist() == list(range(7))
    assert arm.is_chain
    assert arm.link_model_names == [f"panda_link{i}" for i in range(1, 9)]
    assert arm.end_effector_tips == ["panda_link8"]
    assert arm.default_ik_timeout > 0

    hand = panda.get_joint_model_group("hand")
    assert hand.active_joint_model_names == ["panda_finger_joint1"]
    assert hand.variable_count == 1
    assert "panda_finger_joint2" in hand.joint_model_names  # the mimic follower moves with it
    assert set(hand.link_model_names) == {"panda_hand", "panda_hand_tcp", "panda_leftfinger", "panda_rightfinger"}
    assert not hand.is_chain
    # as MoveIt's updated links: below the active joints (and their mimic followers) only; the
    # palm hangs on the fixed panda_hand_joint above the fingers
    assert hand.updated_link_names == ["panda_leftfinger", "panda_rightfinger"]
    assert arm.updated_link_names == [f"panda_link{i}" for i in range(1, 9)] + [
        "panda_hand", "panda_hand_tcp", "panda_leftfinger", "panda_rightfinger"]

    both = panda.get_joint_model_group("panda_arm_hand")
    assert both.variable_names == [*ARM_JOINTS, "panda_finger_joint1"]
    assert both.subgroup_names == ["panda_arm", "hand"]
    assert set(both.link_model_names) == set(arm.link_model_names) | set(hand.link_model_names)
    np.testing.assert_array_equal(both.lower_bounds, panda.lower_bounds[both.variable_indices])
    np.testing.assert_array_equal(both.upper_bounds, panda.upper_bounds[both.variable_indices])


def test_panda_named_states(panda):
    """ready/extended/transport for the arm, open/close for the hand, values as in api.md."""
    assert set(panda.group_state_names("panda_arm")) >= {"ready", "extended"}
    assert panda.group_state_names("hand") == ["open", "close"]
    assert panda.group_state_names("panda_arm_hand") == []
    ready = panda.get_group_state("panda_arm", "ready")
    assert [ready[j] for j in ARM_JOINTS] == pytest.approx(READY)
    assert panda.get_group_state("hand", "open") == {"panda_finger_joint1": 0.035}
    assert panda.get_group_state("hand", "close") == {"panda_finger_joint1": 0.0}
    for name in panda.group_state_names("panda_arm"):
        values = np.array([panda.get_group_state("panda_arm", name)[j] for j in ARM_JOINTS])
        assert np.all(values >= panda.lower_bounds[:7]) and np.all(values <= panda.upper_bounds[:7]), name
    extended = panda.get_group_state("panda_arm", "extended")
    assert extended["panda_joint2"] == 0.0 and extended["panda_joint4"] > -0.1  # stretched out


def test_get_group_state_returns_a_copy(panda):
    """Editing a returned named state does not change the model."""
    panda.get_group_state("hand", "open")["panda_finger_joint1"] = 1.0
    assert panda.get_group_state("hand", "open") == {"panda_finger_joint1": 0.035}


def test_panda_end_effector(panda):
    """End effector hand: group hand on panda_link8 of panda_arm."""
    assert panda.end_effectors == ["hand"]
    eef = panda.get_end_effector("hand")
    assert (eef.name, eef.group, eef.parent_link, eef.parent_group) == ("hand", "hand", "panda_link8", "panda_arm")


def test_panda_frames_and_link_models(panda):
    """panda_hand and panda_hand_tcp are links usable as frames; the model frame is too."""
    for link in ("panda_hand", "panda_hand_tcp", "panda_link0", "panda_leftfinger"):
        assert panda.has_link_model(link)
        assert panda.pinocchio_model.frames[panda.frame_id(link)].name == link
    assert panda.pinocchio_model.frames[panda.frame_id("world")].name == "world"
    assert not panda.has_link_model("panda_link9")
    assert "panda_hand_tcp" in panda.link_model_names
    assert "panda_hand_tcp" not in panda.links_with_collision_geometry
    assert "panda_hand" in panda.links_with_collision_geometry


def test_panda_limits(panda):
    """URDF position and velocity limits; MoveIt's acceleration limits; no continuous joints."""
    assert panda.lower_bounds[3] == pytest.approx(-3.0718)
    assert panda.upper_bounds[3] == pytest.approx(-0.0698)
    assert panda.upper_bounds[7] == pytest.approx(0.04)
    assert panda.velocity_limits[0] == pytest.approx(2.175)
    assert panda.acceleration_limits.tolist() == pytest.approx([3.75, 1.875, 2.5, 3.125, 3.75, 5, 5, 1, 1])
    assert not panda.continuous_mask.any()
    assert panda.mimic_followers == [(8, 7, 1.0, 0.0)]


def test_panda_disabled_pairs_follow_the_srdf(panda):
    """Every disable_collisions pair of the bundled SRDF is a disabled pair of the model."""
    pairs = {frozenset(p) for p in panda.disabled_collision_pairs}
    expected = {frozenset((a, b)) for a, b, _ in parse_srdf(PANDA_SRDF).disabled_collisions}
    assert pairs == expected
    assert frozenset(("panda_link0", "panda_link1")) in pairs
    assert frozenset(("panda_link0", "panda_hand")) not in pairs


def test_geometry_models(panda):
    """Collision and visual models are Pinocchio GeometryModels of the links."""
    assert isinstance(panda.collision_model, pin.GeometryModel)
    assert isinstance(panda.visual_model, pin.GeometryModel)
    frames = {panda.pinocchio_model.frames[g.parentFrame].name for g in panda.collision_model.geometryObjects}
    assert frames == set(panda.links_with_collision_geometry)
    assert panda.visual_model.ngeoms > 0 and panda.collision_model.ngeoms > 0


def test_enforce_mimic(panda):
    """enforce_mimic sets the follower from the master, on one vector or a batch."""
    q = np.zeros((2, 9))
    q[:, 7] = [0.01, 0.03]
    panda.enforce_mimic(q)
    np.testing.assert_array_equal(q[:, 8], [0.01, 0.03])


# ---------------------------------------------------------------------------- the toy robot
def test_toy_robot(toy):
    """Continuous joints are one variable each, unbounded; no virtual joint: the root is the frame."""
    assert toy.name == "robot"
    assert toy.model_frame == "base"
    assert toy.variable_names == ["base-link1-joint", "link1-link2-joint", "link2-tip-joint"]
    assert toy.pinocchio_model.nq == 3
    assert toy.continuous_mask.all()
    assert np.all(np.isinf(toy.lower_bounds)) and np.all(np.isinf(toy.upper_bounds))
    assert toy.acceleration_limits.tolist() == [1.0, 1.0, 1.0]  # the default where nothing says otherwise
    assert toy.velocity_limits.tolist() == [1.0, 1.0, 1.0]
    group = toy.get_joint_model_group("group")
    assert group.variable_names == ["base-link1-joint", "link1-link2-joint"]
    assert group.is_chain and group.end_effector_tips == ["link2"]
    assert toy.get_joint_model_group("eef_group").variable_names == ["link2-tip-joint"]
    assert toy.get_end_effector("eef").parent_group == "group"
    assert toy.links_with_collision_geometry == []


def test_no_group_means_all_active_variables(panda):
    """get_joint_model_group(None or "") is every active (non-mimic) variable."""
    for name in (None, ""):
        jmg = panda.get_joint_model_group(name)
        assert jmg.variable_names == [*ARM_JOINTS, "panda_finger_joint1"]
    assert panda.active_joint_model_names == [*ARM_JOINTS, "panda_finger_joint1"]


def test_without_srdf_there_are_no_groups():
    """A URDF alone loads, with no groups, states or end effectors."""
    model = RobotModel(panda_urdf_path())
    assert model.joint_model_group_names == []
    assert model.end_effectors == []
    assert model.model_frame == "panda_link0"
    assert model.disabled_collision_pairs == []


def test_end_effector_tips_as_moveit(panda):
    """As MoveIt's getEndEffectorTips: an end effector is attached to every group holding its
    parent link (its own group aside), whatever its parent group; a chain group without one has
    no end-effector tip, but IK still moves the chain's tip."""
    from scene_helpers import TOY_URDF

    tips = {g: panda.get_joint_model_group(g).end_effector_tips for g in panda.joint_model_group_names}
    assert tips == {"panda_arm": ["panda_link8"], "hand": [], "panda_arm_hand": ["panda_link8"]}
    ik = {g: panda.get_joint_model_group(g).ik_tips for g in panda.joint_model_group_names}
    assert ik == {"panda_arm": ["panda_link8"], "hand": [], "panda_arm_hand": []}

    srdf = """<robot name="robot">
      <group name="whole"><chain base_link="base" tip_link="tip"/></group>
      <group name="upper"><chain base_link="base" tip_link="link2"/></group>
      <group name="last"><link name="tip"/></group>
      <end_effector name="e" parent_link="link2" group="last"/>
    </robot>"""
    model = RobotModel(str(TOY_URDF), srdf)
    assert model.get_joint_model_group("whole").end_effector_tips == ["link2"]
    assert model.get_joint_model_group("upper").end_effector_tips == ["link2"]
    assert model.get_joint_model_group("last").end_effector_tips == []
    # no parent group in the SRDF: the holder of the parent link with the fewest joints
    assert model.get_end_effector("e").parent_group == "upper"
    assert model.get_joint_model_group("upper").ik_tips == ["link2"]
    assert model.get_joint_model_group("whole").ik_tips == ["tip"]
    bare = RobotModel(str(TOY_URDF), '<robot name="robot"><group name="whole"><chain base_link="base" tip_link="tip"/></group></robot>')
    group = bare.get_joint_model_group("whole")
    assert (group.end_effector_tips, group.ik_tips) == ([], ["tip"])


def test_a_group_of_joints_in_a_row_is_a_chain(panda):
    """As MoveIt's JointModelGroup: a group is a chain when each of its joints lies above the
    next, however the SRDF lists them (xarm7's SRDF gives its arm as joints); the tip is the last
    joint's child link, which IK moves by default."""
    from scene_helpers import TOY_URDF

    srdf = """<robot name="robot">
      <group name="listed"><joint name="link2-tip-joint"/><joint name="base-link1-joint"/></group>
      <group name="split"><joint name="base-link1-joint"/><link name="tip"/></group>
    </robot>"""
    model = RobotModel(str(TOY_URDF), srdf)
    listed = model.get_joint_model_group("listed")
    assert (listed.is_chain, listed.chain_tip, listed.ik_tips) == (True, "tip", ["tip"])
    assert model.get_joint_model_group("split").is_chain
    hand = panda.get_joint_model_group("hand")  # two fingers side by side: not a chain
    assert (hand.is_chain, hand.ik_tips) == (False, [])
    assert not panda.get_joint_model_group("panda_arm_hand").is_chain


def _one_joint_urdf(safety: str) -> str:
    return f"""<robot name="r"><link name="a"/><link name="b"/>
      <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
        <limit lower="-2" upper="2" velocity="1" effort="1"/>{safety}</joint></robot>"""


@pytest.mark.parametrize(
    "safety, bounds",
    [
        ("", (-2.0, 2.0)),
        ('<safety_controller k_velocity="1" soft_lower_limit="-1.5" soft_upper_limit="1.8"/>', (-1.5, 1.8)),
        ('<safety_controller k_velocity="1" soft_lower_limit="-3" soft_upper_limit="3"/>', (-2.0, 2.0)),
        ('<safety_controller k_velocity="1" soft_lower_limit="-1"/>', (-1.0, 0.0)),  # urdfdom: missing = 0
    ],
)
def test_safety_controller_soft_limits_bound_the_joint(safety, bounds):
    """As MoveIt (jointBoundsFromURDF): a <safety_controller>'s soft limits, within the hard
    ones, are the joint's bounds."""
    model = RobotModel(_one_joint_urdf(safety))
    assert (model.lower_bounds[0], model.upper_bounds[0]) == bounds


def test_soft_limits_leaving_no_range_are_an_error():
    with pytest.raises(DescriptionError, match="joint 'j': the <safety_controller> soft limits leave no position"):
        RobotModel(_one_joint_urdf('<safety_controller k_velocity="1" soft_lower_limit="0.5"/>'))
    with pytest.raises(DescriptionError, match="soft_upper_limit='x' is not a number"):
        RobotModel(_one_joint_urdf('<safety_controller k_velocity="1" soft_upper_limit="x"/>'))


def test_joint_limits_override(toy):
    """joint_limits overrides velocity and acceleration per joint."""
    from scene_helpers import TOY_SRDF, TOY_URDF

    model = RobotModel(str(TOY_URDF), str(TOY_SRDF), joint_limits={"link1-link2-joint": {"max_velocity": 2.5, "max_acceleration": 7.0}})
    assert model.velocity_limits.tolist() == [1.0, 2.5, 1.0]
    assert model.acceleration_limits.tolist() == [1.0, 7.0, 1.0]
    with pytest.raises(KeyError, match="unknown joint 'nope'"):
        RobotModel(str(TOY_URDF), str(TOY_SRDF), joint_limits={"nope": {"max_velocity": 1.0}})


@pytest.mark.parametrize("value", [0, -1.0, float("nan"), float("inf"), "fast"])
def test_joint_limits_must_be_positive(toy, value):
    """A limit of 0 (or no number) would stop the joint, and timing divides by it: refused,
    naming the joint, unless its has_..._limits flag is false (MoveIt's Setup Assistant writes
    max_acceleration: 0 beside has_acceleration_limits: false): then the default stays."""
    from scene_helpers import TOY_SRDF, TOY_URDF

    with pytest.raises(ValueError, match="max_acceleration of joint 'link1-link2-joint' must be a positive number"):
        RobotModel(str(TOY_URDF), str(TOY_SRDF), joint_limits={"link1-link2-joint": {"max_acceleration": value}})
    model = RobotModel(str(TOY_URDF), str(TOY_SRDF), joint_limits={
        "link1-link2-joint": {"has_velocity_limits": True, "max_velocity": 2.0,
                              "has_acceleration_limits": False, "max_acceleration": value}})
    assert model.velocity_limits.tolist() == [1.0, 2.0, 1.0]
    assert model.acceleration_limits.tolist() == [1.0, 1.0, 1.0]


def test_joint_limits_yaml_as_loaded(toy):
    """The whole content of MoveIt's joint_limits.yaml (default scaling factors beside a
    joint_limits section) is taken: its joint_limits section."""
    from scene_helpers import TOY_SRDF, TOY_URDF

    yaml_content = {"default_velocity_scaling_factor": 0.1, "default_acceleration_scaling_factor": 0.1,
                    "joint_limits": {"link1-link2-joint": {"has_velocity_limits": True, "max_velocity": 2.5,
                                                           "has_acceleration_limits": True, "max_acceleration": 7.0}}}
    model = RobotModel(str(TOY_URDF), str(TOY_SRDF), joint_limits=yaml_content)
    assert model.velocity_limits.tolist() == [1.0, 2.5, 1.0]
    assert model.acceleration_limits.tolist() == [1.0, 7.0, 1.0]


def test_every_srdf_element_resolves(toy):
    """Groups from joints, links, chains and subgroups; passive joints are not active; default-collision entries."""
    from scene_helpers import TOY_URDF

    srdf = """<robot name="robot">
      <virtual_joint name="vj" type="fixed" parent_frame="map" child_link="base"/>
      <group name="first"><joint name="base-link1-joint"/><joint name="vj"/></group>
      <group name="by_link"><link name="tip"/></group>
      <group name="chain"><chain base_link="link1" tip_link="tip"/></group>
      <group name="combo"><group name="first"/><group name="by_link"/></group>
      <group_state name="up" group="combo"><joint name="base-link1-joint" value="1.5"/></group_state>
      <end_effector name="e" parent_link="link2" group="by_link" parent_group="chain"/>
      <passive_joint name="link1-link2-joint"/>
      <disable_collisions link1="link1" link2="link2" reason="Adjacent"/>
      <disable_default_collisions link="tip"/>
    </robot>"""
    model = RobotModel(str(TOY_URDF), srdf)
    assert model.model_frame == "map"
    assert model.virtual_joint_names == ["vj"]
    assert model.passive_joint_names == ["link1-link2-joint"]
    assert model.active_joint_model_names == ["base-link1-joint", "link2-tip-joint"]
    assert model.get_joint_model_group("first").variable_names == ["base-link1-joint"]
    assert model.get_joint_model_group("by_link").variable_names == ["link2-tip-joint"]
    assert model.get_joint_model_group("by_link").link_model_names == ["tip"]
    chain = model.get_joint_model_group("chain")
    assert chain.joint_model_names == ["link1-link2-joint", "link2-tip-joint"]
    assert chain.variable_names == ["link2-tip-joint"]  # the passive joint is not active
    assert chain.end_effector_tips == ["link2"]  # the end effector's parent link
    combo = model.get_joint_model_group("combo")
    assert combo.variable_names == ["base-link1-joint", "link2-tip-joint"]
    assert combo.subgroup_names == ["first", "by_link"]
    assert model.group_state_names("combo") == ["up"]
    assert model.get_group_state("combo", "up") == {"base-link1-joint": 1.5}
    assert model.get_end_effector("e").group == "by_link"
    assert ("link1", "link2") in model.disabled_collision_pairs
    assert ("tip", "*") in model.disabled_collision_pairs
    assert model.pinocchio_model.frames[model.frame_id("map")].name == "map"


# ---------------------------------------------------------------------------- unknown names
def test_unknown_group_names_it_and_the_groups(panda):
    """KeyError naming the bad group and listing the groups."""
    with pytest.raises(KeyError) as e:
        panda.get_joint_model_group("panda_arn")
    msg = str(e.value)
    assert "panda_arn" in msg and "panda_arm" in msg and "hand" in msg and "panda_arm_hand" in msg
    assert not panda.has_joint_model_group("panda_arn") and panda.has_joint_model_group("hand")


def test_unknown_group_in_state_queries(panda):
    """group_state_names / get_group_state with an unknown group name it and list the groups."""
    with pytest.raises(KeyError, match=r"panda_arn.*panda_arm"):
        panda.group_state_names("panda_arn")
    with pytest.raises(KeyError, match=r"panda_arn.*panda_arm"):
        panda.get_group_state("panda_arn", "ready")


def test_unknown_named_state_names_it_and_the_states(panda):
    """KeyError naming the state, its group and the states that exist."""
    with pytest.raises(KeyError) as e:
        panda.get_group_state("hand", "half")
    msg = str(e.value)
    assert "'half'" in msg and "'hand'" in msg and "open" in msg and "close" in msg


def test_unknown_end_effector(panda):
    """KeyError naming the end effector and those that exist."""
    with pytest.raises(KeyError, match=r"'gripper'.*hand"):
        panda.get_end_effector("gripper")


def test_unknown_joint(panda):
    """variable_index of an unknown joint names it and lists the joints."""
    with pytest.raises(KeyError) as e:
        panda.variable_index("panda_joint8")
    assert "'panda_joint8'" in str(e.value) and "panda_joint7" in str(e.value) and "panda_finger_joint1" in str(e.value)


def test_unknown_link(panda):
    """frame_id of an unknown link names it and lists the links."""
    with pytest.raises(KeyError) as e:
        panda.frame_id("panda_link9")
    assert "'panda_link9'" in str(e.value) and "panda_hand_tcp" in str(e.value)


# ---------------------------------------------------------------------------- bad URDF
LINK = '<link name="{0}"/>'
GOOD_JOINT = """<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
  <axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>"""


def write(tmp_path, name, text) -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def urdf(body: str) -> str:
    return f'<?xml version="1.0"?>\n<robot name="bad">{body}</robot>'


def test_missing_urdf_file(tmp_path):
    """A missing URDF file raises DescriptionError naming the path."""
    with pytest.raises(DescriptionError) as e:
        RobotModel(str(tmp_path / "ghost.urdf"))
    assert "URDF file not found" in str(e.value) and "ghost.urdf" in str(e.value)


def test_malformed_urdf_file(tmp_path):
    """Broken XML in a URDF file names the file."""
    path = write(tmp_path, "broken.urdf", '<robot name="x"><link name="a">')
    with pytest.raises(DescriptionError) as e:
        RobotModel(path)
    assert "malformed XML" in str(e.value) and "broken.urdf" in str(e.value)


@pytest.mark.parametrize(
    "body, words",
    [
        (LINK.format("a") + '<joint name="j1" type="fixed"><parent link="a"/><child link="zz"/></joint>', ["'j1'", "'zz'"]),
        (LINK.format("a") + LINK.format("b") + '<joint name="j1" type="floating"><parent link="a"/><child link="b"/></joint>',
         ["'j1'", "'floating'", "revolute, continuous, prismatic, fixed"]),
        (LINK.format("a") + LINK.format("b") + '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>',
         ["'j1'", "<limit>"]),
        (LINK.format("a") + LINK.format("b") + '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>'
         '<limit lower="-1" upper="1" velocity="1" effort="1"/><mimic joint="ghost"/></joint>', ["'j1'", "'ghost'"]),
        (LINK.format("a") + LINK.format("b"), ["root link", "'a'", "'b'"]),
        (LINK.format("a") + LINK.format("b") + '<joint name="j1" type="fixed"><parent link="a"/></joint>', ["'j1'"]),
    ],
    ids=["unknown-link", "unsupported-type", "no-limit", "unknown-mimic", "two-roots", "no-child"],
)
def test_inconsistent_urdf_names_file_and_item(tmp_path, body, words):
    """Each inconsistency raises DescriptionError naming the file and the bad item."""
    path = write(tmp_path, "bad.urdf", urdf(body))
    with pytest.raises(DescriptionError) as e:
        RobotModel(path)
    msg = str(e.value)
    assert "bad.urdf" in msg
    for word in words:
        assert word in msg


@pytest.mark.parametrize(
    "joint_body, link_c, words",
    [
        ('<limit lower="abc" upper="1" velocity="1" effort="1"/>', "", ["'j1'", "lower", "'abc'"]),
        ('<limit lower="-1" upper="1" velocity="fast" effort="1"/>', "", ["'j1'", "velocity", "'fast'"]),
        ('<limit lower="-1" upper="1" velocity="1" effort="1"/><mimic joint="j0" multiplier="x"/>', "",
         ["'j1'", "multiplier", "'x'"]),
        # numbers that parse but make no robot (Pinocchio took them, or failed without saying where)
        ('<limit lower="1" upper="-1" velocity="1" effort="1"/>', "", ["'j1'", "lower='1' is above upper='-1'"]),
        ('<limit lower="-1" upper="1" velocity="-1" effort="1"/>', "", ["'j1'", "velocity='-1' is negative"]),
        ('<limit lower="-1" upper="1" velocity="1" effort="-2"/>', "", ["'j1'", "effort='-2' is negative"]),
        ('<axis xyz="0 0 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/>', "", ["'j1'", "xyz='0 0 0' is no direction"]),
        ('<limit lower="-1" upper="1" velocity="1" effort="1"/><mimic joint="j1"/>', "", ["'j1' mimics itself"]),
        ('<limit lower="-1" upper="1" velocity="1" effort="1"/>',
         '<collision><geometry><box size="-1 1 1"/></geometry></collision>', ["link 'c'", "size='-1 1 1' is negative"]),
    ],
    ids=["limit-lower", "limit-velocity", "mimic-multiplier", "lower-above-upper", "negative-velocity",
         "negative-effort", "zero-axis", "mimics-itself", "negative-box"],
)
def test_bad_joint_and_shape_values_name_file_item_and_value(tmp_path, joint_body, link_c, words):
    """A limit, axis, mimic or shape value that is not a number, or a number that makes no
    robot, raises DescriptionError naming the file, the joint or link, the attribute and value."""
    body = (
        LINK.format("a") + LINK.format("b") + f'<link name="c">{link_c}</link>'
        + '<joint name="j0" type="revolute"><parent link="a"/><child link="b"/>'
        '<limit lower="-1" upper="1" velocity="1" effort="1"/></joint>'
        + f'<joint name="j1" type="revolute"><parent link="b"/><child link="c"/>{joint_body}</joint>'
    )  # fmt: skip
    path = write(tmp_path, "values.urdf", urdf(body))
    with pytest.raises(DescriptionError) as e:
        RobotModel(path)
    msg = str(e.value)
    assert "values.urdf" in msg
    for word in words:
        assert word in msg, (word, msg)


def test_loader_arguments_of_the_wrong_kind_are_named(tmp_path):
    """package_dirs and joint_limits of the wrong kind are named, not Python's own complaint."""
    path = write(tmp_path, "ok.urdf", urdf(LINK.format("a")))
    with pytest.raises(TypeError, match="package_dirs must be a folder or a list of folders, got 3"):
        RobotModel(path, package_dirs=3)
    with pytest.raises(TypeError, match="joint_limits must be a dict .* got list"):
        RobotModel(path, joint_limits=[{"max_velocity": 1.0}])
    assert RobotModel(path, package_dirs=[tmp_path]).name  # a path object is a folder


def test_srdf_group_defined_twice():
    with pytest.raises(DescriptionError, match="group 'g' is defined twice"):
        parse_srdf('<robot name="r"><group name="g"><joint name="a"/></group><group name="g"><joint name="b"/></group></robot>')


def test_malformed_origin_names_the_joint(tmp_path):
    """A malformed origin is reported through Pinocchio's parser, naming the file and the joint."""
    body = LINK.format("a") + LINK.format("b") + GOOD_JOINT.replace('<axis', '<origin xyz="0 zero 0"/><axis')
    path = write(tmp_path, "origin.urdf", urdf(body))
    with pytest.raises(DescriptionError) as e:
        RobotModel(path)
    assert "origin.urdf" in str(e.value) and "j1" in str(e.value)


def test_missing_package_mesh(tmp_path):
    """A package:// mesh that no package folder holds names the mesh URI and the URDF file."""
    body = '<link name="a"><collision><geometry><mesh filename="package://nopkg/meshes/m.stl"/></geometry></collision></link>'
    path = write(tmp_path, "mesh.urdf", urdf(body))
    with pytest.raises(DescriptionError) as e:
        RobotModel(path)
    assert "package://nopkg/meshes/m.stl" in str(e.value) and "mesh.urdf" in str(e.value)


def test_missing_relative_mesh(tmp_path):
    """A relative mesh path that does not exist names the mesh."""
    body = '<link name="a"><visual><geometry><mesh filename="meshes/absent.stl"/></geometry></visual></link>'
    path = write(tmp_path, "rel.urdf", urdf(body))
    with pytest.raises(DescriptionError, match="absent.stl"):
        RobotModel(path)


def test_unreadable_mesh_names_the_file(tmp_path):
    """A mesh file that is not a mesh raises DescriptionError naming the URDF."""
    (tmp_path / "junk.stl").write_text("this is not a mesh")
    body = '<link name="a"><collision><geometry><mesh filename="junk.stl"/></geometry></collision></link>'
    path = write(tmp_path, "junk.urdf", urdf(body))
    with pytest.raises(DescriptionError) as e:
        RobotModel(path)
    assert "junk.urdf" in str(e.value) and "junk.stl" in str(e.value)


def test_meshes_found_relative_to_the_urdf_and_in_package_dirs(tmp_path):
    """Relative mesh paths resolve next to the URDF file; package:// URIs in package_dirs."""
    (tmp_path / "pkg" / "meshes").mkdir(parents=True)
    write_cube_stl(tmp_path / "pkg" / "meshes" / "cube.stl", 0.1)
    write_cube_stl(tmp_path / "near.stl", 0.1)
    body = (
        '<link name="a"><collision><geometry><mesh filename="near.stl"/></geometry></collision></link>'
        '<link name="b"><collision><geometry><mesh filename="package://pkg/meshes/cube.stl"/></geometry></collision></link>'
        + GOOD_JOINT
    )
    path = write(tmp_path, "meshy.urdf", urdf(body))
    model = RobotModel(path, package_dirs=str(tmp_path))
    assert model.links_with_collision_geometry == ["a", "b"]
    assert model.collision_model.ngeoms == 2
    assert model.resolve_uri("package://pkg/meshes/cube.stl") == str(tmp_path / "pkg" / "meshes" / "cube.stl")


# ---------------------------------------------------------------------------- SRDF against the URDF
TOY_GROUP = '<group name="g"><chain base_link="base" tip_link="link2"/></group>'


@pytest.mark.parametrize(
    "srdf_body, words",
    [
        ('<group name="g"><link name="hand"/></group>', ["'g'", "'hand'", "base, link1, link2, tip"]),
        ('<group name="g"><joint name="elbow"/></group>', ["'g'", "'elbow'", "base-link1-joint"]),
        ('<group name="g"><group name="ghost"/></group>', ["'g'", "'ghost'"]),
        ('<group name="g"><group name="g"/></group>', ["'g'", "itself"]),
        ('<group name="g"><chain base_link="tip" tip_link="link1"/></group>', ["'g'", "'tip'", "'link1'", "ancestor"]),
        (TOY_GROUP + '<group_state name="s" group="ghost"><joint name="base-link1-joint" value="0"/></group_state>',
         ["'s'", "'ghost'"]),
        (TOY_GROUP + '<group_state name="s" group="g"><joint name="link2-tip-joint" value="0"/></group_state>',
         ["'s'", "'link2-tip-joint'", "'g'", "base-link1-joint"]),
        (TOY_GROUP + '<end_effector name="e" parent_link="link2" group="ghost"/>', ["'e'", "'ghost'"]),
        (TOY_GROUP + '<end_effector name="e" parent_link="wrist" group="g"/>', ["'e'", "'wrist'", "link2"]),
        (TOY_GROUP + '<end_effector name="e" parent_link="link2" group="g" parent_group="ghost"/>', ["'e'", "'ghost'"]),
        ('<virtual_joint name="v" type="fixed" parent_frame="world" child_link="link1"/>', ["'v'", "'link1'", "'base'"]),
        ('<virtual_joint name="v" type="spherical" parent_frame="world" child_link="base"/>',
         ["'v'", "'spherical'", "fixed, planar, floating"]),
        ('<passive_joint name="ghost_joint"/>', ["'ghost_joint'"]),
    ],
    ids=[
        "group-unknown-link", "group-unknown-joint", "unknown-subgroup", "self-subgroup", "chain-not-ancestor",
        "state-unknown-group", "state-joint-not-in-group", "eef-unknown-group", "eef-unknown-link",
        "eef-unknown-parent-group", "virtual-joint-not-root", "virtual-joint-unknown-type", "unknown-passive-joint",
    ],
)
def test_srdf_names_missing_from_the_urdf(srdf_body, words):
    """An SRDF naming what the URDF lacks raises DescriptionError naming the item (and what exists)."""
    from scene_helpers import TOY_URDF

    with pytest.raises(DescriptionError) as e:
        RobotModel(str(TOY_URDF), f'<robot name="robot">{srdf_body}</robot>')
    msg = str(e.value)
    assert "SRDF" in msg
    for word in words:
        assert word in msg, (word, msg)


@pytest.mark.parametrize("kind", ["planar", "floating"])
def test_a_mobile_bases_virtual_joint_loads_as_fixed(kind, caplog):
    """A mobile manipulator's SRDF (a planar or floating virtual joint, usually passive, as the
    PR2's) loads: the base stays at the model frame's origin, with a warning that base motion is
    not planned."""
    from scene_helpers import TOY_URDF

    srdf = (f'<robot name="robot"><virtual_joint name="world_joint" type="{kind}" parent_frame="odom" child_link="base"/>'
            '<passive_joint name="world_joint"/><group name="arm"><chain base_link="base" tip_link="link2"/></group></robot>')
    with caplog.at_level("WARNING"):
        model = RobotModel(str(TOY_URDF), srdf)
    assert model.model_frame == "odom" and model.virtual_joint_names == ["world_joint"]
    assert f"type '{kind}'" in caplog.text and "treats it as fixed" in caplog.text
    assert model.get_joint_model_group("arm").variable_names == ["base-link1-joint", "link1-link2-joint"]


def test_missing_srdf_file(tmp_path):
    """A missing SRDF file names the path."""
    from scene_helpers import TOY_URDF

    with pytest.raises(DescriptionError, match="SRDF file not found.*none.srdf"):
        RobotModel(str(TOY_URDF), str(tmp_path / "none.srdf"))


def test_srdf_errors_name_the_file(tmp_path):
    """An SRDF file whose group names an unknown joint: the error names the file, the group and
    the joint (api.md: errors from files name the file and the problem)."""
    from scene_helpers import TOY_URDF

    path = tmp_path / "bad.srdf"
    path.write_text('<robot name="toy"><group name="g"><joint name="nojoint"/></group></robot>')
    with pytest.raises(DescriptionError, match=r"SRDF file '.*bad.srdf': group 'g'.*'nojoint'"):
        RobotModel(str(TOY_URDF), str(path))


def test_group_states_without_a_group_are_ignored(caplog):
    """Pinocchio's reference configurations (a group_state with no group, as example-robot-data's
    SRDFs have them) are dropped with a warning, as MoveIt's SRDF reader does; the rest loads."""
    from scene_helpers import TOY_URDF

    srdf = """<robot name="robot">
      <group name="g"><chain base_link="base" tip_link="tip"/></group>
      <group_state name="home"><joint name="base-link1-joint" value="0.5"/></group_state>
      <group_state name="up" group="g"><joint name="base-link1-joint" value="1.5"/></group_state>
    </robot>"""
    with caplog.at_level("WARNING"):
        model = RobotModel(str(TOY_URDF), srdf)
    assert model.group_state_names("g") == ["up"]
    assert "group_state 'home' names no group; ignored" in caplog.text


def test_unknown_links_in_disabled_pairs_are_ignored(caplog):
    """A disable_collisions pair of links the URDF lacks is dropped with a warning (as MoveIt)."""
    from scene_helpers import TOY_URDF

    srdf = '<robot name="robot"><disable_collisions link1="base" link2="ghost"/></robot>'
    with caplog.at_level("WARNING"):
        model = RobotModel(str(TOY_URDF), srdf)
    assert model.disabled_collision_pairs == []
    assert "ghost" in caplog.text


def test_a_pathlib_path_finds_relative_meshes_too(tmp_path):
    """A URDF given as pathlib.Path resolves relative mesh paths next to the file, as a str path does."""
    write_cube_stl(tmp_path / "near.stl", 0.1)
    path = write(tmp_path, "r.urdf", urdf('<link name="a"><collision><geometry><mesh filename="near.stl"/></geometry></collision></link>'))
    assert RobotModel(path).links_with_collision_geometry == ["a"]
    from pathlib import Path

    assert RobotModel(Path(path)).links_with_collision_geometry == ["a"]


def test_merged_group_is_the_union_named_like_mtc(panda):
    """merged_group(['panda_arm', 'hand']) is 'panda_arm+hand' with both groups' variables, cached."""
    merged = panda.merged_group(["panda_arm", "hand"])
    assert merged.name == "panda_arm+hand"
    assert merged.variable_names == [*panda.get_joint_model_group("panda_arm").variable_names, "panda_finger_joint1"]
    assert panda.merged_group(["panda_arm", "hand"]) is merged
    assert "panda_arm+hand" not in panda.joint_model_group_names
    with pytest.raises(KeyError, match="unknown planning group 'arm'"):
        panda.merged_group(["arm", "hand"])


def test_mimic_followers_own_limits_do_not_bound_a_state(tmp_path):
    """As MoveIt (bounds are checked on the active joints): a follower that mimics its master
    with multiplier -1 leaves its own URDF limits whenever the master is positive (the PR2's
    gripper); the state is still within bounds and valid."""
    from mtc.scene.planning_scene import PlanningScene
    from mtc.scene.robot_state import RobotState

    body = (LINK.format("a") + LINK.format("b") + LINK.format("c") + GOOD_JOINT
            + '<joint name="j2" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/>'
            '<limit lower="0" upper="0.5" velocity="1" effort="1"/><mimic joint="j1" multiplier="-1"/></joint>')
    model = RobotModel(write(tmp_path, "mimic.urdf", urdf(body)))
    state = RobotState(model)
    state.joint_positions = {"j1": 0.3}
    assert state.joint_positions["j2"] == pytest.approx(-0.3)
    assert state.satisfies_bounds()
    assert PlanningScene(model).is_state_valid(state)
    state.joint_positions = {"j1": 1.5}
    assert not state.satisfies_bounds()  # the master's own limits still count


def test_a_tree_groups_joints_are_in_moveits_order_not_the_files(tmp_path):
    """MoveIt orders a group's joints depth first with a link's child joints by name (its joint
    indices); a tree-shaped group (the PR2's "arms") listed them in URDF file order before, so
    set_joint_group_positions drove the other arm with a list in MoveIt's order."""
    from mtc.scene.robot_state import RobotState

    def arm(side):
        return (LINK.format(f"{side}1") + LINK.format(f"{side}2")
                + f'<joint name="{side}_j1" type="revolute"><parent link="a"/><child link="{side}1"/><axis xyz="0 0 1"/>'
                '<limit lower="-1" upper="1" velocity="1" effort="1"/></joint>'
                f'<joint name="{side}_j2" type="revolute"><parent link="{side}1"/><child link="{side}2"/><axis xyz="0 1 0"/>'
                '<limit lower="-1" upper="1" velocity="1" effort="1"/></joint>')

    path = write(tmp_path, "arms.urdf", urdf(LINK.format("a") + arm("r") + arm("l")))  # right first in the file
    srdf = write(tmp_path, "arms.srdf", '<robot name="bad"><group name="right"><chain base_link="a" tip_link="r2"/></group>'
                 '<group name="left"><chain base_link="a" tip_link="l2"/></group>'
                 '<group name="arms"><group name="right"/><group name="left"/></group></robot>')
    model = RobotModel(path, srdf)
    arms = model.get_joint_model_group("arms")
    assert arms.variable_names == ["l_j1", "l_j2", "r_j1", "r_j2"]
    assert list(arms.variable_indices) == sorted(arms.variable_indices)
    state = RobotState(model)
    state.set_joint_group_positions("arms", [0.1, 0.2, 0.3, 0.4])
    assert state.joint_positions["l_j1"] == pytest.approx(0.1) and state.joint_positions["r_j2"] == pytest.approx(0.4)
