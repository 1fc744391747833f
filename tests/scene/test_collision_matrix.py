"""Tests of mtc.scene.collision_matrix: MoveIt's allowed collision matrix."""

from __future__ import annotations

import pytest

from mtc import msgs
from mtc.scene.collision_matrix import AllowedCollisionMatrix


def test_initial_pairs_and_default_entries():
    """Pairs from the SRDF are allowed both ways; ('link', '*') is a default entry."""
    acm = AllowedCollisionMatrix([("a", "b"), ("c", "*")])
    assert acm.get_entry("a", "b") and acm.get_entry("b", "a")
    assert not acm.get_entry("a", "d")
    assert acm.get_entry("c", "anything") and acm.get_entry("anything", "c")
    assert acm.get_default_entry("c") and not acm.get_default_entry("a")
    assert acm.has_entry("b", "a") and not acm.has_entry("c", "x")


def test_set_entry_forms():
    """set_entry(a, b, allowed), with lists on either side, and set_entry(a, allowed) for all of a's entries."""
    acm = AllowedCollisionMatrix()
    acm.set_entry(["a", "b"], ["c", "d"], True)
    assert all(acm.get_entry(x, y) for x in "ab" for y in "cd")
    assert not acm.get_entry("a", "b")
    acm.set_entry("a", False)
    assert not acm.get_entry("a", "c") and not acm.get_entry("a", "d")
    assert acm.get_entry("b", "c")
    assert acm.has_entry("a", "c")  # set to False, not removed
    acm.set_entry("a", "c", allowed=True)
    assert acm.get_entry("c", "a")
    acm.set_entry("x", allowed=True)  # no entries of x: nothing to change
    assert not acm.get_entry("x", "a")


def test_explicit_entry_wins_over_default():
    """A pair's own entry decides; without one, either body's default entry allows it."""
    acm = AllowedCollisionMatrix()
    acm.set_default_entry("obj", True)
    assert acm.get_entry("obj", "link") and acm.get_entry("link", "obj")
    acm.set_entry("obj", "hand", False)
    assert not acm.get_entry("obj", "hand")
    acm.set_default_entry("obj", False)
    assert not acm.get_entry("obj", "link")


def test_remove_entry():
    """remove_entry drops a pair, or every entry and the default of a name."""
    acm = AllowedCollisionMatrix([("a", "b"), ("a", "c"), ("a", "*")])
    acm.remove_entry("a", "b")
    assert not acm.has_entry("a", "b") and acm.has_entry("a", "c")
    acm.remove_entry("a")
    assert not acm.has_entry("a", "c") and not acm.get_default_entry("a")
    assert not acm.get_entry("a", "zzz")


def test_copy_is_independent():
    """A copy's edits do not reach the original, nor the original's the copy."""
    acm = AllowedCollisionMatrix([("a", "b")])
    other = acm.copy()
    other.set_entry("a", "b", False)
    other.set_default_entry("z", True)
    assert acm.get_entry("a", "b") and not acm.get_default_entry("z")
    acm.set_entry("c", "d", True)
    assert not other.get_entry("c", "d")


def test_version_bumps_on_every_change():
    """Every edit bumps version (collision set-ups use it to tell they are stale)."""
    acm = AllowedCollisionMatrix()
    versions = [acm.version]
    acm.set_entry("a", "b", True)
    versions.append(acm.version)
    acm.set_default_entry("a", True)
    versions.append(acm.version)
    acm.remove_entry("a", "b")
    versions.append(acm.version)
    assert versions == sorted(set(versions))
    assert acm.get_entry("a", "q")  # reads do not bump
    assert acm.version == versions[-1]


def test_bad_arguments():
    """allowed must be a bool (or a number, read as one, as moveit_py's pybind11 caster reads
    it); names must be strings or lists of strings."""
    acm = AllowedCollisionMatrix()
    acm.set_entry("a", "b", 1)
    assert acm.get_entry("a", "b") is True
    acm.set_entry("a", 0)
    assert acm.get_entry("a", "b") is False
    acm.set_default_entry("c", 1)
    assert acm.get_default_entry("c") is True
    acm = AllowedCollisionMatrix()
    with pytest.raises(TypeError, match="allowed must be True or False"):
        acm.set_entry("a", "b", "yes")
    with pytest.raises(TypeError, match="allowed must be True or False"):
        acm.set_entry("a", "b")
    with pytest.raises(TypeError, match="allowed must be True or False"):
        acm.set_default_entry("a", None)
    with pytest.raises(TypeError, match="name or a list of names"):
        acm.set_entry("a", [1, 2], True)
    with pytest.raises(TypeError, match="name or a list of names"):
        acm.set_entry(3, "b", True)
    assert acm.entry_names == []


def test_to_msg():
    """to_msg gives a symmetric square matrix over the entry names plus the default entries."""
    acm = AllowedCollisionMatrix([("a", "b"), ("c", "*")])
    acm.set_entry("b", "d", False)
    msg = acm.to_msg()
    assert isinstance(msg, msgs.AllowedCollisionMatrix)
    assert msg.entry_names == ["a", "b", "c", "d"]
    matrix = [e.enabled for e in msg.entry_values]
    assert [len(row) for row in matrix] == [4, 4, 4, 4]
    index = {n: i for i, n in enumerate(msg.entry_names)}
    assert matrix[index["a"]][index["b"]] and matrix[index["b"]][index["a"]]
    assert not matrix[index["b"]][index["d"]]
    assert matrix[index["a"]][index["c"]]  # through c's default entry
    assert all(not matrix[i][i] for i in range(4))
    assert all(matrix[i][j] == matrix[j][i] for i in range(4) for j in range(4))
    assert msg.default_entry_names == ["c"] and msg.default_entry_values == [True]


def test_panda_scene_acm_holds_the_srdf_pairs(panda):
    """The scene's ACM starts with every disabled pair of the SRDF allowed, and nothing else between links."""
    from mtc.scene.planning_scene import PlanningScene

    acm = PlanningScene(panda).allowed_collision_matrix
    disabled = {frozenset(p) for p in panda.disabled_collision_pairs}
    links = panda.links_with_collision_geometry
    for i, a in enumerate(links):
        for b in links[i + 1 :]:
            assert acm.get_entry(a, b) == (frozenset((a, b)) in disabled), (a, b)


def test_token_tells_equal_content():
    """Copies share the token until either changes; every edit renews it; reads do not."""
    acm = AllowedCollisionMatrix([("a", "b")])
    other = acm.copy()
    assert other.token is acm.token
    acm.get_entry("a", "b")
    assert other.token is acm.token
    token = acm.token
    other.set_entry("a", "c", True)
    assert other.token is not token and acm.token is token
    acm.set_default_entry("z", False)
    assert acm.token is not token
    token = acm.token
    acm.remove_entry("a", "b")
    assert acm.token is not token


def test_a_forbidding_default_wins_over_an_allowing_one():
    """With default entries for both bodies and no explicit entry, a forbidding one wins (MoveIt 1)."""
    acm = AllowedCollisionMatrix()
    acm.set_default_entry("a", True)
    assert acm.get_entry("a", "b")
    acm.set_default_entry("b", False)
    assert not acm.get_entry("a", "b")
    acm.set_entry("a", "b", True)
    assert acm.get_entry("a", "b")
