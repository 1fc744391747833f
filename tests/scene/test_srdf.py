"""Tests of mtc.scene.srdf: every SRDF element, and the errors of unreadable files."""

from __future__ import annotations

import pytest

from mtc.scene.srdf import (
    SRDF,
    DescriptionError,
    EndEffectorSpec,
    GroupSpec,
    GroupStateSpec,
    VirtualJointSpec,
    parse_srdf,
)

FULL_SRDF = """<?xml version="1.0"?>
<robot name="toy">
  <virtual_joint name="vj" type="fixed" parent_frame="world" child_link="base"/>
  <group name="arm">
    <chain base_link="base" tip_link="link2"/>
  </group>
  <group name="mixed">
    <joint name="base-link1-joint"/>
    <link name="tip"/>
    <group name="arm"/>
  </group>
  <group_state name="home" group="arm">
    <joint name="base-link1-joint" value="0.5"/>
    <joint name="link1-link2-joint" value="-1.25 7"/>
  </group_state>
  <end_effector name="eef" parent_link="link2" group="mixed" parent_group="arm"/>
  <end_effector name="bare" parent_link="tip" group="arm"/>
  <passive_joint name="link2-tip-joint"/>
  <disable_collisions link1="base" link2="link1" reason="Adjacent"/>
  <disable_collisions link1="link1" link2="link2"/>
  <disable_default_collisions link="tip"/>
  <unknown_element foo="bar"/>
</robot>
"""


def test_every_element_is_read_in_file_order():
    """Groups (chain, joint, link, subgroup), states, end effectors, virtual/passive joints, disabled pairs."""
    srdf = parse_srdf(FULL_SRDF)
    assert isinstance(srdf, SRDF)
    assert srdf.name == "toy"
    assert srdf.virtual_joints == [VirtualJointSpec("vj", "fixed", "world", "base")]
    assert srdf.groups == [
        GroupSpec("arm", chains=[("base", "link2")]),
        GroupSpec("mixed", joints=["base-link1-joint"], links=["tip"], subgroups=["arm"]),
    ]
    # a multi-value joint keeps its first value
    assert srdf.group_states == [GroupStateSpec("home", "arm", {"base-link1-joint": 0.5, "link1-link2-joint": -1.25})]
    assert srdf.end_effectors == [
        EndEffectorSpec("eef", "mixed", "link2", "arm"),
        EndEffectorSpec("bare", "arm", "tip", ""),
    ]
    assert srdf.passive_joints == ["link2-tip-joint"]
    assert srdf.disabled_collisions == [("base", "link1", "Adjacent"), ("link1", "link2", ""), ("tip", "*", "")]


def test_reads_a_file_path_as_well_as_text(tmp_path):
    """A path to an SRDF file gives the same result as its text."""
    path = tmp_path / "toy.srdf"
    path.write_text(FULL_SRDF)
    assert parse_srdf(str(path)) == parse_srdf(FULL_SRDF)
    assert parse_srdf(path) == parse_srdf(FULL_SRDF)  # os.PathLike too


def test_bundled_panda_srdf_has_moveit_names():
    """The shipped SRDF declares MoveIt's panda_moveit_config groups, states and end effector."""
    from mtc.robots import PANDA_SRDF

    srdf = parse_srdf(PANDA_SRDF)
    assert [g.name for g in srdf.groups] == ["panda_arm", "hand", "panda_arm_hand"]
    assert {(s.group, s.name) for s in srdf.group_states} >= {
        ("panda_arm", "ready"),
        ("panda_arm", "extended"),
        ("hand", "open"),
        ("hand", "close"),
    }
    assert srdf.end_effectors == [EndEffectorSpec("hand", "hand", "panda_link8", "panda_arm")]
    assert srdf.virtual_joints[0].parent_frame == "world"
    assert len(srdf.disabled_collisions) > 30


def test_missing_file_names_the_path(tmp_path):
    """A path that does not exist raises DescriptionError naming it."""
    missing = tmp_path / "nope.srdf"
    with pytest.raises(DescriptionError, match="SRDF file not found") as e:
        parse_srdf(str(missing))
    assert "nope.srdf" in str(e.value)


def test_malformed_xml_names_the_file(tmp_path):
    """Broken XML raises DescriptionError naming the file and saying it is malformed."""
    path = tmp_path / "broken.srdf"
    path.write_text('<robot name="x"><group name="a"></robot>')
    with pytest.raises(DescriptionError) as e:
        parse_srdf(str(path))
    assert "malformed XML" in str(e.value) and "broken.srdf" in str(e.value)


def test_malformed_xml_text():
    """Broken XML text raises DescriptionError saying it is SRDF text."""
    with pytest.raises(DescriptionError, match="malformed XML in SRDF text"):
        parse_srdf("<robot><group")


def test_wrong_root_element():
    """The root must be <robot>; the message names both tags."""
    with pytest.raises(DescriptionError, match=r"<srdf>.*<robot>"):
        parse_srdf("<srdf/>")


@pytest.mark.parametrize(
    "element, tag, attribute",
    [
        ('<group/>', "group", "name"),
        ('<group name="g"><chain base_link="a"/></group>', "chain", "tip_link"),
        ('<group name="g"><joint/></group>', "joint", "name"),
        ('<group name="g"><link/></group>', "link", "name"),
        ('<group_state name="s" group="g"><joint name="j"/></group_state>', "joint", "value"),
        ('<end_effector name="e" group="g"/>', "end_effector", "parent_link"),
        ('<virtual_joint name="v" type="fixed" child_link="base"/>', "virtual_joint", "parent_frame"),
        ('<passive_joint/>', "passive_joint", "name"),
        ('<disable_collisions link1="a"/>', "disable_collisions", "link2"),
        ('<disable_default_collisions/>', "disable_default_collisions", "link"),
    ],
)
def test_missing_attribute_names_element_and_attribute(element, tag, attribute):
    """An element without a required attribute names the element and the attribute."""
    with pytest.raises(DescriptionError) as e:
        parse_srdf(f'<robot name="r">{element}</robot>')
    message = str(e.value)
    assert f"<{tag}>" in message and f"'{attribute}'" in message
    assert "SRDF text" in message


def test_non_numeric_state_value_names_state_and_value():
    """A group_state value that is not a number names the state and the value."""
    text = '<robot name="r"><group_state name="home" group="g"><joint name="j" value="abc"/></group_state></robot>'
    with pytest.raises(DescriptionError) as e:
        parse_srdf(text)
    assert "'home'" in str(e.value) and "'abc'" in str(e.value)


def test_not_a_path_or_text():
    """Passing something other than a path or text says what is expected."""
    with pytest.raises(DescriptionError, match="file path or XML text"):
        parse_srdf(42)
