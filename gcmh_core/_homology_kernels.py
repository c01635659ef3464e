"""numba kernels of :mod:`gcmh_core.homology`: the coreduction Morse matching and the flow
along it, orienting, edge classes, the loops of a shortest-path tree, shortening a chain
(their slow twins: tests/core/naive_homology.py and homology_naive.py, compared on random
inputs in tests/core/test_homology.py and test_homology_kernels.py).  A module of their
own: numba's cache is keyed on the file, so editing the Python around them does not
recompile them."""

from __future__ import annotations

import numpy as np
from numba import njit

from ._config import INLINE_JIT, JIT

# ----------------------------------------------------------------------------
# kernels: coreductions, and the flow along the matching
# ----------------------------------------------------------------------------

@njit(**INLINE_JIT)
def _leave(x, dims, cb_off, cb, removed, left, queue, qtail, zstack, ztop):
    """Cell x leaves: each coface left loses a face; one with a single face left joins the
    queue, one with none the stack of its dimension.  Returns the queue's new end."""
    removed[x] = True
    for j in range(cb_off[x], cb_off[x + 1]):
        y = cb[j]
        if removed[y]:
            continue
        left[y] -= 1
        if left[y] == 1:
            queue[qtail] = y
            qtail += 1
        elif left[y] == 0:
            zstack[ztop[dims[y]]] = y
            ztop[dims[y]] += 1
    return qtail


@njit(**JIT)
def _coreduce(dims, top, bd_off, bd, cb_off, cb):
    """Coreduction Morse matching.

    Returns (partner, time, critical): partner[x] is the cell x is paired with (-1 for
    a critical cell), time[x] the step at which x left; critical lists the critical
    cells in the order they were chosen.  A pair (a, b) leaves when b's only face left
    is a; when no cell has exactly one face left, a cell of lowest dimension with no
    face left becomes critical.
    """
    n = dims.size
    left = np.empty(n, dtype=np.int64)
    for x in range(n):
        left[x] = bd_off[x + 1] - bd_off[x]
    removed = np.zeros(n, dtype=np.bool_)
    partner = np.full(n, -1, dtype=np.int64)
    time = np.zeros(n, dtype=np.int64)
    queue = np.empty(n + 1, dtype=np.int64)   # cells that have one face left
    qhead = 0
    qtail = 0
    # per dimension, a stack of cells that have no face left (each pushed once)
    zstack = np.empty(n, dtype=np.int64)
    zoff = np.zeros(top + 2, dtype=np.int64)
    for x in range(n):
        zoff[dims[x] + 1] += 1
    for d in range(top + 1):
        zoff[d + 1] += zoff[d]
    ztop = zoff[:-1].copy()
    for x in range(n):
        if left[x] == 0:
            zstack[ztop[dims[x]]] = x
            ztop[dims[x]] += 1
        elif left[x] == 1:
            queue[qtail] = x
            qtail += 1
    critical = np.empty(n, dtype=np.int64)
    n_crit = 0
    clock = 0
    done = 0
    while done < n:
        # coreductions while some cell has one face left
        while qhead < qtail:
            b = queue[qhead]
            qhead += 1
            if removed[b] or left[b] != 1:
                continue
            a = -1
            for j in range(bd_off[b], bd_off[b + 1]):
                if not removed[bd[j]]:
                    a = bd[j]
                    break
            partner[a] = b
            partner[b] = a
            for x in (a, b):
                time[x] = clock
                clock += 1
                done += 1
                qtail = _leave(x, dims, cb_off, cb, removed, left, queue, qtail, zstack, ztop)
            qhead = min(qhead, qtail)
            if qhead == qtail:
                qhead = 0
                qtail = 0
        if done == n:
            break
        # stuck: the lowest-dimensional cell with no face left becomes critical
        c = -1
        for d in range(top + 1):
            while ztop[d] > zoff[d]:
                ztop[d] -= 1
                x = zstack[ztop[d]]
                if not removed[x]:
                    c = x
                    break
            if c >= 0:
                break
        if c < 0:
            break  # cannot happen: a cell of lowest dimension left has no face left
        time[c] = clock
        clock += 1
        done += 1
        critical[n_crit] = c
        n_crit += 1
        qtail = _leave(c, dims, cb_off, cb, removed, left, queue, qtail, zstack, ztop)
    return partner, time, critical[:n_crit]


@njit(**JIT)
def _swap_rows(heap, a, b):
    for c in range(2):
        t = heap[a, c]
        heap[a, c] = heap[b, c]
        heap[b, c] = t


@njit(**JIT)
def _heap_push(heap, size, key, x):
    heap[size, 0] = key
    heap[size, 1] = x
    i = size
    while i > 0:
        p = (i - 1) // 2
        if heap[p, 0] >= heap[i, 0]:
            break
        _swap_rows(heap, p, i)
        i = p
    return size + 1


@njit(**JIT)
def _heap_pop(heap, size):
    x = heap[0, 1]
    size -= 1
    heap[0, 0] = heap[size, 0]
    heap[0, 1] = heap[size, 1]
    i = 0
    while True:
        big = i
        for c in (2 * i + 1, 2 * i + 2):
            if c < size and heap[c, 0] > heap[big, 0]:
                big = c
        if big == i:
            break
        _swap_rows(heap, big, i)
        i = big
    return x, size


@njit(**JIT)
def _room(arr, used, more):
    """`arr` with room for `more` entries after its first `used` (doubled when short)."""
    if used + more <= arr.size:
        return arr
    grown = np.empty(max(2 * arr.size, used + more), dtype=arr.dtype)
    grown[:used] = arr[:used]
    return grown


_LIMIT = 1 << 60  # coefficients past this would overflow int64 in the next step


@njit(**JIT)
def _flow(chain_off, chain_cells, chain_coefs, dims, partner, time, bd_off, bd, bdv, want_lift):
    """Follow the gradient paths from each chain (CSR over chains; cells of one
    dimension q, integer coefficients).

    For a chain x: every (q-1)-cell a of its boundary that is paired with a q-cell b
    is cancelled by x -= ([dx : a] / [b : a]) b, latest-paired first (b's other faces
    left before a, so each is cancelled once).  What stays of dx is on critical cells
    and cells paired downwards: its critical part is the Morse boundary.

    Returns (bd_off, bd_cells, bd_coefs) of the Morse boundaries, the lifted chains x
    (CSR, when want_lift) and an overflow flag.
    """
    n = dims.size
    n_chains = chain_off.size - 1
    bx = np.zeros(n, dtype=np.int64)
    xx = np.zeros(n, dtype=np.int64)
    in_heap = np.zeros(n, dtype=np.bool_)
    touched_b = np.empty(n, dtype=np.int64)
    touched_x = np.empty(n, dtype=np.int64)
    in_x = np.zeros(n, dtype=np.bool_)
    in_b = np.zeros(n, dtype=np.bool_)
    heap = np.empty((n + 1, 2), dtype=np.int64)
    out_off = np.zeros(n_chains + 1, dtype=np.int64)
    out_cells = np.empty(16, dtype=np.int64)
    out_coefs = np.empty(16, dtype=np.int64)
    lift_off = np.zeros(n_chains + 1, dtype=np.int64)
    lift_cells = np.empty(16, dtype=np.int64)
    lift_coefs = np.empty(16, dtype=np.int64)
    overflow = False
    for k in range(n_chains):
        nb = 0
        nx = 0
        hs = 0
        for i in range(chain_off[k], chain_off[k + 1]):
            c = chain_cells[i]
            v = chain_coefs[i]
            if not in_x[c]:
                in_x[c] = True
                touched_x[nx] = c
                nx += 1
            xx[c] += v
            for j in range(bd_off[c], bd_off[c + 1]):
                a = bd[j]
                bx[a] += v * bdv[j]
                if not in_b[a]:
                    in_b[a] = True
                    touched_b[nb] = a
                    nb += 1
                p = partner[a]
                if p >= 0 and dims[p] > dims[a] and not in_heap[a]:
                    in_heap[a] = True
                    hs = _heap_push(heap, hs, time[a], a)
        while hs > 0:
            a, hs = _heap_pop(heap, hs)
            in_heap[a] = False
            ca = bx[a]
            if ca == 0:
                continue
            b = partner[a]
            s = 0
            for j in range(bd_off[b], bd_off[b + 1]):
                if bd[j] == a:
                    s = bdv[j]
            t = ca * s  # s = +-1: ca / s
            if not in_x[b]:
                in_x[b] = True
                touched_x[nx] = b
                nx += 1
            xx[b] -= t
            if abs(xx[b]) > _LIMIT:
                overflow = True
            for j in range(bd_off[b], bd_off[b + 1]):
                g = bd[j]
                bx[g] -= t * bdv[j]
                if abs(bx[g]) > _LIMIT:
                    overflow = True
                if not in_b[g]:
                    in_b[g] = True
                    touched_b[nb] = g
                    nb += 1
                p = partner[g]
                if p >= 0 and dims[p] > dims[g] and not in_heap[g] and bx[g] != 0:
                    in_heap[g] = True
                    hs = _heap_push(heap, hs, time[g], g)
        # collect the critical part of dx and the lifted chain, and clear
        cnt = 0
        for i in range(nb):
            a = touched_b[i]
            if bx[a] != 0 and partner[a] < 0:
                cnt += 1
        start = out_off[k]
        out_cells = _room(out_cells, start, cnt)
        out_coefs = _room(out_coefs, start, cnt)
        w = start
        for i in range(nb):
            a = touched_b[i]
            if bx[a] != 0 and partner[a] < 0:
                out_cells[w] = a
                out_coefs[w] = bx[a]
                w += 1
            bx[a] = 0
            in_b[a] = False
        out_off[k + 1] = w
        start = lift_off[k]
        w = start
        if want_lift:
            lift_cells = _room(lift_cells, start, nx)
            lift_coefs = _room(lift_coefs, start, nx)
        for i in range(nx):
            c = touched_x[i]
            if want_lift and xx[c] != 0:
                lift_cells[w] = c
                lift_coefs[w] = xx[c]
                w += 1
            xx[c] = 0
            in_x[c] = False
        lift_off[k + 1] = w
    return (out_off, out_cells[:out_off[-1]], out_coefs[:out_off[-1]],
            lift_off, lift_cells[:lift_off[-1]], lift_coefs[:lift_off[-1]], overflow)


@njit(**JIT)
def _orient_faces(off, fac, sub_off, sub_face, sub_sign, n_sub):
    """Signs [c : f] of every face entry of the r-cells (CSR off, fac) such that each
    cell's faces cancel on each (r-2)-cell g they share: [c:f1][f1:g] + [c:f2][f2:g] = 0,
    from the faces' own signs (CSR sub_off, sub_face, sub_sign; 0 = no incidence).

    A breadth-first walk over each cell's faces, joined through the (r-2)-cells two of them
    share.  Returns (sign, error, cell, count): error 0 = fine; 1 = an (r-2)-cell lies on
    `count` faces of `cell`, not 2; 2 = the faces cannot be oriented; 3 = the faces fall
    into `count` pieces (the boundary is not one sphere).  A face with no incidence of its
    own (an edge whose two ends are one vertex) gets +1.
    """
    n_cells = off.size - 1
    m = fac.size
    sign = np.zeros(m, dtype=np.int64)
    count = np.zeros(n_sub, dtype=np.int64)
    first = np.zeros(n_sub, dtype=np.int64)
    first_s = np.zeros(n_sub, dtype=np.int64)
    widest = 0
    for c in range(n_cells):
        t = 0
        for j in range(off[c], off[c + 1]):
            t += sub_off[fac[j] + 1] - sub_off[fac[j]]
        widest = max(widest, t)
    ea = np.empty(widest, dtype=np.int64)
    eb = np.empty(widest, dtype=np.int64)
    es = np.empty(widest, dtype=np.bool_)
    for c in range(n_cells):
        ne = 0
        for j in range(off[c], off[c + 1]):
            f = fac[j]
            for t in range(sub_off[f], sub_off[f + 1]):
                s = sub_sign[t]
                if s == 0:
                    continue
                g = sub_face[t]
                count[g] += 1
                if count[g] == 1:
                    first[g] = j
                    first_s[g] = s
                elif count[g] == 2:
                    ea[ne] = first[g]
                    eb[ne] = j
                    es[ne] = first_s[g] == s
                    ne += 1
        bad = 0
        for j in range(off[c], off[c + 1]):
            f = fac[j]
            for t in range(sub_off[f], sub_off[f + 1]):
                g = sub_face[t]
                if sub_sign[t] != 0 and count[g] != 2 and bad == 0:
                    bad = count[g]
        for j in range(off[c], off[c + 1]):
            f = fac[j]
            for t in range(sub_off[f], sub_off[f + 1]):
                count[sub_face[t]] = 0
        if bad:
            return sign, 1, c, bad
        if ne == 0:
            for j in range(off[c], off[c + 1]):
                sign[j] = 1
            continue
        # walk the faces from each one not reached yet; more than one start: pieces
        pieces = 0
        for j0 in range(off[c], off[c + 1]):
            if sign[j0] != 0:
                continue
            lonely = True
            f = fac[j0]
            for t in range(sub_off[f], sub_off[f + 1]):
                if sub_sign[t] != 0:
                    lonely = False
            sign[j0] = 1
            if lonely:
                continue
            pieces += 1
            changed = True
            while changed:   # cells have few faces: sweep the pairs until nothing changes
                changed = False
                for e in range(ne):
                    a, b = ea[e], eb[e]
                    if sign[a] != 0 and sign[b] == 0:
                        sign[b] = -sign[a] if es[e] else sign[a]
                        changed = True
                    elif sign[b] != 0 and sign[a] == 0:
                        sign[a] = -sign[b] if es[e] else sign[b]
                        changed = True
        if pieces > 1:
            return sign, 3, c, pieces
        for e in range(ne):
            want = -sign[ea[e]] if es[e] else sign[ea[e]]
            if sign[eb[e]] != want:
                return sign, 2, c, 0
    return sign, 0, -1, 0


@njit(**JIT)
def _orient_top(off, fac, sign, n_faces):
    """Orient the top cells (CSR off, fac over their faces, incidences sign = +-1) coherently.

    A breadth-first walk over the dual graph, from the lowest cell not reached yet, faces
    in their order: across a face f on exactly two cell entries (c, s) and (c', s'), c'
    gets eps[c'] = -eps[c] s s' so that eps[c] s + eps[c'] s' = 0 (f cancels).  Returns
    (eps (C,) int8, conflict): conflict lists the faces on two entries that still do not
    cancel (sorted): empty iff the complex is orientable (faces on one entry are boundary,
    on three or more are left out).
    """
    n_cells = off.size - 1
    count = np.zeros(n_faces, dtype=np.int64)
    for j in range(fac.size):
        count[fac[j]] += 1
    # each face's first and second entry (the other side of a face on two entries)
    first = np.full(n_faces, -1, dtype=np.int64)
    second = np.full(n_faces, -1, dtype=np.int64)
    owner = np.empty(fac.size, dtype=np.int64)
    for c in range(n_cells):
        for j in range(off[c], off[c + 1]):
            owner[j] = c
            f = fac[j]
            if first[f] < 0:
                first[f] = j
            else:
                second[f] = j
    eps = np.zeros(n_cells, dtype=np.int8)
    queue = np.empty(n_cells, dtype=np.int64)
    for start in range(n_cells):
        if eps[start] != 0:
            continue
        eps[start] = 1
        head = 0
        tail = 1
        queue[0] = start
        while head < tail:
            c = queue[head]
            head += 1
            for j in range(off[c], off[c + 1]):
                f = fac[j]
                if count[f] != 2:
                    continue
                k = second[f] if first[f] == j else first[f]
                d = owner[k]
                if eps[d] == 0:
                    eps[d] = -eps[c] * sign[j] * sign[k]
                    queue[tail] = d
                    tail += 1
    n_bad = 0
    bad = np.empty(n_faces, dtype=np.int64)
    for f in range(n_faces):
        if count[f] == 2:
            a = first[f]
            b = second[f]
            if eps[owner[a]] * sign[a] + eps[owner[b]] * sign[b] != 0:
                bad[n_bad] = f
                n_bad += 1
    return eps, bad[:n_bad]


@njit(**JIT)
def _edge_classes(order, b1, dims, partner, bd_off, bd, bdv, pos, c1):
    """The Morse chain map on edges: phi[e] in Z^c1 (coordinates on the critical edges),
    for the edges in `order` (increasing coreduction time; global ids b1 + e).

    A critical edge is its own coordinate; an edge paired with a vertex maps to 0; an edge
    e paired with a 2-cell f maps where the rest of f's boundary does, e -> e - [f:e] df
    (f's other edges left before e: their phi is known).  phi of a cycle is a Morse cycle
    in its class.  Returns (phi (E, c1) int64, overflow).
    """
    n_edges = order.size
    phi = np.zeros((n_edges, c1), dtype=np.int64)
    overflow = False
    for i in range(n_edges):
        e = order[i]
        g = b1 + e
        p = partner[g]
        if p < 0:
            phi[e, pos[g]] = 1
        elif dims[p] == 2:
            s = 0
            for j in range(bd_off[p], bd_off[p + 1]):
                if bd[j] == g:
                    s = bdv[j]
            for j in range(bd_off[p], bd_off[p + 1]):
                h = bd[j]
                if h == g:
                    continue
                t = s * bdv[j]
                for k in range(c1):
                    phi[e, k] -= t * phi[h - b1, k]
                    if abs(phi[e, k]) > _LIMIT:
                        overflow = True
    return phi, overflow


@njit(**JIT)
def _root_loops(adj_off, adj_to, adj_edge, weight, eu, ev, edge_bits, root, radius, nearest):
    """The loops closed by a shortest-path tree from `root` (Dijkstra on the graph in CSR:
    adj_to, adj_edge the neighbour and the edge to it, weight per edge >= 0), then for each
    edge e = (u, v) off the tree with both ends settled, the loop root -> u -> v -> root:
    its length dist[u] + weight[e] + dist[v] and its class mask, the xor of edge_bits along
    it (path bits down the tree, in settle order).  Only loops whose mask is not 0 are kept,
    in edge order.  The heap moves a vertex up when a shorter way in is found (each vertex
    in it once).

    A vertex is settled (and its edges followed) when it is at most `radius` away, or
    nearer to the root than `nearest` (the distance to the roots before, updated here: the
    farthest-point choice of roots needs it exact, and a vertex no nearer to this root
    than to those before has no vertex behind it that is).  Every loop through the root
    of length L keeps within L / 2 of it, so a radius of L / 2 finds all loops of length
    at most L, on the same tree as an unbounded walk (the same order of settling up to L / 2).

    Returns (edges, lengths, masks, dist, pred_edge, pred); dist is inf, pred_edge and
    pred -1 at the vertices not settled (pred_edge and pred -1 at the root too).
    """
    n = adj_off.size - 1
    dist = np.full(n, np.inf)
    pred = np.full(n, -1, dtype=np.int64)
    pred_edge = np.full(n, -1, dtype=np.int64)
    done = np.zeros(n, dtype=np.bool_)
    path = np.zeros(n, dtype=np.uint64)
    # a binary heap of vertices keyed by dist, with each one's place (-1: not in it), so a
    # shorter way in moves it up (decrease-key) instead of pushing it again
    heap = np.empty(n, dtype=np.int64)
    place = np.full(n, -1, dtype=np.int64)
    size = 1
    heap[0] = root
    place[root] = 0
    dist[root] = 0.0
    while size > 0:
        u = heap[0]
        d = dist[u]
        place[u] = -1
        size -= 1
        if size > 0:   # the last one sifts down from the top
            x = heap[size]
            dx = dist[x]
            i = 0
            while True:
                c = 2 * i + 1
                if c >= size:
                    break
                if c + 1 < size and dist[heap[c + 1]] < dist[heap[c]]:
                    c += 1
                if dist[heap[c]] >= dx:
                    break
                heap[i] = heap[c]
                place[heap[i]] = i
                i = c
            heap[i] = x
            place[x] = i
        if d > radius and d >= nearest[u]:
            continue
        done[u] = True
        if d < nearest[u]:
            nearest[u] = d
        if pred[u] >= 0:   # its parent settled before it
            path[u] = path[pred[u]] ^ edge_bits[pred_edge[u]]
        for j in range(adj_off[u], adj_off[u + 1]):
            v = adj_to[j]
            nd = d + weight[adj_edge[j]]
            if nd < dist[v] and not done[v]:
                dist[v] = nd
                pred[v] = u
                pred_edge[v] = adj_edge[j]
                i = place[v]
                if i < 0:
                    i = size
                    size += 1
                while i > 0:   # sift up
                    p = (i - 1) >> 1
                    if dist[heap[p]] <= nd:
                        break
                    heap[i] = heap[p]
                    place[heap[i]] = i
                    i = p
                heap[i] = v
                place[v] = i
    for x in range(n):   # the vertices reached but not settled hang from nothing
        if not done[x]:
            dist[x] = np.inf
            pred[x] = -1
            pred_edge[x] = -1
    n_edges = eu.size
    out_e = np.empty(n_edges, dtype=np.int64)
    out_len = np.empty(n_edges, dtype=np.float64)
    out_mask = np.empty(n_edges, dtype=np.uint64)
    k = 0
    for e in range(n_edges):
        u = eu[e]
        v = ev[e]
        if not (done[u] and done[v]) or pred_edge[u] == e or pred_edge[v] == e:
            continue
        m = path[u] ^ path[v] ^ edge_bits[e]
        if m != 0:
            out_e[k] = e
            out_len[k] = dist[u] + weight[e] + dist[v]
            out_mask[k] = m
            k += 1
    return out_e[:k], out_len[:k], out_mask[:k], dist, pred_edge, pred


@njit(**JIT)
def _shorten_chain(cells, coefs, b, bd_off, bd, bdv, cb_off, cb, weight):
    """A smaller q-cycle in the same class (the kernel of homology._shorten): z -> z - t d(f)
    for a (q+1)-cell f and t = +1, then -1, while that lowers sum weight[c - b] |z_c|.

    The (q+1)-cells to try wait in a first-in first-out queue, each once at a time: first
    the cofaces of z's cells in their order, then, whenever z changes on a q-cell, that
    cell's cofaces not waiting already.  Each step lowers the weight by more than 1e-9,
    so no chain comes twice: it ends.  cells: global ids of q-cells (b the global id of
    q-cell 0), weight per q-cell.  Returns (cells, coefficients), cells ascending.
    """
    n_q = weight.size
    z = np.zeros(n_q, dtype=np.int64)
    on = np.zeros(n_q, dtype=np.bool_)
    members = np.empty(max(cells.size, 16), dtype=np.int64)   # q-cells z has touched
    n_mem = 0
    for i in range(cells.size):
        c = cells[i] - b
        z[c] += coefs[i]
        if not on[c]:
            on[c] = True
            members = _room(members, n_mem, 1)
            members[n_mem] = c
            n_mem += 1
    waiting = np.zeros(cb_off.size - 1, dtype=np.bool_)
    queue = np.empty(64, dtype=np.int64)   # a ring buffer
    head = 0
    count = 0
    for i in range(n_mem):
        c = members[i] + b
        for j in range(cb_off[c], cb_off[c + 1]):
            f = cb[j]
            if not waiting[f]:
                waiting[f] = True
                queue, head, count = _ring_push(queue, head, count, f)
    while count > 0:
        f = queue[head]
        head = (head + 1) % queue.size
        count -= 1
        waiting[f] = False
        for t in (1, -1):
            delta = 0.0
            for j in range(bd_off[f], bd_off[f + 1]):
                c = bd[j] - b
                delta += weight[c] * (abs(z[c] - t * bdv[j]) - abs(z[c]))
            if delta < -1e-9:
                for j in range(bd_off[f], bd_off[f + 1]):
                    c = bd[j] - b
                    z[c] -= t * bdv[j]
                    if not on[c]:
                        on[c] = True
                        members = _room(members, n_mem, 1)
                        members[n_mem] = c
                        n_mem += 1
                    for k in range(cb_off[bd[j]], cb_off[bd[j] + 1]):
                        g = cb[k]
                        if not waiting[g]:
                            waiting[g] = True
                            queue, head, count = _ring_push(queue, head, count, g)
                break
    kept = 0
    for i in range(n_mem):
        if z[members[i]] != 0:
            kept += 1
    out = np.empty(kept, dtype=np.int64)
    k = 0
    for i in range(n_mem):
        if z[members[i]] != 0:
            out[k] = members[i]
            k += 1
    out.sort()
    vals = np.empty(kept, dtype=np.int64)
    for i in range(kept):
        vals[i] = z[out[i]]
        out[i] += b
    return out, vals


@njit(**INLINE_JIT)
def _ring_push(queue, head, count, x):
    """x put at the end of a ring buffer of `count` entries from `head` (grown when full):
    (queue, head, count) after it."""
    if count == queue.size:
        queue = _grow_ring(queue, head, count)
        head = 0
    queue[(head + count) % queue.size] = x
    return queue, head, count + 1


@njit(**JIT)
def _grow_ring(queue, head, count):
    """A ring buffer of `count` entries from `head`, copied in order into one twice as long."""
    grown = np.empty(2 * queue.size, dtype=queue.dtype)
    for i in range(count):
        grown[i] = queue[(head + i) % queue.size]
    return grown


@njit(**JIT)
def _tree_residues(pred, pred_edge, eu, value, modulus):
    """Sums of an integer edge cochain down a shortest-path tree, modulo `modulus`: res[x] is the sum of
    +-value[e] along the tree path root -> x (+ where the edge e = (eu[e], ev[e]) runs from the parent
    to the child, - against), in [0, modulus); 0 at the root and at the vertices hanging from nothing
    (pred < 0).  Each vertex walks up to the first vertex known, then the path is filled in going down."""
    n = pred.size
    res = np.zeros(n, dtype=np.int64)
    known = np.zeros(n, dtype=np.bool_)
    stack = np.empty(n, dtype=np.int64)
    for x in range(n):
        if pred[x] < 0:
            known[x] = True
    for x in range(n):
        top = 0
        y = x
        while not known[y]:
            stack[top] = y
            top += 1
            y = pred[y]
        while top > 0:
            top -= 1
            y = stack[top]
            e = pred_edge[y]
            step = value[e] if eu[e] == pred[y] else -value[e]
            res[y] = (res[pred[y]] + step) % modulus
            known[y] = True
    return res


@njit(**JIT)
def _polygon_areas(offs, verts, X):
    """Area of each polygon (CSR loops offs, verts over points X (V, n)) in R^n: its triangles fanned
    from its first vertex, each |a| |b| sin from the Gram determinant (a, b the edges from that vertex)."""
    n_poly = offs.size - 1
    dim = X.shape[1]
    out = np.zeros(n_poly, dtype=np.float64)
    for p in range(n_poly):
        o = verts[offs[p]]
        total = 0.0
        for j in range(offs[p], offs[p + 1]):
            k = j + 1 if j + 1 < offs[p + 1] else offs[p]   # cyclically within the loop
            aa = 0.0
            bb = 0.0
            ab = 0.0
            for d in range(dim):
                a = X[verts[j], d] - X[o, d]
                b = X[verts[k], d] - X[o, d]
                aa += a * a
                bb += b * b
                ab += a * b
            gram = aa * bb - ab * ab
            total += 0.5 * np.sqrt(gram) if gram > 0.0 else 0.0
        out[p] = total
    return out


@njit(**JIT)
def _greedy_basis(mask, basis, n_want):
    """The greedy basis mod 2: the first `n_want` of the GF(2) vectors `mask` (uint64 bit rows, in the
    order given) independent of `basis` (in elimination order, distinct highest bits) and of those taken
    before them.  Each is reduced by the basis so far, in order, by each vector's highest bit, and
    joins it when something is left.  Returns their indices (fewer when the vectors run out)."""
    b = np.empty(basis.size + n_want, dtype=np.uint64)
    top = np.empty(basis.size + n_want, dtype=np.uint64)
    nb = 0
    for j in range(basis.size):
        b[nb] = basis[j]
        nb += 1
    for j in range(nb):
        h = np.uint64(0)
        while (b[j] >> (h + np.uint64(1))) != 0:
            h += np.uint64(1)
        top[j] = h
    chosen = np.empty(n_want, dtype=np.int64)
    k = 0
    for i in range(mask.size):
        if k == n_want:
            break
        x = mask[i]
        for j in range(nb):
            if (x >> top[j]) & np.uint64(1):
                x ^= b[j]
        if x != 0:
            b[nb] = x
            h = np.uint64(0)
            while (x >> (h + np.uint64(1))) != 0:
                h += np.uint64(1)
            top[nb] = h
            nb += 1
            chosen[k] = i
            k += 1
    return chosen[:k]
