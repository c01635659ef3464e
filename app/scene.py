"""Drawing a CellComplex through a projection on any pyvista plotter (no Qt here).

:class:`Scene` owns one pyvista mesh built once per result: lines for curves
(dim 1), filled polygons for surfaces (dim 2), the 2-skeleton for higher
dimensions. Moving a projection slider calls :meth:`Scene.set_projection`,
which writes the projected points (and, for surfaces, the exact vertex normals
of the projected mesh) in place into the mesh's VTK arrays and re-renders: no
new mesh, no new actor, same topology.

Smooth shading of a projected surface: the area-weighted normal of a triangle
(a, b) after projection is ``Pa x Pb = sum_{i<j} (a_i b_j - a_j b_i) (P_i x P_j)``
(``P_i`` = column i of ``P``), linear in the bivector ``a ^ b``. So each vertex
keeps the sum of its faces' bivectors in R^n (computed once, signs aligned with
a neighbour because surfaces such as the Klein bottle are not orientable; the
renderer lights both sides), and a slider step gets all normals with one more
``(V, m) @ (m, 3)`` matmul, ``m = n(n-1)/2``.

The same class renders into the Qt window (a ``pyvistaqt.QtInteractor``) and
into an off-screen ``pyvista.Plotter`` for headless screenshots.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pyvista as pv

from .projection import Projector, planes

BACKGROUND = "#1f2430"
BACKGROUND_TOP = "#4a5468"
SURFACE_COLOR = "#d9a441"
LINE_COLOR = "#f0c05a"
CMAP = "viridis"


@dataclass
class Style:
    """How the mesh is drawn; everything a user can change without a new run."""

    color_by: str | None = None      # a variable name, or None for a solid colour
    cmap: str = CMAP
    opacity: float | None = None     # None: 1 for curves and surfaces, 0.35 above
    show_edges: bool | None = None   # None: off for surfaces, on above
    line_width: float = 3.0
    title: str = ""
    subtitle: str = ""
    scalar_bar: bool = True
    axes: bool = True
    extra: dict = field(default_factory=dict)

    def resolved_opacity(self, dim: int) -> float:
        if self.opacity is not None:
            return float(self.opacity)
        return 1.0 if dim <= 2 else 0.35

    def resolved_edges(self, dim: int) -> bool:
        if self.show_edges is not None:
            return bool(self.show_edges)
        return dim >= 3


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
    I = np.array([p[0] for p in pairs], dtype=np.int64)
    J = np.array([p[1] for p in pairs], dtype=np.int64)
    return a[:, I] * b[:, J] - a[:, J] * b[:, I]


def _orientation_flips(face_of, vids, nxt, n_faces: int) -> np.ndarray:
    """Flip bits that orient the polygons coherently (BFS over faces sharing an edge).

    Two faces sharing an edge agree when they run through it in opposite
    directions. On a non-orientable piece the first assignment wins and a seam
    remains. Returns (n_faces,) bool.
    """
    a = vids
    b = vids[nxt]
    lo = np.minimum(a, b)
    hi = np.maximum(a, b)
    fwd = a < b
    V = int(vids.max()) + 1 if len(vids) else 1
    key = lo * V + hi
    order = np.argsort(key, kind="stable")
    ks = key[order]
    same = np.flatnonzero(ks[1:] == ks[:-1])        # consecutive corners on one edge
    c1, c2 = order[same], order[same + 1]
    f1, f2 = face_of[c1], face_of[c2]
    rel = (fwd[c1] == fwd[c2]).astype(np.int8)       # 1: must differ in flip
    ok = f1 != f2
    f1, f2, rel = f1[ok], f2[ok], rel[ok]
    # CSR adjacency, both directions
    src = np.concatenate([f1, f2])
    dst = np.concatenate([f2, f1])
    rr = np.concatenate([rel, rel])
    o = np.argsort(src, kind="stable")
    src, dst, rr = src[o], dst[o], rr[o]
    ptr = np.zeros(n_faces + 1, dtype=np.int64)
    np.cumsum(np.bincount(src, minlength=n_faces), out=ptr[1:])
    return _bfs_flips(ptr, dst.astype(np.int64), rr, n_faces)


def _bfs_flips(ptr, dst, rel, n_faces):
    try:
        from numba import njit
    except ImportError:  # pragma: no cover - numba is a dependency of gcmh_core
        njit = None
    global _BFS
    if _BFS is None:
        def bfs(ptr, dst, rel, n_faces):
            flip = np.zeros(n_faces, dtype=np.bool_)
            seen = np.zeros(n_faces, dtype=np.bool_)
            queue = np.empty(n_faces, dtype=np.int64)
            for s in range(n_faces):
                if seen[s]:
                    continue
                seen[s] = True
                head = 0
                tail = 1
                queue[0] = s
                while head < tail:
                    f = queue[head]
                    head += 1
                    for e in range(ptr[f], ptr[f + 1]):
                        g = dst[e]
                        if not seen[g]:
                            seen[g] = True
                            flip[g] = flip[f] ^ (rel[e] == 1)
                            queue[tail] = g
                            tail += 1
            return flip
        _BFS = njit(cache=True, nogil=True)(bfs) if njit is not None else bfs
    return _BFS(ptr, dst, rel, n_faces)


_BFS = None


def orient_polygons(offsets: np.ndarray, vids: np.ndarray) -> np.ndarray:
    """The loops with some reversed so that neighbouring polygons wind the same way."""
    offsets = np.asarray(offsets, dtype=np.int64)
    vids = np.asarray(vids, dtype=np.int64)
    N = len(offsets) - 1
    if N == 0:
        return vids
    sizes = np.diff(offsets)
    face_of = np.repeat(np.arange(N), sizes)
    pos = np.arange(len(vids))
    nxt = pos + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    flip = _orientation_flips(face_of, vids, nxt, N)
    if not flip.any():
        return vids
    # reverse flipped loops: position p in face f -> offsets[f] + (offsets[f+1] - 1 - p)
    src = pos.copy()
    fl = flip[face_of]
    src[fl] = offsets[face_of[fl]] + offsets[face_of[fl] + 1] - 1 - pos[fl]
    return vids[src]


def vertex_bivectors(vertices: np.ndarray, offsets: np.ndarray, vids: np.ndarray) -> np.ndarray:
    """Per-vertex sum of the area bivectors of its polygons (V, n(n-1)/2) float64.

    Pass loops oriented by :func:`orient_polygons`; where orientation fails (a
    non-orientable seam) each face's sign is also aligned with one reference
    face at the vertex, so normals never cancel. Order of components: planes().
    """
    X = np.asarray(vertices, dtype=np.float64)
    V, n = X.shape
    pairs = planes(n)
    m = len(pairs)
    offsets = np.asarray(offsets, dtype=np.int64)
    vids = np.asarray(vids, dtype=np.int64)
    N = len(offsets) - 1
    if N == 0 or m == 0:
        return np.zeros((V, m))
    sizes = np.diff(offsets)
    face_of = np.repeat(np.arange(N), sizes)
    pos = np.arange(len(vids))
    nxt = pos + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    Xf = np.where(np.isfinite(X), X, 0.0)
    csum = np.add.reduceat(Xf[vids], offsets[:-1], axis=0)
    cent = csum / np.maximum(sizes, 1)[:, None]
    a = Xf[vids] - cent[face_of]
    b = Xf[vids[nxt]] - cent[face_of]
    w = 0.5 * _wedge(a, b, pairs)                     # (corners, m)
    Bf = np.add.reduceat(w, offsets[:-1], axis=0)     # (N, m) face bivectors
    ref_face = np.full(V, -1, dtype=np.int64)
    ref_face[vids[::-1]] = face_of[::-1]              # first incident face wins
    s = np.sign(np.einsum("ij,ij->i", Bf[face_of], Bf[ref_face[vids]]))
    s[s == 0] = 1.0
    Bv = np.zeros((V, m))
    for c in range(m):
        Bv[:, c] = np.bincount(vids, weights=s * Bf[face_of, c], minlength=V)
    return Bv


def cross_table(P: np.ndarray) -> np.ndarray:
    """(m, 3) rows ``P_i x P_j`` for the planes (i, j) of R^n; P is (3, n)."""
    n = P.shape[1]
    pairs = planes(n)
    if not pairs:
        return np.zeros((0, 3))
    I = [p[0] for p in pairs]
    J = [p[1] for p in pairs]
    return np.cross(P[:, I].T, P[:, J].T)


def tangent_pair(Bv: np.ndarray, n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Two tangent vectors (V, n) per vertex with ``t1 ^ t2`` = the bivector ``Bv`` when it is simple.

    With M the antisymmetric matrix of B and any vector a: u = M a and w = M u
    lie in B's plane and ``B = -(u ^ w) / |u|^2``. A surface's summed bivector
    is nearly simple, so this is accurate; it lets normals be computed with two
    (3, n) projections instead of n(n-1)/2 components. Rows of Bv that are 0
    give zero tangents.
    """
    pairs = planes(n)
    I = np.array([p[0] for p in pairs])
    J = np.array([p[1] for p in pairs])
    V = len(Bv)

    def apply(x):  # M x per vertex, M_ij = B_ij (i<j), M_ji = -B_ij
        y = np.zeros((V, n))
        for c, (i, j) in enumerate(pairs):
            y[:, i] += Bv[:, c] * x[:, j]
            y[:, j] -= Bv[:, c] * x[:, i]
        return y

    best_u = np.zeros((V, n))
    best_norm = np.zeros(V)
    rng = np.random.default_rng(seed)
    for _ in range(3):  # a few probe vectors: keep the one with the largest |M a|
        a = np.broadcast_to(rng.standard_normal(n), (V, n))
        u = apply(a)
        nu = np.einsum("ij,ij->i", u, u)
        better = nu > best_norm
        best_u[better] = u[better]
        best_norm[better] = nu[better]
    w = apply(best_u)
    with np.errstate(divide="ignore", invalid="ignore"):
        t2 = np.where(best_norm[:, None] > 0, -w / best_norm[:, None], 0.0)
    return best_u, t2


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


class Scene:
    """One projected complex on a pyvista plotter.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
    """

    def __init__(self, plotter):
        self.plotter = plotter
        self.complex = None
        self.names: list[str] = []
        self.mesh: pv.PolyData | None = None
        self.actor = None
        self.style = Style()
        self.projector: Projector | None = None
        self._pts = None
        self._normals = None
        self._normal_field = None
        self._P = None
        self._axes_actor = None
        self._title_actor = None
        self._subtitle_actor = None
        self._legend_actor = None
        self._bar_title = None
        plotter.set_background(BACKGROUND, top=BACKGROUND_TOP)
        try:
            plotter.enable_anti_aliasing("ssaa")
        except Exception:  # noqa: BLE001 - not every render window supports it
            pass

    # ------------------------------------------------------------------ build
    @property
    def dim(self) -> int:
        return 0 if self.complex is None else int(self.complex.dim)

    def clear(self) -> None:
        if self.actor is not None:
            self.plotter.remove_actor(self.actor, render=False)
        self._remove_bar()
        self.actor = None
        self.mesh = None
        self.complex = None
        self.projector = None
        self._pts = self._normals = self._normal_field = None

    def set_complex(self, cx, names, P: np.ndarray, style: Style | None = None) -> None:
        """Build the mesh of ``cx`` (a CellComplex) projected by ``P`` (3, n) and show it."""
        self.clear()
        if style is not None:
            self.style = style
        if cx.count(0) == 0:   # nothing to draw (pyvista refuses empty meshes)
            self._set_title()
            return
        self.complex = cx
        self.names = list(names)
        V = cx.vertices
        self.projector = Projector(V)
        pts = self.projector.project(P)
        dim = cx.dim
        if dim <= 1 or len(V) == 0:
            edges = np.asarray(cx.edges, dtype=np.int64).reshape(-1, 2)
            lines = np.empty((len(edges), 3), dtype=np.int64)
            lines[:, 0] = 2
            lines[:, 1:] = edges
            mesh = pv.PolyData(pts, lines=lines.ravel()) if len(edges) else pv.PolyData(pts)
        else:
            offsets, vids = _proper_polygons(*cx.polygons())
            if dim == 2:
                vids = orient_polygons(offsets, vids)
            faces = polygon_faces(offsets, vids)
            mesh = pv.PolyData(pts, faces=faces) if len(faces) else pv.PolyData(pts)
            if dim == 2 and len(faces):
                self._normal_field = NormalField(vertex_bivectors(V, offsets, vids), cx.n)
                mesh.point_data["Normals"] = np.zeros((len(V), 3), dtype=np.float32)
                mesh.point_data.active_normals_name = "Normals"
        for i, name in enumerate(self.names):
            mesh.point_data[name] = np.ascontiguousarray(V[:, i])
        self.mesh = mesh
        self._pts = mesh.points  # a view of the VTK buffer: written in place
        self._normals = mesh.point_data["Normals"] if self._normal_field is not None else None
        self._P = np.asarray(P, dtype=float)
        self._write_normals()
        self._add_actor()
        self._update_axes_labels()
        self.plotter.reset_camera(render=False)

    def adopt(self, other: "Scene", style: Style | None = None) -> None:
        """Show the mesh of another scene (shared, not copied) with its projection."""
        self.complex = other.complex
        self.names = list(other.names)
        self.mesh = other.mesh
        self.projector = other.projector
        self._pts, self._normals, self._normal_field = other._pts, other._normals, other._normal_field
        self._P = other._P
        self.style = style if style is not None else other.style
        self._add_actor()
        self._update_axes_labels()

    def _add_actor(self) -> None:
        if self.mesh is None:
            return
        if self.actor is not None:
            self.plotter.remove_actor(self.actor, render=False)
            self.actor = None
        self._remove_bar()
        st = self.style
        dim = self.dim
        color_by = st.color_by if st.color_by in self.names else None
        kw = dict(
            opacity=st.resolved_opacity(dim),
            show_edges=st.resolved_edges(dim) and dim >= 2,
            edge_color="#202020",
            line_width=st.line_width if dim <= 1 else 0.6,
            smooth_shading=False,
            render=False,
            reset_camera=False,
            name="gcmh-complex",
            specular=0.12,
            specular_power=40.0,
            diffuse=0.85,
            ambient=0.18,
        )
        if dim <= 1:
            kw["render_lines_as_tubes"] = True
            kw["ambient"] = 0.35
        if color_by is not None:
            kw.update(scalars=color_by, cmap=st.cmap, show_scalar_bar=st.scalar_bar,
                      scalar_bar_args=dict(title=color_by, vertical=True, title_font_size=self._font(36),
                                           label_font_size=self._font(26), n_labels=5, fmt="%.2f",
                                           position_x=0.9, position_y=0.2, width=0.045,
                                           height=0.6, color="white", bold=False,
                                           unconstrained_font_size=True))
            self._bar_title = color_by if st.scalar_bar else None
        else:
            kw["color"] = SURFACE_COLOR if dim >= 2 else LINE_COLOR
            kw["show_scalar_bar"] = False
        self.actor = self.plotter.add_mesh(self.mesh, **kw)
        if self._bar_title is not None:
            try:
                bar = self.plotter.scalar_bars[self._bar_title]
            except (KeyError, AttributeError):
                bar = None
            if bar is not None:
                bar.SetTextPosition(0)          # labels and title below the bar, never over it
                bar.SetTitleRatio(1.0)
        if self._normals is not None:
            self.actor.prop.interpolation = "phong"
        self.mesh.set_active_scalars(color_by) if color_by else None
        self._set_title()

    def _remove_bar(self) -> None:
        if self._bar_title is not None:
            try:
                self.plotter.remove_scalar_bar(self._bar_title, render=False)
            except Exception:  # noqa: BLE001 - already gone
                pass
            self._bar_title = None

    def _set_title(self) -> None:
        for a in (self._title_actor, self._subtitle_actor):
            if a is not None:
                self.plotter.remove_actor(a, render=False)
        self._title_actor = self._subtitle_actor = None
        if self.style.title:
            self._title_actor = self.plotter.add_text(self.style.title, position=(0.02, 0.925), viewport=True,
                                                      font_size=self._font(18), color="white", name="gcmh-title")
        if self.style.subtitle:
            self._subtitle_actor = self.plotter.add_text(self.style.subtitle, position=(0.02, 0.885), viewport=True,
                                                         font_size=self._font(11), color="#c8cfdc", name="gcmh-subtitle")

    # ----------------------------------------------------------- fast update
    def set_projection(self, P: np.ndarray, render: bool = True) -> None:
        """Write the points (and normals) for projection ``P`` (3, n) in place."""
        self._P = np.asarray(P, dtype=float)
        if self.mesh is None:
            return
        self.projector.project(self._P, out=self._pts)
        self.mesh.GetPoints().Modified()
        self._write_normals()
        self.mesh.Modified()
        self._update_axes_labels()
        if render:
            self.plotter.renderer.ResetCameraClippingRange()
            self.plotter.render()

    def _write_normals(self) -> None:
        if self._normals is None or self._normal_field is None:
            return
        self._normal_field.write(self._P, self._normals)
        self.mesh.GetPointData().GetNormals().Modified()

    # ---------------------------------------------------------------- style
    def set_style(self, style: Style, render: bool = True) -> None:
        self.style = style
        self._add_actor()
        self._update_axes_labels()
        if render:
            self.plotter.render()

    def set_opacity(self, opacity: float, render: bool = True) -> None:
        self.style.opacity = float(opacity)
        if self.actor is not None:
            self.actor.prop.opacity = float(opacity)
        if render:
            self.plotter.render()

    def set_show_edges(self, on: bool, render: bool = True) -> None:
        self.style.show_edges = bool(on)
        if self.actor is not None:
            self.actor.prop.show_edges = bool(on) and self.dim >= 2
        if render:
            self.plotter.render()

    def _update_axes_labels(self) -> None:
        """Axis names on the orientation widget; a legend of the screen axes when they mix variables."""
        if not self.style.axes or self._P is None or not self.names:
            return
        from .projection import axis_label
        full = [axis_label(self._P[r], self.names, terms=3) for r in range(3)]
        short = []
        for r in range(3):
            row = self._P[r]
            if not np.any(np.abs(row) > 1e-6):
                short.append("-")
                continue
            i = int(np.argmax(np.abs(row)))
            pure = abs(abs(row[i]) - 1.0) < 1e-6
            short.append(full[r] if pure else "~" + self.names[i])   # ~x: "mostly x" (legend has the mix)
        mixed = any(lab.startswith("~") for lab in short)
        legend = "\n".join(f"{'XYZ'[r]} = {full[r]}" for r in range(3) if full[r]) if mixed else ""
        if self._axes_actor is None:
            try:
                self._axes_actor = self.plotter.add_axes(
                    xlabel=short[0], ylabel=short[1], zlabel=short[2],
                    line_width=3, color="white", labels_off=False,
                    viewport=(0.0, 0.0, 0.2, 0.28))
            except Exception:  # noqa: BLE001 - a plotter without an orientation widget
                self._axes_actor = None
        a = self._axes_actor
        if a is not None:
            a.SetXAxisLabelText(short[0])
            a.SetYAxisLabelText(short[1])
            a.SetZAxisLabelText(short[2])
        if self._legend_actor is None:
            self._legend_actor = self.plotter.add_text(legend, position=(0.02, 0.80), viewport=True,
                                                       font_size=self._font(11), color="#dfe4ee",
                                                       name="gcmh-legend")
        else:
            self._legend_actor.SetInput(legend)

    def _font(self, size: float) -> int:
        """A font size scaled to the picture height (sizes are tuned for 1200 pixels)."""
        try:
            h = int(self.plotter.window_size[1])
        except Exception:  # noqa: BLE001
            h = 1200
        return max(6, int(round(size * min(1.5, max(0.55, h / 1200)))))

    def axes_labels(self) -> list[str]:
        from .projection import axis_label
        if self._P is None:
            return ["", "", ""]
        return [axis_label(self._P[r], self.names) for r in range(3)]

    # ------------------------------------------------------------- exports
    def projected_mesh(self) -> pv.PolyData:
        """A copy of the current projected mesh (3D points, all coordinates as point data)."""
        if self.mesh is None:
            raise ValueError("nothing to export: no result yet")
        m = self.mesh.copy(deep=True)
        m.points = np.asarray(m.points, dtype=np.float64)
        return m


def describe(cx, names, color_by=None) -> str:
    """A one-line subtitle: what the picture shows."""
    dim, n, k = cx.dim, cx.n, cx.k
    what = {1: "curve", 2: "surface"}.get(dim, f"{dim}-manifold, 2-skeleton")
    text = f"{what} in R^{n} (n = {n}, k = {k}) · {cx.count(0):,} vertices"
    if color_by:
        text += f" · colour: {color_by}"
    return text


def default_camera(plotter) -> None:
    """An oblique view from above that fits the whole mesh."""
    plotter.view_vector((1.0, -1.6, 1.1), viewup=(0.0, 0.0, 1.0), render=False)
    plotter.reset_camera(render=False)
    plotter.camera.zoom(1.2)
    plotter.renderer.ResetCameraClippingRange()


def copy_camera(src, dst) -> None:
    dst.position = tuple(src.position)
    dst.focal_point = tuple(src.focal_point)
    dst.up = tuple(src.up)
    dst.view_angle = float(src.view_angle)
    dst.parallel_projection = bool(src.parallel_projection)
    dst.parallel_scale = float(src.parallel_scale)


def render_image(scene: Scene, path=None, size=(1600, 1200), transparent: bool = False, camera=None):
    """Render ``scene`` off screen at ``size`` (w, h) and write a PNG to ``path``.

    The mesh is shared, not rebuilt. ``camera``: a pyvista Camera to copy (the
    window's), else the default oblique view. Returns the (h, w, 3 or 4) image.
    """
    import copy

    pl = pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])
    try:
        other = Scene(pl)
        other.adopt(scene, copy.copy(scene.style))
        if camera is not None:
            copy_camera(camera, pl.camera)
            pl.renderer.ResetCameraClippingRange()
        else:
            default_camera(pl)
        if transparent:
            pl.renderer.GradientBackgroundOff()   # a gradient would paint every pixel opaque
        pl.render()
        img = pl.screenshot(str(path) if path is not None else None, transparent_background=transparent,
                            return_img=True, window_size=[int(size[0]), int(size[1])])
    finally:
        pl.close()
    return img
