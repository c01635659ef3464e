"""Which cubes can hold a piece of M_A (paper 3.1, step 1), on the grid and in continuation."""

import numba as nb
import numpy as np
from numba import prange

from .._config import JIT, PARALLEL_JIT

# ----------------------------------------------------------------------------- the candidate pass
# Which cubes can hold a piece of M_A: every component of F has a value >= 0 and one < 0
# among the cube's corners, and no corner value is NaN or infinite.  A per-vertex code
# (bit 2j: F_j >= 0, bit 2j+1: F_j < 0, bit 2k: not finite) OR-ed over the corners is
# separable.  A block's vertices are cut into planes (fixed indices on axes 0 and 1, the
# other axes contiguous): each plane is coded and OR-ed along its own axes while it is in
# cache, and a cube's code is then the OR of four plane codes at one offset.  (Whole-block
# passes, one per axis, read the block five times and took twice as long as evaluating F.)


@nb.njit(**PARALLEL_JIT)
def plane_codes(vals, code, first, inner_dims):
    """vals (Q, P, k): F at the vertices of Q planes of P vertices each (C order over
    inner_dims); code (Q, P) unsigned: for planes first..Q-1, each vertex's code OR-ed
    over the in-plane corners of the cube it is the origin of (along every inner axis).
    Returns how many of those vertices have a value that is not finite.
    """
    q_count, p_count, k = vals.shape
    bad = np.uint64(1) << np.uint64(2 * k)
    nonfinite = 0
    for q in prange(first, q_count):
        here = 0
        for v in range(p_count):
            c = np.uint64(0)
            for j in range(k):
                x = vals[q, v, j]
                if not np.isfinite(x):
                    c = bad
                    here += 1
                    break
                c |= np.uint64(1 if x >= 0.0 else 2) << np.uint64(2 * j)
            code[q, v] = c
        nonfinite += here
        stride = 1
        for a in range(inner_dims.shape[0] - 1, -1, -1):
            length = inner_dims[a]
            block = length * stride
            for o in range(0, p_count, block):  # in increasing index: code[v + stride] is read unchanged
                for v in range(o, o + block - stride):
                    code[q, v] |= code[q, v + stride]
            stride = block
    return nonfinite


@nb.njit(**PARALLEL_JIT)
def scan_candidates(code, d0, d1, inner_dims, k, counts, offsets, out):
    """The candidate cubes of a block whose planes (see `plane_codes`) are code (d0 * d1, P).

    Cube plane t = i0 * (d1 - 1) + i1 holds the cubes with origin (i0, i1, ...).  With
    an empty `out`, counts[t] = its number of candidates; else its candidates' origins
    are written, in C order, to out[offsets[t]:] (n columns).
    """
    full = np.uint64(0)
    for j in range(k):
        full |= np.uint64(3) << np.uint64(2 * j)
    mask = full | (np.uint64(1) << np.uint64(2 * k))
    nd = inner_dims.shape[0]
    last = inner_dims[nd - 1] if nd > 0 else 2  # (no inner axis: one vertex per plane)
    rows = code.shape[1] // last if nd > 0 else 1
    write = out.shape[0] > 0
    for t in prange((d0 - 1) * (d1 - 1)):
        i0 = t // (d1 - 1)
        i1 = t % (d1 - 1)
        q = i0 * d1 + i1
        found = 0
        p = offsets[t] if write else 0
        for r in range(rows):
            rem = r
            inside = True
            for a in range(nd - 2, -1, -1):  # the row's indices on the inner axes but the last
                if rem % inner_dims[a] == inner_dims[a] - 1:
                    inside = False
                rem //= inner_dims[a]
            if not inside:
                continue
            for j in range(last - 1):
                v = r * last + j if nd > 0 else 0
                c = code[q, v] | code[q + 1, v] | code[q + d1, v] | code[q + d1 + 1, v]
                if (c & mask) != full:
                    continue
                if write:
                    out[p, 0] = i0
                    out[p, 1] = i1
                    rem = r
                    for a in range(nd - 2, -1, -1):
                        out[p, 2 + a] = rem % inner_dims[a]
                        rem //= inner_dims[a]
                    if nd > 0:
                        out[p, 1 + nd] = j
                    p += 1
                else:
                    found += 1
        if not write:
            counts[t] = found


@nb.njit(**JIT)
def corner_sets_to_candidates(vals, n_corners, out):
    """out[i]: the candidate test of `codes_to_candidates` for cube i, whose corners are the
    rows i * n_corners .. (i + 1) * n_corners - 1 of vals (continuation gathers them so).

    Serial and fused: a wave is small, and two parallel launches per wave cost more
    than the test.
    """
    k = vals.shape[1]
    full = (np.int64(1) << (2 * k)) - 1
    for i in range(out.shape[0]):
        code = np.int64(0)
        finite = True
        for r in range(i * n_corners, (i + 1) * n_corners):
            for j in range(k):
                x = vals[r, j]
                if not np.isfinite(x):
                    finite = False
                code |= np.int64(1 if x >= 0.0 else 2) << (2 * j)
        out[i] = finite and code == full


# ----------------------------------------------------------------------------- continuation
@nb.njit(**JIT)
def facet_neighbours(wave, masks, div, cube_strides):
    """The cubes across the crossed facets of a wave's cubes, inside the grid.

    wave (m, n) cube origins; masks (m,) crossed-facet bits (bit 2a + side: side 0 leads
    to the cube below on axis a, side 1 above); div (n,) cubes per axis.  Returns
    (cubes (M, n), their linear keys (M,) by cube_strides), cube by cube, facets in bit
    order; a cube reached twice appears twice.
    """
    m, n = wave.shape
    total = 0
    for i in range(m):
        for f in range(2 * n):
            if masks[i] >> f & 1:
                total += 1
    cubes = np.empty((total, n), np.int64)
    keys = np.empty(total, np.int64)
    p = 0
    for i in range(m):
        for f in range(2 * n):
            if not masks[i] >> f & 1:
                continue
            a = f // 2
            to = wave[i, a] + (1 if f & 1 else -1)
            if to < 0 or to >= div[a]:
                continue
            key = 0
            for b in range(n):
                x = to if b == a else wave[i, b]
                cubes[p, b] = x
                key += x * cube_strides[b]
            keys[p] = key
            p += 1
    return cubes[:p], keys[:p]
