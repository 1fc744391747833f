"""MTC's test_mockups.cpp: the mockups themselves behave as upstream's (GeneratorMockup, DelayingWrapper)."""

from __future__ import annotations

from mockups import DelayingWrapper, GeneratorMockup, PredefinedCosts, costs, toy_model

from mtc.core.storage import Interface


class TestGeneratorMockup(GeneratorMockup):
    """MTC's TestGeneratorMockup: a generator with push interfaces of its own."""

    __test__ = False  # not a pytest test class

    def init_standalone(self):
        self.next_starts_ = Interface()
        self.prev_ends_ = Interface()
        GeneratorMockup.reset(self)
        GeneratorMockup.init(self, toy_model())
        self._next_starts = self.next_starts_
        self._prev_ends = self.prev_ends_


def test_generator_mockup_compute():
    """GeneratorMockup.compute: three computes spawn the three costs; then it cannot compute."""
    gen = TestGeneratorMockup([1.0, 2.0, 3.0])
    gen.init_standalone()

    for _ in range(3):
        assert gen.canCompute()
        gen.compute()
    assert not gen.canCompute()

    assert costs(gen.solutions) == [1, 2, 3]


def test_generator_mockup_delayed():
    """GeneratorMockup.delayed: DelayingWrapper([1, 0, 2]) skips 1, 0 and 2 compute steps."""
    gen = TestGeneratorMockup(PredefinedCosts([1.0, 2.0, 3.0]))
    gen.init_standalone()

    w = DelayingWrapper([1, 0, 2], gen)
    w._prev_ends = Interface()
    w._next_starts = Interface()

    def compute_expect_costs(*expected):
        assert w.canCompute()
        w.compute()
        assert costs(gen.solutions) == list(expected)
        assert gen.runs == len(expected)

    # 1st compute() is delayed by 1
    compute_expect_costs()
    compute_expect_costs(1)

    # 2nd compute() is not delayed
    compute_expect_costs(1, 2)

    # 3rd compute() is delayed by 2
    compute_expect_costs(1, 2)
    compute_expect_costs(1, 2)
    compute_expect_costs(1, 2, 3)

    assert not w.canCompute()
