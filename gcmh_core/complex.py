"""The cell complex produced by GCMH, and its ``.npz`` file format.

A :class:`CellComplex` of dimension ``dim = n - k`` lives in R^n:

* ``vertices`` -- (V, n) float64, the 0-cells;
* ``edges`` -- (E, 2) int64, the 1-cells, as vertex ids;
* ``cells[r]`` for r = 2..dim -- ``(offsets, faces)`` in CSR form: the faces of
  r-cell ``i`` are the (r-1)-cell ids ``faces[offsets[i]:offsets[i+1]]``
  (offsets (N_r + 1,) int64, faces (M_r,) int64);
* ``meta`` -- a free-form dict (bounds, div, method, seed, formulas, variables,
  seconds, ...).

Everything here is plain numpy: no per-cell Python loops, so complexes with
millions of cells are handled in about a second.  pyvista is imported only
inside :meth:`CellComplex.to_pyvista` (and :meth:`CellComplex.save_vtu`).

File format ``gcmh-complex/1`` (an ``.npz`` archive, written without pickles):

=====================================  =============================================
key                                    content
=====================================  =============================================
``format``                             the string ``gcmh-complex/1``
``n``, ``k``                           ints
``vertices``                           (V, n) float64
``cells_1``                            (E, 2) int64, vertex ids of each edge
``cells_{r}_offsets``, ``_faces``      for r = 2..n-k, CSR as above
``meta_json``                          JSON text of ``meta`` (numpy values converted),
                                       without ``seconds`` and ``timings``
``run_json`` (optional)                JSON of ``seconds`` and ``timings``, only with
                                       ``save(..., timings=True)``
=====================================  =============================================

The same complex gives the same bytes: members are written in a fixed order with a
fixed date (1980-01-01), and what depends on the machine and the moment (the run's
``seconds`` and ``timings``) is left out unless asked for (``gcmh extract --json``
prints it instead).  :meth:`CellComplex.load` checks every member's header (shape,
dtype, size, compression ratio, memory) before reading any array.

Example
-------
>>> import numpy as np
>>> square = CellComplex(2, 0, [[0, 0], [1, 0], [1, 1], [0, 1]],
...                      [[0, 1], [1, 2], [2, 3], [3, 0]],
...                      {2: ([0, 4], [0, 1, 2, 3])})
>>> square.counts(), square.euler_characteristic()
([4, 4, 1], 1)
>>> square.boundary_facets()
array([0, 1, 2, 3])
"""

from __future__ import annotations

import json
import math
import operator
import os
import zipfile
from collections.abc import Mapping

import numpy as np

from .safe_io import atomic_write

__all__ = ["CellComplex", "FORMAT"]

FORMAT = "gcmh-complex/1"

_INT64_MAX = np.iinfo(np.int64).max


# ----------------------------------------------------------------------------
# validation helpers
# ----------------------------------------------------------------------------

def _as_int(value, name):
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be an int, got {value!r}")
    try:
        return operator.index(value)
    except TypeError:
        raise ValueError(f"{name} must be an int, got {value!r}") from None


def _int_array(value, name, ndim):
    """Convert to a C-contiguous int64 array of `ndim` dimensions (empty input of
    any numeric dtype is accepted)."""
    try:
        arr = np.asarray(value)
    except Exception as exc:  # noqa: BLE001 - ragged lists and whatever an __array__ raises
        raise ValueError(f"{name} must be an integer array: {exc}") from None
    if arr.size == 0:
        if arr.dtype.kind not in "iufb" and arr.dtype != object:
            raise ValueError(f"{name} must be an integer array, got dtype {arr.dtype}")
        shape = (0,) if ndim == 1 else (0, 2)
        if ndim == 2 and arr.ndim == 2:
            shape = arr.shape
        return np.zeros(shape, dtype=np.int64)
    if arr.dtype.kind not in "iu":
        raise ValueError(f"{name} must be an integer array, got dtype {arr.dtype}")
    if arr.ndim != ndim:
        raise ValueError(f"{name} must be {ndim}-dimensional, got shape {arr.shape}")
    if arr.dtype.kind == "u" and arr.size and arr.max() > _INT64_MAX:
        raise ValueError(f"{name} has ids too large for int64")
    return np.ascontiguousarray(arr, dtype=np.int64)


def _component_roots(n_nodes, a, b):
    """(n_nodes,) int64: the smallest node id of each node's component."""
    label = np.arange(n_nodes, dtype=np.int64)
    while a.size:
        la, lb = label[a], label[b]
        differ = la != lb
        if not differ.any():
            break
        la, lb = la[differ], lb[differ]
        a, b = a[differ], b[differ]  # joined ends stay joined: drop those edges
        lo = np.minimum(la, lb)
        hi = np.maximum(la, lb)
        # labels are roots here, so this hooks a root under a smaller one: no cycles
        np.minimum.at(label, hi, lo)
        while True:  # pointer jumping until every node points at its root
            nxt = label[label]
            if np.array_equal(nxt, label):
                break
            label = nxt
    return label


def _frozen(arr):
    """A read-only view (the caller's array itself stays writable)."""
    view = arr.view()
    view.flags.writeable = False
    return view


def _segment_unique(owner, values, n_owner, n_values):
    """Sorted unique `values` within each `owner` segment, as CSR.

    owner, values: (m,) int64, 0 <= owner < n_owner, 0 <= values < n_values.
    Returns offsets (n_owner + 1,) int64 and ids int64.
    """
    owner = np.asarray(owner, dtype=np.int64)
    values = np.asarray(values, dtype=np.int64)
    offsets = np.zeros(n_owner + 1, dtype=np.int64)
    if owner.size == 0:
        return offsets, np.zeros(0, dtype=np.int64)
    base = max(int(n_values), 1)
    if n_owner * base < _INT64_MAX // 2:
        # (np.unique is hash-based in numpy >= 2.3 and much slower than a sort)
        key = np.sort(owner * base + values)
        keep = np.ones(key.size, dtype=bool)
        np.not_equal(key[1:], key[:-1], out=keep[1:])
        key = key[keep]
        uowner = key // base
        uvalues = key - uowner * base
    else:  # huge ids: sort the two columns directly
        order = np.lexsort((values, owner))
        o, v = owner[order], values[order]
        keep = np.ones(o.size, dtype=bool)
        keep[1:] = (o[1:] != o[:-1]) | (v[1:] != v[:-1])
        uowner, uvalues = o[keep], v[keep]
    np.cumsum(np.bincount(uowner, minlength=n_owner), out=offsets[1:])
    return offsets, uvalues


def _gather_segments(offsets, data, items):
    """Concatenate the CSR segments ``data[offsets[i]:offsets[i+1]]`` for i in items.

    Returns (rep, values): rep[j] is the position in `items` whose segment
    values[j] came from.
    """
    starts = offsets[items]
    counts = offsets[items + 1] - starts
    total = int(counts.sum())
    rep = np.repeat(np.arange(items.size, dtype=np.int64), counts)
    first = np.cumsum(counts) - counts  # exclusive prefix sum
    idx = starts[rep] + (np.arange(total, dtype=np.int64) - first[rep])
    return rep, data[idx]


def _jsonable(obj):
    """Recursively convert `obj` (numpy values included) to JSON-native types."""
    if obj is None or isinstance(obj, (str, bool)):
        return obj
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return _jsonable(obj.item())
    if isinstance(obj, (int, float)):
        return obj
    if isinstance(obj, Mapping):
        return {str(key): _jsonable(value) for key, value in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(value) for value in obj]
    if isinstance(obj, (set, frozenset)):
        return [_jsonable(value) for value in sorted(obj, key=repr)]
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    if isinstance(obj, complex):
        return [obj.real, obj.imag]
    return str(obj)


# ----------------------------------------------------------------------------
# the .npz file: written byte for byte the same, read with bounds
# ----------------------------------------------------------------------------

# meta keys that depend on the machine and the moment, or say how a run went rather than what it
# made (a Dask run's scheduler, workers, tasks, blocks: distributed.RUN_META; the cubes a one-process
# sweep skipped by F's bounds, which the blocks do not): left out of meta_json (see save), so
# --scheduler local writes the single-process file byte for byte
VOLATILE_META = ("seconds", "timings", "scheduler", "workers", "tasks", "blocks", "block", "pruned_cubes")
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)  # members carry this date, not the time of writing
_MAX_RATIO = 100  # uncompressed / compressed of a big member: real numbers and ids compress less
_SMALL_MEMBER = 1 << 20  # bytes: a member this small is never called a bomb
_MAX_TEXT = 64 << 20  # characters of meta_json / run_json
_MAX_MEMBERS = 1000


def _write_npz(file, arrays: dict, compressed: bool) -> None:
    """An .npz numpy reads, with fixed dates and order: the same arrays, the same bytes."""
    method = zipfile.ZIP_DEFLATED if compressed else zipfile.ZIP_STORED
    with zipfile.ZipFile(file, "w", compression=method, allowZip64=True) as zf:
        for name, arr in arrays.items():
            info = zipfile.ZipInfo(name + ".npy", date_time=_ZIP_DATE)
            info.compress_type = method
            info.external_attr = 0o644 << 16
            with zf.open(info, "w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asanyarray(arr), allow_pickle=False)


def _member_header(archive, info):
    """(shape, dtype, header bytes) of an .npy member, from its first bytes only."""
    with archive.open(info) as f:
        version = np.lib.format.read_magic(f)
        if version == (1, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
        elif version == (2, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
        else:
            raise ValueError(f"unsupported .npy version {version}")
        return shape, dtype, f.tell()


def _read_checked(archive, bad) -> dict:
    """The arrays of a gcmh-complex archive, each checked from its header before reading."""
    infos = archive.infolist()
    if len(infos) > _MAX_MEMBERS:
        raise bad(f"{len(infos)} members")
    members = {}
    for info in infos:
        if not info.filename.endswith(".npy") or info.is_dir():
            raise bad(f"unexpected member {info.filename!r}")
        members[info.filename[:-4]] = info
    if "format" not in members:
        raise bad("no 'format' key")
    for name in ("n", "k", "vertices", "cells_1"):
        if name not in members:
            raise bad(f"missing key {name!r}")
    headers = {}
    total = 0
    for name, info in members.items():
        try:
            shape, dtype, header = _member_header(archive, info)
        except ValueError as exc:
            raise bad(f"member {name!r}: {exc}") from None
        if dtype.hasobject:
            raise bad(f"member {name!r} holds Python objects (pickles are never loaded)")
        nbytes = math.prod(shape) * dtype.itemsize
        if info.file_size != header + nbytes:
            raise bad(
                f"member {name!r}: its header claims {shape} {dtype} ({nbytes:,} bytes) "
                f"but the archive holds {info.file_size - header:,} bytes"
            )
        if nbytes > _SMALL_MEMBER and nbytes > _MAX_RATIO * max(info.compress_size, 1):
            raise bad(
                f"member {name!r} claims {nbytes:,} bytes from {info.compress_size:,} compressed "
                f"(more than {_MAX_RATIO} to 1: not an array written by save)"
            )
        headers[name] = (shape, dtype)
        total += nbytes

    def scalar(name, kinds):
        shape, dtype = headers[name]
        if shape != () or dtype.kind not in kinds:
            return False
        return True

    if not scalar("format", "US") or headers["format"][1].itemsize > 256:
        raise bad(f"format has dtype {headers['format'][1]} and shape {headers['format'][0]}, expected a string")
    if not (scalar("n", "iu") and scalar("k", "iu")):
        raise bad("'n' and 'k' must be integer scalars")
    small = {}
    for name in ("format", "n", "k"):
        with archive.open(members[name]) as f:
            small[name] = np.lib.format.read_array(f, allow_pickle=False)
    if str(small["format"][()]) != FORMAT:
        raise bad(f"format is {small['format']!r}, expected {FORMAT!r}")
    n, k = int(small["n"]), int(small["k"])
    if not (1 <= n <= 64 and 0 <= k <= n):
        raise bad(f"n = {n}, k = {k} (need 1 <= n <= 64, 0 <= k <= n)")
    expect: dict[str, tuple[int, str, int | None]] = {"vertices": (2, "f", n), "cells_1": (2, "iu", 2)}
    for r in range(2, max(n - k, 1) + 1):
        ko, kf = f"cells_{r}_offsets", f"cells_{r}_faces"
        if ko not in members or kf not in members:
            raise bad(f"missing key {ko!r} or {kf!r}")
        expect[ko] = expect[kf] = (1, "iu", None)
    for name in members:
        if name.startswith("cells_") and name not in expect:
            raise bad(f"unexpected key {name!r} for n - k = {n - k}")
    for name, (ndim, kinds, width) in expect.items():
        shape, dtype = headers[name]
        if dtype.kind not in kinds or (name == "vertices" and dtype != np.float64):
            want = "float64" if name == "vertices" else "int64"
            raise bad(f"{name!r} must be {want}, got {dtype}")
        if len(shape) != ndim or (width is not None and shape[1] != width):
            want = f"(V, {n})" if name == "vertices" else "(E, 2)" if name == "cells_1" else "1-dimensional"
            raise bad(f"{name!r} must have shape {want}, got {shape}")
    for name in ("meta_json", "run_json"):
        if name in headers:
            shape, dtype = headers[name]
            if shape != () or dtype.kind not in "US" or dtype.itemsize > 4 * _MAX_TEXT:
                raise bad(f"{name!r} must be a string (of at most {_MAX_TEXT:,} characters)")
    for name in members:
        if name not in expect and name not in small and name not in ("meta_json", "run_json"):
            shape, dtype = headers[name]
            if math.prod(shape) * dtype.itemsize > _SMALL_MEMBER:
                raise bad(f"extra member {name!r} is larger than {_SMALL_MEMBER:,} bytes")
    from ._memory import available_memory, format_bytes

    avail = available_memory()
    if total > avail:
        raise bad(f"its arrays take {format_bytes(total)} but {format_bytes(avail)} of memory is available")
    data = dict(small)
    for name, info in members.items():
        if name not in data:
            with archive.open(info) as f:
                data[name] = np.lib.format.read_array(f, allow_pickle=False)
    return data


# ----------------------------------------------------------------------------
# the complex
# ----------------------------------------------------------------------------

class CellComplex:
    """A cell complex of dimension ``dim = n - k`` in R^n.

    Parameters
    ----------
    n, k : int
        Ambient dimension and codimension, ``0 <= k <= n``, ``n >= 1``.
    vertices : (V, n) array of real numbers
        Stored as float64.
    edges : (E, 2) integer array
        Vertex ids of each 1-cell; stored as int64.
    cells : dict r -> (offsets, faces), optional
        For r = 2..dim: offsets (N_r + 1,) and faces (M_r,) integer arrays, the
        faces of r-cell i being the (r-1)-cell ids ``faces[offsets[i]:offsets[i+1]]``.
        A missing r means no r-cells.
    meta : dict, optional
        Free-form information (bounds, div, method, seed, formulas, variables, ...).

    The arrays are stored read-only (results such as :meth:`polygons` are
    cached), so build a new complex rather than editing one in place.

    Raises
    ------
    ValueError
        With a message naming the offending argument, for any bad shape, dtype
        or out-of-range id.
    """

    def __init__(self, n, k, vertices, edges, cells=None, meta=None):
        n = _as_int(n, "n")
        k = _as_int(k, "k")
        if n < 1:
            raise ValueError(f"n must be >= 1, got {n}")
        if not 0 <= k <= n:
            raise ValueError(f"k must satisfy 0 <= k <= n = {n}, got {k}")
        self.n = n
        self.k = k
        self.dim = n - k

        # vertices
        try:
            v = np.asarray(vertices)
        except Exception as exc:  # noqa: BLE001 - ragged lists and whatever an __array__ raises
            raise ValueError(f"vertices must be a (V, {n}) float array: {exc}") from None
        if v.size == 0 and v.ndim < 2:
            v = np.zeros((0, n))
        if v.dtype.kind not in "iuf":
            raise ValueError(f"vertices must be a (V, {n}) float array, got dtype {v.dtype}")
        if v.ndim != 2 or v.shape[1] != n:
            raise ValueError(f"vertices must have shape (V, {n}), got {v.shape}")
        v = np.ascontiguousarray(v, dtype=np.float64)
        n_vertices = v.shape[0]

        # edges
        e = _int_array(edges, "edges", 2)
        if e.ndim != 2 or e.shape[1] != 2:
            raise ValueError(f"edges must have shape (E, 2), got {e.shape}")
        if e.size:
            lo, hi = int(e.min()), int(e.max())
            if lo < 0 or hi >= n_vertices:
                bad = lo if lo < 0 else hi
                raise ValueError(
                    f"edges refer to vertex {bad}, but there are {n_vertices} vertices")
        if self.dim < 1 and e.shape[0]:
            raise ValueError(f"a complex of dimension {self.dim} has no edges, got {e.shape[0]}")

        # higher cells
        if cells is None:
            cells = {}
        if not isinstance(cells, Mapping):
            raise ValueError("cells must be a dict r -> (offsets, faces)")
        given = {}
        for key, value in cells.items():
            r = _as_int(key, "cells key")
            if not 2 <= r <= self.dim:
                raise ValueError(
                    f"cells has key {r}, but a complex of dimension {self.dim} "
                    f"has r-cells in CSR form only for r = 2..{self.dim}")
            if r in given:
                raise ValueError(f"cells has key {r} twice")
            given[r] = value
        out = {}
        n_below = e.shape[0]
        for r in range(2, self.dim + 1):
            if r not in given:
                off, fac = np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64)
            else:
                value = given[r]
                if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") \
                        or len(value) != 2:
                    raise ValueError(f"cells[{r}] must be a pair (offsets, faces)")
                off = _int_array(value[0], f"cells[{r}] offsets", 1)
                fac = _int_array(value[1], f"cells[{r}] faces", 1)
                if off.size == 0:
                    raise ValueError(f"cells[{r}] offsets must have length N_{r} + 1 >= 1")
                if off[0] != 0:
                    raise ValueError(f"cells[{r}] offsets must start at 0, got {off[0]}")
                if off.size > 1 and np.any(np.diff(off) < 0):
                    raise ValueError(f"cells[{r}] offsets must be non-decreasing")
                if off[-1] != fac.size:
                    raise ValueError(
                        f"cells[{r}] offsets end at {off[-1]}, but there are "
                        f"{fac.size} face entries")
                if fac.size:
                    lo, hi = int(fac.min()), int(fac.max())
                    if lo < 0 or hi >= n_below:
                        bad = lo if lo < 0 else hi
                        raise ValueError(
                            f"cells[{r}] faces refer to {r - 1}-cell {bad}, but there are "
                            f"{n_below} {r - 1}-cells")
            out[r] = (_frozen(off), _frozen(fac))
            n_below = off.size - 1

        if meta is None:
            meta = {}
        if not isinstance(meta, Mapping):
            raise ValueError(f"meta must be a dict, got {type(meta).__name__}")

        self.vertices = _frozen(v)
        self.edges = _frozen(e)
        self.cells = out
        self.meta = dict(meta)
        self._cache = {}

    # ------------------------------------------------------------------ counts

    def count(self, r) -> int:
        """Number of r-cells, 0 <= r <= dim."""
        r = _as_int(r, "r")
        if not 0 <= r <= self.dim:
            raise ValueError(f"r must be in 0..{self.dim}, got {r}")
        if r == 0:
            return int(self.vertices.shape[0])
        if r == 1:
            return int(self.edges.shape[0])
        return int(self.cells[r][0].size - 1)

    def counts(self) -> list[int]:
        """``[count(0), ..., count(dim)]``."""
        return [self.count(r) for r in range(self.dim + 1)]

    def euler_characteristic(self) -> int:
        """Sum over r of (-1)^r count(r)."""
        return int(sum((-1) ** r * c for r, c in enumerate(self.counts())))

    # --------------------------------------------------------------- boundary

    def facet_cofaces(self) -> np.ndarray:
        """(N_{dim-1},) int64: how many top cells have each (dim-1)-cell as a face.

        For dim == 1 this is the degree of each vertex in the edge list; for
        dim == 0 it is empty.
        """
        if self.dim == 0:
            return np.zeros(0, dtype=np.int64)
        if self.dim == 1:
            return np.bincount(self.edges.ravel(), minlength=self.count(0)).astype(np.int64)
        faces = self.cells[self.dim][1]
        return np.bincount(faces, minlength=self.count(self.dim - 1)).astype(np.int64)

    def boundary_facets(self) -> np.ndarray:
        """int64 ids of the (dim-1)-cells with exactly one top-cell coface."""
        return np.flatnonzero(self.facet_cofaces() == 1).astype(np.int64)

    # ---------------------------------------------------------------- vertices

    def cell_vertices(self, r):
        """Vertex sets of the r-cells as CSR: (offsets (N_r + 1,) int64, ids int64).

        The vertices of r-cell i are ``ids[offsets[i]:offsets[i+1]]``, sorted and
        unique.  Computed level by level (the vertices of an r-cell are the union
        of those of its faces) with vectorized numpy; cached.
        """
        r = _as_int(r, "r")
        if not 0 <= r <= self.dim:
            raise ValueError(f"r must be in 0..{self.dim}, got {r}")
        key = ("cell_vertices", r)
        if key in self._cache:
            return self._cache[key]
        nv = self.count(0)
        if r == 0:
            result = (np.arange(nv + 1, dtype=np.int64), np.arange(nv, dtype=np.int64))
        elif r == 1:
            ne = self.count(1)
            owner = np.repeat(np.arange(ne, dtype=np.int64), 2)
            result = _segment_unique(owner, self.edges.ravel(), ne, nv)
        else:
            off, fac = self.cells[r]
            nr = off.size - 1
            face_owner = np.repeat(np.arange(nr, dtype=np.int64), np.diff(off))
            if r == 2:
                owner = np.repeat(face_owner, 2)
                values = self.edges[fac].ravel()
            else:
                sub_off, sub_ids = self.cell_vertices(r - 1)
                rep, values = _gather_segments(sub_off, sub_ids, fac)
                owner = face_owner[rep]
            result = _segment_unique(owner, values, nr, nv)
        result = (_frozen(result[0]), _frozen(result[1]))
        self._cache[key] = result
        return result

    def polygons(self):
        """Each 2-cell's vertices as an ordered loop: CSR (offsets, vertex ids) int64.

        For a 2-cell whose edges form one cycle v0-v1-...-v(m-1)-v0 the loop lists
        its m vertices in cycle order (starting at the first vertex of its first
        edge, heading to that edge's other vertex); consecutive vertices, and the
        last and the first, share an edge of the cell.  A degenerate 2-cell (edges
        not forming a single cycle) gets the closed walk through its edges that
        starts on its first edge (turning at vertices of degree != 2 to the next
        edge around the vertex): some vertices may repeat, some edges may be
        missed.  Empty when dim < 2.  Vectorized (pointer jumping); cached.
        """
        key = ("polygons",)
        if key in self._cache:
            return self._cache[key]
        if self.dim < 2:
            result = (np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64))
        else:
            result = self._polygons()
        result = (_frozen(result[0]), _frozen(result[1]))
        self._cache[key] = result
        return result

    def _polygons(self):
        off, fac = self.cells[2]
        n_cells = off.size - 1
        counts = np.diff(off)
        m = fac.size
        if m == 0:
            return np.zeros(n_cells + 1, dtype=np.int64), np.zeros(0, dtype=np.int64)
        nv = max(self.count(0), 1)
        n_darts = 2 * m
        # Darts: face entry j gives dart 2j = (u -> v) and dart 2j+1 = (v -> u),
        # where (u, v) is the edge; the darts of cell c are 2*off[c] .. 2*off[c+1]-1.
        tail = self.edges[fac].ravel()                      # tail vertex of each dart
        dart_cell = np.repeat(np.arange(n_cells, dtype=np.int64), 2 * counts)
        first = np.repeat(2 * off[:-1], 2 * counts)         # first dart of the dart's cell
        local = np.arange(n_darts, dtype=np.int64)
        local -= first                                      # dart index within its cell
        # Sort the darts by (cell, tail, local index): one key, one plain sort.
        bits = max(1, int(2 * int(counts.max()) - 1).bit_length())
        if (n_cells * nv) < (_INT64_MAX >> (bits + 1)):
            key = dart_cell * nv
            key += tail
            key <<= bits
            key |= local
            key.sort()
            # each cell's darts stay in the cell's block, so position p holds a dart of
            # cell dart_cell[p]: order[p] = first[p] + local index stored in the key
            order = key & ((1 << bits) - 1)
            order += first
            key >>= bits                                    # group key: (cell, tail)
        else:  # astronomically many cells or vertices
            order = np.lexsort((local, tail, dart_cell))
            key = dart_cell[order] * nv + tail[order]       # may wrap: only compared
        del local
        new_group = np.empty(n_darts, dtype=bool)
        new_group[0] = True
        np.not_equal(key[1:], key[:-1], out=new_group[1:])
        del key
        # sigma: the next dart (cyclically) in the same (cell, tail) group
        group_start = np.flatnonzero(new_group)
        group_len = np.diff(np.append(group_start, n_darts))
        nxt_pos = np.arange(1, n_darts + 1, dtype=np.int64)
        nxt_pos[group_start + group_len - 1] = group_start
        del new_group, group_start, group_len
        sigma = np.empty(n_darts, dtype=np.int64)
        sigma[order] = order[nxt_pos]
        del order, nxt_pos
        # next(a -> b) = sigma(b -> a): the dart leaving b after the reverse dart.
        nxt = sigma.reshape(-1, 2)[:, ::-1].ravel()
        del sigma

        # Walk from each cell's start dart (its first dart): rank the darts on the
        # start's orbit by pointer jumping towards the terminal dart (the one whose
        # next is the start).
        is_terminal = nxt == first
        terminal_darts = np.flatnonzero(is_terminal)
        terminal = np.full(n_cells, -1, dtype=np.int64)
        terminal[dart_cell[terminal_darts]] = terminal_darts
        jump = nxt
        jump[terminal_darts] = terminal_darts
        dist = np.ones(n_darts, dtype=np.int64)
        dist[terminal_darts] = 0
        del is_terminal, first
        tmp = np.empty_like(jump)
        for _ in range(max(1, int(2 * int(counts.max())).bit_length())):
            dist += dist[jump]
            np.take(jump, jump, out=tmp)
            jump, tmp = tmp, jump
        del tmp
        nonempty = counts > 0
        length = np.zeros(n_cells, dtype=np.int64)
        length[nonempty] = dist[2 * off[:-1][nonempty]] + 1
        offsets = np.zeros(n_cells + 1, dtype=np.int64)
        np.cumsum(length, out=offsets[1:])
        d = np.flatnonzero(jump == terminal[dart_cell])
        c = dart_cell[d]
        where = offsets[c] + (length[c] - 1 - dist[d])
        ids = np.empty(int(offsets[-1]), dtype=np.int64)
        ids[where] = tail[d]
        return offsets, ids

    # ------------------------------------------------------------ components

    def component_labels(self) -> np.ndarray:
        """(V,) int64: for each vertex, the smallest vertex id in its connected
        component of the 1-skeleton.  Cached."""
        key = ("component_labels",)
        if key in self._cache:
            return self._cache[key]
        labels = _component_roots(self.count(0), self.edges[:, 0], self.edges[:, 1])
        labels = _frozen(labels)
        self._cache[key] = labels
        return labels

    def connected_components(self) -> int:
        """Number of connected components of the 1-skeleton (isolated vertices count)."""
        labels = self.component_labels()
        return int(np.count_nonzero(labels == np.arange(labels.size)))

    # --------------------------------------------------------------- files

    def save(self, path, *, compressed: bool = True, timings: bool = False) -> None:
        """Write the complex to `path` as an ``.npz`` file in format ``gcmh-complex/1``.

        ``meta`` goes into the key ``meta_json`` (numpy values become lists and
        numbers), except what depends on the machine and the moment (``seconds``,
        ``timings``): the same complex gives the same bytes.  ``timings=True`` keeps
        those in the optional key ``run_json``.  ``.npz`` is added to a file name that
        lacks it.  A file name is written atomically (see `safe_io`: a temporary file
        beside it replaces it when complete, with the usual mode; a symlink is written
        through; a folder, device, FIFO or socket is refused with InputError); `path`
        may also be a binary file object.
        """
        arrays = {
            "format": np.array(FORMAT),
            "n": np.array(self.n, dtype=np.int64),
            "k": np.array(self.k, dtype=np.int64),
            "vertices": np.asarray(self.vertices),
            "cells_1": np.asarray(self.edges),
        }
        for r in range(2, self.dim + 1):
            off, fac = self.cells[r]
            arrays[f"cells_{r}_offsets"] = np.asarray(off)
            arrays[f"cells_{r}_faces"] = np.asarray(fac)
        meta = {key: value for key, value in self.meta.items() if key not in VOLATILE_META}
        arrays["meta_json"] = np.array(json.dumps(_jsonable(meta)))
        run = {key: value for key, value in self.meta.items() if key in VOLATILE_META}
        if timings and run:
            arrays["run_json"] = np.array(json.dumps(_jsonable(run)))
        if hasattr(path, "write"):
            _write_npz(path, arrays, compressed)
            return
        name = os.fspath(path)
        if isinstance(name, bytes):
            name = os.fsdecode(name)
        if not name.endswith(".npz"):
            name += ".npz"

        def write(temp):
            with open(temp, "wb") as f:
                _write_npz(f, arrays, compressed)

        atomic_write(name, write, ".npz")

    @classmethod
    def load(cls, path) -> CellComplex:
        """Read a complex written by :meth:`save`.

        Raises ValueError (naming the file) if it is not a readable
        ``gcmh-complex/1`` file.  Never unpickles anything.  Every member's size,
        dtype and shape are checked from the archive's headers before any array is
        read: a member whose header disagrees with the archive, whose role wants
        another shape or dtype, that would not fit in memory, or that expands from
        far less compressed data than an array of real numbers can (a zip bomb), is
        refused in milliseconds.  Keys other than the format's own, ``meta_json`` and
        ``run_json`` are put into ``meta`` (arrays as lists) unless already there.
        """
        where = os.fspath(path)

        def bad(why):
            return ValueError(f"{where}: not a valid {FORMAT} file: {why}")

        try:
            with open(path, "rb") as f:
                head = f.read(6)
        except (FileNotFoundError, IsADirectoryError, PermissionError):
            raise
        except OSError as exc:
            raise bad(exc) from None
        if head == b"\x93NUMPY":
            raise bad("it is a single .npy array, not an .npz archive")
        try:
            archive = zipfile.ZipFile(path)
        except (zipfile.BadZipFile, OSError, ValueError, EOFError) as exc:
            raise bad(exc) from None
        with archive:
            try:
                data = _read_checked(archive, bad)
            except ValueError:
                raise
            except Exception as exc:  # noqa: BLE001 - corrupt member, bad CRC, truncated stream, ...
                raise bad(exc) from None
        n, k = int(data["n"]), int(data["k"])
        vertices, edges = data["vertices"], data["cells_1"]
        known = {"format", "n", "k", "vertices", "cells_1", "meta_json", "run_json"}
        cells = {}
        for r in range(2, max(n - k, 1) + 1):
            ko, kf = f"cells_{r}_offsets", f"cells_{r}_faces"
            cells[r] = (data[ko], data[kf])
            known.update((ko, kf))

        meta = {}
        for key in ("meta_json", "run_json"):
            if key in data:
                try:
                    part = json.loads(str(data[key][()]))
                except ValueError as exc:
                    raise bad(f"{key!r} is not valid JSON: {exc}") from None
                except RecursionError:
                    raise bad(f"{key!r} is nested too deeply") from None
                if not isinstance(part, dict):
                    raise bad(f"{key!r} must hold a JSON object")
                meta.update(part)
        for name, value in data.items():
            if name not in known and name not in meta:
                meta[name] = value.item() if value.shape == () else value.tolist()

        try:
            return cls(n, k, vertices, edges, cells, meta)
        except ValueError as exc:
            raise bad(exc) from None

    # --------------------------------------------------------------- VTK

    def point_names(self) -> list[str]:
        """Names of the n coordinates: ``meta["variables"]`` if it holds n distinct
        strings, else ``x1..xn``."""
        names = self.meta.get("variables")
        if isinstance(names, (list, tuple)) and len(names) == self.n and \
                all(isinstance(s, str) and s for s in names) and len(set(names)) == self.n:
            return list(names)
        return [f"x{i + 1}" for i in range(self.n)]

    def to_pyvista(self):
        """A ``pyvista.UnstructuredGrid`` of the complex (pyvista imported here).

        Points: the first three coordinates (zero-padded when n < 3).  Cells:
        dim 0 -> one VTK_VERTEX per vertex; dim 1 -> one VTK_LINE per edge;
        dim >= 2 -> one VTK_POLYGON per 2-cell with >= 3 loop vertices (the
        2-skeleton when dim > 2), from :meth:`polygons`.  Point data: one float64
        array per coordinate, named by :meth:`point_names`.  Cell data
        ``cell_id``: the id of the complex cell each VTK cell comes from.
        """
        import pyvista as pv

        nv = self.count(0)
        points = np.zeros((nv, 3), dtype=np.float64)
        m = min(self.n, 3)
        points[:, :m] = self.vertices[:, :m]

        if self.dim == 0:
            ids = np.arange(nv, dtype=np.int64)
            flat = np.column_stack([np.ones(nv, dtype=np.int64), ids]).ravel()
            types = np.full(nv, pv.CellType.VERTEX, dtype=np.uint8)
        elif self.dim == 1:
            ids = np.arange(self.count(1), dtype=np.int64)
            flat = np.column_stack(
                [np.full(ids.size, 2, dtype=np.int64), self.edges]).ravel()
            types = np.full(ids.size, pv.CellType.LINE, dtype=np.uint8)
        else:
            off, loop = self.polygons()
            sizes = np.diff(off)
            ids = np.flatnonzero(sizes >= 3).astype(np.int64)
            keep = np.repeat(sizes >= 3, sizes)
            kept_sizes = sizes[ids]
            kept_loop = loop[keep]
            flat = np.empty(kept_sizes.size + kept_loop.size, dtype=np.int64)
            heads = np.zeros(kept_sizes.size, dtype=np.int64)
            if kept_sizes.size:
                heads[1:] = np.cumsum(kept_sizes[:-1] + 1)
            is_head = np.zeros(flat.size, dtype=bool)
            is_head[heads] = True
            flat[heads] = kept_sizes
            flat[~is_head] = kept_loop
            types = np.full(ids.size, pv.CellType.POLYGON, dtype=np.uint8)

        grid = pv.UnstructuredGrid(flat, types, points)
        for i, name in enumerate(self.point_names()):
            grid.point_data[name] = np.ascontiguousarray(self.vertices[:, i])
        grid.cell_data["cell_id"] = ids
        return grid

    def save_vtu(self, path) -> None:
        """Write :meth:`to_pyvista` to `path` (a ``.vtu`` file, binary), atomically
        and with the same checks of `path` as :meth:`save`; or to `path`'s ``write`` if it
        is a binary file object.  A full disk is an OSError, the old file left as it was."""
        data = _vtu_bytes(self.to_pyvista())
        if hasattr(path, "write"):
            path.write(data)
            return

        def write(temp):
            with open(temp, "wb") as f:
                f.write(data)

        atomic_write(path, write, ".vtu")

    # --------------------------------------------------------------- misc

    def __repr__(self):
        return f"CellComplex(n={self.n}, k={self.k}, counts={self.counts()})"


def _vtu_bytes(grid) -> bytes:
    """``grid`` as the bytes of a binary, zlib-compressed .vtu file (what pyvista's ``save`` writes).

    VTK writes to memory here and Python writes the file: VTK's own file writer, on a full disk,
    went down its error path into ``free(): invalid pointer`` (an abort, the temporary left behind);
    Python's write raises OSError, which the caller reports and cleans up after."""
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

    writer = vtkXMLUnstructuredGridWriter()
    writer.SetInputData(grid)
    writer.SetDataModeToBinary()
    writer.SetCompressorTypeToZLib()
    writer.WriteToOutputStringOn()
    if writer.Write() != 1 or writer.GetErrorCode() != 0:
        raise OSError(f"VTK could not write the .vtu (error code {writer.GetErrorCode()})")
    text = writer.GetOutputString()
    return text if isinstance(text, bytes) else text.encode("utf-8")
