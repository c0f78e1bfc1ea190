"""The skeleton: a joint tree stored parent-before-child with its rest (bind) pose."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .transforms import compose_trs, normalize_quats

__all__ = ["Skeleton", "topological_order", "subtree_of"]


def topological_order(names, parent_names):
    """Order joints so every parent comes before its children.

    Parameters
    ----------
    names : sequence of str
    parent_names : sequence of (str or None)
        The parent of each joint by name; ``None`` (or "") for a root.

    Returns
    -------
    order : list[int]
        Indices into ``names`` in parent-before-child order (siblings keep their input order).

    Raises
    ------
    ValueError
        On a duplicate name, an unknown parent or a cycle, naming the joint.
    """
    names = list(names)
    index = {}
    for i, name in enumerate(names):
        if not isinstance(name, str) or not name:
            raise ValueError(f"expected a non-empty joint name, got {name!r} at index {i}")
        if name in index:
            raise ValueError(f"duplicate joint name {name!r}")
        index[name] = i
    children = {i: [] for i in range(len(names))}
    roots = []
    for i, parent in enumerate(parent_names):
        if parent in (None, ""):
            roots.append(i)
        elif parent not in index:
            raise ValueError(f"joint {names[i]!r} has unknown parent {parent!r}")
        elif parent == names[i]:
            raise ValueError(f"joint {names[i]!r} is its own parent (cycle)")
        else:
            children[index[parent]].append(i)
    order = []
    stack = list(reversed(roots))
    while stack:
        i = stack.pop()
        order.append(i)
        stack.extend(reversed(children[i]))
    if len(order) != len(names):
        stuck = sorted(set(range(len(names))) - set(order))
        raise ValueError(f"joint {names[stuck[0]]!r} is in a cycle of parents")
    return order


@dataclass(eq=False)
class Skeleton:
    """A joint hierarchy with its rest pose.

    Parameters
    ----------
    names : list[str]
        Joint names, parent-before-child.
    parents : (J,) int
        Parent index of each joint, ``-1`` for a root; ``parents[j] < j``.
    rest_translation : (J, 3) float64
        Local (parent-space) translation of each joint at rest.
    rest_rotation : (J, 4) float64, optional
        Local rest rotation, quaternions (x, y, z, w); identity when omitted.
    rest_scale : (J, 3) float64, optional
        Local rest scale; ones when omitted.
    bind_matrices : (J, 4, 4) float64, optional
        Model-space joint matrices the mesh was bound at; the forward kinematics of the rest
        pose when omitted (glTF files may bind elsewhere than their rest pose).
    tails : (J, 3) float64, optional
        Model-space end point of each joint's bone at bind time, where a format gives one
        (NaN rows where it does not); used for leaf bones.
    deform : (J,) bool, optional
        Which joints may receive skin weights; all when omitted. A root that only carries the
        character (a ground-level ``root`` or a zero-length ``_rootJoint``) is not a deformer.
    """

    names: list
    parents: np.ndarray
    rest_translation: np.ndarray
    rest_rotation: np.ndarray = None
    rest_scale: np.ndarray = None
    bind_matrices: np.ndarray = None
    tails: np.ndarray = None
    deform: np.ndarray = None
    index: dict = field(init=False, repr=False)
    levels: list = field(init=False, repr=False)

    def __post_init__(self):
        self.names = [str(n) for n in self.names]
        n = len(self.names)
        if n == 0:
            raise ValueError("expected at least one joint, got an empty skeleton")
        self.parents = np.asarray(self.parents, dtype=np.int64).reshape(-1)
        if self.parents.shape != (n,):
            raise ValueError(f"expected {n} parents, got {self.parents.shape[0]}")
        self.index = {}
        for j, name in enumerate(self.names):
            if name in self.index:
                raise ValueError(f"duplicate joint name {name!r}")
            self.index[name] = j
            p = self.parents[j]
            if p >= j or p < -1:
                raise ValueError(
                    f"joint {name!r}: expected a parent index in [-1, {j - 1}] (parents stored "
                    f"before children), got {p}")
        self.rest_translation = self._array(self.rest_translation, (n, 3), "rest_translation")
        if self.rest_rotation is None:
            self.rest_rotation = np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))
        self.rest_rotation = normalize_quats(self._array(self.rest_rotation, (n, 4), "rest_rotation"))
        if self.rest_scale is None:
            self.rest_scale = np.ones((n, 3))
        self.rest_scale = self._array(self.rest_scale, (n, 3), "rest_scale")
        depth = np.zeros(n, dtype=np.int64)
        for j in range(n):
            if self.parents[j] >= 0:
                depth[j] = depth[self.parents[j]] + 1
        # Joints at one depth only depend on shallower ones, so FK runs one batched matmul per
        # depth instead of one per joint.
        self.levels = [np.flatnonzero(depth == d) for d in range(depth.max() + 1)]
        self.depth = depth
        if self.bind_matrices is None:
            self.bind_matrices = self.forward(self.rest_local_matrices())
        self.bind_matrices = self._array(self.bind_matrices, (n, 4, 4), "bind_matrices")
        self.inverse_bind_matrices = np.linalg.inv(self.bind_matrices)
        if self.tails is None:
            self.tails = np.full((n, 3), np.nan)
        self.tails = self._array(self.tails, (n, 3), "tails")
        self.deform = (np.ones(n, dtype=bool) if self.deform is None
                       else np.asarray(self.deform, dtype=bool).reshape(n))

    def _array(self, value, shape, what):
        arr = np.array(value, dtype=np.float64)
        if arr.shape != shape:
            raise ValueError(f"skeleton {what}: expected shape {shape}, got {arr.shape}")
        if not np.all(np.isfinite(arr)) and what != "tails":
            raise ValueError(f"skeleton {what}: expected finite numbers, got NaN or inf")
        return arr

    # ------------------------------------------------------------------ structure
    def __len__(self):
        return len(self.names)

    @property
    def num_joints(self):
        return len(self.names)

    def joint_index(self, name):
        """Index of the joint called ``name``; ``KeyError`` naming it when unknown."""
        if isinstance(name, (int, np.integer)):
            if not 0 <= name < len(self.names):
                raise KeyError(f"unknown joint index {name}")
            return int(name)
        try:
            return self.index[name]
        except KeyError:
            raise KeyError(f"unknown joint {name!r}") from None

    def children(self, j):
        """Indices of the direct children of joint ``j``."""
        return np.flatnonzero(self.parents == j)

    def subtree(self, j):
        """Indices of joint ``j`` and all its descendants, in stored order."""
        return subtree_of(self.parents, j)

    def bones(self):
        """Bone segments as (parent, child) joint index pairs, (B, 2) int."""
        child = np.flatnonzero(self.parents >= 0)
        return np.stack([self.parents[child], child], axis=1)

    def bone_segments(self, deform=None, tails=None):
        """Model-space bone segments at bind time and the joint that each one moves with.

        A joint's bone runs from its head to its tail where the format gave one, otherwise
        one segment from its head to each child's head; a leaf with no tail is a point
        (zero-length segment). Joints with ``deform`` false own no segment.

        Parameters
        ----------
        deform : (J,) bool, optional
            Joints that own segments (default: the skeleton's ``deform`` flags).
        tails : (J, 3) float64, optional
            Model-space tails, NaN rows where a joint has none (default: the skeleton's).

        Returns
        -------
        starts, ends : (S, 3) float64
        owners : (S,) int
        """
        deform = self.deform if deform is None else deform
        tails = self.tails if tails is None else tails
        heads = self.bind_matrices[:, :3, 3]
        starts, ends, owners = [], [], []
        for j in np.flatnonzero(deform):
            kids = self.children(j)
            if np.all(np.isfinite(tails[j])):
                targets = tails[j][None]
            elif len(kids):
                targets = heads[kids]
            else:
                targets = heads[j][None]
            for end in targets:
                starts.append(heads[j])
                ends.append(end)
                owners.append(j)
        if not owners:
            raise ValueError("expected at least one deforming joint, got none")
        return np.array(starts), np.array(ends), np.array(owners)

    # ------------------------------------------------------------------ kinematics
    def rest_local_matrices(self):
        """(J, 4, 4) local rest matrices."""
        return compose_trs(self.rest_translation, self.rest_rotation, self.rest_scale)

    def forward(self, local_matrices, out=None):
        """Local-to-model: walk the hierarchy, one batched product per depth.

        Parameters
        ----------
        local_matrices : (J, 4, 4) float64
        out : (J, 4, 4) float64, optional
            Buffer to write into.

        Returns
        -------
        model_matrices : (J, 4, 4) float64
        """
        if out is None:
            out = np.empty_like(local_matrices)
        roots = self.levels[0]
        out[roots] = local_matrices[roots]
        for idx in self.levels[1:]:
            out[idx] = out[self.parents[idx]] @ local_matrices[idx]
        return out

    def subset_mask(self, names):
        """Boolean (J,) mask of the named joints; ``KeyError`` for an unknown one."""
        mask = np.zeros(len(self.names), dtype=bool)
        for n in names:
            mask[self.joint_index(n)] = True
        return mask


def subtree_of(parents, j):
    """Indices of joint ``j`` and all its descendants, in stored order.

    Parameters
    ----------
    parents : (J,) int
        Parent before child (``parents[k] < k``; a root's parent is -1), as a
        :class:`Skeleton` stores them and BVH and glTF readers produce them.
    j : int

    Returns
    -------
    (N,) int64
    """
    inside = np.zeros(len(parents), dtype=bool)
    inside[j] = True
    for k in range(j + 1, len(parents)):
        if parents[k] >= 0 and inside[parents[k]]:
            inside[k] = True
    return np.flatnonzero(inside)
