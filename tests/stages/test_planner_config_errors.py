"""Planner configuration errors inside a task: an unknown pipeline or planner id is a
configuration error of the stage that uses the planner, collected by ``Task.init`` with
every other problem of the tree into one ``core.InitStageError`` (api.md, "Errors")."""

from __future__ import annotations

import pytest

import mtc
from mtc import core, stages


def _task(*children):
    task = core.Task()
    task.add(stages.CurrentState("current"))
    for child in children:
        task.add(child)
    return task


def test_unknown_planner_ids_are_collected_per_stage():
    ompl = core.PipelinePlanner("ompl")
    ompl.planner = "RRTConectkConfigDefault"  # a typo
    move = stages.MoveTo("move", ompl)
    move.group = "panda_arm"
    move.setGoal("extended")
    pilz = core.PipelinePlanner("pilz_industrial_motion_planner")
    pilz.planner = "SPLINE"
    rel = stages.MoveRelative("lift", pilz)
    rel.group = "panda_arm"
    rel.setDirection({"panda_joint1": 0.1})
    task = _task(move, rel)
    with pytest.raises(core.InitStageError) as info:
        task.init()
    text = str(info.value)
    assert "move: unknown OMPL planner id 'RRTConectkConfigDefault' (known: " in text
    assert "RRTConnectkConfigDefault" in text
    assert "lift: unknown planner 'SPLINE' for pipeline 'pilz_industrial_motion_planner' (known: PTP, LIN, CIRC)" in text
    assert len(info.value) == 2


def test_unknown_pipeline_of_a_connect_planner_names_the_connect():
    connect = stages.Connect("connect", [("panda_arm", core.PipelinePlanner("chomp"))])
    fixed = stages.FixedState("b")
    fixed.setState(mtc.current_scene().diff())
    task = core.Task()
    task.add(stages.CurrentState("a"), connect, fixed)
    with pytest.raises(core.InitStageError) as info:
        task.init()
    assert "connect: unknown planning pipeline 'chomp' (known: ompl, pilz_industrial_motion_planner)" in str(info.value)


def test_a_valid_planner_id_initializes():
    ompl = core.PipelinePlanner("ompl")
    ompl.planner = "PRMkConfigDefault"
    move = stages.MoveTo("move", ompl)
    move.group = "panda_arm"
    move.setGoal("extended")
    _task(move).init()
