"""QtPresentation: the studio as a teacher shows it to a class.

Installed on a :class:`gcmh_studio.qt_main_window.QtMainWindow` (``QtPresentation(window)``; a
second one replaces the first, so installing is idempotent), it adds:

* **Presentation mode** (F11 toggles, Esc leaves; View menu): full screen, the side
  panel, menus and status bar hidden, the 3D view filling the screen, the title,
  subtitle, colour bar and legend in larger type, and the system typeset in the
  bottom right corner of the view (:mod:`gcmh_studio.typeset`: sympy's LaTeX drawn by
  matplotlib's mathtext into an image drawn by VTK inside the render window, so the
  view's own pixels carry it). Leaving restores the layout as it was.
* **Axes with ticks** (View menu; key A while presenting): pyvista's bounds axes
  around the object, titled with the projection's axes ("y = Im z", or a mixture such
  as "0.71 x + 0.71 w" while a hidden direction is turned in).
* **Next / previous example** (Examples menu; PageDown / PageUp while presenting,
  what a presenter's remote sends): the gallery's examples in order, each opened and
  run by the window's own :meth:`load_example`, as the gallery opens them; a run
  under way is cancelled first.

The window's menus stay as they are; this controller only adds actions through
``window.addAction`` and the menus' public ``addAction``.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np
from qtpy.QtCore import QEvent, QObject, Qt, QTimer
from qtpy.QtGui import QKeySequence
from qtpy.QtWidgets import QAction, QApplication, QDockWidget, QSplitter, QToolBar, QWidget

from gcmh_core.examples import Example

from .typeset import typeset_system

FORMULA_ACTOR = "gcmh-formula"       # the typeset system, bottom right
CAPTION_ACTOR = "gcmh-caption"       # what is happening (loading the next example), top right
TEXT_ACTORS = ("gcmh-title", "gcmh-subtitle", "gcmh-legend")   # the scene's texts, enlarged while presenting
FONT_SCALE = 1.5                     # larger type for a room
AXES_FONT = 13                       # the bounds axes' labels (points; times FONT_SCALE while presenting)
# where the axes' box may lie (-1..1 across the picture, as gcmh_studio.camera.screen_coordinates): clear of the
# colour bar (right), the title (top) and the card (bottom right), with room for the tick labels outside it
AXES_X, AXES_TOP, AXES_BOTTOM = 0.70, 0.66, 0.56
FORMULA_LINES_PER_HEIGHT = 27        # the formula's font: the view's height / this, in pixels
FORMULA_MAX = (0.62, 0.3)            # the card's largest share of the view (width, height)
BELOW_BAR = 0.165                    # with a colour bar (from 0.2 of the height up): the card stays under it
MARGIN = 16                          # pixels between the card and the view's edge
OBJECT_NAME = "gcmh-presentation"


@functools.lru_cache(maxsize=1)
def _examples():
    from gcmh_core.examples import list_examples

    return tuple(list_examples())


def example_names() -> list[str]:
    """The examples in the gallery's order (the gallery shows :func:`gcmh_core.examples.list_examples`)."""
    try:
        return [ex.name for ex in _examples()]
    except Exception:  # noqa: BLE001 - a broken examples folder: nothing to walk through
        return []


def example_for(title: str, names: Sequence[str]) -> Example | None:
    """The example a result with this title and these variables came from, or None (a system typed in)."""
    if not title:
        return None
    try:
        for ex in _examples():
            if ex.title == title and list(ex.variables) == list(names):
                return ex
    except Exception:  # noqa: BLE001
        return None
    return None


def image_actor(rgba: np.ndarray):
    """A VTK 2D actor drawing an (h, w, 4) uint8 RGBA image at a pixel position (alpha-blended)."""
    # (vtkmodules, not ``import vtk``: that loads every VTK module, 1.3 s on the GUI thread)
    from vtkmodules.util import numpy_support
    from vtkmodules.util.vtkConstants import VTK_UNSIGNED_CHAR
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkRenderingCore import vtkActor2D, vtkImageMapper

    h, w = rgba.shape[:2]
    data = vtkImageData()
    data.SetDimensions(w, h, 1)
    flat = np.ascontiguousarray(rgba[::-1].reshape(-1, 4))      # VTK's rows go up
    arr = numpy_support.numpy_to_vtk(flat, deep=True, array_type=VTK_UNSIGNED_CHAR)
    arr.SetNumberOfComponents(4)
    data.GetPointData().SetScalars(arr)
    mapper = vtkImageMapper()
    mapper.SetInputData(data)
    mapper.SetColorWindow(255.0)
    mapper.SetColorLevel(127.5)
    actor = vtkActor2D()
    actor.SetMapper(mapper)
    actor.image_size = (w, h)
    return actor


def _text_card(lines, font_size: int):
    """The card as plain text (when no image can be made): a VTK text actor, right-justified."""
    from vtkmodules.vtkRenderingCore import vtkTextActor

    actor = vtkTextActor()
    actor.SetInput("\n".join(lines))
    prop = actor.GetTextProperty()
    prop.SetFontSize(font_size)
    prop.SetJustificationToRight()
    prop.SetVerticalJustificationToBottom()
    prop.SetColor(0.96, 0.97, 0.99)
    prop.SetBackgroundColor(0.05, 0.06, 0.09)
    prop.SetBackgroundOpacity(0.72)
    return actor


def axis_titles(scene) -> list[str]:
    """The screen axes' titles: the projection's label of each ("s", "0.71 x + 0.71 w") with what a
    plain variable means ("y = Im z"), and the mapping when it is not orthographic."""
    titles = []
    for label in scene.axes_labels():
        titles.append(scene.style.label(label) if label in scene.names else label)
    mapping = getattr(scene.view, "mapping", "orthographic")
    if mapping != "orthographic":
        titles = [f"{t} ({mapping})" if t else t for t in titles]
    return titles


def add_axes(plotter, key: tuple):
    """pyvista's bounds axes on ``plotter`` for ``key`` = (bounds, titles, shown ranges, font size, label
    counts), remembered on the actor as ``_gcmh_key``."""
    bounds, titles, ranges, font, counts = key
    actor = plotter.show_bounds(bounds=bounds, axes_ranges=ranges, xtitle=titles[0], ytitle=titles[1],
                                ztitle=titles[2], location="outer", ticks="outside", font_size=font,
                                color="#e6e9f0", bold=False, n_xlabels=counts[0], n_ylabels=counts[1],
                                n_zlabels=counts[2], fmt="{0:.2g}", use_3d_text=False, render=False)
    actor._gcmh_key = key
    return actor


def axis_offsets(scene) -> np.ndarray:
    """(3,): what each screen axis adds back to the drawn coordinates, which are centred on the
    object's middle (``P (x - c)``, :mod:`gcmh_studio.projection`): the ticks show ``P x``."""
    try:
        return np.asarray(scene.view.P, dtype=float) @ np.asarray(scene.projector.center, dtype=float)
    except Exception:  # noqa: BLE001 - no projection yet
        return np.zeros(3)


class _Keys(QObject):
    """Esc while presenting leaves (the Run menu's Cancel also has Esc: a second shortcut would make
    both ambiguous, so the key is caught before the shortcut map sees it)."""

    def __init__(self, presentation: QtPresentation):
        super().__init__(presentation)
        self.presentation = presentation

    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 - Qt's name
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
        self.current: str | None = None      # the example last opened by stepping
        self._pending: str | None = None     # the example to open when the cancelled run has ended
        self._saved: dict | None = None
        self._formula = None                 # (actor, key it was typeset for)
        self._caption = None
        self._base_fonts: dict[int, tuple] = {}
        self._reframe: str | None = None     # "fit" or "out": frame the axes' box at the next render
        self._keys = _Keys(self)
        self._relayout = QTimer(self)
        self._relayout.setSingleShot(True)
        self._relayout.setInterval(80)
        self._relayout.timeout.connect(self._on_resized)

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
        self._menu_entries = []
        self._add_to_menu("View", [self.present_action, self.formula_action, self.axes_action])
        self._add_to_menu("Examples", [self.next_action, self.previous_action])

        pp = window.projection_panel
        self._connections = [(window.resultChanged, self._on_result), (window.runFinished, self._on_run_finished),
                             (pp.projectionChanged, self._on_turned), (pp.sliceChanged, self._on_turned),
                             (pp.baseChanged, self._on_new_base)]
        for signal, slot in self._connections:   # after the viewer's own slots: it has framed the object
            signal.connect(slot)
        window.viewer.widget.installEventFilter(self._keys)
        window.installEventFilter(self._keys)
        window.viewer.picture_decorators.append(self.decorate)   # screenshots and animations show it too
        self._observer = window.plotter.ren_win.AddObserver("StartEvent", self._before_render)

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
        return [self.present_action, self.formula_action, self.axes_action, self.next_action, self.previous_action]

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
        if self.decorate in self.window.viewer.picture_decorators:
            self.window.viewer.picture_decorators.remove(self.decorate)
        try:
            self.window.plotter.ren_win.RemoveObserver(self._observer)
        except Exception:  # noqa: BLE001 - the render window is gone already
            pass
        self.setObjectName("")

    def closing(self) -> None:
        """The window closes (its plotter with it): out of presentation mode, and no more render hooks."""
        self.leave()
        self._relayout.stop()
        try:
            self.window.plotter.ren_win.RemoveObserver(self._observer)
        except Exception:  # noqa: BLE001 - the render window is gone already
            pass

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
        saved = dict(state=w.windowState(), geometry=w.saveGeometry(), hidden=[], splitters=[], added=[])
        # the view's ancestors' siblings (the side panel), docks and tool bars
        child = w.viewer.widget
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
        # the menus' shortcuts (Space, Ctrl+R, ...) keep working with the menu bar hidden
        for a in self._menu_shortcut_actions():
            if a not in w.actions():
                w.addAction(a)
                saved["added"].append(a)
        for sib in saved["hidden"]:
            sib.hide()
        self._saved = saved
        self.presenting = True
        QApplication.instance().installEventFilter(self._keys)
        self.axes_action.setShortcut(QKeySequence("A"))
        self.formula_action.setShortcut(QKeySequence("F"))
        self.next_action.setShortcuts([QKeySequence(Qt.Key_PageDown)])
        self.previous_action.setShortcuts([QKeySequence(Qt.Key_PageUp)])
        self.present_action.setChecked(True)
        screen = w.windowHandle().screen() if w.windowHandle() is not None else None
        if screen is not None:   # the screen's size first: without a window manager nobody else sets it
            w.setGeometry(screen.geometry())
        w.showFullScreen()
        w.viewer.widget.setFocus()
        self.update_formula()
        self._relayout.start()     # again once the full-screen size has arrived

    def leave(self) -> None:
        """Back to the layout as it was before :meth:`enter`."""
        w = self.window
        if not self.presenting:
            return
        self.presenting = False
        QApplication.instance().removeEventFilter(self._keys)
        for a in (self.formula_action, self.axes_action, self.next_action, self.previous_action):
            a.setShortcuts([])
        self.present_action.setChecked(False)
        self._remove_actor(FORMULA_ACTOR)
        self._formula = None
        self._set_caption("")
        self._restore_fonts()
        saved, self._saved = self._saved, None
        if saved is None:
            return
        for a in saved["added"]:
            w.removeAction(a)
        w.setWindowState(saved["state"])
        if not saved["state"] & (Qt.WindowFullScreen | Qt.WindowMaximized):
            w.restoreGeometry(saved["geometry"])
        for sib in saved["hidden"]:
            sib.show()
        for splitter, state in saved["splitters"]:
            splitter.restoreState(state)
        w.viewer.render()

    def _menu_shortcut_actions(self) -> list[QAction]:
        found, todo = [], [self.window.menuBar()]
        while todo:
            for a in todo.pop().actions():
                if a.menu() is not None:
                    todo.append(a.menu())
                elif not a.shortcut().isEmpty() and a not in self.actions():
                    found.append(a)
        return found

    # ------------------------------------------------------------------ the formula
    def formula_key(self) -> tuple | None:
        """What the card shows: (formulas, variables, params, complex equations, complex variables)."""
        w = self.window
        job = w.model.job
        if w.result is None or job is None:
            return None
        ex = example_for(w.model.title, w.result_names)
        cplx: tuple = (None, None)
        if ex is not None and ex.complex and ex.complex_variables:
            cplx = (tuple(ex.complex), tuple(ex.complex_variables))
        elif ex is None and w.formula_panel.is_complex():   # typed in complex mode (the card checks the split)
            cplx = (tuple(w.formula_panel.complex_equations()), tuple(w.formula_panel.complex_variables()))
        params = tuple(sorted((job.params or {}).items()))
        return (tuple(job.formulas), tuple(job.variables), params) + cplx

    def set_formula_shown(self, on: bool) -> None:
        """The typeset card on or off (it is shown only while presenting)."""
        if self.formula_action.isChecked() != bool(on):
            self.formula_action.setChecked(bool(on))
        if not on:
            self._remove_actor(FORMULA_ACTOR)
            self._formula = None
            self.window.viewer.render()
        else:
            self.update_formula()

    def update_formula(self) -> None:
        """Typeset the system on screen into the corner of the view (while presenting)."""
        if not self.presenting or not self.formula_action.isChecked():
            return
        key = self.formula_key()
        vw, vh = self._view_size()
        if key is None:
            self._remove_actor(FORMULA_ACTOR)
            self._formula = None
            return
        full = key + ((vw, vh),)
        if self._formula is not None and self._formula[1] == full:
            return
        self._remove_actor(FORMULA_ACTOR)
        self._formula = None
        actor = self.card_actor(key, (vw, vh), bool(getattr(self.window.plotter, "scalar_bars", None)))
        if actor is None:
            return
        self.window.plotter.add_actor(actor, name=FORMULA_ACTOR, reset_camera=False, pickable=False, render=False)
        self._formula = (actor, full)
        self.window.viewer.render()

    def card_actor(self, key: tuple, size: tuple[int, int], colour_bar: bool = True):
        """The card of ``key`` (:meth:`formula_key`) as a 2D actor placed for a picture of ``size`` (w, h):
        the typeset image, or plain text when the image cannot be made; None for an empty key."""
        formulas, variables, params, cplx, cvars = key
        vw, vh = size
        share = BELOW_BAR if colour_bar else FORMULA_MAX[1]
        try:
            image, _lines = typeset_system(list(formulas), list(variables), dict(params), cplx, cvars,
                                           font_px=max(14.0, vh / FORMULA_LINES_PER_HEIGHT),
                                           max_size=(int(FORMULA_MAX[0] * vw), int(share * vh) - MARGIN))
            actor = image_actor(image) if image is not None else None
        except Exception:  # noqa: BLE001 - no matplotlib, or no image: the formulas as text
            actor = _text_card([f"{f} = 0" for f in formulas] + [f"{p} = {v:g}" for p, v in params],
                               max(12, int(vh / (1.3 * FORMULA_LINES_PER_HEIGHT))))
        if actor is not None:
            self._place(actor, vw)
        return actor

    def decorate(self, plotter) -> None:
        """Draw on another plotter (an off-screen copy of the view, for a screenshot or an animation) what
        this mode adds to the view: the card while presenting, the axes when shown."""
        w, h = (int(s) for s in plotter.window_size)
        key = self.formula_key() if self.presenting and self.formula_action.isChecked() else None
        if key is not None:
            actor = self.card_actor(key, (w, h), bool(getattr(plotter, "scalar_bars", None)))
            if actor is not None:
                plotter.add_actor(actor, name=FORMULA_ACTOR, reset_camera=False, pickable=False, render=False)
        key = getattr(getattr(self.window.plotter.renderer, "cube_axes_actor", None), "_gcmh_key", None)
        if key is not None:
            add_axes(plotter, key)

    def formula_actor(self):
        """The VTK actor of the typeset card (None when none is shown)."""
        return None if self._formula is None else self._formula[0]

    def _view_size(self) -> tuple[int, int]:
        try:
            w, h = (int(s) for s in self.window.plotter.ren_win.GetSize())
        except Exception:  # noqa: BLE001
            w, h = self.window.viewer.size()
        return max(w, 1), max(h, 1)

    @staticmethod
    def _place(actor, view_width: int) -> None:
        size = getattr(actor, "image_size", None)
        if size is None:   # the plain-text card: right-justified at the corner
            actor.SetPosition(view_width - MARGIN, MARGIN)
        else:
            actor.SetPosition(max(MARGIN, view_width - size[0] - MARGIN), MARGIN)

    def _remove_actor(self, name: str) -> None:
        pl = self.window.plotter
        if name in pl.actors:
            pl.remove_actor(name, render=False)

    def _set_caption(self, text: str, error: bool = False) -> None:
        """A line of large type at the top right of the view (while presenting): what is happening."""
        from vtkmodules.vtkRenderingCore import vtkTextActor

        if not text:
            if self._caption is not None:   # (no caption: nothing to draw again, every run ends here)
                self._remove_actor(CAPTION_ACTOR)
                self._caption = None
                self.window.viewer.render()
            return
        if self._caption is None:
            a = vtkTextActor()
            prop = a.GetTextProperty()
            prop.SetJustificationToRight()
            prop.SetVerticalJustificationToTop()
            prop.SetFontFamilyToArial()
            prop.SetShadow(True)
            coord = a.GetPositionCoordinate()
            coord.SetCoordinateSystemToNormalizedViewport()
            coord.SetValue(0.98, 0.965)
            self.window.plotter.add_actor(a, name=CAPTION_ACTOR, reset_camera=False, pickable=False, render=False)
            self._caption = a
        a = self._caption
        a.SetInput(text)
        prop = a.GetTextProperty()
        prop.SetColor((1.0, 0.55, 0.5) if error else (0.93, 0.95, 1.0))
        prop.SetFontSize(int(max(14, self._view_size()[1] / 40)))
        self.window.viewer.render()

    def caption(self) -> str:
        return "" if self._caption is None else self._caption.GetInput()

    # ------------------------------------------------------------------ before every render
    def _before_render(self, *_args) -> None:
        """Keep the enlarged texts, the card's corner and the axes' bounds and titles in step with what
        the scene drew since (it rebuilds its texts on a new result or style)."""
        try:
            if self.presenting:
                self._scale_fonts()
                if self._formula is not None:
                    vw, vh = self._view_size()
                    self._place(self._formula[0], vw)
                    if self._formula[1][-1] != (vw, vh) and not self._relayout.isActive():
                        self._relayout.start()
            if self.axes_action.isChecked():
                self._update_axes()
                how, self._reframe = self._reframe, None
                if how:
                    self._frame_axes(how)
        except Exception:  # noqa: BLE001 - a render must never fail because of the presentation
            pass

    def _text_props(self) -> list:
        pl = self.window.plotter
        props = [pl.actors[n].GetTextProperty() for n in TEXT_ACTORS if n in pl.actors]
        for bar in getattr(pl, "scalar_bars", {}).values():
            props += [bar.GetTitleTextProperty(), bar.GetLabelTextProperty()]
        return props

    def _scale_fonts(self) -> None:
        for prop in self._text_props():
            entry = self._base_fonts.get(id(prop))
            if entry is None or entry[0] is not prop:
                entry = (prop, prop.GetFontSize())
                self._base_fonts[id(prop)] = entry
            size = int(round(entry[1] * FONT_SCALE))
            if prop.GetFontSize() != size:
                prop.SetFontSize(size)

    def _restore_fonts(self) -> None:
        for prop, base in self._base_fonts.values():
            prop.SetFontSize(base)
        self._base_fonts = {}

    # ------------------------------------------------------------------ axes with ticks
    def set_axes(self, on: bool) -> None:
        """Bounds axes (ticks and labels in the projected coordinates) on or off."""
        pl = self.window.plotter
        on = bool(on)
        if self.axes_action.isChecked() != on:
            self.axes_action.setChecked(on)
        if not on:
            if getattr(pl.renderer, "cube_axes_actor", None) is not None:
                pl.remove_bounds_axes()
            self.window.viewer.render()
            return
        self._reframe = "fit"
        self._update_axes()
        self.window.viewer.render()

    def axes_shown(self) -> bool:
        return getattr(self.window.plotter.renderer, "cube_axes_actor", None) is not None

    def _update_axes(self) -> None:
        scene, pl = self.window.scene, self.window.plotter
        mesh = scene.mesh
        if mesh is None:
            return
        bounds = tuple(float(b) for b in mesh.bounds)
        titles = tuple(axis_titles(scene))
        shown = np.reshape(bounds, (3, 2)) + axis_offsets(scene)[:, None]
        # the ends to a thousandth of the side: float32 noise makes no "-8.2e-06" tick where 0 is meant
        q = 10.0 ** (np.floor(np.log10(np.maximum(np.ptp(shown, axis=1, keepdims=True), 1e-300))) - 3)
        shown = np.round(shown / q) * q + 0.0
        ranges = tuple(float(r) for r in shown.ravel())
        font = int(round(AXES_FONT * (FONT_SCALE if self.presenting else 1.0)))
        # a short side gets three labels (five would overlap there)
        sides = np.diff(np.reshape(bounds, (3, 2)), axis=1).ravel()
        counts = tuple(5 if r >= 0.5 * sides.max() else 3 for r in sides)
        actor = getattr(pl.renderer, "cube_axes_actor", None)
        key = getattr(actor, "_gcmh_key", None)
        if actor is not None and key is not None and key[3:] == (font, counts):
            if key[:3] != (bounds, titles, ranges):
                actor.bounds = bounds
                actor.x_axis_range, actor.y_axis_range, actor.z_axis_range = ranges[0:2], ranges[2:4], ranges[4:6]
                actor.SetXTitle(titles[0])
                actor.SetYTitle(titles[1])
                actor.SetZTitle(titles[2])
                actor._gcmh_key = (bounds, titles, ranges, font, counts)
            return
        add_axes(pl, (bounds, titles, ranges, font, counts))

    def _frame_axes(self, how: str) -> None:
        """Frame the axes' box, not only the object (the camera frames the object's points; the box's
        corners reach further): ``"fit"`` centres the box and zooms it to the picture's free part (a new
        result, base, size, or the axes just turned on); ``"out"`` only zooms out when the box has left
        it (a turn of the projection), so the camera does not breathe while a projection turns. Nothing
        with the View tab's "keep camera", and never on the user's own zoom or turn of the camera."""
        from .camera import screen_coordinates

        pl = self.window.plotter
        actor = getattr(pl.renderer, "cube_axes_actor", None)
        if actor is None or self.window.viewer.keep_camera():
            return
        b = actor.GetBounds()
        corners = np.array([[x, y, z] for x in b[0:2] for y in b[2:4] for z in b[4:6]], dtype=float)
        if how == "fit":
            pl.renderer.ResetCamera(b)          # centred on the box, the direction kept
        for _ in range(3 if how == "fit" else 1):   # pan and zoom (under perspective, again to settle)
            S = screen_coordinates(pl, corners)
            if not np.all(np.isfinite(S)):
                break
            lo, hi = S.min(axis=0), S.max(axis=0)
            if how == "fit":
                f = max((hi[0] - lo[0]) / (2 * AXES_X), (hi[1] - lo[1]) / (AXES_TOP + AXES_BOTTOM))
                self._pan(0.5 * (lo + hi) - np.array([0.0, 0.5 * (AXES_TOP - AXES_BOTTOM)]))
            else:
                f = max(np.abs(S[:, 0]).max() / AXES_X, hi[1] / AXES_TOP, -lo[1] / AXES_BOTTOM)
                if f <= 1.001:
                    break
            if f > 1e-9:
                pl.camera.zoom(1.0 / f)
        pl.renderer.ResetCameraClippingRange()

    def _pan(self, d) -> None:
        """Move the camera across the picture by ``d`` (x, y) in -1..1 picture units (the view shifts by -d)."""
        pl = self.window.plotter
        cam = pl.camera
        fp, pos = np.array(cam.focal_point, float), np.array(cam.position, float)
        ahead = fp - pos
        dist = float(np.linalg.norm(ahead))
        if dist <= 0:
            return
        ahead /= dist
        up = np.array(cam.up, float)
        up -= np.dot(up, ahead) * ahead
        up /= max(float(np.linalg.norm(up)), 1e-12)
        right = np.cross(ahead, up)
        half = cam.parallel_scale if cam.parallel_projection else dist * np.tan(np.radians(cam.view_angle) / 2)
        w, h = self._view_size()
        shift = right * d[0] * half * (w / h) + up * d[1] * half
        cam.focal_point = tuple(fp + shift)
        cam.position = tuple(pos + shift)

    # ------------------------------------------------------------------ walking the gallery
    def next_example(self) -> str | None:
        """Open and run the gallery's next example (after the last: the first); returns its name."""
        return self.step_example(1)

    def previous_example(self) -> str | None:
        """Open and run the gallery's previous example (before the first: the last); returns its name."""
        return self.step_example(-1)

    def current_index(self) -> int | None:
        """The position in the gallery of the example on screen (or being opened), else None."""
        names = example_names()
        for name in (self._pending, self.current):
            if name in names:
                return names.index(name)
        ex = example_for(self.window.model.title, self.window.result_names)
        return names.index(ex.name) if ex is not None and ex.name in names else None

    def step_example(self, step: int) -> str | None:
        names = example_names()
        if not names:
            return None
        i = self.current_index()
        i = (0 if step > 0 else len(names) - 1) if i is None else (i + step) % len(names)
        name = names[i]
        self._pending = name
        title = next((ex.title for ex in _examples() if ex.name == name), name)
        self._set_caption(f"{i + 1}/{len(names)} \u00b7 {title}: computing\u2026" if self.presenting else "")
        if self.window.is_running():
            self.window.cancel()              # its runFinished opens the pending example
            if self.window.is_running():
                return name
        self._open_pending()
        return name

    def _open_pending(self) -> None:
        name, self._pending = self._pending, None
        if name is None:
            return
        self.current = name
        if not self.window.load_example(name):
            self._set_caption(self.window.last_status or f"cannot open {name}", error=True)

    def _on_run_finished(self, how: str) -> None:
        if self._pending is not None:
            QTimer.singleShot(0, self._open_pending)
            return
        if how == "done" or not self.presenting:
            self._set_caption("")
        else:
            self._set_caption(self.window.last_status or f"run {how}", error=True)

    def _on_result(self, _cx) -> None:
        self._reframe = "fit"
        if self.presenting:
            self.update_formula()

    def _on_turned(self) -> None:
        self._reframe = self._reframe or "out"

    def _on_new_base(self) -> None:
        self._reframe = "fit"

    def _on_resized(self) -> None:
        """The view has its new size (after the viewer's own refit): the card and the axes follow."""
        if not (self.presenting or self.axes_shown()):
            return
        self._reframe = "fit"
        self.update_formula()
        self.window.viewer.render()
