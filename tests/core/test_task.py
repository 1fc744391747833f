"""Task details: default robot, error codes, namespace, introspection switch, lazy planner exports."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from mockups import GeneratorMockup, add, toy_model

import mtc
from mtc import core
from mtc.core.task import _normalize_ns


def test_default_robot_is_the_panda():
    """Without a robot model, init() loads mtc.robots.panda() (as MTC loads robot_description)."""
    t = core.Task(introspection=False)
    t.add(GeneratorMockup([1.0]))
    assert t.getRobotModel() is None
    assert t.plan()
    assert t.getRobotModel().name == mtc.robots.panda().name


def test_error_codes():
    ok = core.MoveItErrorCode(core.MoveItErrorCode.SUCCESS)
    assert ok and ok.val == 1 and ok == 1
    for code in (core.MoveItErrorCode.PLANNING_FAILED, core.MoveItErrorCode.TIMED_OUT, core.MoveItErrorCode.PREEMPTED):
        assert not core.MoveItErrorCode(code)
    assert (core.MoveItErrorCode.PLANNING_FAILED, core.MoveItErrorCode.TIMED_OUT, core.MoveItErrorCode.PREEMPTED) == (
        -1, -6, -7)
    assert repr(core.MoveItErrorCode(-6)) == "MoveItErrorCode(TIMED_OUT)"


def test_plan_without_solution_returns_planning_failed(t):
    add(t, GeneratorMockup([float("inf")]))
    result = t.plan()
    assert result == core.MoveItErrorCode.PLANNING_FAILED and not result


@pytest.mark.parametrize("bad", [-1, 2.5, "2", None, True])
def test_plan_rejects_a_bad_max_solutions(t, bad):
    """As MTC's binding (a size_t): max_solutions is a whole number >= 0, checked before
    anything is planned."""
    gen = GeneratorMockup([1.0, 2.0])
    add(t, gen)
    with pytest.raises(TypeError, match=r"max_solutions must be a whole number >= 0 \(0: no limit\), got"):
        t.plan(bad)
    assert gen.runs == 0 and not t.solutions
    assert t.plan(np.int64(1)) and len(t.solutions) == 1


def test_namespace_normalized():
    assert _normalize_ns("") == ""
    assert _normalize_ns("9 my-task") == "my_task"
    assert _normalize_ns("/ns") == "_ns"


def test_set_robot_model_none_is_ignored(t):
    model = t.getRobotModel()
    t.setRobotModel(None)
    assert t.getRobotModel() is model


def test_disable_introspection_only_counts():
    t = core.Task()
    t.enableIntrospection(False)
    t.setRobotModel(toy_model())
    gen = add(t, GeneratorMockup([float("inf")]))
    assert not t.plan()
    assert gen.numFailures() == 1 and gen.failures == []


def test_core_imports_without_planners():
    """mtc.core imports on its own; the planner classes are looked up on first use."""
    code = (
        "import sys; from mtc import core; assert 'mtc.planners' not in sys.modules; "
        "assert core.JointInterpolationPlanner.__name__ == 'JointInterpolationPlanner'; "
        "assert 'mtc.planners' in sys.modules; "
        "assert not hasattr(core, 'NoSuchPlanner')"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_enable_introspection_keyword_is_the_bindings():
    """MTC's Python binding names the argument ``enabled`` (C++: ``enable``, taken too)."""
    t = core.Task()
    t.enableIntrospection(enabled=False)
    assert t._introspection_enabled is False
    t.enableIntrospection(enable=True)
    assert t._introspection_enabled is True
