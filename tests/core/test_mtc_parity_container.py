"""MTC's Task.reuse (test_container.cpp) and Task.taskMoveConstructor (test_move_to.cpp) as MTC
writes them: with the real ``stages.FixedState`` as the monitored stage.

tests/core/test_container.py::test_task_reuse runs the scenario with a hand-made generator.
"""

from __future__ import annotations

from mockups import ConnectMockup, MonitoringGeneratorMockup, new_scene, resetMockupIds, toy_model

from mtc import core, stages


def _configure(t):
    """FixedState 'fixed' (an empty scene) -> ConnectMockup -> MonitoringGeneratorMockup(fixed)."""
    resetMockupIds()
    ref = stages.FixedState("fixed")
    ref.setState(new_scene(t.getRobotModel()))
    t.add(ref)
    t.add(ConnectMockup())
    t.add(MonitoringGeneratorMockup(ref))


def test_task_reuse():
    """Task.reuse: a task is planned, replaced by a new one on the same model, planned again."""
    robot_model = toy_model()

    t = core.Task("first")
    t.setRobotModel(robot_model)
    _configure(t)
    assert t.plan(1)

    t = core.Task("second")
    t.setRobotModel(robot_model)
    assert len(t.stages) == 0  # an empty root container ("task pipeline")
    assert t.stages.parent is t

    _configure(t)
    assert t.plan(1)


def test_task_move_constructor():
    """Task.taskMoveConstructor: a task built in a function and returned works (init, then plan(1))."""

    def create_task():
        t = core.Task("first")
        t.setRobotModel(toy_model())
        ref = stages.FixedState("fixed")
        ref.setState(new_scene(t.getRobotModel()))
        t.add(ref)
        t.add(ConnectMockup())
        t.add(MonitoringGeneratorMockup(ref))
        return t

    t = core.Task()
    t = create_task()
    t.init()
    assert t.plan(1)
