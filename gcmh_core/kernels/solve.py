"""The barycentric solve on a Kuhn (CFK) simplex (paper 3.1.1), and the sign prune before it.

The sign prune: a zero of F in the hull of a set of corners needs every component F_j to
take a value >= 0 and one < 0 among them (a value 0 counts as +epsilon).  It is written
once for each way the kernels hold a set of corners: a bit mask (n <= 6, `crossable_mask`),
a chain of corners in a table row (`crossable_chain`), a cube face (`crossable_face`).
They are inlined (numba, at IR level): as plain calls they doubled the kernel's time.
"""

import numba as nb

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


@nb.njit(**JIT)
def _zero_side(vals, o, value_off, table, s, k, lam):
    """`simplex_crosses`'s answer 2 decided: 1 if the zero is inside the simplex, else 0.

    A value 0 counts as +epsilon (the sign prune's rule, a symbolic perturbation).  Where
    some F_j is 0 on the whole facet opposite corner i and < 0 at i, the solve finds
    lam_i = 0 up to rounding, and the perturbed zero lies inside: lam_i = 0+.  Any other
    slightly negative lam_i is outside.  (Called from the kernels' own loops, rarely: as a
    branch inside the inlined solve it slowed every cube by a fifth.)
    """
    for i in range(k + 1):
        if lam[i] >= 0.0:
            continue
        inside = False
        for j in range(k):
            if vals[o + value_off[table[s, i]], j] < 0.0:
                on_facet = True
                for q in range(k + 1):
                    if q != i and vals[o + value_off[table[s, q]], j] != 0.0:
                        on_facet = False
                if on_facet:
                    inside = True
        if not inside:
            return 0
        lam[i] = 0.0
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
        if not (best > 1e-14):  # (also NaN, from a subnormal row)
            return 0
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
        if not (lam[i] >= 0.0):
            if not (lam[i] > -1e-9):
                return 0
            near = True  # on a facet up to rounding: `_zero_side` decides
    return 2 if near else 1


# The same solve as a plain call, for the rare callers (a walk's interior nodes, `_joined_pieces`):
# each inlined copy costs the first run's compile more than a call costs these callers.
_simplex_crosses_call = nb.njit(**JIT)(simplex_crosses.py_func)
