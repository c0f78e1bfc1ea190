"""glTF 2.0 in: a skinned glTF/GLB file -> :class:`~rigedit.io.data.RigData`.

What is read
------------
- every mesh a viewer draws (the nodes under the file's scene): skinned ones by their skin,
  the others (rigid parts) bound wholly to the node they move with (their nearest joint or
  animated ancestor, the node itself included; a joint of the skeleton either way; a static
  part with nothing moving above it goes to the root joint), their vertices placed in bind
  space by the node's world matrix at rest (:mod:`rigedit.io.gltf_skeleton` says how several
  skins share one skeleton);
- the joints of every skin used and the rigid parts' carriers, named from the nodes
  (``joint_<node index>`` for an unnamed node, duplicates made unique with ``.1``, ``.2``...),
  stored parent-before-child; the joint hierarchy is the node tree (several roots when the
  skins are separate trees, said in ``meta.notes``). A non-joint ancestor (an ``Armature``
  or ``Z_UP`` node) whose transform is a rotation, a uniform scale and a translation is
  folded into the local rest transform *and the animation keys* of the joints below it
  (exact: such a map composes with any TRS into a TRS). Any other non-joint ancestor is kept
  as a non-deforming joint of its own, so nothing is approximated;
- local rest transforms from TRS or from a matrix (decomposed; a sheared matrix is refused);
- the inverse bind matrices as given: ``skeleton.inverse_bind_matrices`` holds the file's own
  values (the bind pose of a glTF need not be the rest pose of its nodes);
- every triangle primitive of those meshes, merged into one mesh in node order with the
  primitive of each vertex kept, and their morph targets (:mod:`rigedit.io.gltf_mesh`,
  :mod:`rigedit.io.gltf_morph`);
- every animation as a clip, morph weight channels as weight tracks
  (:mod:`rigedit.io.gltf_anim`).

Per the spec, the transform of the node that holds a skinned mesh does not move the mesh: the
vertices are used as they are and the joints' global transforms place them. glTF is Y up,
metres, +Z forward, as rigedit's characters are, so no axis change is made.
"""
from __future__ import annotations

import numpy as np

from ..errors import RigFileError
from ..model.transforms import compose_trs
from .data import RigData, RigMeta, build_rig
from .gltf_anim import read_clips
from .gltf_data import GltfData
from .gltf_mesh import MeshPart, read_mesh
from .gltf_skeleton import bind_skins, build_skeleton, skin_joints, unique_names

__all__ = ["read_gltf", "load_gltf", "GltfWarning", "unique_names"]


class GltfWarning(UserWarning):
    """Something in a glTF file was skipped or guessed (the message says what)."""


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
    # a cycle would never reach a root; each node is walked once (a chain of 10,000 nodes
    # walked from every node took seconds)
    up, state = parent.tolist(), [0] * len(nodes)   # 0 unseen, 1 on this walk, 2 reaches a root
    for i in range(len(nodes)):
        walk, k = [], i
        while k >= 0 and state[k] == 0:
            state[k] = 1
            walk.append(k)
            k = up[k]
        if k >= 0 and state[k] == 1:
            raise RigFileError(data.path, f"node {i}: expected a tree, got a cycle")
        for k in walk:
            state[k] = 2
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


def _check_refs(data):
    """Every node's ``mesh`` and ``skin``: None or an index in range."""
    g = data.gltf
    sizes = {"mesh": len(g.meshes or []), "skin": len(g.skins or [])}
    for i, n in enumerate(g.nodes or []):
        for key, size in sizes.items():
            value = getattr(n, key)
            if value is not None and not (isinstance(value, int) and 0 <= value < size):
                raise RigFileError(data.path, f"node {i}: expected '{key}' to be an index "
                                              f"below {size}, got {value!r}")


def _drawn(data, parent):
    """Sorted nodes with a mesh that a viewer draws: those under the file's scene (``scene``,
    else scene 0) when it lists nodes, else every node with a mesh."""
    g = data.gltf
    nodes = g.nodes or []
    meshed = [i for i, n in enumerate(nodes) if n.mesh is not None]
    scenes = g.scenes if isinstance(g.scenes, list) else []
    pick = g.scene if isinstance(g.scene, int) else 0
    roots = scenes[pick].nodes if 0 <= pick < len(scenes) else None
    if not isinstance(roots, list) or not roots \
            or not all(isinstance(r, int) and 0 <= r < len(nodes) for r in roots):
        return meshed
    top = _tops(parent)
    roots = set(roots)
    return [i for i in meshed if top[i] in roots]


def _tops(parent):
    """(N,) list: the root above every node (each node walked once)."""
    up = parent.tolist()
    top = [-1] * len(up)
    for i in range(len(up)):
        walk, k = [], i
        while top[k] < 0 and up[k] >= 0:
            walk.append(k)
            k = up[k]
        root = top[k] if top[k] >= 0 else k
        for k in walk + [k]:
            top[k] = root
    return top


def _animated(data):
    """Nodes that any animation moves (a translation, rotation or scale channel)."""
    out = set()
    for anim in data.gltf.animations or []:
        for ch in (anim.channels if isinstance(anim.channels, list) else []):
            target = getattr(ch, "target", None)
            if target is not None and isinstance(target.node, int) \
                    and target.path in ("translation", "rotation", "scale"):
                out.add(target.node)
    return out


def _carriers(rigid, joints, animated, parent):
    """Per rigid mesh node, the node it moves with: itself or its nearest ancestor that is a
    joint or animated; None when nothing above it moves (a static part)."""
    up, memo, out = parent.tolist(), {}, {}
    for n in rigid:
        walk, k = [], n
        while k >= 0 and k not in memo and k not in joints and k not in animated:
            walk.append(k)
            k = up[k]
        found = memo[k] if k in memo else (k if k >= 0 else None)
        for w in walk:   # every node on the way moves with the same carrier
            memo[w] = found
        out[n] = None if found is None else int(found)
    return out


def _world(data, parent, mat):
    """Node index -> (4, 4) world matrix at rest (cached)."""
    cache = {}

    def world(i):
        if i not in cache:
            chain = []
            k = i
            while k >= 0 and k not in cache:
                chain.append(k)
                k = parent[k]
            m = cache[k] if k >= 0 else np.eye(4)
            for k in reversed(chain):
                m = cache[k] = m @ mat(k)
        return cache[i]

    return world


def _rigid_parts(data, skeleton, smap, rigid, carrier, world):
    """MeshParts of the rigid meshes: each bound wholly to its carrier's joint (the root for a
    static part with no joint above it), its vertices moved into bind space by
    ``inv(IBM_j) @ inv(G_j at rest) @ world(node)`` so that skinning at rest places them where
    the file does."""
    rest = skeleton.forward(skeleton.rest_local_matrices())
    parts = {}
    for n in rigid:
        j = 0 if carrier[n] is None else smap.of_node[carrier[n]]
        m = np.linalg.inv(skeleton.inverse_bind_matrices[j]) @ np.linalg.inv(rest[j]) @ world(n)
        parts[n] = MeshPart(n, np.array([j], dtype=np.int64), m, skinned=False)
    return parts


def _notes(skeleton, used, smap, helpers, rigid, carrier):
    """What the reader decided where glTF is silent, for RigMeta.notes."""
    notes = {}
    if len(used) > 1:
        moved = [s for s in used if smap.skin_offset[s] is not None]
        notes["skins"] = (f"{len(used)} skins ({', '.join(map(str, used))}) merged into one "
                          f"skeleton of {len(skeleton)} joints"
                          + (f"; the vertices of skin {', '.join(map(str, moved))} "
                             "pre-transformed to share the first skin's inverse binds"
                             if moved else "")
                          + (f"; {helpers} helper joints (name.skin<s>) carry inverse binds "
                             "that differ" if helpers else ""))
    roots = int(np.sum(skeleton.parents < 0))
    if roots > 1:
        notes["roots"] = (f"the joints form {roots} separate trees: one skeleton with {roots} "
                          "roots")
    if rigid:
        static = sum(carrier[n] is None for n in rigid)
        notes["parts"] = (f"{len(rigid)} meshes not skinned bound wholly (weight 1) to the "
                          "joint they hang from" + (f"; {static} with no joint above them to "
                                                    f"the root {skeleton.names[0]!r}"
                                                    if static else ""))
    return notes

def read_gltf(path, allow_outside_uris=False):
    """Read a skinned glTF 2.0 file (``.gltf`` or ``.glb``).

    Parameters
    ----------
    path : str or Path
    allow_outside_uris : bool
        Read buffers and images outside the file's folder (see
        :class:`~rigedit.io.gltf_data.GltfData`); off by default.

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
    data = GltfData(path, allow_outside_uris=allow_outside_uris)
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
    _check_refs(data)
    nodes = data.gltf.nodes or []
    if not data.gltf.skins:
        raise RigFileError(data.path, "expected a skinned mesh (a skin), got no skins")
    drawn = _drawn(data, parent)
    skinned = [n for n in drawn if nodes[n].skin is not None]
    rigid = [n for n in drawn if nodes[n].skin is None]
    used = sorted({nodes[n].skin for n in skinned}) or [0]
    joints = list(dict.fromkeys(j for s in used for j in skin_joints(data, s)))
    carrier = _carriers(rigid, set(joints), _animated(data), parent)
    joints += [c for c in dict.fromkeys(carrier.values()) if c is not None and c not in joints]
    local = {}

    def mat(n):
        if n not in local:
            local[n] = _local_matrix(data, n)
        return local[n]

    skeleton, smap = build_skeleton(data, joints, set(joints), parent, mat)
    skeleton, helpers = bind_skins(data, skeleton, smap, used)
    parts = _rigid_parts(data, skeleton, smap, rigid, carrier, _world(data, parent, mat))
    for n in skinned:
        s = nodes[n].skin
        parts[n] = MeshPart(n, smap.skin_to_joint[s], smap.skin_offset[s], skinned=True)
    mesh = read_mesh(data, [parts[n] for n in drawn], GltfWarning)
    clips = read_clips(data, skeleton, smap, GltfWarning, mesh.morph_nodes)
    meta = RigMeta(source=data.path, format="gltf",
                   notes=_notes(skeleton, used, smap, helpers, rigid, carrier))
    return RigData(skeleton, mesh.vertices, mesh.faces, mesh.joints, mesh.weights, clips,
                   surface=mesh.surface, name=data.path.stem, up="y", meta=meta,
                   morphs=mesh.morphs)
