"""Many curves sampled in one vectorised call: a clip's bezier tracks, packed once.

Sampling a pose one curve at a time costs a dozen numpy calls per curve (about 0.1 ms each on
a loaded machine), so a 60-joint pose of bezier tracks would take tens of milliseconds. A
:class:`CurvePack` concatenates the segments of all curves; a sample then finds every curve's
segment with one ``searchsorted`` (each curve's keys shifted into its own time window) and
evaluates all segments together (:func:`~rigedit.animation.curve.evaluate`). A
:class:`BezierTracks` packs a clip's bezier tracks and converts their rotations from Euler
angles in one call per Euler order, writing each pose field with one indexed assignment.
:class:`~rigedit.animation.clip.Clip` keeps one, rebuilt when its ``revision`` changes.
"""
from __future__ import annotations

import numpy as np

from .curve import evaluate
from .euler_curves import euler_to_quat

__all__ = ["CurvePack", "BezierTracks"]


class CurvePack:
    """Curves sampled together.

    Parameters
    ----------
    curves : list of Curve
    """

    def __init__(self, curves):
        n = len(curves)
        counts = np.array([len(c) for c in curves])
        self.first = np.array([c.times[0] for c in curves])
        self.last = np.array([c.times[-1] for c in curves])
        lo = float(self.first.min()) if n else 0.0
        self._lo = lo
        self._window = float((self.last.max() - lo) + 1.0) if n else 1.0
        shifted = [c.times - lo + i * self._window for i, c in enumerate(curves)]
        self._keys = np.concatenate(shifted) if n else np.zeros(0)
        self._key_offset = np.r_[0, np.cumsum(counts)[:-1]].astype(int)
        self._segments_count = np.maximum(counts - 1, 0)
        multi = [c for c in curves if len(c) > 1]
        self._points = (np.concatenate([c.segments() for c in multi]) if multi
                        else np.zeros((0, 4, 2)))
        self._codes = (np.concatenate([c.codes()[:-1] for c in multi]) if multi
                       else np.zeros(0, np.int8))
        # segments of the multi-key curves only: offsets counted over those
        seg_counts = np.where(counts > 1, counts - 1, 0)
        self._segment_offset = np.r_[0, np.cumsum(seg_counts)[:-1]].astype(int)
        self._single = counts == 1
        self._single_value = np.array([c.values[0] for c in curves])
        self._offsets = np.arange(n) * self._window - lo

    def __len__(self):
        return len(self.first)

    def sample(self, t):
        """(n,) value of every curve at time ``t`` (each clamped to its keys)."""
        tq = np.clip(float(t), self.first, self.last)
        out = self._single_value.copy()
        multi = ~self._single
        if not multi.any():
            return out
        pos = np.searchsorted(self._keys, tq + self._offsets, side="right") - 1
        local = np.clip(pos - self._key_offset, 0, np.maximum(self._segments_count - 1, 0))
        seg = (self._segment_offset + local)[multi]
        out[multi] = evaluate(self._points[seg], self._codes[seg], tq[multi])
        return out


class BezierTracks:
    """A clip's tracks split for sampling: the bezier ones packed together, the others kept
    as a list.

    Parameters
    ----------
    tracks : dict[(str, str), Track]
    index : dict[str, int]
        Joint name -> pose row (the skeleton's ``index``).
    """

    def __init__(self, tracks, index):
        self.plain = [(index[j], c, tr) for (j, c), tr in tracks.items() if tr.curves is None]
        keys = [k for k, tr in tracks.items() if tr.curves is not None]
        chosen = [tracks[k] for k in keys]
        self.pack = CurvePack([c for tr in chosen for c in tr.curves])
        # per pose field, the pose rows and the pack rows (tracks) that fill them
        self.vectors = []
        for channel in ("translation", "scale"):
            rows = [i for i, k in enumerate(keys) if k[1] == channel]
            if rows:
                self.vectors.append((channel, np.array([index[keys[i][0]] for i in rows]),
                                     np.array(rows)))
        self.rotations = []
        for order in sorted({tr.euler_order for tr in chosen if tr.channel == "rotation"}):
            rows = [i for i, k in enumerate(keys)
                    if k[1] == "rotation" and chosen[i].euler_order == order]
            self.rotations.append((order, np.array([index[keys[i][0]] for i in rows]),
                                   np.array(rows)))
        self.count = len(keys)

    def __len__(self):
        return self.count

    def write(self, pose, t):
        """Set the pose's values of every bezier track at clip time ``t``."""
        if not self.count:
            return
        v = self.pack.sample(t).reshape(-1, 3)
        for channel, joints, rows in self.vectors:
            getattr(pose, channel)[joints] = v[rows]
        for order, joints, rows in self.rotations:
            pose.rotation[joints] = euler_to_quat(v[rows], order)
