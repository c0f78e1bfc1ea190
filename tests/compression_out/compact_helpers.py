"""What the compressed-output tests share: the Khronos validator run, and a clip of reduced
keys built by hand (so the writer is tested apart from the compressor)."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from rigedit.animation.clip import Clip, Track


def validate(path):
    """The Khronos glTF Validator's ``issues`` of ``path``; skips without the validator."""
    script = os.environ.get("RIGEDIT_GLTF_VALIDATOR")
    if not script or not Path(script).is_file() or shutil.which("node") is None:
        pytest.skip("set RIGEDIT_GLTF_VALIDATOR to tests/gltf_validator.js and NODE_PATH to "
                    "a node_modules with gltf-validator (python3 dev.py test does)")
    run = subprocess.run(["node", script, str(path)], capture_output=True, text=True,
                         timeout=120)
    return json.loads(run.stdout)["issues"]


def reduced_clip(rig, name="walk", every=4, duration_extra=0.0):
    """A clip like a compressor's glTF output: every ``every``-th key of ``rig``'s clip
    ``name`` (rotations slerp, the rest linear; the last key kept), the hips' translation as
    Catmull-Rom, a scale track that holds the rest (one key) and one that holds 1.5 on the
    first joint without a scale track."""
    src = rig.clips[name]
    sk = rig.skeleton
    tracks = {}
    for (joint, channel), tr in src.tracks.items():
        keep = np.unique(np.r_[np.arange(0, len(tr.times), every), len(tr.times) - 1])
        mode = "slerp" if channel == "rotation" else "linear"
        if channel == "translation" and sk.joint_index(joint) == 0 and len(keep) > 2:
            mode = "catmull_rom"
        tracks[(joint, channel)] = Track(channel, tr.times[keep], tr.values[keep], mode)
    free = [n for n in sk.names if (n, "scale") not in tracks]
    tracks[(free[0], "scale")] = Track("scale", [0.0], [sk.rest_scale[sk.joint_index(free[0])]])
    tracks[(free[1], "scale")] = Track("scale", [0.0], [[1.5, 1.5, 1.5]])
    return Clip(f"{name}_reduced", sk, tracks, duration=src.duration + duration_extra,
                loop=src.loop)


def decoded_rotation(values):
    """What a reader gets from normalised SHORT rotations written from ``values`` (K, 4)."""
    ints = np.clip(np.round(np.asarray(values) * 32767.0), -32767, 32767)
    q = np.maximum(ints / 32767.0, -1.0)
    return q / np.linalg.norm(q, axis=1, keepdims=True)
