"""Collapse lens cells: no 2-cell bounded by two edges, no two edges with the same ends.

Where a cell's piece of M_A touches one k-face at two points, the cube's cell gets
a "lens": a 2-cell bounded by two edges that join the same two vertices.  As a CW
complex that is legal, but as a polygon mesh it is a zero-area face with a doubled
edge, which mesh tools and PLY/OBJ readers reject.  Collapsing the lens onto one of
its edges removes one edge and one 2-cell, so the Euler characteristic (and the
homotopy type) is unchanged: the two edges become one, every other cell that had
either edge now has the kept one, and the r-cells (r >= 3) that had the lens as a
face lose that face.

A lens is left alone, and counted, when some other 2-cell has both of its edges
(merging them would fold that cell onto itself); none has been seen in practice.  A lens
whose two edges are in no other 2-cell is a whole disc (M_A's small cap on the box's
boundary): collapsing it would leave an edge in no 2-cell and lose a boundary circle, so it
stays, and `subdivide_double_edges` makes it a triangle.

When the complex has 3-cells, `_balls.collapse_lens_cells` has already made these decisions on
the assembly's records, before the lens 3-cells (a merge of two edges must come before the 3-cells
are compared): what is left here are the lenses it left.  What neither can collapse is coned
(`_balls.cone_lens_balls`).

Two edges with the same ends and no lens between them (a small closed curve of two
edges, or the two edges of a loop that `_balls` split between two cells) are made
distinct by `subdivide_double_edges`: a new vertex halves one of them, and every
2-cell that had it has both halves.  One vertex and one edge more: chi is unchanged.
"""

from __future__ import annotations

import numpy as np

__all__ = ["collapse_lenses", "subdivide_double_edges"]


def collapse_lenses(edges: np.ndarray, cells: dict) -> tuple[np.ndarray, dict, int, int]:
    """Collapse every lens 2-cell.

    edges (E, 2) int64; cells {r: (offsets, faces)} for r >= 2 (CSR, as in CellComplex).
    Returns (edges, cells, collapsed, left): the new arrays (the input's when there is
    no lens), the number of lenses collapsed and the number that could not be.
    Ids of what is kept stay in their order, so the result is as deterministic as the input.
    """
    if 2 not in cells:
        return edges, cells, 0, 0
    offsets, faces = cells[2]
    sizes = np.diff(offsets)
    lenses = np.flatnonzero(sizes == 2)
    if len(lenses) == 0:
        return edges, cells, 0, 0
    rep = np.arange(len(edges), dtype=np.int64)  # each edge's kept edge (union-find, shallow)

    def find(e: int) -> int:
        while rep[e] != e:
            rep[e] = rep[rep[e]]
            e = int(rep[e])
        return e

    # the 2-cells of each edge, only for the edges of lenses (few)
    owner = np.repeat(np.arange(len(sizes), dtype=np.int64), sizes)
    wanted = np.unique(faces[offsets[lenses][:, None] + np.arange(2)])
    hit = np.isin(faces, wanted)
    cofaces: dict[int, set[int]] = {}
    for e, c in zip(faces[hit].tolist(), owner[hit].tolist()):
        cofaces.setdefault(e, set()).add(c)
    removed = np.zeros(len(sizes), bool)
    collapsed = left = 0
    for c in lenses.tolist():
        a, b = (find(int(e)) for e in faces[offsets[c] : offsets[c] + 2])
        if a != b and sorted(edges[a].tolist()) != sorted(edges[b].tolist()):
            left += 1  # two edges that do not close a loop: not a lens, leave it for the checks
            continue
        others = (cofaces[a] & cofaces[b]) - {c} if a != b else set()
        if any(not removed[o] for o in others):
            left += 1
            continue
        if a != b and cofaces[a] == {c} and cofaces[b] == {c}:
            # a whole disc of two edges (M_A's small cap on the box's boundary): collapsing it would
            # leave an edge in no 2-cell and lose a boundary circle; halving an edge makes it a triangle
            continue
        removed[c] = True
        collapsed += 1
        if a != b:
            keep, drop = min(a, b), max(a, b)
            rep[drop] = keep
            cofaces[keep] = (cofaces[keep] | cofaces.pop(drop)) - {c}
    if collapsed == 0:
        return edges, cells, 0, left
    # every edge straight to its kept edge: path halving leaves a chain of three or more merges pointing
    # part way (3 -> 1 -> 0 after find(3)), and new_edge[rep] must name the kept edge itself
    while True:
        up = rep[rep]
        if np.array_equal(up, rep):
            break
        rep = up
    kept_edge = rep == np.arange(len(rep))
    new_edge = np.cumsum(kept_edge) - 1
    out = {}
    keep_cell = ~removed
    faces2 = new_edge[rep[faces]]
    out[2] = _csr_subset(offsets, faces2, keep_cell)
    new_cell = np.cumsum(keep_cell) - 1
    if 3 in cells:
        off3, faces3 = cells[3]
        alive = keep_cell[faces3]
        owner3 = np.repeat(np.arange(len(off3) - 1, dtype=np.int64), np.diff(off3))
        off = np.zeros(len(off3), np.int64)
        np.cumsum(np.bincount(owner3[alive], minlength=len(off3) - 1), out=off[1:])
        out[3] = (off, new_cell[faces3[alive]].astype(np.int64))
    for r in cells:
        if r > 3:
            out[r] = cells[r]
    return np.ascontiguousarray(edges[kept_edge]), out, collapsed, left


def _csr_subset(offsets: np.ndarray, faces: np.ndarray, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows `keep` of a CSR (offsets, faces), faces already renumbered."""
    sizes = np.diff(offsets)
    row_of = np.repeat(keep, sizes)
    off = np.zeros(int(keep.sum()) + 1, np.int64)
    np.cumsum(sizes[keep], out=off[1:])
    return off, np.ascontiguousarray(faces[row_of], np.int64)


def subdivide_double_edges(vertices: np.ndarray, edges: np.ndarray, cells: dict):
    """Halve every edge that has the same two ends as an edge before it (in id order).

    vertices (V, n); edges (E, 2); cells {r: (offsets, faces)}.  The new vertex is the
    edge's midpoint (the edge is drawn as that segment anyway); it and the second half
    get the next ids, in the order of the halved edges.  Returns (vertices, edges,
    cells, halved).
    """
    if len(edges) < 2:
        return vertices, edges, cells, 0
    # an edge's two ends as one integer (lower * V + higher: V^2 < 2^63 for V < 3e9), sorted stably so that
    # each run of equal ends is in id order; one key sort, not a lexsort of three keys and row compares
    # (7 -> 1.7 ms CPU on the 49,000 edges of the complex cosine's GCCH at div 80, every run pays it)
    key = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64) * len(vertices) + np.maximum(edges[:, 0], edges[:, 1])
    order = np.argsort(key, kind="stable")
    key = key[order]
    same = np.zeros(len(edges), bool)
    same[order[1:]] = key[1:] == key[:-1]
    halved = np.flatnonzero(same)
    if len(halved) == 0:
        return vertices, edges, cells, 0
    mid = len(vertices) + np.arange(len(halved), dtype=np.int64)
    vertices = np.concatenate([vertices, 0.5 * (vertices[edges[halved, 0]] + vertices[edges[halved, 1]])])
    second = len(edges) + np.arange(len(halved), dtype=np.int64)
    edges = edges.copy()
    tail = np.stack([mid, edges[halved, 1]], axis=1)
    edges[halved, 1] = mid
    edges = np.concatenate([edges, tail])
    out = dict(cells)
    if 2 in cells:
        offsets, faces = cells[2]
        other = np.full(len(key), -1, np.int64)  # (the edges before halving)
        other[halved] = second
        extra = other[faces]
        owner = np.repeat(np.arange(len(offsets) - 1, dtype=np.int64), np.diff(offsets))
        grown = np.concatenate([faces, extra[extra >= 0]])
        owner = np.concatenate([owner, owner[extra >= 0]])
        rows = np.argsort(owner, kind="stable")
        off = np.zeros(len(offsets), np.int64)
        np.cumsum(np.bincount(owner, minlength=len(offsets) - 1), out=off[1:])
        out[2] = (off, np.ascontiguousarray(grown[rows], np.int64))
    return vertices, edges, out, len(halved)
