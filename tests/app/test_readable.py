"""What a projector shows (issue 27, item 6): words over the picture of at least 14 px at 1280x720, axis names
as the View tab gives them, ticks at round values without "-0", a colour variable that varies on M."""

import numpy as np
import pytest
import pyvista as pv

from gcmh_core import extract
from gcmh_studio.bounds_axes import TickFormat, nice_range, update_axes
from gcmh_studio.labels import MIN_TEXT_PX, caption_sizes
from gcmh_studio.projection import ProjectionModel, varying_colour
from gcmh_studio.scene import Scene, Style, bar_format


@pytest.fixture
def plotter():
    pl = pv.Plotter(off_screen=True, window_size=(1280, 720))
    yield pl
    pl.close()


def _torus4():
    return extract(["x^2 + y^2 - 1", "z^2 + w^2 - 1"], [(-1.5, 1.5)] * 4, 8, variables="x,y,z,w")


def test_words_over_the_picture_are_readable_at_1280_by_720(plotter):
    cx = _torus4()
    sc = Scene(plotter, anti_aliasing=None)
    p = ProjectionModel(n=4, angles=[0, 0, 0, 0, 30.0, 0])      # screen Y mixes y and w
    sc.set_complex(cx, ["x", "y", "z", "w"], p.view(), Style(color_by="w", title="Clifford torus",
                                                             subtitle="coloured by w"))
    t = sc.texts
    assert min(caption_sizes(t.axes_actor)) >= MIN_TEXT_PX
    assert t.subtitle_actor.GetTextProperty().GetFontSize() >= MIN_TEXT_PX
    assert t.legend_actor.GetTextProperty().GetFontSize() >= MIN_TEXT_PX
    assert t.title_actor.GetTextProperty().GetFontSize() >= 20
    labels = [t.axes_actor.GetXAxisLabelText(), t.axes_actor.GetYAxisLabelText(), t.axes_actor.GetZAxisLabelText()]
    assert labels[0] == "x" and labels[1] == "Y" and not any("~" in s for s in labels)
    assert "Y = " in t.legend_actor.GetInput() and "w" in t.legend_actor.GetInput()
    bar = plotter.scalar_bars["w"]
    assert bar.GetLabelTextProperty().GetFontSize() >= MIN_TEXT_PX


def test_bounds_axes_tick_at_round_values(plotter):
    cx = extract(["x^2 + y^2 + (z/0.004)^2 - 1"], [(-1.2, 1.2), (-1.2, 1.2), (-0.005, 0.005)], 10,
                 variables="x,y,z")
    sc = Scene(plotter, anti_aliasing=None)
    sc.set_complex(cx, ["x", "y", "z"], ProjectionModel(n=3).view(), Style())
    update_axes(plotter, sc)
    actor = plotter.renderer.cube_axes_actor
    for a in range(3):
        arr = actor.GetAxisLabels(a)
        texts = [arr.GetValue(i) for i in range(arr.GetNumberOfValues())]
        assert len(texts) >= 3, texts
        assert not any(t.startswith("-0") and float(t) == 0 for t in texts), texts
        vals = np.array([float(t) for t in texts])
        step = np.diff(vals)
        assert np.allclose(step, step[0])
        mant = step[0] / 10.0 ** np.floor(np.log10(step[0]))
        assert np.isclose(mant, [1, 2, 2.5, 5]).any(), texts
        assert np.allclose(vals / step[0], np.round(vals / step[0]), atol=1e-6), texts
    # the box reaches round values around the object
    lo, hi, c = nice_range(-1.0015, 0.998)
    assert (lo, hi, c) == (-1.0, 1.0, 5)
    assert TickFormat(0.5).format(-5.551115123125783e-17) == "0"
    assert TickFormat(0.0025).format(-0.0025) == "-0.0025"
    assert bar_format([-0.002, 0.002]) == "%.4f" and bar_format([0, 10]) == "%.2f"


def test_the_default_colour_varies_on_m():
    X = np.zeros((50, 10))
    X[:, 0], X[:, 1] = np.cos(np.arange(50)), np.sin(np.arange(50))
    X[:, 4] = np.linspace(0, 1, 50)
    names = [f"x{i + 1}" for i in range(10)]
    assert varying_colour(names, X) == "x5"          # x6 .. x10 are 0 on all of it
    X[:, 9] = 1e-3 * np.arange(50)
    assert varying_colour(names, X) == "x10"


def test_coincident_sheets_are_held_apart_in_a_linear_view(plotter):
    """The Clifford torus in Orthographic is a cylinder covered twice: the sheet with x4 > 0 is drawn just
    outside the one with x4 < 0 (no z-fighting speckle), far below a pixel."""
    from gcmh_core.examples import load_example
    from gcmh_studio.scene import SHEET_GAP

    ex = load_example("clifford-torus")
    cx = extract(ex.formulas, ex.bounds, 10, variables=ex.variables)
    sc = Scene(plotter, anti_aliasing=None)
    view = ProjectionModel(n=4).view()                        # (x1, x2, x3), orthographic
    sc.set_complex(cx, list(ex.variables), view, Style(color_by="x4"))
    drawn = np.array(sc.mesh.points, dtype=float)
    plain = sc.projector.project(view.P).astype(float)
    moved = drawn - plain
    r = sc.projector.radii()[0]
    assert np.allclose(np.linalg.norm(moved, axis=1), SHEET_GAP * r, rtol=1e-3)
    radial = plain[:, :2] / np.linalg.norm(plain[:, :2], axis=1, keepdims=True)
    outward = np.einsum("ij,ij->i", moved[:, :2], radial)
    x4 = np.asarray(sc.complex.vertices)[:, 3] - sc.projector.center[3]
    far = np.abs(x4) > 1e-3
    assert (np.sign(outward[far]) == np.sign(x4[far])).all()
    # a view that shows every coordinate moves nothing
    sc3 = extract(["x^2 + y^2 + z^2 - 1"], [(-1.5, 1.5)] * 3, 6, variables="x,y,z")
    sc.set_complex(sc3, ["x", "y", "z"], ProjectionModel(n=3).view(), Style())
    assert np.allclose(np.array(sc.mesh.points), sc.projector.project(np.eye(3)), atol=1e-6)
