"""Cells that are balls (issue 13): split a surface's piece that M_A joins through the cube.

GCMH makes one 2-cell per piece of the cube's vertex-edge graph G_H (paper 3.1.2).  Where M_A
is a thin tube through the cube, G_H has one loop at each end, and GCMH makes two discs where
M_A has one annulus: the complex's topology is wrong (the kernel finds these places with
`kernels.cells._joined_pieces` and reports them).  For surfaces (n - k = 2, where the (k+2)-face is
the cube itself and nothing else in the grid sees the cell) this module replaces those discs
by cells with M_A's topology, keeping every vertex and edge the cube shares with its
neighbours:

1. March the cube's own Kuhn simplices (CMS, paper Section 4, `simplices_chunk` on the one
   cube): a polygonal surface P with M_A's topology in the cube.  Its boundary on the cube's
   facets is GCMH's loops: GCMH's vertices are P's vertices on the cube's k-faces, and each
   GCMH edge is the path of P's boundary edges the walk follows in its (k+1)-face.
2. Orient P's polygons consistently and read each loop's direction from that orientation.
3. A piece of P with m loops, orientable and of genus 0 (chi = 2 - m), becomes m discs cut
   by 2(m - 1) new edges between the loops' vertices: the first loop and the next one are
   joined by two cuts, which split off one disc; what is left has one loop fewer.  Every
   disc runs along its loops in their induced directions, so the cells glue into a surface
   homeomorphic to P with the same boundary, hence into M_A's topology.  Each disc has at
   least four edges and distinct vertices, and no cut joins two vertices an edge already
   joins (the loops are different pieces of G_H).

A piece that is not orientable or has a handle inside one cube (not seen in practice) is left
as the kernel made it and stays counted in meta["non_ball_cells"] minus meta["non_ball_split"].

Keys: a disc takes the key of one of the cells it replaces (the discs are as many as those
cells), so keys stay in the kernels' scheme; a cut edge has the negative key
-(1 + K * room + j), K the smallest replaced cell key, j < room its index, which no kernel
key can meet (`identify` maps K for mirrored frames).
"""

from __future__ import annotations

from functools import lru_cache
from math import factorial

import numpy as np

from .kernels.cell_check import cube_euler_chunk, records_cube_euler, same_faces_candidates
from .kernels.cells import _face_key as _face_key_jit
from .kernels.cms import simplices_chunk
from .kernels.gcmh import cubes_chunk
from .kernels.kuhn_cube import cube_simplex_tables, piece_labels
from .kernels.tables import cube_tables

__all__ = ["REFINED_BELOW", "collapse_lens_cells", "cone_lens_balls", "cut_key", "cut_key_parts", "cut_key_room",
           "refine_cube", "refined_key", "refined_key_simplex", "replace_refined_cells", "split_joined_pieces"]

# a cube face's key from its anchor's global vertex, C(n, dim) and the rank of its free axes: the kernels' own
# formula, called in Python (n - k = 2 splits are rare: no compiled signature for them)
_face_key = _face_key_jit.py_func


def cut_key_room(n_codes_top: int) -> int:
    """Cut indices per replaced cell key (more than a cube's vertices can ask for); n_codes_top: vertex
    codes inside the n-cube (`CubeTables.n_codes[n]`)."""
    return 2 * int(n_codes_top)


def cut_key(cell, j, room):
    """The key of cut j of the piece whose smallest replaced cell key is ``cell``: negative, so no kernel
    key meets it (ints or int64 arrays)."""
    return -(1 + cell * room + j)


def cut_key_parts(keys, room):
    """``cut_key``'s (cell, j) back from keys."""
    return divmod(-keys - 1, room)


def split_joined_pieces(tab, values, cube_row, origin, cube_key, axes_arr, value_off, corner_off):
    """New records for one cube where the kernel reported joined pieces (n - k = 2).

    The arguments are `cubes_chunk`'s for this one cube (arrays of length 1).  Returns
    (old cell keys to drop from the incidence records, new edge rows, new incidence rows,
    pieces joined that are now split), or None when nothing could be split.
    """
    n, k = tab.n, tab.k
    if n - k != 2 or tab.kuhn.corners.shape[0] == 0:
        return None
    args = (values, cube_row, origin, cube_key, axes_arr, value_off, corner_off)
    (g_vk, g_vp, g_edges, g_cells, g_inc), _, _, _ = cubes_chunk(0, 1, *args, tab)
    (c_vk, _, c_edges, _, c_inc), _, degenerate, _ = simplices_chunk(0, 1, *args, tab.kuhn)
    if degenerate:
        return None
    g_vertex = int(cube_key[0])
    surface = _Surface.of(tab, g_vertex, corner_off, c_vk, c_edges, c_inc)
    if surface is None:
        return None
    loops = _Loops(tab, g_vertex, corner_off, surface, g_edges, g_inc)
    position = {int(key): x for key, x in zip(g_vk, g_vp)}
    room = cut_key_room(tab.n_codes[n])
    drop, new_edges, new_inc, split = [], [], [], 0
    cell_keys = sorted(int(x) for x in g_cells[g_cells[:, 0] == 2, 1])
    by_piece: dict[int, list[int]] = {}
    for key in cell_keys:
        piece = loops.piece_of(key)
        if piece is not None:
            by_piece.setdefault(piece, []).append(key)
    for piece, keys in sorted(by_piece.items()):
        m = len(keys)
        if m < 2:
            continue
        if not surface.orientable[piece] or surface.euler[piece] != 2 - m:
            continue
        ordered = [loops.loop(key) for key in keys]
        if any(loop is None for loop in ordered) or keys[0] > (2**62 - room) // room:
            continue
        cut = _cut_into_discs(ordered, position, tab.simplices_per_kface)
        if cut is None:
            continue
        discs, cuts = cut
        for j, (a, b) in enumerate(cuts):
            new_edges.append((cut_key(keys[0], j, room), a, b))
        for key, disc in zip(keys, discs):
            for edge in disc:
                edge_key = cut_key(keys[0], edge[1], room) if edge[0] == "cut" else edge[1]
                new_inc.append((2, key, edge_key))
        drop.extend(keys)
        split += m - 1
    if not split:
        return None
    return (np.array(drop, np.int64), np.array(new_edges, np.int64).reshape(-1, 3),
            np.array(new_inc, np.int64).reshape(-1, 3), split)


class _Surface:
    """P: the CMS polygons of one cube, their pieces, orientation and boundary."""

    gcmh: dict[int, int]  # CMS vertex key -> GCMH vertex key
    ends: dict[int, tuple[int, int]]  # CMS edge key -> its vertices' keys
    facet: dict[int, int]  # CMS edge key -> the cube facets (bits) it lies on
    piece_of_polygon: dict[int, int]
    piece_of_vertex: dict[int, int]
    orientable: dict[int, bool]
    euler: dict[int, int]
    next: dict[int, tuple[int, int]]  # boundary: vertex -> (next vertex, facet on the way)
    cms_of: dict[int, int]  # GCMH vertex key -> CMS vertex key

    @classmethod
    def of(cls, tab, g_vertex, corner_off, c_vk, c_edges, c_inc):
        self = cls()
        kuhn = tab.kuhn
        k = tab.k
        simplex_key = _simplex_keys(kuhn, g_vertex, corner_off)
        row_of = {int(x): s for s, x in enumerate(simplex_key) if s >= kuhn.start[k]}
        gcmh_key = _gcmh_vertex_keys(tab, kuhn, g_vertex, corner_off)
        self.gcmh = {}  # CMS vertex key -> GCMH vertex key
        for v in c_vk:
            s = row_of[int(v)]
            if s in gcmh_key:
                self.gcmh[int(v)] = gcmh_key[s]
        self.ends = {int(e[0]): (int(e[1]), int(e[2])) for e in c_edges}
        self.facet = {key: int(kuhn.cube_facets[row_of[key]]) for key in self.ends}
        polygons: dict[int, list[int]] = {}
        for _, x, y in c_inc[c_inc[:, 0] == 2]:
            polygons.setdefault(int(x), []).append(int(y))
        users: dict[int, list[int]] = {}
        for p, edges in polygons.items():
            for e in edges:
                users.setdefault(e, []).append(p)
        # each polygon's cycle of vertices, in the order of its edges
        cycles = {}
        for p, edges in polygons.items():
            cycle = _cycle([self.ends[e] for e in edges])
            if cycle is None:
                return None
            cycles[p] = cycle
        for e, ps in users.items():  # boundary edges lie on the cube's facets, the others in two polygons
            if len(ps) != (1 if self.facet[e] else 2):
                return None
        # pieces and a consistent orientation (+1: the cycle as listed, -1: reversed)
        self.piece_of_polygon, sign = {}, {}
        self.orientable, self.euler = {}, {}
        for p0 in sorted(polygons):
            if p0 in sign:
                continue
            piece = len(self.orientable)
            sign[p0] = 1
            stack, members, ok = [p0], list[int](), True
            while stack:
                p = stack.pop()
                members.append(p)
                self.piece_of_polygon[p] = piece
                for e in polygons[p]:
                    for q in users[e]:
                        if q == p:
                            continue
                        want = -sign[p] * _direction(cycles[p], self.ends[e]) * _direction(cycles[q], self.ends[e])
                        if q not in sign:
                            sign[q] = want
                            stack.append(q)
                        elif sign[q] != want:
                            ok = False
            verts = {v for p in members for v in cycles[p]}
            piece_edges = {e for p in members for e in polygons[p]}
            self.orientable[piece] = ok
            self.euler[piece] = len(verts) - len(piece_edges) + len(members)
        # the boundary, directed as the orientation induces: next vertex and the facet on the way
        self.next = {}
        self.piece_of_vertex = {}
        for p, edges in polygons.items():
            for v in cycles[p]:
                self.piece_of_vertex[v] = self.piece_of_polygon[p]
            for e in edges:
                if self.facet[e]:
                    a, b = self.ends[e]
                    if _direction(cycles[p], (a, b)) * sign[p] < 0:
                        a, b = b, a
                    if a in self.next:
                        return None
                    self.next[a] = (b, self.facet[e])
        self.cms_of = {g: c for c, g in self.gcmh.items()}
        return self


class _Loops:
    """GCMH's loops (the boundaries of its 2-cells in the cube), directed as P induces."""

    def __init__(self, tab, g_vertex, corner_off, surface, g_edges, g_inc):
        self.tab, self.g_vertex, self.surface = tab, g_vertex, surface
        self.ends = {int(e[0]): (int(e[1]), int(e[2])) for e in g_edges}
        self.edges_of: dict[int, set] = {}
        for _, x, y in g_inc[g_inc[:, 0] == 2]:
            self.edges_of.setdefault(int(x), set()).add(int(y))
        k1 = tab.k + 1
        self.facet_key = {}  # facet bit -> the global key of that (k+1)-face, as edge keys carry it
        for f in range(tab.face_start[k1], tab.face_start[k1 + 1]):
            free, fixed = int(tab.face_free[f]), int(tab.face_fixed[f])
            axis = (~free & ((1 << tab.n) - 1)).bit_length() - 1
            bit = 1 << (2 * axis + ((fixed >> axis) & 1))
            anchor = g_vertex + int(corner_off[fixed])
            self.facet_key[bit] = _face_key(anchor, int(tab.n_subsets[k1]), int(tab.face_rank[f]))

    def piece_of(self, cell):
        edges = self.edges_of.get(cell)
        if not edges:
            return None
        v = self.ends[next(iter(edges))][0]
        return self.surface.piece_of_vertex.get(self.surface.cms_of.get(v))

    def loop(self, cell):
        """[(vertex, edge to the next vertex)] around the cell, or None if P's boundary disagrees."""
        s = self.surface
        edges = self.edges_of[cell]
        start = min(v for e in edges for v in self.ends[e])
        out, at = [], start
        n_codes = int(self.tab.n_codes[self.tab.k + 1])
        for _ in range(len(edges)):
            c = s.cms_of.get(at)
            facet = None
            while True:  # P's boundary path from `at` to the next GCMH vertex, in one facet
                if c not in s.next:
                    return None
                c, facet_here = s.next[c]
                if facet not in (None, facet_here):
                    return None
                facet = facet_here
                if c in s.gcmh:
                    break
            b = s.gcmh[c]
            match = [e for e in edges if set(self.ends[e]) == {at, b} and e // n_codes == self.facet_key.get(facet)]
            if len(match) != 1:
                return None
            out.append((at, match[0]))
            at = b
            if at == start:
                break
        if at != start or {e for _, e in out} != edges:
            return None
        return out


def _cycle(edge_ends):
    """The vertices of a polygon in cyclic order from its edges' ends; None if not one cycle."""
    nbrs: dict[int, list[int]] = {}
    for a, b in edge_ends:
        nbrs.setdefault(a, []).append(b)
        nbrs.setdefault(b, []).append(a)
    if any(len(x) != 2 for x in nbrs.values()):
        return None
    start = min(nbrs)
    cycle, prev, at = [start], None, start
    while True:
        a, b = nbrs[at]
        nxt = a if a != prev else b
        if nxt == start:
            break
        cycle.append(nxt)
        prev, at = at, nxt
        if len(cycle) > len(nbrs):
            return None
    return cycle if len(cycle) == len(nbrs) else None


def _direction(cycle, edge):
    """+1 if the cycle runs a -> b along the edge (a, b), -1 if b -> a."""
    a, b = edge
    i = cycle.index(a)
    return 1 if cycle[(i + 1) % len(cycle)] == b else -1


def _cut_into_discs(loops, position, kfact):
    """Discs (lists of ("edge", key) / ("cut", j)) and cuts [(vertex a, vertex b)] for one piece.

    loops: each [(vertex, edge to the next)] in the direction P induces.  The current outer
    loop C (at first the first loop) is joined to the next loop L by cuts p-s and q-t; the
    disc C[p..q] + (q, t) + L[t..s] + (s, p) is split off and C becomes
    C[q..p] + (p, s) + L[s..t] + (t, q).  Every loop is followed forwards.  (Any p != q and
    s != t give the topology; p and s nearest each other, q half-way round C and t nearest
    q give discs that look like the strips of the tube they are.)  A cut's ends lie on
    different k-faces (kfact: vertex key // kfact is the k-face), or None.
    """
    cuts: list[tuple[int, int]] = []
    discs = []
    outer = [(v, ("edge", e)) for v, e in loops[0]]
    for loop in loops[1:]:
        inner = [(v, ("edge", e)) for v, e in loop]
        # (a cut never joins two vertices on one k-face: an edge of another cube could join them)
        gap = np.array([[float(np.sum((position[v] - position[w]) ** 2)) if v // kfact != w // kfact else np.inf
                         for w, _ in inner] for v, _ in outer])
        if not np.isfinite(gap).any():
            return None
        ip, il = divmod(int(np.argmin(gap)), len(inner))
        half = len(outer) / 2
        options = [(abs((iq - ip) % len(outer) - half), gap[iq, it], iq, it)
                   for iq in range(len(outer)) for it in range(len(inner))
                   if iq != ip and it != il and np.isfinite(gap[iq, it])]
        if not options:
            return None
        _, _, iq, it = min(options)
        p, q = outer[ip][0], outer[iq][0]
        s, t = inner[il][0], inner[it][0]
        ps, qt = len(cuts), len(cuts) + 1
        cuts += [(p, s), (q, t)]
        disc = [e for _, e in _arc(outer, ip, iq)] + [("cut", qt)] + [e for _, e in _arc(inner, it, il)] \
            + [("cut", ps)]
        discs.append(disc)
        outer = _arc(outer, iq, ip) + [(p, ("cut", ps))] + _arc(inner, il, it) + [(t, ("cut", qt))]
    discs.append([e for _, e in outer])
    return discs, cuts


def _arc(loop, i, j):
    """The steps of a loop from position i forwards to position j (j itself not included)."""
    out = []
    while i != j:
        out.append(loop[i])
        i = (i + 1) % len(loop)
    return out


# ----------------------------------------------------------------------------- refinement by CMS
# A piece of M_A hidden inside a face (a loop inside a (k+1)-face reaches no k-face: no GCMH vertex,
# chi 0) is emitted by a refined cube; the check flags every cube on that face alike
# (`kernels.cell_check.cube_euler_chunk`'s hidden count), so every cube that has the face emits it too.
# A refined cell's key: below every cut key (cut keys are at least -2^62), from the key of its Kuhn
# simplex (`kernels.tables.SimplexTables`), which is below 2^62 wherever a refinement is made.
REFINED_BELOW = -(2**62)
# An incidence row (-r, K, S) is no incidence: it says that the r-cell K is replaced by its
# refinement, of which the r-cell S is one (`replace_refined_cells` applies it at the assembly).


def refined_key(simplex_keys):
    """The key of the CMS cell in the Kuhn simplex with this key (ints or int64 arrays)."""
    return REFINED_BELOW - 1 - simplex_keys


# `refined_key`'s simplex keys back: the map is its own inverse
refined_key_simplex = refined_key


def _simplex_keys(kuhn, g_vertex, corner_off):
    """Global keys of the cube's Kuhn simplices (`SimplexTables`' formula)."""
    return (g_vertex + corner_off[kuhn.c0]) * kuhn.key_base + kuhn.code


def _gcmh_vertex_keys(tab, kuhn, g_vertex, corner_off) -> dict:
    """Kuhn row of each k-simplex on a k-face of the cube -> GCMH's key of the vertex there: the
    k-face's key * k! + the lexicographic rank of the order its chain switches the face's axes on
    (`tables.CubeTables`' ksimplex_perm; the whole table's rows or a cube's own, `kuhn_cube`)."""
    k = tab.k
    rows = np.arange(kuhn.start[k], kuhn.start[k + 1])
    chains = kuhn.corners[rows, : k + 1]
    free = chains[:, k] & ~chains[:, 0]
    on_face = _popcount(free, tab.n) == k  # (the others lie inside higher faces)
    rows, chains, free = rows[on_face], chains[on_face], free[on_face]
    f = _face_maps(tab.n, k)[1][free, chains[:, 0]]
    axis = _popcount((chains[:, 1:] ^ chains[:, :-1]) - 1, tab.n)  # the axis switched on at each link
    local = _popcount(free[:, None] & ((np.int64(1) << axis) - 1), tab.n)  # its place among the face's axes
    rank = np.zeros(len(rows), np.int64)
    for i in range(k):
        rank += (local[:, i + 1 :] < local[:, i, None]).sum(axis=1) * factorial(k - 1 - i)
    anchor = g_vertex + corner_off[tab.face_fixed[f]]
    keys = _face_key(anchor, int(tab.n_subsets[k]), tab.face_rank[f]) * tab.simplices_per_kface + rank
    return dict(zip(rows.tolist(), keys.tolist()))


def _popcount(x, n):
    """Set bits of each int64 (below 2^n)."""
    x = np.asarray(x, np.int64)
    out = np.zeros(x.shape, np.int64)
    for a in range(n):
        out += (x >> a) & 1
    return out


def refine_cube(tab, values, cube_row, origin, cube_key, axes_arr, value_off, corner_off, neighbours_checked=False,
                bulges=None):
    """Records that replace every GCMH cell of one cube by the CMS cells it is made of.

    Where a piece of M_A in the cube is not a ball and can't be cut (solids, n - k >= 3: a
    thickened tube is a shell S^2 x I; or a surface piece `split_joined_pieces` declines), the
    cube's own Kuhn simplices give convex cells with M_A's topology (paper Section 4).  The
    cube's cells on its faces are shared with neighbours that keep their GCMH cells: each is
    replaced by its CMS cells (rows (-r, old key, new key), applied to every incidence at the
    assembly, whichever cube or block wrote it), so a neighbour's cell keeps its ball and gets a
    finer boundary.  GCMH's vertices stay; the new vertices lie on the Kuhn k-simplices inside
    the cube's faces.

    The arguments are `cubes_chunk`'s for this one cube (arrays of length 1); neighbours_checked:
    whether every cube's Euler characteristic is checked (`runner.Grid.check_cells`), or the caller
    refines the cubes across the faces listed in `bulges` (a list: the faces (free, fixed) where M_A has
    cells no GCMH cell of the cube holds are appended to it) as well.  Returns
    records (vk, vp, e, c, inc) to add, or None when the cube can't be refined (its own Kuhn table
    too large, n >= 8: `kuhn_cube.MOST_ROWS`; a degenerate crossing; keys out of range; M_A on a
    face where GCMH has no cell and the neighbours are not checked).
    """
    n, k = tab.n, tab.k
    own = _CubeKuhn.of(tab, values, cube_row[0], value_off)
    if own is None:
        return None
    kuhn = own.kuhn
    args = (values, cube_row, origin, cube_key, axes_arr, value_off, corner_off)
    (_, _, g_edges, g_cells, g_inc), _, _, _ = cubes_chunk(0, 1, *args, tab)
    (c_vk, c_vp, c_edges, c_cells, c_inc), _, degenerate, _ = simplices_chunk(0, 1, *args, kuhn)
    if degenerate:
        return None
    g_vertex = int(cube_key[0])
    skeys = _simplex_keys(kuhn, g_vertex, corner_off)
    if len(skeys) and int(skeys.max()) >= -REFINED_BELOW:
        return None
    row_of = {int(x): s for s, x in enumerate(skeys)}
    gcmh_of_row = _gcmh_vertex_keys(tab, kuhn, g_vertex, corner_off)
    carrier = own.carrier  # the face of the cube whose relative interior holds each simplex
    face_dim = _face_dims(n, k)
    face_key_of = {}
    for f in range(tab.face_start[k + 1], tab.face_start[n + 1]):
        dim = int(face_dim[f])
        anchor = g_vertex + int(corner_off[tab.face_fixed[f]])
        face_key_of[(dim, _face_key(anchor, int(tab.n_subsets[dim]), int(tab.face_rank[f])))] = f

    # CMS entities (dim r, simplex key) with their faces; GCMH vertices under their own keys
    faces_of: dict = {}
    for key, a, b in c_edges.tolist():
        faces_of[(1, key)] = [(0, a), (0, b)]
    for r, x, y in c_inc.tolist():
        faces_of.setdefault((r, x), []).append((r - 1, y))
    for r, x in c_cells.tolist():
        faces_of.setdefault((r, x), [])
    entities = [(0, int(v)) for v in c_vk] + sorted(faces_of)
    gcmh_vertex = {(0, int(v)): gcmh_of_row[row_of[int(v)]] for v in c_vk if row_of[int(v)] in gcmh_of_row}
    # GCMH's cells of the cube, each with its face and one of its vertices (as a CMS vertex)
    cms_vertex = {g: x for x, g in gcmh_vertex.items()}
    vertex_of: dict = {}
    for key, a, _ in g_edges.tolist():
        vertex_of[(1, key)] = cms_vertex.get(a)
    for r in range(2, n - k + 1):
        for _, x, y in g_inc[g_inc[:, 0] == r].tolist():
            vertex_of.setdefault((r, x), vertex_of.get((r - 1, y)))
    by_face: dict = {}
    for r, key in vertex_of:
        face = face_key_of.get((r + k, key // int(tab.n_codes[r + k])))
        if face is None or vertex_of[(r, key)] is None:
            return None
        by_face.setdefault(face, []).append((r, key))
    # each GCMH r-cell is replaced by the CMS r-cells (simplices of its face's dimension) of its piece
    top_in_face: dict = {}
    for x in entities:
        if x[0] >= 1:
            f = int(carrier[row_of[x[1]]])
            if face_dim[f] == x[0] + k:  # (a simplex of its face's dimension)
                top_in_face.setdefault(f, []).append(x)
    assigned = []
    covered: set = set()  # the CMS cells given to a GCMH cell so far
    joined = set()  # faces where two of GCMH's cells lie on one piece of M_A (two discs for an annulus)
    # faces with a piece of M_A hidden inside (a loop with no GCMH vertex): no GCMH cell's piece
    hidden = own.euler(values, cube_row, value_off)[1][0]
    hidden_faces = [_face_free_fixed(tab, h) for h in np.flatnonzero(hidden)]
    pieces: _Pieces | None = None
    for f, cells in sorted(by_face.items()):
        new = top_in_face.get(f, [])
        free, fixed = _face_free_fixed(tab, f)
        label = None
        if len(cells) > 1 or any(_in_face(h_free, h_fixed, free, fixed) for h_free, h_fixed in hidden_faces):
            # each cell gets the CMS cells of its own piece of M_A in f
            if pieces is None:
                pieces = _Pieces(entities, faces_of, carrier, row_of, tab)
            label = pieces.in_face(free, fixed)
        for r, key in cells:
            if label is None or pieces is None:
                mine = new
            else:
                index = pieces.index
                mine = [x for x in new if label[index[x]] == label[index[vertex_of[(r, key)]]]]
            if not mine:
                return None
            if not covered.isdisjoint(mine):
                joined.add(f)
            covered.update(mine)
            assigned.append((r, key, mine))
    # A piece of M_A that bulges through one of the cube's faces between its k-faces has cells there
    # that no GCMH cell holds: the neighbour across has them only if it is refined too, which its
    # own Euler check sees; without that check the cube stays as it was.
    bulging = [_face_free_fixed(tab, f) for f, xs in sorted(top_in_face.items())
               if face_dim[f] < n and any(x not in covered for x in xs)]
    if bulges is not None:
        # Each of a joined face's cells is replaced by the whole piece: a neighbour across that keeps
        # GCMH's cells there gets two cells bounded by it, so it is refined too ((8, 4), seed 9).  (Where
        # the kernel has the cube's Kuhn table, n <= 7, every cube on the face reports the joined pieces.)
        bulges.extend(bulging + [_face_free_fixed(tab, f) for f in sorted(joined) if face_dim[f] < n])
    if bulging and not neighbours_checked:
        return None
    replace = [(-r, key, x[1]) for r, key, mine in assigned for x in mine]
    # the records: CMS's, keyed as refined cells; its vertices on the cube's k-faces are GCMH's
    def vkey(x):
        return gcmh_vertex[x] if x in gcmh_vertex else int(refined_key(x[1]))

    new_v = [i for i, v in enumerate(c_vk.tolist()) if (0, v) not in gcmh_vertex]
    vk = refined_key(c_vk[new_v])
    vp = c_vp[new_v]
    e = np.array([(refined_key(key), vkey((0, a)), vkey((0, b))) for key, a, b in c_edges.tolist()],
                 np.int64).reshape(-1, 3)
    c = np.array([(r, refined_key(x)) for r, x in c_cells.tolist()], np.int64).reshape(-1, 2)
    inc = [(r, refined_key(x), refined_key(y)) for r, x, y in c_inc.tolist()]
    inc += [(r, old, refined_key(s)) for r, old, s in replace]
    return vk, vp, e, c, np.array(inc, np.int64).reshape(-1, 3)


class _Pieces:
    """The CMS entities of a cube as a graph (an entity joined to its faces), to split those inside one
    face of the cube into M_A's pieces there (`refine_cube`; at n = 8, k = 3 a cube has 10^5 of them)."""

    def __init__(self, entities, faces_of, carrier, row_of, tab):
        self.index = {x: i for i, x in enumerate(entities)}
        pairs = [(self.index[x], self.index[y]) for x in entities for y in faces_of.get(x, ()) if y in self.index]
        self.a, self.b = (np.array(z, np.int64) for z in (zip(*pairs) if pairs else ((), ())))
        where = carrier[np.array([row_of[x[1]] for x in entities], np.int64)]
        self.free, self.fixed = tab.face_free[where], tab.face_fixed[where]

    def in_face(self, free, fixed):
        """Each entity's piece label among those in the closed face (free, fixed) (others: their own)."""
        inside = ((self.free & ~free) == 0) & ((self.fixed & ~free) == fixed)
        keep = inside[self.a] & inside[self.b] if len(self.a) else np.zeros(0, bool)
        return piece_labels(len(inside), self.a, self.b, keep)


def _face_free_fixed(tab, f) -> tuple[int, int]:
    """The cube face row f as (free, fixed) bits."""
    return int(tab.face_free[f]), int(tab.face_fixed[f])


def _in_face(free, fixed, f_free, f_fixed):
    """Whether the face (free, fixed) of the cube lies in the face (f_free, f_fixed)."""
    return (free & ~f_free) == 0 and (fixed & ~f_free) == f_fixed


def _root(parent, x):
    while parent[x] != x:
        parent[x] = parent[parent[x]]
        x = parent[x]
    return x


def _union(parent, x, y):
    a, b = _root(parent, x), _root(parent, y)
    if a != b:
        parent[b] = a


def replace_refined_cells(e, c, inc):
    """The assembly's records with every cell a cube refined (rows (-r, K, S) of inc) replaced:
    K's own rows go, and every incidence (r + 1, X, K) becomes (r + 1, X, S) for each S.
    Then the lens cells are collapsed (`collapse_lens_cells`)."""
    marked = inc[:, 0] < 0
    if not marked.any():
        return collapse_lens_cells(e, c, inc)
    rep = np.unique(inc[marked], axis=0)
    inc = inc[~marked]
    for r in np.unique(-rep[:, 0]).tolist():
        rows = rep[rep[:, 0] == -r]
        old = np.unique(rows[:, 1])
        if r == 1:
            e = e[~np.isin(e[:, 0], old)]
        else:
            c = c[~((c[:, 0] == r) & np.isin(c[:, 1], old))]
            inc = inc[~((inc[:, 0] == r) & np.isin(inc[:, 1], old))]
        # (r + 1, X, K) -> (r + 1, X, S) for each S that replaces K
        hit = (inc[:, 0] == r + 1) & np.isin(inc[:, 2], old)
        if hit.any():
            order = np.argsort(rows[:, 1], kind="stable")
            by_old, new = rows[order, 1], rows[order, 2]
            lo = np.searchsorted(by_old, inc[hit, 2], side="left")
            hi = np.searchsorted(by_old, inc[hit, 2], side="right")
            count = hi - lo
            expanded = np.repeat(inc[hit], count, axis=0)
            starts = np.repeat(lo - np.concatenate([[0], np.cumsum(count)[:-1]]), count)
            expanded[:, 2] = new[starts + np.arange(len(expanded))]
            inc = np.concatenate([inc[~hit], expanded])
    return collapse_lens_cells(e, c, inc)


def _merged(rep: dict, y: int) -> int:
    while y in rep:
        y = rep[y]
    return y


def collapse_lens_cells(e, c, inc):
    """Collapse every lens r-cell, r >= 2 when there are 3-cells: the assembly's records (e, c, inc)
    without them.

    A lens is an r-cell X with two faces A and B that have the same boundary: M_A's piece in a
    cube's (r+k)-face meets only two of its (r+k-1)-faces, near the face they share (a random
    system in R^6, k = 3, div 4: a 3-cell of two 2-cells with the same edges, and those two as
    "duplicate" cells).  It is collapsed onto A: X goes, B becomes A in every r-cell that had it,
    and the (r+1)-cells that had X lose it.  One r-cell and one (r-1)-cell fewer: chi is
    unchanged, and every boundary that was a sphere stays one.  Dimensions go up, each in rounds
    until none is left (a merge can free a lens that held another), since an (r+1)-cell that loses X
    may become a lens, and nothing at r changes below it.  So the 2-cells go first, here, when there
    are 3-cells: `_regular.collapse_lenses` after the assembly then finds only the lenses left here
    (guessing its decisions instead, and collapsing the 3-cells by the guess, broke 3-cells' boundaries
    where four edges had the same ends at (8, 3): its decisions change once a merge removes a face).
    Left alone: a lens whose A and B are both faces of another r-cell (the merge would fold it), or
    of no other (X is a whole ball on the box's boundary: `cone_lens_balls`, or a whole disc:
    `_regular.subdivide_double_edges`).  Smaller keys are kept and lenses go in key order, as ids
    follow keys; keys of what is kept are unchanged, so the result is as deterministic as the records.
    """
    top = int(c[:, 0].max()) if len(c) else 0
    for r in range(2, top + 1) if top >= 3 else ():
        while True:  # until no r-cell is a lens: each round removes some
            rep, removed = _lenses(e, inc, r)
            if not removed:
                break
            gone = np.array(sorted(removed), np.int64)
            dropped = np.array(sorted(rep), np.int64)
            if r == 2:
                e = e[~np.isin(e[:, 0], dropped)]
            c = c[~(((c[:, 0] == r) & np.isin(c[:, 1], gone)) | ((c[:, 0] == r - 1) & np.isin(c[:, 1], dropped)))]
            inc = inc[~(((inc[:, 0] == r) & np.isin(inc[:, 1], gone))
                        | ((inc[:, 0] == r + 1) & np.isin(inc[:, 2], gone))
                        | ((inc[:, 0] == r - 1) & np.isin(inc[:, 1], dropped)))]
            moved = (inc[:, 0] == r) & np.isin(inc[:, 2], dropped)
            if moved.any():
                inc = inc.copy()
                inc[moved, 2] = [_merged(rep, y) for y in inc[moved, 2].tolist()]
    return e, c, inc


def cone_lens_balls(vertices: np.ndarray, edges: np.ndarray, cells: dict):
    """Make every cell regular by coning (stellar subdivision), dimension by dimension from 2 up:
    every r-cell gets at least r + 1 faces and no two r-cells the same faces.

    What `collapse_lens_cells` and `_regular` leave: a whole-ball lens (an r-cell X bounded by two
    (r-1)-cells A and B with the same boundary and no other coface: M_A's small piece cut off by the
    box near one of its ridges), an r-cell of fewer than r + 1 faces (n >= 8, where no Kuhn tables
    refine a cube: 3-cells of three faces, 4-cells of three at (8, 4)), and two r-cells with the same
    faces that no lens lets collapse ((8, 4): two 3-cells that are the faces of a 4-cell of two).

    Coning a j-cell Z from a new vertex p (at the mean of Z's vertices) replaces Z, in every cell it
    bounds, by the cones over its faces; each cell G of Z's boundary gets its cone, a (dim G + 1)-cell
    with faces G and the cones over G's faces.  Z's boundary is a sphere S, so chi changes by
    1 - chi(S) - (-1)^j = 0, and every boundary that was a sphere is still one (a subdivision).  A cone
    over a regular (j-1)-cell of at least j faces has at least j + 1 faces, and cones over different
    cells differ.  So at dimension r: an r-cell of fewer than r + 1 faces has one of its faces B coned
    (it gets |faces(B)| - 1 >= r - 1 more), then of r-cells with the same faces all but the first are
    coned themselves.  Coning a face keeps different cells different; higher cells only gain faces.

    vertices (V, n), edges (E, 2), cells {r: (offsets, faces)} as in CellComplex (after `_regular`).
    Returns (vertices, edges, cells, coned): the arrays (the inputs where nothing is coned), and the
    number of cells coned.  Kept cells keep their order; new ids follow the old ones, in a fixed order.
    """
    top = max(cells, default=1)
    grid = {1: (2 * np.arange(len(edges) + 1, dtype=np.int64), np.ascontiguousarray(edges, np.int64).ravel())}
    grid.update(cells)
    coned = 0
    for r in range(2, top + 1):
        for _ in range(r):  # (a coned face has at least r faces once the lower dimensions are regular)
            few = _few_faces(grid[r], r + 1)
            if len(few) == 0:
                break
            work = _Coning(vertices, grid)
            for x in few.tolist():
                own = work.row(r, x)
                if len(own) >= r + 1 or len(own) < 2:  # (grown by an earlier cone here; or not a sphere)
                    continue
                # the face to cone: one of no other r-cell first, then the one of most faces, then the last
                # (a whole-ball lens: its second face)
                b = max(enumerate(own), key=lambda iy: (-len(work.cofaces(r - 1, iy[1])),
                                                         len(work.row(r - 1, iy[1])), iy[0]))[1]
                work.cone(r - 1, b)
            if not work.count:
                break
            vertices, grid = work.result()
            coned += work.count
        twins = _same_faces(grid[r])
        if len(twins):
            work = _Coning(vertices, grid)
            for x in twins.tolist():
                work.cone(r, x)
            vertices, grid = work.result()
            coned += work.count
    if not coned:
        return vertices, edges, cells, 0
    off1, f1 = grid.pop(1)
    return vertices, f1.reshape(-1, 2), grid, coned


def _few_faces(csr, least):
    """The cells of a CSR with fewer than `least` distinct faces."""
    offsets, faces = csr
    sizes = np.diff(offsets)
    few = np.flatnonzero(sizes < least)
    if len(few):  # (a face listed twice counts once)
        few = np.array([x for x in few.tolist() if len(np.unique(faces[offsets[x] : offsets[x + 1]])) < least],
                       np.int64)
    return few


def _same_faces(csr):
    """The cells of a CSR whose set of faces an earlier cell has (ascending)."""
    offsets, faces = csr
    if len(offsets) < 3:
        return np.zeros(0, np.int64)
    first: dict = {}
    twins = []
    for x in np.flatnonzero(same_faces_candidates(offsets, faces)).tolist():
        key = frozenset(faces[offsets[x] : offsets[x + 1]].tolist())
        if key in first:
            twins.append(x)
        else:
            first[key] = x
    return np.array(twins, np.int64)


class _Coning:
    """Cells being coned: the CSR of each dimension (1: edges as rows of two vertices) with rows
    rewritten, added and removed on the side, written out by `result`."""

    def __init__(self, vertices, grid):
        self.vertices, self.grid = vertices, grid
        self.points: list = []
        self.rows: dict[int, dict] = {r: {} for r in grid}  # r -> {id: faces}, rewritten or added
        self.added = {r: 0 for r in grid}
        self.removed: dict[int, set] = {r: set() for r in grid}
        # r -> {r-cell: (r+1)-cells added that have it}
        self.extra: dict[int, dict] = {r: {} for r in range(0, max(grid) + 1)}
        self.index: dict = {}
        self.count = 0

    def size(self, r):
        return (len(self.vertices) + len(self.points)) if r == 0 else len(self.grid[r][0]) - 1 + self.added[r]

    def row(self, r, x):
        if x in self.rows[r]:
            return self.rows[r][x]
        offsets, faces = self.grid[r]
        return faces[offsets[x] : offsets[x + 1]].tolist()

    def cofaces(self, r, x):
        """The (r+1)-cells that have the r-cell x now."""
        out = list(self.extra[r].get(x, []))
        if r + 1 in self.grid:
            if r + 1 not in self.index:  # (the original rows' cofaces, sorted once)
                offsets, faces = self.grid[r + 1]
                order = np.argsort(faces, kind="stable")
                owner = np.repeat(np.arange(len(offsets) - 1, dtype=np.int64), np.diff(offsets))[order]
                self.index[r + 1] = (faces[order], owner)
            below, owner = self.index[r + 1]
            lo, hi = np.searchsorted(below, [x, x + 1])
            out += [y for y in owner[lo:hi].tolist() if y not in self.removed[r + 1] and x in self.row(r + 1, y)]
        return sorted(set(out))

    def add(self, r, faces):
        x = self.size(r)
        self.rows[r][x] = faces
        self.added[r] += 1
        for y in faces:
            self.extra[r - 1].setdefault(y, []).append(x)
        return x

    def cone(self, j, z):
        """Replace the j-cell z by the cones over its faces from a new vertex (see `cone_lens_balls`)."""
        closure = {j - 1: sorted(set(self.row(j, z)))}
        for r in range(j - 1, 0, -1):
            closure[r - 1] = sorted({y for x in closure[r] for y in self.row(r, x)})
        at = np.concatenate([self.vertices, np.array(self.points).reshape(-1, self.vertices.shape[1])])
        p = self.size(0)
        self.points.append(at[closure[0]].mean(axis=0))
        apex = {(0, v): self.add(1, [p, v]) for v in closure[0]}
        for r in range(1, j):
            for g in closure[r]:
                apex[(r, g)] = self.add(r + 1, [g] + [apex[(r - 1, y)] for y in self.row(r, g)])
        pieces = [apex[(j - 1, y)] for y in closure[j - 1]]
        for y in self.cofaces(j, z):
            self.rows[j + 1][y] = [w for w in self.row(j + 1, y) if w != z] + pieces
            for w in pieces:
                self.extra[j].setdefault(w, []).append(y)
        self.removed[j].add(z)
        self.count += 1

    def result(self):
        """(vertices, grid) with every change written in; kept ids in order, then the added ones."""
        vertices = np.concatenate([self.vertices, np.array(self.points).reshape(-1, self.vertices.shape[1])]) \
            if self.points else self.vertices
        grid = {}
        new_id = None  # of the dimension below (vertices: none removed)
        for r in sorted(self.grid):
            offsets, faces = self.grid[r]
            m = len(offsets) - 1
            total = m + self.added[r]
            keep = np.ones(total, bool)
            keep[list(self.removed[r])] = False
            sizes = np.zeros(total, np.int64)
            sizes[:m] = np.diff(offsets)
            changed = sorted(self.rows[r])
            sizes[changed] = [len(self.rows[r][x]) for x in changed]
            sizes = sizes[keep]
            out_off = np.zeros(len(sizes) + 1, np.int64)
            np.cumsum(sizes, out=out_off[1:])
            out = np.empty(out_off[-1], np.int64)
            plain = keep[:m].copy()
            plain[[x for x in changed if x < m]] = False
            new_row = np.cumsum(keep) - 1
            # unchanged rows in one gather, the others one by one (few)
            src = np.repeat(plain, np.diff(offsets))
            dst = np.repeat(plain[keep[:m]], sizes[: int(keep[:m].sum())])
            out[np.flatnonzero(np.concatenate([dst, np.zeros(len(out) - len(dst), bool)]))] = faces[src]
            for x in changed:
                if keep[x]:
                    out[out_off[new_row[x]] : out_off[new_row[x] + 1]] = self.rows[r][x]
            if new_id is not None:
                out = new_id[out]
            grid[r] = (out_off, out)
            new_id = new_row
        return vertices, grid


def _lenses(e, inc, r):
    """`collapse_lens_cells`' decisions on the r-cells of the records: (rep, removed), rep maps each
    merged (r-1)-cell key to the one it becomes (`_merged`), removed the lens keys."""
    pairs = np.unique(inc[inc[:, 0] == r][:, 1:], axis=0)  # (X, Y): r-cell X has face Y
    cells, counts = np.unique(pairs[:, 0], return_counts=True)
    lenses = cells[counts == 2]
    rep: dict[int, int] = {}  # a merged face -> the face it became
    removed: set[int] = set()
    if len(lenses) == 0:
        return rep, removed
    two = pairs[np.isin(pairs[:, 0], lenses)].reshape(-1, 2, 2)[:, :, 1]  # A, B of each lens
    wanted = np.unique(two)
    cofaces: dict[int, set[int]] = {}
    for x, y in pairs[np.isin(pairs[:, 1], wanted)].tolist():
        cofaces.setdefault(y, set()).add(x)
    boundary: dict[int, set[int]] = {}
    below = e if r == 2 else inc[inc[:, 0] == r - 1][:, 1:]  # (face, one of its faces or ends)
    for row in np.unique(below[np.isin(below[:, 0], wanted)], axis=0).tolist():
        boundary.setdefault(row[0], set()).update(row[1:])
    for x, (a, b) in zip(lenses.tolist(), two.tolist()):
        a, b = _merged(rep, a), _merged(rep, b)
        if a != b and boundary.get(a, set()) != boundary.get(b, set()):
            continue  # not a lens: two faces that do not close a sphere (left for the checks)
        if a != b and (cofaces[a] & cofaces[b]) - {x} - removed:
            continue
        if a != b and cofaces[a] == {x} and cofaces[b] == {x}:
            continue
        removed.add(x)
        if a != b:
            keep, drop = min(a, b), max(a, b)
            rep[drop] = keep
            cofaces[keep] = (cofaces[keep] | cofaces.pop(drop)) - {x}
    return rep, removed


def cube_euler(tab, records, origin, strides, dims):
    """The Euler characteristic of GCMH's cells in each open face (a `CubeTables` row) of each
    cube of a kernel run (origin (m, n) grid indices), from the run's records
    (`kernels.cell_check.records_cube_euler`): (m, faces)."""
    n, k = tab.n, tab.k
    vk, _, e, c, _ = records
    by_dim = [vk, e[:, 0]] + [c[c[:, 0] == r, 1] for r in range(2, n - k + 1)]
    offsets = np.cumsum([0] + [len(x) for x in by_dim]).astype(np.int64)
    free_of_rank, face_row, _ = _face_maps(n, k)
    return records_cube_euler(np.concatenate(by_dim), offsets, origin @ strides, strides, dims, tab.n_codes,
                                       tab.n_subsets, free_of_rank, face_row, k)


def cubes_with_bad_boundaries(tab, records, origin, strides, dims) -> np.ndarray:
    """(m,) bool: the cubes (origin (m, n) grid indices) that hold the face of a GCMH cell of the
    records whose boundary is not a sphere as `tests/core/naive.structure_problems` tells one: a
    2-cell's edges not one cycle, an r-cell's (r >= 3) faces not a closed connected pseudomanifold
    with a sphere's Euler characteristic.  The default check for n >= 8 (`runner.Grid`), where CMS's
    count in a cube takes a second: GCMH's own records, no Kuhn simplex.  It misses a cell that is not
    a ball but has a sphere's boundary (a disc with a handle) and pieces hidden inside a face."""
    n, k = tab.n, tab.k
    vk, _, e, c, inc = records
    m = len(origin)
    bad_cube = np.zeros(m, bool)
    if m == 0 or len(c) == 0:
        return bad_cube
    free_of_rank = _free_of_rank(n, k)
    # only the cells whose face's anchor lies in a checked cube
    near = np.unique(((origin @ strides)[:, None] + _corner_offsets(n, strides)[None]).ravel())
    ends = {int(x): (int(a), int(b)) for x, a, b in e.tolist()}
    faces_of: dict = {}
    for r, x, y in np.unique(inc, axis=0).tolist():
        faces_of.setdefault((r, x), []).append(y)
    bad = []
    for r, x in np.unique(c, axis=0).tolist():
        face_key = x // int(tab.n_codes[r + k])
        if r < 2 or not _isin(near, face_key // int(tab.n_subsets[r + k])):
            continue
        if not _sphere_boundary(r, faces_of.get((r, x), []), faces_of, ends):
            bad.append((r, face_key))
    for r, face_key in bad:
        dim = r + k
        anchor, rank = divmod(face_key, int(tab.n_subsets[dim]))
        free = int(free_of_rank[dim, rank])
        at = (anchor // strides) % dims
        step = at[None, :] - origin  # the face lies in the cube: 0 or 1 on each axis, 0 on its free axes
        free_axis = ((free >> np.arange(n)) & 1).astype(bool)
        bad_cube |= ((step == 0) | ((step == 1) & ~free_axis[None, :])).all(axis=1)
    return bad_cube


def _corner_offsets(n, strides):
    corners = np.arange(1 << n)
    return (((corners[:, None] >> np.arange(n)) & 1) * strides[None, :]).sum(axis=1)


def _isin(sorted_keys, key):
    i = np.searchsorted(sorted_keys, key)
    return i < len(sorted_keys) and sorted_keys[i] == key


def _sphere_boundary(r, faces, faces_of, ends) -> bool:
    """Whether the (r-1)-cells `faces` (keys) make a sphere as `cubes_with_bad_boundaries` tells one
    (a lens, two faces on one sphere, is one: the assembly collapses or cones it)."""
    if not faces:
        return False
    parent = {y: y for y in faces}
    count: dict = {}
    for y in faces:
        for z in (ends[y] if r == 2 else faces_of.get((r - 1, y), [])):
            count[z] = count.get(z, 0) + 1
            parent.setdefault(("f", z), ("f", z))
            _union(parent, y, ("f", z))
    if any(v != 2 for v in count.values()) or len({_root(parent, y) for y in faces}) != 1:
        return False
    if r == 2:
        return True
    closure = {r - 1: set(faces)}
    for d in range(r - 1, 1, -1):
        closure[d - 1] = {z for y in closure[d] for z in faces_of.get((d, y), [])}
    closure[0] = {v for y in closure.get(1, ()) for v in ends.get(y, ())}
    chi = sum((-1) ** d * len(ids) for d, ids in closure.items())
    return chi == 1 + (-1) ** (r - 1)


def cms_cube_euler(tab, values, cube_row, corner_row, lo, hi):
    """CMS's count in each open face of each cube lo..hi-1 and the pieces of M_A hidden inside
    each open face (`kernels.cell_check.cube_euler_chunk`): (euler, hidden), each (hi - lo, faces).
    For n >= 8 each cube's own Kuhn table (`kuhn_cube`); a cube whose table would be too large
    gets the count UNCOUNTED in every face (so no GCMH count equals it: it is flagged, and its
    refinement declines)."""
    if tab.kuhn.corners.shape[0]:
        return _CubeKuhn.whole(tab).euler(values, cube_row[lo:hi], corner_row)
    euler = np.zeros((hi - lo, len(tab.face_free)), np.int64)
    hidden = np.zeros_like(euler)
    for i in range(lo, hi):
        own = _CubeKuhn.of(tab, values, cube_row[i], corner_row)
        if own is None:
            euler[i - lo] = UNCOUNTED
        else:
            euler[i - lo], hidden[i - lo] = (x[0] for x in own.euler(values, cube_row[i : i + 1], corner_row))
    return euler, hidden


UNCOUNTED = -(2**40)  # `cms_cube_euler`'s count where a cube's table is too large to build


class _CubeKuhn:
    """A cube's Kuhn simplices for CMS: the whole table (n <= 7, one for every cube) or the cube's
    own (n >= 8, `kernels.kuhn_cube`: the chains M_A may cross, keyed alike), with the face of the
    cube each simplex's relative interior lies in (carrier) and each simplex's cofaces."""

    def __init__(self, tab, kuhn, carrier, cofaces):
        self.tab, self.kuhn, self.carrier, self.cofaces = tab, kuhn, carrier, cofaces

    @classmethod
    def of(cls, tab, values, row, corner_row):
        """For the cube whose corner c is row row + corner_row[c] of values; None where its own
        table would be too large."""
        n, k = tab.n, tab.k
        if tab.kuhn.corners.shape[0]:
            return cls.whole(tab)
        kuhn = cube_simplex_tables(n, k, values, int(row), np.ascontiguousarray(corner_row, np.int64))
        if kuhn is None:
            return None
        return cls(tab, kuhn, *cls.of_table(tab, kuhn))

    @staticmethod
    def of_table(tab, kuhn):
        """(carrier, cofaces) of a cube's own table."""
        return _carriers(kuhn, _face_maps(tab.n, tab.k)[1]), _cofaces_of(kuhn)

    @classmethod
    def whole(cls, tab):
        """The whole table's (n <= 7)."""
        return cls(tab, tab.kuhn, _face_maps(tab.n, tab.k)[2], _cofaces(tab.n, tab.k))

    def euler(self, values, cube_row, corner_row):
        """`cube_euler_chunk` on the cubes of cube_row (for the cube's own table: that cube alone)."""
        tab = self.tab
        return cube_euler_chunk(0, len(cube_row), values, np.ascontiguousarray(cube_row, np.int64),
                                np.ascontiguousarray(corner_row, np.int64), self.kuhn, self.carrier,
                                len(tab.face_free), _face_dims(tab.n, tab.k), *self.cofaces)


@lru_cache(maxsize=16)
def _cofaces(n, k):
    """The whole Kuhn table's `_cofaces_of`."""
    return _cofaces_of(cube_tables(n, k).kuhn)


def _cofaces_of(kuhn):
    """The Kuhn simplices that have each simplex as a facet, as CSR (start per simplex row, list)."""
    k, n = kuhn.k, kuhn.n
    rows = np.arange(kuhn.start[k + 1], kuhn.start[n + 1])
    facets = kuhn.facets[rows]
    owner = np.broadcast_to(rows[:, None], facets.shape)
    has = facets >= 0
    order = np.argsort(facets[has], kind="stable")
    below, above = facets[has][order], owner[has][order]
    start = np.searchsorted(below, np.arange(kuhn.start[n + 1] + 1)).astype(np.int64)
    return start, np.ascontiguousarray(above, np.int64)


@lru_cache(maxsize=16)
def _face_dims(n, k):
    """The dimension of each `CubeTables` face row."""
    tab = cube_tables(n, k)
    return np.array([bin(int(x)).count("1") for x in tab.face_free], np.int64)


@lru_cache(maxsize=16)
def _face_maps(n, k):
    """[dim, rank] -> free axes (bits) of the faces of that dimension and rank; [free, fixed] -> the
    `CubeTables` row of that face (-1: none); Kuhn simplex row -> the row of the face whose relative
    interior holds it (`_carriers`; n >= 8: empty, each cube has its own table)."""
    tab = cube_tables(n, k)
    free_of_rank = _free_of_rank(n, k)
    face_row = -np.ones((1 << n, 1 << n), np.int64)
    face_row[tab.face_free, tab.face_fixed] = np.arange(len(tab.face_free))
    return free_of_rank, face_row, _carriers(tab.kuhn, face_row)


@lru_cache(maxsize=16)
def _free_of_rank(n, k):
    """[dim, rank] -> free axes (bits) of the faces of that dimension and rank (`_face_maps`' first map,
    without its 4^n face rows: n = 12 runs check cells' boundaries too)."""
    tab = cube_tables(n, k)
    free_of_rank = np.zeros((n + 1, int(tab.n_subsets.max())), np.int64)
    for dim in range(k, n + 1):
        faces = slice(tab.face_start[dim], tab.face_start[dim + 1])
        free_of_rank[dim, tab.face_rank[faces]] = tab.face_free[faces]
    return free_of_rank


def _carriers(kuhn, face_row):
    """Kuhn simplex row -> the `CubeTables` row of the face whose relative interior holds it (its
    chain's first and last corners give it; rows below dimension k: 0)."""
    k, n = kuhn.k, kuhn.n
    rows = np.arange(kuhn.start[n + 1])
    dims = np.searchsorted(kuhn.start, rows, side="right") - 1
    carrier = np.zeros(len(rows), np.int64)
    mine = rows >= kuhn.start[k]
    last = kuhn.corners[rows[mine], dims[mine]]
    carrier[mine] = face_row[last & ~kuhn.c0[mine], kuhn.c0[mine]]
    return carrier
