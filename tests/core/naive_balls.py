"""Slow, obviously correct twins of the numba kernels `gcmh_core._balls` calls (issue 25)."""

import numpy as np


def naive_same_faces_candidates(offsets, faces):
    """`kernels.cell_check.same_faces_candidates` with no hash: a cell is marked when another cell
    lists the same faces (as a multiset, in any order)."""
    rows = [tuple(sorted(faces[offsets[i] : offsets[i + 1]].tolist())) for i in range(len(offsets) - 1)]
    count: dict = {}
    for row in rows:
        count[row] = count.get(row, 0) + 1
    return np.array([count[row] > 1 for row in rows], bool)


def naive_chain_id(n, chain):
    """`kernels.kuhn_cube`'s id of a chain of corners: c0 (n + 1)^n + sum_a step_a (n + 1)^a, step_a the
    link at which axis a is switched on (0: in c0 or never)."""
    code = 0
    for i in range(1, len(chain)):
        for a in range(n):
            if (chain[i] ^ chain[i - 1]) >> a & 1:
                code += i * (n + 1) ** a
    return int(chain[0]) * (n + 1) ** n + code


def naive_cube_chains(n, k, values, o, corner_row):
    """`kernels.kuhn_cube.cube_simplex_tables`' chains by brute force: every strict chain of the cube's
    corners (`tables._strict_chains`), the k-chains tested by the kernels' solve one by one, then
    every chain of dimension k..n whose corners include a crossed k-chain's.  {d: sorted ids}."""
    from gcmh_core.kernels.solve import _zero_side, simplex_crosses
    from gcmh_core.kernels.tables import _strict_chains

    signs = np.array([sum(1 << j for j in range(k) if values[o + corner_row[c], j] >= 0.0) for c in range(1 << n)],
                     np.int64)
    crossed = []
    for chain in _strict_chains(n, k)[0]:
        table = np.ascontiguousarray(chain[None], np.int64)
        lam = np.empty(k + 1)
        hit = simplex_crosses.py_func(values, o, corner_row, table, 0, k, signs, (1 << k) - 1, np.empty((k, k)),
                                      np.empty(k), lam)
        if hit == 2:
            hit = _zero_side(values, o, corner_row, table, 0, k, lam)
        if hit:
            crossed.append(set(chain.tolist()))
    out = {}
    for d in range(k, n + 1):
        out[d] = sorted(naive_chain_id(n, chain.tolist()) for chain in _strict_chains(n, d)[0]
                        if any(c <= set(chain.tolist()) for c in crossed))
    return out


def naive_piece_labels(n_nodes, a, b, keep):
    """`kernels.kuhn_cube.piece_labels` by search: each node's label is the smallest node it reaches
    over the kept edges."""
    nbrs: dict = {x: set() for x in range(n_nodes)}
    for x, y, k in zip(a.tolist(), b.tolist(), keep.tolist()):
        if k:
            nbrs[x].add(y)
            nbrs[y].add(x)
    out = np.empty(n_nodes, np.int64)
    for x in range(n_nodes):
        seen, todo = {x}, [x]
        while todo:
            for y in nbrs[todo.pop()] - seen:
                seen.add(y)
                todo.append(y)
        out[x] = min(seen)
    return out
