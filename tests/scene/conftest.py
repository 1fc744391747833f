"""Fixtures of the scene tests: the bundled Panda, MTC's toy robot and a one-cube robot."""

from __future__ import annotations

import pytest

# the robot descriptions live in scene_helpers: test modules import them from there, never from
# conftest (another folder's conftest may own the name "conftest" in sys.modules)
from scene_helpers import CUBE_SRDF, CUBE_URDF, TOY_SRDF, TOY_URDF

import mtc
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import RobotModel


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
