"""Tests of stages.FixedCartesianPoses: one state per configured pose and monitored solution."""

from __future__ import annotations

import pytest

from mtc import core, msgs, stages


def _pose(frame, x):
    return msgs.PoseStamped(header=msgs.Header(frame_id=frame),
                            pose=msgs.Pose(position=msgs.Point(x=x), orientation=msgs.Quaternion(w=1.0)))


class TaggedCurrentState(stages.CurrentState):
    """CurrentState whose state carries a property "tag"."""

    def compute(self):
        super().compute()
        self.solutions[0].end.properties.set("tag", "hello")


def _task(make_task, g, introspection=True):
    current = TaggedCurrentState("current")
    g.setMonitoredStage(current)
    return make_task(current, stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())]), g,
                     introspection=introspection)


def test_defaults():
    """Name 'generate poses', no poses, cost Constant(0); poses must be PoseStamped."""
    g = stages.FixedCartesianPoses()
    assert g.name == "generate poses"
    assert g.poses == []
    assert isinstance(g.costTerm(), core.Constant)
    with pytest.raises(TypeError, match=r"poses\[0\] must be a msgs.PoseStamped"):
        g.poses = ["world"]
    g.addPose(_pose("world", 0.1))
    g.addPose(_pose("", 0.2))
    assert [p.pose.position.x for p in g.poses] == [0.1, 0.2]


def test_one_state_per_pose(make_task):
    """Every pose becomes a target_pose (empty frame -> planning frame); nothing is forwarded."""
    g = stages.FixedCartesianPoses("poses")
    g.poses = [_pose("world", 0.1), _pose("", 0.2), _pose("panda_link8", 0.3)]
    g.setForwardedProperties(["tag"])
    task = _task(make_task, g)
    assert task.plan()
    targets = sorted((s.end.properties["target_pose"] for s in g.solutions), key=lambda t: t.pose.position.x)
    assert [(t.header.frame_id, t.pose.position.x) for t in targets] == [
        ("world", 0.1), ("world", 0.2), ("panda_link8", 0.3)]
    assert all(s.cost == 0.0 for s in g.solutions)
    assert all("tag" not in s.end.properties for s in g.solutions)


@pytest.mark.parametrize("introspection", [True, False])
def test_unknown_frame_skips_that_pose(make_task, introspection):
    """A pose in an unknown frame fails ("Unknown frame: 'X'", stored with introspection); the others spawn."""
    g = stages.FixedCartesianPoses("poses")
    g.poses = [_pose("nowhere", 0.1), _pose("world", 0.2)]
    task = _task(make_task, g, introspection)
    assert task.plan()
    assert len(g.solutions) == 1
    assert [f.comment for f in g.failures] == (["Unknown frame: 'nowhere'"] if introspection else [])


def test_add_pose_appends_a_copy_and_refuses_a_non_pose_whole():
    """addPose keeps a copy (editing the message afterwards changes nothing), refuses anything
    but a PoseStamped without touching the list, and appends in place (800 poses, each one
    copy, not the whole list copied again per call)."""
    stage = stages.FixedCartesianPoses("poses")
    pose = msgs.PoseStamped(header=msgs.Header(frame_id="world"))
    for i in range(800):
        pose.pose.position.x = float(i)
        stage.addPose(pose)
    poses = stage.properties.get("poses")
    assert len(poses) == 800 and [p.pose.position.x for p in poses[:3]] == [0.0, 1.0, 2.0]
    with pytest.raises(TypeError, match=r"^poses\[800\] must be a msgs.PoseStamped"):  # (where it would go)
        stage.addPose("world")
    assert len(stage.properties.get("poses")) == 800
