"""An image of a window with its OpenGL 3D view painted in (``grab()`` alone may miss it)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from PyQt5 import QtCore, QtGui, QtWidgets

__all__ = ["window_image"]


def window_image(window, plotter, path=None):
    """Image of ``window`` with ``plotter``'s view in it; saved when ``path`` is given.

    Parameters
    ----------
    window : QWidget
    plotter : pyvistaqt.QtInteractor
        A child of ``window``.
    path : str or Path, optional

    Returns
    -------
    QImage
    """
    plotter.render()
    QtWidgets.QApplication.processEvents()
    plotter.render()
    image = window.grab().toImage()
    # The GL view is a native window that grab() may not capture: paint its own image in.
    view = plotter.screenshot(return_img=True)
    h, w = view.shape[:2]
    view = np.ascontiguousarray(view[:, :, :3])
    qimg = QtGui.QImage(view.data, w, h, 3 * w, QtGui.QImage.Format_RGB888)
    top_left = plotter.mapTo(window, QtCore.QPoint(0, 0))
    ratio = window.devicePixelRatioF()
    painter = QtGui.QPainter(image)
    painter.drawImage(QtCore.QRectF(top_left.x() * ratio, top_left.y() * ratio,
                                    plotter.width() * ratio, plotter.height() * ratio), qimg)
    painter.end()
    if path is not None:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        if not image.save(str(path)):
            raise OSError(f"{path}: cannot write the screenshot")
    return image
