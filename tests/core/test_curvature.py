"""gcmh_core.curvature: the discrete Gauss-Bonnet sum equals chi on closed surfaces and
surfaces with boundary, in R^3 and in R^5; the curvature of a round sphere is 1/r^2."""

import numpy as np
import pytest

from gcmh_core import InputError, extract
from gcmh_core.curvature import GaussBonnet, gauss_bonnet, gaussian_curvature
from gcmh_core.examples import load_example


def example(name, div):
    ex = load_example(name)
    return extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic or None,
                   params=ex.param_values() or None)


CASES = [  # name, div, chi, has boundary
    ("sphere", 8, 2, False),
    ("torus", [16, 16, 6], 0, False),
    ("klein-bottle-closed", [12, 12, 6, 12, 12], 0, False),
    ("genus-two", [26, 16, 10], -2, False),
    ("moebius-band", [16, 16, 6, 16, 4], 0, True),
    ("klein-bottle", [12, 12, 6, 12, 12], 1, True),  # cut open: a disc in R^5
]


@pytest.mark.parametrize(("name", "div", "chi", "bounded"), CASES)
def test_gauss_bonnet_equals_chi(name, div, chi, bounded):
    cx = example(name, div)
    gb = gauss_bonnet(cx)
    assert gb.euler_characteristic == chi == cx.euler_characteristic()
    assert gb.sum == pytest.approx(chi, abs=1e-9)
    assert (gb.turning != 0.0) == bounded
    c = gaussian_curvature(cx)
    assert c.boundary.any() == bounded
    assert np.all(c.area >= 0) and c.area.sum() > 0


def test_disc_cut_from_the_sphere():
    """A spherical cap: curvature and the boundary's turning share 2pi (cap angle ~ the cut)."""
    cx = extract("x^2 + y^2 + z^2 - 1", bounds=[(-1.5, 1.5), (-1.5, 1.5), (0.0, 1.5)], div=12,
                 variables="x, y, z")
    gb = gauss_bonnet(cx)
    assert gb.sum == pytest.approx(1.0, abs=1e-9)
    # a hemisphere: total curvature 2pi (area 2pi, K = 1), turning 0 along the equator
    assert gb.curvature == pytest.approx(1.0, abs=0.1)
    assert "chi = 1" in gb.describe() and "-0.000" not in gb.describe()


def test_flat_disc_has_no_curvature():
    cx = extract("z - 0.1", bounds=[(-1, 1)] * 3, div=5, variables="x, y, z")
    c = gaussian_curvature(cx)
    assert np.abs(c.defect).max() < 1e-9
    assert gauss_bonnet(cx).turning == pytest.approx(1.0)


def test_round_sphere_density():
    c = gaussian_curvature(extract("x^2 + y^2 + z^2 - 4", bounds=(-2.5, 2.5), div=16, variables="x, y, z"))
    interior = c.area > np.percentile(c.area, 10)  # tiny cells' densities are noisy
    assert np.median(c.density[interior]) == pytest.approx(0.25, rel=0.1)


def test_input_is_checked():
    with pytest.raises(InputError, match="needs a CellComplex"):
        gauss_bonnet(None)
    curve = extract(["x^2 + y^2 + z^2 - 1", "z"], bounds=(-1.5, 1.5), div=6, variables="x, y, z")
    with pytest.raises(InputError, match="surfaces"):
        gaussian_curvature(curve)
    assert GaussBonnet(1.0, 0.0, 1).describe() == "Gauss-Bonnet: K / 2pi = 1.000, chi = 1"
