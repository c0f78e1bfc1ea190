import numpy as np
import pytest

from builders import chain_skeleton
from rigedit.model import Skeleton, topological_order
from rigedit.io.skeleton_json import skeleton_from_heads


def test_topological_order_puts_parents_first():
    order = topological_order(["c", "a", "b"], ["b", None, "a"])
    assert [["c", "a", "b"][i] for i in order] == ["a", "b", "c"]


@pytest.mark.parametrize("names,parents,msg", [
    (["a", "a"], [None, "a"], "duplicate joint name 'a'"),
    (["a", "b"], [None, "zz"], "joint 'b' has unknown parent 'zz'"),
    (["a", "b", "c"], [None, "c", "b"], "cycle"),
    (["a"], ["a"], "joint 'a' is its own parent"),
])
def test_bad_hierarchies_name_the_joint(names, parents, msg):
    with pytest.raises(ValueError, match=msg):
        topological_order(names, parents)


def test_skeleton_rejects_child_before_parent_and_bad_shapes():
    with pytest.raises(ValueError, match="joint 'a'"):
        Skeleton(["a", "b"], [1, -1], np.zeros((2, 3)))
    with pytest.raises(ValueError, match="rest_translation"):
        Skeleton(["a", "b"], [-1, 0], np.zeros((3, 3)))
    with pytest.raises(ValueError, match="duplicate joint name 'a'"):
        Skeleton(["a", "a"], [-1, 0], np.zeros((2, 3)))


def test_bind_matrices_are_rest_fk_and_inverse():
    sk = chain_skeleton(4)
    assert np.allclose(sk.bind_matrices[:, :3, 3], [[0, 0, 0], [0, 1, 0], [0, 2, 0], [0, 3, 0]])
    assert np.allclose(sk.bind_matrices @ sk.inverse_bind_matrices, np.eye(4))


def test_subtree_and_levels():
    sk = skeleton_from_heads(["r", "a", "b", "a2", "b2"], [None, "r", "r", "a", "b"],
                             np.arange(15.0).reshape(5, 3))
    a = sk.joint_index("a")
    assert set(sk.names[i] for i in sk.subtree(a)) == {"a", "a2"}
    assert [len(level) for level in sk.levels] == [1, 2, 2]
    with pytest.raises(KeyError, match="unknown joint 'nope'"):
        sk.joint_index("nope")


def test_bone_segments_use_tails_and_skip_non_deforming():
    sk = skeleton_from_heads(["root", "hip", "leg"], [None, "root", "hip"],
                             [[0, 0, 0], [0, 1, 0], [0, 2, 0]],
                             tails=[[0, 0, 0], [np.nan] * 3, [0, 3, 0]],
                             deform=[False, True, True])
    starts, ends, owners = sk.bone_segments()
    assert [sk.names[o] for o in owners] == ["hip", "leg"]
    assert np.allclose(ends, [[0, 2, 0], [0, 3, 0]])
