"""One cube's Kuhn simplices that M_A crosses, for n >= 8 (issue 25: regular cells at every n).

The whole table of the n-cube's Kuhn (CFK) simplices (`tables.simplex_tables`) holds every strict
chain of corners of dimension k..n: millions of rows at n = 7, too many beyond.  A cube's cell
check and refinement need only the chains M_A crosses: a d-chain (d > k) is crossed only if one
of its k-subchains is, and every subchain of a chain is a chain of the triangulation.  So the
crossed k-chains are found first (a walk over chains c0 < c1 < ... < ck, pruned by the signs the
corners above the chain's last corner can still give), then every chain above them, dimension by
dimension (a (d+1)-chain above a d-chain has one corner more, in one of its gaps).

A chain's id is c0 * (n + 1)^n + code, with `tables.SimplexTables`' code (sum_a step_a (n+1)^a,
step_a the link at which axis a is switched on, 0 if never or in c0): (c0, code) is the chain,
and the global key is (grid vertex of c0) * (n + 1)^n + code, so cubes sharing a face agree.
"""

import numba as nb
import numpy as np

from .._config import JIT
from .solve import _zero_side, simplex_crosses
from .tables import SimplexTables

# Rows a cube's table may hold (its chains above the crossed k-chains): about 150 bytes each
MOST_ROWS = 4_000_000


def cube_simplex_tables(n, k, values, o, corner_row, most=MOST_ROWS):
    """The `tables.SimplexTables` of one cube (corner c: row o + corner_row[c] of values) restricted to
    the chains M_A may cross: the crossed k-chains and every chain above one, keyed as the whole
    table's; `cms.simplices_chunk` and `cell_check.cube_euler_chunk` take it as they take the whole
    table (a facet of -1 is not crossed).  None where the cube would need more than `most` rows."""
    kchains = crossed_kchains(values, np.int64(o), corner_row, n, k)
    start, corners, c0, code, facets, cube_facets = chains_above(kchains, n, k, most)
    if start[-1] == 0 and len(kchains):
        return None
    return SimplexTables(n, k, start, corners, c0, code, facets, cube_facets, (n + 1) ** n, np.zeros(0, np.int64))


@nb.njit(**JIT)
def _chain_id(chain, m, n, pw):
    """The id of the chain chain[0..m-1] (see the module's docstring)."""
    code = np.int64(0)
    for i in range(1, m):
        step = chain[i] ^ chain[i - 1]
        for a in range(n):
            if (step >> a) & 1:
                code += i * pw[a]
    return chain[0] * pw[n] + code


@nb.njit(**JIT)
def crossed_kchains(values, o, corner_row, n, k):
    """The k-chains of the cube's Kuhn triangulation that M_A crosses (`simplices_chunk`'s test:
    the sign prune, the solve, `_zero_side` on a facet), (m, k + 1) corners in chain order.

    The walk chooses c0, c1, ... in turn; a prefix is dropped when a component F_j that has one
    sign on it has no corner of the other sign strictly above its last corner (where the rest of
    the chain lies)."""
    n_corners = 1 << n
    full_n = n_corners - 1
    all_signs = (np.int64(1) << k) - 1
    signs = np.empty(n_corners, np.int64)
    for c in range(n_corners):
        p = np.int64(0)
        for j in range(k):
            if values[o + corner_row[c], j] >= 0.0:
                p |= np.int64(1) << j
        signs[c] = p
    # over the corners strictly above c: the components with a value >= 0 somewhere (above_any) and
    # those >= 0 everywhere (above_all); from the top corner down
    incl_any = np.empty(n_corners, np.int64)
    incl_all = np.empty(n_corners, np.int64)
    above_any = np.empty(n_corners, np.int64)
    above_all = np.empty(n_corners, np.int64)
    for c in range(full_n, -1, -1):
        sa = np.int64(0)
        sl = all_signs
        for a in range(n):
            if not (c >> a) & 1:
                sa |= incl_any[c | (1 << a)]
                sl &= incl_all[c | (1 << a)]
        above_any[c] = sa
        above_all[c] = sl
        incl_any[c] = sa | signs[c]
        incl_all[c] = sl & signs[c]
    chain = np.zeros((1, k + 1), np.int64)
    pos = np.zeros(k + 1, np.int64)  # components >= 0 somewhere on the prefix chain[0..i]
    allp = np.zeros(k + 1, np.int64)  # components >= 0 everywhere on it
    sub = np.zeros(k + 1, np.int64)  # the next subset to add at each level (level 0: the next c0)
    mat = np.empty((k, k), np.float64)
    rhs = np.empty(k, np.float64)
    lam = np.empty(k + 1, np.float64)
    out = np.empty((64, k + 1), np.int64)
    used = 0
    i = 0
    sub[0] = 0
    while i >= 0:
        prev = chain[0, i - 1] if i > 0 else 0
        comp = full_n & ~prev
        c = -1
        while True:  # the next candidate corner at level i
            if i == 0:
                if sub[0] > full_n:
                    break
                x = sub[0]
                sub[0] += 1
            else:
                if sub[i] == 0:
                    break
                x = prev | sub[i]
                sub[i] = (sub[i] - 1) & comp
            size = 0
            for a in range(n):
                size += (x >> a) & 1
            if size > n - (k - i):  # (room for the links still to come)
                continue
            p = (pos[i - 1] if i > 0 else 0) | signs[x]
            q = (allp[i - 1] if i > 0 else all_signs) & signs[x]
            if i == k:
                if p == all_signs and q == 0:
                    c = x
                    break
                continue
            if (all_signs & ~p) & ~above_any[x] or q & above_all[x]:
                continue  # some F_j keeps one sign on every chain through this prefix
            c = x
            break
        if c < 0:
            i -= 1
            continue
        chain[0, i] = c
        pos[i] = (pos[i - 1] if i > 0 else 0) | signs[c]
        allp[i] = (allp[i - 1] if i > 0 else all_signs) & signs[c]
        if i < k:
            i += 1
            sub[i] = full_n & ~c
            continue
        hit = simplex_crosses(values, o, corner_row, chain, 0, k, signs, all_signs, mat, rhs, lam)
        if hit == 2:
            hit = _zero_side(values, o, corner_row, chain, 0, k, lam)
        if hit:
            if used == out.shape[0]:
                grown = np.empty((2 * used, k + 1), np.int64)
                grown[:used] = out[:used]
                out = grown
            out[used] = chain[0]
            used += 1
    return out[:used].copy()


@nb.njit(**JIT)
def _decode(ids, d, n, pw):
    """The chains (len(ids), n + 1) of dimension d with these ids, padded with -1."""
    out = -np.ones((ids.shape[0], n + 1), np.int64)
    for r in range(ids.shape[0]):
        c0 = ids[r] // pw[n]
        code = ids[r] % pw[n]
        for i in range(d + 1):
            out[r, i] = c0
        for a in range(n):
            step = (code // pw[a]) % (n + 1)
            if step > 0:
                for i in range(step, d + 1):
                    out[r, i] |= np.int64(1) << a
    return out


@nb.njit(**JIT)
def chains_above(kchains, n, k, most):
    """Every chain of dimension k..n that holds one of the k-chains (`crossed_kchains`), as
    `tables.SimplexTables`' arrays: (start, corners, c0, code, facets, cube_facets); a facet that is
    no such chain (M_A can't cross it) is -1.  Rows of each dimension sorted by id.  More than
    `most` rows: start is returned all 0 and the rest empty (too many to hold)."""
    pw = np.empty(n + 1, np.int64)
    pw[0] = 1
    for a in range(n):
        pw[a + 1] = pw[a] * (n + 1)
    full_n = (np.int64(1) << n) - 1
    ids = np.empty(kchains.shape[0], np.int64)
    for r in range(kchains.shape[0]):
        ids[r] = _chain_id(kchains[r], k + 1, n, pw)
    levels = [np.unique(ids)]
    total = levels[0].shape[0]
    chain = np.empty(n + 2, np.int64)
    for d in range(k + 1, n + 1):
        below = _decode(levels[-1], d - 1, n, pw)
        grown = np.empty(16, np.int64)
        used = 0
        for r in range(below.shape[0]):
            for gap in range(d + 1):  # the new corner goes before below[r, gap] (gap d: after the last)
                lo = below[r, gap - 1] if gap > 0 else -1
                hi = below[r, gap] if gap < d else full_n
                # the new corner x: lo < x < hi (gap 0: any proper subset of c0; gap d: proper superset of
                # the last corner), lo < x as subsets when gap > 0
                base = lo if gap > 0 else 0
                room = hi & ~base
                s = room
                while True:
                    x = base | s
                    ok = (gap == d or x != hi) and (gap == 0 or s != 0)
                    if ok:
                        for i in range(gap):
                            chain[i] = below[r, i]
                        chain[gap] = x
                        for i in range(gap, d):
                            chain[i + 1] = below[r, i]
                        if used == grown.shape[0]:
                            bigger = np.empty(2 * used, np.int64)
                            bigger[:used] = grown[:used]
                            grown = bigger
                        grown[used] = _chain_id(chain, d + 1, n, pw)
                        used += 1
                    if s == 0:
                        break
                    s = (s - 1) & room
        level = np.unique(grown[:used])
        total += level.shape[0]
        if total > most:
            return (np.zeros(n + 2, np.int64), -np.ones((0, n + 1), np.int64), np.zeros(0, np.int64),
                    np.zeros(0, np.int64), -np.ones((0, n + 1), np.int64), np.zeros(0, np.int64))
        levels.append(level)
    start = np.zeros(n + 2, np.int64)
    for d in range(n + 1):
        start[d + 1] = start[d] + (levels[d - k].shape[0] if d >= k else 0)
    corners = -np.ones((total, n + 1), np.int64)
    facets = -np.ones((total, n + 1), np.int64)
    c0 = np.empty(total, np.int64)
    code = np.empty(total, np.int64)
    cube_facets = np.zeros(total, np.int64)
    for d in range(k, n + 1):
        level = levels[d - k]
        rows = _decode(level, d, n, pw)
        for r in range(level.shape[0]):
            s = start[d] + r
            for i in range(d + 1):
                corners[s, i] = rows[r, i]
            c0[s] = level[r] // pw[n]
            code[s] = level[r] % pw[n]
            for a in range(n):  # a cube facet holds the chain: axis a on from c0, or never on
                if (rows[r, 0] >> a) & 1:
                    cube_facets[s] |= np.int64(1) << (2 * a + 1)
                elif not (rows[r, d] >> a) & 1:
                    cube_facets[s] |= np.int64(1) << (2 * a)
            if d > k:
                lower = levels[d - 1 - k]
                for j in range(d + 1):
                    q = 0
                    for i in range(d + 1):
                        if i != j:
                            chain[q] = rows[r, i]
                            q += 1
                    f = _chain_id(chain, d, n, pw)
                    at = np.searchsorted(lower, f)
                    if at < lower.shape[0] and lower[at] == f:
                        facets[s, j] = start[d - 1] + at
    return start, corners, c0, code, facets, cube_facets


@nb.njit(**JIT)
def piece_labels(n_nodes, a, b, keep):
    """Connected pieces of the graph on nodes 0..n_nodes-1 with the edges (a[i], b[i]) where keep[i]:
    each node's label is the smallest node of its piece (union-find; `_balls.refine_cube` splits a
    face's CMS cells into M_A's pieces with it)."""
    parent = np.arange(n_nodes)
    for i in range(a.shape[0]):
        if not keep[i]:
            continue
        x = a[i]
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        y = b[i]
        while parent[y] != y:
            parent[y] = parent[parent[y]]
            y = parent[y]
        if x < y:
            parent[y] = x
        elif y < x:
            parent[x] = y
    for x in range(n_nodes):  # (roots are their pieces' smallest nodes: a parent is never larger)
        parent[x] = parent[parent[x]]
    return parent
