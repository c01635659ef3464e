"""Continuation (GCCH) visits only the cubes M passes through and gives GCMH's complex."""

import numpy as np
import pytest

from gcmh_core import InputError, extract
from gcmh_core.examples import load_example


def _same_complex(a, b):
    assert a.counts() == b.counts()
    assert np.allclose(a.vertices, b.vertices, rtol=0, atol=1e-12)
    assert np.array_equal(a.edges, b.edges)
    for r in a.cells:
        assert all(np.array_equal(x, y) for x, y in zip(a.cells[r], b.cells[r]))


@pytest.mark.parametrize("name, div", [("complex-cosine", 12), ("sphere", 20), ("clifford-torus", 10),
                                       ("three-torus", 4), ("klein-bottle", [12, 12, 6, 12, 12])])
def test_gcch_equals_gcmh_on_connected_examples(name, div):
    ex = load_example(name)
    full = extract(ex.formulas, ex.bounds, div, variables=ex.variables)
    cont = extract(ex.formulas, ex.bounds, div, variables=ex.variables, method="gcch", start=ex.start)
    _same_complex(full, cont)
    assert cont.meta["visited_cubes"] < full.meta["cubes"]


def test_start_point_off_M_is_projected():
    on = extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 16, variables="x,y,z", method="gcch", start=(0, 0, 1))
    off = extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 16, variables="x,y,z", method="gcch", start=(0.2, 0.3, 0.4))
    _same_complex(on, off)
    assert off.euler_characteristic() == 2


def test_auto_finds_every_component():
    two = "((x - 1)^2 + y^2 + z^2 - 0.4) * ((x + 1)^2 + y^2 + z^2 - 0.4)"
    both = extract(two, [(-2, 2), (-1, 1), (-1, 1)], [24, 12, 12], variables="x,y,z", method="gcch", start="auto")
    assert both.connected_components() == 2 and both.euler_characteristic() == 4
    one = extract(two, [(-2, 2), (-1, 1), (-1, 1)], [24, 12, 12], variables="x,y,z", method="gcch", start=(1, 0, 0.5))
    assert one.connected_components() == 1 and one.euler_characteristic() == 2
    sphere = extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 12, variables="x,y,z", method="gcch", start="auto")
    assert sphere.connected_components() == 1 and sphere.euler_characteristic() == 2


def test_several_start_points():
    two = "((x - 1)^2 + y^2 + z^2 - 0.4) * ((x + 1)^2 + y^2 + z^2 - 0.4)"
    both = extract(two, [(-2, 2), (-1, 1), (-1, 1)], [24, 12, 12], variables="x,y,z", method="gcch",
                   start=[(1, 0, 0.6), (-1, 0, 0.6)])
    assert both.connected_components() == 2


def test_sampled_data_continues_from_a_crossing_cube():
    axes = [np.linspace(-1.5, 1.5, 17)] * 3
    x, y, z = np.meshgrid(*axes, indexing="ij")
    values = (x**2 + y**2 + z**2 - 1)[..., None]
    full = extract(values, bounds=(-1.5, 1.5))
    cont = extract(values, bounds=(-1.5, 1.5), method="gcch", start=(0.0, 0.0, 1.0))
    _same_complex(full, cont)
    auto = extract(values, bounds=(-1.5, 1.5), method="gcch", start="auto")  # from every crossing cube
    _same_complex(full, auto)


def test_bad_start_points_say_why():
    f = "x^2 + y^2 + z^2 - 1"
    with pytest.raises(InputError, match="outside the domain"):
        extract(f, (-1.5, 1.5), 8, variables="x,y,z", method="gcch", start=(3, 0, 0))
    with pytest.raises(InputError, match="did not converge|left the domain|not finite"):
        extract("x^2 + y^2 + z^2 + 1", (-1.5, 1.5), 8, variables="x,y,z", method="gcch", start=(0.5, 0.5, 0.5))
    with pytest.raises(InputError, match="coordinates"):
        extract(f, (-1.5, 1.5), 8, variables="x,y,z", method="gcch", start=(0, 0))
    with pytest.raises(InputError, match="continuation"):
        extract(f, (-1.5, 1.5), 8, variables="x,y,z", start=(0, 0, 1))


def test_sampled_start_outside_M_says_so():
    axes = [np.linspace(-1.5, 1.5, 17)] * 3
    x, y, z = np.meshgrid(*axes, indexing="ij")
    values = (x**2 + y**2 + z**2 - 1)[..., None]
    with pytest.raises(InputError, match="start cube"):
        extract(values, bounds=(-1.5, 1.5), method="gcch", start=(0.0, 0.0, 0.0))


def test_processed_cubes_are_the_continuation_path():
    ex = load_example("sphere")
    full = extract(ex.formulas, ex.bounds, 12, variables=ex.variables)
    cont = extract(ex.formulas, ex.bounds, 12, variables=ex.variables, method="gcch", start=ex.start)
    cubes = cont.processed_cubes
    assert cubes.shape == (cont.meta["visited_cubes"], 3)
    assert len(np.unique(cubes, axis=0)) == len(cubes) and cubes.min() >= 0 and cubes.max() < 12
    # every cube holding a vertex of M_A was processed, and the path is a thin shell around M
    lo, h = -1.5, 3.0 / 12
    held = np.unique(np.clip(np.floor((full.vertices - lo) / h).astype(int), 0, 11), axis=0)
    done = {tuple(c) for c in cubes}
    assert sum(tuple(c) in done for c in held) >= 0.95 * len(held)
    radius = np.linalg.norm(lo + (cubes + 0.5) * h, axis=1)
    assert np.all(np.abs(radius - 1) < 2 * np.sqrt(3) * h)
    assert not hasattr(full, "processed_cubes") or full.processed_cubes is None
