"""Linear projections R^n -> R^3 for viewing an n-dimensional complex (pure numpy).

The view shows ``P(theta) @ (x - c)`` for every vertex ``x``, where

* ``c`` is a centre (the middle of the vertices' bounding box), so rotations
  turn the object in place instead of swinging it around the origin;
* ``R(theta)`` is a composition of Givens rotations, one per coordinate plane
  ``(i, j)``, ``i < j``, applied in lexicographic order of the planes;
* ``B`` is a base projection, a ``(3, n)`` matrix with orthonormal rows:
  three chosen coordinates, a generic (seeded random) orthonormal frame, or the
  principal axes of the vertices;
* ``P(theta) = B @ R(theta)``, so its rows stay orthonormal.

Beyond this linear (orthographic) view there are two nonlinear kinds, both
defined on the frame coordinates ``Y = F(theta) (x - c)`` where the ``(n, n)``
frame ``F = [B; H] @ R(theta)`` adds to the three screen rows of ``B`` the
directions ``H`` it hides (:func:`hidden_directions`), rotated alike:

* ``perspective`` (the 4D-viewer way, recursively): an eye at distance ``d``
  on the last hidden axis projects R^n to R^(n-1), scaling every remaining
  coordinate by ``d / (d - y_n)``; then an eye on the next hidden axis, and so
  on down to R^3. A point's factor is the product of its factors, each taken
  on the already scaled coordinate. ``d`` is ``distance`` times the largest
  distance of a vertex from the centre, so the picture keeps its size.
* ``stereographic`` (for manifolds on a sphere, e.g. the Clifford torus): with
  ``r`` the median distance of the vertices from the centre, the sphere of
  radius ``r`` is projected from its pole on the first hidden axis,
  ``y_screen * r / (r - y_pole)`` (the equator stays put); further hidden
  axes (n > 4) are dropped. The rotation acts before the projection, so a
  slider turns the sphere and the picture moves by a Moebius map.

Points at or behind an eye (or at the pole) are held at a finite distance: the
denominator is clamped to ``EYE_CLAMP`` times ``d`` (or ``r``).

This module knows nothing of Qt or VTK; :class:`ProjectionModel` is the state
the projection panel edits and the viewer reads.

Examples
--------
>>> import numpy as np
>>> P = projection_matrix(coordinate_basis(4, (0, 1, 3)), rotation(4, {(2, 3): np.pi / 2}))
>>> np.allclose(P @ P.T, np.eye(3))
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from gcmh_core.examples import VIEW_MAPPINGS as MAPPINGS  # (the names an example's [view] may give)

KINDS = ("coordinates", "generic", "principal")
MAPPING_LABELS = {
    "orthographic": "Orthographic (linear)",
    "perspective": "Perspective from the hidden axes",
    "stereographic": "Stereographic (manifolds on a sphere)",
}
EYE_CLAMP = 0.05
KIND_LABELS = {
    "coordinates": "Coordinate axes",
    "generic": "Generic (random orthonormal)",
    "principal": "Principal axes of the vertices",
}


def planes(n: int) -> list[tuple[int, int]]:
    """The coordinate planes ``(i, j)``, ``0 <= i < j < n``, in lexicographic order."""
    return [(i, j) for i in range(n) for j in range(i + 1, n)]


def givens(n: int, i: int, j: int, theta: float) -> np.ndarray:
    """The ``(n, n)`` rotation by ``theta`` radians in the plane of axes ``i`` and ``j``.

    It maps ``e_i -> cos(theta) e_i + sin(theta) e_j``.
    """
    if not (0 <= i < n and 0 <= j < n and i != j):
        raise ValueError(f"plane ({i}, {j}) is not a pair of distinct axes of R^{n}")
    G = np.eye(n)
    c, s = math.cos(theta), math.sin(theta)
    G[i, i] = c
    G[j, j] = c
    G[j, i] = s
    G[i, j] = -s
    return G


def rotation(n: int, angles) -> np.ndarray:
    """Compose Givens rotations: ``R = G(p_1) @ G(p_2) @ ... `` over the planes in order.

    ``angles`` is either a mapping ``{(i, j): theta}`` (missing planes are 0) or
    a sequence of ``n(n-1)/2`` angles in the order of :func:`planes`. Radians.
    Returns an ``(n, n)`` orthogonal float64 matrix.
    """
    ps = planes(n)
    if isinstance(angles, dict):
        thetas = [float(angles.get(p, 0.0)) for p in ps]
        unknown = set(angles) - set(ps)
        if unknown:
            raise ValueError(f"not planes of R^{n}: {sorted(unknown)}")
    else:
        thetas = [float(a) for a in angles]
        if len(thetas) != len(ps):
            raise ValueError(f"expected {len(ps)} angles for n = {n}, got {len(thetas)}")
    R = np.eye(n)
    for (i, j), t in zip(ps, thetas):
        if t != 0.0:
            # R @ G only mixes columns i and j: O(n) instead of a full product.
            c, s = math.cos(t), math.sin(t)
            ci, cj = R[:, i].copy(), R[:, j].copy()
            R[:, i] = c * ci + s * cj
            R[:, j] = -s * ci + c * cj
    return R


def coordinate_basis(n: int, axes=(0, 1, 2)) -> np.ndarray:
    """The ``(3, n)`` base projection sending coordinate ``axes[a]`` to screen axis ``a``.

    For ``n < 3`` the missing screen axes are zero rows.
    """
    axes = tuple(int(a) for a in axes)
    if len(axes) != 3:
        raise ValueError("three axes are needed (screen X, Y, Z)")
    B = np.zeros((3, n))
    used = [a for a in axes if a >= 0]
    if len(set(used)) != len(used):
        raise ValueError(f"the screen axes must show different coordinates, got {axes}")
    for row, a in enumerate(axes):
        if a < 0:
            continue
        if a >= n:
            raise ValueError(f"axis {a} does not exist in R^{n}")
        B[row, a] = 1.0
    return B


def default_axes(n: int) -> tuple[int, int, int]:
    """``(0, 1, 2)``, with ``-1`` (an empty screen axis) where ``n < 3``."""
    a, b, c = (i if i < n else -1 for i in range(3))
    return a, b, c


def generic_basis(n: int, seed: int = 0) -> np.ndarray:
    """A seeded random ``(3, n)`` matrix with orthonormal rows (QR of a Gaussian matrix)."""
    rng = np.random.default_rng(seed)
    m = min(3, n)
    A = rng.standard_normal((n, m))
    Q, Rr = np.linalg.qr(A)
    Q = Q * np.sign(np.diag(Rr))  # a unique, seed-determined frame
    B = np.zeros((3, n))
    B[:m] = Q.T
    return B


def principal_basis(vertices: np.ndarray) -> np.ndarray:
    """The three principal axes of ``vertices`` ``(V, n)`` as a ``(3, n)`` matrix.

    Rows are the right singular vectors of the centred vertices with the largest
    singular values, signs fixed so the largest entry of each row is positive.
    Falls back to coordinate axes when there are too few vertices.
    """
    X = np.asarray(vertices, dtype=np.float64)
    n = X.shape[1]
    X = X[np.all(np.isfinite(X), axis=1)]
    if len(X) < 2:
        return coordinate_basis(n, default_axes(n))
    if len(X) > 200_000:  # a subsample gives the same axes, much faster
        X = X[np.random.default_rng(0).choice(len(X), 200_000, replace=False)]
    Xc = X - X.mean(axis=0)
    _, _, Vt = np.linalg.svd(Xc, full_matrices=False)
    m = min(3, n, Vt.shape[0])
    B = np.zeros((3, n))
    B[:m] = Vt[:m]
    for r in range(m):
        if B[r, np.argmax(np.abs(B[r]))] < 0:
            B[r] = -B[r]
    return B


def projection_matrix(base: np.ndarray, R: np.ndarray) -> np.ndarray:
    """``P = base @ R``: ``(3, n)`` with orthonormal rows when ``base`` has them."""
    return np.asarray(base, dtype=np.float64) @ np.asarray(R, dtype=np.float64)


def project(X: np.ndarray, P: np.ndarray, center=None, out: np.ndarray | None = None) -> np.ndarray:
    """Project points ``X`` ``(V, n)`` to ``(V, 3)``: ``(X - center) @ P.T``.

    For speed, centre ``X`` once (:meth:`Projector`) and pass ``center=None``;
    ``out`` (``(V, 3)``, same dtype as ``X``) is written in place.
    """
    Pt = np.ascontiguousarray(np.asarray(P).T, dtype=X.dtype)
    if center is not None:
        X = X - np.asarray(center, dtype=X.dtype)
    if out is None:
        return X @ Pt
    np.matmul(X, Pt, out=out)
    return out


def hidden_directions(P: np.ndarray) -> np.ndarray:
    """Orthonormal rows (n-3, n) spanning what the projection ``P`` (3, n) hides.

    Gram-Schmidt of the coordinate axes against P's rows, taking at each step
    the axis with the largest remainder (ties: the lowest index): for a
    coordinate projection the hidden directions are the left-out axes in order.
    Each row's largest entry is positive. Zero rows of P (n < 3) are skipped.
    """
    P = np.asarray(P, dtype=np.float64)
    n = P.shape[1]
    basis = [r / np.linalg.norm(r) for r in P if np.linalg.norm(r) > 1e-12]
    out = []
    eye = np.eye(n)
    while len(basis) < n:
        Bm = np.array(basis).reshape(-1, n)
        R = eye - (eye @ Bm.T) @ Bm
        norms = np.linalg.norm(R, axis=1)
        i = int(np.argmax(norms > norms.max() - 1e-9))
        v = R[i] / norms[i]
        if v[np.argmax(np.abs(v))] < 0:
            v = -v
        basis.append(v)
        out.append(v)
    return np.array(out).reshape(-1, n)


def perspective(Y: np.ndarray, d: float, out: np.ndarray | None = None) -> np.ndarray:
    """Recursive perspective of frame coordinates ``Y`` (n, V) to (3, V), eyes at distance ``d``.

    From the last axis down to axis 3: ``s *= d / (d - s * y_j)`` with the
    denominator clamped to ``EYE_CLAMP * d``; the result is ``s * Y[:3]``.
    """
    n, V = Y.shape
    s = np.ones(V, dtype=Y.dtype)
    den = np.empty(V, dtype=Y.dtype)
    for j in range(n - 1, 2, -1):
        np.multiply(Y[j], s, out=den)
        np.subtract(d, den, out=den)
        np.maximum(den, EYE_CLAMP * d, out=den)
        s *= d / den
    if out is None:
        out = np.empty((3, V), dtype=Y.dtype)
    np.multiply(Y[:3], s, out=out)
    return out


def stereographic(Y: np.ndarray, r: float, out: np.ndarray | None = None) -> np.ndarray:
    """Stereographic projection of frame coordinates ``Y`` (n, V), n >= 4, from the pole ``r e_3``.

    ``out = Y[:3] * r / (r - Y[3])`` (denominator clamped to ``EYE_CLAMP * r``):
    the sphere of radius ``r`` goes to R^3 with its equator (``Y[3] = 0``) fixed.
    """
    if Y.shape[0] < 4:
        raise ValueError("stereographic projection needs n >= 4 (a hidden axis for the pole)")
    den = np.maximum(r - Y[3], EYE_CLAMP * r)
    if out is None:
        out = np.empty((3, Y.shape[1]), dtype=Y.dtype)
    np.multiply(Y[:3], (r / den).astype(Y.dtype, copy=False), out=out)
    return out


@dataclass(frozen=True)
class View:
    """A whole view: the (n, n) frame (3 screen rows, then the hidden ones), the mapping, the eye distance.

    ``P`` (its first 3 rows) is the linear projection; for ``orthographic`` it is all.
    """

    frame: np.ndarray
    mapping: str = "orthographic"
    distance: float = 3.0

    @property
    def P(self) -> np.ndarray:
        return self.frame[:3]

    @property
    def linear(self) -> bool:
        return self.mapping == "orthographic" or self.frame.shape[0] < 4

    def hidden(self) -> np.ndarray:
        """The hidden directions of this view (n-3, n) in data coordinates."""
        return self.frame[3:]


def bbox_center(vertices: np.ndarray) -> np.ndarray:
    """Middle of the bounding box of the finite vertices (zeros when there are none)."""
    X = np.asarray(vertices, dtype=np.float64)
    fin = np.all(np.isfinite(X), axis=1)
    if not fin.any():
        return np.zeros(X.shape[1])
    X = X[fin]
    return 0.5 * (X.min(axis=0) + X.max(axis=0))


def axis_label(row: np.ndarray, names, tol: float = 1e-6, terms: int = 2) -> str:
    """A short label for a screen axis with direction ``row`` (length n) in R^n.

    A pure coordinate gives its name (``"s"``, or ``"-s"``); a mixture gives its
    largest terms, e.g. ``"0.71 x + 0.71 w"`` (with ``"+ ..."`` when more follow).
    """
    row = np.asarray(row, dtype=float)
    if not np.any(np.abs(row) > tol):
        return ""
    order = np.argsort(-np.abs(row), kind="stable")
    big = [i for i in order if abs(row[i]) > tol]
    if len(big) == 1 or abs(abs(row[big[0]]) - 1.0) < 1e-9:
        return ("-" if row[big[0]] < 0 else "") + names[big[0]]
    parts = []
    for t, i in enumerate(big[:terms]):
        c = row[i]
        sign = "-" if c < 0 else "+"
        txt = f"{abs(c):.2f} {names[i]}"
        parts.append(("-" + txt if c < 0 else txt) if t == 0 else f" {sign} {txt}")
    if len(big) > terms:
        parts.append(" + ...")
    return "".join(parts)


def varying_colour(names, vertices) -> str | None:
    """The last of ``names`` whose coordinate varies on ``vertices`` (V, n): a colour that says something
    (the last coordinate of a torus in R^10 is 0 on all of it: one flat colour, a bar "0.00 ... -0.00")."""
    X = np.asarray(vertices, dtype=float)
    if X.ndim != 2 or not len(X) or X.shape[1] != len(names):
        return names[-1] if len(names) else None
    with np.errstate(invalid="ignore"):
        spread = np.nanmax(X, axis=0) - np.nanmin(X, axis=0)
    scale = max(float(np.nanmax(np.abs(spread))) if np.isfinite(spread).any() else 0.0, 1e-300)
    for i in range(len(names) - 1, -1, -1):
        if np.isfinite(spread[i]) and spread[i] > 1e-6 * scale:
            return names[i]
    return names[-1]


@dataclass
class ProjectionModel:
    """The state of the view projection: kind, base parameters and the plane angles.

    Angles are in degrees (what the sliders show), one per plane of :func:`planes`.
    The principal base needs the vertices: call :meth:`set_vertices` when a new
    result arrives.
    """

    n: int
    kind: str = "coordinates"
    axes: tuple = (0, 1, 2)
    seed: int = 0
    angles: np.ndarray = field(default=None)  # type: ignore[arg-type]  # (None: zeros, by __post_init__)
    mapping: str = "orthographic"
    distance: float = 3.0
    _principal: np.ndarray | None = field(default=None, repr=False)
    _principal_vertices: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"unknown projection kind {self.kind!r}; choose one of {KINDS}")
        if self.mapping not in MAPPINGS:
            raise ValueError(f"unknown projection mapping {self.mapping!r}; choose one of {MAPPINGS}")
        if not (self.distance > 1.0):
            raise ValueError(f"the eye distance must be > 1 (in radii of the object), got {self.distance}")
        if self.angles is None:
            self.angles = np.zeros(len(planes(self.n)))
        self.angles = np.asarray(self.angles, dtype=float).copy()
        if len(self.angles) != len(planes(self.n)):
            raise ValueError("wrong number of angles")
        if tuple(self.axes) == (0, 1, 2):
            self.axes = default_axes(self.n)
        coordinate_basis(self.n, self.axes)  # validates

    @property
    def planes(self) -> list[tuple[int, int]]:
        return planes(self.n)

    def set_vertices(self, vertices: np.ndarray) -> None:
        """The vertices of the principal axes (the ``principal`` kind): their SVD runs when that base is
        first used, not for every result that arrives (35-90 ms on the GUI thread for a large one)."""
        self._principal = None
        self._principal_vertices = vertices if len(vertices) else None

    def share_principal(self, other: ProjectionModel) -> None:
        """Use ``other``'s principal axes (computed or still pending)."""
        self._principal, self._principal_vertices = other._principal, other._principal_vertices

    def _principal_basis(self) -> np.ndarray | None:
        if self._principal is None and self._principal_vertices is not None:
            self._principal = principal_basis(self._principal_vertices)
            self._principal_vertices = None
        return self._principal

    def base(self) -> np.ndarray:
        if self.kind == "coordinates":
            return coordinate_basis(self.n, self.axes)
        if self.kind == "generic":
            return generic_basis(self.n, self.seed)
        principal = self._principal_basis()
        if principal is None:
            return coordinate_basis(self.n, default_axes(self.n))
        return principal

    def rotation(self) -> np.ndarray:
        return rotation(self.n, np.radians(self.angles))

    def matrix(self) -> np.ndarray:
        """The current ``(3, n)`` projection ``P(theta)``."""
        return projection_matrix(self.base(), self.rotation())

    def frame(self) -> np.ndarray:
        """The rotated (n, n) frame: the rows of :meth:`matrix`, then the hidden directions."""
        B = self.base()
        n = self.n
        if n <= 3:
            return projection_matrix(B, self.rotation())
        full = np.concatenate([B, hidden_directions(B)])
        return full @ self.rotation()

    def view(self) -> View:
        """The whole current view (frame, mapping, eye distance)."""
        mapping = self.mapping if self.n >= 4 else "orthographic"
        return View(self.frame(), mapping, float(self.distance))

    def reset_angles(self) -> None:
        self.angles[:] = 0.0

    def labels(self, names) -> list[str]:
        """Labels of the three screen axes, from the rows of :meth:`matrix`."""
        P = self.matrix()
        return [axis_label(P[r], names) for r in range(3)]

    def to_dict(self, names=None) -> dict:
        d = {"kind": self.kind, "axes": [int(a) for a in self.axes], "seed": int(self.seed),
             "angles": [float(a) for a in self.angles], "mapping": self.mapping, "distance": float(self.distance)}
        if names is not None:
            d["axes_names"] = [names[a] if a >= 0 else None for a in self.axes]
            d["planes"] = [f"{names[i]}-{names[j]}" for i, j in self.planes]
        return d

    @classmethod
    def from_dict(cls, n: int, d: dict) -> ProjectionModel:
        return cls(n=n, kind=d.get("kind", "coordinates"), axes=tuple(d.get("axes", default_axes(n))),
                   seed=int(d.get("seed", 0)), angles=d.get("angles"),  # type: ignore[arg-type]  # (None: zeros)
                   mapping=d.get("mapping", "orthographic"), distance=float(d.get("distance", 3.0)))


class Projector:
    """Fast repeated projection of fixed vertices: centred once, float32, preallocated.

    ``Projector(vertices).project(P, out)`` writes ``(V, 3)`` into ``out`` with
    one matmul and no temporary of size V. The centred vertices are stored
    transposed, ``(n, V)``, so the product is ``P (3, n) @ X^T (n, V)`` written
    into ``out.T``: a wide, BLAS-friendly product (1M vertices, n = 10: ~5 ms).
    """

    def __init__(self, vertices: np.ndarray, center=None, dtype=np.float32):
        X = np.asarray(vertices, dtype=np.float64)
        self.center = bbox_center(X) if center is None else np.asarray(center, float)
        Xc = X - self.center
        Xc[~np.isfinite(Xc)] = 0.0
        self.XT = np.ascontiguousarray(Xc.T, dtype=dtype)
        self.dtype = np.dtype(dtype)
        self._radii: tuple[float, float] | None = None
        self._Y: np.ndarray | None = None

    def radii(self) -> tuple[float, float]:
        """(largest, median) distance of a vertex from the centre (eye and sphere scales)."""
        if self._radii is None:
            if self.XT.shape[1] == 0:
                self._radii = (1.0, 1.0)
            else:
                r = np.sqrt(np.einsum("iv,iv->v", self.XT, self.XT, dtype=np.float64))
                big, med = float(r.max()), float(np.median(r))
                self._radii = (big if big > 0 else 1.0, med if med > 0 else 1.0)
        return self._radii

    def set_radii(self, radii) -> None:
        """Use another complex's scales (a slice keeps the full complex's eye and sphere)."""
        self._radii = (float(radii[0]), float(radii[1]))

    def project_view(self, view: View, out: np.ndarray | None = None) -> np.ndarray:
        """Write the (V, 3) image of the vertices under ``view`` (any mapping) into ``out``."""
        if view.linear:
            return self.project(view.P, out)
        F = np.asarray(view.frame, dtype=self.dtype)
        V = self.XT.shape[1]
        if self._Y is None or self._Y.shape != (F.shape[0], V):
            self._Y = np.empty((F.shape[0], V), dtype=self.dtype)
        np.matmul(F, self.XT, out=self._Y)
        if out is None:
            out = self.empty()
        direct = out.flags.c_contiguous and out.dtype == self.dtype
        target = out.T if direct else np.empty((3, V), self.dtype)
        big, med = self.radii()
        if view.mapping == "perspective":
            perspective(self._Y, view.distance * big, out=target)
        else:
            stereographic(self._Y, med, out=target)
        if not direct:
            out[...] = target.T
        return out

    @property
    def X(self) -> np.ndarray:
        """The centred vertices (V, n) (a transposed view)."""
        return self.XT.T

    def empty(self) -> np.ndarray:
        return np.empty((self.XT.shape[1], 3), dtype=self.dtype)

    def project(self, P: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        P = np.asarray(P, dtype=self.dtype)
        if out is None:
            out = self.empty()
        if out.flags.c_contiguous and out.dtype == self.dtype:
            np.matmul(P, self.XT, out=out.T)
        else:
            out[...] = (P @ self.XT).T
        return out


def givens_angles(R: np.ndarray) -> np.ndarray:
    """The angles (radians, in the order of :func:`planes`) with ``rotation(n, angles) == R``.

    ``R`` (n, n) orthogonal with determinant +1. Peels the Givens factors off the left
    in the order they compose: ``G(0,1)^T`` zeroes ``R[1, 0]``, then ``G(0,2)^T``
    ``R[2, 0]``, ..., so the first column becomes ``e_0``; then the same for column 1
    with the planes (1, j), and so on. Each angle is in (-pi, pi].
    """
    A = np.array(R, dtype=np.float64)
    n = A.shape[0]
    out = []
    for i, j in planes(n):
        t = math.atan2(A[j, i], A[i, i])
        c, s = math.cos(t), math.sin(t)
        ri, rj = A[i].copy(), A[j].copy()
        A[i] = c * ri + s * rj           # G(i, j)^T from the left
        A[j] = -s * ri + c * rj
        out.append(t)
    return np.array(out)


def plane_rotation(d: np.ndarray, h: np.ndarray, theta: float) -> np.ndarray:
    """The (n, n) rotation by ``theta`` in the plane of unit vectors ``d`` and ``h`` taking ``h``
    towards ``d`` (``Q h = cos h + sin d``); ``d`` is made orthogonal to ``h`` first."""
    h = np.asarray(h, dtype=float) / np.linalg.norm(h)
    d = np.asarray(d, dtype=float) - np.dot(d, h) * h
    nd = np.linalg.norm(d)
    n = len(h)
    if nd < 1e-12:
        return np.eye(n)
    d = d / nd
    c, s = math.cos(theta), math.sin(theta)
    return np.eye(n) + (c - 1.0) * (np.outer(d, d) + np.outer(h, h)) + s * (np.outer(d, h) - np.outer(h, d))


def turned_angles(model: ProjectionModel, screen: np.ndarray, hidden: int, degrees: float) -> np.ndarray:
    """The model's angles (degrees) after turning the 3D direction ``screen`` (a unit 3-vector in the
    projected space, e.g. the camera's right or up) against the ``hidden``-th hidden direction of the
    frame by ``degrees``: what hidden lies along that axis comes into view along ``screen``.

    The whole turn happens in R^n (``R' = R Q``, Q the plane rotation of the frame's directions),
    then is written back as the plane angles the sliders show (:func:`givens_angles`).
    """
    n = model.n
    if n <= 3:
        return model.angles.copy()
    F = model.frame()                             # (n, n): screen rows, then the hidden rows
    hidden = int(min(max(hidden, 0), n - 4))
    d = np.asarray(screen, dtype=float) @ F[:3]   # the R^n direction shown along ``screen``
    h = F[3 + hidden]
    Q = plane_rotation(d, h, math.radians(degrees))
    R = model.rotation() @ Q
    return np.degrees(givens_angles(R))
