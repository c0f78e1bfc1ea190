"""File > Import motion onto this character: retarget a BVH, glTF or rig folder's clip onto
the open rig (:func:`rigedit.rigging.retarget_result`) and add it as a new clip.

Reading the motion and retargeting run off the UI thread (:meth:`MainWindow.run_job`; the
retarget cannot report its progress, so the bar is indeterminate). The new clip is added by the
timeline as one undo step and becomes the current clip. Bad input (an unreadable file, a motion
whose joints map to nothing, a target without legs) gives one message naming the file, and the
document is left as it was.
"""
from __future__ import annotations

import warnings
from pathlib import Path
from types import SimpleNamespace

from PyQt5 import QtWidgets

from ..animation.clip_names import check_clip_name

__all__ = ["ImportMotion", "motion_path"]

FILTERS = ("Motion (*.bvh *.glb *.gltf skeleton.json);;BVH (*.bvh);;glTF (*.glb *.gltf);;"
           "Rig folder (skeleton.json)")


def motion_path(path):
    """The path :func:`rigedit.load_rig` reads for a chosen file: a rig folder is chosen by
    its ``skeleton.json`` (one file dialog for files and folders), other files as they are."""
    path = Path(path)
    return path.parent if path.name.lower() == "skeleton.json" else path


def _load_motion(path):
    import rigedit

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a BVH's unit guess is expected, not an error
        return rigedit.load_rig(path)


def _clip_name(path, source_clip, several):
    """The new clip's base name: the motion file's stem (the clip's own name when the file
    holds several), or ``imported motion`` when that is no valid clip name."""
    base = f"{path.stem} {source_clip}" if several else path.stem
    try:
        return check_clip_name(base.strip())
    except ValueError:
        return "imported motion"


class ImportMotion:
    """The import of a :class:`~rigedit.ui.main_window.MainWindow` (kept apart from
    :class:`~rigedit.ui.file_actions.FileActions` to keep modules small)."""

    def __init__(self, window):
        self.w = window

    def run(self, path=None):
        """Ask for a motion file (or take ``path``) and start reading it. Returns the job."""
        if not isinstance(path, (str, Path)):  # a menu action's "checked" argument
            path = None
        if path is None:
            path, _ = QtWidgets.QFileDialog.getOpenFileName(
                self.w, "Import motion onto this character", "", FILTERS)
        if not path:
            return None
        path = motion_path(path)
        return self.w.run_job(f"Reading {path.name}", lambda report: _load_motion(path),
                              lambda source: self._loaded(path, source))

    def _loaded(self, path, source):
        """Pick the clip (asking when there are several), then retarget off the UI thread."""
        names = list(source.clips)
        if not names:
            raise ValueError(f"{path}: expected a clip to import, got none")
        name = names[0]
        if len(names) > 1:
            name, ok = QtWidgets.QInputDialog.getItem(
                self.w, "Import motion", f"Clip of {path.name}:", names, 0, False)
            if not ok:
                self.w.status("Import motion: cancelled")
                return None
        doc = self.w.document
        rig, skeleton = doc.rig, doc.skeleton
        # the job reads a snapshot of the clips: the user may edit them meanwhile
        target = SimpleNamespace(skeleton=skeleton, clips=dict(doc.clips))
        base = _clip_name(path, name, len(names) > 1)

        def work(report):
            from ..rigging import retarget_result

            report(None)
            return retarget_result(source, name, target, source_what=str(path),
                                   target_what=rig.name or "this character")

        return self.w.run_job(f"Retargeting {path.name}", work,
                              lambda res: self._done(path, res, base, rig, skeleton,
                                                     len(source.skeleton)))

    def _done(self, path, res, base, rig, skeleton, n_source):
        doc = self.w.document
        if doc.rig is not rig or doc.skeleton is not skeleton:
            what = "another rig was opened" if doc.rig is not rig else "the skeleton changed"
            self.w.error("Import motion", f"{path}: import dropped: {what} while it was "
                                          f"retargeted; import it again")
            return None
        clip = res.clip
        added = self.w.timeline.add_clip(clip, base, f"Import motion {path.name}")
        if added is None:
            return None
        mapped = len(res.mapping)
        self.w.status(
            f"Imported {path.name} as clip {added!r} ({clip.duration:.2f} s): joint map "
            f"{mapped} mapped, {len(skeleton) - mapped} of this character's joints unmapped, "
            f"{n_source - mapped} of the motion's unused")
        return added
