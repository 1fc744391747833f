"""Tests of stages.FixedState: spawns one given scene per reset, cost 0, collision check."""

from __future__ import annotations

import io

from pathlib import Path

import pytest

from mtc import core, stages
from mtc.scene.planning_scene import PlanningScene
from mtc.scene.robot_model import RobotModel

DATA = Path(__file__).resolve().parents[1] / "data"


def test_defaults():
    """Name 'fixed state' (api.md), ignore_collisions False, Constant(0) cost term."""
    s = stages.FixedState()
    assert s.name == "fixed state"
    assert s.ignore_collisions is False
    assert isinstance(s.costTerm(), core.Constant) and s.costTerm().cost == 0.0
    assert not s.canCompute()  # no scene yet


def test_spawns_the_scene_once(make_task, ready_scene):
    """The given scene is spawned as it is, once per reset."""
    s = stages.FixedState("start", ready_scene)
    task = make_task(s)
    assert task.plan()
    assert len(s.solutions) == 1
    assert s.solutions[0].end.scene is ready_scene
    assert s.solutions[0].cost == 0.0
    assert not s.canCompute()
    s.reset()
    assert s.canCompute()


def test_seed_snippet_with_set_state():
    """The seed's snippet: PlanningScene(task.getRobotModel()) handed over with setState()."""
    task = core.Task()
    task.loadRobotModel()
    scene = PlanningScene(task.getRobotModel())
    fixed = stages.FixedState("fixed state")
    fixed.setState(scene)
    task.add(fixed)
    assert task.plan()


def test_cost_term_overrides_any_cost(make_task, ready_scene):
    """A user cost term replaces the default Constant(0)."""
    s = stages.FixedState("start", ready_scene)
    s.setCostTerm(lambda solution: 2.5)
    task = make_task(s)
    assert task.plan()
    assert s.solutions[0].cost == 2.5


def test_without_scene_nothing_is_planned(make_task):
    """A FixedState without a scene cannot compute (as MTC): plan() fails, and explainFailure
    says why (MTC prints nothing under its header)."""
    task = make_task(stages.FixedState())
    assert not task.plan()
    out = io.StringIO()
    assert task.explainFailure(out)
    assert out.getvalue() == "Failing stage(s):\nfixed state (0/0): no scene to spawn (set one with setState(scene))\n"


def test_set_state_rejects_other_types():
    """setState() takes a PlanningScene."""
    with pytest.raises(TypeError, match="PlanningScene"):
        stages.FixedState().setState("scene")


def test_colliding_scene_is_a_failure(make_task, ready_scene, box, caplog):
    """A colliding robot state is a failure "in collision" (MTC's comment; the log names the
    pairs) unless ignore_collisions."""
    ready_scene.apply_collision_object(box("wall", (0.3, 0.0, 0.5), size=(0.2, 0.2, 0.2)))
    s = stages.FixedState("start", ready_scene)
    task = make_task(s)
    with caplog.at_level("INFO", logger="mtc.stages.fixed_state"):
        assert not task.plan()
    assert s.failures[0].comment == "in collision"
    assert "wall" in caplog.text and " - " in caplog.text

    s.setIgnoreCollisions(True)
    task.reset()  # plan() does not reset (as MTC): re-arm the generator
    assert task.plan()
    assert len(s.solutions) == 1


def test_scene_of_another_robot_is_an_init_error(make_task):
    """A scene of another robot model is rejected at init, naming both robots."""
    toy = RobotModel(DATA / "toy_robot.urdf", DATA / "toy_robot.srdf")
    task = make_task(stages.FixedState("start", PlanningScene(toy)))
    with pytest.raises(core.InitStageError, match="robot model"):
        task.plan()
