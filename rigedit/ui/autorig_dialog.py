"""File > Auto-rig mesh: a dialog (mesh, template, up and forward axes) that runs
:func:`rigedit.autorig` off the UI thread and opens the result as a new, unsaved character in
bind (edit) mode, so the user can fix joints at once; when the result is NOT SURE the status
bar says why and the first joint in doubt is selected.

The work runs through :class:`~rigedit.ui.jobs.JobRunner` (progress bar with the stage's name,
Cancel).
Bad input (a mesh that is not closed, a template file that is not a skeleton, a mesh with
nothing like the template's limbs) shows through the window's error path and the open document
stays as it was; so does a cancel.
"""
from __future__ import annotations

from pathlib import Path

from PyQt5 import QtWidgets

from ..editor.autorig import autorig_mesh, describe_report, open_autorigged
from .menus import make_action

__all__ = ["AutorigDialog", "AutorigAction", "AXES", "describe_report"]

MESH_FILTERS = ("Meshes (*.obj *.ply *.stl *.off *.vtk *.vtu *.vtp *.glb *.gltf);;"
                "All files (*)")
TEMPLATE_FILTERS = ("Skeletons (skeleton.json *.json *.bvh *.glb *.gltf);;All files (*)")
#: Axis choices of the up and forward boxes: label -> the ``up``/``forward`` argument.
AXES = {"guess": None, "+Y": "y", "-Y": "-y", "+Z": "z", "-Z": "-z", "+X": "x", "-X": "-x"}
TEMPLATES = ("humanoid", "quadruped")
OTHER_TEMPLATE = "skeleton file..."


def template_path(path):
    """The path :func:`rigedit.autorig` reads for a chosen template file: a rig folder is
    chosen by its ``skeleton.json`` (one file dialog for files and folders) when it holds a
    mesh or ``rig.json`` beside it; any other file as it is."""
    path = Path(path)
    folder = path.parent
    if path.name.lower() == "skeleton.json" and (folder / "rig.json").is_file():
        return folder
    return path


class AutorigDialog(QtWidgets.QDialog):
    """The settings: mesh file, template (bundled or a skeleton file), up and forward axes.

    ``arguments()`` gives what :func:`rigedit.autorig` takes. The Auto-rig button is enabled
    only when a mesh is chosen, a template file is chosen when asked for, and up and forward
    are not along one axis.
    """

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setWindowTitle("Auto-rig mesh")
        self.template_file = None
        form = QtWidgets.QFormLayout()
        self.mesh_edit = QtWidgets.QLineEdit()
        self.mesh_edit.setPlaceholderText("a closed mesh in a standing pose")
        browse = QtWidgets.QPushButton("Browse...")
        browse.clicked.connect(self.browse_mesh)
        self.mesh_browse = browse
        row = QtWidgets.QHBoxLayout()
        row.addWidget(self.mesh_edit, 1)
        row.addWidget(browse)
        form.addRow("Mesh", row)
        self.template_combo = QtWidgets.QComboBox()
        self.template_combo.addItems([*TEMPLATES, OTHER_TEMPLATE])
        self.template_combo.activated.connect(self._template_chosen)
        self.template_label = QtWidgets.QLabel("")
        self.template_label.setWordWrap(True)
        row = QtWidgets.QVBoxLayout()
        row.addWidget(self.template_combo)
        row.addWidget(self.template_label)
        form.addRow("Template", row)
        self.up_combo = QtWidgets.QComboBox()
        self.forward_combo = QtWidgets.QComboBox()
        for combo in (self.up_combo, self.forward_combo):
            combo.addItems(list(AXES))
            combo.currentIndexChanged.connect(self._validate)
        form.addRow("Up", self.up_combo)
        form.addRow("Forward (facing)", self.forward_combo)
        note = QtWidgets.QLabel("The character opens as a new, unsaved document in bind mode: "
                                "drag joints to fix their places, then Save.")
        note.setWordWrap(True)
        self.problem_label = QtWidgets.QLabel("")
        self.problem_label.setStyleSheet("color: #e07070")
        self.buttons = QtWidgets.QDialogButtonBox(QtWidgets.QDialogButtonBox.Cancel)
        self.ok_button = self.buttons.addButton("Auto-rig", QtWidgets.QDialogButtonBox.AcceptRole)
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        self.mesh_edit.textChanged.connect(self._validate)
        layout = QtWidgets.QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(note)
        layout.addWidget(self.problem_label)
        layout.addWidget(self.buttons)
        self.setMinimumWidth(460)
        self._validate()

    # ------------------------------------------------------------------ choices
    def browse_mesh(self):
        path, _ = QtWidgets.QFileDialog.getOpenFileName(self, "Mesh to auto-rig", "",
                                                        MESH_FILTERS)
        if path:
            self.mesh_edit.setText(path)

    def _template_chosen(self, index):
        if self.template_combo.itemText(index) != OTHER_TEMPLATE:
            self._validate()
            return
        path, _ = QtWidgets.QFileDialog.getOpenFileName(self, "Template skeleton", "",
                                                        TEMPLATE_FILTERS)
        if path:
            self.template_file = template_path(path)
        if self.template_file is None:  # nothing chosen: back to the default
            self.template_combo.setCurrentIndex(0)
        self._validate()

    def set_axes(self, up=None, forward=None):
        """Choose the up and forward boxes by argument value (``"y"``, ``"-x"``, None)."""
        labels = {v: k for k, v in AXES.items()}
        self.up_combo.setCurrentText(labels[up])
        self.forward_combo.setCurrentText(labels[forward])

    def arguments(self):
        """Keyword arguments for :func:`rigedit.autorig` (besides ``progress``)."""
        name = self.template_combo.currentText()
        template = self.template_file if name == OTHER_TEMPLATE else name
        return {"mesh": self.mesh_edit.text().strip(), "template": template,
                "up": AXES[self.up_combo.currentText()],
                "forward": AXES[self.forward_combo.currentText()]}

    def _problem(self):
        args = self.arguments()
        if not args["mesh"]:
            return "Choose a mesh file."
        if args["template"] is None:
            return "Choose a template skeleton file."
        up, fwd = args["up"], args["forward"]
        if up is not None and fwd is not None and up.lstrip("-") == fwd.lstrip("-"):
            return "Up and forward must be different axes."
        return ""

    def _validate(self, *_):
        if self.template_combo.currentText() == OTHER_TEMPLATE and self.template_file:
            self.template_label.setText(str(self.template_file))
        else:
            self.template_label.setText("")
        self.template_label.setVisible(bool(self.template_label.text()))
        problem = self._problem()
        self.problem_label.setText(problem)
        self.ok_button.setEnabled(not problem)


class AutorigAction:
    """File > Auto-rig mesh.

    Parameters
    ----------
    document : Document
    services : Services
    replacing : callable
        ``replacing(action)`` (:meth:`FileActions.replacing
        <rigedit.ui.file_actions.FileActions.replacing>`): None when the user keeps the open
        document, else a check to call when the new one arrives.
    """

    def __init__(self, document, services, replacing):
        self.document = document
        self.services = services
        self.replacing = replacing
        self.dialog = None

    def actions(self):
        """name -> QAction for :func:`.menus.build_menus`."""
        return {"autorig": make_action(
            self.services.parent, "&Auto-rig mesh...", self.run, "Ctrl+Shift+A",
            tip="Embed a template skeleton (humanoid, quadruped or a skeleton file) in a "
                "mesh and open it in bind mode")}

    def run(self, *_):
        """Show the dialog (window-modal, not blocking); its Auto-rig button starts the job."""
        if self.dialog is None:
            self.dialog = AutorigDialog(self.services.parent)
            self.dialog.accepted.connect(lambda: self.start(**self.dialog.arguments()))
        self.dialog._validate()
        self.dialog.open()
        return self.dialog

    def start(self, mesh, template="humanoid", up=None, forward=None):
        """Auto-rig ``mesh`` off the UI thread; the result becomes the document. Returns
        the job (None when another job runs)."""
        mesh = Path(mesh)
        check = self.replacing("auto-rigging a mesh")
        if check is None:
            return None
        label = f"Auto-rigging {mesh.name}"

        def work(report):
            # report raises Cancelled after the Cancel button; the bar names each stage
            return autorig_mesh(mesh, template=template, up=up, forward=forward,
                                progress=report)

        return self.services.run_job(label, work, lambda rig: self._done(mesh, rig, check),
                                     show_stage=True)

    def _done(self, mesh, rig, check=lambda: True):
        if not check():
            return None
        self.services.status(open_autorigged(self.document, rig, mesh))
        return rig
