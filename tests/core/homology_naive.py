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


def root_loops(n, edges, weight, edge_bits, pred_edge, root, radius, nearest):
    """Twin of ``_root_loops`` given its tree (`pred_edge`: which of the equally short paths it
    took is the heap's choice): the distances by Bellman-Ford; the settled vertices those
    reached at most `radius` away or nearer than `nearest`; each edge off the tree between two
    of them closes the loop root -> u -> v -> root, its mask the xor of the bits on that
    loop's edges, walked up the tree.  Returns (edges, lengths, masks) of the loops whose
    mask is not 0, in edge order, and the settled vertices."""
    dist = shortest_distances(n, edges, weight, root)
    settled = [d < math.inf and (d <= radius or d < near) for d, near in zip(dist, nearest)]
    tree = {int(e) for e in pred_edge if e >= 0}

    def up(x):   # the xor of the bits from x up to the root
        acc = 0
        while pred_edge[x] >= 0:
            e = int(pred_edge[x])
            acc ^= int(edge_bits[e])
            x = edges[e][0] if edges[e][1] == x else edges[e][1]
        return acc

    out = []
    for e, (u, v) in enumerate(edges):
        if settled[u] and settled[v] and e not in tree:
            m = up(u) ^ up(v) ^ int(edge_bits[e])
            if m:
                out.append((e, dist[u] + weight[e] + dist[v], m))
    return out, settled


def shorten_chain(cells, coefs, b, bd_off, bd, bdv, cb_off, cb, weight):
    """Twin of ``_shorten_chain``: z as a dict; the (q+1)-cells to try in a deque, each once at a
    time (first the cofaces of z's cells in their order, then those of every q-cell a step
    changes); a step z -> z - t d(f), t = +1 then -1, when it lowers sum weight |z|."""
    z: dict = {}
    for c, v in zip(cells, coefs):
        z[int(c)] = z.get(int(c), 0) + int(v)
    todo: deque = deque()
    waiting: set = set()

    def wait(c):
        for f in cb[cb_off[c]:cb_off[c + 1]]:
            if int(f) not in waiting:
                waiting.add(int(f))
                todo.append(int(f))

    for c in dict.fromkeys(int(c) for c in cells):
        wait(c)
    while todo:
        f = todo.popleft()
        waiting.discard(f)
        faces = [(int(bd[j]), int(bdv[j])) for j in range(bd_off[f], bd_off[f + 1])]
        for t in (1, -1):
            delta = 0.0
            for c, s in faces:
                delta += weight[c - b] * (abs(z.get(c, 0) - t * s) - abs(z.get(c, 0)))
            if delta < -1e-9:
                for c, s in faces:
                    z[c] = z.get(c, 0) - t * s
                    wait(c)
                break
    kept = sorted(c for c, v in z.items() if v)
    return kept, [z[c] for c in kept]


def shortest_distances(n, edges, weight, root):
    """The distances ``_root_loops`` finds: Bellman-Ford relaxation until nothing changes."""
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
