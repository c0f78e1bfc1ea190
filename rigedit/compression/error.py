"""The error of one clip against another, measured where it is seen (virtual vertices)."""
from __future__ import annotations

import numpy as np

from .frames import frame_times, sample_local
from .virtual import DEFAULT_SHELL, local_offsets, model_matrices, shell_distances, vertex_error

__all__ = ["measure_error", "ErrorMeter"]


class ErrorMeter:
    """Virtual-vertex error of candidates against one reference clip at fixed times.

    The reference's model matrices are computed once; :meth:`error` then costs one FK of the
    candidate. Parameters as :func:`measure_error`.
    """

    def __init__(self, skeleton, reference_clip, times=None, shell=DEFAULT_SHELL, mesh=None):
        self.skeleton = skeleton
        self.times = frame_times(reference_clip) if times is None else \
            np.asarray(times, dtype=np.float64).reshape(-1)
        self.offsets = local_offsets(skeleton, shell_distances(skeleton, shell, mesh))
        self.local = sample_local(reference_clip, self.times, skeleton)
        self.model = model_matrices(skeleton, self.local)

    def error_of_local(self, local):
        """(F, J) error of local poses (F, J, 10) at :attr:`times`."""
        return vertex_error(self.model, model_matrices(self.skeleton, local), self.offsets)

    def error(self, clip):
        """(F, J) error of ``clip`` (anything :func:`sample_local` samples)."""
        return self.error_of_local(sample_local(clip, self.times, self.skeleton))


def measure_error(skeleton, reference_clip, candidate_clip, times=None, shell=DEFAULT_SHELL,
                  mesh=None):
    """Per frame and joint the largest virtual-vertex distance between two clips.

    Parameters
    ----------
    skeleton : Skeleton
    reference_clip, candidate_clip : Clip or any object with ``sample(t, out)``
        A :class:`CompressedClip` and a plain :class:`Clip` are sampled all frames at once.
    times : (F,) float, optional
        Playback times; the reference's frames (:func:`~rigedit.compression.frames.frame_times`:
        its key times plus its frame-rate sampling) when omitted.
    shell : float
        Metres from each joint to its three virtual vertices (ACL's 3 cm by default).
    mesh : (vertices (V, 3), indices (V, K), weights (V, K)), optional
        Take each joint's shell from the skin instead (see
        :func:`~rigedit.compression.virtual.shell_distances`).

    Returns
    -------
    error : (F, J) float64
        Metres, in model space.
    """
    return ErrorMeter(skeleton, reference_clip, times, shell, mesh).error(candidate_clip)
