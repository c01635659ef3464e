"""The simplicial baselines CMS and CCS (paper Section 4) pass the same truth tests as GCMH."""

import numpy as np
import pytest
from test_gcch import _same_complex
from test_topology import CLOSED, _check_complex

from gcmh_core import InputError, extract
from gcmh_core.examples import load_example
from gcmh_core.formula import parse_system

# the closed manifolds of test_topology, at divisions small enough for n! simplices per cube
SMALL = [c if c[0] != "three-torus" else c[:4] + (3, 0) for c in CLOSED if c[0] not in ("genus two",)]


@pytest.mark.parametrize("name, formulas, variables, bounds, div, chi", SMALL, ids=[c[0] for c in SMALL])
def test_cms_closed_manifolds(name, formulas, variables, bounds, div, chi):
    cx = extract(formulas, bounds, div, variables=variables, method="cms")
    gcmh = extract(formulas, bounds, div, variables=variables)
    assert cx.counts()[-1] > gcmh.counts()[-1]  # finer: n! simplices per cube
    assert cx.euler_characteristic() == chi
    assert len(cx.boundary_facets()) == 0
    assert cx.connected_components() == 1
    assert cx.meta["degenerate"] == 0
    _check_complex(cx)


def test_cms_top_cells_are_simplex_pieces():
    # a linear zero set cuts a tetrahedron in a triangle or a quadrilateral
    cx = extract("x^2 + y^2 + z^2 - 1", (-1.3, 1.3), 10, variables="x,y,z", method="cms")
    sizes = np.diff(cx.cells[2][0])
    assert set(np.unique(sizes).tolist()) <= {3, 4}
    # and a (k+1)-simplex in R^4 with k = 2 (a tetrahedron) gives a segment: edges have 2 ends
    cos = load_example("complex-cosine")
    cx = extract(cos.formulas, cos.bounds, 6, variables=cos.variables, method="cms")
    assert cx.edges.shape[1] == 2 and np.all(cx.edges[:, 0] != cx.edges[:, 1])
    assert np.all(np.diff(cx.cells[2][0]) <= 5)  # a plane meets a 4-simplex in at most a pentagon


def test_cms_vertices_within_a_grid_cell_of_M():
    formulas, variables = ["x1^2 + x2^2 - 0.5", "x3^2 + x4^2 - 0.5"], None
    cx = extract(formulas, (-1, 1), 8, method="cms")
    system = parse_system(formulas, variables, n=4)
    x = cx.vertices.copy()
    for _ in range(8):
        F = system.evaluate_points(x)
        J = system.jacobian_points(x)
        x -= np.einsum("vnk,vk->vn", np.linalg.pinv(J), F)
    h = 2 / 8
    assert np.max(np.linalg.norm(x - cx.vertices, axis=1)) < h * np.sqrt(4)


@pytest.mark.parametrize("name, div", [
    ("complex-cosine", 8), ("sphere", 12), ("clifford-torus", 8), ("three-torus", 3),
])
def test_ccs_equals_cms_on_connected_examples(name, div):
    ex = load_example(name)
    full = extract(ex.formulas, ex.bounds, div, variables=ex.variables, method="cms")
    cont = extract(ex.formulas, ex.bounds, div, variables=ex.variables, method="ccs", start=ex.start)
    _same_complex(full, cont)
    assert cont.meta["visited_cubes"] < full.meta["cubes"]


def test_complex_cosine_same_topology_as_gcmh():
    cos = load_example("complex-cosine")
    for div in (5, 10):
        g = extract(cos.formulas, cos.bounds, div, variables=cos.variables)
        s = extract(cos.formulas, cos.bounds, div, variables=cos.variables, method="cms")
        assert s.euler_characteristic() == g.euler_characteristic() == 1
        assert len(s.boundary_facets()) > len(g.boundary_facets())


def test_ccs_auto_finds_both_spheres():
    two = "((x - 1)^2 + y^2 + z^2 - 0.4) * ((x + 1)^2 + y^2 + z^2 - 0.4)"
    both = extract(two, [(-2, 2), (-1, 1), (-1, 1)], [16, 8, 8], variables="x,y,z", method="ccs", start="auto")
    assert both.connected_components() == 2 and both.euler_characteristic() == 4
    one = extract(two, [(-2, 2), (-1, 1), (-1, 1)], [16, 8, 8], variables="x,y,z", method="ccs", start=(1, 0, 0.5))
    assert one.connected_components() == 1 and one.euler_characteristic() == 2


def test_cms_on_sampled_data_and_bad_arguments():
    axes = [np.linspace(-1.5, 1.5, 13)] * 3
    x, y, z = np.meshgrid(*axes, indexing="ij")
    cx = extract((x**2 + y**2 + z**2 - 1)[..., None], bounds=(-1.5, 1.5), method="cms")
    assert cx.euler_characteristic() == 2
    with pytest.raises(InputError, match="continuation only"):
        extract("x^2 + y^2 - 1", (-2, 2), 4, variables="x,y", method="cms", start=(1, 0))
    with pytest.raises(InputError, match="too many"):
        extract("x1^2 + x2^2 + x3^2 + x4^2 + x5^2 + x6^2 + x7^2 + x8^2 - 1", (-2, 2), 2, method="cms")
    with pytest.raises(InputError, match="unknown method"):
        extract("x^2 + y^2 - 1", (-2, 2), 4, variables="x,y", method="marching")


@pytest.mark.parametrize("method", ["cms", "ccs"])
def test_command_line_runs_the_baselines(method, capsys):
    import json

    from gcmh_core.cli import main

    assert main(["extract", "--example", "complex-cosine", "--div", "6", "--method", method, "--json", "--quiet"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["method"] == method and out["euler_characteristic"] == 1
