"""The barycentric solve on a Kuhn (CFK) simplex (paper 3.1.1), and the sign prune before it.

The sign prune: a zero of F in the hull of a set of corners needs every component F_j to
take a value >= 0 and one < 0 among them (a value 0 counts as +epsilon).  It is written
once for each way the kernels hold a set of corners: a bit mask (n <= 6, `crossable_mask`),
a chain of corners in a table row (`crossable_chain`), a cube face (`crossable_face`).
They are inlined (numba, at IR level): as plain calls they doubled the kernel's time.
"""

import numba as nb
import numpy as np

from .._config import INLINE_JIT, JIT


@nb.njit(**INLINE_JIT)
def crossable_mask(positive_corners, m, k):
    """The sign prune on the corners in bit mask m (positive_corners[j], bit c: F_j >= 0 at
    corner c): can F be 0 on their hull?  A whole face at once, a simplex in 2k operations."""
    for j in range(k):
        on = positive_corners[j] & m
        if on == 0 or on == m:  # F_j has one sign on every corner
            return False
    return True


@nb.njit(**INLINE_JIT)
def crossable_chain(corner_signs, table, s, m, full):
    """The sign prune on the corners table[s, 0..m-1] (corner_signs[c], bit j: F_j >= 0 at c;
    full: all k bits)."""
    any_pos = 0
    all_pos = full
    for i in range(m):
        p = corner_signs[table[s, i]]
        any_pos |= p
        all_pos &= p
    return any_pos == full and all_pos == 0


@nb.njit(**INLINE_JIT)
def crossable_face(corner_signs, free, fixed, full):
    """The sign prune on the corners of the cube face (free axes, fixed corner): at k = 8 one
    test instead of one per each of the face's 8! Kuhn simplices (n = 10: 2x faster)."""
    any_pos = 0
    all_pos = full
    sub = free
    while True:  # every subset of the free axes
        p = corner_signs[fixed | sub]
        any_pos |= p
        all_pos &= p
        if sub == 0:
            break
        sub = (sub - 1) & free
    return any_pos == full and all_pos == 0


# |lam_i| below this: the zero is on facet i up to rounding, and `_zero_side` decides symbolically
NEAR_FACET = 1e-9
# a determinant at most this fraction of its Hadamard bound (the product of its rows' norms) is 0
DET_ZERO = 1e-12
# `_sos_det` tries the perturbation's terms over the first this many entries of a facet: all of them up to
# k = 4; above, 2^16 subsets at most (a whole component 0 with k = 6 took 0.5 s a simplex with 2^20)
_SOS_ENTRIES = 16


@nb.njit(**JIT)
def _det(M, d):
    """det of M[:d, :d] (destroyed), and 0 where it is at most DET_ZERO of its Hadamard bound.
    Gaussian elimination with partial pivoting: the same input gives the same float everywhere."""
    bound = 1.0
    for j in range(d):
        r = 0.0
        for i in range(d):
            r += M[j, i] * M[j, i]
        bound *= np.sqrt(r)
    det = 1.0
    for c in range(d):
        piv = c
        best = abs(M[c, c])
        for rr in range(c + 1, d):
            if abs(M[rr, c]) > best:
                best = abs(M[rr, c])
                piv = rr
        if best == 0.0:
            return 0.0
        if piv != c:
            det = -det
            for i in range(c, d):
                t = M[c, i]
                M[c, i] = M[piv, i]
                M[piv, i] = t
        det *= M[c, c]
        for rr in range(c + 1, d):
            fac = M[rr, c] / M[c, c]
            if fac != 0.0:
                for i in range(c, d):
                    M[rr, i] -= fac * M[c, i]
    if not (abs(det) > DET_ZERO * bound):  # (also NaN)
        return 0.0
    return det


@nb.njit(**JIT)
def _sos_det(P, i, k, A):
    """The leading term of det[F(v_q) + eps_q]_{q != i} (k x k: row j, column q), F_j(v_q) moved by
    eps^(2^(q k + j)) (simulation of simplicity, Edelsbrunner and Muecke): the smallest exponent,
    as the bit mask of (q, j) whose perturbations the term takes (0: the determinant itself), and
    its coefficient.  The columns' order is the corners' (chain order, the grid's global order),
    so every simplex that has this facet gets the same sign.  (-1, 0.0): not found (k > 4 only).

    The terms come in the order of their exponents (the subsets of entries as binary numbers);
    a term's coefficient is the determinant with the term's rows replaced by unit rows."""
    cols = np.empty(k, np.int64)
    c = 0
    for q in range(k + 1):
        if q != i:
            cols[c] = q
            c += 1
    n_entries = min(k * k, _SOS_ENTRIES)
    for b in range(np.int64(1) << n_entries):
        rows_used = 0
        cols_used = 0
        ok = True
        bb = b
        t = 0
        while bb:
            if bb & 1:
                jr = t % k
                qc = t // k
                if (rows_used >> jr) & 1 or (cols_used >> qc) & 1:
                    ok = False
                    break
                rows_used |= 1 << jr
                cols_used |= 1 << qc
            bb >>= 1
            t += 1
        if not ok:
            continue
        for j in range(k):
            if (rows_used >> j) & 1:
                for qc in range(k):
                    A[j, qc] = 0.0
            else:
                for qc in range(k):
                    A[j, qc] = P[cols[qc], j]
        exponent = np.int64(0)
        bb = b
        t = 0
        while bb:
            if bb & 1:
                A[t % k, t // k] = 1.0
                exponent |= np.int64(1) << (cols[t // k] * k + t % k)
            bb >>= 1
            t += 1
        d = _det(A, k)
        if d != 0.0:
            return exponent, d
    return np.int64(-1), 0.0


@nb.njit(**JIT)
def _zero_side(vals, o, value_off, table, s, k, lam):
    """`simplex_crosses`' answer 2 decided: 1 if the zero is inside the simplex, else 0, by
    simulation of simplicity (`_sos_det`).

    A zero of F's interpolant on the simplex v_0..v_k is inside where the k + 1 determinants
    D_i = (-1)^i det[F(v_q)]_{q != i} have one sign (lam_i = D_i / sum D); D_i depends on the
    facet opposite v_i only, so the simplices that share that facet agree about it, and a
    (k+1)-simplex has 0 or 2 crossed k-facets.  Every value F_j(v) is F_j(v) + eps^(2^(q k + j))
    (q: v's place in the chain), so no D_i is 0 and a value 0 is positive (the sign prune's
    rule).  lam receives the limit eps -> 0 of the zero: the solve's lam (negatives made 0)
    where it solved (lam[0] is not NaN) and the simplex is not flat, else the ratio of the
    leading terms.  (Called from the kernels' own loops, rarely: as a branch inside the
    inlined solve it slowed every cube by a fifth.)
    """
    m = k + 1
    P = np.empty((m, k))
    for q in range(m):
        r = o + value_off[table[s, q]]
        for j in range(k):
            P[q, j] = vals[r, j]
    A = np.empty((k, k))
    exps = np.empty(m, np.int64)
    coefs = np.empty(m)
    for i in range(m):
        e, c = _sos_det(P, i, k, A)
        if e < 0:
            return 0
        exps[i] = e
        coefs[i] = -c if i & 1 else c
    lead = exps[0]
    for i in range(m):
        if (coefs[i] > 0.0) != (coefs[0] > 0.0):
            return 0
        if exps[i] < lead:
            lead = exps[i]
    if lead == 0 and lam[0] == lam[0]:
        for i in range(m):
            if lam[i] < 0.0:
                lam[i] = 0.0
        return 1
    total = 0.0
    for i in range(m):
        if exps[i] == lead:
            total += coefs[i]
    for i in range(m):
        lam[i] = coefs[i] / total if exps[i] == lead else 0.0
    return 1


@nb.njit(**INLINE_JIT)
def simplex_crosses(vals, o, value_off, table, s, k, pos_mask, full, mat, rhs, lam):
    """Does the CFK simplex with cube corners table[s, 0..k] (chain order) hold a zero?
    1 yes, 0 no, 2 only up to rounding on a facet: then `_zero_side` decides.

    vals (NV, k): F's values (`values` in the kernels); corner c of the cube is row
    o + value_off[c] (`corner_row`); pos_mask and full are the kernels' `corner_signs`
    and `all_signs`; lam (k+1,) receives the barycentric coordinates.  Sign prune
    first: every component needs a value >= 0 and one < 0 among the simplex's corners,
    else there is no solve at all.  The simplex comes as a table and a row, not as the
    row itself: a slice made per simplex costs reference counting that was once most of
    a cube's work.  Kernels prune in their own loops first and call this for the few
    simplices that pass.  (The parameters keep their old names: renamed like the
    kernels' variables, they made the inlined code 10% slower on the complex cosine.)
    """
    m = k + 1
    any_pos = 0
    all_pos = full
    for i in range(m):
        p = pos_mask[table[s, i]]
        any_pos |= p
        all_pos &= p
    if any_pos != full or all_pos != 0:
        return 0
    # Solve sum_{i>=1} lam_i (F(v_i) - F(v_0)) = -F(v_0), a k x k system.
    r0 = o + value_off[table[s, 0]]
    for j in range(k):
        f0 = vals[r0, j]
        rhs[j] = -f0
        for i in range(1, m):
            mat[j, i - 1] = vals[o + value_off[table[s, i]], j] - f0
    # Scaled partial pivoting: each pivot is weighed against the largest entry of its
    # own row (component F_j) as it came, so multiplying F_j by any positive factor
    # changes neither the pivots nor the singularity test.  lam holds the rows'
    # inverse scales until the back substitution writes it.
    for j in range(k):
        scale = 0.0
        for i in range(k):
            a = abs(mat[j, i])
            if a > scale:
                scale = a
        if scale == 0.0:
            return 0
        lam[j] = 1.0 / scale
    for c in range(k):  # Gaussian elimination
        piv = c
        best = abs(mat[c, c]) * lam[c]
        for rr in range(c + 1, k):
            a = abs(mat[rr, c]) * lam[rr]
            if a > best:
                best = a
                piv = rr
        if not (best > 1e-14):  # (also NaN, from a subnormal row): flat, `_zero_side` decides
            lam[0] = np.nan
            return 2
        if piv != c:
            for i in range(k):
                t = mat[c, i]
                mat[c, i] = mat[piv, i]
                mat[piv, i] = t
            t = rhs[c]
            rhs[c] = rhs[piv]
            rhs[piv] = t
            t = lam[c]
            lam[c] = lam[piv]
            lam[piv] = t
        for rr in range(c + 1, k):
            fac = mat[rr, c] / mat[c, c]
            if fac != 0.0:
                for i in range(c, k):
                    mat[rr, i] -= fac * mat[c, i]
                rhs[rr] -= fac * rhs[c]
    total = 0.0
    for c in range(k - 1, -1, -1):
        acc = rhs[c]
        for i in range(c + 1, k):
            acc -= mat[c, i] * lam[i + 1]
        lam[c + 1] = acc / mat[c, c]
        total += lam[c + 1]
    lam[0] = 1.0 - total
    near = False
    for i in range(m):
        if not (lam[i] >= NEAR_FACET):
            if not (lam[i] > -NEAR_FACET):
                return 0
            near = True  # on a facet up to rounding: `_zero_side` decides
    return 2 if near else 1


# The same solve as a plain call, for the rare callers (a walk's interior nodes, `_joined_pieces`):
# each inlined copy costs the first run's compile more than a call costs these callers.
_simplex_crosses_call = nb.njit(**JIT)(simplex_crosses.py_func)
