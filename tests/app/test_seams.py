"""Seams of identified axes drawn whole (gcmh_studio.geometry.display_complex): a 2-cell that crosses a seam is
drawn on both sides of it, next to its neighbours, not stretched across the box or painted through the
whole colour range; the topology stays the complex's own."""

import numpy as np
import pytest

from gcmh_core import extract
from gcmh_core.examples import load_example
from gcmh_studio.geometry import Geometry, display_complex


def _run(name, div):
    ex = load_example(name)
    return extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic)


def _spans(cx, axis):
    off, vids = cx.polygons()
    x = np.asarray(cx.vertices)[vids, axis]
    return np.maximum.reduceat(x, off[:-1]) - np.minimum.reduceat(x, off[:-1])


@pytest.mark.parametrize("name, div, axes", [("torus-angles", 12, ("s", "t")), ("moebius-band", 12, ("s",)),
                                             ("klein-bottle-closed", 8, ("s", "t"))])
def test_no_drawn_cell_spans_half_a_period(name, div, axes):
    cx = _run(name, div)
    shown = display_complex(cx)
    names = cx.meta["variables"]
    for a in axes:
        p = names.index(a)
        period = np.diff(np.asarray(cx.meta["bounds"])[p])[0]
        assert _spans(cx, p).max() > period / 2          # the complex itself has cells across the seam ...
        assert _spans(shown, p).max() < period / 2       # ... drawn whole, next to their neighbours
    source = shown.meta["display_source"]
    n_cells = cx.count(2)
    counts = np.bincount(source, minlength=n_cells)
    assert (counts == 1).all()                           # each cell drawn once
    # a copy's vertices are its cell's vertices moved by periods (and reflected across a flipped seam)
    off, vids = cx.polygons()
    soff, svids = shown.polygons()
    moved = np.flatnonzero([(svids[soff[i]:soff[i + 1]] >= cx.count(0)).any() for i in range(len(source))])
    assert len(moved) > 0
    for i in moved[:20]:
        c = source[i]
        assert soff[i + 1] - soff[i] == off[c + 1] - off[c]
    assert display_complex(cx) is shown                  # (made once per result)


def test_a_flipped_seam_reflects_the_copies():
    cx = _run("moebius-band", 12)
    shown = display_complex(cx)
    names = cx.meta["variables"]
    s, t = names.index("s"), names.index("t")
    lo_t, hi_t = np.asarray(cx.meta["bounds"])[t]
    V, W = np.asarray(cx.vertices), np.asarray(shown.vertices)
    extra = W[len(V):]
    assert len(extra) > 0
    # every moved vertex is an original one moved by the period along s with t reflected
    period = np.diff(np.asarray(cx.meta["bounds"])[s])[0]
    for x in extra[:50]:
        back = x.copy()
        back[s] -= period
        back[t] = lo_t + hi_t - x[t]
        assert np.min(np.abs(V - back).max(axis=1)) < 1e-12


def test_without_identified_axes_the_complex_is_drawn_as_it_is():
    cx = extract(["x^2 + y^2 + z^2 - 1"], [(-1.5, 1.5)] * 3, 8, variables="x,y,z")
    assert display_complex(cx) is cx


def test_picked_cells_are_the_complexs_own():
    cx = _run("torus-angles", 12)
    geo = Geometry.build(cx, lod=False)
    assert sorted(geo.cell_ids.tolist()) == list(range(cx.count(2)))
