"""Cross-sections of a cell complex by a hyperplane ``h(x) = c``, ``h`` linear.

The section of a complex of dimension d is a complex of dimension d - 1, built
from the cell structure alone (no new evaluation of F):

* a 0-cell for each edge whose ends lie on opposite sides of the hyperplane, at
  the point of the edge where ``h = c`` (linear interpolation in R^n);
* a 1-cell for each arc of a 2-cell's boundary loop that lies below the
  hyperplane: it joins the two crossing points that end the arc (the level set
  of ``h`` on a polygon, with the ambiguity of a polygon crossed four or more
  times settled one way everywhere, as marching squares settles it);
* an r-cell (r >= 2) for each connected piece of the sections of the faces of
  an (r+1)-cell, its faces being those sections (the rule GCMH itself uses: one
  cell per connected piece of a cube's vertex-edge graph).

A vertex exactly on the hyperplane counts as above it (symbolic perturbation:
the section is the one of ``h = c - eps``), so every vertex has a side, every
edge crosses or not, and the section is a valid complex whatever ``c`` is:
every r-cell has at least r + 1 faces, and the section of a closed complex is
closed.  Two cells of the section may then meet at one point of R^n (an edge
from a vertex on the hyperplane gives the crossing point at that vertex); the
combinatorics stay those of ``h = c - eps``.

Everything is vectorised with numpy.  :class:`Sectioner` keeps what does not
depend on ``c`` (``h`` at the vertices, each cell's range of ``h``), so moving
``c`` costs only the cells the hyperplane meets: a slider step of the 3-sphere
or the three-torus takes a few milliseconds.

Identified (periodic) axes: the section is the one of the glued space, where the hyperplane is one set
of it.  A direction that does not involve a glued axis is cut as it is.  A direction that involves periodic
axes (``s = c`` on a circle, ``s + t = c`` on a torus of angles) cuts the levels ``c + k Q`` (Q: the period
of ``h``, the periods' common step): each vertex's side is read on the circle (the half-turn after ``c``
is above), and an edge crosses when it meets a level, not the half-turn opposite.  A variable ``b``
reversed across a seam (``t`` of the closed Klein bottle, ``s:flip=t``) cuts ``{b = c} U {b = m - c}``
(``m``: the sum of b's bounds), the one set of the glued space that holds ``b = c``; each vertex's side
is its distance to the mirror's value ``m / 2`` (on the circle if b is periodic) against ``c``'s.  Where
``c`` is so near a value the mirror fixes that one edge would hold both levels (or on it: there the two
levels are one and no side is kept across the seam), the cut is made at the nearest value beyond them
(``meta["section"]["value"]``; ``"asked"`` keeps ``c``).  Directions mixing a reversed axis with others,
or periodic axes of incommensurate periods, are refused with :class:`gcmh_core.errors.InputError`.
Points on an edge across a seam are computed in its first vertex's chart, then put back into the box.

Example
-------
>>> import numpy as np
>>> from gcmh_core.complex import CellComplex
>>> square = CellComplex(2, 0, [[0, 0], [1, 0], [1, 1], [0, 1]],
...                      [[0, 1], [1, 2], [2, 3], [3, 0]], {2: ([0, 4], [0, 1, 2, 3])})
>>> cut = section(square, "x1", 0.25)
>>> cut.dim, cut.counts(), cut.vertices.tolist()
(1, [2, 1], [[0.25, 0.0], [0.25, 1.0]])
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass

import numpy as np

from .complex import CellComplex, _component_roots, _gather_segments
from .errors import InputError

__all__ = ["Profile", "SectionCells", "Sectioner", "direction_vector", "parse_section_spec", "section",
           "section_profile", "section_summary"]


# ----------------------------------------------------------------------------
# validation
# ----------------------------------------------------------------------------

def _check_complex(cx) -> CellComplex:
    if not isinstance(cx, CellComplex):
        raise InputError(f"a section needs a CellComplex, got {type(cx).__name__}")
    if cx.dim < 1:
        raise InputError(f"a complex of dimension {cx.dim} (points) has no sections")
    return cx


def direction_vector(cx: CellComplex, axis_or_direction) -> tuple[np.ndarray, str]:
    """The linear function ``h(x) = u . x`` of a section: (u (n,) float64, a label for it).

    ``axis_or_direction``: a coordinate's index (0..n-1) or name (``cx.point_names()``), or a
    direction (n,) of finite numbers, not all 0 (used as given, not normalised).
    """
    names = cx.point_names()
    n = cx.n
    if isinstance(axis_or_direction, str):
        name = axis_or_direction.strip()
        if name not in names:
            raise InputError(f"no variable {name!r} to cut along (variables: {', '.join(names)})")
        i = names.index(name)
        return np.eye(n)[i], name
    if isinstance(axis_or_direction, (bool, np.bool_)):
        raise InputError(f"the direction must be an axis (index or name) or a vector, got {axis_or_direction!r}")
    try:
        i = operator.index(axis_or_direction)
    except TypeError:
        pass
    else:
        if not 0 <= i < n:
            raise InputError(f"axis {i} does not exist in R^{n} (0..{n - 1})")
        return np.eye(n)[i], names[i]
    try:
        u = np.asarray(axis_or_direction, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"the direction must be an axis (index or name) or a vector, got {axis_or_direction!r}") \
            from None
    if u.shape != (n,):
        raise InputError(f"a direction in R^{n} has {n} components, got shape {u.shape}")
    if not np.all(np.isfinite(u)) or not np.any(u):
        raise InputError(f"the direction must be finite and not 0, got {u.tolist()}")
    label = " + ".join(f"{x:g}*{nm}" for x, nm in zip(u.tolist(), names) if x)
    return u, label


def _check_value(value) -> float:
    if isinstance(value, (bool, np.bool_)):
        raise InputError(f"the section's value must be a number, got {value!r}")
    try:
        c = float(value)
    except (TypeError, ValueError):
        raise InputError(f"the section's value must be a number, got {value!r}") from None
    if not math.isfinite(c):
        raise InputError(f"the section's value must be finite, got {value!r}")
    return c


def _seams(cx: CellComplex):
    """[(axis p, period, lo, flipped axes, their lo + hi)] of ``cx``'s identified axes, the seams that
    reverse axes first (a reversed axis may be periodic itself, never one that reverses others)."""
    from ._validate import as_periodic

    meta = cx.meta
    items, names, bounds, div = meta.get("periodic"), meta.get("variables"), meta.get("bounds"), meta.get("div")
    if not items or not names or bounds is None or div is None:
        return []
    try:
        spec = as_periodic(items, names, div if np.ndim(div) else [div] * cx.n)
        bounds = np.asarray(bounds, dtype=np.float64).reshape(cx.n, 2)
    except (InputError, ValueError):   # (meta that did not come from a run: the complex as it is)
        return []
    out = [(p, bounds[p, 1] - bounds[p, 0], bounds[p, 0], flips, bounds[list(flips), :].sum(axis=1))
           for p, flips in spec]
    return sorted(out, key=lambda seam: not seam[3])


@dataclass
class _Circle:
    """How ``h = u . x`` lives on the glued space: ``mode`` "plain" (no glued axis in u: h is a function
    there), "shift" (h is defined up to multiples of ``period``: a circle-valued function) or "mirror"
    (u is a multiple of an axis reversed across a seam: h is defined up to h -> ``mirror`` - h, and up to
    ``period`` when that axis is periodic too, else ``period`` is 0)."""

    mode: str = "plain"
    period: float = 0.0
    mirror: float = 0.0


def _circle(cx: CellComplex, u: np.ndarray, seams) -> _Circle:
    """The :class:`_Circle` of ``u`` on ``cx``'s glued space; InputError when the hyperplanes ``u . x = c``
    are not sets of it (a reversed axis mixed with others, periodic axes of incommensurate periods)."""
    if not seams:
        return _Circle()
    names = cx.point_names()
    period = {p: per for p, per, *_ in seams}
    flipped = {b: (p, m) for p, _per, _lo, flips, mirror in seams for b, m in zip(flips, mirror)}
    touched = np.flatnonzero(u)
    reversed_ = [a for a in touched.tolist() if a in flipped]
    if reversed_:
        b = reversed_[0]
        if touched.size > 1:
            raise InputError(
                f"a section along {' + '.join(names[a] for a in touched.tolist())} is not one set of the glued "
                f"space: {names[b]} is reversed across the seam of {names[flipped[b][0]]}; cut along {names[b]} "
                f"alone, or along variables not reversed across a seam")
        lam = float(u[b])
        return _Circle("mirror", abs(lam) * period.get(b, 0.0), lam * float(flipped[b][1]))
    shifts = [abs(float(u[a])) * period[a] for a in touched.tolist() if a in period]
    if not shifts:
        return _Circle()
    q = min(shifts)
    ratio = np.asarray(shifts) / q
    if np.any(np.abs(ratio - np.round(ratio)) > 1e-9):
        raise InputError(
            f"a section along {' + '.join(names[a] for a in touched.tolist())} winds round the glued axes at "
            f"periods that are not multiples of one another ({', '.join(f'{x:g}' for x in shifts)}): its "
            f"levels are not closed sets of the glued space; choose coefficients whose periods match")
    # a cell (inside one grid cube) must span less than half a turn of h: its sides are read on the circle
    bounds = np.asarray(cx.meta["bounds"], dtype=np.float64).reshape(cx.n, 2)
    div = cx.meta["div"]
    step = (bounds[:, 1] - bounds[:, 0]) / (np.asarray(div, dtype=np.float64) if np.ndim(div) else float(div))
    if float(np.abs(u) @ step) >= q / 2:
        raise InputError(f"the grid is too coarse to cut along this direction: a cube spans half a turn of it "
                         f"(period {q:g}); cut along a single glued variable or refine the grid")
    return _Circle("shift", q)


def _lift(Y: np.ndarray, X: np.ndarray, seams) -> np.ndarray:
    """The points ``Y`` (m, n) in the charts of the points ``X`` (m, n) next to them: across a seam moved
    by the period (and reflected in the reversed axes), so that ``Y - X`` is the short way round."""
    Y = np.array(Y, dtype=np.float64)
    for p, period, _lo, flips, mirror in seams:
        if flips:
            w = np.flatnonzero(np.abs(Y[:, p] - X[:, p]) > period / 2)
            Y[w, p] += np.sign(X[w, p] - Y[w, p]) * period
            for b, m in zip(flips, mirror):
                Y[w, b] = m - Y[w, b]
        else:
            Y[:, p] += np.round((X[:, p] - Y[:, p]) / period) * period
    return Y


def _into_box(P: np.ndarray, seams) -> np.ndarray:
    """The points ``P`` (m, n), computed in a chart beside the box, back into it (in place)."""
    for p, period, lo, flips, mirror in seams:
        out = (P[:, p] < lo) | (P[:, p] >= lo + period)
        if out.any():
            turns = np.floor((P[out, p] - lo) / period)
            P[out, p] -= turns * period
            if flips:
                odd = np.flatnonzero(out)[np.mod(turns, 2) == 1]
                for b, m in zip(flips, mirror):
                    P[odd, b] = m - P[odd, b]
    return P


# ----------------------------------------------------------------------------
# the kernel
# ----------------------------------------------------------------------------

@dataclass
class SectionCells:
    """A section and where its cells come from.

    complex: the section, a CellComplex of dimension d - 1 in the same R^n;
    sources: for r = 0..d-1, (N_r,) int64: the (r+1)-cell of the sectioned complex each
    r-cell of the section lies in (an edge for a vertex, a 2-cell for an edge, ...).
    """

    complex: CellComplex
    sources: list

    @property
    def euler_characteristic(self) -> int:
        return self.complex.euler_characteristic()

    @property
    def pieces(self) -> int:
        return self.complex.connected_components()


def _ranges(lo_faces, hi_faces, off, fac):
    """Each cell's range of h from its faces' ranges (CSR ``off``, ``fac``): (lo, hi) float64."""
    count = np.diff(off)
    n_cells = count.size
    lo = np.full(n_cells, np.inf)
    hi = np.full(n_cells, -np.inf)
    has = count > 0
    if fac.size:
        starts = off[:-1][has]
        lo[has] = np.minimum.reduceat(lo_faces[fac], starts)
        hi[has] = np.maximum.reduceat(hi_faces[fac], starts)
    return lo, hi


class Sectioner:
    """Sections of one complex by the hyperplanes ``direction . x = c``, for any ``c``.

    What does not depend on ``c`` is made once here: ``h`` at the vertices, each cell's range of
    ``h`` (a cell is met when ``lo < c <= hi``), the edges' vectors across glued seams.  Then
    :meth:`cells` and :meth:`section` cost what the cells met cost.  Along a glued axis (``circle``:
    how ``h`` lives on the glued space) each value reads every edge's side and a cell is met when one
    of its faces is (a pass over all cells, still a few milliseconds).
    """

    def __init__(self, cx: CellComplex, axis_or_direction):
        cx = _check_complex(cx)
        u, label = direction_vector(cx, axis_or_direction)
        self.complex = cx
        self.direction = u
        self.label = label
        self.seams = _seams(cx)
        self.circle = _circle(cx, u, self.seams)
        X = np.asarray(cx.vertices)
        self.h = X @ u
        E = np.asarray(cx.edges)
        self.edge_a = np.ascontiguousarray(E[:, 0])
        self.edge_b = np.ascontiguousarray(E[:, 1])
        # each edge's vector, in its first vertex's chart (the short way round across a seam)
        self.delta = _lift(X[self.edge_b], X[self.edge_a], self.seams) - X[self.edge_a] if self.seams else \
            X[self.edge_b] - X[self.edge_a]
        if self.circle.mode == "plain":
            ha, hb = self.h[self.edge_a], self.h[self.edge_b]
            self.lo = {1: np.minimum(ha, hb)}
            self.hi = {1: np.maximum(ha, hb)}
            for r in range(2, cx.dim + 1):
                off, fac = cx.cells[r]
                self.lo[r], self.hi[r] = _ranges(self.lo[r - 1], self.hi[r - 1], np.asarray(off),
                                                 np.asarray(fac))
        else:   # h is read on a circle: a cell is met when one of its faces is
            self.dh = self.delta @ u
            self.owner = {}
            for r in range(2, cx.dim + 1):
                off = np.asarray(cx.cells[r][0])
                self.owner[r] = np.repeat(np.arange(off.size - 1, dtype=np.int64), np.diff(off))
            if self.circle.mode == "mirror":
                self._folds()

    # ------------------------------------------------------------------ glued: the mirror's folds
    def _fold_distance(self, h: np.ndarray) -> np.ndarray:
        """How far ``h`` is from the value the mirror fixes (``mirror / 2``), round the circle if periodic:
        the function of the glued space whose levels are ``{c, mirror - c}``."""
        d = h - self.circle.mirror / 2
        q = self.circle.period
        return np.abs(d) if q == 0 else np.abs(np.mod(d + q / 2, q) - q / 2)

    def _folds(self) -> None:
        """Where an edge crosses a value the mirror fixes, its fold distance dips to 0 (or, round a circle,
        rises to half the period at the other one): a level nearer that value than both the edge's ends would
        meet the edge twice.  Kept: the largest such end distance at 0 (``fold_low``) and the smallest at the
        half period (``fold_high``)."""
        q, f = self.circle.period, self.circle.mirror / 2
        ha = self.h[self.edge_a]
        hb = ha + self.dh
        lo, hi = np.minimum(ha, hb), np.maximum(ha, hb)
        ga, gb = self._fold_distance(ha), self._fold_distance(hb)
        near = np.minimum(ga, gb)
        fixed = [(f, True)] if q == 0 else [(f, True), (f + q / 2, False)]
        self.fold_low, self.fold_high = 0.0, np.inf
        for value, low in fixed:
            if q:
                value = value + q * np.round((0.5 * (lo + hi) - value) / q)
            across = (lo < value) & (value < hi)
            if not across.any():
                continue
            if low:
                self.fold_low = float(near[across].max())
            else:
                self.fold_high = float(np.maximum(ga, gb)[across].min())

    def _resolved(self, c: float) -> float:
        """``c``, or, when an edge would hold both levels ``c`` and ``mirror - c``, the nearest value on c's
        side whose levels each edge holds at most once."""
        if self.circle.mode != "mirror":
            return c
        g = float(self._fold_distance(np.asarray(c)))
        q, f = self.circle.period, self.circle.mirror / 2
        lo_g, hi_g = self.fold_low, min(self.fold_high, q / 2 if q else np.inf)
        scale = max(self.range()[1] - self.range()[0], q, 1e-300)
        tiny = 1e-6 * scale
        if lo_g + 2 * tiny >= hi_g:
            raise InputError("the grid is too coarse to cut along a variable reversed across a seam: refine it")
        if g > lo_g and g < hi_g:
            return c
        target = lo_g + tiny if g <= lo_g else hi_g - tiny
        # the representative of c's level nearest c, moved to ``target`` from the fixed value
        d = c - f
        if q:
            d = np.mod(d + q / 2, q) - q / 2
        return float(c - d + np.copysign(target, d if d != 0 else 1.0))

    def range(self) -> tuple[float, float]:
        """(min, max) of ``h`` over the finite vertices ((0, 0) when there are none)."""
        h = self.h[np.isfinite(self.h)]
        return (float(h.min()), float(h.max())) if h.size else (0.0, 0.0)

    def levels(self, value, lo: float, hi: float) -> list:
        """The values of ``h`` in ``[lo, hi]`` that the section at ``value`` lies on, in each vertex's own chart:
        ``[value]`` on an unglued direction; round a glued circle every ``value + kQ``, and across a reversed
        seam every ``mirror - value + kQ`` too (where the app draws the band of cells beside the section)."""
        c = self._resolved(_check_value(value))
        circle = self.circle
        if circle.mode == "plain":
            return [c]
        bases = [c] if circle.mode == "shift" else [c, circle.mirror - c]
        out = set()
        for b in bases:
            if circle.period:
                k = np.arange(np.ceil((lo - b) / circle.period), np.floor((hi - b) / circle.period) + 1)
                out.update((b + k * circle.period).tolist())
            elif lo <= b <= hi:
                out.add(b)
        return sorted(out) or [c]

    def section(self, value) -> CellComplex:
        """The section ``h = value``: a CellComplex of dimension d - 1 (see the module's docstring)."""
        return self.cells(value).complex

    def cells(self, value) -> SectionCells:
        """The section ``h = value`` and the cell each of its cells comes from."""
        return self._cells(_check_value(value))

    # ------------------------------------------------------------------ levels
    def _cells(self, asked: float) -> SectionCells:
        cx = self.complex
        c = self._resolved(asked)
        up, crossing, level = self._sides(c)
        met = self._met_masks(c, crossing)
        vertices, edge_vertex, src0 = self._points(crossing, level)
        sources = [src0]
        edges = np.zeros((0, 2), dtype=np.int64)
        higher: dict = {}
        if cx.dim >= 2:
            edges, src1 = self._segments(met(2), up, edge_vertex)
            sources.append(src1)
            below_faces, below_src = edges, src1
            for r in range(2, cx.dim):
                off, fac, src = self._pieces(met(r + 1), r, below_faces, below_src)
                higher[r] = (off, fac)
                sources.append(src)
                below_faces, below_src = (off, fac), src
        meta = {key: cx.meta[key] for key in ("variables", "labels", "formulas", "bounds", "div", "periodic")
                if key in cx.meta}
        meta["section"] = {"direction": self.direction.tolist(), "along": self.label, "value": c,
                           "of_counts": cx.counts()}
        if c != asked:
            meta["section"]["asked"] = asked
        sec = CellComplex(cx.n, cx.k + 1, vertices, edges, higher, meta)
        return SectionCells(sec, sources)

    def _sides(self, c: float):
        """(each vertex above the hyperplane? (V,) bool, each edge crossing it? (E,) bool, the level each
        edge meets in its first vertex's chart: a float, or (E,) floats on a glued circle)."""
        circle, h = self.circle, self.h
        a, b = self.edge_a, self.edge_b
        if circle.mode == "plain":
            up = h >= c                      # a vertex on the hyperplane counts as above it
            return up, up[a] != up[b], c
        q = circle.period
        mid = h[a] + 0.5 * self.dh
        if circle.mode == "shift":          # above: the half-turn after c
            up = np.mod(h - c, q) < q / 2
            level = c + q * np.round((mid - c) / q)
            opposite = c + q / 2 + q * np.round((mid - c - q / 2) / q)
            # sides differ across a level or across the half-turn opposite it (cells span less than half a turn)
            crossing = (up[a] != up[b]) & (np.abs(level - mid) < np.abs(opposite - mid))
            return up, crossing, level
        # mirror: above is farther from the fixed value than c (a function of the glued space)
        g = float(self._fold_distance(np.asarray(c)))
        up = self._fold_distance(h) >= g
        twin = circle.mirror - c
        if q:
            one = c + q * np.round((mid - c) / q)
            two = twin + q * np.round((mid - twin) / q)
        else:
            one, two = np.full(mid.size, c), np.full(mid.size, twin)
        lo = np.minimum(h[a], h[a] + self.dh)
        hi = np.maximum(h[a], h[a] + self.dh)
        inside_one = (lo <= one) & (one <= hi)
        inside_two = (lo <= two) & (two <= hi)
        pick_one = np.where(inside_one != inside_two, inside_one, np.abs(one - mid) <= np.abs(two - mid))
        return up, up[a] != up[b], np.where(pick_one, one, two)

    def _met_masks(self, c: float, crossing: np.ndarray):
        """r -> the r-cells the hyperplane meets (indices, ascending): from each cell's range of h, or on a
        glued circle, the cells one of whose faces is met."""
        if self.circle.mode == "plain":
            return lambda r: self._met(r, c)
        masks = {1: crossing}

        def met_glued(r):
            for k in range(2, r + 1):
                if k not in masks:
                    off = np.asarray(self.complex.cells[k][0])
                    fac = np.asarray(self.complex.cells[k][1])
                    hit = np.bincount(self.owner[k], weights=masks[k - 1][fac], minlength=off.size - 1)
                    masks[k] = hit > 0
            return np.flatnonzero(masks[r])
        return met_glued

    def _met(self, r: int, c: float) -> np.ndarray:
        return np.flatnonzero((self.lo[r] < c) & (self.hi[r] >= c))

    def _points(self, crossing, level):
        """Level 0: a point on each edge crossing the hyperplane; (points, the point of each edge or -1,
        the edge of each point)."""
        a, b = self.edge_a, self.edge_b
        crossing = np.flatnonzero(crossing)
        edge_vertex = np.full(a.size, -1, dtype=np.int64)
        edge_vertex[crossing] = np.arange(crossing.size, dtype=np.int64)
        ea = a[crossing]
        ha = self.h[ea]
        dh = self.h[b[crossing]] - ha if self.circle.mode == "plain" else self.dh[crossing]
        lev = level if np.ndim(level) == 0 else level[crossing]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.clip((lev - ha) / dh, 0.0, 1.0)   # the ends' sides differ, so their h differ
        t = np.where(np.isfinite(t), t, 0.5)
        X = np.asarray(self.complex.vertices)
        P = X[ea] + t[:, None] * self.delta[crossing]
        if self.seams:
            _into_box(P, self.seams)
        return P, edge_vertex, crossing.astype(np.int64)

    def _segments(self, met, up, edge_vertex):
        """Level 1: in each 2-cell met, one segment per arc of its loop below the hyperplane, joining the
        points of the two crossing edges that end the arc.  (edges (E', 2), the 2-cell of each)."""
        off, fac = (np.asarray(x) for x in self.complex.cells[2])
        if met.size == 0:
            return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
        rep, e = _gather_segments(off, fac, met)   # rep: the local 2-cell of each (cell, edge) entry
        a, b = self.edge_a[e], self.edge_b[e]
        ua, ub = up[a], up[b]
        low = ~ua & ~ub
        cross = ua != ub
        # the arcs below: nodes (cell, vertex below), joined along the cell's edges below
        nv = max(self.complex.count(0), 1)
        vm = np.where(ua[cross], b[cross], a[cross])        # the crossing edge's end below
        keys = np.concatenate([rep[low] * nv + a[low], rep[low] * nv + b[low], rep[cross] * nv + vm])
        uniq, node = np.unique(keys, return_inverse=True)
        node = node.ravel()
        n_low = int(low.sum())
        roots = _component_roots(uniq.size, node[:n_low], node[n_low:2 * n_low])
        arc = roots[node[2 * n_low:]]                       # the arc each crossing entry ends
        point = edge_vertex[e[cross]]
        order = np.argsort(arc, kind="stable")
        arc, point = arc[order], point[order]
        # a simple loop's arc has two ends; pair ends in order where a degenerate loop gives more
        start = np.flatnonzero(np.r_[True, arc[1:] != arc[:-1]])
        size = np.diff(np.r_[start, arc.size])
        first = np.repeat(start, size)
        pos = np.arange(arc.size) - first
        even = (pos % 2 == 0) & (pos + 1 < np.repeat(size, size))
        i = np.flatnonzero(even)
        edges = np.stack([point[i], point[i + 1]], axis=1)
        cell = met[rep[cross][order][i]]
        return edges.astype(np.int64), cell.astype(np.int64)

    def _pieces(self, met, r, below_faces, below_src):
        """Level r >= 2: in each (r+1)-cell met, one r-cell per connected piece of the sections of its
        faces (joined where they share an (r-2)-cell).  Returns CSR (offsets, faces) and the source cells.

        ``below_faces``: the section's (r-1)-cells: edges (E', 2) for r = 2, else CSR (offsets, faces);
        ``below_src``: the r-cell of the complex each lies in, ascending.
        """
        off, fac = (np.asarray(x) for x in self.complex.cells[r + 1])
        empty = (np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))
        if met.size == 0 or below_src.size == 0:
            return empty
        rep, f = _gather_segments(off, fac, met)            # (local cell, r-face) entries
        lo = np.searchsorted(below_src, f, side="left")
        hi = np.searchsorted(below_src, f, side="right")
        n_child = hi - lo
        cell = np.repeat(rep, n_child)                      # (local cell, section (r-1)-cell) entries
        first = np.cumsum(n_child) - n_child
        s = np.repeat(lo - first, n_child) + np.arange(int(n_child.sum()), dtype=np.int64)
        m = s.size
        if m == 0:
            return empty
        # the (r-2)-cells of each entry's section cell
        if r == 2:
            owner = np.repeat(np.arange(m, dtype=np.int64), 2)
            g = below_faces[s].ravel()
        else:
            b_off, b_fac = below_faces
            owner, g = _gather_segments(b_off, b_fac, s)
        n_g = int(g.max()) + 1 if g.size else 1
        key = cell[owner] * n_g + g
        order = np.argsort(key, kind="stable")
        key, owner = key[order], owner[order]
        same = np.flatnonzero(key[1:] == key[:-1])
        roots = _component_roots(m, owner[same], owner[same + 1])
        # entries are in cell order, a root is its piece's smallest entry: pieces come out in cell order
        order = np.argsort(roots, kind="stable")
        roots = roots[order]
        new = np.r_[True, roots[1:] != roots[:-1]]
        n_new = int(new.sum())
        offsets = np.zeros(n_new + 1, dtype=np.int64)
        offsets[1:] = np.r_[np.flatnonzero(new)[1:], m]
        faces = s[order]
        source = met[cell[order][new]]
        return offsets, faces.astype(np.int64), source.astype(np.int64)

    # ----------------------------------------------------------------- profile
    def profile(self, values) -> Profile:
        """chi and pieces of the section at each of ``values`` (a 1-D sequence of finite numbers)."""
        vals = np.asarray(values, dtype=np.float64).ravel()
        if not np.all(np.isfinite(vals)):
            raise InputError("the section values must be finite")
        chi = np.zeros(vals.size, dtype=np.int64)
        pieces = np.zeros(vals.size, dtype=np.int64)
        for i, c in enumerate(vals.tolist()):
            sec = self._cells(c).complex
            chi[i] = sec.euler_characteristic()
            pieces[i] = sec.connected_components()
        return Profile(vals, chi, pieces, self.label)


@dataclass
class Profile:
    """chi and the number of pieces (connected components) of the sections at ``values``: (m,) arrays."""

    values: np.ndarray
    chi: np.ndarray
    pieces: np.ndarray
    along: str = ""

    def changes(self) -> np.ndarray:
        """Indices i >= 1 where chi or pieces differ from value i - 1 (where the topology changes)."""
        d = (np.diff(self.chi) != 0) | (np.diff(self.pieces) != 0)
        return np.flatnonzero(d) + 1


# ----------------------------------------------------------------------------
# public functions
# ----------------------------------------------------------------------------

def section(cx: CellComplex, axis_or_direction, value) -> CellComplex:
    """The section of ``cx`` by the hyperplane ``h(x) = value``: a CellComplex of dimension ``cx.dim - 1``.

    Parameters
    ----------
    cx : CellComplex of dimension d >= 1 in R^n
    axis_or_direction : int, str or (n,) array
        A coordinate (index, or name from ``cx.point_names()``): ``h(x) = x_i``; or a direction u:
        ``h(x) = u . x`` (not normalised).
    value : float

    Returns
    -------
    CellComplex of dimension d - 1 (n, k + 1): vertices (V', n) on the edges crossed, an edge per arc of a
    2-cell's loop below the hyperplane, an r-cell per connected piece of an (r+1)-cell's section;
    ``meta["section"]`` names the direction and value.  Empty when the hyperplane misses ``cx``.

    Raises
    ------
    InputError
        For a direction that is not an axis or a finite non-zero vector of length n, a value that is not
        a finite number, a complex of dimension 0, or a direction whose hyperplanes are not sets of the
        glued space (a reversed axis mixed with others, periodic axes of incommensurate periods).
    """
    return Sectioner(cx, axis_or_direction).section(value)


def section_profile(cx: CellComplex, axis_or_direction, values=None, count: int = 101) -> Profile:
    """chi and pieces of the sections of ``cx`` at each of ``values`` (default: ``count`` values evenly
    spaced strictly inside the range of ``h`` over the vertices), for a Morse picture of ``cx``."""
    sec = Sectioner(cx, axis_or_direction)
    if values is None:
        count = operator.index(count)
        if count < 1:
            raise InputError(f"count must be >= 1, got {count}")
        lo, hi = sec.range()
        values = lo + (hi - lo) * (np.arange(count) + 0.5) / count
    return sec.profile(values)


def parse_section_spec(spec_text: str, variables) -> tuple[int, float]:
    """``"VAR=C"`` -> (the index of VAR among ``variables``, C) with C a constant (``0.5``, ``-pi/4``, read by
    :func:`gcmh_core.formula.evaluate_constant`); InputError naming what is wrong.  The command line checks
    ``--section`` with it before the run."""
    from .formula import evaluate_constant

    names = list(variables)
    if not isinstance(spec_text, str) or "=" not in spec_text:
        raise InputError(f"--section wants VAR=C (VAR one of {', '.join(names)}), got {spec_text!r}")
    var, _, const = spec_text.partition("=")
    var = var.strip()
    if var not in names:
        raise InputError(f"--section {spec_text!r}: {var!r} is not a variable (variables: {', '.join(names)})")
    return names.index(var), evaluate_constant(const)


def section_summary(cx: CellComplex, spec_text: str, variables=None) -> tuple[CellComplex, dict, str]:
    """The section named by ``spec_text`` (``"VAR=C"``, see :func:`parse_section_spec`) for the command
    line: (the section, a summary dict, one human line).  ``variables``: the names VAR may take (default
    ``cx.point_names()``)."""
    names = list(variables) if variables is not None else cx.point_names()
    axis, c = parse_section_spec(spec_text, names)
    var = names[axis]
    sec = Sectioner(cx, axis).section(c)
    chi = sec.euler_characteristic()
    pieces = sec.connected_components() if sec.count(0) else 0
    open_facets = int(sec.boundary_facets().size) if sec.dim >= 1 else 0
    cut = sec.meta["section"]["value"]
    summary = {"along": var, "value": cut, "dimension": sec.dim, "counts": sec.counts(),
               "euler_characteristic": chi, "pieces": pieces, "boundary_facets": open_facets}
    head = f"section {var} = {c:g}"
    if cut != c:   # beside a value the mirror of a glued seam fixes: cut where the grid tells the two levels apart
        summary["asked"] = c
        head += f" (cut at {cut:.6g}, the nearest value the grid resolves beside the seam's mirror)"
    if sec.count(0) == 0:
        line = f"{head}: empty (the hyperplane misses the result)"
    else:
        cells = ", ".join(f"{x} {_cell_word(r, x)}" for r, x in enumerate(sec.counts()))
        closed = "closed" if open_facets == 0 else f"{open_facets} boundary facets"
        line = (f"{head}: dimension {sec.dim}, {cells}; chi = {chi}, "
                f"{pieces} piece{'s' if pieces != 1 else ''}, {closed}")
    return sec, summary, line


def _cell_word(r: int, count: int) -> str:
    word = {0: "vertex", 1: "edge"}.get(r, f"{r}-cell")
    if count == 1:
        return word
    return "vertices" if r == 0 else word + "s"
