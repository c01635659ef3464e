"""Slow, obviously correct twins of the newer kernels of gcmh_core._homology_kernels
(the older ones' twins are in naive_homology.py), compared on random inputs in
tests/core/test_homology_kernels.py."""

from __future__ import annotations

import math
from collections import deque


def orient_top(off, fac, sign, n_faces):
    """Twin of ``_orient_top``: (eps list of +-1, sorted list of conflicting faces).

    Each face's entries are listed; a face on two entries joins their cells.  Walk from
    the lowest cell not reached yet, breadth first, faces in their order; the other cell
    of a face gets the sign that makes the face cancel."""
    entries: dict = {}
    for c in range(len(off) - 1):
        for j in range(off[c], off[c + 1]):
            entries.setdefault(int(fac[j]), []).append((c, int(sign[j])))
    eps = [0] * (len(off) - 1)
    for start in range(len(eps)):
        if eps[start]:
            continue
        eps[start] = 1
        todo = deque([start])
        while todo:
            c = todo.popleft()
            for j in range(off[c], off[c + 1]):
                pair = entries[int(fac[j])]
                if len(pair) != 2:
                    continue
                (_, s), (d, t) = pair if pair[0][0] == c else pair[::-1]
                if eps[d] == 0:
                    eps[d] = -eps[c] * s * t
                    todo.append(d)
    bad = [f for f in range(n_faces) if len(entries.get(f, [])) == 2
           and sum(eps[c] * s for c, s in entries[f]) != 0]
    return eps, bad


def edge_classes(order, b1, dims, partner, bd_off, bd, bdv, pos, c1):
    """Twin of ``_edge_classes``: phi[e] as lists, edges taken in `order`."""
    phi = {}
    for e in (int(x) for x in order):
        g = b1 + e
        p = int(partner[g])
        row = [0] * c1
        if p < 0:
            row[int(pos[g])] = 1
        elif dims[p] == 2:
            faces = [(int(bd[j]), int(bdv[j])) for j in range(bd_off[p], bd_off[p + 1])]
            s = next(v for h, v in faces if h == g)
            for h, v in faces:
                if h != g:
                    row = [a - s * v * b for a, b in zip(row, phi[h - b1])]
        phi[e] = row
    return [phi[e] for e in range(len(order))]


def tree_xor(order, pred, tree_bits):
    """Twin of ``_tree_xor``: each vertex's bits, xor of the tree bits on its way to the root."""
    out = []
    for x in range(len(pred)):
        acc, y = 0, x
        while pred[y] >= 0:
            acc ^= int(tree_bits[y])
            y = int(pred[y])
        out.append(acc)
    return out


def shortest_distances(n, edges, weight, root):
    """Twin of ``_shortest_tree``'s distances: Bellman-Ford relaxation until nothing changes."""
    dist = [math.inf] * n
    dist[root] = 0.0
    changed = True
    while changed:
        changed = False
        for (u, v), w in zip(edges, weight):
            for a, b in ((u, v), (v, u)):
                if dist[a] + w < dist[b]:
                    dist[b] = dist[a] + w
                    changed = True
    return dist
