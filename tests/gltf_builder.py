"""Small glTF files built in code for the reader's tests (JSON dicts + one binary buffer)."""
from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import numpy as np

CTYPES = {np.dtype("int8"): 5120, np.dtype("uint8"): 5121, np.dtype("int16"): 5122,
          np.dtype("uint16"): 5123, np.dtype("uint32"): 5125, np.dtype("float32"): 5126}
TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4", 16: "MAT4"}


class GltfBuilder:
    """Accumulates buffer views and accessors into one buffer."""

    def __init__(self):
        self.doc = {"asset": {"version": "2.0"}, "buffers": [], "bufferViews": [],
                    "accessors": [], "nodes": [], "meshes": [], "skins": [], "scenes": [{}],
                    "scene": 0}
        self.bin = bytearray()

    def view(self, data, stride=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if stride:
            view["byteStride"] = stride
        self.bin += data
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, array, dtype="float32", normalized=False, view=None, offset=0,
                 minmax=False):
        """Add ``array`` (N, C) as an accessor (in its own view unless ``view`` is given)."""
        arr = np.asarray(array)
        arr = arr.reshape(len(arr), -1).astype(dtype)
        if view is None:
            view = self.view(arr.tobytes())
        acc = {"bufferView": view, "byteOffset": offset, "componentType": CTYPES[arr.dtype],
               "count": len(arr), "type": TYPES[arr.shape[1]]}
        if normalized:
            acc["normalized"] = True
        if minmax:
            acc["min"] = arr.min(axis=0).tolist()
            acc["max"] = arr.max(axis=0).tolist()
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def accessor_data(self, index):
        """(N, C) float64 values of a tightly packed accessor added by :meth:`accessor`."""
        acc = self.doc["accessors"][index]
        view = self.doc["bufferViews"][acc["bufferView"]]
        dtype = {v: k for k, v in CTYPES.items()}[acc["componentType"]]
        width = {v: k for k, v in TYPES.items()}[acc["type"]]
        start = view["byteOffset"] + acc.get("byteOffset", 0)
        raw = np.frombuffer(bytes(self.bin[start:start + acc["count"] * width * dtype.itemsize]),
                            dtype=dtype)
        return raw.reshape(acc["count"], width).astype(np.float64)

    def replace_accessor(self, index, array):
        """Point accessor ``index`` at new values (a view of its own), min/max updated."""
        arr = np.asarray(array).reshape(len(array), -1).astype(np.float32)
        acc = self.doc["accessors"][index]
        acc.update(bufferView=self.view(arr.tobytes()), byteOffset=0, count=len(arr))
        if "min" in acc:
            acc.update(min=arr.min(0).tolist(), max=arr.max(0).tolist())

    def interleaved(self, arrays, dtypes):
        """Accessors for several (N, C) arrays interleaved in one strided view."""
        parts = [np.asarray(a).reshape(len(a), -1).astype(d) for a, d in zip(arrays, dtypes)]
        sizes = [p.itemsize * p.shape[1] for p in parts]
        pads = [(-s) % 4 for s in sizes]
        stride = sum(sizes) + sum(pads)
        rows = bytearray()
        for i in range(len(parts[0])):
            for p, pad in zip(parts, pads):
                rows += p[i].tobytes() + bytes(pad)
        view = self.view(bytes(rows), stride=stride)
        out, offset = [], 0
        for p, s, pad in zip(parts, sizes, pads):
            out.append(self.accessor(p, p.dtype, view=view, offset=offset))
            offset += s + pad
        return out

    def sparse(self, base, indices, values):
        """Make accessor ``base`` sparse: ``values`` replace its rows ``indices``."""
        vals = np.asarray(values).astype(np.dtype(
            {v: k for k, v in CTYPES.items()}[self.doc["accessors"][base]["componentType"]]))
        self.doc["accessors"][base]["sparse"] = {
            "count": len(indices),
            "indices": {"bufferView": self.view(np.asarray(indices, np.uint16).tobytes()),
                        "componentType": 5123},
            "values": {"bufferView": self.view(vals.tobytes())}}

    def write(self, path, container="glb"):
        """Write as ``glb``, ``embedded`` (data URI) or ``external`` (.gltf + .bin)."""
        path = Path(path)
        while len(self.bin) % 4:
            self.bin.append(0)
        doc = json.loads(json.dumps(self.doc))
        doc["buffers"] = [{"byteLength": len(self.bin)}]
        if container == "embedded":
            doc["buffers"][0]["uri"] = ("data:application/octet-stream;base64,"
                                        + base64.b64encode(bytes(self.bin)).decode())
        elif container == "external":
            (path.parent / (path.stem + " data.bin")).write_bytes(bytes(self.bin))
            doc["buffers"][0]["uri"] = path.stem + "%20data.bin"
        if container == "glb":
            text = json.dumps(doc).encode()
            text += b" " * ((-len(text)) % 4)
            body = (struct.pack("<II", len(text), 0x4E4F534A) + text
                    + struct.pack("<II", len(self.bin), 0x004E4942) + bytes(self.bin))
            path.write_bytes(b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body)
        else:
            path.write_text(json.dumps(doc))
        return path


def trs_matrix(t=(0, 0, 0), q=(0, 0, 0, 1), s=(1, 1, 1)):
    from scipy.spatial.transform import Rotation

    m = np.eye(4)
    m[:3, :3] = Rotation.from_quat(q).as_matrix() * np.asarray(s)[None, :]
    m[:3, 3] = t
    return m


def two_bone(ancestor=None, names=("root", "tip"), mode=4, **options):
    """A bar of 8 vertices along +y bound to two joints, with one clip bending the tip.

    Parameters
    ----------
    ancestor : dict, optional
        A non-joint parent node of the root joint (e.g. {"rotation": [...], "scale": [...]}).
    names : (str or None, str or None)
        Joint node names (None: unnamed).
    mode : 4, 5 or 6
        Triangle list, strip or fan.
    options : positions ("float", "quantized"), normals ("float", "byte"), layout
        ("separate", "interleaved"), sparse (bool), weights ("float", "ubyte", "ushort"),
        two_sets (bool: JOINTS_1/WEIGHTS_1 as well),
        interpolation ("LINEAR", "STEP", "CUBICSPLINE").

    Returns
    -------
    builder : GltfBuilder
    expected : dict with "positions" (8, 3), "faces" (F, 3) the triangles expected back.
    """
    b = GltfBuilder()
    y = np.repeat(np.arange(4) * 0.5, 2)
    pos = np.stack([np.tile([-0.1, 0.1], 4), y, np.zeros(8)], axis=1)
    if options.get("sparse"):
        pos_stored = pos.copy()
        pos_stored[[2, 5]] = 9.0           # wrong in the dense part, fixed by the sparse part
    else:
        pos_stored = pos
    nrm = np.tile([0.0, 0.0, 1.0], (8, 1))
    wt = np.stack([1 - y / 1.5, y / 1.5, np.zeros(8), np.zeros(8)], axis=1)
    jt = np.tile([0, 1, 0, 0], (8, 1))
    attrs = {}
    quant = options.get("positions") == "quantized"
    pos_arr, pos_dtype = (np.round(pos_stored * 1000), "int16") if quant else (pos_stored, "float32")
    nrm_arr, nrm_dtype = (np.round(nrm * 127), "int8") if options.get("normals") == "byte" \
        else (nrm, "float32")
    if options.get("layout") == "interleaved":
        attrs["POSITION"], attrs["NORMAL"] = b.interleaved([pos_arr, nrm_arr],
                                                           [pos_dtype, nrm_dtype])
    else:
        attrs["POSITION"] = b.accessor(pos_arr, pos_dtype)
        attrs["NORMAL"] = b.accessor(nrm_arr, nrm_dtype)
    if options.get("normals") == "byte":
        b.doc["accessors"][attrs["NORMAL"]]["normalized"] = True
    if options.get("sparse"):
        b.sparse(attrs["POSITION"], [2, 5], pos_arr[[2, 5]] * 0 + (
            np.round(pos[[2, 5]] * 1000) if quant else pos[[2, 5]]))
    b.doc["accessors"][attrs["POSITION"]].update(
        min=(pos_arr.min(0)).tolist(), max=(pos_arr.max(0)).tolist())
    attrs["JOINTS_0"] = b.accessor(jt, "uint8")
    kind = options.get("weights", "float")
    if options.get("two_sets"):
        # 8 influence slots: each joint's weight split over JOINTS_0 and JOINTS_1
        attrs["JOINTS_1"] = b.accessor(np.tile([1, 0, 0, 0], (8, 1)), "uint16")
        attrs["WEIGHTS_0"] = b.accessor(wt * [1.0, 0.25, 0, 0], "float32")
        attrs["WEIGHTS_1"] = b.accessor(np.stack([wt[:, 1] * 0.75, np.zeros(8), np.zeros(8),
                                                  np.zeros(8)], 1), "float32")
    elif kind == "float":
        attrs["WEIGHTS_0"] = b.accessor(wt, "float32")
    else:
        top = 255 if kind == "ubyte" else 65535
        attrs["WEIGHTS_0"] = b.accessor(np.round(wt * top), "uint8" if kind == "ubyte"
                                        else "uint16", normalized=True)
    strip = np.arange(8)
    tris = np.array([[0, 1, 3], [0, 3, 2], [2, 3, 5], [2, 5, 4], [4, 5, 7], [4, 7, 6]])
    if mode == 4:
        idx, faces = tris.ravel(), tris
    elif mode == 5:
        idx = strip
        i = np.arange(6)
        faces = np.stack([strip[i], strip[i + 1 + i % 2], strip[i + 2 - i % 2]], axis=1)
    else:
        idx = np.array([0, 1, 3, 5, 7, 6, 4, 2])
        faces = np.stack([idx[1:-1], idx[2:], np.zeros(6, int)], axis=1)
    prim = {"attributes": attrs, "indices": b.accessor(idx, "uint16"), "mode": mode}
    b.doc["meshes"].append({"primitives": [prim]})
    scale_q = 1e-3 if quant else 1.0
    # node 0 (optional ancestor), then the mesh node, then the joints
    nodes = b.doc["nodes"]
    first = 0
    if ancestor is not None:
        nodes.append(dict(ancestor, name="Armature", children=[]))
        first = 1
    mesh_node = {"mesh": 0, "skin": 0, "name": "body"}
    if quant:
        # KHR_mesh_quantization: the integer positions are scaled by a node transform; for a
        # skinned mesh the inverse bind matrices carry that scale (the node's is ignored)
        b.doc["extensionsUsed"] = b.doc["extensionsRequired"] = ["KHR_mesh_quantization"]
    nodes.append(mesh_node)
    root = {"translation": [0.0, 0.0, 0.0], "children": [len(nodes) + 1]}
    tip = {"translation": [0.0, 1.0, 0.0]}
    for node, name in zip((root, tip), names):
        if name is not None:
            node["name"] = name
    nodes += [root, tip]
    j0, j1 = len(nodes) - 2, len(nodes) - 1
    if ancestor is not None:
        nodes[0]["children"] = [j0]
        anc = trs_matrix(ancestor.get("translation", (0, 0, 0)),
                         ancestor.get("rotation", (0, 0, 0, 1)), ancestor.get("scale", (1, 1, 1)))
    else:
        anc = np.eye(4)
    bind = [anc @ trs_matrix((0, 0, 0)), anc @ trs_matrix((0, 1, 0))]
    ibm = np.stack([np.linalg.inv(m) @ np.diag([scale_q] * 3 + [1]) for m in bind])
    skin = {"joints": [j0, j1],
            "inverseBindMatrices": b.accessor(ibm.transpose(0, 2, 1).reshape(2, 16), "float32")}
    b.doc["skins"].append(skin)
    b.doc["scenes"][0]["nodes"] = [0, first] if ancestor is not None else [first, j0]
    times = np.array([0.0, 0.5, 1.0])
    half = np.sin(np.radians([0, 30, 60]) / 2)
    quats = np.stack([half, np.zeros(3), np.zeros(3), np.cos(np.radians([0, 30, 60]) / 2)], 1)
    interp = options.get("interpolation", "LINEAR")
    if interp == "CUBICSPLINE":
        tang = np.zeros((3, 4))
        tang[:, 0] = 0.4
        out = np.stack([tang, quats, -tang], axis=1).reshape(-1, 4)
    else:
        out = quats
    b.doc["animations"] = [{"name": options.get("clip_name", "bend"), "samplers": [
        {"input": b.accessor(times, "float32", minmax=True), "output": b.accessor(out, "float32"),
         "interpolation": interp}],
        "channels": [{"sampler": 0, "target": {"node": j1, "path": "rotation"}}]}]
    return b, {"positions": pos, "faces": faces, "weights": wt[:, :2]}


def _bar_primitive(b, origin, joints, rows=4, height=0.4, skinned=True, targets=None):
    """A bar of ``2 * rows`` vertices going up from ``origin``: weights blend from
    ``joints[0]`` at the bottom to ``joints[1]`` at the top (one joint: weight 1).
    ``targets``: list of (2 * rows, 3) position deltas. Returns the primitive dict."""
    y = np.repeat(np.linspace(0.0, height, rows), 2)
    pos = np.stack([np.tile([-0.05, 0.05], rows), y, np.zeros(2 * rows)], 1) + origin
    attrs = {"POSITION": b.accessor(pos, "float32", minmax=True),
             "NORMAL": b.accessor(np.tile([0.0, 0.0, 1.0], (2 * rows, 1)), "float32")}
    if skinned:
        top = y / height if len(joints) > 1 else np.zeros_like(y)
        wt = np.stack([1 - top, top, np.zeros_like(y), np.zeros_like(y)], 1)
        jt = np.tile([joints[0], joints[-1], 0, 0], (2 * rows, 1))
        attrs["JOINTS_0"] = b.accessor(jt, "uint8")
        attrs["WEIGHTS_0"] = b.accessor(wt, "float32")
    quads = [[2 * i, 2 * i + 1, 2 * i + 3, 2 * i, 2 * i + 3, 2 * i + 2] for i in range(rows - 1)]
    prim = {"attributes": attrs, "indices": b.accessor(np.ravel(quads), "uint16"), "mode": 4}
    if targets:
        prim["targets"] = [{"POSITION": b.accessor(d, "float32", minmax=True)} for d in targets]
    return prim


def two_skins_and_parts(conflict=True):
    """A figure with two skins that share joints and rigid parts, for the reader's tests.

    Nodes: 0 ``hips`` (root joint) > 1 ``spine`` > 2 ``head`` > 3 ``hat`` (a rigid mesh
    under a joint, rotated and scaled); 0 > 4 ``leg``; 5 ``body`` (skin 0: hips, spine,
    head; its mesh also has a rigid-looking second primitive), 6 ``legs`` (skin 1: hips, leg,
    stored in its own frame: its inverse binds carry an offset ``S``), 7 ``arm`` (skin 2:
    spine and head, the head's inverse bind offset differently from the spine's when
    ``conflict``: no single pre-transform serves it), 8 ``base`` (a static mesh at the scene
    root, bound to the root). One clip bends the spine and swings the leg (the root stays).

    Returns
    -------
    builder : GltfBuilder
    info : dict with "vertices" (the total drawn vertex count) and "S" (4, 4)
    """
    b = GltfBuilder()
    nodes = b.doc["nodes"]
    nodes += [{"name": "hips", "translation": [0.0, 1.0, 0.0], "children": [1, 4]},
              {"name": "spine", "translation": [0.0, 0.2, 0.0], "children": [2]},
              {"name": "head", "translation": [0.0, 0.4, 0.0], "children": [3]},
              {"name": "hat", "translation": [0.0, 0.25, 0.05], "rotation":
               [0.0, 0.3826834, 0.0, 0.9238795], "scale": [0.5, 0.5, 0.5], "mesh": 1},
              {"name": "leg", "translation": [0.1, -0.1, 0.0]},
              {"name": "body", "mesh": 0, "skin": 0},
              {"name": "legs", "mesh": 2, "skin": 1},
              {"name": "arm", "mesh": 3, "skin": 2},
              {"name": "base", "translation": [0.0, 0.0, 0.3], "mesh": 4}]
    world = {0: trs_matrix((0, 1, 0))}
    world[1] = world[0] @ trs_matrix((0, 0.2, 0))
    world[2] = world[1] @ trs_matrix((0, 0.4, 0))
    world[4] = world[0] @ trs_matrix((0.1, -0.1, 0))
    s_off = trs_matrix((0.3, -0.2, 0.1), (0, 0, 0.2588190, 0.9659258), (2, 2, 2))

    def ibm(mats):
        return b.accessor(np.stack(mats).transpose(0, 2, 1).reshape(-1, 16), "float32")

    body = [_bar_primitive(b, (0, 1.0, 0), [0, 1], height=0.6),
            _bar_primitive(b, (0.2, 1.4, 0), [2], rows=2, height=0.2)]
    # skin 1's vertices live in the frame S maps to the bind space: v_bind = S @ v_stored
    legs = _bar_primitive(b, (0, 0, 0), [0, 1], height=0.8)
    pos = np.array(b.accessor_data(legs["attributes"]["POSITION"]))
    stored = (np.c_[pos + [0.1, 0.1, 0.0], np.ones(len(pos))] @ np.linalg.inv(s_off).T)[:, :3]
    b.replace_accessor(legs["attributes"]["POSITION"], stored)
    arm_off = trs_matrix((0.0, 0.05, 0.0)) if conflict else np.eye(4)
    b.doc["meshes"] += [{"name": "body", "primitives": body},
                        {"name": "hat", "primitives": [_bar_primitive(b, (0, 0, 0), [0],
                                                                      rows=2, skinned=False)]},
                        {"name": "legs", "primitives": [legs]},
                        {"name": "arm", "primitives": [_bar_primitive(b, (0.3, 1.3, 0), [0, 1])]},
                        {"name": "base", "primitives": [_bar_primitive(b, (0, 0, 0), [0], rows=2,
                                                                       skinned=False)]}]
    inv = {k: np.linalg.inv(m) for k, m in world.items()}
    b.doc["skins"] += [{"joints": [0, 1, 2], "inverseBindMatrices": ibm([inv[0], inv[1], inv[2]])},
                       {"joints": [0, 4], "inverseBindMatrices": ibm([inv[0] @ s_off,
                                                                      inv[4] @ s_off])},
                       {"joints": [1, 2], "inverseBindMatrices": ibm([inv[1], inv[2] @ arm_off])}]
    b.doc["scenes"][0]["nodes"] = [0, 5, 6, 7, 8]
    times = np.array([0.0, 0.5, 1.0])
    ang = np.radians([0, 25, 50]) / 2
    bend = np.stack([np.sin(ang), np.zeros(3), np.zeros(3), np.cos(ang)], 1)
    swing = np.stack([np.zeros(3), np.zeros(3), np.sin(ang), np.cos(ang)], 1)
    t_acc = b.accessor(times, "float32", minmax=True)
    b.doc["animations"] = [{"name": "move", "samplers": [
        {"input": t_acc, "output": b.accessor(bend, "float32")},
        {"input": t_acc, "output": b.accessor(swing, "float32")}],
        "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}},
                     {"sampler": 1, "target": {"node": 4, "path": "rotation"}}]}]
    count = 8 + 4 + 4 + 8 + 8 + 4
    return b, {"vertices": count, "S": s_off}


def morph_bar(interpolation="LINEAR", names=("smile", "frown")):
    """:func:`two_bone`'s bar with two morph targets and a clip keying their weights.

    Target 0 moves every vertex (dense), target 1 moves two (a sparse accessor) and has
    NORMAL deltas. ``mesh.weights`` is (0.1, 0.2); the ``bend`` clip keys the weights at 0,
    0.5 and 1 s: (0, 0), (0.3, 0.7), (1, 0.25), with ``interpolation`` (CUBICSPLINE with
    in-/out-tangents of its own). ``names`` None: no ``extras.targetNames``.

    Returns
    -------
    builder : GltfBuilder
    expected : dict of two_bone's plus "deltas" (2, 8, 3)
    """
    b, expected = two_bone()
    prim = b.doc["meshes"][0]["primitives"][0]
    d0 = np.stack([np.zeros(8), np.zeros(8), np.linspace(0, 0.2, 8)], 1)
    d1 = np.zeros((8, 3))
    d1[[3, 6]] = [[0.05, 0.0, 0.0], [0.0, 0.1, -0.05]]
    n1 = np.zeros((8, 3))
    n1[[3, 6]] = [[0.5, 0.0, 0.0], [0.0, 0.5, 0.0]]
    t0 = {"POSITION": b.accessor(d0, "float32", minmax=True)}
    base = b.accessor(np.zeros((8, 3)), "float32")
    b.sparse(base, [3, 6], d1[[3, 6]])
    b.doc["accessors"][base].pop("bufferView")
    b.doc["accessors"][base].pop("byteOffset")
    b.doc["accessors"][base].update(min=d1.min(0).tolist(), max=d1.max(0).tolist())
    t1 = {"POSITION": base, "NORMAL": b.accessor(n1, "float32")}
    prim["targets"] = [t0, t1]
    mesh = b.doc["meshes"][0]
    mesh["weights"] = [0.1, 0.2]
    if names is not None:
        mesh["extras"] = {"targetNames": list(names)}
    times = np.array([0.0, 0.5, 1.0])
    values = np.array([[0.0, 0.0], [0.3, 0.7], [1.0, 0.25]])
    if interpolation == "CUBICSPLINE":
        tangents = np.array([[0.5, -0.2], [1.0, 0.4], [-0.3, 0.0]])
        out = np.stack([tangents, values, -tangents], axis=1)
    else:
        out = values
    anim = b.doc["animations"][0]
    anim["samplers"].append({"input": b.accessor(times, "float32", minmax=True),
                             "output": b.accessor(out.reshape(-1, 1), "float32"),
                             "interpolation": interpolation})
    mesh_node = next(i for i, n in enumerate(b.doc["nodes"]) if n.get("mesh") == 0)
    anim["channels"].append({"sampler": len(anim["samplers"]) - 1,
                             "target": {"node": mesh_node, "path": "weights"}})
    return b, dict(expected, deltas=np.stack([d0, d1]), normal_deltas=np.stack([np.zeros((8, 3)), n1]))


def deep_chain(n, rigid_chain=False):
    """A skin of ``n`` joints in one chain (each the child of the last) and one skinned bar;
    with ``rigid_chain`` also a chain of ``n`` non-joint nodes each holding a rigid mesh."""
    b = GltfBuilder()
    nodes = b.doc["nodes"]
    for i in range(n):
        nodes.append({"name": f"j{i}", "translation": [0.0, 0.001, 0.0],
                      **({"children": [i + 1]} if i < n - 1 else {})})
    b.doc["meshes"] += [{"primitives": [_bar_primitive(b, (0, 0, 0), [0], rows=2)]},
                        {"primitives": [_bar_primitive(b, (0, 0, 0), [0], rows=2,
                                                       skinned=False)]}]
    ibm = np.tile(np.eye(4), (n, 1, 1)).reshape(n, 16)
    b.doc["skins"].append({"joints": list(range(n)), "inverseBindMatrices": b.accessor(ibm)})
    nodes.append({"mesh": 0, "skin": 0})
    b.doc["scenes"][0]["nodes"] = [0, n]
    if rigid_chain:
        base = len(nodes)
        for i in range(n):
            nodes.append({"mesh": 1, "translation": [0.001, 0.0, 0.0],
                          **({"children": [base + i + 1]} if i < n - 1 else {})})
        b.doc["scenes"][0]["nodes"].append(base)
    return b
