"""A dark Fusion palette, as 3D tools use, so the view and the panels read as one."""
from __future__ import annotations

from PyQt5 import QtGui

__all__ = ["apply_dark_palette"]


def apply_dark_palette(app):
    p = QtGui.QPalette()
    c = QtGui.QColor
    base, window, text, accent = c(36, 39, 45), c(48, 52, 59), c(222, 225, 230), c(74, 144, 226)
    p.setColor(QtGui.QPalette.Window, window)
    p.setColor(QtGui.QPalette.WindowText, text)
    p.setColor(QtGui.QPalette.Base, base)
    p.setColor(QtGui.QPalette.AlternateBase, window)
    p.setColor(QtGui.QPalette.ToolTipBase, c(25, 27, 31))
    p.setColor(QtGui.QPalette.ToolTipText, text)
    p.setColor(QtGui.QPalette.Text, text)
    p.setColor(QtGui.QPalette.Button, c(58, 63, 71))
    p.setColor(QtGui.QPalette.ButtonText, text)
    p.setColor(QtGui.QPalette.Highlight, accent)
    p.setColor(QtGui.QPalette.HighlightedText, c(255, 255, 255))
    p.setColor(QtGui.QPalette.Link, accent)
    for role in (QtGui.QPalette.Text, QtGui.QPalette.ButtonText, QtGui.QPalette.WindowText):
        p.setColor(QtGui.QPalette.Disabled, role, c(120, 124, 130))
    app.setPalette(p)
    app.setStyleSheet("QToolBar { spacing: 3px; padding: 2px; } "
                      "QToolButton:checked { background: #4a90e2; color: white; "
                      "border-radius: 3px; } "
                      "QDockWidget::title { padding: 4px; background: #2b2f35; }")
