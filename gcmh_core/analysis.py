"""Analysis of an extracted complex: orientation of surfaces, a topology report,
and Gauss-Newton refinement of the vertices onto M.

Plain numpy on the public arrays of :class:`~gcmh_core.complex.CellComplex`
(no Qt, no VTK).  Public functions validate their arguments and raise
:class:`~gcmh_core.errors.InputError` with a specific message; private helpers
do the work, vectorised (no Python loop over cells).

Examples
--------
>>> from gcmh_core import extract
>>> cx = extract("x^2 + y^2 + z^2 - 1", bounds=(-1.5, 1.5), div=8, variables="x, y, z")
>>> orient_2cells(cx).consistent
True
>>> topology_report(cx)["euler_characteristic"]
2
"""

from __future__ import annotations

import operator
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .complex import CellComplex, _component_roots
from .errors import InputError
from .newton import gauss_newton

if TYPE_CHECKING:
    from .formula import System

__all__ = ["Orientation", "boundary_components", "graph_components", "orient_2cells", "refine_vertices",
           "topology_report"]


# ----------------------------------------------------------------------------
# graph components (vectorised union-find: hook roots to smaller labels, then jump)
# ----------------------------------------------------------------------------

def graph_components(n_nodes: int, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, int]:
    """Connected components of the graph with nodes 0..n_nodes-1 and edges (a[i], b[i]).

    Parameters
    ----------
    n_nodes : int
    a, b : (m,) integer arrays of node ids.

    Returns
    -------
    labels : (n_nodes,) int64
        Component id of each node, numbered 0.. in order of each component's
        smallest node.
    n_components : int
    """
    n_nodes = operator.index(n_nodes)
    a = np.asarray(a, dtype=np.int64).ravel()
    b = np.asarray(b, dtype=np.int64).ravel()
    if a.shape != b.shape:
        raise InputError(f"edge ends must have the same shape, got {a.shape} and {b.shape}")
    if a.size and (min(a.min(), b.min()) < 0 or max(a.max(), b.max()) >= n_nodes):
        raise InputError(f"edge ends must be node ids in 0..{n_nodes - 1}")
    root = _component_roots(n_nodes, a, b)
    # renumber roots (each the smallest node of its component) as 0, 1, ...
    is_root = root == np.arange(n_nodes)
    number = np.cumsum(is_root) - 1
    return number[root].astype(np.int64), int(is_root.sum())


# ----------------------------------------------------------------------------
# orientation of 2-dimensional results
# ----------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Orientation:
    """A coherent choice of winding for the 2-cells of a surface.

    Attributes
    ----------
    offsets : (F + 1,) int64
    vertices : (offsets[-1],) int64
        The vertex loop of 2-cell ``i`` is ``vertices[offsets[i]:offsets[i+1]]``,
        in its chosen winding: ``cx.polygons()``, some loops reversed.
    consistent : bool
        True when every interior edge (exactly two polygons on it) is run
        through in opposite directions by its two polygons.
    n_flipped : int
        Number of loops reversed relative to ``cx.polygons()``.
    flipped : (F,) bool
        Which loops were reversed (also :meth:`flip_mask`).
    component : (F,) int64
        Component of each polygon in the dual graph (polygons joined through
        interior edges), numbered 0.. in order of their smallest polygon.
    n_components : int
    component_consistent : (n_components,) bool
        Per component: no interior edge of it runs the same way twice.
    conflict_edges : (c,) int64
        Interior edges run through in the same direction by both polygons
        (empty when consistent).  Non-empty for a Moebius strip, whatever the
        choice of windings; which edges, and how many, depend on the order of
        the search (any edge set in the class dual to w1 can come out).  The
        loop :func:`gcmh_core.homology` gives as ``orientation_cycle`` is that
        class shortened: the one the app draws and counts.
    nonmanifold_edges : (m,) int64
        Edges with three or more polygons on them (not used for orientation).
    """

    offsets: np.ndarray
    vertices: np.ndarray
    consistent: bool
    n_flipped: int
    flipped: np.ndarray
    component: np.ndarray
    n_components: int
    component_consistent: np.ndarray
    conflict_edges: np.ndarray
    nonmanifold_edges: np.ndarray

    def flip_mask(self) -> np.ndarray:
        """(F,) bool: True for the polygons reversed relative to ``cx.polygons()``."""
        return self.flipped.copy()

    def loops(self) -> list[np.ndarray]:
        """The oriented loops as a list of int64 arrays (for small complexes and tests)."""
        return np.split(self.vertices, self.offsets[1:-1])


def _check_complex(cx, what):
    if not isinstance(cx, CellComplex):
        raise InputError(f"{what} needs a CellComplex, got {type(cx).__name__}")


def orient_2cells(cx: CellComplex) -> Orientation:
    """Orient the polygons of a 2-dimensional complex coherently, component by component.

    Starting from the loops of :meth:`CellComplex.polygons`, a breadth-first
    search over the dual graph (polygons adjacent through edges with exactly
    two polygons on them) reverses loops so that each interior edge is run
    through in opposite directions by its two polygons.  Where that is
    impossible (a non-orientable surface) the conflicting edges are reported.

    Parameters
    ----------
    cx : CellComplex with ``cx.dim == 2`` (n - k == 2).

    Returns
    -------
    Orientation

    Raises
    ------
    InputError
        If `cx` is not a CellComplex or its dimension is not 2 (orientation of
        higher-dimensional cells is not defined by vertex loops).
    """
    _check_complex(cx, "orient_2cells")
    if cx.dim != 2:
        raise InputError(
            f"orient_2cells orients surfaces (n - k = 2); this complex has dimension "
            f"{cx.dim} (n = {cx.n}, k = {cx.k})")
    return _orient(cx)


def _incidence_signs(cx, offsets, loop):
    """For each face entry j of ``cx.cells[2]`` (polygon p, edge e = (u, v)): +1 if p's
    loop runs u -> v, -1 if v -> u, 0 if the loop does not run along e (degenerate cell).

    Loop steps are matched to face entries by (polygon, vertex pair, rank among equal
    pairs): a 2-cell bounded by two edges with the same two ends (a bigon) then gets
    one edge each way, as its loop does.
    """
    off2, fac2 = cx.cells[2]
    n_poly = off2.size - 1
    lengths = np.diff(offsets)
    # loop steps: position -> next position, cyclically within each loop
    owner = np.repeat(np.arange(n_poly, dtype=np.int64), lengths)
    nxt = np.arange(1, loop.size + 1, dtype=np.int64)
    ends = offsets[1:][lengths > 0] - 1
    nxt[ends] = offsets[:-1][lengths > 0]
    tail, head = loop, loop[nxt]
    fac2 = np.asarray(fac2, dtype=np.int64)
    inc_owner = np.repeat(np.arange(n_poly, dtype=np.int64), np.diff(off2))
    eu, ev = cx.edges[fac2, 0], cx.edges[fac2, 1]

    m_steps, m_inc = tail.size, fac2.size
    own = np.concatenate([owner, inc_owner])
    lo = np.concatenate([np.minimum(tail, head), np.minimum(eu, ev)])
    hi = np.concatenate([np.maximum(tail, head), np.maximum(eu, ev)])
    source = np.concatenate([np.zeros(m_steps, np.int8), np.ones(m_inc, np.int8)])
    # rank of each item among the items of its source with the same (owner, lo, hi)
    order = np.lexsort((source, hi, lo, own))
    o_own, o_lo, o_hi, o_src = own[order], lo[order], hi[order], source[order]
    new_group = np.ones(order.size, dtype=bool)
    new_group[1:] = (o_own[1:] != o_own[:-1]) | (o_lo[1:] != o_lo[:-1]) | (o_hi[1:] != o_hi[:-1]) \
        | (o_src[1:] != o_src[:-1])
    start = np.maximum.accumulate(np.where(new_group, np.arange(order.size), 0))
    rank = np.empty(order.size, dtype=np.int64)
    rank[order] = np.arange(order.size) - start
    # sort by (owner, lo, hi, rank, source): a matched step and face entry are neighbours
    order = np.lexsort((source, rank, hi, lo, own))
    key_same = np.ones(max(order.size - 1, 0), dtype=bool)
    for arr in (own, lo, hi, rank):
        key_same &= arr[order][1:] == arr[order][:-1]
    pair = np.flatnonzero(key_same & (source[order][:-1] == 0) & (source[order][1:] == 1))
    step_i = order[pair]
    inc_i = order[pair + 1] - m_steps
    sign = np.zeros(m_inc, dtype=np.int64)
    sign[inc_i] = np.where(tail[step_i] == eu[inc_i], 1, -1)
    return inc_owner, fac2, sign


def _orient(cx):
    offsets, loop = cx.polygons()
    offsets = np.asarray(offsets, dtype=np.int64)
    loop = np.asarray(loop, dtype=np.int64)
    n_poly = offsets.size - 1
    inc_poly, inc_edge, sign = _incidence_signs(cx, offsets, loop)

    # interior edges: exactly two incidences; pair them up by sorting on the edge
    cof = np.bincount(inc_edge, minlength=cx.count(1))
    interior = cof[inc_edge] == 2
    order = np.argsort(inc_edge[interior], kind="stable")
    ip, ie, isg = inc_poly[interior][order], inc_edge[interior][order], sign[interior][order]
    p, q = ip[0::2], ip[1::2]
    sp, sq = isg[0::2], isg[1::2]
    dual_edge = ie[0::2]
    # a polygon glued to itself (both incidences one polygon) is no dual edge; nor is an
    # edge a degenerate loop skips (sign 0): those stay in the conflict check below
    usable = (p != q) & (sp != 0) & (sq != 0)
    # relation: p and q must end with different flip states iff they run e the same way
    same_way = sp == sq

    comp, n_comp = graph_components(n_poly, p[usable], q[usable])
    flipped = _bfs_flips(n_poly, p[usable], q[usable], same_way[usable], comp, n_comp)

    eff_p = sp * np.where(flipped[p], -1, 1)
    eff_q = sq * np.where(flipped[q], -1, 1)
    bad = (eff_p == eff_q) | (sp == 0) | (sq == 0)
    conflict_edges = np.sort(dual_edge[bad])
    comp_ok = np.ones(n_comp, dtype=bool)
    comp_ok[comp[p[bad]]] = False
    comp_ok[comp[q[bad]]] = False

    new_loop = _reverse_segments(offsets, loop, flipped)
    return Orientation(
        offsets=_ro(offsets), vertices=_ro(new_loop), consistent=bool(not bad.any()),
        n_flipped=int(flipped.sum()), flipped=_ro(flipped), component=_ro(comp),
        n_components=int(n_comp), component_consistent=_ro(comp_ok),
        conflict_edges=_ro(conflict_edges.astype(np.int64)),
        nonmanifold_edges=_ro(np.flatnonzero(cof > 2).astype(np.int64)),
    )


def _ro(arr):
    arr = np.array(arr)  # own copy: the caller's arrays stay theirs
    arr.flags.writeable = False
    return arr


def _bfs_flips(n_poly, p, q, same_way, comp, n_comp):
    """Level-synchronous BFS from the smallest polygon of every component at once.

    p, q, same_way: (m,) dual edges and whether the two loops run their shared
    edge the same way (then exactly one of them must be reversed).
    Returns flipped (n_poly,) bool.
    """
    # CSR adjacency, both directions
    src = np.concatenate([p, q])
    dst = np.concatenate([q, p])
    rel = np.concatenate([same_way, same_way])
    order = np.argsort(src, kind="stable")
    dst, rel = dst[order], rel[order]
    ptr = np.zeros(n_poly + 1, dtype=np.int64)
    np.cumsum(np.bincount(src, minlength=n_poly), out=ptr[1:])

    flipped = np.zeros(n_poly, dtype=bool)
    seen = np.zeros(n_poly, dtype=bool)
    # seeds: first polygon of each component
    first = np.full(n_comp, n_poly, dtype=np.int64)
    np.minimum.at(first, comp, np.arange(n_poly, dtype=np.int64))
    frontier = first[first < n_poly]
    seen[frontier] = True
    while frontier.size:
        starts, counts = ptr[frontier], ptr[frontier + 1] - ptr[frontier]
        total = int(counts.sum())
        if total == 0:
            break
        rep = np.repeat(np.arange(frontier.size), counts)
        idx = starts[rep] + np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
        nbr = dst[idx]
        fresh = ~seen[nbr]
        nbr, parent, r = nbr[fresh], frontier[rep[fresh]], rel[idx[fresh]]
        # a polygon reached from two parents in one wave takes the first; the other
        # edge is checked afterwards like every non-tree edge
        nbr, first_hit = np.unique(nbr, return_index=True)
        flipped[nbr] = flipped[parent[first_hit]] ^ r[first_hit]
        seen[nbr] = True
        frontier = nbr
    return flipped


def _reverse_segments(offsets, loop, flipped):
    """Reverse the CSR segments of `loop` whose polygon is flipped."""
    lengths = np.diff(offsets)
    owner = np.repeat(np.arange(lengths.size, dtype=np.int64), lengths)
    pos = np.arange(loop.size, dtype=np.int64)
    start, end = offsets[:-1][owner], offsets[1:][owner] - 1
    src = np.where(flipped[owner], start + end - pos, pos)
    return loop[src]


# ----------------------------------------------------------------------------
# topology report
# ----------------------------------------------------------------------------

def _check_system(cx, system, what):
    if system is None:
        return
    for attr in ("n", "k", "evaluate_points", "jacobian_points"):
        if not hasattr(system, attr):
            raise InputError(f"{what}: system must be a gcmh_core.formula.System (missing {attr!r})")
    if (system.n, system.k) != (cx.n, cx.k):
        raise InputError(
            f"{what}: the system maps R^{system.n} -> R^{system.k}, but the complex lives in "
            f"R^{cx.n} with codimension {cx.k}")


def boundary_components(cx: CellComplex) -> int:
    """Number of connected components of the boundary (dim-1)-complex of `cx`.

    The boundary is the union of the (dim-1)-cells with exactly one top-cell
    on them; two of them are connected when they share a vertex.  For a curve
    (dim 1) every end point is its own component; for dim 0 the answer is 0.
    """
    _check_complex(cx, "boundary_components")
    return _boundary_components(cx)


def _boundary_components(cx):
    facets = cx.boundary_facets()
    if cx.dim <= 1 or facets.size == 0:
        return int(facets.size) if cx.dim == 1 else 0
    off, ids = cx.cell_vertices(cx.dim - 1)
    starts, counts = off[facets], off[facets + 1] - off[facets]
    total = int(counts.sum())
    rep = np.repeat(np.arange(facets.size), counts)
    idx = starts[rep] + np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
    verts = ids[idx]
    # chain the vertices of each facet: consecutive entries of one facet are joined
    same = rep[1:] == rep[:-1]
    a, b = verts[:-1][same], verts[1:][same]
    used = np.unique(verts)
    local = np.searchsorted(used, np.concatenate([a, b]))
    _, n = graph_components(used.size, local[: a.size], local[a.size:])
    return n


def topology_report(cx: CellComplex, system: System | None = None) -> dict:
    """Facts about an extracted complex, for a panel or a log.

    Parameters
    ----------
    cx : CellComplex
    system : gcmh_core.formula.System, optional
        F itself; when given, ``max_abs_F`` is the largest |F_j| over the vertices.

    Returns
    -------
    dict with keys
        ``n``, ``k``, ``dim`` (ints); ``counts`` (list of dim+1 ints, cells by
        dimension); ``euler_characteristic`` (int); ``connected_components``
        (int, of the 1-skeleton); ``boundary_facets`` (int, (dim-1)-cells on
        one top cell); ``boundary_components`` (int); ``closed`` (bool, no
        boundary facets and at least one cell); ``max_abs_F`` (float or None);
        ``nonfinite_vertices`` (int); ``timings`` (dict phase -> seconds, from
        ``cx.meta['timings']``); ``seconds`` (float or None, total);
        ``orientation`` (None unless dim == 2, else a dict with ``consistent``,
        ``n_flipped``, ``n_components``, ``orientable_components``,
        ``conflict_edges`` and ``nonmanifold_edges`` (counts; conflict_edges
        depends on the search order: see :class:`Orientation`)).
    """
    _check_complex(cx, "topology_report")
    _check_system(cx, system, "topology_report")
    counts = cx.counts()
    nb = int(cx.boundary_facets().size)
    report = {
        "n": cx.n, "k": cx.k, "dim": cx.dim,
        "counts": [int(c) for c in counts],
        "euler_characteristic": int(cx.euler_characteristic()),
        "connected_components": int(cx.connected_components()),
        "boundary_facets": nb,
        "boundary_components": _boundary_components(cx),
        "closed": bool(nb == 0 and counts[0] > 0),
        "max_abs_F": None,
        "nonfinite_vertices": int(np.count_nonzero(~np.isfinite(cx.vertices).all(axis=1))),
    }
    if system is not None:
        report["max_abs_F"] = _max_abs_F(system, np.asarray(cx.vertices))
    timings = cx.meta.get("timings") or {}
    report["timings"] = {str(k): float(v) for k, v in dict(timings).items()
                         if isinstance(v, (int, float, np.number))}
    seconds = cx.meta.get("seconds")
    report["seconds"] = float(seconds) if isinstance(seconds, (int, float, np.number)) else None
    report["orientation"] = None
    if cx.dim == 2:
        o = _orient(cx)
        report["orientation"] = {
            "consistent": o.consistent,
            "n_flipped": o.n_flipped,
            "n_components": o.n_components,
            "orientable_components": int(o.component_consistent.sum()),
            "conflict_edges": int(o.conflict_edges.size),
            "nonmanifold_edges": int(o.nonmanifold_edges.size),
        }
    return report


# ----------------------------------------------------------------------------
# refinement onto M
# ----------------------------------------------------------------------------

def _max_abs_F(system, X):
    """Largest |F_j| over the rows of X with finite values (nan if there are none)."""
    if X.shape[0] == 0:
        return 0.0
    values = np.abs(system.evaluate_points(X))
    finite = np.isfinite(values).all(axis=1)
    return float(values[finite].max()) if finite.any() else float("nan")


def refine_vertices(cx: CellComplex, system: System, steps: int = 3) -> tuple[CellComplex, float, float]:
    """Move every vertex closer to M by Gauss-Newton steps ``x <- x - J(x)^+ F(x)``.

    ``J^+`` is the Moore-Penrose pseudo-inverse of the exact Jacobian (k, n),
    so each step is the shortest move that zeroes the linearised F.  A vertex
    only takes a step that lowers its |F| (near singular points of M a full
    step may overshoot); vertices with non-finite F or J stay put.  The cells
    are unchanged.

    Parameters
    ----------
    cx : CellComplex
    system : gcmh_core.formula.System
        The F that `cx` approximates (``system.n == cx.n``, ``system.k == cx.k``).
    steps : int, default 3
        Number of Gauss-Newton steps, 0 <= steps <= 100.

    Returns
    -------
    refined : CellComplex
        Same cells, vertices (V, n) float64 moved; ``meta`` is a copy of
        ``cx.meta`` with ``refined_steps`` and ``max_abs_F`` added.
    max_abs_F_before, max_abs_F_after : float
        Largest |F_j| over the vertices before and after.
    """
    _check_complex(cx, "refine_vertices")
    if system is None:
        raise InputError("refine_vertices needs the system F (gcmh_core.formula.parse_system)")
    _check_system(cx, system, "refine_vertices")
    if isinstance(steps, (bool, np.bool_)):
        raise InputError(f"steps must be an int, got {steps!r}")
    try:
        steps = operator.index(steps)
    except TypeError:
        raise InputError(f"steps must be an int, got {steps!r}") from None
    if not 0 <= steps <= 100:
        raise InputError(f"steps must be in 0..100, got {steps}")
    X = np.array(cx.vertices, dtype=np.float64)
    before = _max_abs_F(system, X)
    X = gauss_newton(system, X, steps).x  # only steps that lower |F|: the vertex stays near its cell
    after = _max_abs_F(system, X)
    meta = dict(cx.meta)
    meta["refined_steps"] = int(meta.get("refined_steps", 0)) + steps
    meta["max_abs_F"] = after
    cells = {r: cx.cells[r] for r in range(2, cx.dim + 1)}
    refined = CellComplex(cx.n, cx.k, X, cx.edges, cells, meta)
    return refined, before, after
