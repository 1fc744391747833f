"""Tests of stages.ModifyPlanningScene: edits forward, their inversion backward, failures."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from mtc import core, msgs, stages

FAR = (0.6, 0.4, 0.8)  # a place no arm link reaches at 'ready'


def forward_task(make_task, *stages_):
    return make_task(stages.CurrentState(), *stages_)


def backward_task(make_task, scene, *stages_):
    # propagators before a generator run backward
    return make_task(*stages_, stages.FixedState("end", scene))


def end_scene(stage):
    return stage.solutions[0].end.scene


def start_scene(stage):
    return stage.solutions[0].start.scene


def test_defaults():
    """Name 'modify planning scene', no edits, and a zero cost term."""
    s = stages.ModifyPlanningScene()
    assert s.name == "modify planning scene"
    assert isinstance(s.costTerm(), core.Constant) and s.costTerm().cost == 0.0


def test_add_object_forward(make_task, sphere):
    """addObject adds the object to a diff of the incoming scene; the start scene is untouched."""
    m = stages.ModifyPlanningScene("add")
    m.addObject(sphere("ball", FAR))
    task = forward_task(make_task, m)
    assert task.plan()
    assert end_scene(m).world_object_names == ["ball"]
    assert start_scene(m).world_object_names == []
    assert end_scene(m).parent is start_scene(m)
    assert m.solutions[0].cost == 0.0


def test_add_object_keeps_a_copy_of_the_message(make_task, sphere):
    """Changing the message after addObject does not change what is added."""
    m = stages.ModifyPlanningScene()
    obj = sphere("ball", FAR)
    m.addObject(obj)
    obj.id = "renamed"
    task = forward_task(make_task, m)
    assert task.plan()
    assert end_scene(m).world_object_names == ["ball"]


def test_add_object_with_other_operation_is_ignored(make_task, sphere, caplog):
    """addObject only takes ADD objects; others are ignored with an error log (as MTC)."""
    m = stages.ModifyPlanningScene()
    obj = sphere("ball", FAR)
    obj.operation = msgs.CollisionObject.MOVE
    m.addObject(obj)
    assert "operation not set to ADD" in caplog.text
    task = forward_task(make_task, m)
    assert task.plan()
    assert end_scene(m).world_object_names == []


def test_remove_and_move_object_forward(make_task, ready_scene, sphere):
    """removeObject and moveObject change the incoming scene's objects."""
    ready_scene.apply_collision_object(sphere("a", FAR))
    ready_scene.apply_collision_object(sphere("b", (0.6, -0.4, 0.8)))
    m = stages.ModifyPlanningScene()
    m.removeObject("a")
    moved = msgs.CollisionObject(
        id="b", header=msgs.Header(frame_id="world"), operation=msgs.CollisionObject.MOVE,
        pose=msgs.Pose(position=msgs.Point(x=0.7, y=-0.4, z=0.9), orientation=msgs.Quaternion(w=1.0)),
    )
    m.moveObject(moved)
    task = make_task(stages.FixedState("start", ready_scene), m)
    assert task.plan()
    scene = end_scene(m)
    assert scene.world_object_names == ["b"]
    assert scene.get_world_object("b").pose[:3, 3].tolist() == pytest.approx([0.7, -0.4, 0.9])


def test_attach_and_detach_forward(make_task, ready_scene, sphere):
    """attachObject attaches a world object to a link; detachObject puts it back into the world."""
    ready_scene.apply_collision_object(sphere("ball", (0.3, 0.0, 0.45), radius=0.02))
    attach = stages.ModifyPlanningScene("attach")
    attach.attachObject("ball", "panda_hand")
    attach.allowCollisions("ball", ["panda_hand", "panda_leftfinger", "panda_rightfinger"], True)
    detach = stages.ModifyPlanningScene("detach")
    detach.detachObject("ball", "panda_hand")
    task = make_task(stages.FixedState("start", ready_scene), attach, detach)
    assert task.plan()
    attached = end_scene(attach)
    assert attached.attached_object_names == ["ball"]
    assert attached.get_attached_object("ball").link == "panda_hand"
    assert attached.world_object_names == []
    detached = end_scene(detach)
    assert detached.attached_object_names == [] and detached.world_object_names == ["ball"]


def test_attach_objects_keeps_each_calls_flag(make_task, ready_scene, sphere):
    """attachObjects per call: a later detach call for the same link is not turned into an attach
    (MTC kept the first flag per link, Appendix A #10; mtc fixes it)."""
    ready_scene.apply_collision_object(sphere("a", FAR, radius=0.02))
    ready_scene.attach_object("a", "panda_hand")
    ready_scene.apply_collision_object(sphere("b", (0.6, -0.4, 0.8), radius=0.02))
    m = stages.ModifyPlanningScene()
    m.attachObjects(["b"], "panda_hand", True)
    m.detachObjects("a", "panda_hand")
    task = make_task(stages.FixedState("start", ready_scene), m)
    assert task.plan()
    assert end_scene(m).attached_object_names == ["b"]
    assert end_scene(m).world_object_names == ["a"]


def test_allow_collisions_pairs_and_all(make_task):
    """allowCollisions(first, second) sets pair entries; allowCollisions(name) allows all of name."""
    m = stages.ModifyPlanningScene()
    m.allowCollisions(["panda_link1", "panda_link2"], "panda_hand", True)
    m.allowCollisions("panda_link5")
    task = forward_task(make_task, m)
    assert task.plan()
    acm = end_scene(m).allowed_collision_matrix
    assert acm.get_entry("panda_link1", "panda_hand") and acm.get_entry("panda_link2", "panda_hand")
    assert acm.get_default_entry("panda_link5")
    assert not start_scene(m).allowed_collision_matrix.get_entry("panda_link1", "panda_hand")


def test_allow_collisions_by_mtc_keywords(make_task):
    """MTC's binding names its arguments: allowCollisions(object=..., enable_collision=...) and
    allowCollisions(first=..., second=..., enable_collision=...); object= with first/second, or
    no names at all, is a TypeError that changes nothing."""
    m = stages.ModifyPlanningScene()
    m.allowCollisions(object="panda_link5", enable_collision=True)
    m.allowCollisions(first="panda_link1", second=["panda_hand"], enable_collision=True)
    for bad in (lambda: m.allowCollisions(), lambda: m.allowCollisions("a", object="b"),
                lambda: m.allowCollisions(second="b", object="c")):
        with pytest.raises(TypeError, match="allowCollisions"):
            bad()
    task = forward_task(make_task, m)
    assert task.plan()
    acm = end_scene(m).allowed_collision_matrix
    assert acm.get_default_entry("panda_link5") and acm.get_entry("panda_link1", "panda_hand")
    assert not acm.get_default_entry("panda_link1") and not acm.get_entry("panda_link2", "panda_hand")
    assert not any(acm.get_default_entry(name) for name in ("a", "b", "c"))  # the refused calls


def test_allow_collisions_with_an_empty_list_allows_all(make_task):
    """As MTC: an empty second list means every collision of the first names, as no list does
    (the default entry and all explicit entries)."""
    m = stages.ModifyPlanningScene()
    m.allowCollisions("panda_link1", "panda_hand", False)
    m.allowCollisions(["panda_link1", "panda_link5"], [], True)
    task = forward_task(make_task, m)
    assert task.plan()
    acm = end_scene(m).allowed_collision_matrix
    assert acm.get_default_entry("panda_link1") and acm.get_default_entry("panda_link5")
    assert acm.get_entry("panda_link1", "panda_hand")


def test_allow_collisions_with_group(make_task, panda):
    """allowCollisions(name, JointModelGroup, allow) allows the group's links with geometry."""
    m = stages.ModifyPlanningScene()
    m.allowCollisions("thing", panda.get_joint_model_group("hand"), True)
    task = forward_task(make_task, m)
    assert task.plan()
    acm = end_scene(m).allowed_collision_matrix
    assert acm.get_entry("thing", "panda_leftfinger") and acm.get_entry("thing", "panda_hand")


@pytest.mark.parametrize("bad", [None, 1, 1.5, {}])
def test_invalid_names_raise(bad):
    """Invalid names raise at the call (a RuntimeError as MTC's binding, and a TypeError)."""
    m = stages.ModifyPlanningScene()
    with pytest.raises(RuntimeError):
        m.attachObjects(bad, "panda_hand")
    with pytest.raises(TypeError):
        m.allowCollisions(bad, "panda_hand")
    with pytest.raises(RuntimeError):
        m.allowCollisions("a", bad if bad is not None else 3)
    with pytest.raises(RuntimeError):
        m.removeObject(bad)


def test_add_object_backward_removes_it(make_task, ready_scene, sphere):
    """Backward, an added object is removed from the start scene."""
    ready_scene.apply_collision_object(sphere("ball", FAR))
    m = stages.ModifyPlanningScene()
    m.addObject(sphere("ball", FAR))
    task = backward_task(make_task, ready_scene, m)
    assert task.plan()
    assert start_scene(m).world_object_names == []
    assert end_scene(m).world_object_names == ["ball"]


def test_attach_and_allow_backward_are_inverted(make_task, ready_scene, sphere):
    """Backward, attach becomes detach and allowed collisions become forbidden."""
    ready_scene.apply_collision_object(sphere("ball", (0.3, 0.0, 0.45), radius=0.02))
    ready_scene.attach_object("ball", "panda_hand")
    ready_scene.allowed_collision_matrix.set_entry("ball", "panda_hand", True)
    m = stages.ModifyPlanningScene()
    m.attachObject("ball", "panda_hand")
    m.allowCollisions("ball", "panda_hand", True)
    task = backward_task(make_task, ready_scene, m)
    assert task.plan()
    start = start_scene(m)
    assert start.attached_object_names == [] and start.world_object_names == ["ball"]
    assert not start.allowed_collision_matrix.get_entry("ball", "panda_hand")


@pytest.mark.parametrize(
    ("edit", "message"),
    [("remove", "cannot apply removeObject() backwards"), ("move", "cannot apply moveObject() backwards")],
)
def test_remove_and_move_cannot_run_backward(make_task, ready_scene, sphere, edit, message):
    """Removing or moving an object cannot be inverted: a failure with MTC's text."""
    ready_scene.apply_collision_object(sphere("ball", FAR))
    m = stages.ModifyPlanningScene()
    if edit == "remove":
        m.removeObject("ball")
    else:
        m.moveObject(msgs.CollisionObject(id="ball", operation=msgs.CollisionObject.MOVE,
                                          pose=msgs.Pose(orientation=msgs.Quaternion(w=1.0))))
    task = backward_task(make_task, ready_scene, m)
    assert not task.plan()
    assert m.numFailures() == 1
    assert m.failures[0].comment == message


def test_unknown_object_is_logged_and_skipped(make_task, caplog):
    """As MTC (which ignores MoveIt's result there): attaching an object that does not exist is
    an error in the log naming it, and the stage still succeeds."""
    m = stages.ModifyPlanningScene()
    m.attachObject("ghost", "panda_hand")
    task = forward_task(make_task, m)
    with caplog.at_level("ERROR", logger="mtc.stages.modify_planning_scene"):
        assert task.plan()
    assert "'ghost'" in caplog.text and "panda_hand" in caplog.text
    assert f"{m.name}: cannot attach object 'ghost'" in caplog.text  # names the stage that skipped it
    assert m.numFailures() == 0 and m.solutions[0].end.scene.attached_object_names == []


def test_resulting_collision_is_a_failure(make_task, box):
    """A scene left in collision fails with '<a> colliding with <b>'."""
    m = stages.ModifyPlanningScene()
    m.addObject(box("wall", (0.3, 0.0, 0.5), size=(0.2, 0.2, 0.2)))
    task = forward_task(make_task, m)
    assert not task.plan()
    comment = m.failures[0].comment
    assert " colliding with " in comment and "wall" in comment
    # as MTC, collision markers: a contact of every colliding pair
    contacts = [mk for mk in m.failures[0].markers if mk["type"] == "contact"]
    assert contacts and all("wall" in mk["name"] and mk["color"] == "red" for mk in contacts)


def test_failures_are_only_counted_without_introspection(make_task, box):
    """Without introspection a failure is counted but not stored."""
    m = stages.ModifyPlanningScene()
    m.addObject(box("wall", (0.3, 0.0, 0.5), size=(0.2, 0.2, 0.2)))
    task = make_task(stages.CurrentState(), m, introspection=False)
    assert not task.plan()
    assert m.numFailures() == 1 and m.failures == []


def test_callback_sees_scene_and_properties(make_task, sphere):
    """setCallback's function runs last on the modified scene with the stage's properties."""
    seen = {}

    def callback(scene, properties):
        seen["objects"] = list(scene.world_object_names)
        seen["has_timeout"] = "timeout" in properties
        scene.apply_collision_object(sphere("from callback", (0.6, -0.4, 0.8)))

    m = stages.ModifyPlanningScene()
    m.addObject(sphere("ball", FAR))
    m.setCallback(callback)
    task = forward_task(make_task, m)
    assert task.plan()
    assert seen == {"objects": ["ball"], "has_timeout": True}
    assert sorted(end_scene(m).world_object_names) == ["ball", "from callback"]


def test_callback_exception_is_a_failure(make_task):
    """An exception in the callback becomes the failure comment."""

    def callback(scene, properties):
        raise ValueError("no table in sight")

    m = stages.ModifyPlanningScene()
    m.setCallback(callback)
    task = forward_task(make_task, m)
    assert not task.plan()
    assert m.failures[0].comment == "no table in sight"


def test_seed_add_sphere_and_attach(make_task):
    """The seed's snippet: add a sphere with one stage, attach it to panda_hand with the next."""
    obj = msgs.CollisionObject()
    obj.header.frame_id = "world"
    obj.id = "sphere"
    sphere_shape = msgs.SolidPrimitive()
    sphere_shape.type = msgs.SolidPrimitive.SPHERE
    sphere_shape.dimensions = [0.02]
    pose = msgs.PoseStamped()
    pose.header.frame_id = "world"
    pose.pose.position.x, pose.pose.position.z = 0.307, 0.285
    pose.pose.orientation.w = 1.0
    obj.primitives.append(sphere_shape)
    obj.primitive_poses.append(pose.pose)
    obj.operation = msgs.CollisionObject.ADD
    modify = stages.ModifyPlanningScene("add sphere")
    modify.addObject(obj)
    attach = stages.ModifyPlanningScene("attach sphere")
    attach.attachObject("sphere", "panda_hand")
    task = make_task(stages.CurrentState(), modify, attach)
    assert task.plan()
    scene = end_scene(attach)
    assert scene.attached_object_names == ["sphere"]
    shape = scene.get_frame_transform("sphere") @ scene.get_attached_object("sphere").object.shape_poses[0]
    assert shape[:3, 3] == pytest.approx([0.307, 0.0, 0.285])


def test_removing_an_absent_object_is_logged_and_skipped(make_task, ready_scene, sphere, caplog):
    """MTC ignores MoveIt's result of a collision-object edit: removing or moving an object the
    scene does not have logs an error and the stage still succeeds (a defensive clean-up stage
    works); the other edits of the stage are applied."""
    m = stages.ModifyPlanningScene()
    m.removeObject("old_box")
    m.moveObject(msgs.CollisionObject(id="ghost", header=msgs.Header(frame_id="world"),
                                      operation=msgs.CollisionObject.MOVE,
                                      pose=msgs.Pose(orientation=msgs.Quaternion(w=1.0))))
    m.addObject(sphere("ball", FAR))
    task = make_task(stages.FixedState("start", ready_scene), m)
    assert task.plan()
    assert end_scene(m).world_object_names == ["ball"]
    assert "old_box" in caplog.text and "ghost" in caplog.text
    assert f"{m.name}: cannot apply collision object 'old_box'" in caplog.text


def test_a_skipped_edit_is_reported_on_stderr_without_logging_set_up():
    """As MoveIt prints its errors to the console: a misspelled object to attach is skipped (the
    stage succeeds, as in MTC), and the error reaches stderr although nothing set up logging."""
    script = textwrap.dedent('''
        from mtc import core, stages
        task = core.Task()
        task.add(stages.CurrentState("current"))
        attach = stages.ModifyPlanningScene("attach")
        attach.attachObject("boxx", "panda_hand")
        task.add(attach)
        assert task.plan()
    ''')
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "cannot attach object 'boxx' to link 'panda_hand'" in run.stderr
