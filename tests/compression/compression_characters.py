"""Test characters that break compressors: long chains, flips, constant and scale tracks,
very short and non-looping clips, translation-only joints (numpy only, built in code)."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from rigedit.animation import Clip, Track
from rigedit.model import Skeleton


def chain(n=10, length=0.1):
    """``n`` joints along +Y, ``length`` metres apart."""
    t = np.zeros((n, 3))
    t[1:, 1] = length
    return Skeleton([f"j{i}" for i in range(n)], np.arange(n) - 1, t)


def smooth_rotations(frames, rate=30.0, amplitude=0.6, seed=0, phase=0.0):
    """(frames, 4) quaternions of a smooth random swing (a few sines per axis)."""
    rng = np.random.default_rng(seed)
    t = np.arange(frames) / rate
    freq = rng.uniform(0.3, 2.0, size=3)
    rotvec = amplitude * np.sin(2 * np.pi * freq[None] * t[:, None] + phase
                                + rng.uniform(0, 6.3, 3))
    return Rotation.from_rotvec(rotvec).as_quat()


def mocap_clip(skeleton, frames=240, rate=120.0, seed=0, loop=False, root_translation=True,
               name="take"):
    """Every joint's rotation keyed at every frame (BVH-like), the root also translating."""
    t = np.arange(frames) / rate
    tracks = {}
    for j, joint in enumerate(skeleton.names):
        tracks[(joint, "rotation")] = Track("rotation", t, smooth_rotations(
            frames, rate, amplitude=0.4, seed=seed + j))
    if root_translation:
        move = np.column_stack([0.5 * t, 0.02 * np.sin(4 * t), 0.1 * np.cos(t)])
        tracks[(skeleton.names[0], "translation")] = Track("translation", t, move)
    return Clip(name, skeleton, tracks, loop=loop)
