"""glTF 2.0 in: a skinned glTF/GLB file -> :class:`~rigedit.io.data.RigData`.

What is read
------------
- the first skin that has meshes bound (a warning when the file has several skins);
- its joints in the skin's order, named from the nodes (``joint_<node index>`` for an unnamed
  node, duplicates made unique with ``.1``, ``.2``...), stored parent-before-child; the joint
  hierarchy is the node tree. A non-joint ancestor (an ``Armature`` or ``Z_UP`` node) whose
  transform is a rotation, a uniform scale and a translation is folded into the local rest
  transform *and the animation keys* of the joints below it (exact: such a map composes with
  any TRS into a TRS). Any other non-joint ancestor is kept as a non-deforming joint of its
  own, so nothing is approximated;
- local rest transforms from TRS or from a matrix (decomposed; a sheared matrix is refused);
- the inverse bind matrices as given: ``skeleton.inverse_bind_matrices`` holds the file's own
  values (the bind pose of a glTF need not be the rest pose of its nodes);
- every triangle primitive of every mesh bound to that skin, merged into one mesh with the
  primitive of each vertex kept (:mod:`rigedit.io.gltf_mesh`);
- every animation as a clip (:mod:`rigedit.io.gltf_anim`).

Per the spec, the transform of the node that holds a skinned mesh does not move the mesh: the
vertices are used as they are and the joints' global transforms place them. glTF is Y up,
metres, +Z forward, as rigedit's characters are, so no axis change is made.
"""
from __future__ import annotations

import warnings

import numpy as np

from ..errors import RigFileError
from ..model.skeleton import Skeleton, topological_order
from ..model.transforms import compose_trs, decompose_trs
from .data import RigData, RigMeta, build_rig
from .gltf_anim import read_clips
from .gltf_data import GltfData
from .gltf_mesh import read_mesh

__all__ = ["read_gltf", "load_gltf", "GltfWarning", "unique_names"]


class GltfWarning(UserWarning):
    """Something in a glTF file was skipped or guessed (the message says what)."""


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


def _node_parents(data):
    """(N,) parent node index of every node, -1 for a root; cycles and shared children
    refused."""
    nodes = data.gltf.nodes or []
    parent = np.full(len(nodes), -1, dtype=np.int64)
    for i, node in enumerate(nodes):
        if not isinstance(node.children or [], list):
            raise RigFileError(data.path, f"node {i}: expected 'children' to be a list, got "
                                          f"{node.children!r}")
        for c in node.children or []:
            if not isinstance(c, int) or not 0 <= c < len(nodes):
                raise RigFileError(data.path, f"node {i}: expected child indices below "
                                              f"{len(nodes)}, got {c!r}")
            if parent[c] >= 0 or c == i:
                raise RigFileError(data.path, f"node {c}: expected one parent, got nodes "
                                              f"{parent[c]} and {i}")
            parent[c] = i
    for i in range(len(nodes)):  # a cycle would never reach a root
        k, steps = i, 0
        while k >= 0:
            k, steps = parent[k], steps + 1
            if steps > len(nodes):
                raise RigFileError(data.path, f"node {i}: expected a tree, got a cycle")
    return parent


def _local_matrix(data, index):
    """(4, 4) local matrix of a node, validated."""
    node = data.gltf.nodes[index]
    try:
        if node.matrix is not None:
            m = np.asarray(node.matrix, dtype=np.float64).reshape(4, 4).T
        else:
            t = np.asarray(node.translation if node.translation is not None else [0, 0, 0],
                           dtype=np.float64).reshape(3)
            r = np.asarray(node.rotation if node.rotation is not None else [0, 0, 0, 1],
                           dtype=np.float64).reshape(4)
            s = np.asarray(node.scale if node.scale is not None else [1, 1, 1],
                           dtype=np.float64).reshape(3)
            if not (np.all(np.isfinite(r)) and np.linalg.norm(r) > 1e-12):
                raise ValueError(f"rotation {r.tolist()}")
            m = compose_trs(t[None], r[None], s[None])[0] if np.all(np.isfinite(t)) and \
                np.all(np.isfinite(s)) else np.full((4, 4), np.nan)
    except (TypeError, ValueError) as exc:
        raise RigFileError(data.path, f"node {index}: expected a valid transform, got {exc}") \
            from None
    if not np.all(np.isfinite(m)):
        raise RigFileError(data.path, f"node {index}: expected finite transform numbers, got "
                                      "NaN or inf")
    return m


def _similarity(m, tol=1e-6):
    """Scale factor c when ``m``'s linear part is c times a proper rotation, else None."""
    lin = m[:3, :3]
    c = np.cbrt(np.linalg.det(lin))
    if c <= 1e-12:
        return None
    return float(c) if np.allclose(lin.T @ lin, c * c * np.eye(3), atol=tol * c * c) else None


def _choose_skin(data):
    g = data.gltf
    skins = g.skins or []
    if not skins:
        raise RigFileError(data.path, "expected a skinned mesh (a skin), got no skins")
    for i, n in enumerate(g.nodes or []):
        for key in ("mesh", "skin"):
            value = getattr(n, key)
            if value is not None and not (isinstance(value, int) and value >= 0):
                raise RigFileError(data.path, f"node {i}: expected '{key}' to be an index, got "
                                              f"{value!r}")
    bound = [[i for i, n in enumerate(g.nodes or []) if n.skin == s and n.mesh is not None]
             for s in range(len(skins))]
    chosen = next((s for s in range(len(skins)) if bound[s]), 0)
    if len(skins) > 1:
        warnings.warn(f"{data.path}: {len(skins)} skins; using skin {chosen} "
                      f"({skins[chosen].name or 'unnamed'}), the first with a mesh",
                      GltfWarning, stacklevel=3)
    return chosen, bound[chosen]


class SkeletonMap:
    """How the file's nodes became the skeleton: ``nodes`` (skeleton joint -> node),
    ``of_node`` (node -> skeleton joint), ``skin_to_joint`` (skin joint -> skeleton joint),
    ``prefix`` (skeleton joint -> (4, 4) folded similarity of non-joint ancestors, or None)."""

    def __init__(self, nodes, prefix, skin_nodes):
        self.nodes = list(nodes)
        self.of_node = {n: j for j, n in enumerate(self.nodes)}
        self.prefix = prefix
        self.skin_to_joint = np.array([self.of_node[n] for n in skin_nodes], dtype=np.int64)


def _skin_joints(data, skin_index):
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
        The skin's joints, then the non-joint ancestors that cannot be folded (not a
        similarity), which become joints of their own.
    parent_of : dict[int, int or None]
    prefix : dict[int, (4, 4) array or None]
        The product of the folded non-joint ancestors between a member and its parent.
    """
    members = list(joints)
    inside = set(joints)
    for n in joints:  # non-joint ancestors that cannot be folded become joints themselves
        k = parent[n]
        while k >= 0:
            if k not in inside and _similarity(mat(k)) is None:
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
    t, r, s = [], [], []
    for n in ordered:
        m = mat(n) if prefix[n] is None else prefix[n] @ mat(n)
        tt, rr, ss = decompose_trs(m[None])
        if not np.allclose(compose_trs(tt, rr, ss)[0], m, atol=1e-6 * max(1.0, np.abs(m).max())):
            raise RigFileError(data.path, f"node {n} ({name_of[n]!r}): expected a transform "
                                          "without shear, got a sheared matrix")
        t.append(tt[0]), r.append(rr[0]), s.append(ss[0])
        if nodes[n].matrix is None and prefix[n] is None:  # keep the file's own TRS exactly
            node = nodes[n]
            t[-1] = np.asarray(node.translation if node.translation is not None else [0, 0, 0],
                               dtype=np.float64)
            if node.rotation is not None:
                r[-1] = np.asarray(node.rotation, dtype=np.float64)
            s[-1] = np.asarray(node.scale if node.scale is not None else [1, 1, 1],
                               dtype=np.float64)
    return t, r, s


def _build_skeleton(data, skin_index, parent):
    nodes = data.gltf.nodes or []
    joints = _skin_joints(data, skin_index)
    local = {}

    def mat(n):
        if n not in local:
            local[n] = _local_matrix(data, n)
        return local[n]

    members, parent_of, prefix = _members(joints, parent, mat)
    raw = [nodes[n].name if isinstance(nodes[n].name, str) and nodes[n].name.strip()
           else f"joint_{n}" for n in members]
    names = unique_names(raw)
    name_of = dict(zip(members, names))
    order = topological_order(names, [name_of.get(parent_of[n]) for n in members])
    ordered = [members[i] for i in order]
    t, r, s = _rest_trs(data, ordered, prefix, mat, name_of)
    smap = SkeletonMap(ordered, [prefix[n] for n in ordered], joints)
    parents = [-1 if parent_of[n] is None else smap.of_node[parent_of[n]] for n in ordered]
    deform = np.array([n in set(joints) and _own(nodes[n]).get("deform") is not False
                       for n in ordered])
    tails = np.array([_tail(nodes[n]) for n in ordered])
    rest = Skeleton([name_of[n] for n in ordered], parents, np.array(t), np.array(r),
                    np.array(s), deform=deform)
    ibm = _inverse_binds(data, skin_index, len(joints))
    inverse = np.linalg.inv(rest.bind_matrices)
    inverse[smap.skin_to_joint] = ibm
    try:
        bind = np.linalg.inv(inverse)
    except np.linalg.LinAlgError:
        raise RigFileError(data.path, f"skin {skin_index}: expected invertible inverse bind "
                                      "matrices, got a singular one") from None
    skeleton = Skeleton(rest.names, rest.parents, rest.rest_translation, rest.rest_rotation,
                        rest.rest_scale, bind_matrices=bind, tails=tails, deform=deform)
    # the file's inverse bind matrices as given, not inverted twice
    skeleton.inverse_bind_matrices = inverse
    return skeleton, smap


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


def read_gltf(path):
    """Read a skinned glTF 2.0 file (``.gltf`` or ``.glb``).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    RigData
        With ``surface`` (normals, UVs, materials and each vertex's primitive), the file's
        influences and clips. A skin with no mesh bound gives 0 vertices.

    Raises
    ------
    RigFileError
        Naming the file and the problem: not glTF, a broken container, an accessor or buffer
        view out of range, a skin without joints, a joint index beyond the skin, NaN in
        positions or matrices, an extension the file requires that rigedit lacks.
    """
    data = GltfData(path)
    try:
        return _read(data)
    except RigFileError:
        raise
    except (TypeError, ValueError, KeyError, IndexError, AttributeError) as exc:
        # a field of an unexpected kind that no specific check named (the specific checks
        # above give the precise messages); still one line naming the file
        raise RigFileError(data.path, f"expected valid glTF, got a malformed field "
                                      f"({type(exc).__name__}: {exc})") from None


def load_gltf(path):
    """Read a skinned glTF 2.0 file into a :class:`~rigedit.rig.Rig` (:func:`read_gltf`, then
    ``Rig.from_data``). Kept for the callers of old: new code reads the data and builds the
    rig."""
    return build_rig(read_gltf(path))


def _read(data):
    parent = _node_parents(data)
    skin_index, mesh_nodes = _choose_skin(data)
    skeleton, smap = _build_skeleton(data, skin_index, parent)
    mesh = read_mesh(data, mesh_nodes, len(data.gltf.skins[skin_index].joints), GltfWarning)
    indices = smap.skin_to_joint[mesh.joints] if mesh.joints.size else mesh.joints
    clips = read_clips(data, skeleton, smap, GltfWarning)
    return RigData(skeleton, mesh.vertices, mesh.faces, indices, mesh.weights, clips,
                   surface=mesh.surface, name=data.path.stem, up="y",
                   meta=RigMeta(source=data.path, format="gltf"))

