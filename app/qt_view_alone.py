"""The view alone in its window, and the layout back as it was: what presentation mode hides and restores."""

from __future__ import annotations

from qtpy.QtCore import Qt
from qtpy.QtWidgets import QAction, QDockWidget, QSplitter, QToolBar, QWidget


def view_alone(window, view: QWidget, exclude=()) -> dict:
    """Hide everything of ``window`` but ``view``: its ancestors' siblings (the side panel), docks, tool bars,
    the menu and status bars. The menus' shortcuts (but those of ``exclude``) keep working with the menu bar
    hidden. Returns what :func:`restore_layout` needs (the window's state and geometry are saved too)."""
    w = window
    saved: dict = dict(state=w.windowState(), geometry=w.saveGeometry(), hidden=[], splitters=[], added=[])
    child = view
    while child is not None and child is not w:
        parent = child.parentWidget()
        if isinstance(parent, QSplitter):
            saved["splitters"].append((parent, parent.saveState()))
        if parent is not None and parent is not w:
            for sib in parent.findChildren(QWidget, options=Qt.FindDirectChildrenOnly):
                if sib is not child and sib.isVisible() and not sib.isWindow() \
                        and type(sib).__name__ != "QSplitterHandle":
                    saved["hidden"].append(sib)
        child = parent
    for kind in (QDockWidget, QToolBar):
        saved["hidden"] += [d for d in w.findChildren(kind) if d.isVisible()]
    for bar in (w.menuBar(), w.statusBar()):
        if bar.isVisible():
            saved["hidden"].append(bar)
    # (Space, Ctrl+R, ...)
    for a in menu_shortcut_actions(w.menuBar(), exclude):
        if a not in w.actions():
            w.addAction(a)
            saved["added"].append(a)
    for sib in saved["hidden"]:
        sib.hide()
    return saved


def restore_layout(window, saved: dict) -> None:
    """The layout of ``window`` as it was before :func:`view_alone` returned ``saved``."""
    w = window
    for a in saved["added"]:
        w.removeAction(a)
    w.setWindowState(saved["state"])
    if not saved["state"] & (Qt.WindowFullScreen | Qt.WindowMaximized):
        w.restoreGeometry(saved["geometry"])
    for sib in saved["hidden"]:
        sib.show()
    for splitter, state in saved["splitters"]:
        splitter.restoreState(state)


def menu_shortcut_actions(menubar, exclude=()) -> list[QAction]:
    """The actions with a shortcut in ``menubar``'s menus and their submenus, but those of ``exclude``."""
    found, todo = [], [menubar]
    while todo:
        for a in todo.pop().actions():
            if a.menu() is not None:
                todo.append(a.menu())
            elif not a.shortcut().isEmpty() and a not in exclude:
                found.append(a)
    return found
