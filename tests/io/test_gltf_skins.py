"""glTF in: every skin and every rigid part a viewer draws, against the spec's formulas.

The reference (:func:`drawn`) places every mesh node of the scene as the spec says, per
vertex, from the file's arrays (``tests/gltf_reference.py``'s accessors and node
transforms): a skinned mesh by ``sum_i w_i * world(joint_i) @ IBM_i @ v`` with its own skin's
inverse binds (its node's transform ignored), any other mesh by ``world(node) @ v``; morph
targets added first, ``v + sum_m w_m * delta_m``, with the weights of the node's ``weights``
channel (LINEAR, STEP or CUBICSPLINE) or the mesh's ``weights``.
"""
from __future__ import annotations

import numpy as np
import pytest

from gltf_builder import two_skins_and_parts
from gltf_reference import Reference, _interpolate
from rigedit.io.gltf_read import read_gltf
from rigedit.rig import Rig
from testpaths import DATA

ROBOT = DATA / "threejs-characters" / "RobotExpressive.glb"
#: The hat's primitive in the figure read back: parts come in node order, node 3 first.
HAT = 0


def _get(attrs, name):
    return attrs.get(name) if isinstance(attrs, dict) else getattr(attrs, name, None)


def morph_weights(ref, anim, t, node):
    """(M,) the morph weights of mesh node ``node`` at time ``t`` of animation ``anim``."""
    mesh = ref.g.meshes[ref.g.nodes[node].mesh]
    count = len(mesh.primitives[0].targets or [])
    weights = list(mesh.weights or [0.0] * count)
    if anim is None:
        return np.array(weights, dtype=float)
    a = ref.g.animations[anim]
    for ch in a.channels:
        if ch.target.node == node and ch.target.path == "weights":
            smp = a.samplers[ch.sampler]
            times = [e[0] for e in ref.accessor(smp.input)]
            flat = [e[0] for e in ref.accessor(smp.output)]
            keys = [flat[i:i + count] for i in range(0, len(flat), count)]
            weights = _interpolate(times, keys, t, smp.interpolation or "LINEAR", False)
    return np.array(weights, dtype=float)


def drawn(ref, anim=None, t=0.0, weights=None):
    """(V, 3) every triangle primitive of every mesh node of the scene, in node order;
    ``weights``: {node: (M,) morph weights} instead of the file's."""
    world = ref.global_matrices(anim, t)
    out = []
    for n, node in enumerate(ref.g.nodes):
        if node.mesh is None:
            continue
        mw = (weights or {}).get(n)
        mw = morph_weights(ref, anim, t, n) if mw is None else mw
        palette = None
        if node.skin is not None:
            skin = ref.g.skins[node.skin]
            ibm = [np.array(e, float).reshape(4, 4).T for e in ref.accessor(skin.inverseBindMatrices)]
            palette = [world(j) @ ibm[i] for i, j in enumerate(skin.joints)]
        for prim in ref.g.meshes[node.mesh].primitives:
            at = prim.attributes
            pos = np.array(ref.accessor(at.POSITION), dtype=float)
            for m, target in enumerate(prim.targets or []):
                if _get(target, "POSITION") is not None:
                    pos = pos + mw[m] * np.array(ref.accessor(_get(target, "POSITION")), float)
            h = np.c_[pos, np.ones(len(pos))]
            if palette is None:
                out.append((h @ world(n).T)[:, :3])
                continue
            js, ws = ref.accessor(at.JOINTS_0), ref.accessor(at.WEIGHTS_0)
            for v in range(len(pos)):
                total = sum(ws[v])
                acc = sum((w / total) * (palette[j] @ h[v]) for j, w in zip(js[v], ws[v]) if w)
                out.append(acc[None, :3])
    return np.concatenate(out)


def worst(path, rig, times=(0.0, 0.25, 0.5, 0.8, 1.0), clips=None):
    """Largest distance between rigedit's skinning and :func:`drawn` over the clips (named
    ``clips``, all when None; matched to the file's animations by name) at ``times``
    (seconds, clamped by the clips), over the drawn bounding-box diagonal."""
    ref = Reference(path)
    rest = drawn(ref)
    diag = float(np.linalg.norm(np.ptp(rest, axis=0)))
    err = float(np.abs(rig.skin(rig.rest_pose()) - rest).max())
    order = [a.name for a in ref.g.animations or []]
    for name in (list(rig.clips) if clips is None else clips):
        clip, a = rig.clips[name], order.index(name)
        for t in times:
            t = min(t, clip.duration)
            got = rig.skin(clip.sample(t), morph_weights=clip.sample_morphs(t) or None)
            err = max(err, float(np.abs(got - drawn(ref, a, t)).max()))
    return err / diag


@pytest.mark.parametrize("conflict", [True, False])
def test_two_skins_and_rigid_parts_skin_like_the_spec(tmp_path, conflict):
    b, info = two_skins_and_parts(conflict=conflict)
    path = b.write(tmp_path / "figure.glb")
    data = read_gltf(path)
    assert len(data.vertices) == info["vertices"]
    names = data.skeleton.names
    # one skeleton: the union of the three skins' joints, the root first, and where skin 2's
    # head bind differs from skin 0's, a helper joint under the head that carries it
    assert names[0] == "hips" and set(names) - {"head.skin2"} == {"hips", "spine", "head", "leg"}
    assert ("head.skin2" in names) == conflict
    if conflict:
        assert data.skeleton.parents[names.index("head.skin2")] == names.index("head")
    assert int(np.sum(data.skeleton.parents < 0)) == 1
    assert "skins" in data.meta.notes and "parts" in data.meta.notes
    assert "pre-transformed" in data.meta.notes["skins"]
    # the hat is wholly the head's, the static base the root's
    hat = data.surface.vertex_primitive == HAT
    assert np.all(data.indices[hat][:, 0] == names.index("head"))
    assert np.all(data.weights[hat][:, 0] == 1)
    base = data.surface.vertex_primitive == data.surface.vertex_primitive.max()   # node 8
    assert np.all(data.indices[base][:, 0] == 0) and np.all(data.weights[base][:, 0] == 1)
    # the arm's head vertices ride the helper joint where skin 2's bind differs
    arm = data.surface.vertex_primitive == 4
    top = data.weights[arm][:, 1] > 0
    want = names.index("head.skin2") if conflict else names.index("head")
    assert np.all(data.indices[arm][top, 1] == want)
    rig = Rig.from_data(data)
    assert worst(path, rig) < 1e-6


def test_separate_trees_give_several_roots(tmp_path):
    b, _ = two_skins_and_parts(conflict=False)
    # the leg becomes a root of its own (no longer under the hips); skin 1 then holds
    # hips and leg, which are no longer one tree with the rest
    b.doc["nodes"][0]["children"] = [1]
    b.doc["nodes"][4]["translation"] = [0.1, 0.9, 0.0]
    b.doc["scenes"][0]["nodes"].append(4)
    b.doc["skins"][1]["joints"] = [4]
    inv = np.linalg.inv(np.array([[1, 0, 0, 0.1], [0, 1, 0, 0.9], [0, 0, 1, 0], [0, 0, 0, 1.0]]))
    b.doc["skins"][1]["inverseBindMatrices"] = b.accessor(inv.T.reshape(1, 16), "float32")
    legs = b.doc["meshes"][2]["primitives"][0]["attributes"]
    legs["JOINTS_0"] = b.accessor(np.zeros((8, 4)), "uint8")
    path = b.write(tmp_path / "two_trees.glb")
    data = read_gltf(path)
    assert int(np.sum(data.skeleton.parents < 0)) == 2
    assert "2 roots" in data.meta.notes["roots"]
    assert worst(path, Rig.from_data(data)) < 1e-6


def _robot():
    if not ROBOT.is_file():
        pytest.skip(f"shared data not present: {ROBOT}")
    return ROBOT


def test_robot_expressive_shows_every_part():
    path = _robot()
    ref = Reference(path)
    drawn_counts = {ref.g.nodes[n].name: sum(ref.g.accessors[p.attributes.POSITION].count
                                             for p in ref.g.meshes[node.mesh].primitives)
                    for n, node in enumerate(ref.g.nodes) if node.mesh is not None}
    assert len(drawn_counts) == 14
    data = read_gltf(path)
    assert len(data.vertices) == sum(drawn_counts.values()) == 7214
    # every part is there: its primitives' vertex counts, in node order
    prims = [ref.g.accessors[p.attributes.POSITION].count for n, node in enumerate(ref.g.nodes)
             if node.mesh is not None for p in ref.g.meshes[node.mesh].primitives]
    assert np.bincount(data.surface.vertex_primitive).tolist() == prims
    assert len(data.skeleton) == 43 and data.morphs.names == ("Angry", "Surprised", "Sad")


def test_robot_expressive_skins_like_the_spec():
    path = _robot()
    rig = Rig.from_data(read_gltf(path))
    # the walk and the wave (its face keys the three shapes) at a few times
    assert rig.clips["Wave"].morph_tracks
    assert worst(path, rig, times=(0.0, 0.37, 1.1), clips=["Walking", "Wave"]) < 1e-5


@pytest.mark.parametrize("trees", [1, 2])
def test_rigid_parts_and_skins_export_back_the_same_way(tmp_path, trees):
    from rigedit.io.gltf_write import save_gltf
    from test_gltf_morph import _validate

    b, _ = two_skins_and_parts()
    if trees == 2:   # a second tree: the static base carried by an animated node of its own
        b.doc["animations"][0]["channels"].append(
            {"sampler": 1, "target": {"node": 8, "path": "rotation"}})
    path = b.write(tmp_path / "figure.glb")
    first = Rig.from_data(read_gltf(path))
    assert int(np.sum(first.skeleton.parents < 0)) == trees
    assert worst(path, first) < 1e-6
    out = save_gltf(first, tmp_path / "again.glb")
    again = Rig.from_data(read_gltf(out))
    assert again.skeleton.names == first.skeleton.names
    assert int(np.sum(again.skeleton.parents < 0)) == trees
    # the rigid parts went out as skinned primitives, each vertex wholly on its joint
    g = Reference(out).g
    assert len(g.meshes[0].primitives) == len(set(first.surface.vertex_primitive.tolist()))
    hat = np.flatnonzero(first.surface.vertex_primitive == HAT)
    dense = again.binding.dense()
    assert np.all(dense[hat, first.skeleton.names.index("head")] == 1)
    clip_a, clip_b = first.clips["move"], again.clips["move"]
    for t in (0.0, 0.3, 0.5, 1.0):
        assert np.abs(first.skin(clip_a.sample(t)) - again.skin(clip_b.sample(t))).max() < 1e-6
    # the export itself, read by the spec's formulas, draws the same figure
    assert worst(out, again) < 1e-6
    assert np.abs(drawn(Reference(out), 0, 0.5) - drawn(Reference(path), 0, 0.5)).max() < 1e-6
    _validate(out)


def test_a_deep_node_chain_reads_in_linear_time(tmp_path):
    """5,000 joints in one chain and 5,000 nested rigid parts: every walk up the tree is done
    once per node (walking from every node to the root, as before, took 1.8 s at 2,000 and
    grows with the square)."""
    import time

    from gltf_builder import deep_chain

    path = deep_chain(5000, rigid_chain=True).write(tmp_path / "deep.glb")
    start = time.process_time()
    data = read_gltf(path)
    spent = time.process_time() - start
    assert len(data.skeleton) == 5000 and len(data.vertices) == 4 + 4 * 5000
    # every rigid part is carried by the root (nothing above them moves): placed at rest
    assert np.allclose(data.vertices[-4:, 0], np.array([-0.05, 0.05, -0.05, 0.05]) + 5.0,
                       atol=1e-6)
    assert spent < 6.0, spent


@pytest.mark.parametrize("scale", [[0.5, 0.5, 0.5], [-0.5, 0.5, 0.5]])
def test_a_mirrored_rigid_part_keeps_its_faces_facing_out(tmp_path, scale):
    """A rigid part's faces stay on the side of its normals (transformed by the inverse
    transpose) when its placement mirrors it: the winding is reversed, as a viewer does for a
    node of negative determinant."""
    b, _ = two_skins_and_parts()
    b.doc["nodes"][3]["scale"] = scale
    path = b.write(tmp_path / "mirrored.glb")
    data = read_gltf(path)
    hat = data.surface.vertex_primitive == HAT
    faces = data.faces[np.all(hat[data.faces], axis=1)]
    v = data.vertices
    face_n = np.cross(v[faces[:, 1]] - v[faces[:, 0]], v[faces[:, 2]] - v[faces[:, 0]])
    vert_n = data.surface.normals[faces[:, 0]]
    assert len(faces) and np.all(np.sum(face_n * vert_n, axis=1) > 0)
    assert worst(path, Rig.from_data(data)) < 1e-6
