"""The walk (paper 3.1.1, Fig. 3) that joins the vertices of M_H on a (k+1)-face, for both kernels.

A (k+1)-face with two vertices has one edge; with more, the walk pairs them: in each crossed
Kuhn (k+1)-simplex of the face its two crossed k-facets (nodes) are linked (`_link`), and
the links are followed from each boundary node to the next (`_walk_edges`).  The tables'
kernel (`gcmh`) numbers the nodes by its tables, the lazy kernel by a hash table of the
nodes it meets: both hand over rows of walk_next0/1.
"""

import numba as nb

from .._config import INLINE_JIT, JIT


@nb.njit(**INLINE_JIT)
def _link(walk_next0, walk_next1, n_crossed, node_a, node_b):
    """One Kuhn (k+1)-simplex of the walk: its two crossed k-facets (rows node_a, node_b) are
    linked.  Returns the degenerate events: any other count of crossed facets, or a node
    linked a third time.  (Inlined: it runs once per crossed simplex of a walk.)"""
    if n_crossed == 0:
        return 0
    if n_crossed != 2:
        return 1
    degenerate = 0
    for pair in range(2):
        u = node_a if pair == 0 else node_b
        w = node_b if pair == 0 else node_a
        if walk_next0[u] < 0:
            walk_next0[u] = w
        elif walk_next1[u] < 0:
            walk_next1[u] = w
        else:
            degenerate += 1
    return degenerate


@nb.njit(**JIT)
def _walk_edges(walk_next0, walk_next1, node_id, n_boundary, n_steps, found_row, found_vertex, n_found, walked,
                edge_a, edge_b, edge_face, ne, face):
    """The walk's edges on one (k+1)-face: from each crossed boundary node (found_row[q], its row
    in the links walk_next0/1, -1 if it has none; found_vertex[q], its vertex) the links are
    followed to the next boundary node (node_id[row] < n_boundary), and the two vertices are
    joined as edge rows ne.. on the face.  Returns (ne, degenerate events).  (A plain call:
    once per face that needs the walk.)"""
    degenerate = 0
    for q in range(n_found):
        walked[q] = 0
    for q in range(n_found):
        if walked[q]:
            continue
        start = found_row[q]
        before = -1
        at = start
        end = -1
        if start >= 0:
            for _step in range(n_steps):
                nxt = walk_next0[at] if walk_next0[at] != before else walk_next1[at]
                if nxt < 0:
                    break
                before = at
                at = nxt
                if node_id[at] < n_boundary:
                    end = at
                    break
        if end < 0 or end == start:
            degenerate += 1
            walked[q] = 1
            continue
        for q2 in range(n_found):
            if found_row[q2] == end:
                walked[q2] = 1
                edge_b[ne] = found_vertex[q2]
        walked[q] = 1
        edge_a[ne] = found_vertex[q]
        edge_face[ne] = face
        ne += 1
    return ne, degenerate
