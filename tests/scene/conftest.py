"""Fixtures of the scene tests: the bundled Panda, MTC's toy robot and a one-cube robot."""

from __future__ import annotations

from pathlib import Path

import pytest

import mtc
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import RobotModel

DATA = Path(__file__).resolve().parents[1] / "data"
TOY_URDF = DATA / "toy_robot.urdf"
TOY_SRDF = DATA / "toy_robot.srdf"

#: A robot whose only geometry is a 0.1 m cube on a prismatic joint along x (limits +-1 m),
#: and a 0.02 x 0.02 x 0.2 m rod on a revolute joint about z at the cube's centre, so that
#: distances to primitives can be computed by hand.
CUBE_URDF = """<?xml version="1.0"?>
<robot name="cube_robot">
  <link name="base"/>
  <link name="cube">
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="rod">
    <collision>
      <origin xyz="0 0 0.15"/>
      <geometry><box size="0.02 0.02 0.2"/></geometry>
    </collision>
  </link>
  <joint name="slide" type="prismatic">
    <parent link="base"/>
    <child link="cube"/>
    <axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" velocity="0.5" effort="10"/>
  </joint>
  <joint name="turn" type="revolute">
    <parent link="cube"/>
    <child link="rod"/>
    <axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="2" effort="10"/>
  </joint>
</robot>
"""

CUBE_SRDF = """<?xml version="1.0"?>
<robot name="cube_robot">
  <virtual_joint name="vj" type="fixed" parent_frame="world" child_link="base"/>
  <group name="slider"><joint name="slide"/></group>
  <group name="rod"><joint name="turn"/></group>
  <group name="all"><group name="slider"/><group name="rod"/></group>
  <disable_collisions link1="cube" link2="rod" reason="Adjacent"/>
</robot>
"""


@pytest.fixture(scope="session")
def panda() -> RobotModel:
    """The bundled Panda (cached by ``mtc.robots.panda``)."""
    return mtc.robots.panda()


@pytest.fixture(scope="session")
def toy() -> RobotModel:
    """MTC's toy robot: base -> link1 -> link2 -> tip, three continuous joints about x."""
    return RobotModel(str(TOY_URDF), str(TOY_SRDF))


@pytest.fixture(scope="session")
def cube() -> RobotModel:
    """A cube on a prismatic joint with a rod on top (see ``CUBE_URDF``)."""
    return RobotModel(CUBE_URDF, CUBE_SRDF)


@pytest.fixture
def scene(panda) -> PlanningScene:
    """An empty Panda scene with the arm at ``ready`` and the hand ``open``."""
    ps = PlanningScene(panda)
    ps.current_state.set_to_default_values("panda_arm", "ready")
    ps.current_state.set_to_default_values("hand", "open")
    return ps


@pytest.fixture
def cube_scene(cube) -> PlanningScene:
    """An empty scene of the cube robot (cube at the origin, rod upright along z)."""
    return PlanningScene(cube)
