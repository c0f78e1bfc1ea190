"""The joint map of File > Import motion: see the map a retarget used, edit it, load one from
JSON, save it (as ``rigedit retarget --map/--save-map`` do), then add the clip.

One row per joint of the motion, in its skeleton's order: the motion's joint and the
character's joint it drives ("(none)": unused; a character joint no row names keeps its rest
pose). The dialog never retargets by itself: it asks its owner
(:class:`~rigedit.ui.import_motion.ImportMotion`) through :attr:`JointMapDialog.retarget`,
which shows the new result with :meth:`JointMapDialog.show_result`.
"""
from __future__ import annotations

from collections import Counter

from PyQt5 import QtCore, QtWidgets

__all__ = ["JointMapDialog", "NONE"]

NONE = "(none)"


class JointMapDialog(QtWidgets.QDialog):
    """The map table with Load map, Save map, Automatic map, Retarget and Add clip.

    Parameters
    ----------
    source_names, target_names : list[str]
        The motion's and the character's joint names (skeleton order).
    title : str
        What is imported ("walk.bvh, clip take").

    Signals
    -------
    retarget(object)   a map ``{motion joint: character joint}`` to retarget with, or None
                       for the automatic map
    load_requested()   the Load map button (the owner reads and checks the file)
    save_requested()   the Save map button
    """

    retarget = QtCore.pyqtSignal(object)
    load_requested = QtCore.pyqtSignal()
    save_requested = QtCore.pyqtSignal()

    def __init__(self, source_names, target_names, title, parent=None):
        super().__init__(parent)
        self.setWindowTitle(f"Import motion: joint map ({title})")
        self.source_names = list(source_names)
        self.target_names = list(target_names)
        self.used = None  # the map of the clip on offer; None before any result
        self.summary = QtWidgets.QLabel()
        self.summary.setWordWrap(True)
        self.table = QtWidgets.QTableWidget(len(self.source_names), 2)
        self.table.setHorizontalHeaderLabels(["Motion joint", "Drives this character's joint"])
        self.table.verticalHeader().setVisible(False)
        self.table.horizontalHeader().setSectionResizeMode(QtWidgets.QHeaderView.Stretch)
        self.combos = []
        for row, name in enumerate(self.source_names):
            item = QtWidgets.QTableWidgetItem(name)
            item.setFlags(item.flags() & ~QtCore.Qt.ItemIsEditable)
            self.table.setItem(row, 0, item)
            combo = QtWidgets.QComboBox()
            combo.addItems([NONE, *self.target_names])
            combo.currentIndexChanged.connect(self._changed)
            self.table.setCellWidget(row, 1, combo)
            self.combos.append(combo)
        self.problem = QtWidgets.QLabel()
        self.problem.setWordWrap(True)
        self.problem.setStyleSheet("color: #e07070")
        box = QtWidgets.QDialogButtonBox()
        role = QtWidgets.QDialogButtonBox
        self.load_button = box.addButton("Load map...", role.ActionRole)
        self.save_button = box.addButton("Save map...", role.ActionRole)
        self.auto_button = box.addButton("Automatic map", role.ActionRole)
        self.retarget_button = box.addButton("Retarget with this map", role.ActionRole)
        self.add_button = box.addButton("Add clip", role.AcceptRole)
        self.cancel_button = box.addButton(role.Cancel)
        self.load_button.clicked.connect(self.load_requested)
        self.save_button.clicked.connect(self.save_requested)
        self.auto_button.clicked.connect(lambda: self.retarget.emit(None))
        self.retarget_button.clicked.connect(lambda: self.retarget.emit(self.mapping()))
        box.accepted.connect(self.accept)
        box.rejected.connect(self.reject)
        layout = QtWidgets.QVBoxLayout(self)
        layout.addWidget(self.summary)
        layout.addWidget(self.table, 1)
        layout.addWidget(self.problem)
        layout.addWidget(box)
        self.resize(560, 620)
        self._busy = False
        self._changed()

    # ------------------------------------------------------------------ the table
    def mapping(self):
        """The map as the table shows it: ``{motion joint: character joint}``."""
        return {src: combo.currentText() for src, combo in zip(self.source_names, self.combos)
                if combo.currentText() != NONE}

    def set_mapping(self, mapping):
        """Show ``mapping`` in the table (names not in the skeletons are ignored)."""
        for src, combo in zip(self.source_names, self.combos):
            combo.blockSignals(True)
            target = mapping.get(src, NONE)
            combo.setCurrentIndex(max(combo.findText(target), 0))
            combo.blockSignals(False)
        self._changed()

    def repeats(self):
        """Character joints chosen for more than one motion joint."""
        return sorted(t for t, n in Counter(self.mapping().values()).items() if n > 1)

    def show_result(self, mapping, text):
        """A retarget finished with ``mapping``; ``text`` says what it gave. ``mapping``
        None: it failed (``text`` says why) and there is no clip to add."""
        self.used = None if mapping is None else dict(mapping)
        if mapping is not None:
            self.set_mapping(mapping)
        self.summary.setText(text)
        self._changed()

    def set_busy(self, busy):
        """While a retarget runs, nothing here can start another one or add a clip."""
        self._busy = bool(busy)
        self._changed()

    def _changed(self, *_):
        repeats = self.repeats()
        edited = self.used is None or self.mapping() != self.used
        if repeats:
            self.problem.setText(f"Each character joint can be driven once: "
                                 f"{', '.join(repeats)} chosen more than once.")
        elif edited and self.used is not None:
            self.problem.setText("The map was edited: retarget with it before adding "
                                 "the clip.")
        else:
            self.problem.setText("")
        free = not self._busy
        self.retarget_button.setEnabled(free and edited and not repeats and
                                        bool(self.mapping()))
        self.add_button.setEnabled(free and not edited)
        self.save_button.setEnabled(free and not repeats and bool(self.mapping()))
        self.load_button.setEnabled(free)
        self.auto_button.setEnabled(free)
