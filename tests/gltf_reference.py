"""An independent reading of glTF skinning for the tests: the spec's formulas, per vertex.

Nothing here uses rigedit. Buffers come from pygltflib; accessors are read element by element
with ``struct`` (offsets, strides, sparse substitution and normalisation written out from the
spec); node transforms are evaluated from the animated TRS of each node; a vertex is
``sum_i w_i * (global(joint_i) @ IBM_i) @ v`` with the weights divided by their sum (the spec
asks for weights that sum to 1; quantised ones only come close). LINEAR rotation keys are
normalised before the slerp (a key stands for a rotation; files round them to a few digits). The transform of the node
that holds the skinned mesh is ignored, as the spec says.
"""
from __future__ import annotations

import base64
import math
import struct
from pathlib import Path
from urllib.parse import unquote

import numpy as np
import pygltflib

FORMATS = {5120: "b", 5121: "B", 5122: "h", 5123: "H", 5125: "I", 5126: "f"}
SIZES = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
NORM = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}


class Reference:
    """A glTF file read the slow, obvious way."""

    def __init__(self, path):
        self.path = Path(path)
        self.g = pygltflib.GLTF2().load(str(path))
        self.buffers = []
        self._cache = {}
        for i, buf in enumerate(self.g.buffers):
            if buf.uri is None:
                self.buffers.append(self.g.binary_blob())
            elif buf.uri.startswith("data:"):
                self.buffers.append(base64.b64decode(buf.uri.split(",", 1)[1]))
            else:
                self.buffers.append((self.path.parent / unquote(buf.uri)).read_bytes())

    def _element(self, view_index, offset, i, ctype, width):
        bv = self.g.bufferViews[view_index]
        data = self.buffers[bv.buffer]
        size = SIZES[ctype]
        step = bv.byteStride or size * width
        base = (bv.byteOffset or 0) + offset + i * step
        return [struct.unpack_from("<" + FORMATS[ctype], data, base + c * size)[0]
                for c in range(width)]

    def accessor(self, index):
        """list of element lists, normalised ints as floats (cached)."""
        if index not in self._cache:
            self._cache[index] = self._read(index)
        return self._cache[index]

    def _read(self, index):
        a = self.g.accessors[index]
        width = WIDTHS[a.type]
        if a.bufferView is None:
            out = [[0] * width for _ in range(a.count)]
        else:
            out = [self._element(a.bufferView, a.byteOffset or 0, i, a.componentType, width)
                   for i in range(a.count)]
        if a.sparse is not None:
            s = a.sparse
            idx = [self._element(s.indices.bufferView, s.indices.byteOffset or 0, k,
                                 s.indices.componentType, 1)[0] for k in range(s.count)]
            for k, i in enumerate(idx):
                bv = self.g.bufferViews[s.values.bufferView]
                data = self.buffers[bv.buffer]
                size = SIZES[a.componentType]
                base = (bv.byteOffset or 0) + (s.values.byteOffset or 0) + k * size * width
                out[i] = [struct.unpack_from("<" + FORMATS[a.componentType], data,
                                             base + c * size)[0] for c in range(width)]
        if a.normalized:
            out = [[max(v / NORM[a.componentType], -1.0) for v in e] for e in out]
        return out

    # ------------------------------------------------------------------ scene
    def skin_index(self):
        for s in range(len(self.g.skins)):
            if any(n.skin == s and n.mesh is not None for n in self.g.nodes):
                return s
        return 0

    def mesh_primitives(self):
        s = self.skin_index()
        for n, node in enumerate(self.g.nodes):
            if node.skin == s and node.mesh is not None:
                for prim in self.g.meshes[node.mesh].primitives:
                    if (prim.mode if prim.mode is not None else 4) in (4, 5, 6):
                        yield prim

    def parents(self):
        parent = {}
        for i, node in enumerate(self.g.nodes):
            for c in node.children or []:
                parent[c] = i
        return parent

    def node_trs(self, n):
        node = self.g.nodes[n]
        if node.matrix is not None:
            return np.array(node.matrix, dtype=float).reshape(4, 4).T
        return (list(node.translation or [0, 0, 0]), list(node.rotation or [0, 0, 0, 1]),
                list(node.scale or [1, 1, 1]))

    def sample(self, anim, t):
        """{(node, path): value} of animation ``anim`` at time ``t`` (the spec's samplers)."""
        out = {}
        a = self.g.animations[anim]
        for ch in a.channels:
            if ch.target.path not in ("translation", "rotation", "scale"):
                continue
            smp = a.samplers[ch.sampler]
            times = [e[0] for e in self.accessor(smp.input)]
            vals = self.accessor(smp.output)
            mode = smp.interpolation or "LINEAR"
            out[(ch.target.node, ch.target.path)] = _interpolate(
                times, vals, t, mode, ch.target.path == "rotation")
        return out

    def global_matrices(self, anim=None, t=0.0):
        animated = {} if anim is None else self.sample(anim, t)
        parent = self.parents()
        cache = {}

        def world(n):
            if n in cache:
                return cache[n]
            trs = self.node_trs(n)
            if isinstance(trs, np.ndarray):
                local = trs
            else:
                t_, r_, s_ = trs
                t_ = animated.get((n, "translation"), t_)
                r_ = animated.get((n, "rotation"), r_)
                s_ = animated.get((n, "scale"), s_)
                local = _trs_matrix(t_, r_, s_)
            m = world(parent[n]) @ local if n in parent else local
            cache[n] = m
            return m

        return world

    def skinned(self, anim=None, t=0.0):
        """(V, 3) skinned positions of the merged triangle primitives."""
        skin = self.g.skins[self.skin_index()]
        world = self.global_matrices(anim, t)
        if skin.inverseBindMatrices is None:
            ibm = [np.eye(4)] * len(skin.joints)
        else:
            ibm = [np.array(e, dtype=float).reshape(4, 4).T
                   for e in self.accessor(skin.inverseBindMatrices)]
        joint_mats = [world(n) @ ibm[i] for i, n in enumerate(skin.joints)]
        out = []
        for prim in self.mesh_primitives():
            at = prim.attributes
            pos = self.accessor(at.POSITION)
            sets = [(self.accessor(getattr(at, f"JOINTS_{k}")),
                     self.accessor(getattr(at, f"WEIGHTS_{k}")))
                    for k in range(2) if getattr(at, f"JOINTS_{k}", None) is not None]
            for v in range(len(pos)):
                p = np.array(list(pos[v]) + [1.0])
                acc = np.zeros(4)
                total = sum(w for _, ws in sets for w in ws[v])
                for js, ws in sets:
                    for j, w in zip(js[v], ws[v]):
                        if w:
                            acc += (w / total) * (joint_mats[j] @ p)
                out.append(acc[:3])
        return np.array(out).reshape(-1, 3)

    def key_times(self, anim):
        a = self.g.animations[anim]
        ts = set()
        for smp in a.samplers:
            ts.update(e[0] for e in self.accessor(smp.input))
        return sorted(ts)


def _quat_matrix(q):
    x, y, z, w = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _trs_matrix(t, r, s):
    m = np.eye(4)
    m[:3, :3] = _quat_matrix(r) * np.asarray(s, dtype=float)[None, :]
    m[:3, 3] = t
    return m


def _slerp(a, b, u):
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = float(np.dot(a, b))
    if d < 0:
        b, d = -b, -d
    if d > 0.9999999:
        q = a + u * (b - a)
        return q / np.linalg.norm(q)
    th = math.acos(min(d, 1.0))
    return (math.sin((1 - u) * th) * a + math.sin(u * th) * b) / math.sin(th)


def _interpolate(times, vals, t, mode, rotation):
    n = len(times)
    cubic = mode == "CUBICSPLINE"
    value = (lambda k: vals[3 * k + 1]) if cubic else (lambda k: vals[k])
    if t <= times[0]:
        return list(value(0))
    if t >= times[-1]:
        return list(value(n - 1))
    k = 0
    while times[k + 1] <= t:
        k += 1
    td = times[k + 1] - times[k]
    u = (t - times[k]) / td
    if mode == "STEP":
        return list(value(k))
    if mode == "LINEAR":
        a, b = np.array(value(k), float), np.array(value(k + 1), float)
        if rotation:
            # a key stands for the rotation q/|q| (files round unit quaternions to a few
            # digits, e.g. SimpleSkin's 0.383/0.924); slerp runs between those rotations
            return list(_slerp(a / np.linalg.norm(a), b / np.linalg.norm(b), u))
        return list(a + u * (b - a))
    vk, bk = np.array(vals[3 * k + 1], float), np.array(vals[3 * k + 2], float)
    vk1, ak1 = np.array(vals[3 * (k + 1) + 1], float), np.array(vals[3 * (k + 1)], float)
    p = ((2 * u ** 3 - 3 * u ** 2 + 1) * vk + td * (u ** 3 - 2 * u ** 2 + u) * bk
         + (-2 * u ** 3 + 3 * u ** 2) * vk1 + td * (u ** 3 - u ** 2) * ak1)
    return list(p / np.linalg.norm(p)) if rotation else list(p)
