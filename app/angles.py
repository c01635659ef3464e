"""Angles drawn as angles: periodic (glued) axes as circles, their seam, a cyclic colour map (no Qt, no VTK).

A result on a domain with identified axes (``cx.meta["periodic"]``, e.g. ``["s:flip=t", "t"]``) has
coordinates that are angles: s = 2pi is s = 0. Drawn as numbers they are a box whose opposite faces are
far apart, so the seam looks like a cut.

* :func:`circle_rows` ("angles as circles") maps the angles to the nested torus they parametrise, made of
  (cos, sin) of each angle: the first angle a circle of radius ``2 rho`` (``rho`` = period / 2pi), each
  further angle a circle of half the radius before it about the previous torus (its cos along that
  torus's outward normal, its sin in a new direction). Two angles give the ring torus
  ((2 + cos t) cos s, (2 + cos t) sin s, sin t). An axis reversed across another's seam (the Klein bottle's
  t, the Moebius band's t) turns its new direction half a turn while the other angle turns once
  (``cos(s/2) e + sin(s/2) e'``), so the map takes the same value on both sides of every seam: the
  picture is closed. The other coordinates stay as they are.
* :class:`CircleProjector` projects those rows with the view's (3, n) matrix ``P``: every row is drawn
  along the screen column of the axis it comes from (the first circle's sin along the next angle's column,
  each further angle's new direction along its own column turned by ``K``, x -> y -> z -> x), so the
  sliders turn the closed picture as they turn the box; an angle off screen (a hidden axis) adds nothing.
* :func:`seam_lines` is the seam itself: where M crosses the glued face, as segments in R^n.
* :func:`cyclic_colour` says which colour map and range a coordinate gets: a cyclic one over the period
  for a periodic axis, so 0 and 2pi have one colour.
"""

from __future__ import annotations

import numpy as np

from .projection import Projector, View

CYCLIC_CMAP = "twilight_shifted"   # a cyclic map: its two ends are one colour
FIRST_RADIUS = 2.0                  # the first angle's circle, in radii rho = period / 2pi
SHRINK = 0.5                        # each further angle's circle, against the one before it
# K: the screen turned a third of a turn about (1, 1, 1), x -> y -> z -> x: a direction for an angle's
# second coordinate that differs from its first
K = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def seam_spec(cx) -> list:
    """[(axis, period, lo, (flipped axes), (their lo + hi))] of the identified axes in ``cx.meta``."""
    from .geometry import seam_spec as spec

    return spec(cx)


def periodic_axes(cx) -> dict:
    """{axis: (lo, period)} of ``cx``'s periodic axes."""
    return {p: (lo, period) for p, period, lo, _, _ in seam_spec(cx)}


def flipped_by(spec) -> dict:
    """{axis b: the periodic axis p whose seam reverses b} (the first one, when several do)."""
    out: dict = {}
    for p, _, _, flips, _ in spec:
        for b in flips:
            out.setdefault(int(b), int(p))
    return out


def cyclic_colour(cx, name: str, names) -> tuple[str, list[float]] | None:
    """(colour map, [lo, hi]) for colouring ``cx`` by coordinate ``name`` when it is a periodic axis that no
    seam reverses (the two ends of its period get one colour); None otherwise (the ordinary map)."""
    if name not in names:
        return None
    a = list(names).index(name)
    spec = seam_spec(cx)
    per = {p: (lo, period) for p, period, lo, _, _ in spec}
    if a not in per or a in flipped_by(spec):
        return None
    lo, period = per[a]
    return CYCLIC_CMAP, [float(lo), float(lo + period)]


def _order(spec) -> list:
    """The periodic axes in nesting order: an axis that reverses others before the axes it reverses."""
    flips = flipped_by(spec)
    axes = [int(p) for p, *_ in spec]
    return [p for p in axes if p not in flips] + [p for p in axes if p in flips]


def circle_rows(X: np.ndarray, spec, center=None) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """The rows of "angles as circles" for points ``X`` (V, n): ``(Y (q, V) float64, owners)``.

    ``owners[j] = (axis, turn)``: row j is drawn along ``K^turn @ P[:, axis]`` (:func:`circle_matrix`);
    ``turn = -1`` means "along the next angle's column" (the first circle's second coordinate).
    ``center`` (n,): subtracted from the coordinates that stay as they are (the view's centre).
    """
    X = np.asarray(X, dtype=np.float64)
    V, n = X.shape
    c = np.zeros(n) if center is None else np.asarray(center, dtype=np.float64)
    per = {int(p): (lo, period) for p, period, lo, _, _ in spec}
    mirror = {int(b): m / 2.0 for _, _, _, flips, ms in spec for b, m in zip(flips, ms)}
    flips = flipped_by(spec)
    order = _order(spec)
    rows: list[np.ndarray] = []
    owners: list[tuple[int, int]] = []
    theta = {p: 2 * np.pi * (X[:, p] - per[p][0]) / per[p][1] for p in order}
    rho = {p: per[p][1] / (2 * np.pi) for p in order}
    # the nested torus: its point E and its outward normal N (unit), both as lists of rows
    E: list[np.ndarray] = []
    N: list[np.ndarray] = []
    radius = 0.0
    for j, p in enumerate(order):
        r = FIRST_RADIUS * rho[p] if j == 0 else radius * SHRINK
        radius = r
        cos_t, sin_t = np.cos(theta[p]), np.sin(theta[p])
        if j == 0:
            E = [r * cos_t, r * sin_t]
            N = [cos_t, sin_t]
            owners += [(p, 0), (p, -1)]
            continue
        new = [sin_t]                       # the new direction's coefficient(s)
        if p in flips:                      # reversed across q's seam: the new direction turns half a turn
            half = theta[flips[p]] / 2
            new = [sin_t * np.cos(half), sin_t * np.sin(half)]
        E = [e + r * cos_t * nn for e, nn in zip(E, N)] + [r * w for w in new]
        N = [cos_t * nn for nn in N] + list(new)
        owners += [(p, t + 1) for t in range(len(new))]
    # an ordinary axis reversed across a seam (the Moebius band's t): a radius along the normal, turning
    for b, p in flips.items():
        if b in per or not E:
            continue
        u = X[:, b] - mirror[b]
        half = theta[p] / 2
        E = [e + u * np.cos(half) * nn for e, nn in zip(E, N)] + [u * np.sin(half)]
        N = N + [np.zeros(V)]
        owners.append((b, 0))
    for i in range(n):
        if i in per or (i in flips and E):
            continue
        rows.append(X[:, i] - c[i])
        owners.append((i, 0))
    Y = np.array(E + rows, dtype=np.float64).reshape(len(E) + len(rows), V)
    # (owners lists the nested rows first, in the order E holds them, then the axes kept)
    return Y, owners


def circle_matrix(P: np.ndarray, owners, spec) -> np.ndarray:
    """The (3, q) matrix that draws the rows of :func:`circle_rows` under the view ``P`` (3, n)."""
    P = np.asarray(P, dtype=np.float64)
    order = _order(spec)
    nxt = order[1] if len(order) > 1 else None
    cols = []
    for axis, turn in owners:
        if turn == -1:
            col = P[:, nxt] if nxt is not None else K @ P[:, axis]
        else:
            col = np.linalg.matrix_power(K, turn) @ P[:, axis]
        cols.append(col)
    return np.array(cols).T.reshape(3, len(owners))


class CircleProjector(Projector):
    """A :class:`gcmh_studio.projection.Projector` of "angles as circles": the rows of :func:`circle_rows`
    (centred once, as ``XT``), drawn by :func:`circle_matrix` of each view's linear part (the sliders turn
    it; a perspective or stereographic mapping is not applied on top)."""

    def __init__(self, vertices: np.ndarray, spec, center=None, dtype=np.float32):
        super().__init__(vertices, center=center, dtype=dtype)
        self.raw = np.asarray(vertices, dtype=np.float64)   # (what a plain projector is made of again)
        Y, self.owners = circle_rows(np.asarray(vertices, dtype=np.float64), spec, self.center)
        Y[~np.isfinite(Y)] = 0.0
        self.XT = np.ascontiguousarray(Y, dtype=dtype)
        self.spec = spec
        self._radii = None

    def project(self, P: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        return super().project(circle_matrix(P, self.owners, self.spec), out)

    def project_view(self, view: View, out: np.ndarray | None = None) -> np.ndarray:
        return self.project(view.P, out)


def seam_lines(cx) -> tuple[np.ndarray, np.ndarray]:
    """The glued seams of ``cx`` (a surface): ``(points (m, n), segments (E, 2))``.

    A 2-cell crossing the seam of axis p has edges from near ``lo`` to near ``hi``; each such edge meets the
    glued face where its low end, carried up a period (and reflected where the seam reverses axes), and its
    high end straddle ``hi``. The two crossings of a cell make one segment. The points are on the high side
    (where :func:`gcmh_studio.geometry.display_complex` draws the cells that cross)."""
    from .geometry import _proper_polygons

    spec = seam_spec(cx)
    n = int(cx.n)
    if not spec or cx.dim != 2:
        return np.zeros((0, n)), np.zeros((0, 2), np.int64)
    V = np.asarray(cx.vertices, dtype=np.float64)
    offsets, vids = _proper_polygons(*cx.polygons())
    points: list[np.ndarray] = []
    index: dict = {}
    segs: list[tuple[int, int]] = []
    for p, period, lo, flips, mirror in spec:
        hi = lo + period
        x = V[vids, p] if len(vids) else np.zeros(0)
        if not len(x):
            continue
        span = np.maximum.reduceat(x, offsets[:-1]) - np.minimum.reduceat(x, offsets[:-1])
        for c in np.flatnonzero(span > period / 2):
            loop = vids[offsets[c]:offsets[c + 1]].tolist()
            hits = []
            for a, b in zip(loop, loop[1:] + loop[:1]):
                if abs(V[a, p] - V[b, p]) <= period / 2:
                    continue
                key = (p, min(a, b), max(a, b))
                if key not in index:
                    low, high = (a, b) if V[a, p] < V[b, p] else (b, a)
                    q = V[low].copy()
                    q[p] += period
                    for f, m in zip(flips, mirror):
                        q[f] = m - q[f]
                    d = q[p] - V[high, p]
                    t = min(max((hi - V[high, p]) / d, 0.0), 1.0) if d > 0 else 0.5
                    index[key] = len(points)
                    points.append(V[high] + t * (q - V[high]))
                hits.append(index[key])
            for i in range(0, len(hits) - 1, 2):
                segs.append((hits[i], hits[i + 1]))
    if not segs:
        return np.zeros((0, n)), np.zeros((0, 2), np.int64)
    return np.array(points), np.array(segs, dtype=np.int64)


# ------------------------------------------------------------------ linkages
def linkage_joints(names, formulas) -> tuple[float, float] | None:
    """For a closed planar linkage of unit rods given by angles (the pentagon linkage): (x, y) of the fixed
    rod's far end, read from the system, or None when the system is not one.

    The system must be ``sum cos(a_i) - X = 0`` and ``sum sin(a_i) - Y = 0`` over all its variables
    (X, Y numbers): the rods start at (0, 0), point along the angles, and close at (X, Y)."""
    import sympy as sp

    if len(formulas) != 2 or len(names) < 2:
        return None
    try:
        syms = {nm: sp.Symbol(nm) for nm in names}
        exprs = [sp.sympify(str(f).replace("^", "**"), locals=syms) for f in formulas]
    except (sp.SympifyError, SyntaxError, TypeError):
        return None
    s = list(syms.values())
    want_c = sum(sp.cos(a) for a in s)
    want_s = sum(sp.sin(a) for a in s)
    close_x = sp.simplify(want_c - exprs[0])
    close_y = sp.simplify(want_s - exprs[1])
    if close_x.free_symbols or close_y.free_symbols:
        return None
    return float(close_x), float(close_y)


def linkage_points(angles) -> np.ndarray:
    """The joints (m + 1, 2) of unit rods from (0, 0) along ``angles`` (radians), end to end."""
    a = np.asarray(angles, dtype=float)
    steps = np.stack([np.cos(a), np.sin(a)], axis=1)
    return np.concatenate([np.zeros((1, 2)), np.cumsum(steps, axis=0)])


def circular_mean(values, period: float, lo: float) -> float:
    """The mean of angles ``values`` on a circle of ``period`` starting at ``lo`` (the middle of a small cell
    that crosses the seam is near the seam, not half a period away)."""
    t = 2 * np.pi * (np.asarray(values, dtype=float) - lo) / period
    m = np.arctan2(np.sin(t).mean(), np.cos(t).mean()) % (2 * np.pi)
    return float(lo + m * period / (2 * np.pi))


# ------------------------------------------------------------------ the View tab's switches
class AngleLook:
    """The View tab's "angles as circles" and "show the glued seam" of the window's model: its
    :class:`gcmh_studio.model.AngleView`, so that sessions and Undo keep them; ``changed`` tells the 3D view
    and the switches. One per model: :func:`angle_look`."""

    def __init__(self, model):
        self.model = model
        self.changed = model.events.angle_view

    @property
    def circles(self) -> bool:
        return self.model.angle_view.circles

    @property
    def seam(self) -> bool:
        return self.model.angle_view.seam

    def set(self, circles: bool | None = None, seam: bool | None = None) -> None:
        changes = {k: bool(v) for k, v in (("circles", circles), ("seam", seam)) if v is not None}
        self.model.set_angle_view(**changes)


def angle_look(model) -> AngleLook:
    """The :class:`AngleLook` of ``model`` (a StudioModel), made at the first call."""
    look = getattr(model, "_angle_look", None)
    if look is None:
        look = AngleLook(model)
        model._angle_look = look
    return look
