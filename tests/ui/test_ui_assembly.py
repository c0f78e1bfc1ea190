"""The window is assembled from parts (issue 18): one table places every action, no module
patches a menu afterwards or sets attributes on the window, and the one private attribute of
pyvistaqt the editor reads is named in one wrapper that checks it and falls back."""
import re

import pytest

from testpaths import REPO

pytestmark = pytest.mark.ui

UI = REPO / "rigedit" / "ui"


def _names():
    from rigedit.ui.menus import MENUS, TOOLBAR, TOOLBAR_ROWS, Label

    names = [n for _, sections in MENUS for section in sections for n in section]
    names += [n for n in TOOLBAR if n is not None and not isinstance(n, Label)]
    return set(names) | set(TOOLBAR_ROWS)


def _actions(parent):
    from PyQt5 import QtWidgets

    from rigedit.ui.menus import TOOLBAR_ROWS

    return {n: (QtWidgets.QToolBar(n, parent) if n in TOOLBAR_ROWS
                else QtWidgets.QAction(n, parent)) for n in _names()}


def test_the_menu_table_places_every_action_once_and_in_order(qtbot):
    from PyQt5 import QtWidgets

    from rigedit.ui.menus import MENUS, build_menus

    window = QtWidgets.QMainWindow()
    qtbot.addWidget(window)
    actions = _actions(window)
    tools = build_menus(window, actions)
    for (title, sections), top in zip(MENUS, window.menuBar().actions()):
        assert top.text() == title
        got = [a.text() or "----" for a in top.menu().actions()]
        want = "|----|".join("|".join(s) for s in sections).split("|")
        assert got == want
    assert actions["weight_brush"] in tools.actions()


def test_a_name_no_part_made_and_an_action_no_table_places_are_errors(qtbot):
    from PyQt5 import QtWidgets

    from rigedit.ui.menus import build_menus

    window = QtWidgets.QMainWindow()
    qtbot.addWidget(window)
    actions = _actions(window)
    del actions["save_as"]
    with pytest.raises(KeyError, match="save_as"):
        build_menus(window, actions)
    window = QtWidgets.QMainWindow()
    qtbot.addWidget(window)
    actions = _actions(window)
    actions["forgotten"] = QtWidgets.QAction("Forgotten", window)
    with pytest.raises(ValueError, match="forgotten"):
        build_menus(window, actions)


def test_the_window_has_the_tables_menus(demo_window):
    from rigedit.ui.menus import MENUS

    tops = [a.text() for a in demo_window.menuBar().actions()]
    assert tops == [title for title, _ in MENUS]
    file_menu = demo_window.menuBar().actions()[0].menu()
    texts = [a.text() for a in file_menu.actions()]
    assert texts.index("Export &video...") == texts.index("Save screenshot...") - 1
    assert texts[texts.index("&Recompute weights") + 1] == "Recompute weights with"


def test_no_module_patches_menus_or_sets_attributes_on_the_window():
    index = re.compile(r"menuBar\(\)\.actions\(\)\[")
    by_label = re.compile(r"\.text\(\)\.(replace|startswith)\(")
    foreign = re.compile(r"\b(window|self\.w|self\.window)\.[a-z_]+ = ")
    for path in sorted(UI.glob("*.py")):
        text = path.read_text()
        assert not index.search(text), f"{path.name} patches a menu by index"
        assert not by_label.search(text), f"{path.name} finds an action by its label"
        assert not foreign.search(text), f"{path.name} sets an attribute on the window"
        assert "Mixin" not in text, f"{path.name} has a mixin"


def test_only_qt_render_names_pyvistaqts_in_paint():
    users = [p.name for p in sorted((REPO / "rigedit").rglob("*.py"))
             if "_in_paint" in p.read_text()]
    assert users == ["qt_render.py"]


def test_in_paint_is_checked_at_import_and_falls_back(qtbot, monkeypatch):
    from PyQt5 import QtWidgets
    from pyvistaqt import QtInteractor

    from rigedit.ui import qt_render

    assert qt_render.HAS_IN_PAINT  # the pyvistaqt installed keeps the attribute
    assert not qt_render._sets_attribute(QtInteractor, "_no_such_attribute")
    parent = QtWidgets.QWidget()
    qtbot.addWidget(parent)
    plotter = QtInteractor(parent, multi_samples=0, auto_update=False)
    try:
        assert qt_render.in_paint(plotter) is False   # not painting now
        monkeypatch.setattr(qt_render, "HAS_IN_PAINT", False)
        assert qt_render.in_paint(plotter) is False
        # without the attribute no redirect: VTK keeps rendering its own requests
        assert qt_render.route_renders_through_qt(plotter, lambda: None) is False
        assert plotter.iren.interactor.GetEnableRender()
        monkeypatch.setattr(qt_render, "HAS_IN_PAINT", True)
        assert qt_render.route_renders_through_qt(plotter, lambda: None) is True
        assert not plotter.iren.interactor.GetEnableRender()
    finally:
        plotter.close()
