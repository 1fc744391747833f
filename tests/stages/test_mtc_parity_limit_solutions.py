"""MTC's test_limit_solutions.cpp (master, after #745): LimitSolutions around a GeneratorMockup."""

from __future__ import annotations

import sys
from pathlib import Path

# tests/mockups.py is shared by the test folders
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mockups import DelayingWrapper, GeneratorMockup, PredefinedCosts, make_task  # noqa: E402

from mtc import stages  # noqa: E402


def test_returns_max_solutions():
    """LimitSolutionsTest.returnsMaxSolutions."""
    t = make_task()
    g = GeneratorMockup(PredefinedCosts([2.0, 1.0, 3.0]))
    ls = stages.LimitSolutions("LimitSolutions", g)
    ls.setMaxSolutions(2)
    t.add(ls)

    assert t.plan()
    assert len(t.solutions) == 2


def test_returns_all_child_solutions_if_fewer_than_max():
    """LimitSolutionsTest.returnsAllChildSolutionsIfFewerThanMax."""
    t = make_task()
    g = GeneratorMockup(PredefinedCosts([2.0, 1.0, 3.0]))
    ls = stages.LimitSolutions("LimitSolutions", g)
    ls.setMaxSolutions(5)
    t.add(ls)

    assert t.plan()
    assert len(t.solutions) == 3


def test_returns_best_solutions():
    """LimitSolutionsTest.returnsBestSolutions: of the 4 costs made in one compute, only the
    first 3 are considered, so the cheapest (1.0) is not among the solutions."""
    t = make_task()
    # generator can create solutions with costs 1-4 in a single call to compute
    g = GeneratorMockup(PredefinedCosts([4.0, 2.0, 3.0, 1.0]), 4)
    ls = stages.LimitSolutions("LimitSolutions", g)
    ls.setMaxSolutions(3)  # however, only the first 3 solutions will be considered
    t.add(ls)

    assert t.plan()
    assert len(t.solutions) == 3  # only 3 solutions should have been generated
    assert t.solutions[0].cost == 2.0  # solution with cost 1.0 was not considered anymore


def test_child_not_called_after_limit_reached():
    """LimitSolutionsTest.childNotCalledAfterLimitReached (#745)."""
    t = make_task()
    g = GeneratorMockup(PredefinedCosts([4.0, 2.0, 3.0, 1.0]), 1)

    ls = stages.LimitSolutions("LimitSolutions", g)
    ls.setMaxSolutions(1)

    delayed = DelayingWrapper([0, 0, 1, 1, 1], ls)
    t.add(delayed)

    assert t.plan()
    assert len(t.solutions) == 1
    assert g.runs == 1  # generator (child) should run only once
