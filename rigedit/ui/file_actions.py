"""The File menu's work: open, save, export, weights. Reading and computing run in a worker
(:class:`~rigedit.ui.jobs.JobRunner`); a bad file gives one message naming it and keeps the
current rig.
"""
from __future__ import annotations

from pathlib import Path

from PyQt5 import QtWidgets

from ..editor import files
from ..editor.files import pose_to_dict  # noqa: F401 - its old home
from ..editor.recompute import RecomputeWeights
from .menus import make_action

__all__ = ["FileActions", "pose_to_dict"]


class FileActions:
    """The File menu's open, save, export and weights actions.

    Parameters
    ----------
    document : Document
    services : Services
        Status, errors, the job runner and the dialogs' parent.
    confirm_close : callable
        ``confirm_close()`` is True where unsaved changes are asked about (the app; not
        scripts or tests driving the window).
    ask_unsaved : callable
        ``ask_unsaved(action) -> bool``: whether the unsaved changes may go before ``action``
        ("opening another rig"): saved, or discarded by the user.
    screenshot : callable
        ``screenshot(path)`` writes a picture of the window.
    quit : callable
        File > Quit.
    """

    def __init__(self, document, services, confirm_close, ask_unsaved, screenshot, quit):
        self.doc = document
        self.services = services
        self.parent = services.parent
        self.status = services.status
        self.error = services.error
        self.confirm_close = confirm_close
        self.ask_unsaved = ask_unsaved
        self.screenshot = screenshot
        self.quit = quit

    def actions(self):
        """name -> QAction for :func:`.menus.build_menus`."""
        p = self.parent
        return {
            "open_folder": make_action(p, "&Open rig folder...", self.open_folder, "Ctrl+O"),
            "open_mesh_skeleton": make_action(p, "Open mesh + skeleton...",
                                              self.open_mesh_skeleton),
            "open_file": make_action(p, "Open glTF or BVH file...", self.open_file,
                                     "Ctrl+Shift+O"),
            "save": make_action(p, "&Save rig", self.save, "Ctrl+S"),
            "save_as": make_action(p, "Save rig &as...", self.save_as, "Ctrl+Shift+S"),
            "export": make_action(p, "&Export glTF or BVH...", self.export, "Ctrl+E"),
            "export_pose": make_action(p, "Export pose (JSON)...", self.export_pose),
            "export_skeleton": make_action(p, "Export skeleton (JSON)...",
                                           self.export_skeleton),
            "load_weights": make_action(p, "Load weights...", self.load_weights),
            "save_weights": make_action(p, "Save weights...", self.save_weights),
            "recompute_weights": make_action(
                p, "&Recompute weights", self.recompute_weights, "Ctrl+R",
                tip="Recompute the weights: bone heat for a mesh with faces, inverse "
                    "distance for a point cloud; joints flagged not deforming take none"),
            "save_screenshot": make_action(p, "Save screenshot...", self.save_screenshot),
            "quit": make_action(p, "&Quit", self.quit, "Ctrl+Q"),
        }

    def _run(self, label, fn, on_done):
        return self.services.run_job(label, fn, on_done)

    # ------------------------------------------------------------------ dialogs
    def _ask_open(self, title, filters):
        path, _ = QtWidgets.QFileDialog.getOpenFileName(self.parent, title, "", filters)
        return path or None

    def _ask_save(self, title, name, filters):
        path, _ = QtWidgets.QFileDialog.getSaveFileName(self.parent, title, name, filters)
        return path or None

    # ------------------------------------------------------------------ replacing the document
    def may_replace(self, action):
        """Whether the open document may be replaced (``action``: by what, for the question):
        no unsaved changes, or the user saved or discarded them. Asked where closing asks
        (``confirm_close``: the app; not scripts or tests driving the window)."""
        return not self.confirm_close() or self.ask_unsaved(action)

    def replacing(self, action):
        """Ask before reading a new document in the background; returns None when the user
        keeps the open one, else a check for the moment the new one arrives: edits made
        meanwhile are asked about again, so reading a file never drops them silently."""
        if not self.may_replace(action):
            return None
        doc = self.doc
        rig, top = doc.rig, doc.undo_stack.top

        def still_ok():
            if doc.rig is rig and doc.undo_stack.top is top:
                return True  # nothing changed since the question
            if self.may_replace(action):
                return True
            self.status(f"Kept {doc.rig.name}: {action} cancelled")
            return False

        return still_ok

    # ------------------------------------------------------------------ open
    def open_folder(self, path=None):
        """Open a rig folder (mesh, skeleton.json, optional weights and animations)."""
        check = self.replacing("opening another rig")
        if check is None:
            return None
        path = path or QtWidgets.QFileDialog.getExistingDirectory(self.parent,
                                                                  "Open rig folder")
        if not path:
            return None
        return self._run(f"Opening {Path(path).name}",
                         lambda report: files.load_rig_folder(path),
                         lambda rig: self._opened(rig, check))

    def open_mesh_skeleton(self, mesh_path=None, skeleton_path=None):
        """Open a mesh file and a skeleton file; weights are computed."""
        check = self.replacing("opening another rig")
        if check is None:
            return None
        mesh_path = mesh_path or self._ask_open(
            "Open mesh", "Meshes (*.obj *.ply *.stl *.vtk *.vtu *.vtp)")
        if not mesh_path:
            return None
        skeleton_path = skeleton_path or self._ask_open("Open skeleton", "Skeleton (*.json)")
        if not skeleton_path:
            return None

        def work(report):
            return files.load_mesh_skeleton(mesh_path, skeleton_path, progress=report)

        return self._run(f"Opening {Path(mesh_path).name}", work,
                         lambda rig: self._opened(rig, check))

    def open_file(self, path=None):
        """Open a glTF/GLB file or a BVH file (a skeleton and its motion, no mesh)."""
        check = self.replacing("opening another rig")
        if check is None:
            return None
        path = path or self._ask_open("Open glTF or BVH file",
                                      "Rigs and motion (*.glb *.gltf *.fbx *.bvh *.rgc)")
        if not path:
            return None
        # what the reader decided (a BVH's unit guess) is in rig.notes for the status bar
        return self._run(f"Opening {Path(path).name}",
                         lambda report: files.load_rig(path, quiet=True),
                         lambda rig: self._opened(rig, check))

    def _opened(self, rig, check):
        if not check():
            return
        self.doc.set_rig(rig)
        notes = "".join(f"; {key}: {value}" for key, value in sorted(rig.notes.items()))
        self.status(f"Opened {rig.name}: {len(rig.vertices):,} vertices, "
                      f"{len(rig.skeleton)} joints, {len(rig.clips)} clips{notes}")

    # ------------------------------------------------------------------ save
    def save(self):
        """Save into the folder the rig came from; a rig without one, or a bundled character
        (read-only), asks for a new place (Save As)."""
        path = self.doc.rig.path
        if path is None or not Path(path).is_dir() or files.is_bundled(path):
            return self.save_as()
        return self.save_to(path)

    def save_as(self, path=None):
        """Save into a folder chosen by the user (or ``path``). A folder that holds another
        rig is replaced only after the user confirms."""
        path = path or QtWidgets.QFileDialog.getExistingDirectory(self.parent,
                                                                  "Save rig into folder")
        if not path:
            return None
        current = self.doc.rig.path
        other_rig = (Path(path) / "rig.json").is_file() and not (
            current is not None and Path(current).resolve() == Path(path).resolve())
        if other_rig and not files.is_bundled(path) and not self._confirm_replace(path):
            return None
        return self.save_to(path)

    def _confirm_replace(self, path):
        answer = QtWidgets.QMessageBox.question(
            self.parent, "Save rig", f"{path} already holds a rig. Replace it with this one? "
            "(Its clips that this rig lacks are deleted; other files stay.)")
        return answer == QtWidgets.QMessageBox.Yes

    def _attempt(self, title, action, done):
        """Run ``action()``; on bad input or an OS error show one message titled ``title``
        and return False, else show ``done`` in the status bar and return True."""
        try:
            action()
        except (ValueError, OSError) as exc:
            self.error(title, str(exc))
            return False
        self.status(done)
        return True

    def save_to(self, path):
        """Write the rig folder (each file atomically); the status bar says where."""
        # the document then has no unsaved changes: the title loses its star, autosave rests
        rig = self.doc.rig
        return self._attempt("Save rig", lambda: files.save_rig_folder(self.doc, path),
                             f"Saved {rig.name} to {path}")

    def export_pose(self, path=None):
        path = path or self._ask_save("Export pose", "pose.json", "JSON (*.json)")
        return bool(path) and self._attempt(
            "Export pose", lambda: files.export_pose(self.doc, path),
            f"Exported the pose to {path}")

    def export_skeleton(self, path=None):
        path = path or self._ask_save("Export skeleton", "skeleton.json", "JSON (*.json)")
        return bool(path) and self._attempt(
            "Export skeleton", lambda: files.export_skeleton(self.doc, path),
            f"Exported the skeleton to {path}")

    def export(self, path=None):
        """Export the rig as glTF (.glb/.gltf, every clip), FBX (.fbx, every clip, in
        centimetres) or BVH (the skeleton and the current clip); the format follows the
        extension."""
        rig = self.doc.rig
        path = path or self._ask_save("Export", f"{rig.name}.glb",
                                      "glTF binary (*.glb);;glTF (*.gltf);;FBX (*.fbx);;"
                                      "BVH (*.bvh)")
        if not path:
            return False
        return self._attempt("Export", lambda: files.export_rig(self.doc, path),
                             f"Exported {rig.name} to {path}")

    # ------------------------------------------------------------------ weights
    def load_weights(self, path=None):
        """Replace the skin weights from a .npz file (one undo step)."""
        path = path or self._ask_open("Load weights", "Weights (*.npz)")
        if not path:
            return False
        return self._attempt("Load weights", lambda: files.load_weights(self.doc, path),
                             f"Loaded weights from {path}")

    def save_weights(self, path=None):
        path = path or self._ask_save("Save weights", "weights.npz", "Weights (*.npz)")
        return bool(path) and self._attempt(
            "Save weights", lambda: files.save_weights(self.doc, path),
            f"Saved weights to {path}")

    def recompute_weights(self, method=None):
        """Recompute the weights off the UI thread (progress, cancel); one undo step.
        ``method`` is ``"heat"`` or ``"idw"``; by default heat for a mesh with faces."""
        if not isinstance(method, str):  # a menu action's "checked" argument
            method = None
        job = RecomputeWeights(self.doc, method)   # what the document holds now
        return self._run("Computing weights", job.compute,
                         lambda result: self.status(job.apply(result)[0]))

    def save_screenshot(self, path=None):
        path = path or self._ask_save("Save screenshot", "rigedit.png", "PNG (*.png)")
        return bool(path) and self._attempt("Screenshot", lambda: self.screenshot(path),
                                            f"Saved a screenshot to {path}")
