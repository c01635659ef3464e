"""Identified domain axes: a periodic axis, possibly reversing other axes across its seam.

An axis p of the domain may be *periodic*: its bounds lo and hi are one point, so the
grid's last line d is its line 0 (x_p + P ~ x_p, P = hi - lo).  Crossing the seam may
also reverse other axes b (a *flip*): (x_p + P, x_b) ~ (x_p, c_b - x_b), c_b = lo_b + hi_b.
The Klein bottle of the paper is F(x, y, z, s, t) with s periodic reversing t, and t
periodic; the Moebius band reverses its width across its s seam.

What has to agree across a seam for the cubes on either side to share their faces,
vertices and cells exactly (as neighbouring cubes do everywhere else):

1. The grid lines (`identified_axes`): on a periodic axis line d is line 0 + P; an axis
   reversed by a flip is mirror-symmetric, x_{d-j} = c - x_j (for an even div: the
   mirror maps cube j to cube d-1-j and each parity to the other, see 3.).
2. F's values: line d holds *copies* of line 0's values (mirrored along the flipped
   axes), never re-evaluations (F(2pi + e) and F(e) differ in the last bits, and a sign
   that differs there would put a vertex on one side of the seam only).
3. The triangulation.  The kernel splits each face into its Kuhn simplices, and a
   reflection maps the Kuhn triangulation of a face with a flipped axis free to a
   *different* triangulation.  So a cube whose index along a flipped axis b is odd is
   processed in the frame mirrored along b (the "Union Jack" parity): axis b reversed,
   its values read from the mirrored corners, the ordinary kernel run there, and its
   records mapped back (positions x_b -> c_b - x_b; keys: each key's face anchor
   mirrored along b, its local code kept).  Codes computed in different frames still
   agree: a face with b fixed has the same triangulation and codes in both frames, and
   a face with b free is shared only by cubes with the same index along b.  Across the
   seam, cube j on one side meets cube d-1-j on the other, of the other parity: the
   reflection maps one frame onto the other, so both sides compute the same local codes.
4. The keys (`IdentifiedGrid.assemble`): every key whose face lies on a seam (its
   anchor has index d on the periodic axis) becomes its image's key (index 0, anchors
   mirrored along the flipped axes).  An identified vertex keeps the position computed
   on the side away from the seam.

The full sweep (`IdentifiedGrid.sweep`) evaluates F in slabs along an axis no seam
reverses (an unglued one when there is one) and runs the candidate cubes through this
grid; the interval-pruned sweep is not used for periodic runs.  Start points may be
projected across a seam (`project_wrapped`).  Continuation crosses seams
to the identified cube (`IdentifiedGrid.wrapped_neighbours`).  On a Dask cluster
(`distributed`) every task builds the IdentifiedGrid from (spec, bounds); a block
that ends on a seam copies that face's values from the vertices identified with it,
wherever they lie (`IdentifiedGrid.block_values`), and the records keep each vertex's
frame (`packed_records`), so the client's `assemble` picks the same positions in
whatever order blocks and waves come back.
"""

from __future__ import annotations

import copy
import math
import time
from itertools import combinations
from math import comb, factorial

import numpy as np

from . import _balls
from ._validate import describe_periodic
from .complex import CellComplex
from .errors import Cancelled, InputError
from .grid import candidate_scan, perturbed_axes
from .runner import Grid

__all__ = ["IdentifiedGrid", "identified_axes", "check_invariance", "describe_periodic"]

# F's invariance is checked at this many random points of the domain
INVARIANCE_SAMPLES = 300
# ... to this relative tolerance (of each component's largest |F| over the samples)
INVARIANCE_RTOL = 1e-8
# Vertices evaluated per slab of the sweep (as in `sweep.SLAB_VERTICES`)
_SLAB_VERTICES = 1 << 22


def identified_axes(bounds, div, seed, amplitude, spec) -> list[np.ndarray]:
    """`grid.perturbed_axes`, then made to wrap: line d = line 0 + P on a periodic axis,
    x_{d-j} = c - x_j exactly on an axis a flip reverses (its line 0 stays at lo when it
    is periodic too, since then line d = lo + P must be c - line 0)."""
    axes = perturbed_axes(bounds, div, seed, amplitude)
    periodic = {p for p, _ in spec}
    flipped = {b for _, flips in spec for b in flips}
    for b in sorted(flipped):
        lo, hi = bounds[b]
        c = lo + hi
        line = axes[b]
        d = len(line) - 1
        if b in periodic:
            line[0] = lo
        line[d // 2] = 0.5 * c
        for j in range(d // 2):
            line[d - j] = c - line[j]
    for p in sorted(periodic):
        lo, hi = bounds[p]
        axes[p][-1] = axes[p][0] + (hi - lo)
    return axes


def _constant_text(x: float) -> str:
    for m, text in ((1, "pi"), (2, "2pi"), (4, "4pi"), (0.5, "pi/2")):
        if math.isclose(x, m * math.pi, rel_tol=1e-12):
            return text
    return f"{x:g}"


def check_invariance(system, bounds, spec, samples: int = INVARIANCE_SAMPLES) -> None:
    """InputError unless F(image of x) = F(x) at `samples` random points x of the domain,
    for the identification of every periodic axis (its flips included).  When F is
    invariant with one more axis reversed, the message says so."""
    n = system.n
    rng = np.random.default_rng(0x67636D68)
    X = bounds[:, 0] + rng.uniform(0.0, 1.0, (samples, n)) * (bounds[:, 1] - bounds[:, 0])
    names = system.variables
    with np.errstate(all="ignore"):
        F0 = np.asarray(system.evaluate_points(X), np.float64)

    def images(p, flips):
        """F at the images of X, and the index of a point where it differs from F(X) (or None)."""
        Y = X.copy()
        Y[:, p] += bounds[p, 1] - bounds[p, 0]
        for b in flips:
            Y[:, b] = (bounds[b, 0] + bounds[b, 1]) - X[:, b]
        with np.errstate(all="ignore"):
            F1 = np.asarray(system.evaluate_points(Y), np.float64)
        ok = np.isfinite(F0).all(axis=1) & np.isfinite(F1).all(axis=1)
        scale = np.max(np.abs(F0[ok]), axis=0, initial=0.0) if ok.any() else np.zeros(system.k)
        bad = np.flatnonzero(ok & np.any(np.abs(F1 - F0) > INVARIANCE_RTOL * np.maximum(scale, 1e-300), axis=1))
        return F1, (int(bad[0]) if len(bad) else None)

    for p, flips in spec:
        F1, i = images(p, flips)
        if i is None:
            continue
        period = _constant_text(bounds[p, 1] - bounds[p, 0])
        how = f"{period}-periodic in {names[p]}"
        if flips:
            how += " with " + ", ".join(names[b] for b in flips) + " reversed"
        image = _image_text(X[i], names, bounds, p, flips, period)
        hint = ""
        for b in range(n):
            if b != p and b not in flips and images(p, (*flips, b))[1] is None:
                fix = ",".join(names[a] for a in (*flips, b))
                hint = f"; it is with {names[b]} reversed too: {names[p]}:flip={fix}"
                break
        raise InputError(f"F is not {how}: F({_point_text(X[i], names)}) = ({_point_text(F0[i])}) but "
                         f"F({image}) = ({_point_text(F1[i])}){hint}")


def _point_text(x, names=None) -> str:
    """"x=0.1, s=0.3" (or "0.1, 0.3" without names), six digits each."""
    if names is None:
        return ", ".join(f"{v:.6g}" for v in x)
    return ", ".join(f"{name}={v:.6g}" for name, v in zip(names, x))


def _image_text(x, names, bounds, p, flips, period) -> str:
    """The image of x across the seam of axis p, written out: "s=0.3 + 2pi, t=2pi - 0.7"."""
    parts = []
    for a, (name, v) in enumerate(zip(names, x)):
        if a == p:
            parts.append(f"{name}={v:.6g} + {period}")
        elif a in flips:
            c = bounds[a, 0] + bounds[a, 1]
            parts.append(f"{name}=-{v:.6g}" if c == 0 else f"{name}={_constant_text(c)} - {v:.6g}")
        else:
            parts.append(f"{name}={v:.6g}")
    return ", ".join(parts)


def _incidence_dims(r: int, k: int) -> tuple[int, int]:
    """The face dimensions of an incidence row's two keys: (r, X, Y) an r-cell and its
    (r-1)-face; (-r, K, S) an r-cell and a refined r-cell that replaces it (`_balls`)."""
    return (r + k, r - 1 + k) if r > 0 else (-r + k, -r + k)


class IdentifiedGrid(Grid):
    """A `Grid` whose periodic axes wrap (see the module docstring).

    spec: ((p, (b, ...)), ...): periodic axis p, the axes its seam reverses.
    bounds (n, 2): the domain (c_b = lo_b + hi_b is the mirror of a flipped axis).
    axes: from `identified_axes`.
    """

    defers_refinement = False  # (`Grid.defers_refinement`)

    def __init__(self, n, k, axes, method="gcmh", cancel=None, *, spec, bounds, progress=None, check_cells=None):
        super().__init__(n, k, axes, method, cancel, progress, check_cells)
        self.spec = tuple((int(p), tuple(int(b) for b in flips)) for p, flips in spec)
        self.periodic_axes = sorted(p for p, _ in self.spec)
        self.flipped_axes = sorted({b for _, flips in self.spec for b in flips})
        self.centres = np.asarray(bounds, np.float64).sum(axis=1)
        self.widths = np.diff(np.asarray(bounds, np.float64), axis=1)[:, 0]
        self.div = self.dims - 1
        # the key layout of `gcmh_core.kernels` (its glossary), computed here rather than read from the
        # tables: a face of dimension dim has key (anchor * C(n, dim) + rank) * n_codes[dim] + code,
        # rank its free axes' index in combinations(range(n), dim); a simplex (anchor) * (n+1)^n + code
        self._n_subsets = np.array([comb(n, d) for d in range(n + 1)], np.int64)
        self._n_codes = np.array([comb(d, k) * 2 ** max(d - k, 0) * factorial(k) if d >= k else 1
                                  for d in range(n + 1)], np.int64)
        self._rank_free = {dim: np.array([sum(1 << a for a in axes) for axes in combinations(range(n), dim)],
                                         np.int64) for dim in range(k, n + 1)}
        self._key_base = (n + 1) ** n
        self._frames = {}
        # vertex records that came from a mirrored frame: id(array) -> (array, each row's frame
        # pattern); the array is held so that ids stay unique (see assemble)
        self._vk_frames: dict = {}

    # ------------------------------------------------------------------ vertices and frames
    def canonical(self, multi: np.ndarray) -> np.ndarray:
        """Grid vertex multi-indices (m, n) with every index d on a periodic axis replaced
        by the vertex it is identified with (index 0 there, mirrored along its flips)."""
        multi = multi.copy()
        for _ in range(len(self.spec) + 1):
            moved = False
            for p, flips in self.spec:
                sel = multi[:, p] == self.div[p]
                if sel.any():
                    moved = True
                    multi[sel, p] = 0
                    for b in flips:
                        multi[sel, b] = self.div[b] - multi[sel, b]
            if not moved:
                break
        return multi

    def _frame(self, pattern: int) -> Grid:
        """A shallow copy of this grid mirrored along the axes in `pattern` (bit b)."""
        if pattern not in self._frames:
            fg = copy.copy(self)
            fg.axes_arr = self.axes_arr.copy()
            for b in range(self.n):
                if pattern >> b & 1:
                    line = self.axes[b]
                    fg.axes_arr[b, : len(line)] = self.centres[b] - line[::-1]
            self._frames[pattern] = fg
        fg = self._frames[pattern]
        fg.parts = {key: [] for key in self.parts}
        fg.stats = dict.fromkeys(self.stats, 0)  # (counts from zero, added back in _take_frame_records)
        fg.timings = dict.fromkeys(self.timings, 0.0)
        return fg

    def _run(self, values, cube_row, origin, value_off) -> np.ndarray:
        """`Grid.run_kernel` on candidate cubes, each in its parity's frame.  value_off:
        the row offsets of the corners in the ordinary frame."""
        pattern = np.zeros(len(origin), np.int64)
        for b in self.flipped_axes:
            pattern |= (origin[:, b] & 1) << b
        masks = np.zeros(len(origin), np.int64)
        corners = np.arange(1 << self.n)
        for pat in np.unique(pattern):
            idx = np.flatnonzero(pattern == pat)
            pat = int(pat)
            if pat == 0:
                masks[idx] = Grid.run_kernel(self, values, cube_row[idx], origin[idx], value_off)
                continue
            fg = self._frame(pat)
            fo = origin[idx].copy()
            mirrored = [b for b in range(self.n) if pat >> b & 1]
            for b in mirrored:
                fo[:, b] = self.div[b] - 1 - fo[:, b]
            # corner c of the mirrored frame is corner c ^ pat of the cube
            m = Grid.run_kernel(fg, values, cube_row[idx], fo, value_off[corners ^ pat])
            for b in mirrored:  # its facets below/above along b swap sides
                lo_bit, hi_bit = (m >> (2 * b)) & 1, (m >> (2 * b + 1)) & 1
                m = (m & ~(np.int64(3) << (2 * b))) | (lo_bit << (2 * b + 1)) | (hi_bit << (2 * b))
            masks[idx] = m
            self._take_frame_records(fg, mirrored)
        return masks

    def _take_frame_records(self, fg, mirrored) -> None:
        """The records of a mirrored frame, mapped back to the grid's frame and kept."""
        k = self.k
        for vk, vp, e, c, inc in zip(*(fg.parts[key] for key in ("vk", "vp", "e", "c", "i"))):
            vk = self._frame_keys(vk, k, mirrored)
            vp = vp.copy()
            for b in mirrored:
                vp[:, b] = self.centres[b] - vp[:, b]
            e = e.copy()
            e[:, 0] = self._frame_keys(e[:, 0], k + 1, mirrored)
            e[:, 1] = self._frame_keys(e[:, 1], k, mirrored)
            e[:, 2] = self._frame_keys(e[:, 2], k, mirrored)
            c = c.copy()
            inc = inc.copy()
            for r in np.unique(c[:, 0]):
                sel = c[:, 0] == r
                c[sel, 1] = self._frame_keys(c[sel, 1], int(r) + k, mirrored)
            for r in np.unique(inc[:, 0]):
                sel = inc[:, 0] == r
                dim_x, dim_y = _incidence_dims(int(r), k)
                inc[sel, 1] = self._frame_keys(inc[sel, 1], dim_x, mirrored)
                inc[sel, 2] = self._frame_keys(inc[sel, 2], dim_y, mirrored)
            for key, arr in zip(("vk", "vp", "e", "c", "i"), (vk, vp, e, c, inc)):
                self.parts[key].append(arr)
            self._vk_frames[id(vk)] = (vk, np.full(len(vk), sum(1 << b for b in mirrored), np.int64))
        for key, value in fg.stats.items():  # (every count the kernel run keeps, whatever it is)
            self.stats[key] = self.stats.get(key, 0) + value
        for key, value in fg.timings.items():
            self.timings[key] = self.timings.get(key, 0.0) + value

    # ------------------------------------------------------------------ records (distributed runs)
    def _vk_patterns(self) -> np.ndarray:
        """The frame pattern (bit b: mirrored along b) of every vertex record, in parts' order."""
        none = np.zeros(0, np.int64)
        return np.concatenate([self._vk_frames.get(id(a), (None, np.zeros(len(a), np.int64)))[1]
                               for a in self.parts["vk"]] or [none])

    def empty_copy(self) -> IdentifiedGrid:
        """`Grid.empty_copy`, with no frame records and frames of its own."""
        grid = super().empty_copy()
        assert isinstance(grid, IdentifiedGrid)  # (a copy of self)
        grid._frames = {}
        grid._vk_frames = {}
        return grid

    def packed_records(self) -> dict:
        """`Grid.packed_records` and each vertex record's frame ("vk_frame"): the assembly
        orders identified vertices by it."""
        out = super().packed_records()
        out["vk_frame"] = self._vk_patterns() if self.parts["vk"] else None
        return out

    def add_records(self, packed: dict) -> None:
        super().add_records(packed)
        vk = packed["parts"]["vk"]
        if vk is not None and packed.get("vk_frame") is not None:
            self._vk_frames[id(vk)] = (vk, packed["vk_frame"])

    # ------------------------------------------------------------------ keys
    def _decode(self, keys, dim):
        """keys -> (anchor multi-indices (m, n), free axes (m, n) bool, the rest of the key);
        dim None: keys of Kuhn simplices (in any method's grid)."""
        n = self.n
        if self.simplicial or dim is None:  # (anchor vertex) * (n+1)^n + code, code = sum step_a (n+1)^a
            base = self._key_base
            anchor, code = np.divmod(keys, base)
            free = (code[:, None] // (n + 1) ** np.arange(n, dtype=np.int64)[None]) % (n + 1) > 0
            rest: tuple[np.ndarray, ...] = (code,)
        else:  # (anchor * C(n, dim) + rank) * n_codes[dim] + local code
            q, code = np.divmod(keys, self._n_codes[dim])
            anchor, rank = np.divmod(q, self._n_subsets[dim])
            free = (self._rank_free[dim][rank][:, None] >> np.arange(n)[None]) & 1 == 1
            rest = (rank, code)
        multi = (anchor[:, None] // self.strides[None]) % self.dims[None]
        return multi, free, rest

    def _encode(self, multi, rest, dim):
        anchor = multi @ self.strides
        if self.simplicial or dim is None:
            return anchor * self._key_base + rest[0]
        rank, code = rest
        return (anchor * self._n_subsets[dim] + rank) * self._n_codes[dim] + code

    def _frame_keys(self, keys, dim, mirrored):
        """Keys from a frame mirrored along `mirrored`, as keys of the grid's frame: the
        anchor (the face's lowest corner) of a face with b free moves to its other end.
        dim None: keys of Kuhn simplices."""
        if not len(keys):
            return keys
        if (keys < 0).any():  # keys `_balls` made
            return self._balls_keys(keys, dim, lambda x, d: self._frame_keys(x, d, mirrored))
        multi, free, rest = self._decode(keys, dim)
        for b in mirrored:
            multi[:, b] = self.div[b] - multi[:, b] - free[:, b]
        return self._encode(multi, rest, dim)

    def _balls_keys(self, keys, dim, image):
        """`image` (a key map) applied to keys that may be `_balls`': a cut edge's key names a
        cell key K of its cube (mapped as an n-face's), a refined cell's a Kuhn simplex."""
        keys = keys.copy()
        refined = keys < _balls.REFINED_BELOW
        cuts = (keys < 0) & ~refined
        if cuts.any():
            room = _balls.cut_key_room(self._n_codes[self.n])
            cell, j = _balls.cut_key_parts(keys[cuts], room)
            keys[cuts] = _balls.cut_key(image(cell, self.n), j, room)
        if refined.any():
            keys[refined] = _balls.refined_key(image(_balls.refined_key_simplex(keys[refined]), None))
        plain = keys >= 0
        keys[plain] = image(keys[plain], dim)
        return keys

    def _seam_keys(self, keys, dim):
        """Keys of faces on a seam replaced by their images' keys; and which were.  dim None:
        keys of Kuhn simplices."""
        moved_any = np.zeros(len(keys), bool)
        if not len(keys):
            return keys, moved_any
        if (keys < 0).any():
            moved = {}

            def image(x, d):
                mapped, moved[d] = self._seam_keys(x, d)
                return mapped

            keys = self._balls_keys(keys, dim, image)
            # (a cut's key names a cube, never on a seam's far side; only plain and refined keys move)
            refined = keys < _balls.REFINED_BELOW
            if None in moved:
                moved_any[refined] = moved[None]
            if dim in moved:
                moved_any[keys >= 0] = moved[dim]
            return keys, moved_any
        multi, free, rest = self._decode(keys, dim)
        for _ in range(len(self.spec) + 1):
            shifted = False
            for p, flips in self.spec:
                sel = multi[:, p] == self.div[p]  # (a face with p free has its anchor below d)
                if sel.any():
                    shifted = True
                    moved_any |= sel
                    multi[sel, p] = 0
                    for b in flips:
                        multi[sel, b] = self.div[b] - multi[sel, b] - free[sel, b]
            if not shifted:
                break
        return self._encode(multi, rest, dim), moved_any

    def assemble(self) -> CellComplex:
        """Seam keys replaced by their images', then `Grid.assemble`.  Vertices computed
        on a seam go last, so an identified vertex keeps the position from the other side;
        before them, those computed in a mirrored frame (the same point, other last bits),
        ordered by frame, so the positions do not depend on the order in which cubes, slabs,
        blocks or waves were processed."""
        k = self.k
        t = time.perf_counter()
        cat = {key: np.concatenate(arrs) if arrs else None for key, arrs in self.parts.items()}
        if cat["vk"] is not None and cat["vp"] is not None:  # (always both or neither)
            vk, moved = self._seam_keys(cat["vk"], k)
            order = np.lexsort((self._vk_patterns(), moved))
            self.parts["vk"] = [vk[order]]
            self.parts["vp"] = [cat["vp"][order]]
        if cat["e"] is not None:
            e = cat["e"].copy()
            e[:, 0] = self._seam_keys(e[:, 0], k + 1)[0]
            e[:, 1] = self._seam_keys(e[:, 1], k)[0]
            e[:, 2] = self._seam_keys(e[:, 2], k)[0]
            self.parts["e"] = [e]
        if cat["c"] is not None:
            c = cat["c"].copy()
            for r in np.unique(c[:, 0]):
                sel = c[:, 0] == r
                c[sel, 1] = self._seam_keys(c[sel, 1], int(r) + k)[0]
            self.parts["c"] = [c]
        if cat["i"] is not None:
            inc = cat["i"].copy()
            for r in np.unique(inc[:, 0]):
                sel = inc[:, 0] == r
                dim_x, dim_y = _incidence_dims(int(r), k)
                inc[sel, 1] = self._seam_keys(inc[sel, 1], dim_x)[0]
                inc[sel, 2] = self._seam_keys(inc[sel, 2], dim_y)[0]
            self.parts["i"] = [inc]
        seam_seconds = time.perf_counter() - t
        cx = super().assemble()
        cx.meta["timings"]["assemble"] += seam_seconds
        return cx

    # ------------------------------------------------------------------ the runs
    def block_values(self, system, lo, hi) -> np.ndarray:
        """F at the vertices of the block of cubes lo..hi-1, as `sweep` holds them: evaluated
        below line d of every periodic axis; on a seam (a block that ends at line d) copied
        from the vertices identified with it, wherever they lie.  Every value is then
        `evaluate_grid`'s at an unglued vertex, so a block of a Dask run sees the bytes the
        single-process sweep sees."""
        return self._box_values(system, np.asarray(lo, np.int64), np.asarray(hi, np.int64))

    def _box_values(self, system, lo, hi) -> np.ndarray:
        """F at the grid vertices lo..hi (inclusive, per axis).  The face on line d of a
        periodic axis p is the box on line 0 of p, its range along each axis p flips
        mirrored (j -> d_b - j), read backwards; that box may reach line d of a flipped
        axis in turn, which has no flips of its own (`as_periodic`), so this recursion
        ends.  The faces are boxes: F on them by `evaluate_grid`, not vertex by vertex."""
        n, k = self.n, self.k
        top = hi.copy()
        for p in self.periodic_axes:
            top[p] = min(top[p], self.div[p] - 1)
        values = np.empty((*(hi - lo + 1).tolist(), k))
        if np.all(top >= lo):
            values[tuple(slice(0, int(top[a] - lo[a]) + 1) for a in range(n))] = system.evaluate_grid(
                [self.axes[a][lo[a] : top[a] + 1] for a in range(n)])
        for p, flips in self.spec:
            if hi[p] != self.div[p]:
                continue
            ilo, ihi = lo.copy(), hi.copy()
            ilo[p] = ihi[p] = 0
            for b in flips:
                ilo[b], ihi[b] = self.div[b] - hi[b], self.div[b] - lo[b]
            image = self._box_values(system, ilo, ihi)
            if flips:
                image = np.flip(image, axis=flips)
            dst = [slice(None)] * n
            dst[p] = slice(-1, None)
            values[tuple(dst)] = image  # (a vertex on two seams: both write its one value)
        return values

    def process_block(self, values, lo, hi, first_layer=None) -> np.ndarray:
        """`Grid.process_block` with each cube in its frame.  values: F at the block's
        vertices, line d of a periodic axis already holding line 0's (mirrored) values."""
        n = self.n
        lo = np.asarray(lo, np.int64)
        hi = np.asarray(hi, np.int64)
        values = np.ascontiguousarray(values, np.float64)
        t = time.perf_counter()
        origin, last_layer, nonfinite = candidate_scan(values, first_layer)
        if nonfinite:  # (counted once: line d of a periodic axis is line 0)
            owned = tuple(slice(None) if hi[a] == self.dims[a] - 1 and a not in self.periodic_axes
                          else slice(None, -1) for a in range(n))
            self.stats["nonfinite_vertices"] += int(np.count_nonzero(~np.isfinite(values[owned]).all(axis=-1)))
        self.timings["candidates"] += time.perf_counter() - t
        if len(origin) == 0:
            return last_layer
        block_strides = np.ones(n, np.int64)
        for a in range(n - 2, -1, -1):
            block_strides[a] = block_strides[a + 1] * values.shape[a + 1]
        value_off = np.array([sum(int(block_strides[a]) for a in range(n) if c >> a & 1) for c in range(1 << n)],
                             np.int64)
        cube_row = origin @ block_strides
        self._run(values.reshape(-1, self.k), cube_row, origin + lo, value_off)
        return last_layer

    def process_cubes(self, origins, system, sampled) -> tuple[np.ndarray, np.ndarray]:
        """`Grid.process_cubes` with F's values at a seam copied from the vertex identified
        with it, and each cube in its frame."""
        n = self.n
        t = time.perf_counter()
        corners = (origins @ self.strides)[:, None] + self.corner_off[None]
        ids = corners.reshape(-1)
        multi = self.canonical(np.stack(np.unravel_index(ids, tuple(self.dims)), axis=1))
        canon = multi @ self.strides
        uniq, inverse = np.unique(canon, return_inverse=True)
        umulti = np.stack(np.unravel_index(uniq, tuple(self.dims)), axis=1)
        uvals = np.asarray(system.evaluate_points(
            np.stack([self.axes[a][umulti[:, a]] for a in range(n)], axis=1)), np.float64)
        nonfinite = uniq[~np.isfinite(uvals).all(axis=1)]
        values = np.ascontiguousarray(uvals[inverse.reshape(-1)], np.float64)
        self.timings["evaluate"] += time.perf_counter() - t
        return self.cubes_from_corner_values(values, origins, self._run), nonfinite

    def wrapped_neighbours(self, wave, masks, cube_strides) -> tuple[np.ndarray, np.ndarray]:
        """`kernels.candidates.facet_neighbours` with seams crossed: past the last cube of a periodic
        axis is its first (and back), mirrored along the axes its seam reverses."""
        n = self.n
        out = []
        for f in range(2 * n):
            sel = (masks >> f) & 1 == 1
            if not sel.any():
                continue
            a, up = f // 2, f & 1
            cubes = wave[sel].copy()
            cubes[:, a] += 1 if up else -1
            flips = dict(self.spec).get(a)
            if flips is not None:
                wrap = (cubes[:, a] < 0) | (cubes[:, a] >= self.div[a])
                cubes[wrap, a] %= self.div[a]
                for b in flips:
                    cubes[wrap, b] = self.div[b] - 1 - cubes[wrap, b]
            else:
                cubes = cubes[(cubes[:, a] >= 0) & (cubes[:, a] < self.div[a])]
            out.append(cubes)
        cubes = np.concatenate(out) if out else np.zeros((0, n), np.int64)
        return cubes, cubes @ cube_strides

    def wrap_points(self, X: np.ndarray) -> np.ndarray:
        """Points (m, n) brought into the domain across the seams (x_p mod P; an odd number
        of crossings reverses the seam's flipped axes)."""
        X = np.array(X, np.float64)
        lo = 0.5 * (self.centres - self.widths)  # (centres = lo + hi, widths = hi - lo)
        order = sorted(self.spec, key=lambda item: not item[1])  # (flipping seams first)
        for p, flips in order:
            period = self.widths[p]
            turns = np.floor((X[:, p] - lo[p]) / period)
            X[:, p] -= turns * period
            odd = turns % 2 == 1
            for b in flips:
                X[odd, b] = self.centres[b] - X[odd, b]
        return X

    def project_wrapped(self, project):
        """`continuation.project_onto_M` that may cross seams: Newton runs in the domain
        widened by one period on each side of a glued axis, and its points are wrapped."""
        def run(system, X0, bounds):
            wide = np.array(bounds, np.float64)
            for p, _ in self.spec:
                wide[p] += (-self.widths[p], self.widths[p])
            X, ok, why = project(system, X0, wide)
            return self.wrap_points(X), ok, why
        return run

    def _fill_seams(self, values, skip) -> None:
        """Line d of every periodic axis but `skip` := line 0's values mirrored along its
        flips (values span the whole grid on every axis but `skip`)."""
        n = self.n
        for _ in range(len(self.spec)):  # (a seam's copy may read another seam's line d)
            for p, flips in self.spec:
                if p == skip:
                    continue
                src: list[slice | int] = [slice(None)] * n
                dst: list[slice | int] = [slice(None)] * n
                src[p], dst[p] = 0, -1
                view = values[tuple(src)]
                for b in flips:
                    view = np.flip(view, axis=b if b < p else b - 1)
                values[tuple(dst)] = view

    def sweep(self, system, progress=None, cancel=None) -> CellComplex:
        """Every cube: F in slabs along an axis no seam reverses (an unglued one if there is
        one), line d of glued axes copied from line 0, not evaluated."""
        n, k = self.n, self.k
        dims = self.dims
        glued = set(self.periodic_axes)
        sa = min((a for a in range(n) if a not in self.flipped_axes), key=lambda a: (a in glued, a))
        flips_sa = dict(self.spec).get(sa, ())
        layer = int(np.prod([int(d) for a, d in enumerate(dims) if a != sa]))
        thickness = int(max(1, min(dims[sa] - 1, _SLAB_VERTICES // max(layer * k, 1))))
        starts = list(range(0, int(dims[sa]) - 1, thickness))
        reuse = sa == 0  # (slabs along axis 0: the last layer and its candidate codes carry over)
        previous = codes = layer0 = None
        for si, i0 in enumerate(starts):
            if cancel is not None and cancel():
                raise Cancelled("extraction cancelled")
            if progress is not None:
                progress("extracting", si / len(starts))
            i1 = min(i0 + thickness, int(dims[sa]) - 1)
            lo = np.zeros(n, np.int64)
            hi = dims - 1
            lo[sa], hi[sa] = i0, i1
            t = time.perf_counter()
            first = 1 if reuse and previous is not None else 0
            copied = 1 if sa in glued and i1 == dims[sa] - 1 else 0  # (line d of the slab axis: line 0)
            lines = []
            for a in range(n):
                if a == sa:
                    lines.append(self.axes[a][i0 + first : i1 + 1 - copied])
                elif a in glued:
                    lines.append(self.axes[a][:-1])  # (line d is copied)
                else:
                    lines.append(self.axes[a])
            shape = [len(x) + (a in glued) for a, x in enumerate(lines)]
            shape[sa] = i1 - i0 + 1
            values = np.empty((*shape, k))
            inner = tuple(slice(first, shape[a] - copied) if a == sa else slice(None, -1) if a in glued
                          else slice(None) for a in range(n))
            if len(lines[sa]):
                values[inner] = system.evaluate_grid(lines)
            at: list[slice | int] = [slice(None)] * n
            if first:
                at[sa] = 0
                values[tuple(at)] = previous
            self._fill_seams(values, skip=sa)
            if sa in glued and i0 == 0:
                at[sa] = 0
                layer0 = values[tuple(at)].copy()
            if copied:
                assert layer0 is not None  # (kept at the first slab, i0 == 0, of the glued axis sa)
                view = layer0
                for b in flips_sa:
                    view = np.flip(view, axis=b if b < sa else b - 1)
                at[sa] = -1
                values[tuple(at)] = view
            self.timings["evaluate"] += time.perf_counter() - t
            codes = self.process_block(values, lo, hi, codes if first else None)
            at[sa] = -1
            previous = values[tuple(at)]
        if progress is not None:
            progress("assembling", 1.0)
        return self.assemble()
