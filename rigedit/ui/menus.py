"""The one place that says where each action goes: the menu bar and the tool bars.

Each part of the window makes its own actions and hands them over by name (its ``actions()``
mapping); :func:`build_menus` places them by the tables below. A name in a table that no part
gave, or an action no table places, is an error at start-up, so a new action cannot be lost
and no menu is patched afterwards by index or by label.
"""
from __future__ import annotations

from PyQt5 import QtCore, QtGui, QtWidgets

__all__ = ["MENUS", "TOOLBAR", "TOOLBAR_ROWS", "Label", "build_menus", "make_action"]


class Label(str):
    """A tool bar entry that is a text label, not an action (``Label(" Mode ")``)."""


#: menu title -> its sections (separated by lines), each a tuple of action names. An entry
#: may be a QMenu (a submenu).
MENUS = (
    ("&File", (("open_folder", "open_mesh_skeleton", "open_file", "autorig", "reembed",
                "import_motion"),
               ("save", "save_as"),
               ("export", "export_compressed", "export_pose", "export_skeleton"),
               ("load_weights", "save_weights", "recompute_weights", "recompute_with"),
               ("export_video", "save_screenshot", "quit"))),
    ("&Edit", (("undo", "redo"),
               ("reset_joint", "reset_pose", "mirror_l_to_r", "mirror_r_to_l"))),
    ("&View", (("solid", "translucent", "wireframe"),
               ("skeleton", "gizmos", "weights", "weight_brush", "dqs", "floor",
                "compare_compressed"),
               ("front", "side", "top", "back", "reset_camera"),
               ("joints_dock", "info_dock", "shapes_dock", "timeline_dock", "graph_dock"))),
)

#: The "Tools" tool bar: action or widget names, :class:`Label` texts, None for a separator.
TOOLBAR = (Label(" Mode "), "pose_mode", "edit_mode", None,
           Label(" IK chain "), "chain_spin", None,
           Label(" Axis "), "axis_free", "axis_x", "axis_y", "axis_z", None,
           "solid", "translucent", "wireframe", None,
           "skeleton", "gizmos", "weights", "weight_brush", None,
           "front", "side", "top", "reset_view")

#: Tool bars (QToolBar entries) on rows of their own below the "Tools" one.
TOOLBAR_ROWS = ("weight_brush_bar",)


def make_action(parent, text, slot, shortcut=None, checkable=False, checked=False, tip=None):
    """A QAction of ``parent`` calling ``slot`` (``toggled`` when ``checkable``, else
    ``triggered``)."""
    act = QtWidgets.QAction(text, parent)
    if shortcut:
        act.setShortcut(QtGui.QKeySequence(shortcut))
    act.setCheckable(checkable)
    if checkable:
        act.setChecked(checked)
        act.toggled.connect(slot)
    else:
        act.triggered.connect(slot)
    if tip:
        act.setStatusTip(tip)
        act.setToolTip(tip)
    return act


def build_menus(window, actions):
    """Place ``actions`` (name -> QAction, QMenu, QWidget or QToolBar) into ``window``'s menu
    bar and tool bars by :data:`MENUS`, :data:`TOOLBAR` and :data:`TOOLBAR_ROWS`.

    Returns
    -------
    toolbar : QToolBar
        The "Tools" tool bar.

    Raises
    ------
    KeyError
        A table names an action no part gave.
    ValueError
        A part gave an action no table places.
    """
    placed = set()

    def take(name):
        if name not in actions:
            raise KeyError(f"the menus place {name!r}, which no part of the window made")
        placed.add(name)
        return actions[name]

    bar = window.menuBar()
    for title, sections in MENUS:
        menu = bar.addMenu(title)
        for k, section in enumerate(sections):
            if k:
                menu.addSeparator()
            for name in section:
                item = take(name)
                (menu.addMenu if isinstance(item, QtWidgets.QMenu) else menu.addAction)(item)
    toolbar = _tool_bar(window, take)
    for name in TOOLBAR_ROWS:
        window.addToolBarBreak()
        window.addToolBar(take(name))
    left = sorted(set(actions) - placed)
    if left:
        raise ValueError(f"no menu or tool bar places {', '.join(left)}")
    return toolbar


def _tool_bar(window, take):
    tb = window.addToolBar("Tools")
    tb.setObjectName("tools")
    tb.setMovable(False)
    tb.setIconSize(QtCore.QSize(16, 16))
    tb.setToolButtonStyle(QtCore.Qt.ToolButtonTextOnly)
    for entry in TOOLBAR:
        if entry is None:
            tb.addSeparator()
        elif isinstance(entry, Label):
            tb.addWidget(QtWidgets.QLabel(entry))
        else:
            item = take(entry)
            (tb.addAction if isinstance(item, QtWidgets.QAction) else tb.addWidget)(item)
    return tb
