"""The graph editor's channel list: the selected joints' channels, each with its colour and a
check box that shows or hides its curve.

Which channels are hidden is kept by channel id across refreshes (an edit, another joint
selected and back), so hiding "rotation Y" stays hidden while the user works.
"""
from __future__ import annotations

from PyQt5 import QtCore, QtGui, QtWidgets

__all__ = ["ChannelList"]

_ID_ROLE = QtCore.Qt.UserRole


def _swatch(rgb, size=12):
    pix = QtGui.QPixmap(size, size)
    pix.fill(QtGui.QColor.fromRgbF(*(min(max(float(c), 0.0), 1.0) for c in rgb[:3])))
    return QtGui.QIcon(pix)


class ChannelList(QtWidgets.QListWidget):
    """Check boxes of the channels.

    Signals
    -------
    visibility_changed()   the set of hidden channels changed (read :attr:`hidden`)

    Attributes
    ----------
    hidden : set of ChannelId
    """

    visibility_changed = QtCore.pyqtSignal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.hidden = set()
        self._ids = []
        self.setSelectionMode(QtWidgets.QAbstractItemView.NoSelection)
        self.setUniformItemSizes(True)
        self.itemChanged.connect(self._on_item_changed)
        self.setToolTip("Tick a channel to show its curve")

    def set_channels(self, channels):
        """List ``channels`` (ChannelView); a channel without a track (no curve) is listed
        greyed out."""
        self.blockSignals(True)
        self.clear()
        self._ids = []
        for c in channels:
            # one joint's channels: its name is the dock's, the rows say what and which axis
            text = c.label[len(c.id.joint) + 1:] if c.label.startswith(c.id.joint) else c.label
            item = QtWidgets.QListWidgetItem(_swatch(c.colour), text)
            item.setToolTip(c.label)
            flags = QtCore.Qt.ItemIsUserCheckable | QtCore.Qt.ItemIsEnabled
            if c.curve is None:
                flags &= ~QtCore.Qt.ItemIsEnabled
                item.setToolTip(f"{c.label}: no keys in this clip")
            item.setFlags(flags)
            # a channel without keys draws nothing: unticked, but not hidden (keyed, it shows)
            item.setCheckState(QtCore.Qt.Unchecked if c.id in self.hidden or c.curve is None
                               else QtCore.Qt.Checked)
            item.setData(_ID_ROLE, len(self._ids))
            self._ids.append(c.id)
            self.addItem(item)
        self.blockSignals(False)

    def set_shown(self, channel_id, shown):
        """Show or hide one channel (as its check box does)."""
        for row, cid in enumerate(self._ids):
            if cid == channel_id:
                self.item(row).setCheckState(QtCore.Qt.Checked if shown else QtCore.Qt.Unchecked)
                return
        raise KeyError(f"no channel {channel_id!r} in the list")

    def _on_item_changed(self, item):
        cid = self._ids[item.data(_ID_ROLE)]
        before = cid in self.hidden
        if item.checkState() == QtCore.Qt.Checked:
            self.hidden.discard(cid)
        else:
            self.hidden.add(cid)
        if before != (cid in self.hidden):
            self.visibility_changed.emit()
