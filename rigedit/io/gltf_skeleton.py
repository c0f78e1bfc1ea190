"""glTF 2.0 in: the one skeleton of a file's skins and rigid-part carriers.

Every skin with a drawn mesh contributes its joints; so does the node that carries each rigid
part (:mod:`rigedit.io.gltf_read` picks them). The union, with the non-joint ancestors that
cannot be folded, becomes one :class:`~rigedit.model.skeleton.Skeleton` stored
parent-before-child. Skins that share joints or hang from one node tree give one tree; skins
in separate trees give a skeleton with several roots.

Inverse bind matrices (:func:`bind_skins`): the first skin's are kept as given. A later skin
whose shared joints carry other inverse binds is reconciled exactly: with ``C`` the offset
``inv(IBM_first) @ IBM_skin`` of its first shared joint, that skin's vertices are
pre-transformed by ``C`` (so ``G @ IBM_first @ (C v) == G @ IBM_skin @ v``) and its joints
new to the skeleton get ``IBM_skin @ inv(C)``. A shared joint whose offset differs from ``C``
gets a helper joint (``<joint>.skin<s>``: a child at identity, never animated, so it moves
exactly with its parent) that carries that skin's inverse bind.
"""
from __future__ import annotations

import numpy as np

from ..errors import RigFileError
from ..model.skeleton import Skeleton, topological_order
from ..model.transforms import compose_trs, decompose_trs

__all__ = ["SkeletonMap", "build_skeleton", "bind_skins", "skin_joints", "similarity"]


def similarity(m, tol=1e-6):
    """Scale factor c when ``m``'s linear part is c times a proper rotation, else None."""
    lin = m[:3, :3]
    c = np.cbrt(np.linalg.det(lin))
    if c <= 1e-12:
        return None
    return float(c) if np.allclose(lin.T @ lin, c * c * np.eye(3), atol=tol * c * c) else None


class SkeletonMap:
    """How the file's nodes became the skeleton.

    Attributes
    ----------
    nodes : list[int]
        Skeleton joint -> node (helper joints, appended last, have no node: -1).
    of_node : dict[int, int]
        Node -> skeleton joint.
    prefix : list of (4, 4) array or None
        Per skeleton joint, the folded similarity of its non-joint ancestors.
    skin_to_joint : dict[int, (K,) int64]
        Per skin, its joint slot -> skeleton joint (a helper joint where the skin's inverse
        bind could not be shared).
    skin_offset : dict[int, (4, 4) array or None]
        Per skin, the matrix its vertices are pre-transformed by (None: as they are).
    """

    def __init__(self, nodes, prefix):
        self.nodes = list(nodes)
        self.of_node = {n: j for j, n in enumerate(self.nodes)}
        self.prefix = list(prefix)
        self.skin_to_joint, self.skin_offset = {}, {}


def skin_joints(data, skin_index):
    """The skin's joint node indices, checked: a non-empty list of distinct node indices."""
    skin = data.gltf.skins[skin_index]
    count = len(data.gltf.nodes or [])
    if not isinstance(skin.joints or [], list):
        raise RigFileError(data.path, f"skin {skin_index}: expected 'joints' to be a list of "
                                      f"node indices, got {skin.joints!r}")
    joints = list(skin.joints or [])
    if not joints:
        raise RigFileError(data.path, f"skin {skin_index}: expected joints, got none")
    for n in joints:
        if not isinstance(n, int) or not 0 <= n < count:
            raise RigFileError(data.path, f"skin {skin_index}: expected joint node indices "
                                          f"below {count}, got {n!r}")
    if len(set(joints)) != len(joints):
        raise RigFileError(data.path, f"skin {skin_index}: expected distinct joints, got a "
                                      "node listed twice")
    return joints


def _members(joints, parent, mat):
    """The nodes that become joints, each one's parent among them, and the folded prefix.

    Returns
    -------
    members : list[int]
        ``joints``, then the non-joint ancestors that cannot be folded (not a similarity),
        which become joints of their own.
    parent_of : dict[int, int or None]
    prefix : dict[int, (4, 4) array or None]
        The product of the folded non-joint ancestors between a member and its parent.
    """
    members = list(joints)
    inside, walked = set(joints), set()
    for n in joints:  # non-joint ancestors that cannot be folded become joints themselves
        k = parent[n]
        while k >= 0 and k not in walked:   # above a walked node all is decided
            walked.add(k)
            if k not in inside and similarity(mat(k)) is None:
                inside.add(k)
                members.append(k)
            k = parent[k]
    parent_of, prefix = {}, {}
    for n in members:
        p, chain = parent[n], []
        while p >= 0 and p not in inside:
            chain.append(p)
            p = parent[p]
        parent_of[n] = p if p >= 0 else None
        pre = np.eye(4)
        for k in reversed(chain):
            pre = pre @ mat(k)
        prefix[n] = None if np.allclose(pre, np.eye(4), atol=1e-12, rtol=0) else pre
    return members, parent_of, prefix


def _rest_trs(data, ordered, prefix, mat, name_of):
    """Local rest translations, rotations and scales (lists of arrays) of the joints' nodes:
    the file's own TRS where a node has one and nothing was folded into it, else decomposed
    from the (prefixed) matrix, a sheared one refused."""
    nodes = data.gltf.nodes
    m = np.array([mat(n) if prefix[n] is None else prefix[n] @ mat(n) for n in ordered])
    t, r, s = decompose_trs(m)   # all at once: one joint at a time took 0.45 ms each
    back = compose_trs(t, r, s)
    tol = 1e-6 * np.maximum(1.0, np.abs(m).max(axis=(1, 2)))
    bad = np.flatnonzero(np.any(np.abs(back - m) > tol[:, None, None] + 1e-5 * np.abs(m),
                                axis=(1, 2)))   # np.allclose's rule, per joint
    if len(bad):
        n = ordered[bad[0]]
        raise RigFileError(data.path, f"node {n} ({name_of[n]!r}): expected a transform "
                                      "without shear, got a sheared matrix")
    t, r, s = list(t), list(r), list(s)
    for i, n in enumerate(ordered):
        if nodes[n].matrix is None and prefix[n] is None:  # keep the file's own TRS exactly
            node = nodes[n]
            t[i] = np.asarray(node.translation if node.translation is not None else [0, 0, 0],
                              dtype=np.float64)
            if node.rotation is not None:
                r[i] = np.asarray(node.rotation, dtype=np.float64)
            s[i] = np.asarray(node.scale if node.scale is not None else [1, 1, 1],
                              dtype=np.float64)
    return t, r, s


def build_skeleton(data, joints, bound, parent, mat):
    """The rest skeleton of the nodes ``joints`` (inverse binds: the rest pose's).

    Parameters
    ----------
    data : GltfData
    joints : list[int]
        Distinct nodes: every used skin's joints, then the rigid parts' carriers.
    bound : set[int]
        The nodes that deform (skin joints and carriers; rigedit's ``deform: false`` extra
        still wins).
    parent : (N,) int64
        Parent node of every node, -1 for a root.
    mat : callable
        Node index -> its validated (4, 4) local matrix.

    Returns
    -------
    skeleton : Skeleton
    smap : SkeletonMap
    """
    nodes = data.gltf.nodes or []
    members, parent_of, prefix = _members(joints, parent, mat)
    raw = [nodes[n].name if isinstance(nodes[n].name, str) and nodes[n].name.strip()
           else f"joint_{n}" for n in members]
    name_of = dict(zip(members, unique_names(raw)))
    order = topological_order([name_of[n] for n in members],
                              [name_of.get(parent_of[n]) for n in members])
    ordered = [members[i] for i in order]
    t, r, s = _rest_trs(data, ordered, prefix, mat, name_of)
    smap = SkeletonMap(ordered, [prefix[n] for n in ordered])
    parents = [-1 if parent_of[n] is None else smap.of_node[parent_of[n]] for n in ordered]
    deform = np.array([n in bound and _own(nodes[n]).get("deform") is not False
                       for n in ordered])
    tails = np.array([_tail(nodes[n]) for n in ordered])
    skeleton = Skeleton([name_of[n] for n in ordered], parents, np.array(t), np.array(r),
                        np.array(s), tails=tails, deform=deform)
    return skeleton, smap


def unique_names(names):
    """Make names unique in order: a repeat of ``x`` becomes ``x.1``, ``x.2``, ... (skipping
    names the list already holds)."""
    taken, used, out = set(names), set(), []
    for name in names:
        new, k = name, 0
        while new in used or (new != name and new in taken):
            k += 1
            new = f"{name}.{k}"
        used.add(new)
        out.append(new)
    return out


def _close(a, b):
    return np.allclose(a, b, rtol=0, atol=1e-6 * max(1.0, np.abs(a).max(), np.abs(b).max()))


def _share_binds(data, smap, skins, inverse):
    """Put each skin's inverse binds into ``inverse`` (a list of (4, 4), one per skeleton
    joint, extended here by one per helper joint); fill ``smap.skin_to_joint`` and
    ``smap.skin_offset``. Returns the helpers as (parent joint, skin) pairs."""
    assigned, helpers = {}, []
    for s in skins:
        nodes = skin_joints(data, s)
        ibm = _inverse_binds(data, s, len(nodes))
        idx = [smap.of_node[n] for n in nodes]
        shared = [k for k, j in enumerate(idx) if j in assigned]
        offset = np.eye(4)
        if shared:
            offset = np.linalg.inv(assigned[idx[shared[0]]]) @ ibm[shared[0]]
            if _close(offset, np.eye(4)):   # float32 noise: keep this skin's binds as given
                offset = np.eye(4)
        undo = np.linalg.inv(offset)
        jmap = []
        for k, j in enumerate(idx):
            want = ibm[k] @ undo   # the bind that serves the pre-transformed vertices
            if j not in assigned:
                assigned[j] = inverse[j] = want
            elif not _close(assigned[j], want):
                helpers.append((j, s))
                inverse.append(want)
                j = len(inverse) - 1
            jmap.append(j)
        smap.skin_to_joint[s] = np.array(jmap, dtype=np.int64)
        smap.skin_offset[s] = None if np.array_equal(offset, np.eye(4)) else offset
    return helpers


def bind_skins(data, skeleton, smap, skins):
    """Give ``skeleton`` the inverse binds of ``skins`` (see the module docstring).

    Parameters
    ----------
    skeleton : Skeleton
        From :func:`build_skeleton`; its inverse binds are the rest pose's.
    smap : SkeletonMap
        Filled in here: ``skin_to_joint`` and ``skin_offset`` per skin; helper joints
        appended to ``nodes`` (as -1) and ``prefix``.
    skins : list[int]
        The skins used, in file order.

    Returns
    -------
    skeleton : Skeleton
        A new one when helper joints were added or binds differ from the rest pose, with
        ``inverse_bind_matrices`` holding the file's values as given.
    helpers : int
        The number of helper joints added.
    """
    inverse = list(np.linalg.inv(skeleton.bind_matrices))
    helpers = _share_binds(data, smap, skins, inverse)
    sk = skeleton
    names, parents = list(sk.names), list(sk.parents)
    for j, s in helpers:
        names.append(unique_names(names + [f"{sk.names[j]}.skin{s}"])[-1])
        parents.append(j)
        smap.nodes.append(-1)
        smap.prefix.append(None)
    extra = len(helpers)
    inverse = np.array(inverse)
    try:
        bind = np.linalg.inv(inverse)
    except np.linalg.LinAlgError:
        raise RigFileError(data.path, "expected invertible inverse bind matrices, got a "
                                      "singular one") from None
    # parent-before-child as a file written from this skeleton reads back (depth first)
    order = np.array(topological_order(names, [names[p] if p >= 0 else None
                                               for p in parents]), dtype=np.int64)
    new = np.empty_like(order)
    new[order] = np.arange(len(order))
    smap.nodes = [smap.nodes[i] for i in order]
    smap.prefix = [smap.prefix[i] for i in order]
    smap.of_node = {n: j for j, n in enumerate(smap.nodes) if n >= 0}
    smap.skin_to_joint = {s: new[m] for s, m in smap.skin_to_joint.items()}
    parents = [-1 if parents[i] < 0 else int(new[parents[i]]) for i in order]
    inverse, bind = inverse[order], bind[order]
    out = Skeleton([names[i] for i in order], parents,
                   np.r_[sk.rest_translation, np.zeros((extra, 3))][order],
                   np.r_[sk.rest_rotation, np.tile([0.0, 0, 0, 1], (extra, 1))][order],
                   np.r_[sk.rest_scale, np.ones((extra, 3))][order], bind_matrices=bind,
                   tails=np.r_[sk.tails, np.full((extra, 3), np.nan)][order],
                   deform=np.r_[sk.deform, np.ones(extra, bool)][order])
    out.inverse_bind_matrices = inverse   # the file's values as given, not inverted twice
    return out, extra


def _own(node):
    """rigedit's own extras of a node (written by rigedit's glTF export), or {}."""
    own = node.extras.get("rigedit") if isinstance(node.extras, dict) else None
    return own if isinstance(own, dict) else {}


def _tail(node):
    """(3,) a joint's bone tail from rigedit's extras, NaN when absent or malformed."""
    try:
        tail = np.asarray(_own(node).get("tail"), dtype=np.float64).reshape(3)
    except (TypeError, ValueError):
        return np.full(3, np.nan)
    return tail if np.all(np.isfinite(tail)) else np.full(3, np.nan)


def _inverse_binds(data, skin_index, count):
    """(count, 4, 4) inverse bind matrices of a skin (identity when it gives none)."""
    skin = data.gltf.skins[skin_index]
    if skin.inverseBindMatrices is None:
        return np.tile(np.eye(4), (count, 1, 1))
    m = data.accessor(skin.inverseBindMatrices, f"skin {skin_index} inverseBindMatrices")
    if m.shape[1] != 16 or len(m) < count:
        raise RigFileError(data.path, f"skin {skin_index}: expected {count} MAT4 inverse bind "
                                      f"matrices, got {len(m)} of width {m.shape[1]}")
    m = m[:count].reshape(count, 4, 4).transpose(0, 2, 1).astype(np.float64)
    if not np.all(np.isfinite(m)):
        raise RigFileError(data.path, f"skin {skin_index}: expected finite inverse bind "
                                      "matrices, got NaN or inf")
    if np.any(np.abs(np.linalg.det(m[:, :3, :3])) < 1e-300):
        raise RigFileError(data.path, f"skin {skin_index}: expected invertible inverse bind "
                                      "matrices, got a singular one")
    return m
