"""Homology generators, the w1 loop and curvature as things to draw, without Qt.

Everything here is line segments in R^n (vertices (m, n), edges (E, 2)), the form the
scene's overlays take (:meth:`gcmh_studio.scene.Scene.set_overlay`): they are projected
with the same view as the result and clipped by the same slice, so they follow every
rotation.  A generator of H1 is its edges; of H0 its component's edges; of H2 the edges
of its 2-cells, or on a 3-manifold its 2-cells as triangles (:func:`generator_surface`,
drawn see-through by :mod:`gcmh_studio.homology_surfaces`).  The w1 loop comes with
small oriented loops, one in each polygon beside it: coherent polygons turn the same way
seen from one side, and across the w1 loop the sense of turning flips.

    from gcmh_core.homology import homology
    h = homology(cx)
    X, E = generator_lines(cx, h.generators[1][0])
    scene.set_overlay("homology-1-0", X, E, cycle_color(0), width=6.0)
"""

from __future__ import annotations

import numpy as np

# distinct from the overlays' red boundary, green pick and the colour maps' extremes
CYCLE_COLORS = ("#ffb000", "#00c2ff", "#ff4fd8", "#7cff4f", "#ff7a1a", "#b58cff", "#00e0b0", "#ffe14d",
                "#ff5a5a", "#4f7cff")
W1_COLOR = "#ff2d2d"
ARROW_COLOR = "#ffffff"


def cycle_color(i: int) -> str:
    """The colour of the i-th generator drawn (repeats after ten)."""
    return CYCLE_COLORS[int(i) % len(CYCLE_COLORS)]


def unwrap_segments(cx, X, E) -> tuple[np.ndarray, np.ndarray]:
    """Segments (X (m, n), E (k, 2)) of a result on identified axes, as the result is drawn
    (:func:`gcmh_studio.geometry.display_complex`): a segment that crosses a seam gets its
    low end moved up a period (reflected across a flipped seam), not a line across the box."""
    return _unwrap(cx, X, E, 2)


def unwrap_triangles(cx, X, T) -> tuple[np.ndarray, np.ndarray]:
    """Triangles (X (m, n), T (k, 3)) of a result on identified axes, unwrapped across the
    seams as :func:`unwrap_segments` does segments."""
    return _unwrap(cx, X, T, 3)


def _unwrap(cx, X, cells, size):
    """Cells of `size` points each: one that spans more than half a period of a glued
    axis gets its low points moved up a period (the flipped axes mirrored)."""
    from .geometry import seam_spec

    spec = seam_spec(cx)
    X = np.asarray(X, dtype=np.float64)
    E = np.asarray(cells, dtype=np.int64).reshape(-1, size)
    if not spec or E.size == 0:
        return X, E
    ends = X[E]                      # (k, size, n): each cell its own points
    crossed = np.zeros(len(E), bool)
    for p, period, lo, flips, mirror in spec:
        far = np.ptp(ends[:, :, p], axis=1) > period / 2
        if not far.any():
            continue
        crossed |= far
        low = far[:, None] & (ends[:, :, p] < lo + period / 2)
        ends[:, :, p] += np.where(low, period, 0.0)
        for b, m in zip(flips, mirror):
            ends[:, :, b] = np.where(low, m - ends[:, :, b], ends[:, :, b])
    if not crossed.any():
        return X, E
    keep = ~crossed
    moved = ends[crossed].reshape(-1, X.shape[1])
    k = int(crossed.sum())
    new_cells = len(X) + np.arange(size * k, dtype=np.int64).reshape(k, size)
    return np.concatenate([X, moved]), np.concatenate([E[keep], new_cells])


def _compact(X, edges):
    """(vertices, edges) with only the vertices the edges use, renumbered."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    used, inverse = np.unique(edges.ravel(), return_inverse=True)
    return np.asarray(X, dtype=np.float64)[used], inverse.reshape(-1, 2).astype(np.int64)


def _edges_of_2cells(cx, cells):
    off, fac = cx.cells[2]
    cells = np.asarray(cells, dtype=np.int64)
    counts = off[cells + 1] - off[cells]
    idx = np.repeat(off[cells], counts) + np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    return np.unique(fac[idx])


def generator_lines(cx, cycle) -> tuple[np.ndarray, np.ndarray]:
    """Segments in R^n that show one generator (a :class:`gcmh_core.homology.Cycle`).

    Returns vertices (m, n) float64 and edges (E, 2) int64 (E may be 0).
    """
    q = int(cycle.dim)
    cells = np.asarray(cycle.cells, dtype=np.int64)
    if q == 0:   # a class of H0 is a component: its edges
        labels = cx.component_labels()
        if cx.dim < 1 or cells.size == 0:
            return np.zeros((0, cx.n)), np.zeros((0, 2), dtype=np.int64)
        mine = np.isin(labels[np.asarray(cx.edges)[:, 0]], labels[cells])
        return _compact(cx.vertices, np.asarray(cx.edges)[mine])
    if q == 1:
        return _compact(cx.vertices, np.asarray(cx.edges)[cells])
    if q == 2:
        return _compact(cx.vertices, np.asarray(cx.edges)[_edges_of_2cells(cx, cells)])
    # q >= 3: the 2-cells of its cells' boundaries, down to edges
    for r in range(q, 2, -1):
        off, fac = cx.cells[r]
        counts = off[cells + 1] - off[cells]
        idx = np.repeat(off[cells], counts) + np.arange(int(counts.sum())) - \
            np.repeat(np.cumsum(counts) - counts, counts)
        cells = np.unique(fac[idx])
    return _compact(cx.vertices, np.asarray(cx.edges)[_edges_of_2cells(cx, cells)])


def generator_surface(cx, cycle) -> tuple[np.ndarray, np.ndarray]:
    """The 2-cells of an H2 cycle (a :class:`gcmh_core.homology.Cycle` of dimension 2) as
    triangles in R^n, each polygon fanned from its first vertex: vertices (m, n) float64
    and triangles (T, 3) int64, unwrapped across identified seams.  For a translucent
    surface on a 3-manifold (:func:`gcmh_studio.homology_surfaces.draw_homology_surfaces`)."""
    offs, verts = (np.asarray(a, dtype=np.int64) for a in cx.polygons())
    cells = np.asarray(cycle.cells, dtype=np.int64)
    tris = []
    for c in cells.tolist():
        ring = verts[offs[c]:offs[c + 1]]
        tris += [(ring[0], ring[i], ring[i + 1]) for i in range(1, ring.size - 1)]
    T = np.array(tris, dtype=np.int64).reshape(-1, 3)
    X = np.asarray(cx.vertices, dtype=np.float64)
    used, inverse = np.unique(T.ravel(), return_inverse=True)
    return unwrap_triangles(cx, X[used], inverse.reshape(-1, 3))


def edge_cycle_loops(cx, cycle) -> list[np.ndarray]:
    """An H1 cycle as closed vertex walks (for a text list or an export): each a (m,) int64
    array of vertex ids, first = last.  Edges with coefficient c are walked |c| times."""
    E = np.asarray(cx.edges)[np.asarray(cycle.cells)]
    coef = np.asarray(cycle.coefficients)
    darts = []
    for (u, v), c in zip(E.tolist(), coef.tolist()):
        darts += [(u, v) if c > 0 else (v, u)] * abs(int(c))
    out_of: dict = {}
    for i, (u, _) in enumerate(darts):
        out_of.setdefault(u, []).append(i)
    used = [False] * len(darts)
    loops = []
    for start in range(len(darts)):
        if used[start]:
            continue
        walk, i = [darts[start][0]], start
        while True:
            used[i] = True
            v = darts[i][1]
            walk.append(v)
            nxt = next((j for j in out_of.get(v, []) if not used[j]), None)
            if nxt is None:
                break
            i = nxt
        loops.append(np.array(walk, dtype=np.int64))
    return loops


def edge_attribute(cx, cycles) -> np.ndarray:
    """(E,) int32: 1 + the index of the first cycle through each edge, 0 elsewhere (a "cycle"
    attribute for a PLY/OBJ export of the edges)."""
    out = np.zeros(cx.count(1) if cx.dim >= 1 else 0, dtype=np.int32)
    for i in reversed(range(len(cycles))):
        out[np.asarray(cycles[i].cells)] = i + 1
    return out


def w1_lines(cx, loop_edges, orientation, shrink: float = 0.45) -> tuple[tuple, tuple]:
    """The w1 loop of a non-orientable surface and the orientation beside it.

    Returns ((X, E) of the loop's edges, (X, E) of small oriented loops: in each polygon
    on either side of the loop, the polygon's loop as `orientation` (the
    :attr:`gcmh_core.homology.Homology.orientation` the loop comes with) winds it, shrunk
    towards its centre by `shrink`, with an arrowhead on its first side).  Across the w1
    loop these turn the same way round their shared edge: that is where the orientation
    reverses.
    """
    loop_edges = np.asarray(loop_edges, dtype=np.int64)
    line = _compact(cx.vertices, np.asarray(cx.edges)[loop_edges])
    off, fac = cx.cells[2]
    owner = np.repeat(np.arange(off.size - 1), np.diff(off))
    polys = np.unique(owner[np.isin(fac, loop_edges)])
    X = np.asarray(cx.vertices, dtype=np.float64)
    offs, verts = (np.asarray(a) for a in cx.polygons())
    edges = np.asarray(cx.edges)
    sense = np.asarray(orientation)
    pts: list[np.ndarray] = []
    segs: list[tuple[int, int]] = []
    for p in polys.tolist():
        ring = verts[offs[p]:offs[p + 1]]
        if ring.size < 3:
            continue
        # wind the ring as the orientation runs the polygon's first edge (u, v)
        u, v = edges[fac[off[p]]]
        forward = bool(np.any((ring == u) & (np.roll(ring, -1) == v)))
        if forward != (sense[p] > 0):
            ring = ring[::-1]
        c = X[ring].mean(axis=0)
        R = c + shrink * (X[ring] - c)
        base = int(sum(len(a) for a in pts))
        m = ring.size
        pts.append(R)
        segs += [(base + i, base + (i + 1) % m) for i in range(m)]
        # arrowhead at the end of the first side, its barbs back along the side and inwards
        tip, tail = R[1], R[0]
        back = tail - tip
        inward = c - tip
        barbs = np.array([tip + 0.45 * back + 0.25 * inward, tip + 0.45 * back - 0.25 * inward])
        k = base + m
        pts.append(barbs)
        segs += [(base + 1, k), (base + 1, k + 1)]
    if not pts:
        return line, (np.zeros((0, cx.n)), np.zeros((0, 2), dtype=np.int64))
    return line, (np.concatenate(pts), np.array(segs, dtype=np.int64))


def curvature_values(cx, clip: float = 2.0) -> tuple[np.ndarray, str]:
    """Per-vertex Gaussian curvature density for a colour map, and the Gauss-Bonnet line.

    Each vertex shows the density of its star (it and its neighbours).  The densities are
    clipped to `clip` times their 95th percentile of |K| (a few tiny
    cells have huge densities that would wash the map out).
    """
    from gcmh_core.curvature import gauss_bonnet, gaussian_curvature

    c = gaussian_curvature(cx)
    # averaged over each vertex's star (defects and areas summed over it and its neighbours): a tiny
    # cell's vertex alone has a huge, noisy density
    e = np.asarray(cx.edges)

    def star(x):
        return x + np.bincount(e[:, 0], x[e[:, 1]], len(x)) + np.bincount(e[:, 1], x[e[:, 0]], len(x))

    defect, area = star(c.defect), star(c.area)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(area > 0, defect / area, 0.0)
    if k.size:
        cap = clip * float(np.percentile(np.abs(k), 95)) or 1.0
        k = np.clip(k, -cap, cap)
    return k, gauss_bonnet(cx).describe()


def write_cycles(mesh, path) -> str:
    """Write the homology overlays as one projected mesh (:func:`gcmh_studio.overlays.homology_lines_mesh`:
    lines and H2 polygons with cell data ``cycle`` and point data ``RGB``) keeping which cycle each cell
    belongs to: .ply (ASCII) as ``vertex`` x y z red green blue, ``edge`` vertex1 vertex2 cycle and
    ``face`` vertex_indices cycle; .obj as one group ``g cycle-N`` (``g w1`` for 0) per cycle, vertices
    with their colours; .vtp as it is.  Returns the path written."""
    import os

    path = str(path)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".vtp":
        mesh.save(path)
        return path
    if ext not in (".ply", ".obj"):
        raise ValueError(f"unknown cycles format {ext!r}: use .ply, .obj or .vtp")
    P = np.asarray(mesh.points, dtype=np.float64)
    rgb = np.asarray(mesh.point_data["RGB"], dtype=np.int64) if "RGB" in mesh.point_data.keys() \
        else np.full((len(P), 3), 255, dtype=np.int64)
    cycle = np.asarray(mesh.cell_data["cycle"], dtype=np.int64)
    lines = _cell_lists(mesh.lines)
    faces = _cell_lists(mesh.faces)
    # VTK numbers a mesh's cells vertices first, then lines, then polygons
    n_verts = mesh.n_cells - len(lines) - len(faces)
    line_cycle, face_cycle = cycle[n_verts:n_verts + len(lines)], cycle[n_verts + len(lines):]
    with open(path, "w") as f:
        if ext == ".ply":
            f.write(f"ply\nformat ascii 1.0\ncomment GCMH Studio homology cycles (0: the w1 loop)\n"
                    f"element vertex {len(P)}\nproperty double x\nproperty double y\nproperty double z\n"
                    f"property uchar red\nproperty uchar green\nproperty uchar blue\n"
                    f"element edge {len(lines)}\nproperty int vertex1\nproperty int vertex2\nproperty int cycle\n"
                    f"element face {len(faces)}\nproperty list uchar int vertex_indices\nproperty int cycle\n"
                    f"end_header\n")
            for p, c in zip(P.tolist(), rgb.tolist()):
                f.write(f"{p[0]!r} {p[1]!r} {p[2]!r} {c[0]} {c[1]} {c[2]}\n")
            for cells, cyc in ((lines, line_cycle), (faces, face_cycle)):
                for cell, k in zip(cells, cyc.tolist()):
                    if cells is lines:
                        f.write(f"{cell[0]} {cell[1]} {k}\n")
                    else:
                        f.write(f"{len(cell)} {' '.join(str(v) for v in cell)} {k}\n")
            return path
        f.write("# GCMH Studio homology cycles: one group per cycle (w1: the w1 loop), vertex colours\n")
        for p, c in zip(P.tolist(), (rgb / 255.0).tolist()):
            f.write(f"v {p[0]!r} {p[1]!r} {p[2]!r} {c[0]:.4f} {c[1]:.4f} {c[2]:.4f}\n")
        for k in sorted(set(line_cycle.tolist()) | set(face_cycle.tolist())):
            f.write(f"g {'w1' if k == 0 else f'cycle-{k}'}\n")
            for cells, cyc, tag in ((lines, line_cycle, "l"), (faces, face_cycle, "f")):
                for cell, kk in zip(cells, cyc.tolist()):
                    if kk == k:
                        f.write(f"{tag} {' '.join(str(v + 1) for v in cell)}\n")
    return path


def _cell_lists(arr) -> list:
    """A VTK legacy cell array ``[m, v.., m, v..]`` as a list of vertex lists."""
    arr = np.asarray(arr, dtype=np.int64)
    out, i = [], 0
    while i < len(arr):
        m = int(arr[i])
        out.append(arr[i + 1:i + 1 + m].tolist())
        i += m + 1
    return out
