"""Geometry of a CellComplex for drawing, in numpy only (no Qt, no VTK): safe in the worker thread.

:class:`Geometry` holds what the viewer needs to draw a result and to redraw it
quickly under any projection: the VTK-style cell array (lines for curves,
polygons for surfaces and 2-skeletons), the centred float32 vertices
(:class:`gcmh_studio.projection.Projector`) and, for surfaces, a :class:`NormalField`.

Smooth shading of a projected surface: the area-weighted normal of a triangle
(a, b) after projection is ``Pa x Pb = sum_{i<j} (a_i b_j - a_j b_i) (P_i x P_j)``
(``P_i`` = column i of ``P``), linear in the bivector ``a ^ b``. So each vertex
keeps the sum of its faces' bivectors in R^n (computed once, from polygons
oriented coherently by gcmh_core.analysis.orient_2cells; where a surface is not orientable the signs are
also aligned with one neighbour), and a slider step gets every vertex normal
with one more small matmul.

That identity needs a linear projection. Under a nonlinear one (perspective,
stereographic) :class:`MeshNormals` computes the normals from the projected
points instead: polygon area vectors summed at their vertices with the same
per-corner signs, in one compiled (numba) pass over the corners.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .projection import Projector, planes


def polygon_faces(offsets: np.ndarray, vids: np.ndarray) -> np.ndarray:
    """VTK legacy face array ``[m0, v.., m1, v.., ...]`` from a CSR list of loops."""
    offsets = np.asarray(offsets, dtype=np.int64)
    vids = np.asarray(vids, dtype=np.int64)
    sizes = np.diff(offsets)
    N = len(sizes)
    out = np.empty(len(vids) + N, dtype=np.int64)
    heads = offsets[:-1] + np.arange(N)
    out[heads] = sizes
    mask = np.ones(len(out), dtype=bool)
    mask[heads] = False
    out[mask] = vids
    return out


def _proper_polygons(offsets, vids):
    """Drop loops with fewer than 3 vertices (degenerate 2-cells can't be drawn as polygons)."""
    offsets = np.asarray(offsets, dtype=np.int64)
    vids = np.asarray(vids, dtype=np.int64)
    sizes = np.diff(offsets)
    if len(sizes) == 0 or sizes.min() >= 3:
        return offsets, vids
    keep = sizes >= 3
    vids = vids[np.repeat(keep, sizes)]
    offsets = np.concatenate([[0], np.cumsum(sizes[keep])])
    return offsets, vids


def _wedge(a: np.ndarray, b: np.ndarray, pairs) -> np.ndarray:
    """Bivector components ``a_i b_j - a_j b_i`` for each pair (i, j): (m, len(pairs))."""
    ii = np.array([p[0] for p in pairs], dtype=np.int64)
    jj = np.array([p[1] for p in pairs], dtype=np.int64)
    return a[:, ii] * b[:, jj] - a[:, jj] * b[:, ii]


def oriented_loops(cx, offsets, vids, cell_ids) -> np.ndarray:
    """The 2-cells' loops (``offsets``, ``vids`` for cells ``cell_ids``) coherently oriented
    by ``gcmh_core.analysis.orient_2cells`` (one orientation for the whole project)."""
    from gcmh_core.analysis import orient_2cells

    o = orient_2cells(cx)
    oo, ov = np.asarray(o.offsets, dtype=np.int64), np.asarray(o.vertices, dtype=np.int64)
    sz = np.diff(oo)[cell_ids]
    if not np.array_equal(sz, np.diff(offsets)):
        raise ValueError("the loops to orient are not the complex's 2-cells")
    first = np.cumsum(sz) - sz
    take = np.repeat(oo[cell_ids] - first, sz) + np.arange(int(sz.sum()))
    return ov[take]


def vertex_bivectors(vertices: np.ndarray, offsets: np.ndarray, vids: np.ndarray, return_signs: bool = False):
    """Per-vertex sum of the area bivectors of its polygons (V, n(n-1)/2) float64.

    Pass loops oriented by :func:`oriented_loops`; where orientation fails (a
    non-orientable seam) each face's sign is also aligned with one reference
    face at the vertex, so normals never cancel. Order of components: planes().
    With ``return_signs``, also the (corners,) float64 sign used at each corner.
    """
    X = np.asarray(vertices, dtype=np.float64)
    V, n = X.shape
    pairs = planes(n)
    m = len(pairs)
    offsets = np.asarray(offsets, dtype=np.int64)
    vids = np.asarray(vids, dtype=np.int64)
    N = len(offsets) - 1
    if N == 0 or m == 0:
        Bv = np.zeros((V, m))
        return (Bv, np.ones(len(vids))) if return_signs else Bv
    sizes = np.diff(offsets)
    face_of = np.repeat(np.arange(N), sizes)
    pos = np.arange(len(vids))
    nxt = pos + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    Xf = np.where(np.isfinite(X), X, 0.0)
    csum = np.add.reduceat(Xf[vids], offsets[:-1], axis=0)
    cent = csum / np.maximum(sizes, 1)[:, None]
    a = Xf[vids] - cent[face_of]                      # (corners, n), column by column below
    b = Xf[vids[nxt]] - cent[face_of]
    aT = np.ascontiguousarray(a.T)
    bT = np.ascontiguousarray(b.T)
    del a, b
    Bf = np.empty((N, m))                             # face bivectors, one plane at a time (little memory)
    for c, (i, j) in enumerate(pairs):
        w = aT[i] * bT[j]
        w -= aT[j] * bT[i]
        Bf[:, c] = 0.5 * np.add.reduceat(w, offsets[:-1])
    del aT, bT
    ref_face = np.full(V, -1, dtype=np.int64)
    ref_face[vids[::-1]] = face_of[::-1]              # first incident face wins
    BfT = np.ascontiguousarray(Bf.T)
    ref = ref_face[vids]
    dot = np.zeros(len(vids))                         # <face bivector, reference bivector> per corner
    for c in range(m):
        dot += BfT[c][face_of] * BfT[c][ref]
    s = np.sign(dot)
    s[s == 0] = 1.0
    Bv = np.zeros((V, m))
    for c in range(m):
        Bv[:, c] = np.bincount(vids, weights=s * BfT[c][face_of], minlength=V)
    return (Bv, s) if return_signs else Bv


def cross_table(P: np.ndarray) -> np.ndarray:
    """(m, 3) rows ``P_i x P_j`` for the planes (i, j) of R^n; P is (3, n)."""
    n = P.shape[1]
    pairs = planes(n)
    if not pairs:
        return np.zeros((0, 3))
    ii = [p[0] for p in pairs]
    jj = [p[1] for p in pairs]
    return np.cross(P[:, ii].T, P[:, jj].T)


def tangent_pair(Bv: np.ndarray, n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Two tangent vectors (V, n) per vertex with ``t1 ^ t2`` = the bivector ``Bv`` when it is simple.

    With M the antisymmetric matrix of B and any vector a: u = M a and w = M u
    lie in B's plane and ``B = -(u ^ w) / |u|^2``. A surface's summed bivector
    is nearly simple, so this is accurate; it lets normals be computed with two
    (3, n) projections instead of n(n-1)/2 components. Rows of Bv that are 0
    give zero tangents.
    """
    pairs = planes(n)
    V = len(Bv)
    BT = np.ascontiguousarray(Bv.T)

    def apply(x):  # M x per vertex, M_ij = B_ij (i<j), M_ji = -B_ij; x and the result are (n, V)
        y = np.zeros((n, V))
        for c, (i, j) in enumerate(pairs):
            y[i] += BT[c] * x[j]
            y[j] -= BT[c] * x[i]
        return y

    best_u = np.zeros((n, V))
    best_norm = np.zeros(V)
    rng = np.random.default_rng(seed)
    for _ in range(3):  # a few probe vectors: keep the one with the largest |M a|
        a = rng.standard_normal(n)
        u = np.zeros((n, V))
        for c, (i, j) in enumerate(pairs):
            u[i] += BT[c] * a[j]
            u[j] -= BT[c] * a[i]
        nu = np.einsum("iv,iv->v", u, u)
        better = nu > best_norm
        best_u[:, better] = u[:, better]
        best_norm[better] = nu[better]
    w = apply(best_u)
    with np.errstate(divide="ignore", invalid="ignore"):
        t2 = np.where(best_norm > 0, -w / best_norm, 0.0)
    return best_u.T, t2.T


class NormalField:
    """Vertex normals of the projected surface for any projection P, fast.

    n <= 5: exact, ``N = Bv @ cross_table(P)`` (m = n(n-1)/2 <= 10 columns).
    n > 5: ``N = (P t1) x (P t2)`` with the tangent pair of :func:`tangent_pair`.
    Arrays are stored transposed (components, V) float32 for wide matmuls.
    """

    def __init__(self, Bv: np.ndarray, n: int):
        self.n = n
        V = len(Bv)
        if n <= 5:
            self.mode = "bivector"
            self.BT = np.ascontiguousarray(Bv.T, dtype=np.float32)
        else:
            self.mode = "tangents"
            t1, t2 = tangent_pair(Bv, n)
            self.T1 = np.ascontiguousarray(t1.T, dtype=np.float32)
            self.T2 = np.ascontiguousarray(t2.T, dtype=np.float32)
            self._a = np.empty((3, V), dtype=np.float32)
            self._b = np.empty((3, V), dtype=np.float32)
            self._t = np.empty(V, dtype=np.float32)

    def write(self, P: np.ndarray, out: np.ndarray) -> None:
        """Write (V, 3) normals for projection P (3, n) into ``out`` (C-contiguous float32)."""
        oT = out.T
        if self.mode == "bivector":
            C = cross_table(np.asarray(P, dtype=np.float64)).astype(np.float32)
            np.matmul(C.T, self.BT, out=oT)
            return
        P32 = np.asarray(P, dtype=np.float32)
        a, b, t = self._a, self._b, self._t
        np.matmul(P32, self.T1, out=a)
        np.matmul(P32, self.T2, out=b)
        for r, (i, j) in enumerate(((1, 2), (2, 0), (0, 1))):
            np.multiply(a[i], b[j], out=oT[r])
            np.multiply(a[j], b[i], out=t)
            np.subtract(oT[r], t, out=oT[r])


def _mesh_normals_py(pts, offsets, vids, sgn, out):
    """Per face: its normal, relative to its first corner (sum of (p_i - p_0) x (p_i+1 - p_0)),
    added with the corner's sign to each of its vertices."""
    out[:] = 0.0
    for f in range(len(offsets) - 1):
        a = offsets[f]
        b = offsets[f + 1]
        p0 = vids[a]
        ox, oy, oz = pts[p0, 0], pts[p0, 1], pts[p0, 2]
        nx = 0.0
        ny = 0.0
        nz = 0.0
        for i in range(a + 1, b - 1):
            p = vids[i]
            q = vids[i + 1]
            ux, uy, uz = pts[p, 0] - ox, pts[p, 1] - oy, pts[p, 2] - oz
            wx, wy, wz = pts[q, 0] - ox, pts[q, 1] - oy, pts[q, 2] - oz
            nx += uy * wz - uz * wy
            ny += uz * wx - ux * wz
            nz += ux * wy - uy * wx
        for i in range(a, b):
            v = vids[i]
            s = sgn[i]
            out[v, 0] += s * nx
            out[v, 1] += s * ny
            out[v, 2] += s * nz


_MESH_NORMALS: Callable[..., Any] | None = None


def _mesh_normals_kernel():
    global _MESH_NORMALS
    if _MESH_NORMALS is None:
        try:
            from numba import njit
            _MESH_NORMALS = njit(cache=True, nogil=True)(_mesh_normals_py)
        except ImportError:  # pragma: no cover - numba is a dependency of gcmh_core
            _MESH_NORMALS = _mesh_normals_py
    return _MESH_NORMALS


class MeshNormals:
    """Vertex normals computed from projected points (for nonlinear views): one compiled pass over the corners.

    Each polygon's normal (a fan from its first corner: exact area vector of a
    planar polygon) is added to its vertices with the corner's sign, the sign
    that aligns it with the vertex's reference face in R^n (as for the
    bivectors), so a non-orientable seam does not cancel.
    """

    def __init__(self, offsets: np.ndarray, vids: np.ndarray, n_vertices: int, signs: np.ndarray | None = None):
        self.offsets = np.ascontiguousarray(offsets, dtype=np.int64)
        self.vids = np.ascontiguousarray(vids, dtype=np.int64)
        self.V = int(n_vertices)
        self.signs = (np.ones(len(self.vids), dtype=np.float32) if signs is None
                      else np.ascontiguousarray(signs, dtype=np.float32))

    def write(self, pts: np.ndarray, out: np.ndarray) -> None:
        """(V, 3) normals of the mesh with points ``pts`` (V, 3) into ``out`` (V, 3)."""
        _mesh_normals_kernel()(pts, self.offsets, self.vids, self.signs, out)


@dataclass
class Geometry:
    """Everything to draw ``cx`` under any projection (built once per result).

    dim: the complex's dimension; kind: "lines" or "polygons";
    cells: VTK legacy cell array (``[2, a, b, ...]`` or ``[m, v0..v(m-1), ...]``) int64;
    projector: centred float32 vertices; normals: a NormalField for surfaces, else None;
    offsets, vids: the drawn polygons as oriented CSR loops (None for lines), edges (E, 2) for lines;
    cell_ids: per drawn cell, its index among the complex's 2-cells (or edges).
    """

    dim: int
    n: int
    kind: str
    cells: np.ndarray
    projector: Projector
    normals: NormalField | None = None
    offsets: np.ndarray | None = None
    vids: np.ndarray | None = None
    edges: np.ndarray | None = None
    cell_ids: np.ndarray | None = None
    signs: np.ndarray | None = None
    coarse: Geometry | None = None      # a coarse level of detail of a very large result (drawn while moving)
    _mesh_normals: MeshNormals | None = None

    def mesh_normals(self) -> MeshNormals | None:
        """Normals from projected points (for nonlinear views); None for lines."""
        if self.kind != "polygons" or self.normals is None:
            return None
        if self._mesh_normals is None:
            assert self.offsets is not None and self.vids is not None   # (polygons have their loops)
            self._mesh_normals = MeshNormals(self.offsets, self.vids, self.projector.XT.shape[1], self.signs)
        return self._mesh_normals

    @classmethod
    def from_slice(cls, sl, dim: int, n: int, center, radii, cell_ids=None) -> Geometry:
        """Drawing arrays of an :class:`gcmh_studio.slicing.Slice` of a geometry (its loops stay oriented).

        ``center`` and ``radii`` are the full complex's, so the slice does not move.
        """
        projector = Projector(sl.vertices, center=center)
        projector.set_radii(radii)
        ids = sl.cell_source if cell_ids is None else np.asarray(cell_ids)[sl.cell_source]
        if sl.edges is not None:
            lines = np.empty((len(sl.edges), 3), dtype=np.int64)
            lines[:, 0] = 2
            lines[:, 1:] = sl.edges
            return cls(dim, n, "lines", lines.ravel(), projector, edges=sl.edges, cell_ids=ids)
        normals = signs = None
        if dim == 2 and len(sl.vids):
            Bv, signs = vertex_bivectors(sl.vertices, sl.offsets, sl.vids, return_signs=True)
            normals = NormalField(Bv, n)
        return cls(dim, n, "polygons", polygon_faces(sl.offsets, sl.vids), projector, normals,
                   offsets=sl.offsets, vids=sl.vids, cell_ids=ids, signs=signs)

    @classmethod
    def build(cls, cx, lod: bool = True) -> Geometry:
        """Drawing arrays of ``cx`` (as :func:`display_complex` draws it: seams of identified axes
        whole; ``cell_ids`` are ``cx``'s own); with ``lod``, above ``LOD_VERTICES`` vertices also a
        coarse copy."""
        cx = display_complex(cx)
        geo = cls._build(cx)
        V = len(np.asarray(cx.vertices))
        if lod and V > LOD_VERTICES:
            geo.coarse = coarse_geometry(geo, np.asarray(cx.vertices), LOD_TARGET)
        elif lod and geo.dim >= 3 and geo.offsets is not None and len(geo.offsets) - 1 > LOD_SKELETON_CELLS:
            # a see-through 2-skeleton is drawn in many layers: software GL pays for every layer's pixels
            geo.coarse = coarse_geometry(geo, np.asarray(cx.vertices), max(V // 8, 500))
        return geo

    @classmethod
    def _build(cls, cx) -> Geometry:
        V = np.asarray(cx.vertices)
        dim = int(cx.dim)
        projector = Projector(V)
        if dim <= 1:
            edges = np.asarray(cx.edges, dtype=np.int64).reshape(-1, 2)
            lines = np.empty((len(edges), 3), dtype=np.int64)
            lines[:, 0] = 2
            lines[:, 1:] = edges
            return cls(dim, cx.n, "lines", lines.ravel(), projector, edges=edges,
                       cell_ids=np.arange(len(edges), dtype=np.int64))
        offsets0, vids0 = cx.polygons()
        cell_ids = np.flatnonzero(np.diff(np.asarray(offsets0)) >= 3)
        offsets, vids = _proper_polygons(offsets0, vids0)
        normals = signs = None
        if dim == 2:
            vids = oriented_loops(cx, offsets, vids, cell_ids)
            if len(vids):
                Bv, signs = vertex_bivectors(V, offsets, vids, return_signs=True)
                normals = NormalField(Bv, cx.n)
        source = cx.meta.get("display_source")
        if source is not None:  # (a seam's copies name the cell they show)
            cell_ids = np.asarray(source, np.int64)[cell_ids]
        return cls(dim, cx.n, "polygons", polygon_faces(offsets, vids), projector, normals,
                   offsets=offsets, vids=vids, cell_ids=cell_ids, signs=signs)


LOD_VERTICES = 150_000    # above this a result also gets a coarse level of detail ...
LOD_TARGET = 30_000       # ... of about this many vertices
LOD_SKELETON_CELLS = 60_000  # a 2-skeleton (dim >= 3) with more 2-cells gets one of an eighth of its vertices
# (below it, the full see-through mesh under one headlight moves as fast and keeps its cells' edges, which the
# coarse copy blurs: the three-torus at its div, 27,648 cells)


def row_ids(key: np.ndarray) -> np.ndarray:
    """Dense ids (0..m-1) of the distinct rows of ``key`` (N, n) int64, numbered in the rows' lexicographic
    order: ``np.unique(key, axis=0, return_inverse=True)[1]``, by sorts of one int64 column. (np.unique
    over rows sorts a void dtype and holds the GIL the whole time: the GUI thread stalled 0.25 s while
    the worker made the coarse copy of a large result.)"""
    key = np.asarray(key, dtype=np.int64)
    if key.ndim != 2 or len(key) == 0:
        return np.zeros(len(key), dtype=np.int64)
    key = key - key.min(axis=0)            # (a shift per column keeps the order)
    acc = np.zeros(len(key), dtype=np.int64)
    top = 1                                # acc < top
    for j in range(key.shape[1]):
        r = int(key[:, j].max()) + 1
        if top * r >= 2**62:               # would overflow: renumber what is there densely first
            _, acc = np.unique(acc, return_inverse=True)
            acc = acc.ravel().astype(np.int64)
            top = int(acc.max()) + 1
        acc = acc * r + key[:, j]
        top *= r
    _, ids = np.unique(acc, return_inverse=True)
    return ids.ravel().astype(np.int64)


def coarse_geometry(geo: Geometry, V: np.ndarray, target: int = LOD_TARGET) -> Geometry:
    """A coarse copy of ``geo`` (vertices ``V`` (V, n)) by vertex clustering in R^n: vertices in one cube
    of side h merge into their mean, loops keep the corners that remain distinct (those with fewer than
    three, and edges with one, vanish). Clustering in R^n, not on screen, makes it valid for every
    projection, so it is made once, in the worker, like the full arrays."""
    X = np.asarray(V, dtype=np.float64)
    fin = np.all(np.isfinite(X), axis=1)
    Xf = np.where(fin[:, None], X, 0.0)
    dim = max(1, min(int(geo.dim), 2))
    lo = Xf[fin].min(axis=0) if fin.any() else np.zeros(X.shape[1])
    span = np.ptp(Xf[fin], axis=0) if fin.any() else np.ones(X.shape[1])
    # the clusters of a d-manifold grow like h^-d: start from the mean spacing, correct once by the count
    h = float(np.linalg.norm(span)) / max(len(X), 1) ** (1.0 / dim) * (len(X) / max(target, 1)) ** (1.0 / dim)
    for _ in range(3):
        key = np.floor((Xf - lo) / max(h, 1e-300)).astype(np.int64)
        cid = row_ids(key)
        m = int(cid.max()) + 1
        if m <= 1.5 * target:
            break
        h *= (m / target) ** (1.0 / dim)
    cnt = np.bincount(cid, minlength=m).astype(np.float64)
    C = np.stack([np.bincount(cid, weights=Xf[:, j], minlength=m) for j in range(X.shape[1])], 1) / cnt[:, None]
    center = geo.projector.center
    if geo.kind == "lines":
        E = cid[np.asarray(geo.edges, dtype=np.int64)]
        E = E[E[:, 0] != E[:, 1]]
        E = np.unique(np.sort(E, axis=1), axis=0)
        lines = np.empty((len(E), 3), dtype=np.int64)
        lines[:, 0] = 2
        lines[:, 1:] = E
        pr = Projector(C, center=center)
        pr.set_radii(geo.projector.radii())
        return Geometry(geo.dim, geo.n, "lines", lines.ravel(), pr, edges=E)
    offsets = np.asarray(geo.offsets, dtype=np.int64)
    vids = cid[np.asarray(geo.vids, dtype=np.int64)]
    sizes = np.diff(offsets)
    nxt = np.arange(1, len(vids) + 1)
    nxt[offsets[1:] - 1] = offsets[:-1]
    keep = vids != vids[nxt]                          # drop a corner equal to the next one
    face_of = np.repeat(np.arange(len(sizes)), sizes)
    new_sizes = np.bincount(face_of[keep], minlength=len(sizes))
    good = new_sizes >= 3
    keep &= good[face_of]
    vids = vids[keep]
    offsets = np.concatenate([[0], np.cumsum(new_sizes[good])]).astype(np.int64)
    pr = Projector(C, center=center)
    pr.set_radii(geo.projector.radii())
    normals = signs = None
    if geo.normals is not None and len(vids):
        Bv, signs = vertex_bivectors(C, offsets, vids, return_signs=True)
        normals = NormalField(Bv, geo.n)
    return Geometry(geo.dim, geo.n, "polygons", polygon_faces(offsets, vids), pr, normals,
                    offsets=offsets, vids=vids, signs=signs)


# ---------------------------------------------------------------------- overlays and picking (numpy only)
def boundary_lines(cx):
    """The boundary facets of ``cx`` as segments in R^n: (vertices (m, n), edges (E, 2)).

    Surfaces: the boundary edges; higher dimensions: the edges of the boundary
    2-cells (dim 3) -- for curves the boundary is points, drawn as nothing.
    """
    V = np.asarray(cx.vertices)
    empty = (np.zeros((0, V.shape[1])), np.zeros((0, 2), np.int64))
    if cx.dim < 2:
        return empty
    ids = np.asarray(cx.boundary_facets(), dtype=np.int64)
    if len(ids) == 0:
        return empty
    if cx.dim == 2:
        E = np.asarray(cx.edges, dtype=np.int64).reshape(-1, 2)[ids]
    elif cx.dim == 3:
        off, vids = (np.asarray(a, dtype=np.int64) for a in cx.polygons())
        sizes = np.diff(off)
        pick = np.repeat(np.isin(np.arange(len(sizes)), ids), sizes)
        nxt = np.arange(1, len(vids) + 1)
        nxt[off[1:] - 1] = off[:-1]
        E = np.stack([vids[pick], vids[nxt][pick]], 1)
    else:
        return empty
    used, inv = np.unique(E, return_inverse=True)
    return V[used], inv.reshape(-1, 2)


def _grid_of(cx):
    b = cx.meta.get("bounds")
    d = cx.meta.get("div")
    if b is None or d is None:
        raise ValueError("this result does not say its grid (bounds, div)")
    lo = np.array([float(x[0]) for x in b])
    hi = np.array([float(x[1]) for x in b])
    div = np.array(d if np.ndim(d) else [d] * cx.n, dtype=np.int64)
    return lo, (hi - lo) / div, div


def cell_cubes(cx, X):
    """Grid cube (n,) int64 of each point of ``X`` (centroids of cells) from the result's bounds and div."""
    lo, h, div = _grid_of(cx)
    q = np.floor((np.asarray(X) - lo) / h).astype(np.int64)
    return np.clip(q, 0, div - 1)


def cell_info(cx, cell: int) -> dict:
    """Facts about a 2-cell (or a curve's edge): its vertex ids, their coordinates, its grid cube, its outline."""
    V = np.asarray(cx.vertices)
    if cx.dim == 1:
        E = np.asarray(cx.edges, dtype=np.int64).reshape(-1, 2)
        if not 0 <= cell < len(E):
            raise ValueError(f"no edge {cell} (the curve has {len(E)})")
        vs = E[cell]
    else:
        off, vids = cx.polygons()
        if not 0 <= cell < len(off) - 1:
            raise ValueError(f"no 2-cell {cell} (the result has {len(off) - 1})")
        vs = np.asarray(vids[off[cell]:off[cell + 1]], dtype=np.int64)
    coords = V[vs]
    try:
        cube = cell_cubes(cx, coords.mean(axis=0)[None])[0]
    except ValueError:
        cube = None
    m = len(vs)
    edges = np.stack([np.arange(m), (np.arange(m) + 1) % m], 1) if m > 2 else np.array([[0, 1]])
    return dict(cell=int(cell), vertices=vs, coords=coords, cube=cube, lines=(coords, edges))


GRID_EDGE_LIMIT = 400_000


def grid_cube_lines(cx):
    """Edges of the grid cubes the result passes through, as segments in R^n: (corners (m, n), edges (E, 2)).

    After continuation these are the cubes it processed (``cx.processed_cubes``, its
    path: M_A's cubes and the neighbours it looked at); otherwise (a full sweep, or a
    complex loaded from a file) the cubes holding the centroid of a top-dimensional
    cell, i.e. the cubes M_A passes through. Corners are the unperturbed grid points.
    """
    lo, h, div = _grid_of(cx)
    n = cx.n
    dim = cx.dim
    V = np.asarray(cx.vertices)
    if getattr(cx, "processed_cubes", None) is not None:
        cubes = np.asarray(cx.processed_cubes, dtype=np.int64).reshape(-1, n)
    else:
        if dim == 1:
            E = np.asarray(cx.edges, dtype=np.int64).reshape(-1, 2)
            cent = 0.5 * (V[E[:, 0]] + V[E[:, 1]])
        else:
            off, vids = (np.asarray(a, dtype=np.int64) for a in cx.cell_vertices(dim))
            sizes = np.maximum(np.diff(off), 1)
            cent = np.add.reduceat(V[vids], off[:-1], axis=0) / sizes[:, None] if len(vids) else np.zeros((0, n))
        cubes = np.unique(cell_cubes(cx, cent), axis=0)
    per = n * 2 ** (n - 1)
    if len(cubes) * per > GRID_EDGE_LIMIT:
        raise ValueError(f"{len(cubes):,} cubes with {per} edges each are too many to draw; use a smaller div")
    # every edge: a corner g (n,) and an axis a with the corner's bit a = 0
    bits = (np.arange(2 ** n)[:, None] >> np.arange(n)) & 1                        # (2^n, n)
    starts, axes = [], []
    for a in range(n):
        b = bits[bits[:, a] == 0]
        starts.append((cubes[:, None, :] + b[None]).reshape(-1, n))
        axes.append(np.full(len(cubes) * len(b), a))
    g = np.concatenate(starts)
    ax = np.concatenate(axes)
    key = np.concatenate([g, ax[:, None]], 1)
    key = np.unique(key, axis=0)
    g, ax = key[:, :n], key[:, n]
    g2 = g.copy()
    g2[np.arange(len(g2)), ax] += 1
    pts, inv = np.unique(np.concatenate([g, g2]), axis=0, return_inverse=True)
    inv = inv.ravel()
    E = np.stack([inv[:len(g)], inv[len(g):]], 1)
    return lo + pts * h, E


# ---------------------------------------------------------------- seams of identified axes
def display_complex(cx):
    """``cx`` as it is drawn: itself, or for a surface on a domain with identified axes
    (``cx.meta["periodic"]``, e.g. ["s:flip=t", "t"]) a copy in which every 2-cell that
    crosses a seam is drawn whole on its high side.

    Such a cell has vertices at both ends of the periodic axis: drawn as it is, it would be
    stretched across the whole box (projected along that axis) and painted through the
    whole colour range (coloured by it). In the copy its low vertices are moved up by the
    period (and reflected across a flipped seam), next to its neighbours on the high side
    (the picture then reaches a cell past the box there and stops a cell short of the low side).
    ``meta["display_source"]``: each 2-cell's cell in ``cx``. The topology is ``cx``'s: this
    copy is for the eye only. Cached on ``cx``.
    """
    cache = getattr(cx, "_cache", None)
    key = ("display_complex",)
    if cache is not None and key in cache:
        return cache[key]
    out = _unwrapped_seams(cx)
    if cache is not None:
        cache[key] = out
    return out


def seam_spec(cx):
    """[(axis, period, lo, (flipped axes), (their lo + hi))] of ``cx.meta`` (read by the engine's own
    `as_periodic`), or [] when it names no identified axes."""
    from gcmh_core._validate import as_periodic
    from gcmh_core.errors import InputError

    meta = getattr(cx, "meta", None) or {}
    items, names, bounds, div = meta.get("periodic"), meta.get("variables"), meta.get("bounds"), meta.get("div")
    if not items or not names or bounds is None or div is None:
        return []
    try:
        spec = as_periodic(items, names, div)
    except InputError:  # (meta that did not come from a run: draw the complex as it is)
        return []
    bounds = np.asarray(bounds, dtype=float)
    return [(p, bounds[p, 1] - bounds[p, 0], bounds[p, 0], flips, tuple(bounds[b].sum() for b in flips))
            for p, flips in spec]


def _unwrapped_seams(cx):
    from gcmh_core import CellComplex

    spec = seam_spec(cx)
    if not spec or cx.dim != 2:
        return cx
    V = np.asarray(cx.vertices, dtype=np.float64)
    offsets, vids = _proper_polygons(*cx.polygons())
    sizes = np.diff(offsets)
    seam = np.zeros(len(sizes), bool)
    for p, period, _, _, _ in spec:
        x = V[vids, p]
        span = np.maximum.reduceat(x, offsets[:-1]) - np.minimum.reduceat(x, offsets[:-1]) if len(x) else x
        seam |= span > period / 2
    if not seam.any():
        return cx
    # every seam cell moved whole to the high side of each seam it crosses: its low vertices up a period (a
    # vertex keeps one id per move, so neighbouring cells share it).  (A copy on each side left two
    # coincident copies, coloured apart, where the periodic axis is not one of the three shown.)
    extra_pts: list[np.ndarray] = []
    moved: dict = {}
    loops, sources = [], []
    for c in np.flatnonzero(seam):
        loop = vids[offsets[c]:offsets[c + 1]]
        pts = V[loop].copy()
        shift = np.zeros((len(loop), len(spec)), np.int64)  # per vertex: the seams it was moved across
        for a, (p, period, lo, flips, mirror) in enumerate(spec):
            if pts[:, p].max() - pts[:, p].min() <= period / 2:
                continue
            side = pts[:, p] < lo + period / 2
            pts[side, p] += period
            for b, m in zip(flips, mirror):
                pts[side, b] = m - pts[side, b]
            shift[side, a] = 1
        ids = loop.copy()
        for i, (v, s) in enumerate(zip(loop.tolist(), map(tuple, shift))):
            if any(s):
                new = moved.get((v, s))
                if new is None:
                    new = moved[(v, s)] = len(V) + len(extra_pts)
                    extra_pts.append(pts[i])
                ids[i] = new
        loops.append(ids)
        sources.append(c)
    keep = ~seam
    kept = vids[np.repeat(keep, sizes)]
    all_vids = np.concatenate([kept] + loops)
    all_sizes = np.concatenate([sizes[keep], [len(x) for x in loops]]).astype(np.int64)
    source = np.concatenate([np.flatnonzero(keep), np.asarray(sources, np.int64)])
    new_off = np.zeros(len(all_sizes) + 1, np.int64)
    np.cumsum(all_sizes, out=new_off[1:])
    # edges from the loops' consecutive vertices, each pair once
    nxt = np.arange(len(all_vids)) + 1
    nxt[new_off[1:] - 1] = new_off[:-1]
    v0, v1 = all_vids, all_vids[nxt]
    n_vertices = len(V) + len(extra_pts)
    pair = np.minimum(v0, v1) * n_vertices + np.maximum(v0, v1)
    keys, faces = np.unique(pair, return_inverse=True)
    edges = np.stack([keys // n_vertices, keys % n_vertices], axis=1)
    verts = np.concatenate([V, np.asarray(extra_pts).reshape(-1, V.shape[1])])
    meta = dict(cx.meta)
    meta["display_source"] = source
    return CellComplex(cx.n, cx.k, verts, edges, {2: (new_off, faces.astype(np.int64))}, meta)
