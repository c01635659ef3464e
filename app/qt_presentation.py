"""QtPresentation: the studio as a teacher shows it to a class.

Installed on a :class:`gcmh_studio.qt_main_window.QtMainWindow` (``QtPresentation(window)``; a
second one replaces the first, so installing is idempotent), it adds:

* **Presentation mode** (F11 toggles, Esc leaves; View menu): full screen, the side
  panel, menus and status bar hidden, the 3D view filling the screen, the title,
  subtitle, colour bar and legend in larger type, and the system typeset in the
  bottom right corner of the view (:mod:`gcmh_studio.typeset`: sympy's LaTeX drawn by
  matplotlib's mathtext into an image drawn by VTK inside the render window, so the
  view's own pixels carry it: :mod:`gcmh_studio.formula_card`). Leaving restores the
  layout as it was (:mod:`gcmh_studio.qt_view_alone`).
* **The control strip** (:mod:`gcmh_studio.qt_presentation_strip`; H while presenting hides it and brings
  it back): beside the view, in large type, the parameters' sliders, the slice, the turn of a plane and
  the animation to play; Space plays it live in the view (a rotation, a tour, a slice sweep or a
  parameter sweep: coarse steps while it moves, the full grid where it stops).  A parameter set here, or
  by a playing sweep (the controller's ``events.sweep``), goes through the formula panel's own parameter
  input, as a hand on its slider would.
* **Axes with ticks** (View menu; key A while presenting): pyvista's bounds axes
  around the object, titled with the projection's axes ("y = Im z", or a mixture such
  as "0.71 x + 0.71 w" while a hidden direction is turned in): :mod:`gcmh_studio.bounds_axes`.
* **Next / previous example** (Examples menu; PageDown / PageUp while presenting,
  what a presenter's remote sends): the gallery's examples in order, each opened and
  run by the window's own :meth:`load_example`, as the gallery opens them; a run
  under way is cancelled first (:class:`gcmh_studio.qt_gallery_walk.QtGalleryWalk`).

The window's menus stay as they are; this controller only adds actions through
``window.addAction`` and the menus' public ``addAction``.  It holds the window's side (actions,
keys, full screen, the strip, the walk); what the mode draws in the view (the card, a caption,
the larger type, the axes' framing) is :class:`gcmh_studio.view_decorations.ViewDecorations`,
and what the card shows :func:`gcmh_studio.presentation.card_key`.
"""

from __future__ import annotations

from qtpy.QtCore import QEvent, QObject, Qt, QTimer
from qtpy.QtGui import QKeySequence
from qtpy.QtWidgets import QAction, QApplication, QSplitter, QWidget

from .presentation import card_key
from .qt_gallery_walk import QtGalleryWalk
from .qt_presentation_strip import QtPresentationStrip
from .qt_view_alone import restore_layout, view_alone
from .view_decorations import FORMULA_ACTOR, ViewDecorations

__all__ = ["FORMULA_ACTOR", "QtPresentation"]

OBJECT_NAME = "gcmh-presentation"


class _Keys(QObject):
    """Esc while presenting leaves (the Run menu's Cancel also has Esc: a second shortcut would make
    both ambiguous, so the key is caught before the shortcut map sees it)."""

    def __init__(self, presentation: QtPresentation):
        super().__init__(presentation)
        self.presentation = presentation

    def eventFilter(self, obj, ev) -> bool:
        p = self.presentation
        if (ev.type() in (QEvent.ShortcutOverride, QEvent.KeyPress) and p.presenting
                and ev.key() == Qt.Key_Escape and isinstance(obj, QWidget) and obj.window() is p.window):
            ev.accept()
            if ev.type() == QEvent.KeyPress:
                QTimer.singleShot(0, p.leave)
            return True
        if ev.type() == QEvent.Resize and obj is p.window.viewer.widget:
            p._relayout.start()
        elif ev.type() == QEvent.Close and obj is p.window:
            p.closing()
        return False


class QtPresentation(QObject):
    """Presentation mode, bounds axes and example stepping for ``window`` (see the module docstring)."""

    def __init__(self, window):
        super().__init__(window)
        for old in window.findChildren(QtPresentation, OBJECT_NAME):
            if old is not self:
                old.uninstall()
        self.setObjectName(OBJECT_NAME)
        self.window = window
        self.presenting = False
        self._saved: dict | None = None
        self._keys = _Keys(self)
        self._relayout = QTimer(self)
        self._relayout.setSingleShot(True)
        self._relayout.setInterval(80)
        self._relayout.timeout.connect(self._on_resized)
        self.decorations = ViewDecorations(window.viewer, self._card_resized)   # what it draws in the view
        self.walk = QtGalleryWalk(window, self.decorations.set_caption, self)

        self.present_action = self._action("&Presentation mode", "F11", self.toggle,
                                           "full screen: the view alone, larger type and the formula (F11; Esc leaves)")
        self.present_action.setCheckable(True)
        self.formula_action = self._action("Show the &formula", None, self.set_formula_shown,
                                           "the system typeset in the corner of the view (F while presenting)")
        self.formula_action.setCheckable(True)
        self.formula_action.setChecked(True)
        self.axes_action = self._action("&Axes with ticks", None, self.set_axes,
                                        "ticks and labels in the projected coordinates (A while presenting)")
        self.axes_action.setCheckable(True)
        self.next_action = self._action("&Next example", None, self.next_example,
                                        "the gallery's next example (Page Down while presenting)")
        self.previous_action = self._action("P&revious example", None, self.previous_example,
                                            "the gallery's previous example (Page Up while presenting)")
        self.strip_action = self._action("Control &strip", None, self.set_strip_shown,
                                         "the parameters, the slice, a turn and Play beside the view while "
                                         "presenting (H while presenting)")
        self.strip_action.setCheckable(True)
        self.strip_action.setChecked(True)
        self._menu_entries = []
        self._add_to_menu("View", [self.present_action, self.formula_action, self.axes_action, self.strip_action])
        self.strip = self._make_strip()
        self._add_to_menu("Examples", [self.next_action, self.previous_action])

        events = window.model.events   # the model's, not the View tab's: undo, sessions and animation turn it too
        self._connections = [(window.resultChanged, self._on_result), (window.runFinished, self._on_run_finished),
                             (events.projection, self._on_turned), (events.slice, self._on_turned),
                             (events.base, self._on_new_base)]
        for signal, slot in self._connections:   # after the viewer's own slots: it has framed the object
            signal.connect(slot)
        window.viewer.widget.installEventFilter(self._keys)
        window.installEventFilter(self._keys)
        window.viewer.picture_decorators.append(self.decorate)   # screenshots and animations show it too

    # ------------------------------------------------------------------ installing
    def _action(self, text: str, shortcut, slot, tip: str) -> QAction:
        a = QAction(text, self.window)
        a.setObjectName(f"{OBJECT_NAME}-{text.replace('&', '').split()[0].lower()}")
        if shortcut:
            a.setShortcut(QKeySequence(shortcut))
        a.setStatusTip(tip)
        a.setToolTip(tip)
        a.triggered.connect(slot)
        self.window.addAction(a)
        return a

    def _add_to_menu(self, title: str, actions) -> None:
        """Our entries at the end of the window's menu ``title`` (found by its text), after a separator."""
        for a in self.window.menuBar().actions():
            menu = a.menu()
            if menu is not None and a.text().replace("&", "") == title:
                sep = menu.addSeparator()
                self._menu_entries.append((menu, sep))
                for action in actions:
                    menu.addAction(action)
                    self._menu_entries.append((menu, action))
                return

    def actions(self) -> list[QAction]:
        return [self.present_action, self.formula_action, self.axes_action, self.next_action, self.previous_action,
                self.strip_action]

    def _make_strip(self) -> QtPresentationStrip:
        """The control strip, hidden, beside the view in its splitter (or over it, in another layout); its
        signals to the formula panel's parameters and the Animate tab, and a playing sweep's to the
        parameters too."""
        w = self.window
        strip = QtPresentationStrip(w.model)
        split = w.viewer.widget.parentWidget()
        if isinstance(split, QSplitter):
            split.addWidget(strip)
            split.setCollapsible(split.indexOf(strip), False)
        else:
            strip.setParent(w)
        strip.hide()
        ap = w.animation_panel
        strip.paramMoved.connect(self.set_parameter)
        strip.modeRequested.connect(ap.set_mode)
        strip.playRequested.connect(ap.toggle_play)
        self._strip_connections = [(ap.playingChanged, strip.set_playing), (ap.modeChanged, self._show_modes),
                                   (w.controller.events.sweep, self.set_parameter)]
        for signal, slot in self._strip_connections:
            signal.connect(slot)
        self.strip = strip
        self._show_modes()
        return strip

    def _show_modes(self, *_) -> None:
        ap = self.window.animation_panel
        modes = [ap.mode_combo.itemData(i) for i in range(ap.mode_combo.count())]
        self.strip.set_modes(modes, ap.mode())

    def set_parameter(self, name: str, value: float, final: bool = True) -> None:
        """Parameter ``name`` to ``value`` through the formula panel's own input, as a hand on its slider:
        not ``final`` (held, or a sweep playing) a coarse step, ``final`` the full grid."""
        from .qt_parameters import STEPS, step_value

        w = self.window
        params = w.formula_panel.parameters
        if name not in params.rows:
            return
        spec = params.rows[name].state   # (a sweep's value on the slider's grid: "a = 0.99", not 0.998123)
        lo, hi = float(spec["min"]), float(spec["max"])
        if hi > lo and lo <= value <= hi:
            value = step_value(lo, hi, int(round((value - lo) / (hi - lo) * STEPS)))
        params.set_value(name, value, commit=bool(final))   # (final: "committed", the full step)
        if not final:
            w.controller.parameter_step(True, moved=name)

    def set_strip_shown(self, on: bool) -> None:
        """The control strip on or off (it is shown only while presenting)."""
        if self.strip_action.isChecked() != bool(on):
            self.strip_action.setChecked(bool(on))
        if on and self.presenting:
            handle = self.window.windowHandle()
            screen = handle.screen() if handle is not None else None
            self.strip.fit_width(screen.geometry().width() if screen is not None else self.window.width())
            self.strip.refresh()
            self._show_modes()
            self.strip.set_playing(self.window.animation_panel.is_playing())
        self.strip.setVisible(bool(on) and self.presenting)

    def uninstall(self) -> None:
        """Take this controller's actions, menu entries, overlays and hooks off the window."""
        if self.presenting:
            self.leave()
        self.set_axes(False)
        for menu, a in self._menu_entries:
            menu.removeAction(a)
        self._menu_entries = []
        for a in self.actions():
            self.window.removeAction(a)
            a.setEnabled(False)
        for signal, slot in self._connections:
            try:
                signal.disconnect(slot)
            except (TypeError, RuntimeError):
                pass
        self.window.viewer.widget.removeEventFilter(self._keys)
        self.window.removeEventFilter(self._keys)
        for signal, slot in self._strip_connections:
            try:
                signal.disconnect(slot)
            except (TypeError, RuntimeError):
                pass
        self.strip.disconnect_model()
        self.strip.hide()
        self.strip.deleteLater()
        if self.decorate in self.window.viewer.picture_decorators:
            self.window.viewer.picture_decorators.remove(self.decorate)
        self.decorations.detach()
        self.setObjectName("")

    def closing(self) -> None:
        """The window closes (its plotter with it): out of presentation mode, and no more render hooks."""
        self.leave()
        self._relayout.stop()
        self.decorations.detach()

    # ------------------------------------------------------------------ presentation mode
    def toggle(self) -> None:
        """F11: into presentation mode, or back out of it."""
        if self.presenting:
            self.leave()
        else:
            self.enter()

    def enter(self) -> None:
        """Full screen, the view alone, larger type and the formula; :meth:`leave` undoes each step."""
        w = self.window
        if self.presenting:
            return
        self._saved = view_alone(w, w.viewer.widget, exclude=self.actions())
        self.presenting = self.decorations.large_type = True
        QApplication.instance().installEventFilter(self._keys)
        self.axes_action.setShortcut(QKeySequence("A"))
        self.formula_action.setShortcut(QKeySequence("F"))
        self.strip_action.setShortcut(QKeySequence("H"))
        self.next_action.setShortcuts([QKeySequence(Qt.Key_PageDown)])
        self.previous_action.setShortcuts([QKeySequence(Qt.Key_PageUp)])
        self.present_action.setChecked(True)
        screen = w.windowHandle().screen() if w.windowHandle() is not None else None
        if screen is not None:   # the screen's size first: without a window manager nobody else sets it
            w.setGeometry(screen.geometry())
        w.showFullScreen()
        self.set_strip_shown(self.strip_action.isChecked())
        w.viewer.widget.setFocus()
        self.update_formula()
        self._relayout.start()     # again once the full-screen size has arrived

    def leave(self) -> None:
        """Back to the layout as it was before :meth:`enter`."""
        w = self.window
        if not self.presenting:
            return
        self.presenting = self.decorations.large_type = False
        QApplication.instance().removeEventFilter(self._keys)
        for a in (self.formula_action, self.axes_action, self.next_action, self.previous_action, self.strip_action):
            a.setShortcuts([])
        self.strip.hide()
        self.present_action.setChecked(False)
        self.decorations.hide_card(render=False)
        self.decorations.set_caption("")
        self.decorations.restore_fonts()
        saved, self._saved = self._saved, None
        if saved is None:
            return
        restore_layout(w, saved)
        w.viewer.render()

    # ------------------------------------------------------------------ the formula and the axes
    def formula_key(self) -> tuple | None:
        """What the card shows: (formulas, variables, params, complex equations, complex variables)."""
        return card_key(self.window.model)

    def set_formula_shown(self, on: bool) -> None:
        """The typeset card on or off (it is shown only while presenting)."""
        if self.formula_action.isChecked() != bool(on):
            self.formula_action.setChecked(bool(on))
        if not on:
            self.decorations.hide_card()
        else:
            self.update_formula()

    def _card_shown(self) -> bool:
        return self.presenting and self.formula_action.isChecked()

    def update_formula(self) -> None:
        """Typeset the system on screen into the corner of the view (while presenting)."""
        if self._card_shown():
            self.decorations.show_card(self.formula_key())

    def decorate(self, plotter) -> None:
        """Draw on another plotter (an off-screen copy of the view, for a screenshot or an animation) what
        this mode adds to the view: the card while presenting, the axes when shown."""
        self.decorations.decorate(plotter, self.formula_key() if self._card_shown() else None)

    def formula_actor(self):
        """The VTK actor of the typeset card (None when none is shown)."""
        return self.decorations.card()

    def caption(self) -> str:
        return self.decorations.caption()

    def set_axes(self, on: bool) -> None:
        """Bounds axes (ticks and labels in the projected coordinates) on or off."""
        if self.axes_action.isChecked() != bool(on):
            self.axes_action.setChecked(bool(on))
        self.decorations.set_axes(on)

    def axes_shown(self) -> bool:
        return self.decorations.axes_shown()

    def _card_resized(self) -> None:
        if not self._relayout.isActive():
            self._relayout.start()

    # ------------------------------------------------------------------ walking the gallery
    def next_example(self) -> str | None:
        """Open and run the gallery's next example (after the last: the first); returns its name."""
        return self.step_example(1)

    def previous_example(self) -> str | None:
        """Open and run the gallery's previous example (before the first: the last); returns its name."""
        return self.step_example(-1)

    def step_example(self, step: int) -> str | None:
        return self.walk.step(step, say=self.presenting)

    def _on_run_finished(self, how: str) -> None:
        if self.walk.run_finished():
            return
        if how == "done" or not self.presenting:
            self.decorations.set_caption("")
        else:
            self.decorations.set_caption(self.window.last_status or f"run {how}", error=True)

    def _on_result(self, _cx) -> None:
        self.decorations.reframing.fit()
        if self.presenting:
            self.update_formula()

    def _on_turned(self) -> None:
        self.decorations.reframing.turned()

    def _on_new_base(self) -> None:
        self.decorations.reframing.fit()

    def _on_resized(self) -> None:
        """The view has its new size (after the viewer's own refit): the card and the axes follow."""
        if not (self.presenting or self.axes_shown()):
            return
        self.decorations.reframing.fit()
        self.update_formula()
        self.window.viewer.render()
