"""What a run will cost, known before it starts: work, peak memory, and a refusal when it won't fit.

`estimate_run` adds up what an extraction holds at its peak, from (n, k, div, method)
and a probe of F on a coarse grid (a few thousand vertices, milliseconds):

* the cube tables for (n, k) (`kernels.tables`): int64 arrays counted exactly (faces of
  dimension k..n; unless `kernels.tables.lazy_tables` also k! Kuhn simplices per k-face, the walk template of
  (k+1)! simplices and its map onto every (k+1)-face, the Kuhn triangulation for n = 7),
  plus the numpy temporaries of their build;
* the kernel's scratch: per thread, with Kuhn simplices in the tables arrays of one entry per k-simplex and
  walk node of the cube, written for every cube; for lazy tables the pruned walk's functionals
  on the corners of one (k+1)-face;
* the grid lines (n arrays of div + 1), and for the full sweep the slab buffer
  (`sweep.SLAB_VERTICES`, at least two layers), F's temporaries on it and the sign codes;
* the records of the candidate cubes and their assembly.  The probe counts, per
  candidate cube, the faces of each dimension d >= k on which every component of F
  changes sign: a d-face crossed by M holds one (d-k)-cell with its 2(d-k) faces,
  and each costs the bytes measured below.  On a grid finer than the probe a
  candidate cube is cut by M as by a random plane, which crosses
  C(n-k, d-k) 2^(n-d) of its d-faces on average (for k = 1 that sums to 3^(n-1)).
  Sampled data may be rough at the scale of a cube (noise), which a strided probe
  smooths away: the probe also reads blocks of the run's own cubes (`_fine_blocks`),
  and from them judges whether GCMH's n = 3 marching pass, whose records are a fifth
  of the general kernel's, will hand the run over (`_hands_over`).

`check_budget` refuses (`TooLargeError`, an `InputError`) a run whose peak exceeds
the memory this machine can give (MemAvailable, or $GCMH_MEMORY_LIMIT), or whose work
would take more than five minutes ($GCMH_TIME_LIMIT seconds; not for cluster runs),
unless forced.  A grid too large to index is refused even when forced.

The constants were measured with tests/core/test_budget.py's profile (peak RSS of a
child process minus that of importing gcmh_core and compiling): the estimate is
within a factor of two of the measured peaks for n = 2..10 (see its table).
"""

from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass, replace
from math import comb, factorial

import numpy as np

from ._cost import (
    _KERNEL_SECONDS_PER_ENTRY,
    DEFAULT_CHECK_SHARE,
    _functionals,
    check_seconds,
    checks_cells,
    kernel_batch_cubes,
    kernel_entries,
)
from ._memory import available_memory, format_bytes, format_seconds
from .errors import InputError, TooLargeError
from .kernels.tables import lazy_tables

__all__ = [
    "TooLargeError",
    "Estimate",
    "available_memory",
    "estimate",
    "estimate_run",
    "check_budget",
    "kernel_batch_cubes",
    "check_image_size",
    "check_frames",
    "format_bytes",
]

# Vertices of the probe grid (per run: milliseconds of F, a few passes over booleans).
_PROBE_VERTICES = 600_000  # (9^6: div 8 probed exactly in R^6)
# A run that fits many times over is decided on a coarser probe first: the full probe was the most of
# what a small run had gained since 00ff70c (docs/benchmarks-compare.md).  What that probe expects is
# taken _QUICK_MARGIN times before it is trusted (a feature at the coarse probe's scale is
# seen in fewer of its cubes); a run that might not fit that way, or where it sees nothing, is probed
# in full as before.
_QUICK_PROBE_VERTICES = 40_000
_QUICK_MARGIN = 8.0
_PROBE_OVERHEAD = 4_000_000  # bytes beside the probe's arrays (the evaluator's, numpy's)
# Seconds per byte of the cube tables' arrays (numpy writes them; on a fresh VM page the first
# touch dominates: 1 ns/B warm, 5 ns/B measured for R^10, k = 8), and per entry of the label
# enumeration behind the Kuhn triangulation (n <= 7: n (n+2)^n entries).
_TABLE_SECONDS_PER_BYTE = 5e-9
_KUHN_SECONDS_PER_ENTRY = 5e-9
# Peak bytes per record the kernel emits for a crossed face, through the assembly
# (records are grown by doubling, then concatenated and sorted).
_RECORD_OVERHEAD = 3.2
# k >= 2: per candidate cube, more records than the crossed faces say (measured: the
# faces where every component changes sign undercount the cells of k >= 2 in a cube)
_K_FACTOR = {1: 1.0, 2: 1.2}
_K_FACTOR_MORE = 1.6
# GCMH's marching pass for n = 3, k = 1 (`kernels.marching3`) writes the complex in its final form,
# no records to sort: its peak is this fraction of the records' (0.27-0.33 measured at div 100-300 with
# its work arrays new; kept between runs they are less: the estimate was 1.6-2.1x the peak at 0.3)
_MARCHING_RECORDS = 0.2
# CMS/CCS: the cells of the n! simplices of a cube instead of one cell: n!/2 times the records
# (measured: 3 in R^3, 12 in R^4)
# Seconds: per vertex and component of F (evaluation and candidate pass), per byte of records.
_VERTEX_SECONDS = 4e-9
# Glued (periodic) axes: the identified grid's sweep is never pruned by F's bounds (`sweep`) and evaluates F
# about 2.8x slower a vertex than the plain sweep (the closed Klein bottle at its div, 59M vertices: evaluate
# 8.5-12.7 s against 3.7-3.9 s for the same grid cut open and unpruned, runs alternated at a load of 12-16)
_GLUED_VERTEX_FACTOR = 2.8
_RECORD_SECONDS_PER_N = 1.5e-9  # per byte of records and dimension n (the walks grow with n)
WORK_LIMIT_SECONDS = 300.0
# Sampled data: blocks of the run's own cubes the probe reads at full resolution (`_fine_blocks`), and what
# their ambiguous squares say of the marching pass's hand-over (`_hands_over`): cubes whose piece of M is
# not a ball per candidate cube, measured against the share s of ambiguous squares per candidate cube
# (noisy spheres: 3 in 687,162 at s = 0.0122, 512^3 noise 0.001; 2,523 in 396,509 at s = 0.168, 256^3
# noise 0.01; none at s = 0.0014: about 2 s^3), and the expected count from which the run is taken to
# hand over (a false alarm costs a larger estimate, a miss 1 / _MARCHING_RECORDS times the records).
_FINE_BLOCKS = 96
_NONBALL_PER_AMBIGUITY3 = 2.5
_HAND_OVER_EXPECTED = 0.05
# A run goes ahead only when the memory available is this many times its estimated peak.
MEMORY_MARGIN = 2.0
_KEY_LIMIT = 2**63
# A run's fixed working set: thread pools, per-thread copies of the grid, kernel scratch
# (measured 10-30 MB above an idle process for runs with almost no cells)
_RUN_OVERHEAD = 14_000_000
_LEAF_CUBES = 4096  # cubes of a block the pruned sweep evaluates (sweep._LEAF_CUBES)

# Images and animations the headless renderer (VTK, offscreen) can produce.
MAX_IMAGE_SIDE = 8192  # pixels per side: larger render targets come back black
MAX_IMAGE_PIXELS = 8192 * 8192 // 2  # the frame buffer, its RGBA copy and the PNG encoder
MAX_FRAMES = 2000  # frames of one animation, all held until the GIF/MP4 is written


@dataclass(frozen=True)
class Estimate:
    """What a run will cost.  Bytes are peak resident memory above an idle process."""

    n: int
    k: int
    method: str
    div: tuple
    cubes: int
    vertices: int
    candidate_cubes: int  # expected (from the probe)
    table_bytes: int
    grid_bytes: int  # grid lines, slab buffer, F's temporaries, sign codes
    record_bytes: int  # the candidate cubes' records and their assembly
    peak_bytes: int
    seconds: float  # rough: the order of magnitude on one core of a laptop
    available_bytes: int
    seconds_limit: float

    @property
    def fits_memory(self) -> bool:
        # the estimate is within a factor of two of measured peaks (tests/core/test_budget.py),
        # and was seen twice under one (n = 7, k = 1, div 8: 3.9 GB, measured 7.8 GB):
        # a run is let through only with that much room to spare
        return self.peak_bytes * MEMORY_MARGIN <= self.available_bytes

    @property
    def fits(self) -> bool:
        return self.fits_memory and self.seconds <= self.seconds_limit

    def as_dict(self) -> dict:
        d = asdict(self)
        d["div"] = list(self.div)
        d["fits"] = self.fits
        return d

    def describe(self) -> str:
        """One line: the estimate and what this machine gives."""
        return (
            f"n={self.n}, k={self.k}, {self.method}, div {'x'.join(map(str, self.div))}: "
            f"{self.cubes:,} cubes, about {self.candidate_cubes:,} crossed by M; "
            f"peak memory about {format_bytes(self.peak_bytes)} "
            f"(tables {format_bytes(self.table_bytes)}, grid {format_bytes(self.grid_bytes)}, "
            f"cells {format_bytes(self.record_bytes)}) of {format_bytes(self.available_bytes)} available; "
            f"about {format_seconds(self.seconds)}"
        )


def _threads() -> int:
    """Kernel threads a run uses (numba's default: NUMBA_NUM_THREADS, else every core)."""
    try:
        return max(1, int(os.environ.get("NUMBA_NUM_THREADS", "")))
    except ValueError:
        return os.cpu_count() or 1


def _time_limit() -> float:
    text = os.environ.get("GCMH_TIME_LIMIT")
    if not text:
        return WORK_LIMIT_SECONDS
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"GCMH_TIME_LIMIT: expected seconds, got {text!r}") from None
    if not value > 0:
        raise InputError(f"GCMH_TIME_LIMIT must be positive, got {text!r}")
    return value


# ----------------------------------------------------------------------------- the parts
def table_cost(n: int, k: int) -> tuple[int, int, float]:
    """(peak bytes of the build, bytes held after it, seconds) of `kernels.tables.cube_tables(n, k)`.

    The held bytes are its arrays to the byte (tests/core/test_budget.py compares); the
    build's temporaries add the largest of: the walk's Lehmer digits and ranks ((k+1)! rows of
    k+1 int64, about three such), an anchor table of the faces, the Kuhn triangulation's
    label enumeration (n <= 7: two n (n+2)^n byte arrays).  Lazy tables (`kernels.tables.lazy_tables`)
    are the faces only."""
    m = k + 1
    w = 8  # int64
    faces = sum(comb(n, r) << (n - r) for r in range(k, n + 1))
    kfaces = comb(n, k) << (n - k)
    simplices = kfaces * factorial(k)
    k1faces = comb(n, m) << (n - m)
    walk = factorial(m)
    boundary = 2 * m * factorial(k)
    held = w * (3 * faces + (n + 2) + 2 * (n + 1) + (n + 1) ** 2)
    temporary = 3 * w * faces + 16_384  # (+ the face lists' Python objects: all there is for small n, large k)
    if not lazy_tables(n, k):
        held += w * simplices * (k + 3)  # corners, face, permutation
        held += w * (2 * walk * (m + 1) + walk * k // 2 * (k + 1))  # simplex corners and nodes, interior nodes
        held += w * k1faces * ((1 << m) + boundary)  # corner map, boundary simplices
        temporary = max(temporary, 3 * w * walk * m)
    if n <= 6:  # corner masks
        held += w * (simplices + kfaces + k1faces)
    seconds = 1e-3
    if n <= 7:  # the Kuhn triangulation and each k-simplex's row in it
        rows = simplicial_rows(n, k)
        held += w * simplices + w * (rows * (2 * (n + 1) + 3 + (1 if n <= 6 else 0)) + n + 2)
        temporary = max(temporary, 2 * n * (n + 2) ** n)
        seconds += n * (n + 2) ** n * _KUHN_SECONDS_PER_ENTRY
    else:  # (an empty triangulation)
        held += w * (n + 2)
    seconds += held * _TABLE_SECONDS_PER_BYTE
    return int(held + temporary), int(held), float(seconds)


def kernel_scratch(n: int, k: int) -> int:
    """Bytes one kernel thread writes whatever the cube: an entry per k-simplex (which vertex it
    holds) and per walk node (two links, a flag); for lazy tables a cube's corner signs and three
    values of each functional per corner of a (k+1)-face."""
    m = k + 1
    if lazy_tables(n, k):
        return 8 * (1 << n) + 3 * 8 * _functionals(k) * (1 << m)
    simplices = (comb(n, k) << (n - k)) * factorial(k)
    nodes = 2 * m * factorial(k) + factorial(m) * k // 2
    return 8 * simplices + 17 * nodes


def simplicial_rows(n: int, k: int) -> int:
    """Simplices of dimension k..n of the CFK triangulation of the n-cube (`simplex_tables`):
    chains c0 < ... < cd of corners, each axis in c0, added at one of the d steps, or never."""
    rows = 0
    for d in range(k, n + 1):
        rows += sum((-1) ** i * comb(d, i) * (d + 2 - i) ** n for i in range(d + 1))
    return rows


def _count(x: int) -> str:
    """A count for a message: 1,234,567, or about 10^903 when it has more than 18 digits."""
    return f"{x:,}" if x < 10**18 else f"about 10^{int(x.bit_length() * math.log10(2))}"


def index_room(n: int, k: int, vertices: int, simplicial: bool) -> int:
    """The largest key `runner.Grid` would form; at 2^63 the grid cannot be indexed."""
    if vertices >= _KEY_LIMIT:   # (n = 100000: the terms below are integers of 30000 digits, n of them)
        return vertices
    if simplicial:
        return vertices * (n + 1) ** n
    return max(vertices * comb(n, d) * comb(d, k) * 2 ** (d - k) * factorial(k) for d in range(k, n + 1))


def _random_plane_faces(n: int, k: int) -> np.ndarray:
    """(n + 1,) expected crossed faces of each dimension of a cube that a random
    (n-k)-plane crosses (fine grids): C(n-k, d-k) 2^(n-d) for d >= k."""
    return np.array([comb(n - k, d - k) * 2.0 ** (n - d) if d >= k else 0.0 for d in range(n + 1)])


def _bytes_per_cube(n: int, k: int, faces: np.ndarray) -> float:
    """Peak bytes per candidate cube whose crossed faces (per dimension) are `faces`.

    The kernel's records (`gcmh_core.kernels`): a vertex per crossed k-face (its key and n
    coordinates), an edge per crossed (k+1)-face (three keys), an r-cell per crossed
    (k+r)-face (two words) with its 2r faces (three words each); held while the
    kernel grows its buffers by doubling, then concatenated and sorted."""
    faces = np.asarray(faces, np.float64)
    raw = faces[k] * (8 + 8 * n) + (faces[k + 1] * 24 if k + 1 <= n else 0.0)
    for d in range(k + 2, n + 1):
        raw += faces[d] * (16 + 2 * (d - k) * 24)
    return _RECORD_OVERHEAD * raw * _K_FACTOR.get(k, _K_FACTOR_MORE)


def _probe_side(div, budget: int) -> int:
    """The largest side s with prod(min(div_a, s) + 1) <= budget vertices (at least 1): axes of
    few cubes (div 1 across a flat direction) leave the budget to the others."""
    lo, hi = 1, max(1, int(max(div)))
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if math.prod(min(int(d), mid) + 1 for d in div) <= budget:
            lo = mid
        else:
            hi = mid - 1
    return lo


def _probe_grid(n, div, bounds, system, sampled, budget):
    side = _probe_side(div, budget)
    pdiv = np.minimum(div, side)
    exact = bool(np.all(pdiv == div))
    if sampled is not None:
        step = np.maximum(div // pdiv, 1)
        values = sampled[tuple(slice(None, None, int(s)) for s in step)]
        return values, np.array(values.shape[:-1], np.int64) - 1, bool(np.all(step == 1))
    axes = [np.linspace(lo, hi, int(p) + 1) for (lo, hi), p in zip(bounds, pdiv)]
    if not exact:  # interior lines off the "nice" numbers (0, pi) where F often vanishes exactly
        for a in axes:
            a[1:-1:2] += (a[1] - a[0]) * 0.123
    return system.evaluate_grid(axes), pdiv, exact


def _candidates(values: np.ndarray, batch: bool = False) -> np.ndarray:
    """Boolean (d0, ..., d_{n-1}) candidate cubes of F's values (d0+1, ..., k): every
    component has both signs on the cube's corners (OR along each axis in turn).  ``batch``: the
    first axis numbers separate grids (b, d0+1, ..., k), never ORed across."""
    k = values.shape[-1]
    # The signs of all k components packed in one integer per vertex (bit 2j: F_j >= 0, bit
    # 2j + 1: F_j < 0), so each axis takes one OR over the grid, not 2k.  The integer is the
    # narrowest that holds 2k bits, and each comparison is one pass over the contiguous
    # values: every run probes, and with uint64 codes and 2k comparisons of strided columns
    # the probe's test took 11 of a plain cosine run's 75 ms CPU at div 40 (now 3).  NaN
    # sets neither bit.
    code = next(t for t in (np.uint8, np.uint16, np.uint32, np.uint64) if 2 * k <= 8 * np.dtype(t).itemsize)
    with np.errstate(invalid="ignore"):
        bits = ((values >= 0).view(np.uint8), (values < 0).view(np.uint8))
    signs = np.zeros(values.shape[:-1], code)
    for j in range(k):
        for side in range(2):
            signs |= bits[side][..., j].astype(code) << code(2 * j + side)
    for a in range(1 if batch else 0, values.ndim - 1):
        lo = (slice(None),) * a + (slice(None, -1),)
        hi = (slice(None),) * a + (slice(1, None),)
        signs = signs[lo] | signs[hi]
    return signs == code((1 << 2 * k) - 1)


def _crossed_faces(values: np.ndarray, cand: np.ndarray, n: int, k: int) -> np.ndarray:
    """(n + 1,) mean crossed faces of each dimension over (up to 64 of) the candidate cubes."""
    picked = np.flatnonzero(cand.reshape(-1))
    picked = picked[np.linspace(0, len(picked) - 1, min(len(picked), 64)).astype(np.int64)]
    origin = np.stack(np.unravel_index(picked, cand.shape), axis=1)  # (m, n)
    corners = np.array([[c >> (n - 1 - a) & 1 for a in range(n)] for c in range(1 << n)])  # C order
    idx = origin[:, None, :] + corners[None]  # (m, 2^n, n)
    vals = values[tuple(idx[..., a] for a in range(n))]  # (m, 2^n, k)
    with np.errstate(invalid="ignore"):
        cp = (vals >= 0).reshape((len(picked),) + (2,) * n + (k,))
        cn = (vals < 0).reshape((len(picked),) + (2,) * n + (k,))
    for a in range(n):  # along each corner axis a third entry, "free": the OR of the two ends
        cp = np.concatenate([cp, cp.any(axis=1 + a, keepdims=True)], axis=1 + a)
        cn = np.concatenate([cn, cn.any(axis=1 + a, keepdims=True)], axis=1 + a)
    crossed = np.all(cp & cn, axis=-1).reshape(len(picked), -1)  # (m, 3^n); ternary digit 2: free
    free = np.zeros(3**n, np.int64)
    for a in range(n):
        free += (np.arange(3**n) // 3 ** (n - 1 - a)) % 3 == 2
    return np.bincount(free, weights=crossed.sum(axis=0), minlength=n + 1)[: n + 1] / len(picked)


def _probe(n, k, div, bounds, system, sampled, vertices=_PROBE_VERTICES) -> tuple[float, np.ndarray, bool, bool]:
    """F on a coarse grid of about `vertices` vertices: (candidate cubes of the run expected, crossed
    faces of each dimension per candidate cube, whether the probe grid is the run's grid, whether the
    n = 3 marching pass will hand the run over to the general kernel: `_hands_over`)."""
    div = np.asarray(div, np.int64)
    for budget in (vertices, 4 * vertices):  # finer once if it saw nothing
        values, pdiv, exact = _probe_grid(n, div, bounds, system, sampled, budget)
        cand = _candidates(values)
        count = int(cand.sum())
        if count or exact:
            break
    cubes = float(np.prod(div.astype(np.float64)))
    s = (cubes / float(np.prod(pdiv))) ** (1.0 / n)  # run cubes per probe cube, per axis
    plane = _random_plane_faces(n, k)
    if count == 0:  # nothing seen: M (if any) is smaller than a probe cube
        return (0.0 if exact else min(cubes, s ** (n - k))), plane, exact, False
    if exact:
        return float(count), _crossed_faces(values, cand, n, k), True, _hands_over(values, cand, float(count), n, k)
    if sampled is not None:  # data may be rough at the scale of a cube: look at some at full resolution
        fine, fine_cand, covered = _fine_blocks(sampled, cand, div, pdiv)
        per_probe_cube = float(fine_cand.sum()) / fine.shape[0]
        expected = min(cubes, count * per_probe_cube * cubes / covered)
        # (a value that is not finite anywhere stops the marching pass: a NaN region of the probe's)
        nonfinite = (n, k) == (3, 1) and not np.isfinite(values).all()
        if not fine_cand.any():
            return expected, plane, False, bool(nonfinite or not np.isfinite(fine).all())
        if n > 10:
            faces = plane
        else:  # the blocks end to end along axis 0; the cubes across two blocks are no candidates
            joined = np.zeros((fine.shape[0] * fine.shape[1] - 1, *fine_cand.shape[2:]), bool)
            for b, c in enumerate(fine_cand):
                joined[b * fine.shape[1]: b * fine.shape[1] + c.shape[0]] = c
            faces = _crossed_faces(fine.reshape(-1, *fine.shape[2:]), joined, n, k)
        return expected, faces, False, nonfinite or _hands_over(fine, fine_cand, expected, n, k, batch=True)
    # M meets s^e times as many cubes on a grid s times finer, e -> n - k once the
    # probe resolves M; e halfway between that and what the probe shows against its
    # every-other-line subgrid (which still grows towards n - k)
    e = float(n - k)
    if np.all(pdiv >= 4):
        half = int(_candidates(values[tuple(slice(None, None, 2) for _ in range(n))]).sum())
        if half:
            e = 0.5 * (e + min(e, max(1.0, math.log2(count / half))))
    expected = min(cubes, count * s**e)
    faces = plane if n > 10 else _crossed_faces(values, cand, n, k)
    # on a finer grid M is flatter in each cube: towards the plane's count
    return expected, faces + (plane - faces) * (1.0 - 1.0 / s), False, False


def _fine_blocks(sampled, cand: np.ndarray, div: np.ndarray, pdiv: np.ndarray):
    """Sampled values at full resolution on (up to _FINE_BLOCKS of) the probe's candidate cubes, each block
    the run's cubes inside one probe cube: (the blocks (b, s0 + 1, ..., k), their candidate cubes (b, s0, ...),
    the run's cubes the probe's cubes cover).  A strided probe of rough data (noise at the scale of a grid
    cube) sees a smooth surface: at 256^3 with noise 0.01 it expected 196,000 candidate cubes of 397,000."""
    step = np.maximum(div // pdiv, 1)
    picked = np.flatnonzero(cand.reshape(-1))
    picked = picked[np.linspace(0, len(picked) - 1, min(len(picked), _FINE_BLOCKS)).astype(np.int64)]
    origins = np.stack(np.unravel_index(picked, cand.shape), axis=1) * step
    fine = np.stack([np.asarray(sampled[tuple(slice(int(o), int(o + s) + 1) for o, s in zip(origin, step))],
                                np.float64) for origin in origins])
    return fine, _candidates(fine, batch=True), float(np.prod(pdiv.astype(np.float64) * step))


def _hands_over(values: np.ndarray, cand: np.ndarray, expected: float, n: int, k: int, batch: bool = False) -> bool:
    """Whether GCMH's n = 3 marching pass (`sweep._march`) will give the run to the general kernel, whose
    records take about 1 / _MARCHING_RECORDS times the memory: at a value that is not finite, or at the
    first cube whose piece of M is not a ball (`kernels.marching3`, a case of its 8 corner signs).  On
    the run's own grid (the exact probe) the cases say it; on samples of it (`batch`: blocks of
    the run's cubes) one such cube in a million is enough, too rare to be seen, so it is expected from
    the share of squares whose signs alternate (the ambiguous squares of marching cubes), which
    noise makes common: _NONBALL_PER_AMBIGUITY3 times its cube per candidate cube."""
    if (n, k) != (3, 1):
        return False
    if not np.isfinite(values).all():
        return True
    from .kernels.marching3 import cube_cases

    lead = (slice(None),) if batch else ()
    pos = values[..., 0] >= 0

    def shifted(offsets):  # pos at each cube's (or square's) corner `offsets` (0, 1 or None: every layer)
        return pos[lead + tuple(slice(None) if o is None else slice(o, pos.shape[len(lead) + a] - 1 + o)
                                for a, o in enumerate(offsets))]

    case = np.zeros(shifted((0, 0, 0)).shape, np.uint8)
    for c in range(8):  # corner c: bit a set = +1 along axis a (as `cube_cases`)
        case |= shifted(tuple(c >> a & 1 for a in range(3))).astype(np.uint8) << np.uint8(c)
    nonball = int(np.count_nonzero(cube_cases().cube_nonball[case]))
    if not batch:
        return nonball > 0
    ambiguous = 0
    for a in range(3):  # the squares normal to axis a whose diagonal corners agree and neighbours differ
        corners = {}
        for i in range(2):
            for j in range(2):
                it = iter((i, j))
                corners[i, j] = shifted(tuple(None if b == a else next(it) for b in range(3)))
        ambiguous += int(np.count_nonzero((corners[0, 0] == corners[1, 1]) & (corners[0, 1] == corners[1, 0])
                                          & (corners[0, 0] != corners[0, 1])))
    share = ambiguous / max(1, int(cand.sum()))
    return max(nonball / max(1, int(cand.sum())), _NONBALL_PER_AMBIGUITY3 * share**3) * expected >= _HAND_OVER_EXPECTED


# ----------------------------------------------------------------------------- the estimate
def estimate_run(
    n: int,
    k: int,
    div,
    *,
    method: str = "gcmh",
    bounds=None,
    system=None,
    sampled=None,
    scheduler=None,
    probe: bool | None = None,
    check_cells: bool | None = None,
    glued: bool = False,
) -> Estimate:
    """The cost of extracting with these (validated) arguments; see the module's docstring.

    system: a `formula.System` (probed on a coarse grid over `bounds`), or sampled:
    F's values on the grid; with neither, M is taken to cross the grid like a plane
    through its middle.  scheduler: a cluster run holds no slab here, only the records.
    probe: None probes F only when the run might not fit even if M crossed every cube
    (small runs don't pay for the probe); True always (`gcmh extract --dry-run`).
    glued: some axes are identified (periodic): the sweep is not pruned and evaluates F at every vertex.
    Raises InputError (never forceable) for a grid too large to index.
    """
    from ._methods import CONTINUATION_METHODS, SIMPLICIAL_METHODS

    div_t = tuple(int(d) for d in np.broadcast_to(np.asarray(div, np.int64), (n,)))
    vertices = math.prod(d + 1 for d in div_t)
    simplicial = method in SIMPLICIAL_METHODS
    # what the cell check costs: "all" candidate cubes compared with CMS, or the certificate first
    checked = checks_cells(n, k, simplicial, check_cells) and ("all" if check_cells else "certified")
    if index_room(n, k, vertices, simplicial) >= _KEY_LIMIT:
        raise InputError(f"the grid is too large to index ({_count(vertices)} vertices in R^{n}): use a smaller div"
                         + (" or fewer variables" if n > 62 else ""))
    if simplicial and n > 7:
        raise InputError(f"the simplicial baselines split an n-cube into n! simplices: n = {n} is too many (at most 7)")
    continuation = method in CONTINUATION_METHODS
    plane = _random_plane_faces(n, k)
    cubes = math.prod(div_t)
    pruned = not glued and not continuation and scheduler is None and _prunable(system, sampled, cubes)
    if probe is None:  # every cube crossed, like a plane: an upper bound
        worst = _cost(n, k, div_t, method, simplicial, continuation, scheduler, sampled, float(cubes), plane, False,
                      checked, glued, hands_over=sampled is not None)
        if _fits_easily(worst):
            return worst
    probe_bytes = 0
    hands_over = False
    if system is not None or sampled is not None:
        quick = _probe(n, k, div_t, bounds, system, sampled, _QUICK_PROBE_VERTICES) if probe is None else None
        # (an exact probe was the run's grid: a finer one sees the same)
        if quick is not None and (quick[2] or (quick[0] and _fits_easily(_cost(
                n, k, div_t, method, simplicial, continuation, scheduler, sampled,
                min(float(cubes), _QUICK_MARGIN * quick[0]), quick[1], pruned, checked, glued, quick[3])))):
            budget, (expected, faces, _, hands_over) = _QUICK_PROBE_VERTICES, quick
        else:
            budget = _PROBE_VERTICES
            expected, faces, _, hands_over = _probe(n, k, div_t, bounds, system, sampled, budget)
        if sampled is None:
            probe_bytes = _probe_bytes(k, _probe_vertices(div_t, budget))
    else:
        expected, faces = min(float(cubes), float(cubes) ** ((n - k) / n)), plane
    est = _cost(n, k, div_t, method, simplicial, continuation, scheduler, sampled, expected, faces, pruned, checked,
                glued, hands_over)
    if probe_bytes + _PROBE_OVERHEAD > est.peak_bytes:   # (the probe's peak, before the run's)
        est = replace(est, peak_bytes=int(probe_bytes + _PROBE_OVERHEAD))
    return est


def _fits_easily(estimate: Estimate) -> bool:
    """Whether a run fits many times over (an eighth of the memory, a tenth of the time): its probe can
    be skipped (the every-cube bound) or coarse (`_QUICK_PROBE_VERTICES`)."""
    return estimate.peak_bytes <= estimate.available_bytes // 8 and estimate.seconds <= estimate.seconds_limit / 10


def _probe_vertices(div, budget: int = _PROBE_VERTICES) -> int:
    """Vertices of the probe's (first) grid."""
    side = _probe_side(np.asarray(div, np.int64), budget)
    return math.prod(min(int(d), side) + 1 for d in div)


def _probe_bytes(k: int, vertices: int) -> int:
    """The probe's own peak: F's k values at each probe vertex and the evaluation's temporaries, then the packed
    signs (measured: 41 bytes a vertex for k = 3, 48 for k = 4, 61 for k = 5 at about 530,000 vertices). A small
    run of large k was all probe: n = 5, k = 4, div 40 peaked at 28.7 MB against an estimate of 16.1 MB (the
    issue's 2.03x), n = 6, k = 5, div 10 at 32.5 MB against 18.9."""
    return int(vertices * (10 * k + 12))


def _pruned_vertices(n: int, k: int, expected: float, vertices: int):
    """(leaf blocks, their vertices) of the pruned sweep, or None where it would give up
    (the blocks would hold over half the grid's vertices) for the plain sweep."""
    side = _LEAF_CUBES ** (1.0 / n)
    leaves = max(1.0, expected / min(_LEAF_CUBES, side ** (n - k))) if expected else 0.0
    block_vertices = leaves * (side + 1) ** n
    if block_vertices > 0.5 * vertices:
        return None
    return leaves, block_vertices


def _marching() -> bool:
    """Whether a full sweep with n = 3, k = 1 takes the marching pass (`sweep.MARCHING3`)."""
    from . import sweep

    marching = getattr(sweep, "MARCHING3", False)
    return bool(sweep.PRUNE is not True if marching is None else marching)


def _prunable(system, sampled, cubes: int) -> bool:
    """Whether the full sweep will drop blocks by F's interval bounds (`sweep`)."""
    from . import sweep

    prune = sweep.PRUNE
    if prune is None:
        prune = cubes >= getattr(sweep, "_PRUNE_MIN_CUBES", 1 << 16)
    return bool(prune) and system is not None and sampled is None and sweep.enclosure_of(system) is not None


def _cost(n, k, div_t, method, simplicial, continuation, scheduler, sampled, expected, faces, pruned,
          checked=False, glued=False, hands_over=False) -> Estimate:
    from .sweep import SLAB_VERTICES

    dims = [d + 1 for d in div_t]
    vertices = math.prod(dims)
    # (the simplicial methods' tables are the cube tables' Kuhn triangulation, n <= 7)
    table_peak, tables_held, table_seconds = table_cost(n, k)
    records = expected * _bytes_per_cube(n, k, faces) * (factorial(n) / 2 if simplicial else 1.0)
    if (n, k) == (3, 1) and not simplicial and not continuation and scheduler is None and _marching() \
            and not hands_over:  # (else the general kernel's records, after the pass gave up: `_hands_over`)
        records *= _MARCHING_RECORDS
    grid = sum(dims) * 8 * 4  # lines, their offsets, the stacked copy in Grid
    layer = math.prod(dims[1:])
    if continuation:  # F at the corners of each wave, and the visited cubes
        front = expected ** ((n - k - 1) / max(n - k, 1)) if expected else 0.0
        grid += int(front * (1 << n) * (8 * k + 40) + expected * 40)
        work_vertices = expected * (1 << n)
    elif pruned and _pruned_vertices(n, k, expected, vertices) is not None:
        # the blocks F's bounds leave (of <= 4096 cubes: 16^3, 8^4), evaluated one per thread
        leaves, work_vertices = _pruned_vertices(n, k, expected, vertices)
        side = _LEAF_CUBES ** (1.0 / n) + 1
        grid += int(leaves * n * 8 * 8 + 2 * side**n * k * 8 * 3)
    elif scheduler is None:
        thickness = max(1, min(div_t[0], SLAB_VERTICES // max(layer * k, 1)))
        slab = (thickness + 1) * layer
        code_bytes = 1 if 2 * k + 1 <= 8 else 2 if 2 * k + 1 <= 16 else 4
        buffer = 0 if sampled is not None else slab * k * 8
        grid += buffer + slab * (8 + code_bytes)  # + one full-slab temporary of F
        work_vertices = float(vertices) * (_GLUED_VERTEX_FACTOR if glued else 1.0)
    else:  # the workers evaluate; this process gathers the records
        work_vertices = 0.0
    if not simplicial and expected:  # each kernel thread's scratch, written for every cube
        grid += int(min(_threads(), max(expected, 1.0)) * kernel_scratch(n, k))
    peak = max(table_peak, tables_held + grid + records) + _RUN_OVERHEAD
    kernel_seconds = 0.0 if simplicial else expected * kernel_entries(n, k) * _KERNEL_SECONDS_PER_ENTRY
    seconds = (
        table_seconds
        + work_vertices * k * _VERTEX_SECONDS
        + records * _RECORD_SECONDS_PER_N * n
        + kernel_seconds
        # the cells' Euler check (`_cost.checks_cells`): CMS's count of each candidate cube's simplices when
        # asked for every cube; by default the certificate, and CMS where it can't vouch
        + (0.0 if not checked else expected * check_seconds(n, k) if checked == "all"
           else kernel_seconds * DEFAULT_CHECK_SHARE)
    )
    return Estimate(
        n=n,
        k=k,
        method=method,
        div=div_t,
        cubes=math.prod(div_t),
        vertices=vertices,
        candidate_cubes=int(round(expected)),
        table_bytes=int(table_peak),
        grid_bytes=int(grid),
        record_bytes=int(records),
        peak_bytes=int(peak),
        seconds=float(seconds),
        available_bytes=available_memory(),
        # a cluster's time is its workers'; here only the memory of the gathered records counts
        seconds_limit=_time_limit() if scheduler is None else math.inf,
    )


def estimate(
    F,
    bounds=None,
    div=None,
    *,
    variables=None,
    n: int | None = None,
    k: int | None = None,
    method: str = "gcmh",
    scheduler=None,
    periodic=None,
) -> Estimate:
    """The cost of `extract(F, bounds, div, ...)` with the same arguments, without running it
    (`gcmh extract --dry-run`; the app shows it before a run).  Bad arguments raise the
    InputError `extract` would."""
    from ._methods import METHODS
    from ._validate import as_periodic, prepare

    if method not in METHODS:
        raise InputError(f"unknown method {method!r}; choose from {', '.join(METHODS)}")
    if isinstance(div, (list, tuple)) and len(div) == 1:
        div = div[0]
    n_, k_, bounds_, div_, system, sampled = prepare(F, variables, n, k, bounds, div, slices=True)
    if system is not None:
        names = list(system.variables)
    elif variables is not None and not isinstance(variables, str):
        names = list(variables)
    else:
        names = [f"x{i + 1}" for i in range(n_)]
    glued = any(flips is not None for _, flips in as_periodic(periodic, names, div_)) if periodic else False
    return estimate_run(n_, k_, div_, method=method, bounds=bounds_, system=system, sampled=sampled,
                        scheduler=scheduler, probe=True, glued=glued)


def check_budget(estimate: Estimate, force: bool = False) -> None:
    """Raise TooLargeError when the run won't fit (unless force); the message names
    the estimate and what to change."""
    if force or estimate.fits:
        return
    e = estimate
    if not e.fits_memory:
        what = (
            f"this run needs about {format_bytes(e.peak_bytes)} of memory; with room for the estimate's "
            f"error ({MEMORY_MARGIN:g}x) that is more than the {format_bytes(e.available_bytes)} available"
        )
    else:
        what = f"this run would take about {format_seconds(e.seconds)} (limit {format_seconds(e.seconds_limit)})"
    hints = []
    if e.table_bytes >= 0.3 * e.peak_bytes or max(e.div) == 1:
        listed = 5 <= e.k and not lazy_tables(e.n, e.k)
        simplices = f" and {factorial(e.k):,} Kuhn simplices in each {e.k}-face" if listed else ""
        hints.append(
            f"in R^{e.n} a single cube has {3 ** e.n:,} faces{simplices} (the cube tables alone take "
            f"{format_bytes(e.table_bytes)}): use fewer variables"
        )
    else:
        hints.append("use a smaller div")
        if e.method in ("gcmh", "cms"):
            hints.append('method="gcch" (continuation visits only the cubes M crosses)')
        hints.append("a cluster (scheduler=...)")
    hints.append("or force=True (--force) to run anyway")
    raise TooLargeError(
        f"{what} (n={e.n}, k={e.k}, div {'x'.join(map(str, e.div))}, {e.method}: "
        f"about {e.candidate_cubes:,} of {e.cubes:,} cubes crossed by M); " + ", ".join(hints)
    )


# ----------------------------------------------------------------------------- images
def check_image_size(width: int, height: int) -> None:
    """Raise InputError unless the headless renderer can draw a width x height image."""
    for what, v in (("width", width), ("height", height)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise InputError(f"image {what} must be an integer, got {v!r}")
        if v < 1:
            raise InputError(f"image {what} must be at least 1 pixel, got {v}")
        if v > MAX_IMAGE_SIDE:
            raise InputError(f"image {what} {v} is above the renderer's limit of {MAX_IMAGE_SIDE} pixels")
    if int(width) * int(height) > MAX_IMAGE_PIXELS:
        raise InputError(
            f"image {width}x{height} has {int(width) * int(height):,} pixels, above the renderer's limit of "
            f"{MAX_IMAGE_PIXELS:,} (e.g. {MAX_IMAGE_SIDE}x{MAX_IMAGE_PIXELS // MAX_IMAGE_SIDE})"
        )


def check_frames(frames: int, width: int, height: int) -> None:
    """Raise InputError unless an animation of `frames` frames of width x height fits:
    at most MAX_FRAMES frames, and all of them (RGB, held until written) in the memory
    available (with room for the encoder)."""
    check_image_size(width, height)
    if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)):
        raise InputError(f"frames must be an integer, got {frames!r}")
    if frames < 1:
        raise InputError(f"an animation needs at least 1 frame, got {frames}")
    if frames > MAX_FRAMES:
        raise InputError(f"{frames} frames is above the limit of {MAX_FRAMES}")
    need = 2 * int(frames) * int(width) * int(height) * 3
    avail = available_memory()
    if need > avail:
        raise TooLargeError(
            f"{frames} frames of {width}x{height} need about {format_bytes(need)} of memory but "
            f"{format_bytes(avail)} is available: use fewer frames or a smaller size"
        )
