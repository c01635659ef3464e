"""What the picture says in words: the title and subtitle of a view, the colour bar's title, the names of
the screen axes, and what an example's variables mean (``{"y": "Im z"}``, read from the example files by
their titles).  :class:`SceneTexts` draws them on a plotter for a :class:`gcmh_studio.scene.Scene`.  No Qt here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .projection import axis_label

if TYPE_CHECKING:
    from gcmh_core.examples import Example

TITLE_Y = 0.925          # the texts' baselines, up the picture (0..1)
SUBTITLE_Y = 0.885
LEGEND_Y = 0.80

def with_meaning(name: str, labels: dict) -> str:
    """``name``, with its meaning when ``labels`` gives one: "y = Im z"."""
    meaning = labels.get(name)
    return f"{name} = {meaning}" if meaning else name


def describe(cx, names, color_by=None, labels: dict | None = None) -> str:
    """A one-line subtitle: what the picture shows."""
    dim, n, k = cx.dim, cx.n, cx.k
    what = {1: "curve", 2: "surface"}.get(dim, f"{dim}-manifold, 2-skeleton")
    text = f"{what} in R^{n} (n = {n}, k = {k}) · {cx.count(0):,} vertices"
    if color_by:
        text += f" · colour: {with_meaning(color_by, labels or {})}"
    return text


def example_labels(ex) -> dict:
    """What an example's variables mean ({"y": "Im z"}): its file's ``[view] labels``, or those of its
    complex equations (the loader's ``Example.labels``); {} when it says nothing."""
    raw = getattr(ex, "labels", None) or {}
    return {k: " ".join(str(v).split())[:24] for k, v in raw.items() if k in ex.variables and str(v).strip()}


_EXAMPLES: dict = {}            # (title, variables) -> the example they are (or None)
_TITLES: dict | None = None      # example title -> names of the example files with it


def _example_titles() -> dict:
    """{title: [example names]} from the files' ``title`` keys only (loading every example, as before,
    parsed all their formulas: 0.27 s on the GUI thread when the three-torus arrived)."""
    global _TITLES
    if _TITLES is None:
        import tomllib

        from gcmh_core.examples import example_names, examples_dir

        found: dict = {}
        folder = examples_dir()
        for name in example_names():
            try:
                title = tomllib.loads((folder / f"{name}.toml").read_text(encoding="utf-8")).get("title")
            except (OSError, ValueError):
                continue
            if isinstance(title, str):
                found.setdefault(title.strip(), []).append(name)
        _TITLES = found
    return _TITLES


def warm_labels() -> None:
    """Read the examples' titles in a daemon thread now (the window calls this when it opens), so the first
    result does not wait for them on the GUI thread."""
    import threading

    if _TITLES is None:
        threading.Thread(target=_example_titles, name="gcmh-example-titles", daemon=True).start()


def example_for(title: str, names) -> Example | None:
    """The example a result with this title and these variables came from (a run of an example in the
    window), else None (a system the user typed)."""
    if not title:
        return None
    key = (title, tuple(names))
    if key not in _EXAMPLES:
        found = None
        try:
            from gcmh_core.examples import load_example

            for name in _example_titles().get(title.strip(), []):
                ex = load_example(name)
                if ex.title == title and list(ex.variables) == list(names):
                    found = ex
                    break
        except Exception:  # noqa: BLE001
            found = None
        _EXAMPLES[key] = found
    return _EXAMPLES[key]


def _gluing(periodic, variables) -> tuple:
    """Glued axes in one spelling (the engine's own reading; a grid of 8 cubes an axis passes its checks)."""
    from gcmh_core._validate import as_periodic
    from gcmh_core.errors import InputError

    if isinstance(periodic, str):   # (the field's text, "t  s:flip=t")
        from .inputs import check_periodic

        periodic = check_periodic(periodic, variables, None)[1]
    try:
        return as_periodic(periodic or None, list(variables), [8] * len(variables))
    except InputError:
        return ("?",)


def gluing_title(title: str, formulas, variables, periodic) -> tuple[str, str | None]:
    """(title, story) of a run of the example called ``title`` with the glued axes ``periodic``: the example
    itself when they are its own ((title, None): its story stays); else the example with these equations
    glued so (the cut-open Klein bottle glued by hand is the closed one: its title and story); else the
    title saying how it is glued, and no story ("": the example's no longer applies)."""
    ex = example_for(title, variables)
    if ex is None:
        return title, None
    glued = _gluing(periodic, variables)
    if glued == _gluing(ex.periodic, variables):
        return title, None
    from gcmh_core.examples import list_examples

    same = [str(f).strip() for f in formulas]
    for other in list_examples(on_error=lambda *a: None):
        if (list(other.variables) == list(variables) and [str(f).strip() for f in other.formulas] == same
                and _gluing(other.periodic, variables) == glued):
            return other.title, " ".join(str(other.description).split())
    base = title.split(",")[0].strip()
    if not glued:
        return f"{base}, cut open", ""
    text = "  ".join(periodic) if isinstance(periodic, (list, tuple)) else str(periodic)
    return f"{base}, glued ({text})", ""


def labels_for(title: str, names) -> dict:
    """The labels of the example with this title and these variables, else {} (a system the user typed)."""
    ex = example_for(title, names)
    return {} if ex is None else example_labels(ex)


def view_subtitle(cx, names, color_by=None, two_sided: bool = False, mapping: str = "orthographic",
                  labels: dict | None = None) -> str:
    """The subtitle of a view (window and headless alike): :func:`describe`, then the two sides and the mapping."""
    sub = describe(cx, names, None if two_sided else color_by, labels) if cx is not None else ""
    if two_sided and cx is not None:
        sub += " \u00b7 two sides: gold front, blue back"
    if mapping != "orthographic":
        sub += f" \u00b7 {mapping}"
    return sub



def font_size(plotter, size: float) -> int:
    """A font size scaled to the picture (sizes are tuned for 1600x1200; a narrow picture counts by its
    width, so a title fits across a portrait screenshot)."""
    try:
        w, h = (int(x) for x in plotter.window_size)
    except Exception:  # noqa: BLE001
        w, h = 1600, 1200
    ref = min(h, 0.75 * w)
    return max(6, int(round(size * min(1.5, max(0.55, ref / 1200)))))


MIN_TEXT_PX = 14       # no word over the picture smaller (a projector at 1280x720 shows 7 px as a smudge)
MIN_TITLE_PX = 20
AXES_LABEL_PX = 24     # the orientation widget's axis names, at 1600x1200
CHAR_EM = 0.6          # a character's width in VTK's sans font, in font sizes (a generous average)
# pyvista's add_text draws a text actor at twice the font size it is given: these sizes are pixels, and
# :func:`text_size` halves them for it


def readable(plotter, size: float, least: int = MIN_TEXT_PX, text: str | None = None, left: float = 0.02) -> int:
    """A text's size in pixels: :func:`font_size`, but never under ``least``; with ``text``, no larger than lets
    its longest line fit from ``left`` (a fraction of the width) to the picture's right edge (a narrow
    picture: smaller, never under 6)."""
    px = max(int(least), font_size(plotter, size))
    if text:
        try:
            width = int(plotter.window_size[0])
        except Exception:  # noqa: BLE001
            return px
        longest = max(len(line) for line in str(text).splitlines()) if str(text).strip() else 0
        if longest:
            px = min(px, int((1.0 - left - 0.02) * width / (CHAR_EM * longest)))
    return max(6, px)


def text_size(plotter, size: float, least: int = MIN_TEXT_PX, text: str | None = None) -> int:
    """pyvista's ``add_text`` font size for a text of :func:`readable` pixels (it draws twice its size)."""
    return max(3, readable(plotter, 2 * size, least, text) // 2)


def axes_labels(P, names) -> list[str]:
    """The screen axes' names for the view matrix ``P`` (3, n): "x", or a mixture "0.71 x + 0.71 w"."""
    if P is None:
        return ["", "", ""]
    return [axis_label(P[r], names) for r in range(3)]


class SceneTexts:
    """The words drawn over a scene: title, subtitle, the colour bar's title, the axis names on the
    orientation widget and, when the screen axes mix variables, their legend. Each actor is made once and
    its text changed in place."""

    def __init__(self, plotter):
        self.plotter = plotter
        self.title_actor = None
        self.subtitle_actor = None
        self.legend_actor = None
        self.axes_actor = None
        self.bar_title: str | None = None       # the colour bar shown (pyvista keys its bars by title)

    def set_title(self, title: str, subtitle: str) -> None:
        pl = self.plotter
        for a in (self.title_actor, self.subtitle_actor):
            if a is not None:
                pl.remove_actor(a, render=False)
        self.title_actor = self.subtitle_actor = None
        if title:
            self.title_actor = pl.add_text(title, position=(0.02, TITLE_Y), viewport=True,
                                           font_size=text_size(pl, 18, MIN_TITLE_PX, title), color="white",
                                           name="gcmh-title")
        if subtitle:
            self.subtitle_actor = pl.add_text(subtitle, position=(0.02, SUBTITLE_Y), viewport=True,
                                              font_size=text_size(pl, 11, text=subtitle), color="#c8cfdc",
                                              name="gcmh-subtitle")

    def bar_args(self, title: str) -> dict:
        """pyvista's ``scalar_bar_args`` for the colour bar titled ``title``."""
        return dict(title=title, vertical=True, title_font_size=readable(self.plotter, 36, MIN_TITLE_PX),
                    label_font_size=readable(self.plotter, 26), n_labels=5, fmt="%.2f",
                    position_x=0.9, position_y=0.2, width=0.045, height=0.6, color="white", bold=False,
                    unconstrained_font_size=True)

    def bar_added(self, title: str | None) -> None:
        """The mesh was added with the colour bar ``title`` (None: no bar): lay out its texts."""
        self.bar_title = title
        if title is None:
            return
        try:
            bar = self.plotter.scalar_bars[title]
        except (KeyError, AttributeError):
            return
        bar.SetTextPosition(0)          # labels and title below the bar, never over it
        bar.SetTitleRatio(1.0)

    def remove_bar(self) -> None:
        if self.bar_title is not None:
            try:
                self.plotter.remove_scalar_bar(self.bar_title, render=False)
            except Exception:  # noqa: BLE001 - already gone
                pass
            self.bar_title = None

    def set_axes(self, P, names, style) -> None:
        """Axis names on the orientation widget for the view matrix ``P`` (3, n); a legend of the screen
        axes when they mix variables. ``style``: the scene's Style (its ``axes`` switch and labels)."""
        if not style.axes or P is None or not names:
            return
        full = [axis_label(P[r], names, terms=3) for r in range(3)]
        short = []
        for r in range(3):
            row = P[r]
            if not np.any(np.abs(row) > 1e-6):
                short.append("-")
                continue
            i = int(np.argmax(np.abs(row)))
            pure = abs(abs(row[i]) - 1.0) < 1e-6
            # a mixture is named by its screen axis, X, Y or Z, as the View tab names them; the legend
            # says what it mixes
            short.append(style.label(full[r]) if pure else "XYZ"[r])
        mixed = any(lab in "XYZ" for lab in short)
        legend = "\n".join(f"{'XYZ'[r]} = {full[r]}" for r in range(3) if full[r]) if mixed else ""
        if self.axes_actor is None:
            try:
                self.axes_actor = self.plotter.add_axes(
                    xlabel=short[0], ylabel=short[1], zlabel=short[2],
                    line_width=3, color="white", labels_off=False,
                    viewport=(0.0, 0.0, 0.2, 0.28))
            except Exception:  # noqa: BLE001 - a plotter without an orientation widget
                self.axes_actor = None
        a = self.axes_actor
        if a is not None:
            a.SetXAxisLabelText(short[0])
            a.SetYAxisLabelText(short[1])
            a.SetZAxisLabelText(short[2])
            set_caption_size(a, readable(self.plotter, AXES_LABEL_PX))
        if self.legend_actor is None:
            self.legend_actor = self.plotter.add_text(legend, position=(0.02, LEGEND_Y), viewport=True,
                                                      font_size=text_size(self.plotter, 11, text=legend),
                                                      color="#dfe4ee",
                                                      name="gcmh-legend")
        else:
            self.legend_actor.SetInput(legend)
            self.legend_actor.GetTextProperty().SetFontSize(2 * text_size(self.plotter, 11, text=legend))


def set_caption_size(axes_actor, px: int) -> None:
    """The orientation widget's axis names at ``px`` pixels, whatever the size of its corner (VTK scales
    a caption to its actor's box: about 7 px at 1280x720)."""
    for cap in (axes_actor.GetXAxisCaptionActor2D(), axes_actor.GetYAxisCaptionActor2D(),
                axes_actor.GetZAxisCaptionActor2D()):
        cap.GetTextActor().SetTextScaleModeToNone()
        prop = cap.GetCaptionTextProperty()
        prop.SetFontSize(int(px))
        prop.SetBold(True)
        prop.SetShadow(True)


def caption_sizes(axes_actor) -> list[int]:
    """The orientation widget's axis names' font sizes (pixels), as drawn."""
    return [int(c.GetCaptionTextProperty().GetFontSize()) for c in (
        axes_actor.GetXAxisCaptionActor2D(), axes_actor.GetYAxisCaptionActor2D(),
        axes_actor.GetZAxisCaptionActor2D())]
