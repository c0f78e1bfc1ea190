"""File > Export compressed: the settings dialog, the export run as a job, the report shown.

The work is :class:`rigedit.editor.compression.CompressedExport` (made here on the main
thread from what the document holds, run in the window's job runner); this module only asks
and tells. The settings the dialog last accepted are the comparison's too
(:mod:`.compare_view`), through the shared :class:`CompressionSettings`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from PyQt5 import QtCore, QtWidgets

from ..editor.compression import GLTF_SUFFIXES, CompressedExport
from .menus import make_action

__all__ = ["CompressionSettings", "CompressDialog", "ExportCompressed", "LARGEST_CM"]

#: More than this is a typo rather than a tolerance (1 m), as on the command line.
LARGEST_CM = 100.0


@dataclass
class CompressionSettings:
    """The bound and shell in centimetres (the issue's defaults: 0.01 cm on a 3 cm shell)."""

    max_error_cm: float = 0.01
    shell_cm: float = 3.0

    @property
    def max_error(self):
        """Metres."""
        return self.max_error_cm / 100

    @property
    def shell(self):
        """Metres."""
        return self.shell_cm / 100


def centimetres(label, text):
    """A positive finite number of centimetres up to :data:`LARGEST_CM` from ``text``;
    ``ValueError`` naming the field otherwise."""
    try:
        value = float(str(text).strip())
    except ValueError:
        raise ValueError(f"{label}: expected a number of centimetres, got {text!r}") from None
    if not (math.isfinite(value) and 0 < value <= LARGEST_CM):
        raise ValueError(f"{label}: expected a positive number of centimetres up to "
                         f"{LARGEST_CM:g}, got {text!r}")
    return value


class CompressDialog(QtWidgets.QDialog):
    """Max error, shell, the clips, the output and meshopt; OK refuses bad values with one
    message in the dialog (:attr:`error_label`) and stays open.

    Attributes
    ----------
    export : CompressedExport or None
        What OK accepted (the document's clips copied then).
    """

    def __init__(self, document, settings, parent=None):
        super().__init__(parent)
        self.setWindowTitle("Export compressed")
        self.document = document
        self.settings = settings
        self.export = None
        rig = document.rig
        form = QtWidgets.QFormLayout(self)
        self.max_error_edit = QtWidgets.QLineEdit(f"{settings.max_error_cm:g}")
        self.max_error_edit.setToolTip("No virtual vertex of any frame strays further")
        form.addRow("Max error (cm)", self.max_error_edit)
        self.shell_edit = QtWidgets.QLineEdit(f"{settings.shell_cm:g}")
        self.shell_edit.setToolTip("Distance of the virtual vertices from each joint "
                                   "(ACL's 3 cm)")
        form.addRow("Shell (cm)", self.shell_edit)
        self.clip_list = QtWidgets.QListWidget()
        for name in rig.clips:
            item = QtWidgets.QListWidgetItem(name)
            item.setFlags(item.flags() | QtCore.Qt.ItemIsUserCheckable)
            item.setCheckState(QtCore.Qt.Checked)
            self.clip_list.addItem(item)
        self.clip_list.setMaximumHeight(120)
        form.addRow("Clips", self.clip_list)
        self.path_edit = QtWidgets.QLineEdit(str(Path.cwd() / f"{rig.name}-compressed.glb"))
        browse = QtWidgets.QPushButton("File...")
        browse.clicked.connect(self._browse)
        folder = QtWidgets.QPushButton("Folder...")
        folder.clicked.connect(self._browse_folder)
        row = QtWidgets.QHBoxLayout()
        row.addWidget(self.path_edit, 1)
        row.addWidget(browse)
        row.addWidget(folder)
        form.addRow("Output (.glb, .gltf, .rgc or a folder)", row)
        self.meshopt_box = QtWidgets.QCheckBox("Also compress the buffers "
                                               "(EXT_meshopt_compression, glTF only)")
        form.addRow("", self.meshopt_box)
        self.path_edit.textChanged.connect(self._path_changed)
        self._path_changed(self.path_edit.text())
        self.error_label = QtWidgets.QLabel()
        self.error_label.setStyleSheet("color: #ff8a80")
        self.error_label.setWordWrap(True)
        form.addRow(self.error_label)
        buttons = QtWidgets.QDialogButtonBox(QtWidgets.QDialogButtonBox.Ok
                                             | QtWidgets.QDialogButtonBox.Cancel)
        buttons.button(QtWidgets.QDialogButtonBox.Ok).setText("Export")
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def _path_changed(self, text):
        gltf = Path(text.strip()).suffix.lower() in GLTF_SUFFIXES
        self.meshopt_box.setEnabled(gltf)
        if not gltf:
            self.meshopt_box.setChecked(False)

    def _browse(self):
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self, "Export compressed", self.path_edit.text(),
            "glTF binary (*.glb);;glTF (*.gltf);;rigedit compressed clips (*.rgc)")
        if path:
            self.path_edit.setText(path)

    def _browse_folder(self):
        path = QtWidgets.QFileDialog.getExistingDirectory(self, "Export into rig folder")
        if path:
            self.path_edit.setText(path)

    def clips(self):
        """The names checked."""
        items = (self.clip_list.item(i) for i in range(self.clip_list.count()))
        return [it.text() for it in items if it.checkState() == QtCore.Qt.Checked]

    def make_export(self):
        """The :class:`CompressedExport` of the values shown; ``ValueError`` (one message
        naming the field) for a bad one."""
        max_error = centimetres("Max error", self.max_error_edit.text())
        shell = centimetres("Shell", self.shell_edit.text())
        path = self.path_edit.text().strip()
        if not path:
            raise ValueError("Output: expected a file or folder to write")
        clips = self.clips()
        if not clips:
            raise ValueError("Clips: expected at least one clip checked")
        export = CompressedExport(self.document, path, max_error / 100, shell / 100, clips,
                                  self.meshopt_box.isChecked())
        self.settings.max_error_cm, self.settings.shell_cm = max_error, shell
        return export

    def accept(self):
        try:
            self.export = self.make_export()
        except ValueError as exc:
            self.error_label.setText(str(exc))
            return
        self.error_label.clear()
        super().accept()


class ExportCompressed:
    """File > Export compressed.

    Parameters
    ----------
    document : Document
    services : Services
    settings : CompressionSettings
        Shared with the comparison (the last values accepted).

    Attributes
    ----------
    last_report : CompressionReport or None
    last_message : QMessageBox or None
        The report shown after the last export.
    """

    def __init__(self, document, services, settings):
        self.document = document
        self.services = services
        self.settings = settings
        self.last_report = None
        self.last_message = None

    def actions(self):
        """name -> QAction for :func:`.menus.build_menus`."""
        return {"export_compressed": make_action(
            self.services.parent, "Export &compressed...", self.run,
            tip="Compress the clips with a guaranteed error into glTF, a rig folder or a "
                ".rgc file")}

    def dialog(self):
        return CompressDialog(self.document, self.settings, self.services.parent)

    def run(self, *_):
        """Ask (modal), then export in the background."""
        dialog = self.dialog()
        if dialog.exec_() != QtWidgets.QDialog.Accepted:
            return None
        return self.start(dialog.export)

    def start(self, export):
        """Run ``export`` (a :class:`CompressedExport`) as a job; the report at the end.
        Returns the job, or None when another one runs."""
        return self.services.run_job(f"Compressing into {export.path.name}", export.run,
                                     lambda report: self._done(export, report),
                                     show_stage=True)

    def _done(self, export, report):
        self.last_report = report
        self.services.status(
            f"Exported {len(report.clips)} compressed clips to {export.path}: ratio "
            f"{report.ratio:.1f}:1, max error {report.max_error * 100:.4f} cm, 99th "
            f"percentile {report.p99_error * 100:.4f} cm, {report.compressed_bytes} bytes")
        box = QtWidgets.QMessageBox(QtWidgets.QMessageBox.Information, "Export compressed",
                                    f"Wrote {export.path}\n\n" + "\n".join(report.lines()),
                                    QtWidgets.QMessageBox.Ok, self.services.parent)
        box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
        box.open()
        self.last_message = box
