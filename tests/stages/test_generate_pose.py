"""Tests of stages.GeneratePose: spawns the monitored stage's end scenes with a target_pose."""

from __future__ import annotations

import pytest

from mtc import core, msgs, stages


def _pose(frame: str, z: float = 0.0) -> msgs.PoseStamped:
    return msgs.PoseStamped(
        header=msgs.Header(frame_id=frame),
        pose=msgs.Pose(position=msgs.Point(z=z), orientation=msgs.Quaternion(w=1.0)),
    )


def _task(make_task, generator, introspection=True):
    """The seed's generate_pose.py: CurrentState -> Connect -> generator (monitoring 'current state')."""
    current = stages.CurrentState("current state")
    connect = stages.Connect("connect", [("panda_arm", core.JointInterpolationPlanner())])
    generator.setMonitoredStage(current)
    return make_task(current, connect, generator, introspection=introspection)


def test_defaults():
    """Name 'generate pose', cost Constant(0), pose undefined."""
    g = stages.GeneratePose()
    assert g.name == "generate pose"
    assert isinstance(g.costTerm(), core.Constant) and g.costTerm().cost == 0.0
    assert g.properties.get("pose", None) is None
    with pytest.raises(TypeError):
        g.pose = 3
    g.pose = "panda_link8"  # as MTC's message casters: a frame name is the identity pose there
    assert g.pose.header.frame_id == "panda_link8" and g.pose.pose.orientation.w == 1.0
    g.setPose(_pose("panda_link8"))
    assert g.pose.header.frame_id == "panda_link8"


def test_init_errors(make_task):
    """No monitored stage and no pose: both reported at init."""
    g = stages.GeneratePose("gen")
    task = make_task(stages.CurrentState(), stages.Connect("c", [("panda_arm", core.JointInterpolationPlanner())]), g)
    with pytest.raises(core.InitStageError) as e:
        task.init()
    assert "gen: no monitored stage defined" in str(e.value)
    assert "gen: Property 'pose': undefined" in str(e.value)


def test_seed_generate_pose(make_task):
    """The seed's snippet: one solution, whose state carries target_pose in panda_link8."""
    g = stages.GeneratePose("generate pose")
    g.pose = _pose("panda_link8")
    task = _task(make_task, g)
    assert task.plan()
    assert task.numSolutions() == 1
    (solution,) = g.solutions
    target = solution.end.properties["target_pose"]
    assert target.header.frame_id == "panda_link8"
    assert solution.cost == 0.0
    assert solution.end.scene is not task["current state"].solutions[0].end.scene  # a diff
    assert any(m["name"] == "pose frame" for m in solution.markers)


def test_empty_frame_means_planning_frame(make_task):
    """A pose without frame is taken in the planning frame ('world')."""
    g = stages.GeneratePose("gen")
    g.pose = _pose("", z=0.5)
    task = _task(make_task, g)
    assert task.plan()
    target = g.solutions[0].end.properties["target_pose"]
    assert target.header.frame_id == "world"
    assert target.pose.position.z == 0.5


@pytest.mark.parametrize("introspection", [True, False])
def test_unknown_frame(make_task, introspection):
    """Unknown frame: a failure "Unknown frame: 'X'" when failures are stored, else only a warning."""
    g = stages.GeneratePose("gen")
    g.pose = _pose("nowhere")
    task = _task(make_task, g, introspection=introspection)
    assert not task.plan()
    assert len(g.solutions) == 0
    if introspection:
        assert [f.comment for f in g.failures] == ["Unknown frame: 'nowhere'"]
    else:
        assert g.failures == []


def test_forwards_properties_of_the_monitored_state(make_task):
    """forwarded_properties are copied from the monitored solution's end state."""

    class Tagged(stages.CurrentState):
        def compute(self):
            super().compute()
            self.solutions[0].end.properties.set("tag", "hello")

    current = Tagged("current state")
    g = stages.GeneratePose("gen")
    g.pose = _pose("world")
    g.setMonitoredStage(current)
    g.setForwardedProperties(["tag"])
    task = make_task(current, stages.Connect("c", [("panda_arm", core.JointInterpolationPlanner())]), g)
    assert task.plan()
    assert g.solutions[0].end.properties["tag"] == "hello"


def test_one_state_per_monitored_solution_cheapest_first(make_task, ready_scene):
    """Each monitored solution yields one state; queued solutions are handled cheapest first."""
    alternatives = core.Alternatives("starts")
    scenes = {}
    for cost in (2.0, 1.0):
        scenes[cost] = ready_scene.diff()
        fixed = stages.FixedState(f"fixed {cost}", scenes[cost])
        fixed.setCostTerm(core.Constant(cost))
        alternatives.add(fixed)
    g = stages.GeneratePose("gen")
    g.pose = _pose("world")
    g.setMonitoredStage(alternatives)
    order = []
    g.addSolutionCallback(lambda s: order.append(s.end.scene.parent))
    task = make_task(alternatives, stages.Connect("c", [("panda_arm", core.JointInterpolationPlanner())]), g)
    # both starts arrive before the generator computes: the cheaper one is handled first
    task.init()
    alternatives.compute()
    g.compute()
    g.compute()
    assert order == [scenes[1.0], scenes[2.0]]
