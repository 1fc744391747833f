"""Tests of stages.CurrentState: one diff of the current scene per init, cost 0."""

from __future__ import annotations

from pathlib import Path

import mtc
from mtc import core, stages
from mtc.scene.robot_model import RobotModel

DATA = Path(__file__).resolve().parents[1] / "data"


def test_defaults():
    """Name 'current state'; timeout 3.0 set as a manual value (survives reset)."""
    s = stages.CurrentState()
    assert s.name == "current state"
    assert s.timeout == 3.0
    assert "planning scene" in s.properties.property("timeout").description()
    s.properties.reset()
    assert s.timeout == 3.0


def test_spawns_a_diff_of_the_current_scene(make_task, box):
    """The solution's scene is a child of the current scene, with its objects and state."""
    psi = mtc.PlanningSceneInterface()
    psi.add_object(box("table", (0.6, 0.0, 0.2)))
    s = stages.CurrentState("start")
    task = make_task(s)
    assert task.plan()
    assert len(s.solutions) == 1
    solution = s.solutions[0]
    assert solution.cost == 0.0
    scene = solution.end.scene
    current = mtc.current_scene()
    assert scene is not current and scene.parent is current
    assert scene.world_object_names == ["table"]
    assert scene.current_state == current.current_state


def test_later_changes_of_the_current_scene_do_not_leak(make_task, box):
    """The spawned scene keeps what the current scene was at compute time."""
    s = stages.CurrentState()
    task = make_task(s)
    assert task.plan()
    mtc.PlanningSceneInterface().add_object(box("late", (0.6, 0.0, 0.2)))
    assert s.solutions[0].end.scene.world_object_names == []


def test_one_computation_per_init(make_task):
    """canCompute() is false after one compute; each plan() initializes it again."""
    s = stages.CurrentState()
    task = make_task(s)
    assert task.plan()
    assert not s.canCompute()
    assert task.plan()
    # plan() initializes again (it does not reset, as MTC): one more solution
    assert len(task.solutions) == 2
    task.reset()
    assert not s.canCompute()  # reset() alone does not re-arm it, as MTC


def test_current_scene_follows_the_task_robot():
    """A task on another robot reads a current scene of that robot."""
    toy = RobotModel(DATA / "toy_robot.urdf", DATA / "toy_robot.srdf")
    task = core.Task()
    task.setRobotModel(toy)
    s = stages.CurrentState()
    task.add(s)
    assert task.plan()
    assert s.solutions[0].end.scene.robot_model is toy
    assert mtc.current_scene().robot_model is not toy or mtc.current_scene(toy).robot_model is toy


def test_default_task_uses_the_panda():
    """The seed's snippet: a Task without a model plans a CurrentState on the Panda."""
    task = core.Task()
    task.name = "current state demo"
    task.add(stages.CurrentState("current state"))
    assert task.plan()
    assert task.solutions[0].end.scene.robot_model is mtc.robots.panda()
