"""Tests of stages.NoOp: passes a diff of the scene on, either way, at cost 0."""

from __future__ import annotations

from mtc import core, stages


def test_defaults():
    """Name 'no-op', direction resolved by its neighbours."""
    assert stages.NoOp().name == "no-op"


def test_forward(make_task):
    """Forward: the end scene is a diff of the start scene; empty solution of cost 0."""
    n = stages.NoOp()
    task = make_task(stages.CurrentState(), n)
    assert task.plan()
    sol = n.solutions[0]
    assert sol.cost == 0.0 and sol.trajectory is None
    assert sol.end.scene.parent is sol.start.scene


def test_backward(make_task, ready_scene):
    """Backward: the start scene is a diff of the end scene."""
    n = stages.NoOp()
    task = make_task(n, stages.FixedState("end", ready_scene))
    assert task.plan()
    sol = n.solutions[0]
    assert sol.start.scene.parent is sol.end.scene


def test_holds_custom_properties_and_forwards_them(make_task):
    """A NoOp holds properties that children inherit, and forwards interface properties."""
    n = stages.NoOp("holder")
    n.setProperty("group", "panda_arm")
    n.setForwardedProperties(["target"])

    class Tag(stages.NoOp):
        def computeForward(self, from_state):
            to_state = core.InterfaceState(from_state.scene.diff())
            to_state.properties.set("target", "box")
            self.sendForward(from_state, to_state, core.SubTrajectory())

    tag = Tag("tag")
    task = make_task(stages.CurrentState(), tag, n)
    assert task.plan()
    assert n.properties.get("group") == "panda_arm"
    assert n.solutions[0].end.properties.get("target") == "box"
