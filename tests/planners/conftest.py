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


@pytest.fixture
def rod_past_a_pin(panda):
    """``rod_past_a_pin(pin=True)``: (scene, goal scene): the closed hand holds a 60 cm rod
    (2 mm radius) along its x axis; turning ``panda_joint7`` by -1.5 rad sweeps the rod through
    a 2 mm pin standing 29 cm from the tcp. The pin lies between two waypoints of the Cartesian
    and Pilz motions, which a check of the waypoints alone misses."""
    import math

    def make(pin: bool = True):
        scene = PlanningScene(panda)
        state = scene.current_state
        state.set_to_default_values("panda_arm", "ready")
        state.set_to_default_values("hand", "close")
        quarter = msgs.Quaternion(y=math.sin(math.pi / 4), w=math.cos(math.pi / 4))
        scene.apply_collision_object(msgs.CollisionObject(
            id="rod", header=msgs.Header(frame_id="panda_hand_tcp"),
            primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.CYLINDER, dimensions=[0.6, 0.002])],
            primitive_poses=[msgs.Pose(orientation=quarter)]))
        scene.attach_object("rod", "panda_hand", ["panda_leftfinger", "panda_rightfinger", "panda_hand"])
        if pin:
            tcp = state.get_global_link_transform("panda_hand_tcp")[:3, 3]
            at = tcp + 0.29 * np.array([math.cos(0.7313), math.sin(0.7313), 0.0])
            scene.apply_collision_object(msgs.CollisionObject(
                id="pin", header=msgs.Header(frame_id="world"),
                primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.CYLINDER, dimensions=[0.04, 0.002])],
                primitive_poses=[msgs.Pose(position=msgs.Point(*at), orientation=msgs.Quaternion(w=1.0))]))
        assert not scene.is_state_colliding()
        goal = scene.diff()
        goal.current_state.joint_positions = {"panda_joint7": goal.current_state.joint_positions["panda_joint7"] - 1.5}
        return scene, goal

    return make
