"""MTC's test mockups (``stage_mockups.h``, ``mtc_semantics.md`` §7.1) for scheduler tests.

The mockups produce states and solutions with predefined costs and count their runs;
many expected results depend on their exact cost-consumption semantics, kept here.
"""

from __future__ import annotations

import math
from pathlib import Path

from mtc import core

INF = math.inf
DATA = Path(__file__).parent / "data"

_toy_model = None


def toy_model():
    """The toy 3-joint robot of MTC's tests (continuous joints, no geometry), loaded once."""
    global _toy_model
    if _toy_model is None:
        import mtc

        _toy_model = mtc.RobotModel(str(DATA / "toy_robot.urdf"), str(DATA / "toy_robot.srdf"))
    return _toy_model


def new_scene(robot_model=None):
    """An empty planning scene of the toy robot."""
    import mtc

    return mtc.PlanningScene(robot_model if robot_model is not None else toy_model())


class PredefinedCosts(core.CostTerm):
    """A list of costs handed out one by one; usable as cost term (same cost for any solution kind).

    Args:
        costs: The costs.
        finite: If False, the last cost repeats forever.
    """

    def __init__(self, costs=(), finite: bool = True):
        self.costs = list(costs)
        self.finite = finite

    @classmethod
    def constant(cls, c: float) -> "PredefinedCosts":
        """An infinite supply of ``c``."""
        return cls([c], finite=False)

    @classmethod
    def single(cls, c: float) -> "PredefinedCosts":
        """Exactly one ``c``."""
        return cls([c], finite=True)

    def exhausted(self) -> bool:
        return not self.costs

    def cost(self) -> float:
        # keep the tests going, but this should not happen
        assert self.costs, "PredefinedCosts exhausted"
        if not self.costs:
            return 0.0
        c = self.costs[0]
        if self.finite or len(self.costs) > 1:
            self.costs.pop(0)
        return c

    def __call__(self, solution):
        return self.cost()


def _costs(costs, default):
    if costs is None:
        return default
    if isinstance(costs, PredefinedCosts):
        return costs
    return PredefinedCosts(list(costs), finite=True)


_ids: dict[str, int] = {}


def _next_id(kind: str) -> int:
    _ids[kind] = _ids.get(kind, 0) + 1
    return _ids[kind]


def resetMockupIds() -> None:
    """Zero the name counters of all mockup kinds."""
    _ids.clear()


class GeneratorMockup(core.Generator):
    """Spawns a new state of its own empty scene per cost (``solutions_per_compute`` per run)."""

    def __init__(self, costs=None, solutions_per_compute: int = 1):
        super().__init__(f"GEN{_next_id('GEN')}")
        self.costs = _costs(costs, PredefinedCosts([0.0], finite=True))
        self.solutions_per_compute = solutions_per_compute
        self.runs = 0
        self.ps = None

    def init(self, robot_model):
        self.ps = new_scene(robot_model)
        super().init(robot_model)

    def reset(self):
        # as MTC's mockup: only the counter (the costs are not refilled)
        self.runs = 0

    def canCompute(self):
        return not self.costs.exhausted()

    def compute(self):
        self.runs += 1
        i = 0
        while self.canCompute() and i < self.solutions_per_compute:
            self.spawn(core.InterfaceState(self.ps), self.costs.cost())
            i += 1


class MonitoringGeneratorMockup(core.MonitoringGenerator):
    """Spawns a diff of every monitored solution's end scene at once (cost 0)."""

    def __init__(self, monitored, costs=None):
        super().__init__(f"MON{_next_id('MON')}", monitored)
        self.costs = _costs(costs, PredefinedCosts.constant(0.0))
        self.runs = 0

    def reset(self):
        self.runs = 0

    def canCompute(self):
        return False

    def compute(self):
        pass

    def onNewSolution(self, solution):
        self.runs += 1
        self.spawn(core.InterfaceState(solution.end.scene.diff()), core.SubTrajectory())


def _cpp_double(x: float) -> str:
    """C++ ``std::to_string(double)``: fixed notation with 6 decimals."""
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return f"{x:.6f}"


class ConnectMockup(core.Connecting):
    """Connects every pair with the next predefined cost; comment "<from cost> -> <to cost>"."""

    def __init__(self, costs=None):
        super().__init__(f"CON{_next_id('CON')}")
        self.costs = _costs(costs, PredefinedCosts.constant(0.0))
        self.runs = 0

    def reset(self):
        self.runs = 0

    def compute(self, from_state, to_state):
        self.runs += 1
        solution = core.SubTrajectory()
        solution.cost = self.costs.cost()
        solution.comment = f"{_cpp_double(from_state.priority.cost)} -> {_cpp_double(to_state.priority.cost)}"
        self.connect(from_state, to_state, solution)


class PropagatorMockup(core.PropagatingEitherWay):
    """Propagates a diff of the input scene with the next predefined cost, in either direction."""

    def __init__(self, costs=None, solutions_per_compute: int = 1, name: str | None = None):
        super().__init__(name or f"PRO{_next_id('PRO')}")
        self.costs = _costs(costs, PredefinedCosts.constant(0.0))
        self.solutions_per_compute = solutions_per_compute
        self.runs = 0

    def reset(self):
        self.runs = 0

    def computeForward(self, from_state):
        self.runs += 1
        for _ in range(self.solutions_per_compute):
            solution = core.SubTrajectory(None, self.costs.cost())
            self.sendForward(from_state, core.InterfaceState(from_state.scene.diff()), solution)

    def computeBackward(self, to_state):
        self.runs += 1
        for _ in range(self.solutions_per_compute):
            solution = core.SubTrajectory(None, self.costs.cost())
            self.sendBackward(core.InterfaceState(to_state.scene.diff()), to_state, solution)


class ForwardMockup(PropagatorMockup):
    """A PropagatorMockup restricted to FORWARD, named FWD<n> (the PRO counter counts too)."""

    def __init__(self, costs=None, solutions_per_compute: int = 1):
        super().__init__(costs, solutions_per_compute)
        self.restrictDirection(core.PropagatingEitherWay.FORWARD)
        self.name = f"FWD{_next_id('FWD')}"


class BackwardMockup(PropagatorMockup):
    """A PropagatorMockup restricted to BACKWARD, named BWD<n>."""

    def __init__(self, costs=None, solutions_per_compute: int = 1):
        super().__init__(costs, solutions_per_compute)
        self.restrictDirection(core.PropagatingEitherWay.BACKWARD)
        self.name = f"BWD{_next_id('BWD')}"


class DelayingWrapper(core.WrapperBase):
    """Delays its child: ``delays[0]`` compute steps pass before the child computes (then pop)."""

    def __init__(self, delays, child):
        super().__init__("delayer", child)
        self.delays = list(delays)

    def compute(self):
        if self.delays:
            if self.delays[0] == 0:
                self.delays.pop(0)  # we can compute now
            else:
                self.delays[0] -= 1  # continue delaying
                return
        super().compute()

    def onNewSolution(self, solution):
        self.liftSolution(solution)


def add(container, stage):
    """Add ``stage`` to ``container`` and return it (to read its ``runs`` later)."""
    container.add(stage)
    return stage


def make_task(**kwargs):
    """A task on the toy robot without introspection (as MTC's unit tests run)."""
    resetMockupIds()
    t = core.Task(introspection=False, **kwargs)
    t.setRobotModel(toy_model())
    return t


def costs(solutions):
    """The costs of solutions in their stored order (MTC's EXPECT_COSTS)."""
    return [s.cost for s in solutions]
