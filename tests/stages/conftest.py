"""Fixtures of the stage tests: the Panda, a fresh current scene per test, small task helpers."""

from __future__ import annotations

import pytest

import mtc
from mtc import msgs
from mtc.scene.planning_scene import PlanningScene


@pytest.fixture(scope="session")
def panda():
    """The bundled Panda (the robot ``core.Task()`` uses by default)."""
    return mtc.robots.panda()


@pytest.fixture(autouse=True)
def fresh_current_scene():
    """Every test starts from the initial current scene (arm ``ready``, hand ``open``, no objects)."""
    mtc.reset_current_scene()
    yield
    mtc.reset_current_scene()


@pytest.fixture
def ready_scene(panda) -> PlanningScene:
    """A scene with the arm at ``ready`` and the hand ``open``."""
    scene = PlanningScene(panda)
    scene.current_state.set_to_default_values("panda_arm", "ready")
    scene.current_state.set_to_default_values("hand", "open")
    return scene


def _make_task(*stages, introspection: bool = True):
    """A task on the Panda with the given stages."""
    from mtc import core

    task = core.Task(introspection=introspection)
    task.setRobotModel(mtc.robots.panda())
    task.add(*stages)
    return task


def _box(name: str, position, size=(0.1, 0.1, 0.1), frame: str = "world") -> msgs.CollisionObject:
    """An ADD message of a box at ``position`` (identity orientation)."""
    x, y, z = position
    return msgs.CollisionObject(
        id=name,
        header=msgs.Header(frame_id=frame),
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.BOX, dimensions=list(size))],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        pose=msgs.Pose(position=msgs.Point(x=x, y=y, z=z), orientation=msgs.Quaternion(w=1.0)),
        operation=msgs.CollisionObject.ADD,
    )


def _sphere(name: str, position, radius: float = 0.05, frame: str = "world") -> msgs.CollisionObject:
    """An ADD message of a sphere at ``position``."""
    x, y, z = position
    return msgs.CollisionObject(
        id=name,
        header=msgs.Header(frame_id=frame),
        primitives=[msgs.SolidPrimitive(type=msgs.SolidPrimitive.SPHERE, dimensions=[radius])],
        primitive_poses=[msgs.Pose(orientation=msgs.Quaternion(w=1.0))],
        pose=msgs.Pose(position=msgs.Point(x=x, y=y, z=z), orientation=msgs.Quaternion(w=1.0)),
        operation=msgs.CollisionObject.ADD,
    )


@pytest.fixture
def make_task():
    """``make_task(*stages, introspection=True)``: a Panda task with these stages."""
    return _make_task


@pytest.fixture
def box():
    """``box(name, position, size=(0.1,)*3, frame="world")``: an ADD CollisionObject."""
    return _box


@pytest.fixture
def sphere():
    """``sphere(name, position, radius=0.05, frame="world")``: an ADD CollisionObject."""
    return _sphere
