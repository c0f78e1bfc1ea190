"""An independent glTF animation reader, FK and error metric for the compression benchmark.

Nothing of rigedit is imported here: the file is read with pygltflib and numpy, the views of
``EXT_meshopt_compression`` are decoded with the ``meshopt`` package (meshoptimizer's own
decoder), the samplers are evaluated as glTF 2.0 specifies them (LINEAR: lerp, and slerp on
the shortest arc for rotations; STEP; CUBICSPLINE: Hermite with the tangents scaled by the
key interval, rotations normalised after), and the FK runs over the file's whole node tree.
So the same code measures rigedit's output, gltfpack's and glTF-Transform's.

The metric is ACL's: three virtual vertices per skin joint at ``shell`` metres along the
joint's own x, y and z axes (at rest; the offset is divided by the joint's world scale at
rest so a joint under a 0.01 armature still gets a 3 cm shell), and the error of a joint at a
frame the largest distance between where the reference and the candidate put one of its
points, in world space (so a parent's error counts in every child).

The size is ACL's too: raw = 10 float32 (translation, rotation, scale) per skin joint per
source key; compressed = the bytes of the buffer views that animation samplers' accessors
read (each view once; a meshopt view counts its compressed bytes).
"""
from __future__ import annotations

import base64
from pathlib import Path

import numpy as np
import pygltflib

__all__ = ["GltfAnimations", "virtual_vertex_error", "RAW_BYTES_PER_KEY"]

#: ACL's raw size: 10 float32 per joint per key.
RAW_BYTES_PER_KEY = 40
_DTYPE = {5120: "<i1", 5121: "<u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
_NORM = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
_COLS = {"translation": slice(0, 3), "rotation": slice(3, 7), "scale": slice(7, 10)}
MESHOPT = "EXT_meshopt_compression"


def _quat_matrix(q):
    """(..., 3, 3) rotation matrices of (..., 4) unit quaternions x, y, z, w."""
    x, y, z, w = np.moveaxis(q, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1)],
        -2)


def _trs_matrix(local):
    """(..., 4, 4) matrices of (..., 10) rows translation, rotation, scale."""
    out = np.zeros(local.shape[:-1] + (4, 4))
    q = local[..., 3:7] / np.linalg.norm(local[..., 3:7], axis=-1, keepdims=True)
    out[..., :3, :3] = _quat_matrix(q) * local[..., None, 7:10]
    out[..., :3, 3] = local[..., 0:3]
    out[..., 3, 3] = 1.0
    return out


def _slerp(a, b, u):
    """Row-wise slerp of (F, 4) unit quaternions on the shortest arc."""
    dot = np.sum(a * b, axis=1)
    b = np.where(dot[:, None] < 0, -b, b)
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    small = theta < 1e-6
    s = np.where(small, 1.0, np.sin(theta))
    wa = np.where(small, 1 - u, np.sin((1 - u) * theta) / s)
    wb = np.where(small, u, np.sin(u * theta) / s)
    out = wa[:, None] * a + wb[:, None] * b
    return out / np.linalg.norm(out, axis=1, keepdims=True)


class GltfAnimations:
    """One glTF file's nodes, skin joints and animations, read without rigedit.

    Parameters
    ----------
    path : str or Path
        ``.glb`` or ``.gltf`` (buffers embedded, or files beside it).
    """

    def __init__(self, path):
        self.path = Path(path)
        self.gltf = pygltflib.GLTF2().load(str(self.path))
        self._buffers = {}
        g = self.gltf
        self.names = [n.name or f"node_{i}" for i, n in enumerate(g.nodes)]
        self.parents = np.full(len(g.nodes), -1)
        for i, n in enumerate(g.nodes):
            for c in n.children or []:
                self.parents[c] = i
        self.order = self._topological()
        self.rest = np.array([self._node_rest(n) for n in g.nodes])   # (N, 10)
        self.joints = list(g.skins[0].joints) if g.skins else list(range(len(g.nodes)))
        self.animations = {a.name or f"animation_{i}": a for i, a in enumerate(g.animations)}

    # ------------------------------------------------------------------ data
    def _topological(self):
        order, seen = [], set()
        for i in range(len(self.parents)):
            chain = []
            j = i
            while j >= 0 and j not in seen:
                chain.append(j)
                j = self.parents[j]
            for k in reversed(chain):
                seen.add(k)
                order.append(k)
        return order

    @staticmethod
    def _node_rest(node):
        if node.matrix is not None:   # a matrix node: decomposed (no shear in these files)
            m = np.array(node.matrix, dtype=float).reshape(4, 4).T
            s = np.linalg.norm(m[:3, :3], axis=0)
            r = m[:3, :3] / s
            from scipy.spatial.transform import Rotation

            return np.r_[m[:3, 3], Rotation.from_matrix(r).as_quat(), s]
        t = node.translation or [0, 0, 0]
        r = node.rotation or [0, 0, 0, 1]
        s = node.scale or [1, 1, 1]
        return np.r_[t, r, s].astype(float)

    def _buffer(self, index):
        if index not in self._buffers:
            buf = self.gltf.buffers[index]
            if buf.uri is None:
                data = self.gltf.binary_blob()
            elif buf.uri.startswith("data:"):
                data = base64.b64decode(buf.uri.split(",", 1)[1])
            else:
                data = (self.path.parent / buf.uri).read_bytes()
            self._buffers[index] = data
        return self._buffers[index]

    def view_bytes(self, index):
        """The bytes of a buffer view, meshopt-decoded where the view is compressed."""
        view = self.gltf.bufferViews[index]
        ext = (view.extensions or {}).get(MESHOPT)
        if ext is None:
            buf = self._buffer(view.buffer)
            start = view.byteOffset or 0
            return buf[start:start + view.byteLength]
        import meshopt

        buf = self._buffer(ext["buffer"])
        start = ext.get("byteOffset", 0)
        packed = buf[start:start + ext["byteLength"]]
        rows = meshopt.decode_gltf_buffer(packed, ext["count"], ext["byteStride"], ext["mode"],
                                          ext.get("filter", "NONE"))
        return np.asarray(rows).tobytes()[:view.byteLength]

    def stored_bytes(self, index):
        """Bytes a view takes in the file (compressed size for a meshopt view)."""
        view = self.gltf.bufferViews[index]
        ext = (view.extensions or {}).get(MESHOPT)
        return ext["byteLength"] if ext is not None else view.byteLength

    def accessor(self, index):
        """(count, width) float64 values of an accessor (normalised integers scaled)."""
        acc = self.gltf.accessors[index]
        width = _WIDTH[acc.type]
        dtype = np.dtype(_DTYPE[acc.componentType])
        out = np.zeros((acc.count, width))
        if acc.bufferView is not None:
            view = self.gltf.bufferViews[acc.bufferView]
            raw = self.view_bytes(acc.bufferView)
            stride = view.byteStride or dtype.itemsize * width
            start = acc.byteOffset or 0
            rows = np.frombuffer(raw, np.uint8, count=stride * (acc.count - 1)
                                 + dtype.itemsize * width, offset=start)
            rows = np.lib.stride_tricks.as_strided(rows, (acc.count, dtype.itemsize * width),
                                                   (stride, 1))
            out = np.ascontiguousarray(rows).view(dtype).reshape(acc.count, width).astype(float)
        if acc.sparse is not None:
            sp = acc.sparse
            idx = np.frombuffer(self.view_bytes(sp.indices.bufferView), _DTYPE[
                sp.indices.componentType], count=sp.count, offset=sp.indices.byteOffset or 0)
            val = np.frombuffer(self.view_bytes(sp.values.bufferView), dtype,
                                count=sp.count * width, offset=sp.values.byteOffset or 0)
            out[idx.astype(np.int64)] = val.reshape(-1, width)
        if acc.normalized:
            out = np.maximum(out / _NORM[acc.componentType], -1.0)
        return out

    # ------------------------------------------------------------------ animations
    def key_times(self, name):
        """(K,) the sorted distinct key times of animation ``name``."""
        anim = self.animations[name]
        return np.unique(np.concatenate([self.accessor(s.input)[:, 0] for s in anim.samplers]))

    def animation_bytes(self, names=None):
        """Bytes of the views the samplers of ``names`` (all when None) read, each once."""
        views = set()
        for name in (self.animations if names is None else names):
            for s in self.animations[name].samplers:
                for a in (s.input, s.output):
                    acc = self.gltf.accessors[a]
                    if acc.bufferView is not None:
                        views.add(acc.bufferView)
                    if acc.sparse is not None:
                        views |= {acc.sparse.indices.bufferView, acc.sparse.values.bufferView}
        return sum(self.stored_bytes(v) for v in views)

    def sample(self, name, times):
        """(F, N, 10) local translation, rotation, scale of every node at ``times``."""
        times = np.asarray(times, dtype=float)
        local = np.repeat(self.rest[None], len(times), axis=0)
        anim = self.animations[name]
        for ch in anim.channels:
            path = ch.target.path
            if path not in _COLS or ch.target.node is None:
                continue
            s = anim.samplers[ch.sampler]
            local[:, ch.target.node, _COLS[path]] = self._evaluate(s, path, times)
        return local

    def _evaluate(self, sampler, path, times):
        keys = self.accessor(sampler.input)[:, 0]
        out = self.accessor(sampler.output)
        mode = sampler.interpolation or "LINEAR"
        cubic = mode == "CUBICSPLINE"
        values = out.reshape(len(keys), 3, -1)[:, 1] if cubic else out
        if len(keys) == 1:
            v = np.repeat(values[:1], len(times), axis=0)
            return v / np.linalg.norm(v, axis=1, keepdims=True) if path == "rotation" else v
        t = np.clip(times, keys[0], keys[-1])
        k = np.clip(np.searchsorted(keys, t, side="right") - 1, 0, len(keys) - 2)
        dt = keys[k + 1] - keys[k]
        u = np.clip((t - keys[k]) / dt, 0.0, 1.0)
        if mode == "STEP":
            v = values[np.where(t >= keys[k + 1], k + 1, k)]
        elif cubic:
            tri = out.reshape(len(keys), 3, -1)
            u2, u3 = u * u, u * u * u
            v = ((2 * u3 - 3 * u2 + 1)[:, None] * tri[k, 1]
                 + ((u3 - 2 * u2 + u) * dt)[:, None] * tri[k, 2]
                 + (-2 * u3 + 3 * u2)[:, None] * tri[k + 1, 1]
                 + ((u3 - u2) * dt)[:, None] * tri[k + 1, 0])
        elif path == "rotation":
            a = values[k] / np.linalg.norm(values[k], axis=1, keepdims=True)
            b = values[k + 1] / np.linalg.norm(values[k + 1], axis=1, keepdims=True)
            return _slerp(a, b, u)
        else:
            v = (1 - u)[:, None] * values[k] + u[:, None] * values[k + 1]
        if path == "rotation":
            v = v / np.linalg.norm(v, axis=1, keepdims=True)
        return v

    def world(self, local):
        """(F, N, 4, 4) world matrices of (F, N, 10) local rows over the node tree."""
        mats = _trs_matrix(local)
        out = np.empty_like(mats)
        for i in self.order:
            p = self.parents[i]
            out[:, i] = mats[:, i] if p < 0 else out[:, p] @ mats[:, i]
        return out

    def joint_names(self):
        return [self.names[j] for j in self.joints]

    def joint_world(self, name, times):
        """(F, J, 4, 4) world matrices of the skin joints at ``times``."""
        return self.world(self.sample(name, times))[:, self.joints]

    def rest_joint_world(self):
        """(J, 4, 4) world matrices of the skin joints at the nodes' rest TRS."""
        return self.world(self.rest[None])[0, self.joints]


def virtual_vertex_error(reference, candidate, rest, shell=0.03):
    """(F, J) metres between the virtual vertices the two clips place.

    Parameters
    ----------
    reference, candidate : (F, J, 4, 4) world matrices of the same joints at the same frames
    rest : (J, 4, 4) the joints' world matrices at rest (for the shell's scale)
    shell : float
        Metres from each joint to its three points.
    """
    scale = np.cbrt(np.abs(np.linalg.det(rest[:, :3, :3])))
    d = shell / np.where(scale > 0, scale, 1.0)                     # (J,)
    points = np.zeros((len(d), 3, 4))
    points[:, [0, 1, 2], [0, 1, 2]] = d[:, None]
    points[:, :, 3] = 1.0
    a = np.einsum("fjab,jpb->fjpa", reference, points)[..., :3]
    b = np.einsum("fjab,jpb->fjpa", candidate, points)[..., :3]
    return np.linalg.norm(a - b, axis=-1).max(axis=-1)
