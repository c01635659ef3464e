"""Integer homology of an extracted complex: Betti numbers over Q and Z/2, torsion,
generating cycles, and the loop along which a surface's orientation reverses.

The cells of a GCMH result are balls (a regular CW complex), so the boundary
matrices over Z need only incidence numbers [c : f] = +-1, found by orienting each
cell consistently with its faces (:func:`incidences`).  The complex is then
reduced by *coreductions* (Mrozek and Batko; CAPD RedHom's CoreductionMorse): a cell
b whose boundary, in what is left, is one cell a is paired with it, and both leave;
when no cell has exactly one face left, a cell with no face left is declared
critical.  The pairs form an acyclic matching (discrete Morse theory), the critical
cells span the *Morse complex*, whose boundary follows the gradient paths
(:func:`_flow`).  On a surface the vertex pairs are a spanning tree and the face pairs a
spanning tree of the dual graph: the tree-cotree decomposition, so the critical
edges are few.  Smith normal form (exact, Python ints) runs only on the Morse complex.

Generators of H1 are short loops (:func:`_short_loops`, Erickson and Whittlesey's greedy
basis from a few roots): each edge's class is read off the Morse complex
(:func:`_edge_classes`), loops closed by shortest-path trees are taken shortest first while
independent mod 2, and their classes are checked to be a basis over Z (else the Smith
form's cycles, straightened across 2-cells, stay: :func:`_shorten`).  H2 generators of a
3-manifold are made smaller across 3-cells the same way.

Example
-------
>>> from gcmh_core import CellComplex
>>> square = CellComplex(2, 0, [[0, 0], [1, 0], [1, 1], [0, 1]],
...                      [[0, 1], [1, 2], [2, 3], [3, 0]], {2: ([0, 4], [0, 1, 2, 3])})
>>> homology(square).describe()
'H0 = Z, H1 = 0, H2 = 0'
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .complex import CellComplex
from .errors import InputError

__all__ = ["Cycle", "Homology", "homology", "incidences", "summary", "summary_line"]


# ----------------------------------------------------------------------------
# results
# ----------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Cycle:
    """A cycle of the complex: ``sum(coefficients[i] * cell cells[i])`` over dim-cells.

    ``order`` is 0 for a generator of a free summand Z, else the order s of the cyclic
    summand Z/s it generates.
    """

    dim: int
    cells: np.ndarray         # (m,) int64 ids of dim-cells
    coefficients: np.ndarray  # (m,) int64, nonzero
    order: int = 0

    def __len__(self) -> int:
        return int(self.cells.size)


@dataclass(frozen=True, eq=False)
class Homology:
    """Homology of a cell complex with integer coefficients.

    Attributes
    ----------
    betti : list of int
        Betti numbers over Q, b_0 .. b_dim.
    betti_mod2 : list of int
        Dimensions of H_q(X; Z/2).
    torsion : list of list of int
        Per dimension, the orders of the cyclic factors of the torsion of H_q(X; Z)
        (invariant factors > 1, ascending): the Klein bottle gives ``[[], [2], []]``.
    generators : list of tuple of Cycle, or None
        Per dimension, cycles generating H_q(X; Z): the free summands first (order 0),
        then the torsion summands.  None when computed with ``generators=False``.
    orientation_cycle : (m,) int64 edge ids, or None
        For a surface that is not orientable: the edges across which the orientation
        :attr:`orientation` chooses flips (a Z/2 cycle, relative to the boundary when
        there is one, Poincare dual to the first Stiefel-Whitney class w1: a loop on the
        Klein bottle, an arc across the Moebius band).  None otherwise, and None when
        computed with ``generators=False``.
    orientation : (F,) int64 of +-1, or None
        For a surface (computed with generators): the orientation of each 2-cell, +1
        when it runs its first edge (``cx.edges[cx.cells[2][1][cx.cells[2][0][f]]]``,
        (u, v)) from u to v, -1 when from v to u.  Coherent (each interior edge run
        both ways) except across :attr:`orientation_cycle`.
    critical : list of int
        Critical cells per dimension after the coreductions (the Morse complex's size).
    """

    betti: list
    betti_mod2: list
    torsion: list
    generators: list | None
    orientation_cycle: np.ndarray | None
    critical: list
    orientation: np.ndarray | None = None

    @property
    def euler_characteristic(self) -> int:
        return int(sum((-1) ** q * b for q, b in enumerate(self.betti)))

    def as_dict(self) -> dict:
        """``{"betti": [...], "betti_mod2": [...], "torsion": [[...], ...]}`` (JSON-ready)."""
        return {"betti": [int(b) for b in self.betti],
                "betti_mod2": [int(b) for b in self.betti_mod2],
                "torsion": [[int(t) for t in ts] for ts in self.torsion]}

    def group(self, q: int) -> str:
        """H_q as text: ``"Z^2 + Z/2"``, ``"0"``."""
        return _group_text(self.betti[q], self.torsion[q])

    def describe(self) -> str:
        """One line: ``"H0 = Z, H1 = Z + Z/2, H2 = 0"``."""
        return _describe(self.betti, self.torsion)


def _group_text(b, torsion):
    parts = []
    if b:
        parts.append("Z" if b == 1 else f"Z^{b}")
    parts += [f"Z/{t}" for t in torsion]
    return " + ".join(parts) if parts else "0"


def _describe(betti, torsion):
    return ", ".join(f"H{q} = {_group_text(b, t)}" for q, (b, t) in enumerate(zip(betti, torsion)))


# ----------------------------------------------------------------------------
# incidence numbers
# ----------------------------------------------------------------------------

def incidences(cx: CellComplex) -> list:
    """Incidence numbers [c : f] of every cell with its faces, from cell orientations.

    Returns a list ``signs`` with ``signs[r]`` an int64 array aligned with the face
    list of the r-cells: for r = 1, (E, 2) (-1 at the first vertex, +1 at the second;
    0 and 0 for an edge whose two ends are one vertex); for r >= 2, aligned with
    ``cx.cells[r][1]``.  ``signs[0]`` is empty.  With these, boundary of boundary is 0.

    Raises InputError if some cell's boundary is not an orientable closed
    pseudo-manifold (the cell is not a ball).
    """
    _check(cx)
    return _incidences(cx)


def _faces(cx, r):
    """(owner, face) of every face entry of the r-cells, r >= 1."""
    if r == 1:
        ne = cx.count(1)
        return np.repeat(np.arange(ne, dtype=np.int64), 2), np.asarray(cx.edges).ravel()
    off, fac = cx.cells[r]
    return np.repeat(np.arange(off.size - 1, dtype=np.int64), np.diff(off)), np.asarray(fac)


def _incidences(cx):
    signs: list[np.ndarray] = [np.zeros(0, dtype=np.int64)]
    if cx.dim >= 1:
        e = np.asarray(cx.edges)
        s = np.tile(np.array([-1, 1], dtype=np.int64), (e.shape[0], 1))
        s[e[:, 0] == e[:, 1]] = 0
        signs.append(s.ravel())
    for r in range(2, cx.dim + 1):
        signs.append(_orient_cells(cx, r, signs[r - 1]))
    if cx.dim >= 1:
        signs[1] = signs[1].reshape(-1, 2)
    return signs


def _orient_cells(cx, r, below):
    """Signs of the r-cells' face entries such that each cell's faces cancel on every
    (r-2)-cell they share: [c:f1][f1:g] + [c:f2][f2:g] = 0 (kernel: _orient_faces)."""
    from ._homology_kernels import _orient_faces  # (numba loads on first use, not with the package)

    off, fac = cx.cells[r]
    sub_owner, sub_face = _faces(cx, r - 1)
    n_below = cx.count(r - 1)
    sub_off = np.zeros(n_below + 1, dtype=np.int64)
    np.cumsum(np.bincount(sub_owner, minlength=n_below), out=sub_off[1:])
    sign, error, cell, count = _orient_faces(np.asarray(off), np.asarray(fac), sub_off, np.asarray(sub_face),
                                             np.ascontiguousarray(np.asarray(below).ravel()), cx.count(r - 2))
    if error == 1:
        raise InputError(f"{r}-cell {cell} is not a ball: one of its {r - 2}-faces lies on "
                         f"{count} of its {r - 1}-faces, not 2")
    if error == 2:
        raise InputError(f"{r}-cell {cell} is not a ball: its boundary cannot be oriented")
    if error == 3:
        raise InputError(f"{r}-cell {cell} is not a ball: its boundary has {count} pieces")
    return sign


# ----------------------------------------------------------------------------
# the chain complex in one numbering: cell ids global, dimension by dimension
# ----------------------------------------------------------------------------

def _chain_complex(cx, signs):
    """Global CSR boundary (cell -> faces, signs; zero incidences left out) and
    coboundary, with ``base[r]`` the global id of r-cell 0."""
    counts = cx.counts()
    base = np.zeros(len(counts) + 1, dtype=np.int64)
    np.cumsum(counts, out=base[1:])
    owners, faces, vals = [], [], []
    for r in range(1, cx.dim + 1):
        owner, fac = _faces(cx, r)
        s = signs[r].ravel()
        nz = s != 0
        owners.append(owner[nz] + base[r])
        faces.append(fac[nz] + base[r - 1])
        vals.append(s[nz])
    n = int(base[-1])
    if owners:
        owner = np.concatenate(owners)
        face = np.concatenate(faces)
        val = np.concatenate(vals)
    else:
        owner = face = val = np.zeros(0, dtype=np.int64)
    bd_off = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(owner, minlength=n), out=bd_off[1:])
    # owner is sorted already (dimension by dimension, cell by cell)
    order = np.argsort(face, kind="stable")
    cb_off = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(face, minlength=n), out=cb_off[1:])
    dims = np.repeat(np.arange(len(counts), dtype=np.int64), counts)
    return base, dims, bd_off, face, val, cb_off, owner[order]


# ----------------------------------------------------------------------------
# Smith normal form over Z (Python ints: exact whatever the entries grow to)
# ----------------------------------------------------------------------------

def _identity(n):
    return [[int(i == j) for j in range(n)] for i in range(n)]


def _smith(A, m, n, transforms):
    """Diagonalise the m x n integer matrix A (list of rows, changed in place):
    L A R = diag(s_1 | s_2 | ...), s_i > 0.

    Returns (s, R, Rinv, Linv, L); the matrices are empty unless `transforms`.
    """
    R = _identity(n) if transforms else []
    Rinv = _identity(n) if transforms else []
    Linv = _identity(m) if transforms else []
    L = _identity(m) if transforms else []
    s: list[int] = []
    t = 0

    def swap_rows(i, j):
        A[i], A[j] = A[j], A[i]
        if transforms:
            L[i], L[j] = L[j], L[i]
            for row in Linv:
                row[i], row[j] = row[j], row[i]

    def swap_cols(i, j):
        for row in A:
            row[i], row[j] = row[j], row[i]
        if transforms:
            for row in R:
                row[i], row[j] = row[j], row[i]
            Rinv[i], Rinv[j] = Rinv[j], Rinv[i]

    def add_row(i, src, c):  # row_i += c row_src
        ri, rs = A[i], A[src]
        for j in range(t, n):
            if rs[j]:
                ri[j] += c * rs[j]
        if transforms:
            li, ls = L[i], L[src]
            for k in range(m):
                if ls[k]:
                    li[k] += c * ls[k]
            for row in Linv:
                if row[i]:
                    row[src] -= c * row[i]

    def add_col(j, src, c):  # col_j += c col_src
        for row in A:
            if row[src]:
                row[j] += c * row[src]
        if transforms:
            for row in R:
                if row[src]:
                    row[j] += c * row[src]
            rj, rs = Rinv[j], Rinv[src]
            for k in range(n):
                if rj[k]:
                    rs[k] -= c * rj[k]

    while t < min(m, n):
        best = None
        for i in range(t, m):
            row = A[i]
            for j in range(t, n):
                v = row[j]
                if v and (best is None or abs(v) < best[0]):
                    best = (abs(v), i, j)
                    if best[0] == 1:
                        break
            if best is not None and best[0] == 1:
                break
        if best is None:
            break
        swap_rows(t, best[1])
        swap_cols(t, best[2])
        while True:
            p = A[t][t]
            for i in range(t + 1, m):
                if A[i][t]:
                    add_row(i, t, -(A[i][t] // p))
            for j in range(t + 1, n):
                if A[t][j]:
                    add_col(j, t, -(A[t][j] // p))
            rest = [(abs(A[i][t]), i, True) for i in range(t + 1, m) if A[i][t]] + \
                   [(abs(A[t][j]), j, False) for j in range(t + 1, n) if A[t][j]]
            if rest:  # a remainder smaller than the pivot: it becomes the pivot
                _, k, is_row = min(rest)
                if is_row:
                    swap_rows(t, k)
                else:
                    swap_cols(t, k)
                continue
            bad = next(((i, j) for i in range(t + 1, m) for j in range(t + 1, n) if A[i][j] % p), None)
            if bad is None:
                break
            add_row(t, bad[0], 1)  # brings an entry p does not divide into row t
        if A[t][t] < 0:
            A[t] = [-v for v in A[t]]
            if transforms:
                L[t] = [-v for v in L[t]]
                for row in Linv:
                    row[t] = -row[t]
        s.append(A[t][t])
        t += 1
    return s, R, Rinv, Linv, L


def _matmul(A, B, m, k, n):
    out = [[0] * n for _ in range(m)]
    for i in range(m):
        Ai, Oi = A[i], out[i]
        for j in range(k):
            a = Ai[j]
            if a:
                Bj = B[j]
                for c in range(n):
                    if Bj[c]:
                        Oi[c] += a * Bj[c]
    return out


# ----------------------------------------------------------------------------
# public function -> validated wrapper -> kernels
# ----------------------------------------------------------------------------

def _check(cx):
    if not isinstance(cx, CellComplex):
        raise InputError(f"homology needs a CellComplex, got {type(cx).__name__}")


def homology(cx: CellComplex, generators: bool = True) -> Homology:
    """Homology of `cx` over Z, Q and Z/2, with generating cycles.

    Parameters
    ----------
    cx : CellComplex
        A regular cell complex (every cell a ball), as GCMH extracts.
    generators : bool, default True
        Also compute cycles generating each H_q(X; Z) (False is faster when only the
        groups are wanted).

    Returns
    -------
    Homology

    Raises
    ------
    InputError
        If `cx` is not a CellComplex, `generators` is not a bool, or a cell is not a
        ball (its boundary is no orientable sphere, or the extraction reported pieces
        left unsplit in ``meta["non_ball_left"]``).

    Examples
    --------
    >>> from gcmh_core import extract
    >>> cx = extract("x^2 + y^2 + z^2 - 1", bounds=(-1.5, 1.5), div=6, variables="x, y, z")
    >>> h = homology(cx)
    >>> h.betti, h.torsion
    ([1, 0, 1], [[], [], []])
    """
    _check(cx)
    if not isinstance(generators, (bool, np.bool_)):
        raise InputError(f"generators must be True or False, got {generators!r}")
    left = cx.meta.get("non_ball_left", 0)
    if isinstance(left, (int, np.integer)) and left > 0:
        # such a cell's own topology would be counted as the manifold's
        raise InputError(f"homology: the extraction left {int(left)} piece(s) that are not balls "
                         f"(meta['non_ball_left']); the cell complex is not regular there")
    return _homology(cx, bool(generators))


def _morse_complex(cx):
    """Incidences, coreductions and the Morse boundary.

    Returns (chain, partner, time, crit, D, signs): chain the global CSR complex, crit[q]
    the critical q-cells (global ids), D[q] (q = 1..dim) the Morse boundary as a list of
    rows (len(crit[q-1]) x len(crit[q]), Python ints), signs the incidences.
    """
    from ._homology_kernels import _coreduce, _flow

    signs = _incidences(cx)
    base, dims, bd_off, bd, bdv, cb_off, cb = _chain_complex(cx, signs)
    partner, time, critical = _coreduce(dims, cx.dim, bd_off, bd, cb_off, cb)
    critical = np.sort(critical)
    crit = [critical[dims[critical] == q] for q in range(cx.dim + 1)]
    ones = np.ones(critical.size, dtype=np.int64)
    off = np.arange(critical.size + 1, dtype=np.int64)
    m_off, m_cells, m_coefs, *_, overflow = _flow(off, critical, ones, dims, partner, time,
                                                  bd_off, bd, bdv, False)
    if overflow:
        raise InputError("homology: a Morse boundary coefficient passed 2^60 (int64 would overflow)")
    pos = np.full(dims.size, -1, dtype=np.int64)
    for q in range(cx.dim + 1):
        pos[crit[q]] = np.arange(crit[q].size)
    D: list = [None]
    for q in range(1, cx.dim + 1):
        rows = [[0] * int(crit[q].size) for _ in range(int(crit[q - 1].size))]
        first = int(np.searchsorted(critical, base[q]))
        for col in range(int(crit[q].size)):
            k = first + col
            for a, v in zip(m_cells[m_off[k]:m_off[k + 1]].tolist(), m_coefs[m_off[k]:m_off[k + 1]].tolist()):
                rows[int(pos[a])][col] += v
        D.append(rows)
    chain = (base, dims, bd_off, bd, bdv, cb_off, cb)
    return chain, partner, time, crit, D, signs


def _homology(cx, want_generators):
    chain, partner, time, crit, D, signs = _morse_complex(cx)
    base, dims, bd_off, bd, bdv, _, _ = chain
    top = cx.dim
    size = [int(c.size) for c in crit]
    # rank and invariant factors of each Morse boundary D_q, with R_q and R_q^-1
    factors: list[list[int]] = [[]]
    Rs: list = [_identity(size[0]) if want_generators else None]
    Rinvs: list = [None]
    for q in range(1, top + 1):
        s, R, Rinv, *_ = _smith([row[:] for row in D[q]], size[q - 1], size[q], want_generators)
        factors.append(s)
        Rs.append(R)
        Rinvs.append(Rinv)
    factors.append([])
    betti, betti2, torsion = [], [], []
    gens: list = []
    for q in range(top + 1):
        r_q, r_next = len(factors[q]), len(factors[q + 1])
        betti.append(size[q] - r_q - r_next)
        odd = sum(1 for f in factors[q] if f % 2) + sum(1 for f in factors[q + 1] if f % 2)
        betti2.append(size[q] - odd)
        torsion.append(sorted(f for f in factors[q + 1] if f > 1))
        if want_generators:
            gens.append(_generators(cx, q, top, size, r_q, D, Rs, Rinvs, crit, chain, partner, time))
    loop = sense = None
    if want_generators and top == 2 and cx.count(2):
        from ._homology_kernels import _orient_top

        off, fac = cx.cells[2]
        eps, bad = _orient_top(np.asarray(off), np.asarray(fac), signs[2], cx.count(1))
        if bad.size:
            eps, bad = _shorten_w1(np.asarray(off), np.asarray(fac), eps.astype(np.int64), bad,
                                   _cell_weights(cx, 1))
            loop = _ro(bad)
        sense = _ro(eps * signs[2][np.asarray(off)[:-1]])
    return Homology(betti=betti, betti_mod2=betti2, torsion=torsion, generators=gens if want_generators else None,
                    orientation_cycle=loop, critical=size, orientation=sense)


def _generators(cx, q, top, size, r_q, D, Rs, Rinvs, crit, chain, partner, time):
    """Cycles generating H_q: the kernel of D_q in the basis R_q[:, r_q:], the image of
    D_{q+1} in it diagonalised, each basis cycle lifted from the Morse complex."""
    base, dims, bd_off, bd, bdv, _, _ = chain
    n_ker = size[q] - r_q
    if n_ker == 0:
        return ()
    R = Rs[q]
    K = [row[r_q:] for row in R]  # size[q] x n_ker
    if q < top and size[q + 1]:
        coords = _matmul(Rinvs[q], D[q + 1], size[q], size[q], size[q + 1]) if q > 0 else \
            [row[:] for row in D[q + 1]]
        A = coords[r_q:]
        image = [row[:] for row in A]   # (the Smith form works in place)
        s, _, _, Linv, L = _smith(A, n_ker, size[q + 1], True)
    else:
        s, Linv, L, image = [], _identity(n_ker), _identity(n_ker), [[] for _ in range(n_ker)]
    basis = _matmul(K, Linv, size[q], n_ker, n_ker)  # columns: the new basis of ker
    wanted = [(i, 0) for i in range(len(s), n_ker)] + [(i, f) for i, f in enumerate(s) if f > 1]
    chains_off, chains_cells, chains_coefs = [0], [], []
    for i, _ in wanted:
        for row, c in zip(basis, crit[q].tolist()):
            if row[i]:
                chains_cells.append(c)
                chains_coefs.append(row[i])
        chains_off.append(len(chains_cells))
    from ._homology_kernels import _LIMIT, _flow

    if any(abs(v) > _LIMIT for v in chains_coefs):
        raise InputError("homology: a generator's coefficient passed 2^60 (int64 would overflow)")
    out = _flow(np.array(chains_off, dtype=np.int64), np.array(chains_cells, dtype=np.int64),
                np.array(chains_coefs, dtype=np.int64), dims, partner, time, bd_off, bd, bdv, True)
    lift_off, lift_cells, lift_coefs, overflow = out[3], out[4], out[5], out[6]
    if overflow:
        raise InputError("homology: a generator's coefficient passed 2^60 (int64 would overflow)")
    chains = [(lift_cells[lift_off[k]:lift_off[k + 1]], lift_coefs[lift_off[k]:lift_off[k + 1]])
              for k in range(len(wanted))]
    if q == 1 and top >= 2:
        n_free = n_ker - len(s)
        loops = None
        if len(wanted):   # (H1 = 0 may still leave critical edges: boundaries, nothing to draw)
            tors = [i for i, _ in wanted[n_free:]]
            ker_rows = Rinvs[q][r_q:]
            # a torsion class's coordinate as a function of Morse cycles: row i of L (L A R = diag) after
            # the kernel's coordinates, read modulo its order
            reads = [[sum(L[i][k] * ker_rows[k][c] for k in range(n_ker)) for c in range(size[q])] for i in tors]
            classes = _Classes(crit[q], ker_rows, image, [[row[i] for row in Linv] for i in tors],
                               [[row[i] for row in basis] for i in tors], [f for _, f in wanted[n_free:]], D[2],
                               reads)
            loops = _short_loops(cx, chain, partner, time, classes, n_free,
                                 [c for c, _ in chains[:n_free]])
        weight = _cell_weights(cx, 1)
        if loops is not None:   # the free loops, then a short loop for each torsion class found
            chains = loops[:n_free] + [t if t is not None else _shorten(cells, coefs, chain, weight)
                                       for t, (cells, coefs) in zip(loops[n_free:], chains[n_free:])]
        else:
            chains = [_shorten(cells, coefs, chain, weight) for cells, coefs in chains]
    elif q == 2 and top >= 3:   # H2 of a 3-manifold: surfaces, made smaller across 3-cells
        weight = _cell_weights(cx, 2)
        chains = [_shorten(cells, coefs, chain, weight, 2) for cells, coefs in chains]
    cycles = []
    for (cells, coefs), (_, order) in zip(chains, wanted):
        cells = cells - base[q]
        o = np.argsort(cells)
        cycles.append(Cycle(q, _ro(cells[o]), _ro(coefs[o]), int(order)))
    return tuple(cycles)


@dataclass(frozen=True)
class _Classes:
    """What tells H1 classes apart, from the Morse complex: ``crit`` the critical edges
    (global ids), ``ker_rows`` the rows of R^-1 that give a Morse cycle's coordinates in
    the kernel's basis, ``image`` the boundaries in those coordinates (n_ker x c2),
    ``torsion`` the torsion generators' coordinates and ``torsion_cycles`` the same as
    Morse cycles (Z^c1 each), ``D2`` the Morse boundary of the critical 2-cells (c1 x c2),
    ``reads`` per torsion generator j a row over the critical edges whose product with a
    Morse cycle, modulo ``orders[j]``, is the cycle's coordinate along generator j (0 on
    boundaries)."""

    crit: np.ndarray
    ker_rows: list
    image: list
    torsion: list
    torsion_cycles: list
    orders: list
    D2: list
    reads: list

    def coords(self, m) -> list:
        """A Morse cycle's coordinates in the kernel's basis."""
        return [sum(a * int(b) for a, b in zip(row, m)) for row in self.ker_rows]

    def _factors(self, cols):
        """Invariant factors of the boundaries with the columns `cols` beside them."""
        n_ker = len(self.ker_rows)
        M = [[c[i] for c in cols] + list(self.image[i]) for i in range(n_ker)]
        return _smith(M, n_ker, len(cols) + (len(self.image[0]) if n_ker else 0), False)[0]

    def generate(self, morse_cycles, torsion=None) -> bool:
        """True if these Morse cycles (Z^c1 each) and the torsion generators (their
        coordinates; by default the Smith form's) generate H1 (the free ones then span a
        complement of the torsion: a basis of H1 with it)."""
        s = self._factors([self.coords(m) for m in morse_cycles] + (self.torsion if torsion is None else torsion))
        return len(s) == len(self.ker_rows) and all(f == 1 for f in s)

    def replaces(self, j, m, free) -> bool:
        """True if the Morse cycle m can stand for torsion generator j beside the free
        Morse cycles `free`: order s_j times its class is a boundary, and with the rest it
        generates H1 (then its order is s_j and the sum stays direct)."""
        y = self.coords(m)
        if self._factors([[self.orders[j] * v for v in y]]) != self._factors([]):
            return False
        return self.generate(free, self.torsion[:j] + [y] + self.torsion[j + 1:])


def _xor_reduce(values, vectors):
    """Reduce the uint64 bit rows `values` (array) by GF(2) `vectors` in the order given,
    each reduced by those before it, by its highest bit (Gaussian elimination)."""
    for b in vectors:
        pivot = np.uint64(int(b).bit_length() - 1)
        values ^= np.where((values >> pivot) & np.uint64(1), np.uint64(b), np.uint64(0))
    return values


def _echelon(vectors):
    """GF(2) vectors (ints) reduced to an elimination order with distinct highest bits."""
    out: list[int] = []
    for v in vectors:
        v = int(_xor_reduce(np.array([v], dtype=np.uint64), out)[0])
        if v:
            out.append(v)
    return out


# roots: as many as cost about what the groups do (a walk from a root costs about a third of
# the groups' time per cell), at least a few
_ROOTS = (4, 16)
_ROOT_WORK = 1_000_000   # edges x roots
_TORSION_TRIES = 64      # loops tried for a torsion class, shortest first


def _short_loops(cx, chain, partner, time, classes, n_free, old):
    """Short free generators of H1 (Erickson and Whittlesey's greedy homology basis, from a
    few roots): from each root a shortest-path tree, each edge off it closes a loop (root ->
    u -> v -> root); the loops, shortest first, join while independent mod 2 of those taken,
    of the torsion generators and of the boundaries.  Roots: points along the cycles of the
    Smith normal form (`old`, global edge ids) and a few spread out.  Returns the loops as
    (global edge ids, coefficients), or None when their classes with the torsion are not a
    basis of H1 over Z (then the Smith form's cycles stay), or when the critical edges are
    too many for 64-bit class masks.  After the n_free free loops, one entry per torsion
    generator: the shortest loop tried that can stand for it, or None.
    """
    from ._homology_kernels import _edge_classes, _greedy_basis, _root_loops

    base, dims, bd_off, bd, bdv, _, _ = chain
    b1, n_edges, n_vert = int(base[1]), cx.count(1), cx.count(0)
    c1 = int(classes.crit.size)
    if c1 == 0 or c1 > 64 or n_edges * c1 > 20_000_000:
        return None
    pos = np.full(dims.size, -1, dtype=np.int64)
    pos[classes.crit] = np.arange(c1)
    order = np.argsort(time[b1:b1 + n_edges], kind="stable").astype(np.int64)
    phi, overflow = _edge_classes(order, b1, dims, partner, bd_off, bd, bdv, pos, c1)
    if overflow:
        return None
    shifts = np.arange(c1, dtype=np.uint64)

    def bits(rows):
        return np.bitwise_or.reduce((np.asarray(rows) & 1).astype(np.uint64) << shifts, axis=-1)

    # classes mod 2: the boundaries' span in echelon form; every mask is kept reduced by it
    image = _echelon(int(b) for b in bits(np.array(classes.D2, dtype=np.int64).T.reshape(-1, c1)))
    edge_bits = _xor_reduce(bits(phi), image)
    taken: list[int] = []
    for m in classes.torsion_cycles:   # the torsion generators' classes first (odd ones vanish mod 2)
        t = int(_xor_reduce(bits(np.array(m, dtype=np.int64)[None, :]), image)[0])
        taken = _echelon(taken + [t]) if t else taken
    E = np.asarray(cx.edges, dtype=np.int64)
    weight = _edge_lengths(cx)
    adj_off, adj_to, adj_edge = _adjacency(E, n_vert)
    n_roots = max(_ROOTS[0], min(_ROOTS[1], _ROOT_WORK // max(n_edges, 1)))
    # even torsion classes mod 2: the loops that can stand for them (odd ones vanish mod 2)
    wants = [int(_xor_reduce(bits(np.array(m, dtype=np.int64)[None, :]), image)[0]) if order % 2 == 0 else 0
             for m, order in zip(classes.torsion_cycles, classes.orders)]
    lengths: list = []
    masks: list = []
    which: list = []
    trees: list = []
    used: list = []
    u, v = E[:, 0], E[:, 1]
    # No loop longer than `bound` can be taken: the greedy basis from more loops is
    # shorter place by place (a matroid's), so the longest of one taken already bounds it,
    # and a torsion class's shortest loop seen bounds the one that stands for it.  Loops
    # past it are dropped, and a walk from a root goes no farther than half of it (beyond
    # the vertices nearer to it than to the roots before, which choose the next root).
    bound = [np.inf]
    nearest = np.full(n_vert, np.inf)
    far_enough = np.zeros(n_vert)    # re-roots choose no root: they walk their half bound only

    def grow(r, nearest):
        """The loops closed by the shortest-path tree from r."""
        radius = 0.5 * bound[0] * (1 + 1e-9)
        keep, length, m, dist, pred_edge, pred = _root_loops(adj_off, adj_to, adj_edge, weight, u, v,
                                                             edge_bits, r, radius, nearest)
        short = length <= 2 * radius
        lengths.append(length[short])
        masks.append(m[short])
        which.append(np.stack([np.full(int(short.sum()), len(trees)), keep[short]], axis=1))
        trees.append((pred_edge, pred, dist))
        used.append(r)

    def greedy():
        """The shortest loops independent mod 2: [(tree, edge)] (None if too few); lowers bound."""
        length = np.concatenate(lengths)
        o = np.argsort(length, kind="stable")
        every = np.concatenate(masks)
        picked = _greedy_basis(every[o], np.array(taken, dtype=np.uint64), n_free)
        if picked.size < n_free:
            return None
        order = np.concatenate(which)[o[picked]]
        chosen = [tuple(int(x) for x in row) for row in order]
        longest = float(length[o[picked[-1]]]) if chosen else 0.0
        for w in filter(None, wants):   # (a torsion class with no loop seen yet bounds nothing)
            seen = length[every == np.uint64(w)]
            longest = max(longest, float(seen.min()) if seen.size else np.inf)
        if any(order % 2 for order in classes.orders):   # (the masks do not see odd torsion: whole walks)
            longest = np.inf
        bound[0] = min(bound[0], longest)
        return chosen

    # roots spread out: the first on a cycle of the Smith form, each next one the vertex
    # farthest from those before (an unreached one first: another component); the greedy
    # basis after the first few bounds the walks of the rest
    r = int(E[old[0][0] - b1, 0]) if old and len(old[0]) else 0
    for i in range(min(n_roots, n_vert)):
        grow(r, nearest)
        if i + 1 in (1, 2, 4, 8):
            greedy()
        far = np.isinf(nearest)
        r = int(np.flatnonzero(far)[0]) if far.any() else int(np.argmax(nearest))
    chosen = greedy()
    # a loop through a root away from the shortest in its class runs to it and round it: its
    # far end (the closing edge) lies near that shortest loop, so roots there tighten it
    for _ in range(2):
        if chosen is None:
            return None
        new = {int(E[e, 0]) for _, e in chosen} - set(used)
        if not new:
            break
        for r in sorted(new):
            grow(r, far_enough)
        chosen = greedy()
    if chosen is None:
        return None
    loops: list = []
    morse = []
    for k, e in chosen:
        cells, coefs = _tree_loop(E, trees[k], e)
        loops.append((cells + b1, coefs))
        morse.append((coefs[:, None] * phi[cells]).sum(axis=0).tolist())
    if not classes.generate(morse):
        return None
    def stand_in(j, tries):
        """The first loop of `tries` ((tree, edge) pairs, shortest first) that can stand for torsion j."""
        for k, e in tries[:_TORSION_TRIES]:
            cells, coefs = _tree_loop(E, trees[k], e)
            if classes.replaces(j, (coefs[:, None] * phi[cells]).sum(axis=0).tolist(), morse):
                return cells + b1, coefs
        return None

    # a torsion class of even order: the shortest loop with its class mod 2 that can stand for it; of odd
    # order s (invisible mod 2): the shortest whose coordinate along it, read mod s, is not 0
    o = np.argsort(np.concatenate(lengths), kind="stable")
    every, where = np.concatenate(masks)[o], np.concatenate(which)[o]
    for j, (want, order) in enumerate(zip(wants, classes.orders)):
        found = None
        if want:
            found = stand_in(j, [tuple(where[i]) for i in np.flatnonzero(every == np.uint64(want)).tolist()])
        elif order % 2:
            found = stand_in(j, _loops_read(classes.reads[j], order, phi, trees, u, v, weight))
        loops.append(found)
    return loops


def _loops_read(read, order, phi, trees, u, v, weight):
    """The loops of the trees (pred_edge, pred, dist) whose coordinate along a torsion class of odd
    `order` is not 0: the class's reading ``read`` (over the critical edges) becomes a cochain mod order
    on the edges (through their Morse classes phi), summed down each tree.  Returns (tree, edge) pairs,
    shortest loop first."""
    from ._homology_kernels import _tree_residues

    value = (phi % order) @ np.array([int(x) % order for x in read], dtype=np.int64) % order
    found, size = [], []
    for k, (pred_edge, pred, dist) in enumerate(trees):
        res = _tree_residues(pred, pred_edge, u, value, order)
        off_tree = np.isfinite(dist[u]) & np.isfinite(dist[v])
        off_tree[pred_edge[pred_edge >= 0]] = False
        e = np.flatnonzero(off_tree & ((res[u] + value - res[v]) % order != 0))
        found += [(k, int(x)) for x in e.tolist()]
        size.append(dist[u[e]] + weight[e] + dist[v[e]])
    o = np.argsort(np.concatenate(size), kind="stable") if size else np.zeros(0, np.int64)
    return [found[i] for i in o]


def _adjacency(E, n_vert):
    """The graph of the edges (E, 2) as CSR (off, neighbour, edge id), both ways; an edge
    whose two ends are one vertex is left out."""
    proper = E[:, 0] != E[:, 1]
    ends = np.concatenate([E[proper, 0], E[proper, 1]])
    to = np.concatenate([E[proper, 1], E[proper, 0]])
    eid = np.concatenate([np.flatnonzero(proper)] * 2).astype(np.int64)
    o = np.argsort(ends, kind="stable")
    off = np.zeros(n_vert + 1, dtype=np.int64)
    np.cumsum(np.bincount(ends, minlength=n_vert), out=off[1:])
    return off, to[o], eid[o]


def _tree_loop(E, tree, e):
    """The loop root -> u -> v -> root through edge e = (u, v) off a shortest-path tree
    (pred_edge, pred, ...): (edge ids, coefficients), the two tree paths' common part cancelled."""
    pred_edge, pred = tree[:2]
    z: dict = {e: 1}
    for x, sign in ((int(E[e, 0]), 1), (int(E[e, 1]), -1)):   # + path to u, - path to v
        while pred[x] >= 0:
            f = int(pred_edge[x])
            into = 1 if E[f, 1] == x else -1    # the edge runs pred -> x
            z[f] = z.get(f, 0) + sign * into
            x = int(pred[x])
    cells = np.array(sorted(f for f, c in z.items() if c), dtype=np.int64)
    return cells, np.array([z[f] for f in cells.tolist()], dtype=np.int64)


def _edge_lengths(cx):
    """(E,) float64: each edge's length in R^n, across an identified seam the short way
    (the low end moved up a period, flipped axes mirrored, as the result is drawn)."""
    from ._validate import as_periodic

    X = np.asarray(cx.vertices, dtype=np.float64)
    e = np.asarray(cx.edges, dtype=np.int64)
    a, b = X[e[:, 0]].copy(), X[e[:, 1]].copy()
    meta = cx.meta or {}
    items, names, bounds, div = meta.get("periodic"), meta.get("variables"), meta.get("bounds"), meta.get("div")
    if items and names and bounds is not None and div is not None:
        try:
            spec = as_periodic(items, names, div)
        except InputError:
            spec = ()
        bounds = np.asarray(bounds, dtype=np.float64)
        for p, flips in spec:
            lo, period = bounds[p, 0], bounds[p, 1] - bounds[p, 0]
            far = np.abs(a[:, p] - b[:, p]) > period / 2
            for end in (a, b):
                low = far & (end[:, p] < lo + period / 2)
                end[low, p] += period
                for f in flips:
                    end[low, f] = bounds[f].sum() - end[low, f]
    length = np.linalg.norm(a - b, axis=1)
    length[~np.isfinite(length)] = 0.0
    return length


def _cell_weights(cx, q):
    """(N_q,) float64 in [1, 2] for the q-cells, q = 1 or 2: 1 + size / (2 x median),
    capped, the size an edge's length or a polygon's area (fanned from its first vertex).
    Shortening counts cells first and size second (a cell across an identified seam looks
    large in R^n: the cap keeps it from costing more than two cells)."""
    X = np.asarray(cx.vertices, dtype=np.float64)
    if q == 1:
        e = np.asarray(cx.edges)
        size = np.linalg.norm(X[e[:, 0]] - X[e[:, 1]], axis=1) if e.size else np.ones(0)
    else:
        from ._homology_kernels import _polygon_areas

        offs, verts = (np.asarray(a, dtype=np.int64) for a in cx.polygons())
        size = _polygon_areas(offs, verts, np.ascontiguousarray(X))
    size[~np.isfinite(size)] = 0.0
    if size.size == 0:
        return size
    mid = float(np.median(size)) or 1.0
    return 1.0 + np.minimum(size / (2.0 * mid), 1.0)


def _shorten(cells, coefs, chain, weight, q=1):
    """A smaller q-cycle in the same class: z -> z - t d(f) for a (q+1)-cell f and t = +-1
    while that lowers sum weight_e |z_e| (weight[e - base[q]]: about one per cell, a little
    more for a larger one).  Straightens z across a cell that holds more than half of its
    boundary, and slides it across one that holds half when the other half is smaller.
    Each step lowers the weight by a positive amount, so no chain comes twice: it ends.

    cells: global ids of q-cells, coefs their coefficients.
    """
    from ._homology_kernels import _shorten_chain

    base, _, bd_off, bd, bdv, cb_off, cb = chain
    return _shorten_chain(np.asarray(cells, dtype=np.int64), np.asarray(coefs, dtype=np.int64), int(base[q]),
                          bd_off, bd, bdv, cb_off, cb, np.asarray(weight, dtype=np.float64))


def _shorten_w1(off, fac, eps, loop, weight):
    """A shorter w1 loop: reversing a 2-cell's orientation toggles each interior edge it has
    once on the loop or off it; a cell is reversed while that lowers the loop's weight
    (about one per edge, a little more for a longer one).  Returns (eps, loop edges)
    changed alike, so the loop stays where the orientation eps flips."""
    count = np.bincount(fac, minlength=weight.size)
    owner = np.repeat(np.arange(off.size - 1), np.diff(off))
    o = np.argsort(fac, kind="stable")
    co_off = np.zeros(weight.size + 1, dtype=np.int64)
    np.cumsum(count, out=co_off[1:])
    co = owner[o]
    on = set(loop.tolist())
    todo = {int(c) for e in on for c in co[co_off[e]:co_off[e + 1]].tolist()}
    while todo:
        c = todo.pop()
        edges = fac[off[c]:off[c + 1]].tolist()
        toggled = [e for e in edges if count[e] == 2 and edges.count(e) == 1]
        delta = sum(weight[e] * (-1 if e in on else 1) for e in toggled)
        if delta < -1e-9:
            eps[c] = -eps[c]
            for e in toggled:
                on.symmetric_difference_update((e,))
                todo.update(int(d) for d in co[co_off[e]:co_off[e + 1]].tolist())
    return eps, np.array(sorted(on), dtype=np.int64)


def _ro(arr):
    arr = np.array(arr, dtype=np.int64)
    arr.flags.writeable = False
    return arr


def summary(cx: CellComplex) -> tuple[dict, str]:
    """The ``"homology"`` object of ``gcmh extract --json`` and its summary line.

    >>> from gcmh_core import extract
    >>> cx = extract("x^2 + y^2 + z^2 - 1", bounds=(-1.5, 1.5), div=6, variables="x, y, z")
    >>> summary(cx)[1]
    'homology: H0 = Z, H1 = 0, H2 = Z (mod 2 Betti 1, 0, 1)'
    """
    d = homology(cx, generators=False).as_dict()
    return d, summary_line(d)


def summary_line(d: dict) -> str:
    """The summary line of a ``"homology"`` object (:meth:`Homology.as_dict`, or ``{"error": why}``
    for a complex homology refuses)."""
    if "error" in d:
        return f"homology: not computed: {d['error']}"
    return f"homology: {_describe(d['betti'], d['torsion'])} (mod 2 Betti {', '.join(str(b) for b in d['betti_mod2'])})"
