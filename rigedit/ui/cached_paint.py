"""A widget's picture cached in a pixmap, so a small change (a moving time cursor) repaints a
thin strip from it instead of painting everything again (the timeline's ruler, the graph
editor's canvas)."""
from __future__ import annotations

from PyQt5 import QtCore, QtGui

__all__ = ["cached_picture"]


def cached_picture(widget, pixmap, paint):
    """``pixmap`` when it is still valid for ``widget``'s pixel ratio, else a new transparent
    one of the widget's size painted by ``paint(pixmap)``.

    Parameters
    ----------
    widget : QWidget
    pixmap : QPixmap or None
        The cached picture (None: it must be painted again).
    paint : callable
        ``paint(device)`` paints the picture.

    Returns
    -------
    QPixmap
    """
    ratio = widget.devicePixelRatioF()
    if pixmap is None or pixmap.devicePixelRatioF() != ratio:
        pixmap = QtGui.QPixmap(widget.size() * ratio)
        pixmap.setDevicePixelRatio(ratio)
        pixmap.fill(QtCore.Qt.transparent)
        paint(pixmap)
    return pixmap
