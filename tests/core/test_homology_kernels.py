"""The newer kernels of gcmh_core._homology_kernels against their slow twins
(tests/core/homology_naive.py) on random inputs."""

import numpy as np
import pytest
from homology_naive import orient_top

from gcmh_core._homology_kernels import _orient_top

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@st.composite
def cells_over_faces(draw):
    """Random top cells over a few faces: each cell 1 to 5 face entries, signs +-1 (a face
    on one, two or more entries, twice in one cell too)."""
    n_faces = draw(st.integers(1, 12))
    n_cells = draw(st.integers(1, 10))
    sizes = draw(st.lists(st.integers(1, 5), min_size=n_cells, max_size=n_cells))
    off = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    fac = np.array(draw(st.lists(st.integers(0, n_faces - 1), min_size=int(off[-1]), max_size=int(off[-1]))),
                   dtype=np.int64)
    sign = np.array(draw(st.lists(st.sampled_from([-1, 1]), min_size=fac.size, max_size=fac.size)),
                    dtype=np.int64)
    return off, fac, sign, n_faces


@settings(max_examples=200, deadline=None, derandomize=True)
@given(cells_over_faces())
def test_orient_top_against_naive(case):
    off, fac, sign, n_faces = case
    eps, bad = _orient_top(off, fac, sign, n_faces)
    eps2, bad2 = orient_top(off, fac, sign, n_faces)
    assert eps.tolist() == eps2 and bad.tolist() == bad2
