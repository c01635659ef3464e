"""What one cube costs the kernel: the table entries it reads, and so how many cubes make a
kernel run of about a quarter second.  (Apart from `budget`, which imports the sweep to
estimate whole runs, so that the runner can ask it without an import cycle.)"""

from __future__ import annotations

from math import comb, factorial

from .kernels.tables import lazy_tables

__all__ = ["CHECK_SIMPLICES", "DEFAULT_CHECK_SHARE", "check_seconds", "checks_cells", "kernel_batch_cubes",
           "kernel_entries",
           "kuhn_simplices"]

# Seconds per table entry the kernel reads for one candidate cube: every k-simplex's corners,
# every (k+1)-face's boundary nodes and, where the walk runs, its (k+1)! simplices; for lazy
# tables, per value the pruned walk computes (R^10, k = 8: about 1 ms per cube).
_KERNEL_SECONDS_PER_ENTRY = 2e-9


def _functionals(k: int) -> int:
    """Rows the lazy kernel keeps for its prune's functionals (`kernels.lazy._face_functionals`: F's
    components and up to 2k differences of W F's rows, _MODEL_NEIGHBOURS = 2)."""
    return 3 * k


def kernel_entries(n: int, k: int) -> int:
    """Table entries `kernels.gcmh.cubes_chunk` reads for one candidate cube (at most): the corners of
    every k-simplex, the boundary nodes of every (k+1)-face and its walk's simplices.  For lazy
    tables (`cubes_chunk_lazy`): the sign prune over every k-face's corners, then the prune's
    functionals (k + 2 operations per corner each) on the k-faces M crosses, 2^(n-k) as for a plane."""
    m = k + 1
    kfaces = comb(n, k) << (n - k)
    if lazy_tables(n, k):
        return kfaces * (1 << k) + (1 << (n - k)) * _functionals(k) * (1 << k) * (k + 2)
    simplices = kfaces * factorial(k)
    k1faces = comb(n, m) << (n - m)
    return simplices * (k + 2) + k1faces * (2 * m * factorial(k) + factorial(m) * (m + 2))


def kernel_batch_cubes(n: int, k: int, seconds: float = 0.25, most: int = 4096) -> int:
    """Candidate cubes a kernel run can take and still end within about `seconds` on one thread
    (between 16 and `most`): a run's cancel is polled between runs, and at k = 10 in R^12 a cube
    takes some 3 ms (4096 of them: 12 s)."""
    per_cube = kernel_entries(n, k) * _KERNEL_SECONDS_PER_ENTRY
    return int(max(16, min(most, seconds // per_cube)))


# Kuhn simplices per cube (dimensions k..n) up to which the cells are checked by default, and the
# check's seconds per candidate cube and simplex (measured: 1e-8 to 2e-8 on R^4 and R^6)
CHECK_SIMPLICES = 2500
_CHECK_SECONDS_PER_SIMPLEX = 2e-8


def kuhn_simplices(n: int, k: int) -> int:
    """Simplices of dimensions k..n in a cube's Kuhn triangulation (`kernels.tables.simplex_tables`' rows):
    the strict chains c0 < ... < cd of its corners, for each d."""
    total = 0
    for d in range(k, n + 1):
        # chains c0 < ... < cd: each axis gets a label 0..d+1 (in c0, switched on at link j, never),
        # links 1..d each used: surjections of n axes onto those d links plus two optional labels
        total += sum((-1) ** j * comb(d, j) * (d + 2 - j) ** n for j in range(d + 1))
    return total


def checks_cells(n: int, k: int, simplicial: bool, check_cells: bool | None) -> bool:
    """Whether a run checks its cells (`runner.Grid.check_cells`), unless ``check_cells`` is False: GCMH
    and GCCH from n = 3 on but surfaces in R^3 (the one-pass marching).  For n <= 7 against CMS's Euler
    characteristic on the whole Kuhn table; curves too: a small closed loop of M inside a cube meets none
    of its k-faces, so GCMH has no vertex on it (noise in R^3 and R^5 lost 1-8 % of its pieces that way;
    the check's pass for pieces hidden in a face finds them).  By default (None) only the cubes the
    interval certificate can't vouch for are compared (`kernels.cell_check.graph_certified_chunk`); True
    compares every candidate cube.  From n = 8 on each compared cube builds its own table of the Kuhn
    simplices M_A may cross (`kernels.kuhn_cube`: 0.01 to 0.5 s a cube), so by default
    only the boundaries of GCMH's cells there are checked (`_balls.cubes_with_bad_boundaries`), which
    curves' cells don't have: curves are checked from n = 8 on only when asked for."""
    if simplicial or n - k < 1 or n < 3 or (n, k) == (3, 1) or check_cells is False:
        return False
    if n <= 7:
        return not lazy_tables(n, k)
    return n - k >= 2 or bool(check_cells)


# The default check's share of the kernel's time: the certificate on every candidate cube, CMS on the few
# it can't vouch for (the examples in R^4..R^7, CPU seconds with and without: 0.97 to 1.34 times)
DEFAULT_CHECK_SHARE = 0.4


def check_seconds(n: int, k: int) -> float:
    """The check's seconds per candidate cube."""
    return kuhn_simplices(n, k) * _CHECK_SECONDS_PER_SIMPLEX
