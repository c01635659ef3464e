"""What presentation mode draws in the 3D view: the typeset card in the bottom right corner
(:mod:`gcmh_studio.formula_card`), a caption at the top right, the scene's texts in larger type
(as large as fits), and the bounds axes (:mod:`gcmh_studio.bounds_axes`) framed as the object
changes.  VTK actors on the viewer's plotter, kept in step before every render; no Qt here (the
actions, keys and full screen are :mod:`gcmh_studio.qt_presentation`'s)."""

from __future__ import annotations

from collections.abc import Callable

from .bounds_axes import add_axes, frame_axes, update_axes
from .formula_card import card_actor, place_card
from .presentation import Reframing

FORMULA_ACTOR = "gcmh-formula"       # the typeset system, bottom right
CAPTION_ACTOR = "gcmh-caption"       # what is happening (loading the next example), top right
TEXT_ACTORS = ("gcmh-title", "gcmh-subtitle", "gcmh-legend")   # the scene's texts, enlarged while presenting
FONT_SCALE = 1.5                     # larger type for a room


class ViewDecorations:
    """The card, caption, larger type and axes in the view of ``viewer`` (its ``plotter``, ``scene``,
    ``render()``, ``keep_camera()`` and ``size()``).  ``card_resized()`` is called (from a render) when
    the card on screen was typeset for another view size: the caller typesets it again, later."""

    def __init__(self, viewer, card_resized: Callable[[], None]):
        self.viewer = viewer
        self.card_resized = card_resized
        self.large_type = False              # the scene's texts enlarged (while presenting)
        self.axes_on = False
        self.reframing = Reframing()
        self._card = None                    # (actor, (key, view size) it was typeset for)
        self._caption = None
        self._base_fonts: dict[int, tuple] = {}
        self._observer = viewer.plotter.ren_win.AddObserver("StartEvent", self._before_render)

    def detach(self) -> None:
        """No more work before the view's renders (the window closes, or the presentation is uninstalled)."""
        try:
            self.viewer.plotter.ren_win.RemoveObserver(self._observer)
        except Exception:  # noqa: BLE001 - the render window is gone already
            pass

    def view_size(self) -> tuple[int, int]:
        try:
            w, h = (int(s) for s in self.viewer.plotter.ren_win.GetSize())
        except Exception:  # noqa: BLE001
            w, h = self.viewer.size()
        return max(w, 1), max(h, 1)

    def _remove_actor(self, name: str) -> None:
        pl = self.viewer.plotter
        if name in pl.actors:
            pl.remove_actor(name, render=False)

    # ------------------------------------------------------------------ the card
    def show_card(self, key: tuple | None) -> None:
        """The card of ``key`` (:func:`gcmh_studio.presentation.card_key`) typeset for the view's size, or
        none for None; typeset again only when the key or the size has changed."""
        if key is None:
            self.hide_card(render=False)
            return
        size = self.view_size()
        if self._card is not None and self._card[1] == (key, size):
            return
        self.hide_card(render=False)
        pl = self.viewer.plotter
        actor = card_actor(key, size, bool(getattr(pl, "scalar_bars", None)))
        if actor is None:
            return
        pl.add_actor(actor, name=FORMULA_ACTOR, reset_camera=False, pickable=False, render=False)
        self._card = (actor, (key, size))
        self.viewer.render()

    def hide_card(self, render: bool = True) -> None:
        self._remove_actor(FORMULA_ACTOR)
        self._card = None
        if render:
            self.viewer.render()

    def card(self):
        """The VTK actor of the card (None when none is shown)."""
        return None if self._card is None else self._card[0]

    def decorate(self, plotter, key: tuple | None) -> None:
        """Draw on another plotter (an off-screen copy of the view) the card of ``key`` (None: no card) and
        the axes when they are shown."""
        w, h = (int(s) for s in plotter.window_size)
        if key is not None:
            actor = card_actor(key, (w, h), bool(getattr(plotter, "scalar_bars", None)))
            if actor is not None:
                plotter.add_actor(actor, name=FORMULA_ACTOR, reset_camera=False, pickable=False, render=False)
        axes = getattr(getattr(self.viewer.plotter.renderer, "cube_axes_actor", None), "_gcmh_key", None)
        if axes is not None:
            add_axes(plotter, axes)

    # ------------------------------------------------------------------ the caption
    def set_caption(self, text: str, error: bool = False) -> None:
        """A line of large type at the top right of the view: what is happening ("" takes it away)."""
        from vtkmodules.vtkRenderingCore import vtkTextActor

        if not text:
            if self._caption is not None:   # (no caption: nothing to draw again, every run ends here)
                self._remove_actor(CAPTION_ACTOR)
                self._caption = None
                self.viewer.render()
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
            self.viewer.plotter.add_actor(a, name=CAPTION_ACTOR, reset_camera=False, pickable=False, render=False)
            self._caption = a
        a = self._caption
        a.SetInput(text)
        prop = a.GetTextProperty()
        prop.SetColor((1.0, 0.55, 0.5) if error else (0.93, 0.95, 1.0))
        prop.SetFontSize(int(max(14, self.view_size()[1] / 40)))
        self.viewer.render()

    def caption(self) -> str:
        return "" if self._caption is None else self._caption.GetInput()

    # ------------------------------------------------------------------ before every render
    def _before_render(self, *_args) -> None:
        """Keep the enlarged texts, the card's corner and the axes' bounds and titles in step with what
        the scene drew since (it rebuilds its texts on a new result or style)."""
        try:
            if self.large_type:
                self._scale_fonts()
            if self._card is not None:
                size = self.view_size()
                place_card(self._card[0], size[0])
                if self._card[1][1] != size:
                    self.card_resized()
            if self.axes_on:
                self._update_axes()
                how = self.reframing.take()
                if how and not self.viewer.keep_camera():   # never against the View tab's "keep camera"
                    frame_axes(self.viewer.plotter, how, self.view_size())
        except Exception:  # noqa: BLE001 - a render must never fail because of the presentation
            pass

    # ------------------------------------------------------------------ larger type
    def _text_props(self) -> list:
        pl = self.viewer.plotter
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
        self._fit_texts()

    def _fit_texts(self) -> None:
        """The enlarged title and subtitle smaller again where they would leave the view (a long title ran
        off its right edge and its top was cut)."""
        pl = self.viewer.plotter
        W, H = self.view_size()
        boxes = {}
        for name in TEXT_ACTORS:
            actor = pl.actors.get(name)
            if actor is None or not actor.GetInput():
                continue
            bb = [0.0] * 4
            actor.GetBoundingBox(pl.renderer, bb)   # (x0, x1, y0, y1) in pixels
            over = max(bb[1] / (0.98 * W), bb[3] / (0.97 * H))   # (the box is a few pixels short of the glyphs)
            if over > 1.0:
                prop = actor.GetTextProperty()
                prop.SetFontSize(max(6, int(prop.GetFontSize() / over)))
                actor.GetBoundingBox(pl.renderer, bb)
            boxes[name] = (actor, bb)
        if "gcmh-title" in boxes and "gcmh-subtitle" in boxes:   # the subtitle's top below the title
            (_, t), (sub, b) = boxes["gcmh-title"], boxes["gcmh-subtitle"]
            room = t[2] - b[2] - 2.0
            if b[3] - b[2] > room > 0:
                prop = sub.GetTextProperty()
                prop.SetFontSize(max(6, int(prop.GetFontSize() * room / (b[3] - b[2]))))

    def restore_fonts(self) -> None:
        """The scene's texts at their own sizes again."""
        self.large_type = False
        for prop, base in self._base_fonts.values():
            prop.SetFontSize(base)
        self._base_fonts = {}

    # ------------------------------------------------------------------ axes with ticks
    def set_axes(self, on: bool) -> None:
        """Bounds axes (ticks and labels in the projected coordinates) on, framed at the next render, or off."""
        pl = self.viewer.plotter
        self.axes_on = bool(on)
        if not on:
            if getattr(pl.renderer, "cube_axes_actor", None) is not None:
                pl.remove_bounds_axes()
        else:
            self.reframing.fit()
            self._update_axes()
        self.viewer.render()

    def axes_shown(self) -> bool:
        return getattr(self.viewer.plotter.renderer, "cube_axes_actor", None) is not None

    def _update_axes(self) -> None:
        update_axes(self.viewer.plotter, self.viewer.scene, FONT_SCALE if self.large_type else 1.0)
