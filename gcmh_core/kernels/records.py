"""The records a chunk kernel returns, in cube order: rows grown as they are written, then
copied out."""

import numba as nb
import numpy as np

from .._config import INLINE_JIT, JIT

# f, of its vertices.  A vertex's local code in f depends only on where its k-face
# and Kuhn simplex sit inside f, so both cubes sharing f compute the same key.
EDGE_COLS = 3  # edge key, vertex key a, vertex key b
CELL_COLS = 2  # r, cell key
INC_COLS = 3  # r, key of the r-cell X, key of its (r-1)-face Y


# A helper inlined into a kernel loop takes scalars, not arrays: in functions as large
# as the chunk kernels numba leaves the reference counts of array arguments of an
# inlined call unpruned, and those atomic updates cost more than the work.


@nb.njit(**JIT)
def _new_records(rows, n):
    return (
        np.empty(rows, np.int64),
        np.empty((rows, n), np.float64),
        np.empty((rows, EDGE_COLS), np.int64),
        np.empty((rows, CELL_COLS), np.int64),
        np.empty((rows, INC_COLS), np.int64),
    )


# Copies are loops: a slice assignment (b[:used] = a[:used]) brings numba's shape-mismatch
# error path, whose message formatting compiled for seconds on a first run.
@nb.njit(**JIT)
def _grown_keys(a, used):
    """a's first `used` entries in an array twice as long."""
    b = np.empty(2 * a.shape[0] + 1, a.dtype)
    for i in range(used):
        b[i] = a[i]
    return b


@nb.njit(**JIT)
def _grown_rows(a, used):
    """a's first `used` rows in an array with twice the rows."""
    b = np.empty((2 * a.shape[0] + 1, a.shape[1]), a.dtype)
    for i in range(used):
        for j in range(a.shape[1]):
            b[i, j] = a[i, j]
    return b


@nb.njit(**JIT)
def _records_upto(vk, vp, e, c, i, used_v, used_e, used_c, used_i):
    """The written rows, copied out of the (up to twice too long) growing arrays."""
    return vk[:used_v].copy(), vp[:used_v].copy(), e[:used_e].copy(), c[:used_c].copy(), i[:used_i].copy()


# A GCMH chunk between its phases (`gcmh.cubes_chunk`, `lazy.cubes_chunk_lazy`): the vertices and
# edges of cubes lo..hi-1, cube i's in rows cube_v0[i - lo]..cube_v0[i - lo + 1] - 1 and
# cube_e0[...]; an edge's ends are the cube's own vertex numbers (0..nv-1).  The vertex rows are
# the vertex records; the edge records (edge_out) share the edges' rows.
CHUNK_FIELDS = ("cube_v0", "cube_e0", "crossed_facets", "vertex_key", "vertex_point", "vertex_face", "vertex_perm",
                "vertex_ksimplex", "edge_a", "edge_b", "edge_face", "edge_out")


@nb.njit(**INLINE_JIT)
def new_chunk(cubes, vertex_rows, edge_rows, n):
    """Empty chunk arrays (CHUNK_FIELDS) for `cubes` cubes."""
    return (
        np.zeros(cubes + 1, np.int64), np.zeros(cubes + 1, np.int64), np.zeros(cubes, np.int64),
        np.empty(vertex_rows, np.int64), np.empty((vertex_rows, n), np.float64), np.empty(vertex_rows, np.int64),
        np.empty(vertex_rows, np.int64), np.empty(vertex_rows, np.int64),
        np.empty(edge_rows, np.int64), np.empty(edge_rows, np.int64), np.empty(edge_rows, np.int64),
        np.empty((edge_rows, EDGE_COLS), np.int64),
    )


@nb.njit(**INLINE_JIT)
def grown_chunk(vertex_key, vertex_point, vertex_face, vertex_perm, vertex_ksimplex, edge_a, edge_b, edge_face,
                edge_out, used_v, used_e):
    """The chunk's vertex and edge arrays with room for twice the rows, the first used_v and used_e kept."""
    return (
        _grown_keys(vertex_key, used_v), _grown_rows(vertex_point, used_v), _grown_keys(vertex_face, used_v),
        _grown_keys(vertex_perm, used_v), _grown_keys(vertex_ksimplex, used_v),
        _grown_keys(edge_a, used_e), _grown_keys(edge_b, used_e), _grown_keys(edge_face, used_e),
        _grown_rows(edge_out, used_e),
    )
