"""Tests of stages.GenerateRandomPose: the seed pose plus seeded random variations per dimension."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mtc import core, msgs, stages
from mtc.stages import PoseDimension

SEED = (0.4, 0.1, 0.5)


def _seed_pose():
    x, y, z = SEED
    return msgs.PoseStamped(header=msgs.Header(frame_id="world"),
                            pose=msgs.Pose(position=msgs.Point(x=x, y=y, z=z), orientation=msgs.Quaternion(w=1.0)))


def _task(make_task, g):
    current = stages.CurrentState("current")
    g.setMonitoredStage(current)
    return make_task(current, stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())]), g)


def _generator(**props):
    g = stages.GenerateRandomPose("random pose")
    g.pose = _seed_pose()
    for k, v in props.items():
        setattr(g, k, v)
    return g


def _positions(g):
    # spawn order: the solutions all cost 0, so their stored order is the spawn order
    return np.array([[getattr(s.end.properties["target_pose"].pose.position, a) for a in "xyz"] for s in g.solutions])


def test_defaults():
    """Name, max_solutions 20, timeout 1.0, seed 0; PoseDimension values as MTC's enum."""
    g = stages.GenerateRandomPose()
    assert g.name == "generate random pose"
    assert g.max_solutions == 20
    assert g.timeout == 1.0
    assert g.seed == 0
    assert [d.name for d in PoseDimension] == ["X", "Y", "Z", "ROLL", "PITCH", "YAW"]
    assert int(PoseDimension.YAW) == 5
    g.set_max_solutions(5)
    assert g.max_solutions == 5
    with pytest.raises(TypeError):
        g.set_max_solutions(-1)


def test_without_sampler_nothing_is_computed(make_task):
    """No sample_dimension(): canCompute() stays False although a monitored solution is queued."""
    g = _generator()
    task = _task(make_task, g)
    assert not task.plan()
    assert len(g.solutions) == 0


def test_seed_first_then_uniform_samples(make_task):
    """The seed pose first, then max_solutions - 1 samples, x uniform within +-width/2, y, z unchanged."""
    g = _generator()
    g.sample_dimension(PoseDimension.X, 0.1)
    task = _task(make_task, g)
    assert task.plan()
    p = _positions(g)
    assert len(p) == 20
    np.testing.assert_allclose(p[0], SEED)
    assert np.all(np.abs(p[1:, 0] - SEED[0]) <= 0.05)
    assert np.ptp(p[1:, 0]) > 0.02
    np.testing.assert_allclose(p[:, 1:], np.tile(SEED[1:], (20, 1)))


@pytest.mark.parametrize("timeout, count", [(1e-9, 2), (0.0, 1)])
def test_any_positive_timeout_gives_one_sample(make_task, timeout, count):
    """As MTC, the time is measured after each sample: a timeout > 0 always allows one."""
    g = _generator(timeout=timeout)
    g.sample_dimension(PoseDimension.X, 0.1)
    assert _task(make_task, g).plan()
    assert len(g.solutions) == count


def test_each_dimension_keeps_its_width(make_task):
    """Fix of MTC's function-static distributions: X width 0.01 and Y width 0.4 are both honoured."""
    g = _generator()
    g.sample_dimension(PoseDimension.X, 0.01)
    g.sample_dimension(PoseDimension.Y, 0.4)
    task = _task(make_task, g)
    assert task.plan()
    p = _positions(g)[1:]
    assert np.all(np.abs(p[:, 0] - SEED[0]) <= 0.005)
    assert np.ptp(p[:, 1]) > 0.1


def test_normal_distribution_and_rotations(make_task):
    """A normal YAW sampler turns the pose about its z-axis only."""
    g = _generator(max_solutions=8)
    g.sample_dimension(PoseDimension.YAW, 0.5, "normal")
    task = _task(make_task, g)
    assert task.plan()
    assert len(g.solutions) == 8
    for s in g.solutions:
        T = msgs.pose_to_matrix(s.end.properties["target_pose"].pose)
        np.testing.assert_allclose(T[:3, 3], SEED, atol=1e-12)
        np.testing.assert_allclose(T[:3, 2], [0, 0, 1], atol=1e-12)


def test_local_frame_translation(make_task):
    """X/Y/Z translate along the seed pose's own axes (a yawed seed moves x along its rotated axis)."""
    g = _generator(max_solutions=5)
    seed = _seed_pose()
    seed.pose.orientation = msgs.Quaternion(z=math.sin(math.pi / 4), w=math.cos(math.pi / 4))  # 90 deg yaw
    g.pose = seed
    g.sample_dimension(PoseDimension.X, 0.2)
    task = _task(make_task, g)
    assert task.plan()
    p = _positions(g)
    np.testing.assert_allclose(p[:, 0], SEED[0], atol=1e-12)  # local x = world y
    assert np.ptp(p[:, 1]) > 0.01


def test_same_seed_same_poses(make_task):
    """Two runs with the same seed sample the same poses; another seed samples others."""

    def run(seed):
        g = _generator(seed=seed)
        g.sample_dimension(PoseDimension.Z, 0.3)
        task = _task(make_task, g)
        assert task.plan()
        return _positions(g)

    a, b, c = run(0), run(0), run(7)
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)


def test_callable_sampler(make_task):
    """A callable width is a custom sampler f(rng) -> deviation."""
    g = _generator(max_solutions=3)
    g.sample_dimension(PoseDimension.Z, lambda rng: 0.25)
    task = _task(make_task, g)
    assert task.plan()
    np.testing.assert_allclose(_positions(g)[1:, 2], SEED[2] + 0.25)


@pytest.mark.parametrize(
    "args, error, match",
    [
        ((7, 0.1), ValueError, "unknown pose dimension 7"),
        ((PoseDimension.X, -0.1), ValueError, "width must be finite and >= 0"),
        ((PoseDimension.X, 0.1, "cauchy"), ValueError, "unknown distribution 'cauchy'"),
        ((PoseDimension.X, "wide"), TypeError, "width must be a number or a callable"),
    ],
)
def test_bad_sampler_arguments(args, error, match):
    """Bad dimensions, widths and distributions are rejected at the call."""
    with pytest.raises(error, match=match):
        stages.GenerateRandomPose().sample_dimension(*args)
