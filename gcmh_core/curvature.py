"""Discrete Gaussian curvature of a surface in any R^n, and the Gauss-Bonnet sum.

A surface (dim 2) of a GCMH result has polygons for 2-cells, not always planar in R^n.
Each polygon is coned from the mean of its vertices into triangles; the curvature at a
vertex is its angle defect 2pi - (sum of the triangles' angles there), the apex's own
defect (zero for a planar convex polygon) shared equally by the polygon's vertices.  At
a boundary vertex (on an edge with one polygon) pi - (angle sum) is the boundary's
turning (geodesic curvature) instead.  Then, exactly as for a smooth surface,

    (total curvature + boundary turning) / 2pi = chi

(discrete Gauss-Bonnet: the angles of T triangles add up to pi T).  The curvature density
(defect over a third of the vertex's triangles' area) is what a colour map shows.

>>> from gcmh_core import extract
>>> cx = extract("x^2 + y^2 + z^2 - 1", bounds=(-1.5, 1.5), div=6, variables="x, y, z")
>>> round(gauss_bonnet(cx).sum, 9), cx.euler_characteristic()
(2.0, 2)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .complex import CellComplex
from .errors import InputError

__all__ = ["Curvature", "GaussBonnet", "gauss_bonnet", "gaussian_curvature"]


@dataclass(frozen=True, eq=False)
class Curvature:
    """Per-vertex discrete curvature of a surface.

    Attributes
    ----------
    defect : (V,) float64
        Angle defect (radians): 2pi - angle sum at interior vertices, plus each polygon's
        apex defect shared among its vertices; 0 where a vertex is on no polygon.
    turning : (V,) float64
        pi - angle sum at boundary vertices (the boundary's geodesic turning), else 0.
    area : (V,) float64
        The vertex's share of the coned triangles' area (half of each triangle at it).
    boundary : (V,) bool
        Vertices on a boundary edge.
    """

    defect: np.ndarray
    turning: np.ndarray
    area: np.ndarray
    boundary: np.ndarray

    @property
    def density(self) -> np.ndarray:
        """(V,) float64: Gaussian curvature, defect / area (0 where the area is 0)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            k = self.defect / self.area
        k[~np.isfinite(k)] = 0.0
        return k


@dataclass(frozen=True)
class GaussBonnet:
    """Total curvature and boundary turning, both divided by 2pi, next to chi."""

    curvature: float
    turning: float
    euler_characteristic: int

    @property
    def sum(self) -> float:
        """(total curvature + boundary turning) / 2pi: chi for a surface."""
        return self.curvature + self.turning

    def describe(self) -> str:
        """``"Gauss-Bonnet: (K + k_g) / 2pi = 0.000 + 1.000 = 1.000, chi = 1"``."""
        k, t, s = (_fixed(x) for x in (self.curvature, self.turning, self.sum))
        if self.turning == 0.0:
            return f"Gauss-Bonnet: K / 2pi = {k}, chi = {self.euler_characteristic}"
        return f"Gauss-Bonnet: (K + k_g) / 2pi = {k} + {t} = {s}, chi = {self.euler_characteristic}"


def _fixed(x):
    return f"{round(x, 3) + 0.0:.3f}"  # + 0.0: no "-0.000"


def _check(cx, what):
    if not isinstance(cx, CellComplex):
        raise InputError(f"{what} needs a CellComplex, got {type(cx).__name__}")
    if cx.dim != 2:
        raise InputError(f"{what} is defined on surfaces (n - k = 2); this complex has dimension {cx.dim}")


def gaussian_curvature(cx: CellComplex) -> Curvature:
    """Discrete Gaussian curvature at each vertex of a surface `cx` (dim 2) in R^n."""
    _check(cx, "gaussian_curvature")
    return _curvature(cx)


def gauss_bonnet(cx: CellComplex) -> GaussBonnet:
    """Total curvature / 2pi and boundary turning / 2pi of a surface, and its chi."""
    _check(cx, "gauss_bonnet")
    c = _curvature(cx)
    two_pi = 2.0 * np.pi
    return GaussBonnet(float(c.defect.sum() / two_pi), float(c.turning.sum() / two_pi),
                       int(cx.euler_characteristic()))


def _angle(a, b):
    """Angles between the rows of a and b (any dimension), stable near 0 and pi."""
    na = np.linalg.norm(a, axis=1)
    nb = np.linalg.norm(b, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ua, ub = a / na[:, None], b / nb[:, None]
        ang = 2.0 * np.arctan2(np.linalg.norm(ua - ub, axis=1), np.linalg.norm(ua + ub, axis=1))
    return np.nan_to_num(ang)


def _curvature(cx):
    X = np.asarray(cx.vertices)
    nv = X.shape[0]
    off, loop = cx.polygons()
    off = np.asarray(off)
    loop = np.asarray(loop)
    sizes = np.diff(off)
    owner = np.repeat(np.arange(sizes.size), sizes)
    nxt = np.arange(1, loop.size + 1)
    ends = off[1:][sizes > 0] - 1
    nxt[ends] = off[:-1][sizes > 0]
    u, v = loop, loop[nxt]  # the cone triangles (apex of owner, u, v)
    apex = np.zeros((sizes.size, X.shape[1]))
    np.add.at(apex, owner, X[loop])
    with np.errstate(invalid="ignore", divide="ignore"):
        apex /= np.maximum(sizes, 1)[:, None]
    A, U, V = apex[owner], X[u], X[v]
    at_u = _angle(A - U, V - U)
    at_v = _angle(A - V, U - V)
    at_apex = _angle(U - A, V - A)
    angle_sum = np.bincount(u, at_u, minlength=nv) + np.bincount(v, at_v, minlength=nv)
    on_polygon = np.bincount(loop, minlength=nv) > 0
    # the boundary: edges with exactly one polygon on them
    cof = cx.facet_cofaces()
    boundary = np.zeros(nv, dtype=bool)
    boundary[np.asarray(cx.edges)[cof == 1].ravel()] = True
    defect = np.where(on_polygon & ~boundary, 2.0 * np.pi - angle_sum, 0.0)
    turning = np.where(boundary, np.pi - angle_sum, 0.0)
    apex_defect = 2.0 * np.pi - np.bincount(owner, at_apex, minlength=sizes.size)
    share = np.where(sizes > 0, apex_defect / np.maximum(sizes, 1), 0.0)
    defect += np.bincount(loop, share[owner], minlength=nv)
    # triangle areas, half to each of its two polygon vertices
    au, av = np.linalg.norm(A - U, axis=1), np.linalg.norm(V - U, axis=1)
    tri = 0.5 * au * av * np.sin(at_u)
    area = 0.5 * (np.bincount(u, tri, minlength=nv) + np.bincount(v, tri, minlength=nv))
    return Curvature(defect=defect, turning=turning, area=area, boundary=boundary)
