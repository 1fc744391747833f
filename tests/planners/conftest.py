"""Fixtures of the planner tests: the Panda (loaded once) and scenes with the arm at ``ready``."""

from __future__ import annotations

import numpy as np
import pytest

import mtc
from mtc import msgs
from mtc.scene.planning_scene import PlanningScene


@pytest.fixture(scope="session")
def panda():
    """The bundled Panda."""
    return mtc.robots.panda()


@pytest.fixture
def ready_scene(panda) -> PlanningScene:
    """A scene with the arm at ``ready``, the hand ``open`` and no objects."""
    scene = PlanningScene(panda)
    scene.current_state.set_to_default_values("panda_arm", "ready")
    scene.current_state.set_to_default_values("hand", "open")
    return scene


def _add_box(scene: PlanningScene, name: str, position, size=(0.1, 0.1, 0.1)) -> None:
    """Add a box at ``position`` (world frame, identity orientation) to ``scene``."""
    pose = np.eye(4)
    pose[:3, 3] = position
    scene.apply_collision_object(
        msgs.CollisionObject(
            id=name,
            header=msgs.Header(frame_id="world"),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=list(size))],
            primitive_poses=[msgs.matrix_to_pose(np.eye(4))],
            pose=msgs.matrix_to_pose(pose),
            operation=msgs.CollisionObject.ADD,
        )
    )


@pytest.fixture
def add_box():
    """``add_box(scene, name, position, size=(0.1, 0.1, 0.1))``: put a box into a scene."""
    return _add_box
