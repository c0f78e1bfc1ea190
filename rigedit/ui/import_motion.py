"""File > Import motion onto this character: retarget a BVH, glTF or rig folder's clip onto
the open rig and add it as a new clip; the work is :mod:`rigedit.editor.import_motion`'s.

Reading the motion and retargeting run off the UI thread (:class:`~rigedit.ui.jobs.JobRunner`; the
retarget cannot report its progress, so the bar is indeterminate). The joint map used is then
shown (:class:`~rigedit.ui.joint_map_dialog.JointMapDialog`, not modal: the character stays in
view): it can be edited there or loaded from JSON and the retarget run again, and saved, as
``rigedit retarget --map/--save-map`` do. Add clip adds the clip by the timeline as one undo
step and makes it current. Bad input (an unreadable file, a motion whose joints map to nothing,
a target without legs, a map naming unknown joints) gives one message naming the file, and the
document is left as it was; when the retarget fails, the map stays open to be mended.
"""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from PyQt5 import QtWidgets

from ..editor import import_motion as motion
from ..editor.import_motion import motion_path
from .menus import make_action

__all__ = ["ImportMotion", "motion_path"]

MAP_FILTERS = "Joint map (*.json);;All files (*)"
FILTERS = ("Motion (*.bvh *.glb *.gltf *.fbx skeleton.json);;BVH (*.bvh);;glTF (*.glb *.gltf);;"
           "FBX (*.fbx);;Rig folder (skeleton.json)")


def _names(names, most=8):
    """``a, b, c`` or ``a, b, ... and 7 more`` (a status line stays short)."""
    shown = ", ".join(names[:most])
    return shown if len(names) <= most else f"{shown} and {len(names) - most} more"


class ImportMotion:
    """File > Import motion onto this character.

    Parameters
    ----------
    document : Document
    services : Services
    add_clip : callable
        ``add_clip(clip, base_name, label)`` adds the clip as one undo step and returns its
        name, or None (the timeline's :meth:`ClipManager.add_clip
        <rigedit.ui.timeline_clips.ClipManager.add_clip>`).
    """

    def __init__(self, document, services, add_clip):
        self.document = document
        self.services = services
        self.parent = services.parent
        self.status = services.status
        self.error = services.error
        self.add_clip = add_clip
        self.ctx = None      # the import under way: motion, clip, target, last result
        self.dialog = None   # its joint map dialog

    def actions(self):
        """name -> QAction for :func:`.menus.build_menus`."""
        return {"import_motion": make_action(
            self.parent, "Import motion onto this character...", self.run,
            tip="Retarget a BVH, glTF or rig folder's clip onto this character as a new clip")}

    def run(self, path=None):
        """Ask for a motion file (or take ``path``) and start reading it. Returns the job."""
        if not isinstance(path, (str, Path)):  # a menu action's "checked" argument
            path = None
        if path is None:
            path, _ = QtWidgets.QFileDialog.getOpenFileName(
                self.parent, "Import motion onto this character", "", FILTERS)
        if not path:
            return None
        path = motion_path(path)
        return self.services.run_job(f"Reading {path.name}",
                                     lambda report: motion.read_motion(path),
                                     lambda source: self._loaded(path, source))

    def _loaded(self, path, source):
        """Pick the clip (asking when there are several), then retarget off the UI thread."""
        names = list(source.clips)
        if not names:
            raise ValueError(f"{path}: expected a clip to import, got none")
        name = names[0]
        if len(names) > 1:
            name, ok = QtWidgets.QInputDialog.getItem(
                self.parent, "Import motion", f"Clip of {path.name}:", names, 0, False)
            if not ok:
                self.status("Import motion: cancelled")
                return None
        doc = self.document
        # the job reads a snapshot of the clips: the user may edit them meanwhile
        ctx = SimpleNamespace(path=path, source=source, clip=name, rig=doc.rig,
                              skeleton=doc.skeleton, res=None, target=motion.target_of(doc),
                              base=motion.clip_name(path, name, len(names) > 1))
        self._close_dialog()
        self.ctx = ctx
        return self.retarget(None)

    # ------------------------------------------------------------------ the map
    def retarget(self, mapping=None, how=None):
        """Retarget the chosen clip with ``mapping`` (None: the automatic map) off the UI
        thread; the joint map dialog then shows the map used. Returns the job."""
        ctx = self.ctx
        if ctx is None:
            return None
        how = how or ("automatic" if mapping is None else "edited")

        def work(report):
            report(None)
            try:
                return motion.retarget_motion(ctx.source, ctx.clip, ctx.target, mapping,
                                              source_what=str(ctx.path),
                                              target_what=ctx.rig.name or "this character")
            except ValueError as exc:  # no legs mapped, ...: shown, and the map stays editable
                return exc

        if self.dialog is not None:
            self.dialog.set_busy(True)
        job = self.services.run_job(f"Retargeting {ctx.path.name}", work,
                                    lambda res: self._retargeted(ctx, res, mapping, how),
                                    on_cancel=lambda: self._idle(ctx))
        if job is None:
            self._idle(ctx)
        return job

    def _idle(self, ctx):
        if self.dialog is not None and ctx is self.ctx:
            self.dialog.set_busy(False)

    def _retargeted(self, ctx, res, mapping, how):
        if ctx is not self.ctx:
            return None
        if isinstance(res, ValueError):
            ctx.res = None
            text = f"No clip: {res}"
            self.error("Import motion", str(res))
        else:
            ctx.res = res
            ctx.summary, rest = motion.describe_result(res, ctx.source.skeleton, ctx.skeleton,
                                                       how)
            text = (f"{ctx.path.name}, clip {ctx.clip!r} ({res.clip.duration:.2f} s): "
                    f"{ctx.summary}." + (f" Unmapped, kept at their rest pose: "
                                         f"{_names(rest)}." if rest else ""))
        dialog = self._dialog(ctx)
        dialog.show_result(None if ctx.res is None else ctx.res.mapping, text)
        dialog.set_busy(False)
        if ctx.res is None and mapping is not None:
            dialog.set_mapping(mapping)  # the failed map stays on show, to be mended
        dialog.show()
        dialog.raise_()
        return ctx.res

    def _dialog(self, ctx):
        from .joint_map_dialog import JointMapDialog

        if self.dialog is None:
            d = JointMapDialog(ctx.source.skeleton.names, ctx.skeleton.names,
                               f"{ctx.path.name}, clip {ctx.clip}", self.parent)
            d.retarget.connect(self.retarget)
            d.load_requested.connect(self.load_map)
            d.save_requested.connect(self.save_map)
            d.accepted.connect(self._add)
            d.rejected.connect(self._cancel)
            self.dialog = d
        return self.dialog

    def _close_dialog(self):
        if self.dialog is not None:
            self.dialog.blockSignals(True)
            self.dialog.close()
            self.dialog.deleteLater()
        self.dialog = None

    def load_map(self, path=None):
        """Read a JSON map ``{motion joint: character joint}`` (checked against both
        skeletons) and retarget with it. Returns the job, or None."""
        ctx = self.ctx
        if not isinstance(path, (str, Path)):
            path, _ = QtWidgets.QFileDialog.getOpenFileName(
                self.dialog or self.parent, "Load joint map", "", MAP_FILTERS)
        if not path or ctx is None:
            return None
        try:
            mapping = motion.load_map(path, ctx.source.skeleton, ctx.skeleton)
        except (ValueError, OSError) as exc:
            self.error("Load joint map", str(exc))
            return None
        if self.dialog is not None:
            self.dialog.set_mapping(mapping)
        return self.retarget(mapping, how=f"from {Path(path).name}")

    def save_map(self, path=None):
        """Write the map on show as JSON (what ``--map`` reads). Returns True when written."""
        if self.dialog is None:
            return False
        if not isinstance(path, (str, Path)):
            path, _ = QtWidgets.QFileDialog.getSaveFileName(
                self.dialog, "Save joint map", f"{self.ctx.path.stem}_map.json", MAP_FILTERS)
        if not path:
            return False
        try:
            motion.save_map(path, self.dialog.mapping())
        except (ValueError, OSError) as exc:
            self.error("Save joint map", f"{path}: {exc}")
            return False
        self.status(f"Saved the joint map ({len(self.dialog.mapping())} joints) to {path}")
        return True

    def _cancel(self):
        self.ctx = None
        self._close_dialog()
        self.status("Import motion: cancelled")

    # ------------------------------------------------------------------ the clip
    def _add(self):
        ctx, self.ctx = self.ctx, None
        self._close_dialog()
        if ctx is None or ctx.res is None:
            return None
        path, res = ctx.path, ctx.res
        doc = self.document
        what = motion.dropped_because(doc, ctx.rig, ctx.skeleton)
        if what is not None:
            self.error("Import motion", f"{path}: import dropped: {what} while it was "
                                          f"retargeted; import it again")
            return None
        clip = res.clip
        added = self.add_clip(clip, ctx.base, f"Import motion {path.name}")
        if added is None:
            return None
        self.status(f"Imported {path.name} as clip {added!r} ({clip.duration:.2f} s): "
                      f"{ctx.summary}")
        return added
