"""A topology that says how sure it is (issue 25, item 6): `confirm` repeats a run on a second grid."""

import numpy as np
import pytest

from gcmh_core import InputError, extract
from gcmh_core.confirm import confirm, invariants

THIN_TORUS = "(sqrt(x^2+y^2)-0.8)^2 + z^2 - 0.0025"  # a tube of radius 0.05, far below a cube of 0.3


def test_a_smooth_surface_is_confirmed():
    c = confirm("x1^2 + x2^2 + x3^2 - 1", (-1.5, 1.5), 8)
    assert c.agree and c.first == c.second == {"euler_characteristic": 2, "pieces": 1, "boundary": 0}
    assert (c.div, c.seed, c.suggested_div) == ([12, 12, 12], 1, None)
    assert c.message.startswith("confirmed on a second grid (div 12, seed 1): Euler characteristic 2, 1 piece,")
    torus = confirm(["x1^2+x2^2-0.5", "x3^2+x4^2-0.5"], (-1, 1), 8)  # (k = 2)
    assert torus.agree and torus.first["euler_characteristic"] == 0


@pytest.mark.parametrize("div", [6, 8])
def test_a_tube_below_the_resolution_is_not_confirmed(div):
    c = confirm(THIN_TORUS, (-1.2, 1.2), div, variables="x,y,z")
    assert not c.agree and c.first != c.second
    assert "below the grid's resolution" in c.message and c.suggested_div == [2 * c.div[0]] * 3
    assert c.complex is not None and invariants(c.complex) == c.second


def test_the_first_run_is_reused_and_the_seed_moves_on():
    first = extract(THIN_TORUS, (-1.2, 1.2), 8, variables="x,y,z", seed=4)
    c = confirm(THIN_TORUS, result=first, variables="x,y,z")
    assert c.first == invariants(first) and c.seed == 5 and c.div == [12, 12, 12]
    assert c.as_dict()["message"] == c.message and "complex" not in c.as_dict()


def test_what_confirm_refuses():
    values = np.ones((5, 5, 5, 1))
    with pytest.raises(InputError, match="needs F as formulas"):
        confirm(values, (0, 1))
    with pytest.raises(InputError, match="factor"):
        confirm("x1^2 + x2^2 + x3^2 - 1", (-1.5, 1.5), 4, factor=1.0)
