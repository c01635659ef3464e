"""Slicing a complex by a window of a linear functional in R^n (pure numpy: no Qt, no VTK).

A slice keeps the part of the complex where ``h(x) = u . x`` lies in
``[c - w, c + w]``; ``u`` is a coordinate axis or a direction the projection
hides. Cells are *clipped* at the two window planes, not dropped: polygons by
Sutherland-Hodgman against the half-spaces ``h >= c - w`` and ``h <= c + w``,
segments by the same rule; a new vertex is interpolated linearly in R^n.

Both clips run over all polygons at once (CSR loops, one numpy pass per plane).
A new vertex is named by the original edge it lies on and the plane that cut
it, and computed from that edge's two original vertices in a fixed order: two
polygons sharing an edge get the very same new vertex (bit for bit), so the
slice stays one connected mesh, and the winding of every loop is kept (the
oriented loops of the full surface stay oriented).

Examples
--------
>>> import numpy as np
>>> X = np.array([[0., 0.], [2., 0.], [2., 2.], [0., 2.]])
>>> s = clip_polygons(X, np.array([0, 4]), np.arange(4), np.array([1., 0.]), 1.0, 0.5)
>>> sorted(set(np.round(s.vertices[:, 0], 6)))
[0.5, 1.5]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .projection import hidden_directions  # noqa: F401 - the slicing directions a view hides


@dataclass
class Slice:
    """The clipped complex.

    vertices: (V', n) float64, the used original vertices then the new ones;
    source: (V',) int64, the original vertex id, or -1 for a new vertex;
    offsets (F'+1,) int64 and vids: CSR loops (polygons) -- or for segments
    ``edges`` (E', 2) int64 with offsets/vids None; cell_source: (F',) or (E',)
    int64, the original cell each clipped cell comes from.
    """

    vertices: np.ndarray
    source: np.ndarray
    offsets: np.ndarray | None
    vids: np.ndarray | None
    cell_source: np.ndarray
    edges: np.ndarray | None = None

    @property
    def n_cells(self) -> int:
        return len(self.cell_source)

    @property
    def empty(self) -> bool:
        return self.n_cells == 0


def _check(X, u, c, w):
    X = np.asarray(X, dtype=np.float64)
    if X.ndim != 2:
        raise ValueError(f"vertices must be (V, n), got shape {X.shape}")
    u = np.asarray(u, dtype=np.float64).ravel()
    if len(u) != X.shape[1]:
        raise ValueError(f"the slicing direction has {len(u)} components, the vertices {X.shape[1]}")
    if not np.isfinite(c) or not np.isfinite(w) or w < 0:
        raise ValueError(f"the window needs a finite centre and a half-width >= 0, got c={c}, w={w}")
    return X, u


def _new_vertices(X, h, a, b, level):
    """Points where edges (a, b) meet ``h = level``, from the edge in (min, max) order (shared bit for bit)."""
    lo = np.minimum(a, b)
    hi = np.maximum(a, b)
    ha, hb = h[lo], h[hi]
    den = hb - ha
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(den != 0, (level - ha) / den, 0.5)
    t = np.clip(t, 0.0, 1.0)[:, None]
    return X[lo] + t * (X[hi] - X[lo]), lo, hi


def _clip_half(face, vk, hv, ea, eb, level, keep_above, key_offset=0):
    """One Sutherland-Hodgman pass over all loops against ``h >= level`` (or ``<=``).

    A corner is (face, vertex key, h value, the original edge (ea, eb) its
    outgoing side runs along, or -1 when that side runs along a clip plane).
    Vertex keys >= 0 are original vertices; a new vertex gets key
    -1 - (key_offset + j) for row j of the returned (a, b) edge list. Returns the corners of the clipped
    loops (same layout) and the new vertices' edges.
    """
    m = len(face)
    if m == 0:
        return face, vk, hv, ea, eb, np.empty(0, np.int64), np.empty(0, np.int64)
    # next corner in the same loop
    start = np.flatnonzero(np.r_[True, face[1:] != face[:-1]])
    ends = np.r_[start[1:], m] - 1
    nxt = np.arange(1, m + 1)
    nxt[ends] = start
    inside = hv >= level if keep_above else hv <= level
    nin = inside[nxt]
    cross = inside != nin
    # each corner emits: itself if inside, then the crossing point of its outgoing side if it crosses
    emit = inside.astype(np.int64) + cross
    pos = np.cumsum(emit) - emit
    total = int(emit.sum())
    o_face = np.empty(total, np.int64)
    o_vk = np.empty(total, np.int64)
    o_h = np.empty(total)
    o_ea = np.empty(total, np.int64)
    o_eb = np.empty(total, np.int64)
    k = pos[inside]
    ii = np.flatnonzero(inside)
    o_face[k] = face[ii]
    o_vk[k] = vk[ii]
    o_h[k] = hv[ii]
    o_ea[k] = ea[ii]
    o_eb[k] = eb[ii]
    ci = np.flatnonzero(cross)
    kc = pos[ci] + inside[ci]
    na, nb = ea[ci], eb[ci]
    if np.any(na < 0):  # a side along the other plane never crosses: the window is not empty
        raise AssertionError("a clip-plane side crossed the other plane")
    o_face[kc] = face[ci]
    o_vk[kc] = -1 - (key_offset + np.arange(len(ci)))
    o_h[kc] = level
    leaving = inside[ci]
    # entering: the outgoing side runs on along the original edge; leaving: along the plane
    o_ea[kc] = np.where(leaving, -1, na)
    o_eb[kc] = np.where(leaving, -1, nb)
    return o_face, o_vk, o_h, o_ea, o_eb, na, nb


def _proper_loops(face, n_faces):
    """Mask over corners keeping the loops with at least 3 corners (a clip can leave slivers of 1 or 2)."""
    return (np.bincount(face, minlength=n_faces) >= 3)[face]


def _finish(X, h, vk, new_lists):
    """One vertex array for the corner keys: the used originals, then the distinct new points.

    ``new_lists``: chunks of new corners in key order, each (a, b) original
    edges, the plane's level and the plane's id (0: low, 1: high). A new point
    is named by (edge, plane id).
    """
    n = X.shape[1]
    pts, keys = [], []
    for a, b, level, plane in new_lists:
        P, lo, hi = _new_vertices(X, h, a, b, level)
        pts.append(P)
        keys.append(np.stack([lo, hi, np.full(len(lo), plane)], 1))
    allkeys = np.concatenate(keys)
    allpts = np.concatenate(pts) if pts else np.empty((0, n))
    used_old = np.unique(vk[vk >= 0])
    if len(allkeys):
        _, first, inv = np.unique(allkeys, axis=0, return_index=True, return_inverse=True)
        inv = inv.ravel()
    else:
        first, inv = np.empty(0, np.int64), np.empty(0, np.int64)
    old_map = np.full(len(X), -1, np.int64)
    old_map[used_old] = np.arange(len(used_old))
    out_ids = np.empty(len(vk), np.int64)
    isold = vk >= 0
    out_ids[isold] = old_map[vk[isold]]
    out_ids[~isold] = len(used_old) + inv[-1 - vk[~isold]]
    verts = np.concatenate([X[used_old], allpts[first]])
    source = np.concatenate([used_old, np.full(len(first), -1, np.int64)])
    return verts, source, out_ids


def clip_polygons(vertices, offsets, vids, direction, c: float, w: float) -> Slice:
    """Clip CSR polygon loops to the slab ``c - w <= direction . x <= c + w``.

    vertices (V, n) float64; offsets (F+1,) int64; vids (sum,) int64 loops;
    direction (n,) (not normalised here: h is ``direction . x``). The loop
    winding is kept. Returns a :class:`Slice` (empty when nothing is inside).
    """
    X, u = _check(vertices, direction, c, w)
    offsets = np.asarray(offsets, dtype=np.int64)
    vids = np.asarray(vids, dtype=np.int64)
    h = X @ u
    F = len(offsets) - 1
    sizes = np.diff(offsets)
    face = np.repeat(np.arange(F, dtype=np.int64), sizes)
    # quick reject: whole loops below or above the window
    hv = h[vids]
    fmin = np.full(F, np.inf)
    fmax = np.full(F, -np.inf)
    if len(vids):
        fmin = np.minimum.reduceat(hv, offsets[:-1]) if F else fmin
        fmax = np.maximum.reduceat(hv, offsets[:-1]) if F else fmax
    lo, hi = c - w, c + w
    live = (fmax >= lo) & (fmin <= hi) & (sizes >= 3)
    keep = live[face]
    face, vk, hv = face[keep], vids[keep], hv[keep]
    # outgoing original edge of each corner
    m = len(face)
    start = np.flatnonzero(np.r_[True, face[1:] != face[:-1]]) if m else np.empty(0, np.int64)
    ends = np.r_[start[1:], m] - 1 if m else np.empty(0, np.int64)
    nxt = np.arange(1, m + 1)
    if m:
        nxt[ends] = start
    ea, eb = vk.copy(), vk[nxt]
    f1, k1, h1, a1, b1, na1, nb1 = _clip_half(face, vk, hv, ea, eb, lo, True)
    ok = _proper_loops(f1, F)
    f1, k1, h1, a1, b1 = f1[ok], k1[ok], h1[ok], a1[ok], b1[ok]
    f2, k2, h2, a2, b2, na2, nb2 = _clip_half(f1, k1, h1, a1, b1, hi, False, key_offset=len(na1))
    ok = _proper_loops(f2, F)
    f2, k2 = f2[ok], k2[ok]
    if len(f2) == 0:
        n = X.shape[1]
        return Slice(np.empty((0, n)), np.empty(0, np.int64), np.zeros(1, np.int64), np.empty(0, np.int64),
                     np.empty(0, np.int64))
    verts, source, ids = _finish(X, h, k2, [(na1, nb1, lo, 0), (na2, nb2, hi, 1)])
    faces_kept, counts = np.unique(f2, return_counts=True)
    offs = np.zeros(len(faces_kept) + 1, np.int64)
    np.cumsum(counts, out=offs[1:])
    return Slice(verts, source, offs, ids, faces_kept.astype(np.int64))


def clip_polygons_at(vertices, offsets, vids, direction, levels, w: float) -> Slice:
    """:func:`clip_polygons` around each of ``levels`` (a glued space's section has several: ``s = c`` and
    ``s = c + 2pi`` where a seam's cells are drawn past the box, ``t = c`` and ``t = 2pi - c`` across a
    reversed seam), the bands in one :class:`Slice` (a polygon in two bands comes twice)."""
    parts = [clip_polygons(vertices, offsets, vids, direction, float(c), w) for c in levels]
    if len(parts) == 1:
        return parts[0]
    shift = np.cumsum([0] + [len(p.vertices) for p in parts[:-1]])
    starts = np.cumsum([0] + [int(np.asarray(p.offsets)[-1]) for p in parts[:-1]])
    return Slice(np.concatenate([p.vertices for p in parts]), np.concatenate([p.source for p in parts]),
                 np.concatenate([np.zeros(1, np.int64)] + [np.asarray(p.offsets)[1:] + s0
                                                            for p, s0 in zip(parts, starts)]).astype(np.int64),
                 np.concatenate([p.vids + v0 for p, v0 in zip(parts, shift)]).astype(np.int64),
                 np.concatenate([p.cell_source for p in parts]).astype(np.int64))


def clip_segments(vertices, edges, direction, c: float, w: float) -> Slice:
    """Clip segments (E, 2) int64 to the slab ``c - w <= direction . x <= c + w`` (a curve's slice)."""
    X, u = _check(vertices, direction, c, w)
    E = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    h = X @ u
    lo, hi = c - w, c + w
    a, b = E[:, 0], E[:, 1]
    ha, hb = h[a], h[b]
    live = (np.maximum(ha, hb) >= lo) & (np.minimum(ha, hb) <= hi)
    idx = np.flatnonzero(live)
    a, b, ha, hb = a[idx], b[idx], ha[idx], hb[idx]
    n = X.shape[1]
    if len(idx) == 0:
        return Slice(np.empty((0, n)), np.empty(0, np.int64), None, None, np.empty(0, np.int64),
                     edges=np.empty((0, 2), np.int64))
    # each end: the original vertex if inside, else the point on the plane it is beyond
    keys = np.empty((len(idx), 2), np.int64)
    chunks = []
    cnt = 0
    for col, (v, hv) in enumerate(((a, ha), (b, hb))):
        k = v.copy()
        for plane, (level, beyond) in enumerate(((lo, hv < lo), (hi, hv > hi))):
            j = np.flatnonzero(beyond)
            k[j] = -1 - (cnt + np.arange(len(j)))
            chunks.append((a[j], b[j], level, plane))
            cnt += len(j)
        keys[:, col] = k
    verts, source, out = _finish(X, h, keys.ravel(), chunks)
    edges_out = out.reshape(-1, 2)
    nondeg = edges_out[:, 0] != edges_out[:, 1]
    return Slice(verts, source, None, None, idx[nondeg].astype(np.int64), edges=edges_out[nondeg])


def window_range(vertices, direction) -> tuple[float, float]:
    """(min, max) of ``direction . x`` over the finite vertices ((0, 0) when none)."""
    X = np.asarray(vertices, dtype=np.float64)
    X = X[np.all(np.isfinite(X), axis=1)]
    if len(X) == 0:
        return 0.0, 0.0
    h = X @ np.asarray(direction, dtype=np.float64)
    return float(h.min()), float(h.max())


@dataclass
class SliceWindow:
    """What the user slices by: coordinate ``index`` or, with ``hidden``, the view's hidden direction ``index``.

    ``c`` and ``w``: the window ``[c - w, c + w]`` of ``u . x``.
    """

    index: int
    hidden: bool = False
    c: float = 0.0
    w: float = 0.1

    def direction(self, view_frame: np.ndarray) -> np.ndarray:
        """The unit vector u (n,) for a view with frame (n, n) (rows: 3 screen, then hidden)."""
        F = np.asarray(view_frame, dtype=np.float64)
        n = F.shape[1]
        if self.hidden:
            H = F[3:]
            if not (0 <= self.index < len(H)):
                raise ValueError(f"hidden direction {self.index + 1} does not exist (n = {n} hides {len(H)})")
            return H[self.index].copy()
        if not (0 <= self.index < n):
            raise ValueError(f"coordinate {self.index} does not exist in R^{n}")
        return np.eye(n)[self.index]

    def label(self, names) -> str:
        return f"hidden direction {self.index + 1}" if self.hidden else str(names[self.index])
