"""GenerateRandomPose: random poses around a seed pose, sampled per dimension.

MTC's ``stages/generate_random_pose.h`` (semantics §2.12). For every solution of the
monitored stage, the seed ``pose`` is spawned first, then up to ``max_solutions - 1`` random
variations of it (within ``timeout``). Each configured dimension is sampled by its own
sampler and applied in the order the dimensions were configured: X/Y/Z translate along the
pose's own axes, ROLL/PITCH/YAW rotate about them.

Fixes and additions to MTC:

* each dimension keeps its own distribution and width (MTC's distributions are
  function-static, so the first width configured per distribution type is used for all
  dimensions, Appendix A #9);
* sampling is reproducible: the random numbers come from ``numpy`` generators seeded with
  the ``seed`` property and the number of upstream solutions consumed since ``reset()``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np

from mtc import msgs
from mtc.core.properties import BindingEnum, unsigned_int
from mtc.core.storage import InterfaceState, SubTrajectory
from mtc.stages.generate_pose import GeneratePose, copy_pose_stamped, frame_marker, pose_stamped

__all__ = ["GenerateRandomPose", "PoseDimension"]


class PoseDimension(BindingEnum):
    """A dimension of a pose to sample (MTC's ``GenerateRandomPose::PoseDimension``)."""

    X = 0
    Y = 1
    Z = 2
    ROLL = 3
    PITCH = 4
    YAW = 5


_DISTRIBUTIONS = ("uniform", "normal")


def _local_transform(dim: PoseDimension, value: float) -> np.ndarray:
    """Translation along / rotation about the local axis of ``dim`` by ``value`` [m or rad]."""
    T = np.eye(4)
    if dim <= PoseDimension.Z:
        T[dim, 3] = value
        return T
    axis = dim - PoseDimension.ROLL
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    c, s = math.cos(value), math.sin(value)
    T[i, i], T[i, j], T[j, i], T[j, j] = c, -s, s, c
    return T


class GenerateRandomPose(GeneratePose):
    """Spawn the seed ``pose`` and random variations of it for each monitored solution.

    Args:
        name: Stage name.

    Properties:
        pose: The seed pose (``PoseStamped``).
        max_solutions: Poses per upstream solution, the seed included (default 20).
        timeout: Time limit per upstream solution [s] (default 1.0).
        seed: Seed of the random numbers (default 0): the same task samples the same poses.

    Configure at least one dimension with :meth:`sample_dimension`, else the stage never
    computes. Cost: always 0.
    """

    def __init__(self, name: str = "generate random pose"):
        super().__init__(name)
        p = self.properties
        p.property("pose").setDescription("seed pose")
        p.property("timeout").setDefaultValue(1.0)
        p.declare("max_solutions", 20, "maximum number of spawned solutions per upstream solution",
                  type=unsigned_int)
        p.declare("seed", 0, "seed of the random number generator", type=int)
        # (dimension, sampler(rng) -> deviation) in configuration order
        self._samplers: list[tuple[PoseDimension, Callable[[np.random.Generator], float]]] = []
        self._consumed = 0

    def setMaxSolutions(self, max_solutions: int) -> None:
        """Set ``max_solutions`` (MTC's C++ setter)."""
        self.properties.set("max_solutions", max_solutions)

    def set_max_solutions(self, max_solutions: int) -> None:
        """Set ``max_solutions`` (MTC's Python binding's name)."""
        self.setMaxSolutions(max_solutions)

    def sample_dimension(self, dimension, width, distribution: str = "uniform") -> None:
        """Sample one dimension of the pose (MTC's ``sampleDimension``; Python name as MTC's binding).

        Args:
            dimension: A :class:`PoseDimension` (or its int value).
            width: For ``"uniform"``: the full width of the interval centred on the seed
                value [m or rad]; for ``"normal"``: the standard deviation. Or a callable
                ``f(rng) -> deviation`` (``rng`` a ``numpy.random.Generator``) for any other
                distribution.
            distribution: ``"uniform"`` (default, MTC's binding) or ``"normal"``.

        Raises:
            ValueError: Unknown dimension or distribution, or a negative width.
            TypeError: ``width`` is neither a number nor a callable.
        """
        if not (msgs.is_number(dimension, integral=True) and int(dimension) in PoseDimension._value2member_map_):
            raise ValueError(
                f"unknown pose dimension {dimension!r} (PoseDimension: {', '.join(d.name for d in PoseDimension)})"
            )
        dim = PoseDimension(int(dimension))
        if callable(width):
            fn = width

            def sampler(rng, fn=fn, dim=dim):
                value = fn(rng)
                number = msgs.real_value(value)
                if number is None:
                    raise TypeError(f"the sampler of dimension {dim.name} must return a number, got {value!r}")
                if not math.isfinite(number):
                    raise ValueError(f"the sampler of dimension {dim.name} must return a finite number, got {value!r}")
                return number
        else:
            if not msgs.is_number(width):
                raise TypeError(f"width must be a number or a callable f(rng) -> deviation, got {type(width).__name__}")
            width = float(width)
            if not math.isfinite(width) or width < 0.0:
                raise ValueError(f"width must be finite and >= 0, got {width}")
            if distribution == "uniform":
                half = 0.5 * width
                sampler = lambda rng: float(rng.uniform(-half, half))  # noqa: E731
            elif distribution == "normal":
                sampler = lambda rng: float(rng.normal(0.0, width))  # noqa: E731
            else:
                raise ValueError(f"unknown distribution {distribution!r} (distributions: {', '.join(_DISTRIBUTIONS)})")
        self._samplers.append((dim, sampler))

    def reset(self) -> None:
        super().reset()
        self._consumed = 0

    def canCompute(self) -> bool:
        return bool(self._upstream) and bool(self._samplers)

    def compute(self) -> None:
        if not self._upstream or not self._samplers:
            return
        s = self._upstream.pop()
        p = self.properties
        rng = np.random.default_rng([int(p.get("seed")) & 0xFFFFFFFF, self._consumed])
        self._consumed += 1
        scene = s.end.scene.diff()
        seed_pose = copy_pose_stamped(p.get("pose"))
        frame = seed_pose.header.frame_id
        if not frame:
            frame = seed_pose.header.frame_id = scene.planning_frame
        elif not scene.knows_frame_transform(frame):
            self.failOrWarn(scene, f"Unknown frame: '{frame}'")
            return
        seed = msgs.pose_to_matrix(seed_pose.pose)
        ns = self.markerNS()

        def spawn(target) -> None:
            state = InterfaceState(scene)
            self.forwardProperties(s.end, state)
            state.properties.set("target_pose", target)
            solution = SubTrajectory(None, 0.0)
            solution.markers.append(frame_marker(ns, "pose frame", target))
            self.spawn(state, solution)

        spawn(seed_pose)
        max_solutions = p.get("max_solutions")
        timeout = p.get("timeout")
        start = time.perf_counter()
        elapsed = 0.0  # as MTC: measured after each sample, so any timeout > 0 gives one
        count = 1
        while count < max_solutions and elapsed < timeout:
            count += 1
            T = seed
            for dim, sampler in self._samplers:
                T = T @ _local_transform(dim, sampler(rng))
            spawn(pose_stamped(T, frame))
            elapsed = time.perf_counter() - start
