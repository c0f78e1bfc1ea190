"""What the window uses of animation compression (issue 20): File > Export compressed and
View > Compare compressed. Pure Python: no Qt, no VTK.

:class:`CompressedExport` takes what the document holds when it is made (on the main thread:
the rig's data with copies of the chosen clips) and writes it in :meth:`~CompressedExport.run`
(safe in a worker): ``.glb``/``.gltf`` through :func:`rigedit.io.gltf_compress
.save_gltf_compressed_rig` (the bound checked on the file as read), ``.rgc`` (rigedit's
compressed clip file, :mod:`rigedit.io.compressed_file`), or a rig folder whose clips are
``animations/NAME.rgc`` compressed clip files. These are the calls ``rigedit compress`` makes
(:func:`rigedit.cli.compress.compress_and_write`, which the editor may not import).
Every writer writes a temporary file and renames it: a failed export leaves what was there.

:class:`CompressedPreview` compresses the current clip once per (clip, revision, duration,
loop, skeleton, bound, shell) and says at any time where the compressed skeleton's joints
are and how far each one's virtual vertices are from the original's.
"""
from __future__ import annotations

import dataclasses
import os
from pathlib import Path
from types import MappingProxyType

import numpy as np

from ..animation.clip import Clip
from ..compression import CompressedClip, check_max_error, compress_clips
from ..compression.frames import frame_times, sample_local
from ..compression.virtual import (DEFAULT_SHELL, check_shell, local_offsets, model_matrices,
                                   shell_distances, vertex_error)
from ..errors import RigFileError
from ..model.pose import Pose

__all__ = ["GLTF_SUFFIXES", "COMPRESSED_SUFFIX", "CompressedExport", "export_compressed",
           "output_kind", "CompressedPreview", "PreviewEntry", "ReadOnlyCompressedClip",
           "shown_clips"]

GLTF_SUFFIXES = (".glb", ".gltf")
#: rigedit's compressed clip file (:data:`rigedit.io.compressed_file.SUFFIX`).
COMPRESSED_SUFFIX = ".rgc"


def output_kind(path):
    """``"gltf"``, ``"rgc"`` or ``"folder"`` for an export path; ``ValueError`` for another
    file suffix (a path without one, or an existing folder, is a rig folder)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in GLTF_SUFFIXES:
        return "gltf"
    if suffix == COMPRESSED_SUFFIX:
        return "rgc"
    if not suffix or path.is_dir():
        return "folder"
    raise ValueError(f"{path}: expected a .glb, .gltf or {COMPRESSED_SUFFIX} file or a "
                     f"folder, got {suffix!r}")


class CompressedExport:
    """One export of compressed clips, prepared on the main thread, written by :meth:`run`.

    Parameters
    ----------
    document : Document
    path : str or Path
        ``.glb``/``.gltf``, ``.rgc`` or a folder (:func:`output_kind`).
    max_error : float
        Metres, > 0: no virtual vertex of any frame strays further.
    shell : float
        Metres from each joint to its virtual vertices.
    clips : list of str, optional
        The clips to write; all the rig's when None.
    meshopt : bool
        glTF only: the buffers also compressed with ``EXT_meshopt_compression``.

    Raises
    ------
    ValueError
        A bound or shell that is not a positive finite number, an unknown clip, a rig
        without clips, a clip that is already compressed, another suffix, or ``meshopt``
        for a file that is not glTF or without the meshopt package.
    """

    def __init__(self, document, path, max_error, shell=DEFAULT_SHELL, clips=None,
                 meshopt=False):
        self.path = Path(path)
        self.kind = output_kind(self.path)
        self.max_error = check_max_error(max_error)
        self.shell = check_shell(shell)
        self.meshopt = bool(meshopt)
        rig = document.rig
        names = list(rig.clips) if clips is None else list(dict.fromkeys(clips))
        unknown = [n for n in names if n not in rig.clips]
        if unknown:
            raise ValueError(f"unknown clip {unknown[0]!r}; the rig has "
                             f"{', '.join(rig.clips) or 'none'}")
        if not names:
            raise ValueError(f"{rig.name} has no clip to compress")
        packed = [n for n in names if not isinstance(rig.clips[n], Clip)]
        if packed:
            raise ValueError(f"clip {packed[0]!r} is compressed already (read from a "
                             f"{COMPRESSED_SUFFIX} file): it is written as it is by File > "
                             "Export, not compressed again")
        if self.meshopt:
            from ..io.gltf_write_compact import meshopt_available

            if self.kind != "gltf":
                raise ValueError(f"meshopt: expected a .glb or .gltf file, got {self.path}")
            if not meshopt_available():
                raise ValueError("meshopt: needs the meshopt package (pip install "
                                 "'rigedit[meshopt]')")
        self.names = names
        # the worker reads these, never the document the user goes on editing
        self.data = dataclasses.replace(rig.data(), clips={n: rig.clips[n].copy()
                                                           for n in names})

    def run(self, progress=None):
        """Compress and write (safe in a worker thread).

        Parameters
        ----------
        progress : callable, optional
            ``progress(fraction, stage)`` (:mod:`rigedit.progress`); its ``Cancelled`` stops
            the work before anything is written.

        Returns
        -------
        CompressionReport
            Errors of what was written as it reads back; sizes as stored.

        Raises
        ------
        RigFileError
            Naming the file: a bound no compression reaches, or the write failed.
        """
        report = progress or (lambda fraction, stage=None: None)
        report(None, "compress")
        bound = dict(max_error=self.max_error, shell=self.shell)
        data = self.data
        try:
            if self.kind == "gltf":
                return self._gltf(report, bound)
            result = compress_clips(data.skeleton, data.clips, target="rigedit",
                                    progress=report, **bound)
            report(1.0, "write")
            if self.kind == "rgc":
                from ..io.compressed_file import save_compressed

                save_compressed(self.path, data.skeleton, result.clips)
            else:   # a rig folder: each clip as animations/NAME.rgc beside mesh and skeleton
                from .. import save_rig

                save_rig(dataclasses.replace(data, clips=result.clips), self.path)
            return result.report
        except ValueError as exc:   # a bound no encoding reaches (RigFileError passes)
            if isinstance(exc, RigFileError):
                raise
            raise RigFileError(self.path, str(exc)) from None


    def _gltf(self, report, bound):
        """Compact glTF written beside ``path`` and renamed onto it once ``report`` (its last
        chance to cancel: the compressor takes no progress) lets it."""
        from ..io.gltf_compress import save_gltf_compressed_rig

        path = self.path
        partial = path.with_name(f".{path.stem}.{os.getpid()}.partial{path.suffix}")
        try:
            result = save_gltf_compressed_rig(self.data, partial, self.names,
                                              meshopt=self.meshopt, **bound)
            report(1.0, "write")
            os.replace(partial, path)
        finally:
            partial.unlink(missing_ok=True)
        return result


def export_compressed(document, path, max_error, shell=DEFAULT_SHELL, clips=None,
                      meshopt=False, progress=None):
    """:class:`CompressedExport` made and run in one call (scripts, tests); returns the
    :class:`~rigedit.compression.CompressionReport`."""
    return CompressedExport(document, path, max_error, shell, clips, meshopt).run(progress)


# ---------------------------------------------------------------------- the comparison
@dataclasses.dataclass
class PreviewEntry:
    """One compressed clip of the comparison (made by :meth:`CompressedPreview.compute`).

    Attributes
    ----------
    key : tuple
        What it was made from (:attr:`CompressedPreview.key`).
    original : Clip
        The copy of the clip that was compressed.
    compressed : CompressedClip
    report : CompressionReport
    times : (F,) float64
        The frames checked (seconds).
    errors : (F, J) float64
        Metres, each joint's virtual-vertex error at each frame (<= the bound).
    """

    key: tuple
    original: Clip
    compressed: CompressedClip
    report: object
    times: np.ndarray
    errors: np.ndarray


class CompressedPreview:
    """The document's current clip compressed, for View > Compare compressed.

    Parameters
    ----------
    document : Document
    max_error : float
        Metres, > 0.
    shell : float
        Metres from each joint to its virtual vertices.

    The compression itself (:meth:`compute`, ~0.1-0.5 s for the bundled quadruped's clips)
    may run in a worker on a :meth:`snapshot`; :meth:`accept` puts its result in place.
    :meth:`refresh` does all three in the calling thread when the cached entry is stale.
    """

    def __init__(self, document, max_error, shell=DEFAULT_SHELL):
        self.document = document
        self.max_error = check_max_error(max_error)
        self.shell = check_shell(shell)
        self.entry = None
        self._offsets = None   # (skeleton, (J,) local shell distances)
        self._poses = None     # (reference, candidate) Pose reused by at()

    # ------------------------------------------------------------------ the cache
    @property
    def key(self):
        """What the comparison depends on now: the current clip (name, object, revision,
        duration, loop), the skeleton and the settings; None without a clip."""
        d = self.document
        clip = d.clip
        if clip is None:
            return None
        return (d.current_clip, id(clip), getattr(clip, "revision", 0), clip.duration,
                clip.loop, id(d.skeleton), self.max_error, self.shell)

    @property
    def stale(self):
        """Whether the document's clip or skeleton changed since the entry was made."""
        return self.entry is None or self.entry.key != self.key

    def snapshot(self):
        """``(key, skeleton, clip copy)`` to :meth:`compute` from, taken now.

        Raises
        ------
        ValueError
            Without a current clip, or for a clip that is compressed already.
        """
        d = self.document
        clip = d.clip
        if clip is None:
            raise ValueError("no clip to compare: open or create a clip first")
        if not isinstance(clip, Clip):
            raise ValueError(f"clip {d.current_clip!r} is compressed already (read from a "
                             f"{COMPRESSED_SUFFIX} file): it has no original to compare with")
        return self.key, d.skeleton, clip.copy()

    def compute(self, snapshot, progress=None):
        """Compress the snapshot's clip and measure every frame (safe in a worker).

        Returns
        -------
        PreviewEntry
        """
        key, skeleton, clip = snapshot
        result = compress_clips(skeleton, {clip.name: clip}, max_error=self.max_error,
                                shell=self.shell, target="rigedit", progress=progress)
        compressed = result.clips[clip.name]
        times = frame_times(clip)
        errors = self._measure(skeleton, sample_local(clip, times, skeleton),
                               compressed.sample_many(times))[0]
        return PreviewEntry(key, clip, compressed, result.report, times, errors)

    def accept(self, entry):
        """Use ``entry``; False (and the old entry kept) when the document changed since
        its snapshot, so it is stale already."""
        if entry.key != self.key:
            return False
        self.entry = entry
        return True

    def refresh(self, progress=None):
        """Compress the current clip now unless the entry is up to date; returns the entry."""
        if self.stale:
            self.accept(self.compute(self.snapshot(), progress))
        return self.entry

    # ------------------------------------------------------------------ what it shows
    def _entry(self):
        if self.entry is None:
            raise ValueError("nothing compressed yet: refresh() or compute() first")
        return self.entry

    @property
    def errors(self):
        """(F, J) float64 metres at :attr:`times`."""
        return self._entry().errors

    @property
    def times(self):
        return self._entry().times

    @property
    def report(self):
        return self._entry().report

    def _measure(self, skeleton, reference, candidate):
        """``(errors (N, J), candidate model matrices (N, J, 4, 4))`` of local poses
        (N, J, 10) against reference ones: one forward kinematics for both."""
        if self._offsets is None or self._offsets[0] is not skeleton:
            self._offsets = (skeleton, local_offsets(skeleton,
                                                     shell_distances(skeleton, self.shell)))
        both = model_matrices(skeleton, np.concatenate([reference, candidate]))
        n = len(reference)
        return vertex_error(both[:n], both[n:], self._offsets[1]), both[n:]

    def at(self, t):
        """The compressed pose at playback time ``t`` and its error there.

        Returns
        -------
        positions : (J, 3) float64
            The compressed pose's joint positions in model space.
        errors : (J,) float64
            Each joint's virtual-vertex error at ``t`` (metres): measured at ``t`` itself,
            so between the checked frames it is what is on screen, not a frame's.
        """
        e = self._entry()
        skeleton = e.compressed.skeleton   # the one compressed for (a rest edit makes it stale)
        if self._poses is None or self._poses[0].skeleton is not skeleton:
            self._poses = (Pose(skeleton), Pose(skeleton))
        # one pose each through the clips' own samplers: ~10x less than sample_local's
        # vectorised path costs for a single time (measured, 27 tracks)
        reference, candidate = (clip.sample(float(t), out=pose).as_array()[None]
                                for clip, pose in zip((e.original, e.compressed), self._poses))
        errors, model = self._measure(skeleton, reference, candidate)
        return model[0, :, :3, 3].copy(), errors[0]

    def summary(self, frame_errors=None):
        """One line: ``compressed 18.2:1, max error 0.0097 cm, this frame 0.0041 cm``
        (``frame_errors``: (J,) metres, :meth:`at`'s, for the last part)."""
        r = self.report
        line = f"compressed {r.ratio:.1f}:1, max error {r.max_error * 100:.4f} cm"
        if frame_errors is not None:
            line += f", this frame {float(np.max(frame_errors)) * 100:.4f} cm"
        return line


# ---------------------------------------------------------------------- compressed clips opened
#: What a plain clip can do that a compressed one refuses (its keys are its bits).
_EDITS = ("state", "restore", "set_track", "remove_track", "set_morph_track",
          "remove_morph_track", "set_morph_key", "set_key", "key_pose", "delete_keys",
          "move_keys", "paste_keys", "set_interpolation", "set_duration")


def _refuse(name):
    def refused(self, *args, **kwargs):
        raise ValueError(f"clip {self.name!r} is compressed (played as stored): its keys "
                         "cannot be edited; Duplicate it (a plain copy of its keys) to edit")
    refused.__name__ = name
    refused.__doc__ = "Refused: a compressed clip is not edited (``ValueError``)."
    return refused


class ReadOnlyCompressedClip(CompressedClip):
    """A compressed clip as the window holds it: its stored keys
    (:meth:`CompressedClip.plain`) as a read-only ``tracks`` mapping, the pose decoded from
    its bits, and every key edit one ``ValueError`` that says why, before anything changes
    (a plain :class:`CompressedClip` has no edit methods: an edit was an ``AttributeError``).
    :meth:`copy` (Duplicate) gives a plain, editable clip of the stored keys.

    Parameters
    ----------
    clip : CompressedClip
    """

    def __init__(self, clip):
        super().__init__(clip.skeleton, clip.blob)

    @property
    def tracks(self):
        """``{(joint name, channel): Track}`` of the stored keys, read-only."""
        return MappingProxyType(self.plain().tracks)

    def copy_keys(self, t, joints=None):
        """The stored keys' values at ``t`` (Copy works; Paste goes into a plain clip)."""
        return self.plain().copy_keys(t, joints)


for _edit in _EDITS:
    setattr(ReadOnlyCompressedClip, _edit, _refuse(_edit))


def shown_clips(rig):
    """``rig`` with each :class:`CompressedClip` of ``rig.clips`` replaced (in place) by a
    :class:`ReadOnlyCompressedClip` of the same bits, as the window opens it; returns it."""
    for name, clip in list(rig.clips.items()):
        if isinstance(clip, CompressedClip) and not isinstance(clip, ReadOnlyCompressedClip):
            rig.clips[name] = ReadOnlyCompressedClip(clip)
    return rig
