"""MTC's test_stage.cpp as MTC writes it: ComputeIK.init and ModifyPlanningScene.allowCollisions on
the toy robot.

(Stage.registerCallbacks is in tests/core/test_stage.py; Connect.compatible with upstream's exact
sequence of scene edits is in test_mtc_parity_scene_rules.py.)
"""

from __future__ import annotations

import pytest
from mockups import GeneratorMockup, toy_model

from mtc import core, stages


def test_compute_ik_init():
    """ComputeIK.init: neither eef nor group is fine; an unknown one is an InitStageError."""
    ik = stages.ComputeIK("ik", GeneratorMockup())
    robot_model = toy_model()
    props = ik.properties

    # neither eef nor group defined should not throw
    ik.init(robot_model)

    # invalid eef should throw
    props.set("eef", "undefined")
    with pytest.raises(core.InitStageError):
        ik.init(robot_model)

    # valid eef should not throw
    props.set("eef", "eef")
    ik.init(robot_model)

    props.set("eef", None)  # boost::any(): undefined again

    # invalid group should throw
    props.set("group", "undefined")
    with pytest.raises(core.InitStageError):
        ik.init(robot_model)

    # valid group should not throw
    props.set("group", "group")
    ik.init(robot_model)


def test_modify_planning_scene_allow_collisions():
    """ModifyPlanningScene.allowCollisions: a name or a list/set of names on either side."""
    s = stages.ModifyPlanningScene()
    first, second = "foo", "boom"
    s.allowCollisions(first, second, True)
    s.allowCollisions(first, ["ab", "abc"], False)

    s.allowCollisions("foo", ["bar", "boom"], True)
    s.allowCollisions("foo", {"ab", "abc"}, False)

