"""File > Export video: the settings dialog and the recording run with a progress dialog.

The recording itself is :func:`rigedit.render.recorder.record_clip` (the same code as the
``rigedit render`` command): its own off-screen plotter, a copy of the clip, exact times
``start + i / fps``. It runs on the main thread (VTK must) in steps: the progress callback
processes Qt events between frames, so the progress dialog repaints and its Cancel button
works; the dialog is modal, so the document cannot change under the recording.
"""
from __future__ import annotations

from pathlib import Path

from PyQt5 import QtCore, QtWidgets

from ..errors import RigFileError
from ..progress import Cancelled
from ..render.camera import camera_state
from ..render.recorder import RecordingCancelled, record_clip
from .menus import make_action

__all__ = ["RecordDialog", "RecordVideo", "record_video"]


def record_video(document, view, status, path, fps=30, duration=None, size=(1280, 720),
                 start=0.0, camera="view", orbit=360.0, clip=None, follow_root=False,
                 progress=True, parent=None, **options):
    """Record the document's current clip (or ``clip``, a name) to ``path``.

    Parameters
    ----------
    document : Document
    view : SceneView
        The editor's view: its camera and skinning method are the recording's.
    status : callable
        ``status(text)``.
    path : str or Path
        ``.mp4`` or ``.gif``.
    fps : float
    duration : float, optional
        Seconds from ``start``; up to the clip's end when omitted.
    size : (int, int)
    start : float
        Clip time of the first frame.
    camera : {"view", "orbit"} or dict
        ``"view"`` copies the editor's current camera; ``"orbit"`` starts from it and turns
        ``orbit`` degrees about the vertical axis over the recording; a dict is used as is
        (see :func:`~rigedit.render.camera.camera_state`).
    follow_root : bool
        Move the camera with the root's horizontal motion.
    progress : bool
        Show a progress dialog with Cancel (processes Qt events between frames).
    parent : QWidget, optional
        The progress dialog's parent (window-modal over it).

    Returns
    -------
    frames : int
        Frames written, or 0 when cancelled (no file is then left behind).
    """
    doc = document
    name = clip if clip is not None else doc.current_clip
    clip_obj = doc.clips.get(name) if name is not None else None
    if duration is None:
        end = clip_obj.duration if clip_obj is not None and clip_obj.duration > 0 else 1.0
        duration = max(end - start, 1.0 / fps)
    cam = camera if isinstance(camera, dict) else camera_state(view.plotter.camera)
    turn = float(orbit) if camera == "orbit" else 0.0
    dialog = None
    callback = None
    if progress:
        total = max(1, int(round(duration * fps)))
        dialog = QtWidgets.QProgressDialog(f"Recording {Path(path).name}...", "Cancel", 0, total,
                                           parent)
        dialog.setWindowTitle("Export video")
        dialog.setWindowModality(QtCore.Qt.WindowModal)
        dialog.setMinimumDuration(0)
        dialog.setValue(0)

        def callback(fraction, stage=None):   # rigedit.progress's protocol
            dialog.setValue(int(round(fraction * total)))
            QtWidgets.QApplication.processEvents()   # the dialog repaints, Cancel works
            if dialog.wasCanceled():
                raise Cancelled()
    options.setdefault("skinning", view.scene.skinning)  # as the view shows it (LBS/DQS)
    try:
        n = record_clip(doc.rig, clip_obj, path, fps=fps, duration=duration, size=size,
                        start=start, camera=cam, orbit=turn, follow_root=follow_root,
                        progress=callback, **options)
    except RecordingCancelled:
        status("Export video: cancelled")
        return 0
    finally:
        if dialog is not None:
            dialog.reset()
            dialog.deleteLater()
        # the interactive view keeps its own plotter; repaint it in case the window was covered
        view.plotter.update()
    status(f"Recorded {n} frames to {path}")
    return n


class RecordDialog(QtWidgets.QDialog):
    """Export settings: file, size, frame rate, time range, camera."""

    def __init__(self, document, parent=None):
        super().__init__(parent)
        self.setWindowTitle("Export video")
        doc = document
        clip = doc.clips.get(doc.current_clip) if doc.current_clip else None
        end = clip.duration if clip is not None and clip.duration > 0 else 1.0
        form = QtWidgets.QFormLayout(self)
        self.path_edit = QtWidgets.QLineEdit(str(Path.cwd() / f"{clip.name if clip else 'rest'}.mp4"))
        browse = QtWidgets.QPushButton("Browse...")
        browse.clicked.connect(self._browse)
        row = QtWidgets.QHBoxLayout()
        row.addWidget(self.path_edit, 1)
        row.addWidget(browse)
        form.addRow("File (MP4 or GIF)", row)
        self.width_spin, self.height_spin = QtWidgets.QSpinBox(), QtWidgets.QSpinBox()
        for s, v in ((self.width_spin, 1280), (self.height_spin, 720)):
            s.setRange(16, 7680)
            s.setSingleStep(2)
            s.setValue(v)
        size = QtWidgets.QHBoxLayout()
        size.addWidget(self.width_spin)
        size.addWidget(QtWidgets.QLabel("x"))
        size.addWidget(self.height_spin)
        form.addRow("Size (pixels)", size)
        self.fps_spin = QtWidgets.QSpinBox()
        self.fps_spin.setRange(1, 120)
        self.fps_spin.setValue(30)
        form.addRow("Frame rate", self.fps_spin)
        self.clip_end = clip.duration if clip is not None else None
        self.start_spin, self.end_spin = QtWidgets.QDoubleSpinBox(), QtWidgets.QDoubleSpinBox()
        for s, v in ((self.start_spin, 0.0), (self.end_spin, end)):
            s.setRange(0.0, 3600.0)
            s.setDecimals(3)
            s.setSuffix(" s")
            s.setValue(v)
        rng = QtWidgets.QHBoxLayout()
        rng.addWidget(self.start_spin)
        rng.addWidget(QtWidgets.QLabel("to"))
        rng.addWidget(self.end_spin)
        form.addRow(f"Time range ({clip.name if clip else 'no clip'})", rng)
        self.view_radio = QtWidgets.QRadioButton("Current view")
        self.orbit_radio = QtWidgets.QRadioButton("Orbit")
        self.view_radio.setChecked(True)
        self.orbit_spin = QtWidgets.QDoubleSpinBox()
        self.orbit_spin.setRange(-1440, 1440)
        self.orbit_spin.setValue(360)
        self.orbit_spin.setSuffix(" °")
        cam = QtWidgets.QHBoxLayout()
        for w in (self.view_radio, self.orbit_radio, self.orbit_spin):
            cam.addWidget(w)
        form.addRow("Camera", cam)
        self.follow_box = QtWidgets.QCheckBox("Follow the root's horizontal motion")
        form.addRow("", self.follow_box)
        buttons = QtWidgets.QDialogButtonBox(QtWidgets.QDialogButtonBox.Ok
                                             | QtWidgets.QDialogButtonBox.Cancel)
        buttons.button(QtWidgets.QDialogButtonBox.Ok).setText("Record")
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def _browse(self):
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self, "Export video", self.path_edit.text(), "Video (*.mp4 *.gif)")
        if path:
            self.path_edit.setText(path)

    def settings(self):
        """Keyword arguments for :func:`record_video`; ``ValueError`` for a time range that
        is empty or starts past the clip's end (past the end, a looping clip plays again
        from its start and another holds its last pose, as ``rigedit render --end``)."""
        start, end = self.start_spin.value(), self.end_spin.value()
        if end <= start:
            raise ValueError(f"Time range: expected an end after the start ({start:g} s), "
                             f"got {end:g} s")
        if self.clip_end and start >= self.clip_end:
            raise ValueError(f"Time range: the start ({start:g} s) is past the clip's end "
                             f"({self.clip_end:g} s)")
        return {"path": self.path_edit.text().strip(), "fps": self.fps_spin.value(),
                "size": (self.width_spin.value(), self.height_spin.value()), "start": start,
                "duration": end - start,
                "camera": "orbit" if self.orbit_radio.isChecked() else "view",
                "orbit": self.orbit_spin.value(), "follow_root": self.follow_box.isChecked()}


class RecordVideo:
    """File > Export video.

    Parameters
    ----------
    document : Document
    view : SceneView
    services : Services
    """

    def __init__(self, document, view, services):
        self.document = document
        self.view = view
        self.services = services

    def actions(self):
        """name -> QAction for :func:`.menus.build_menus`."""
        return {"export_video": make_action(self.services.parent, "Export &video...", self.run)}

    def record(self, path, **kwargs):
        """:func:`record_video` of the document in the editor's view; returns the frames."""
        return record_video(self.document, self.view, self.services.status, path,
                            parent=self.services.parent, **kwargs)

    def run(self, *_):
        """Show the dialog and record on OK; errors become one message."""
        dialog = RecordDialog(self.document, self.services.parent)
        if dialog.exec_() != QtWidgets.QDialog.Accepted:
            return 0
        try:
            kwargs = dialog.settings()
            return self.record(kwargs.pop("path"), **kwargs)
        except (RigFileError, ValueError, OSError) as exc:
            self.services.error("Export video", str(exc))
            return 0
