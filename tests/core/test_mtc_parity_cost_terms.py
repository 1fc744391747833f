"""MTC's test_cost_terms.cpp PassThrough tests as MTC writes them: with the real ``stages.PassThrough``.

tests/core/test_cost_terms.py runs them on a hand-made wrapper. Upstream's ``Standalone<T>``
runs one compute step of a container fed with one state per open end; ``_compute_with_stages``
below does the same.
"""

from __future__ import annotations

from mockups import BackwardMockup, PredefinedCosts, new_scene, toy_model

from mtc import core, stages
from mtc.core.stage import END_IF_MASK, READS_END, READS_START, START_IF_MASK, WRITES_NEXT_START, WRITES_PREV_END
from mtc.core.storage import Interface, Priority

STAGE_COST = 7.0


def BackwardCostMockup():
    return BackwardMockup(PredefinedCosts.constant(STAGE_COST))


def _leaf(stage, first: bool):
    while isinstance(stage, core.ContainerBase):
        stage = stage[0] if first else stage[-1]
    return stage


def _compute_with_stages(container, children):
    """MTC's Standalone<T>::computeWithStages: add the children, prepare the interfaces, compute once."""
    container.clear()
    for child in children:
        container.add(child)
    container._resetStage()
    flags = (_leaf(container, True).requiredInterface() & START_IF_MASK) | (
        _leaf(container, False).requiredInterface() & END_IF_MASK
    )
    dummy = Interface()
    container._prev_ends = dummy if flags & WRITES_PREV_END else None
    container._next_starts = dummy if flags & WRITES_NEXT_START else None
    container._initStage(toy_model())
    container._resolveInterface(flags)
    scene = new_scene()
    if flags & READS_START:
        container.starts.add(core.InterfaceState(scene, Priority(1, 0.0)))
    if flags & READS_END:
        container.ends.add(core.InterfaceState(scene, Priority(1, 0.0)))
    container._runCompute()


def test_pass_through_uses_cost():
    """CostTerm.PassThroughUsesCost."""
    container = stages.PassThrough()
    stage = BackwardCostMockup()
    stage.setCostTerm(core.Constant(84.0))

    _compute_with_stages(container, [stage])

    wrapped = container.solutions[0]
    assert isinstance(wrapped, core.WrappedSolution)
    assert wrapped.cost == 84.0, "PassThrough forwards children's cost"
    assert wrapped.wrapped.cost == 84.0, "Child cost equals PassThrough cost"


def test_pass_through_overwrites_cost():
    """CostTerm.PassThroughOverwritesCost."""
    container = stages.PassThrough()
    stage = BackwardCostMockup()
    stage.setCostTerm(core.Constant(84.0))
    container.setCostTerm(core.Constant(72.0))

    _compute_with_stages(container, [stage])

    wrapped = container.solutions[0]
    assert isinstance(wrapped, core.WrappedSolution)
    assert wrapped.cost == 72.0, "PassThrough can apply custom cost"
    assert wrapped.wrapped.cost == 84.0, "child's cost is not affected"


def test_pass_through_can_modify_cost():
    """CostTerm.PassThroughCanModifyCost."""
    container = stages.PassThrough()
    stage = BackwardCostMockup()
    stage.setCostTerm(core.Constant(8.0))
    container.setCostTerm(lambda s: s.cost * s.cost)

    _compute_with_stages(container, [stage])

    wrapped = container.solutions[0]
    assert isinstance(wrapped, core.WrappedSolution)
    assert wrapped.cost == 8.0 * 8.0, "PassThrough can compute cost based on child"
    assert wrapped.wrapped.cost == 8.0, "child's cost is not affected"
